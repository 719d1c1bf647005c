"""MTF compensation: a restoration filter designed from a fitted sensor
(:mod:`.design`), applied tile by tile to any raster (:mod:`.apply`), and
what it gains in sharpness and costs in noise and ringing (:mod:`.report`)."""

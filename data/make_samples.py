"""Write the synthetic sample chips of data/ (deterministic)."""
from pathlib import Path

import imgmtf

here = Path(__file__).parent
sensor = imgmtf.Sensor()
for name, target, kwargs in (
        ("edge_16bit.tif", imgmtf.Target("edge", 6.0, 200.0, 1200.0), dict(bits=16)),
        ("edge_8bit_noisy.tif", imgmtf.Target("edge", 84.0, 30.0, 210.0),
         dict(bits=8, noise_std_dn=1.8, seed=7))):
    noise = {k: kwargs.pop(k) for k in ("noise_std_dn", "seed") if k in kwargs}
    chip = imgmtf.render(sensor, target, 100, **kwargs, **noise)
    imgmtf.write_geotiff(here / name, chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
    print(name, float(chip.true_mtf(0.5)))

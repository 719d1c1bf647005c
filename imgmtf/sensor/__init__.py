"""The generic sensor: what makes a chip.

The imaging chain's stages, each with its analytic transfer function
(:mod:`.stages`), the sensor they make up (:mod:`.model`), the targets it
images (:mod:`.targets`), the noise (:mod:`.noise`) and the renderer that
turns them into exact, quantised chips (:mod:`.rendering`).  Nothing here
knows of the estimators.
"""

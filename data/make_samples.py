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


def scene():
    """A 512 x 256 px, 16-bit, georeferenced mosaic of 128 px tiles holding
    targets a scan must accept or reject (truth in the IMGMTF tag)."""
    import json

    import numpy as np
    tile = imgmtf.Renderer(sensor, 128)
    noise = dict(noise_std_dn=6.0)
    layout = [  # (row, col, target, expected scan verdict, seed)
        (0, 0, imgmtf.Target("edge", 7.0, 300.0, 1500.0), "accepted", 1),
        (1, 0, imgmtf.Target("edge", 82.0, 300.0, 1500.0), "accepted", 2),
        (0, 1, imgmtf.Target("pulse", -5.0, 300.0, 1500.0, width_px=3.0), "bar", 3),
        (1, 1, imgmtf.Target("edge", 45.0, 300.0, 1500.0), "angle", 4),
        (0, 2, imgmtf.Target("edge", 8.0, 300.0, 70000.0), "saturated", 5),
        (1, 2, imgmtf.Target("edge", -9.0, 300.0, 1500.0), "non-uniform", 6),
        (0, 3, imgmtf.Target("pulse", 6.0, 300.0, 1500.0, width_px=12.0), "two-targets", 7),
        (1, 3, imgmtf.Target("edge", 10.0, 300.0, 1500.0), "too-short", 8),
    ]
    image = np.zeros((256, 512), np.uint16)
    truth = []
    for r, c, target, verdict, seed in layout:
        chip = tile(target, seed=seed, **noise)
        block = chip.image.astype(float)
        if verdict == "non-uniform":       # a field that brightens across the bright side
            block += np.clip(np.arange(128) - 64, 0, None)[None, :] * 20.0
        if verdict == "too-short":         # only 30 rows of the edge on a uniform field
            short = np.full_like(block, 300.0)
            short[50:80] = block[50:80]
            block = short
        image[128 * r: 128 * (r + 1), 128 * c: 128 * (c + 1)] = np.clip(block, 0, 65535)
        truth.append({"tile_xywh": [128 * c, 128 * r, 128, 128], "verdict": verdict,
                      "target": target.to_dict(),
                      "true_mtf_nyquist": round(float(chip.true_mtf(0.5)), 6),
                      "true_mtf50_cy_px": round(chip.true_mtf50_cy_px(), 6)})
    imgmtf.write_geotiff(here / "scene.tif", image, gsd_m=sensor.gsd_m, crs="EPSG:32633",
                         origin_m=(500000.0, 4650000.0),
                         provenance={"imgmtf_version": imgmtf.__version__, "sensor": sensor.to_dict(),
                                     "noise_std_dn": noise["noise_std_dn"], "tiles": truth})
    print("scene.tif", json.dumps([(t["verdict"], t["true_mtf_nyquist"]) for t in truth]))


scene()

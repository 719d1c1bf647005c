"""Realistic traps: an edge of known MTF spoiled the way real images are.

Each trap is built from closed forms (tests/conftest.py's exact edge
chips: every pixel the exact edge response at its distance from the edge;
Gaussian optics sigma 0.4 px and a square pixel at 6 deg unless said, 100 x
100 px, 200 -> 1200 DN with 3 DN of noise) and spoiled one way.  Each must
be measured within 0.02 of its truth at Nyquist, or refused (or warned)
for the right reason: no silent wrong number.  Prints each trap's
outcome, then the noise-free chips other generators write (a flat white
of exactly one value; MTF50 within 1 % of truth) and noise-free bars.

usage: python bench/traps.py
"""
from __future__ import annotations

import math
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import rasterio
from scipy.ndimage import gaussian_filter

import imgmtf as im
from imgmtf.batch import MeasureSettings, measure_file
from imgmtf.errors import ImgmtfError
from imgmtf.transfer import parse_transfer

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from conftest import (
    diffraction_transfer,
    exact_edge_chip,
    gaussian_pixel_transfer,
    olpf_transfer,
    product,
    true_mtf50,
)

ANGLE = 6.0
H = gaussian_pixel_transfer(0.4, ANGLE)
TRUTH = float(H(0.5))
TOLERANCE = 0.02


def chip(noise=3.0, h=H, angle=ANGLE, seed=1, **kw):
    return exact_edge_chip(h, angle, offset=0.2, noise_std=noise, seed=seed, dtype=np.float64, **kw)


def distance(shape=(100, 100), angle=ANGLE, offset=0.2):
    rows, cols = shape
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    a = math.radians(angle)
    return (x - (cols - 1) / 2) * math.cos(a) + (y - (rows - 1) / 2) * math.sin(a) - offset


def written(image, suffix, **options):
    """``image`` written to a temporary file and read back as a user's would be."""
    path = Path(tempfile.mkdtemp()) / f"trap{suffix}"
    driver = {".jpg": "JPEG", ".png": "PNG"}.get(suffix, "GTiff")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with rasterio.open(path, "w", driver=driver, width=image.shape[1], height=image.shape[0], count=1,
                           dtype=image.dtype, **options) as dst:
            dst.write(image, 1)
    return str(path)


def traps():
    """(name, image or file, expected reasons or warning words, truth at Nyquist, measure keywords)."""
    d = distance()
    c = 1000.0
    out = []
    out.append(("curved illumination (bright side + 10 % u^2)", chip() + c * 0.1 * np.clip(d / 50, 0, None) ** 2,
                {"non-uniform"}, TRUTH, {}))
    out.append(("plateau that never settles (20 % still to come, 15 px)",
                chip() + c * 0.2 * (1 - np.exp(-np.clip(d, 0, None) / 15)), {"non-uniform"}, TRUTH, {}))
    out.append(("a bowl beside the target (15 % dip 18 px out)",
                chip() - c * 0.15 * np.exp(-((d - 18) / 6) ** 2), {"non-uniform", "two-targets"}, TRUTH, {}))
    gains = 1 + 0.01 * np.random.default_rng(7).normal(size=100)
    out.append(("pushbroom striping (1 % column gains)", chip() * gains[None, :],
                {"non-uniform"}, TRUTH, {}))
    halves = np.vstack([chip(h=gaussian_pixel_transfer(0.5, ANGLE))[:50],
                        chip(h=gaussian_pixel_transfer(0.9, ANGLE), seed=2)[50:]])
    out.append(("blur changing along the edge (sigma 0.5 / 0.9 px)", halves, {"varying-blur"},
                float(gaussian_pixel_transfer(0.5, ANGLE)(0.5)), {}))
    out.append(("a shadow band on the bright side (40 %, 4 px, 12 px out)",
                chip() - c * 0.4 * ((d > 12) & (d < 16)), {"two-targets", "non-uniform"}, TRUTH, {}))
    out.append(("a road beside the edge (60 %, 6 px, 10 px out on the dark side)",
                chip() + c * 0.6 * ((d < -10) & (d > -16)), {"two-targets", "non-uniform"}, TRUTH, {}))
    twelve = exact_edge_chip(H, ANGLE, offset=0.2, low=3000, high=4400, noise_std=20.0, seed=3, dtype=np.float64)
    out.append(("12-bit data clipped at 4095 in a 16-bit file", np.minimum(twelve, 4095).astype(np.uint16),
                {"saturated"}, TRUTH, {}))
    edge8 = exact_edge_chip(H, ANGLE, offset=0.2, low=30, high=210, noise_std=1.0, dtype=np.uint8, shape=(96, 96))
    out.append(("JPEG quality 75 (file)", written(edge8, ".jpg", QUALITY=75), {"JPEG compression"}, TRUTH, {}))
    out.append(("JPEG quality 20 (file)", written(edge8, ".jpg", QUALITY=20), {"compression"}, TRUTH, {}))
    linear8 = exact_edge_chip(H, ANGLE, offset=0.2, low=0.1, high=0.8, noise_std=0.002, dtype=np.float64)
    grid = np.linspace(0.0, 1.0, 400001)
    srgb = np.rint(np.interp(linear8, parse_transfer("srgb").linearise(grid, 1.0), grid) * 255).astype(np.uint8)
    gamma_file = written(srgb, ".tif")
    out.append(("8-bit sRGB-encoded greyscale TIFF, as stored (file)", gamma_file, {"taken as linear"}, TRUTH, {}))
    out.append(("the same, --transfer srgb (file)", gamma_file, set(), TRUTH, {"transfer": "srgb"}))
    corner = chip()
    corner[55:, :] = exact_edge_chip(H, 90.0 - ANGLE, offset=0.2, noise_std=3.0, seed=4, dtype=np.float64)[55:, :]
    out.append(("a corner (the edge turns halfway)", corner, {"not-straight", "two-targets"}, TRUTH, {}))
    hot = chip()
    rng = np.random.default_rng(3)
    hot[rng.choice(100, 12, replace=False), rng.choice(np.r_[5:40, 62:95], 12, replace=False)] = \
        np.where(np.arange(12) % 2, 4000.0, 0.0)
    out.append(("12 hot and dead pixels", hot, set(), TRUTH, {}))
    holes = chip()
    y, x = np.mgrid[0:100, 0:100]
    for cy, cx, r in ((20, 30, 6), (60, 70, 8), (80, 45, 4)):
        holes[(y - cy) ** 2 + (x - cx) ** 2 < r * r] = np.nan
    out.append(("NaN holes (cloud mask, 3 blobs)", holes, set(), TRUTH, {}))
    bar = im.render(im.Sensor(), im.Target("pulse", ANGLE, 200.0, 1200.0, 0.3, 2.0), (100, 80),
                    noise_std_dn=3.0, seed=5)
    shade = bar.image.astype(float) - 300.0 * ((distance((100, 80), offset=0.3) > 7)
                                              & (distance((100, 80), offset=0.3) < 11))
    out.append(("a bar with a shadow beside it", shade, {"two-targets", "non-uniform"}, float(bar.true_mtf(0.5)),
                {"measure": im.measure_pulse, "width_px": 2.0}))
    h45 = gaussian_pixel_transfer(0.4, 43.0)
    out.append(("near-45 deg (43 deg)", chip(h=h45, angle=43.0), {"angle", "unsuitable"}, float(h45(0.5)), {}))
    texture = 50.0 * gaussian_filter(np.random.default_rng(3).normal(size=(100, 100)), 2.0) / 0.14
    out.append(("a textured side (5 % texture)", chip() + (d > 3) * texture, {"non-uniform", "two-targets"},
                TRUTH, {}))
    return out


def outcome(target, expected, truth, options):
    """(verdict, line): measured within tolerance, or refused/warned as expected."""
    options = dict(options)
    measure = options.pop("measure", im.measure_edge)
    try:
        if isinstance(target, str):
            (record,) = measure_file(target, MeasureSettings(transfer=options.get("transfer", "linear")))
            if not record.ok:
                raise ImgmtfError(record.error or "", reason=record.reason)
            nyquist, said = record.get("mtf_nyquist"), record.get("warnings") or []
        else:
            result = measure(target, **options)
            nyquist, said = result.mtf_nyquist, list(result.warnings)
    except ImgmtfError as exc:
        right = exc.reason in expected
        return right, f"refused   {exc.reason:13s} {'right reason' if right else 'WRONG REASON'}: {str(exc)[:90]}"
    error = nyquist - truth
    warned = [w for w in said if any(word in w for word in expected)]
    if abs(error) <= TOLERANCE:
        note = f"; warned: {warned[0][:60]}" if warned else ""
        return True, f"measured  {nyquist:.4f} (truth {truth:.4f}, {error:+.4f}){note}"
    if warned:
        return True, f"warned    {nyquist:.4f} (truth {truth:.4f}, {error:+.4f}): {warned[0][:70]}"
    return False, f"SILENT WRONG NUMBER {nyquist:.4f} (truth {truth:.4f}, {error:+.4f})"


def generator_chips():
    """Noise-free chips with a white of exactly one value (63897 DN, as MTF
    Mapper's generator writes), and a last-digit wobble below it in steps of
    17 DN: (name, image, truth transfer)."""
    pixel = gaussian_pixel_transfer(0.0, 5.0)
    chips = []
    for name, h in (("Gaussian sigma 0.45 px + pixel", gaussian_pixel_transfer(0.45, 5.0)),
                    ("Gaussian sigma 0.7 px + pixel", gaussian_pixel_transfer(0.7, 5.0))):
        exact = exact_edge_chip(h, 5.0, low=1638.0, high=63897.0, offset=0.2, dtype=np.float64)
        wobble = 17.0 * np.floor(np.abs(np.random.default_rng(5).normal(0.0, 1.9, exact.shape)))
        chips.append((name + ", white wobble", np.rint(exact - wobble).astype(np.uint16), h))
        chips.append((name + ", exact", np.rint(exact).astype(np.uint16), h))
    for n in (4.0, 5.6, 8.0, 11.0, 16.0):
        airy = diffraction_transfer(8.6 / n)
        chips.append((f"Airy f/{n:g}", exact_edge_chip(airy, 5.0, shape=(100, 200), low=1638.0, high=63897.0,
                                                       offset=0.2), airy))
        h = product(airy, pixel)
        chips.append((f"Airy + pixel f/{n:g}", exact_edge_chip(h, 5.0, shape=(100, 200), low=1638.0,
                                                               high=63897.0, offset=0.2), h))
    h = product(diffraction_transfer(8.6 / 5.6), pixel, olpf_transfer(0.75, 5.0))
    chips.append(("Airy + 4-dot OLPF f/5.6", exact_edge_chip(h, 5.0, shape=(100, 200), low=1638.0, high=63897.0,
                                                             offset=0.2), h))
    return chips


def main() -> int:
    start = time.perf_counter()
    print("1. traps: each measured within 0.02 of its truth at Nyquist, or refused/warned for the right reason")
    wrong = 0
    for name, target, expected, truth, options in traps():
        right, line = outcome(target, expected, truth, options)
        wrong += not right
        print(f"  {name:58s} {line}")
    print(f"  {wrong} silent wrong number(s) or wrong reason(s)")
    print("\n2. noise-free chips with an exactly flat white (63897 DN): MTF50 error")
    worst = 0.0
    for name, image, h in generator_chips():
        try:
            r = im.measure_edge(image)
            error = r.mtf50_cy_px / true_mtf50(h) - 1
            worst = max(worst, abs(error))
            print(f"  {name:40s} MTF50 {r.mtf50_cy_px:.4f} (truth {true_mtf50(h):.4f}, {100 * error:+.2f} %)")
        except ImgmtfError as exc:
            worst = math.inf
            print(f"  {name:40s} REFUSED {exc.reason}: {str(exc)[:90]}")
    print(f"  worst |MTF50 error| {100 * worst:.2f} %")
    print("\n3. noise-free bars (the paper's sensor): MTF error away from the sinc's zeros")
    for width in (3.0, 5.0, 8.0, 10.0):
        bar = im.render(im.Sensor(), im.Target("pulse", 6.0, 200.0, 1200.0, 0.3, width), (100, 80))
        try:
            r = im.measure_pulse(bar.image, width_px=width)
            f = np.array([0.5, 1.5]) / width
            print(f"  {width:4.1f} px  measured, worst |MTF error| at {f[0]:.3f}, {f[1]:.3f} cy/px "
                  f"{np.max(np.abs(r.mtf_function(f) - bar.true_mtf(f))):.4f}")
        except ImgmtfError as exc:
            print(f"  {width:4.1f} px  REFUSED {exc.reason}: {str(exc)[:90]}")
    print(f"\n{time.perf_counter() - start:.0f} s")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())

"""Accuracy of the edge estimator against exact truth, per blur family.

Chips come from the generic sensor's renderer, which evaluates every pixel
as the exact edge response at its distance from the edge (diffraction's
1/x^2 tail in closed form; tests/test_rendering.py checks it against an
independent computation); the truth is the sensor's analytic transfer
function along the edge normal.

Families (pixel aperture 1 px throughout; diffraction for 4.73 um pixels
at 550 nm, so f/N has its cut-off at 8.6 / N cy/px):

  gaussian      Gaussian optics sigma 0.35, 0.5, 0.7 px
  sensor        the paper's sensor (optics, detector, motion, electronics),
                across and along track
  diffraction   f/5.6, f/8, f/11, f/16, f/22
  diff+gauss    f/8 and f/11 with Gaussian optics sigma 0.4 px
  defocus       a uniform disk of radius 1, 1.5, 2 px with sigma 0.3 px
  olpf          a 4-dot OLPF of split 0.75 px with f/5.6 diffraction

Each at angles 3.5-11 deg (and 84 deg along track for "sensor"), 8 bit
(30 -> 210 DN) and 16 bit (200 -> 1200 DN); long-tailed families on 100 x
200 px chips, the others on 100 x 100.  Prints, per family and depth:

1. noise-free: worst |error| of MTF at Nyquist (absolute), of MTF50 and of
   FWHM (relative);
2. noisy (SNR = step / noise sd of 100, 50, 25; N chips each, random angle
   and offset): bias and RMS error of MTF at Nyquist, and the share of
   chips refused (they should be none).

Then the noise study the docs quote: 100 x 100 Gaussian (sigma 0.5 px)
edges at SNR 200, 100, 50, 25, 300 chips each, RMS error at Nyquist.

usage: python bench/edge_accuracy.py [--chips N] [--study-chips N] [--method msg]
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np

import imgmtf as im
from imgmtf.sensor.stages import OLPF, Defocus, Detector, Diffraction, GaussianOptics

PITCH_M, WAVELENGTH_M = 4.73e-6, 0.55e-6
ANGLES = (3.5, 5.0, 7.5, 9.0, 11.0)
DEPTHS = {8: (30.0, 210.0), 16: (200.0, 1200.0)}


def diffraction(n):
    return Diffraction(f_number=n, wavelength_m=WAVELENGTH_M, pixel_pitch_m=PITCH_M)


def gaussian(sigma):
    return GaussianOptics(sigma_x_m=sigma, sigma_y_m=sigma)


PIXEL = Detector(width_x_m=1.0, width_y_m=1.0)
FAMILIES = {
    "gaussian": ([im.Sensor(1.0, [gaussian(s), PIXEL]) for s in (0.35, 0.5, 0.7)], (100, 100)),
    "sensor": ([im.Sensor()], (100, 100)),
    "diffraction": ([im.Sensor(1.0, [diffraction(n), PIXEL]) for n in (5.6, 8, 11, 16, 22)], (100, 200)),
    "diff+gauss": ([im.Sensor(1.0, [diffraction(n), gaussian(0.4), PIXEL]) for n in (8, 11)], (100, 200)),
    "defocus": ([im.Sensor(1.0, [Defocus(radius_m=r), gaussian(0.3), PIXEL]) for r in (1.0, 1.5, 2.0)],
                (100, 200)),
    "olpf": ([im.Sensor(1.0, [OLPF(split_m=0.75), diffraction(5.6), PIXEL])], (100, 200)),
}


def measure(chip, method):
    r = im.measure_edge(chip.image, method=method, intervals=im.Intervals("none"))
    return (r.mtf_nyquist - float(chip.true_mtf(0.5)), r.mtf50_cy_px / chip.true_mtf50_cy_px() - 1,
            r.fwhm_px / chip.true_fwhm_px() - 1)


def noise_free(method):
    print("1. noise-free: worst |error|: MTF@Nyq absolute, MTF50 and FWHM relative")
    print(f"{'family':12s} {'bits':>4s} {'chips':>5s} {'MTF@Nyq':>8s} {'MTF50 %':>8s} {'FWHM %':>7s}")
    rng = np.random.default_rng(1)
    for family, (sensors, shape) in FAMILIES.items():
        for bits, (low, high) in DEPTHS.items():
            errors = []
            for sensor in sensors:
                renderer = im.Renderer(sensor, shape, bits=bits)
                angles = ANGLES + ((84.0,) if family == "sensor" else ())
                for angle in angles:
                    target = im.Target("edge", angle, low, high, float(rng.uniform(-0.5, 0.5)))
                    errors.append(measure(renderer(target), method))
            e = np.abs(np.array(errors))
            print(f"{family:12s} {bits:4d} {len(errors):5d} {e[:, 0].max():8.4f} {100 * e[:, 1].max():8.2f} "
                  f"{100 * e[:, 2].max():7.2f}")


def noisy(method, chips):
    print(f"\n2. noisy, {chips} chips per SNR: bias / RMS error of MTF at Nyquist (refused)")
    print(f"{'family':12s} {'bits':>4s} " + " ".join(f"{'SNR ' + str(s):>22s}" for s in (100, 50, 25)))
    for family, (sensors, shape) in FAMILIES.items():
        for bits, (low, high) in DEPTHS.items():
            cells = []
            for snr in (100, 50, 25):
                rng = np.random.default_rng(snr * bits)
                errors, refused = [], 0
                for i in range(chips):
                    sensor = sensors[i % len(sensors)]
                    angle = float(rng.uniform(3.0, 12.0) * rng.choice([-1, 1]))
                    target = im.Target("edge", angle, low, high, float(rng.uniform(-0.5, 0.5)))
                    chip = im.render(sensor, target, shape, bits=bits, noise_std_dn=(high - low) / snr,
                                     seed=int(rng.integers(2 ** 31)))
                    try:
                        errors.append(measure(chip, method)[0])
                    except im.ImgmtfError:
                        refused += 1
                e = np.array(errors)
                cells.append(f"{e.mean():+.4f} / {math.sqrt(np.mean(e ** 2)):.4f} ({refused})")
            print(f"{family:12s} {bits:4d} " + " ".join(f"{c:>22s}" for c in cells))


def noise_study(method, chips):
    print(f"\n3. noise study: 100 x 100 px, Gaussian sigma 0.5 px + pixel, 3-12 deg, {chips} chips per SNR")
    renderer = im.Renderer(im.Sensor(1.0, [gaussian(0.5), PIXEL]), 100)
    for snr in (200, 100, 50, 25):
        rng = np.random.default_rng(snr)
        errors = []
        for _ in range(chips):
            angle = float(rng.uniform(3, 12) * rng.choice([-1, 1]))
            chip = renderer(im.Target("edge", angle, 200.0, 1200.0, float(rng.uniform(-0.5, 0.5))),
                            noise_std_dn=1000.0 / snr, seed=int(rng.integers(2 ** 31)))
            errors.append(measure(chip, method)[0])
        e = np.array(errors)
        print(f"SNR {snr:3d}: bias {e.mean():+.4f}  RMS {math.sqrt(np.mean(e ** 2)):.4f}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--chips", type=int, default=40, help="noisy chips per family, depth and SNR")
    p.add_argument("--study-chips", type=int, default=300, help="chips per SNR in the noise study")
    p.add_argument("--method", default="msg")
    a = p.parse_args()
    start = time.perf_counter()
    noise_free(a.method)
    noisy(a.method, a.chips)
    noise_study(a.method, a.study_chips)
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()

"""Coverage of the confidence intervals on noisy chips of known MTF.

For each case N chips are rendered with a random angle (3-12 deg, either
sign) and sub-pixel offset, white system noise of (high - low) / SNR DN
and, in the "ground" cases, the paper's 20-layer ground noise as well.
Each chip is measured (msg) and the script counts how often the nominal
95 % intervals for MTF at Nyquist and MTF50 contain the true values.  With
N chips a true coverage of 95 % is read within +-2 sqrt(0.95 * 0.05 / N)
(+-3.1 % for N = 200) in 95 % of runs.

Cases: fixed (target, rows, SNR, blur) families (bars of 1.5 px, their
width given, or read off the profile by the estimator), and "mixed": SNR drawn
log-uniformly from 25 to 200, 40 to 200 rows, Gaussian (sigma 0.35-0.7 px)
or diffraction (f/5.6-f/16) blur with the pixel aperture.

Prints per case: coverage of each interval, its mean width, the RMS error
of the estimate, and the standard deviation the width implies (width /
3.92) over that RMS (1 when the interval is the right width).

usage: python bench/coverage.py [--chips N] [--workers W] [--intervals influence|bootstrap]
"""
from __future__ import annotations

import argparse
import functools
import time
import zlib
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import imgmtf as im
from imgmtf.sensor.stages import Detector, Diffraction, GaussianOptics

LOW, HIGH = 200.0, 1200.0
PULSE_WIDTH_PX = 1.5
PIXEL = Detector(width_x_m=1.0, width_y_m=1.0)
CASES = [  # (name, target, rows, snr, ground noise, blur)
    ("edge 100 rows SNR 200", "edge", 100, 200, False, "paper"),
    ("edge 100 rows SNR 100", "edge", 100, 100, False, "paper"),
    ("edge 100 rows SNR 50", "edge", 100, 50, False, "paper"),
    ("edge 100 rows SNR 25", "edge", 100, 25, False, "paper"),
    ("edge 40 rows SNR 100", "edge", 40, 100, False, "paper"),
    ("edge 40 rows SNR 25", "edge", 40, 25, False, "paper"),
    ("edge 100 rows f/11 SNR 50", "edge", 100, 50, False, "diffraction"),
    ("edge 100 rows SNR 100 +ground", "edge", 100, 100, True, "paper"),
    ("bar 100 rows SNR 100", "pulse", 100, 100, False, "paper"),
    ("bar 100 rows SNR 50", "pulse", 100, 50, False, "paper"),
    ("bar width read SNR 200", "pulse-width-read", 100, 200, False, "paper"),
    ("bar width read SNR 100", "pulse-width-read", 100, 100, False, "paper"),
    ("mixed", "edge", None, None, False, "mixed"),
]


def _sensor(blur, rng):
    if blur == "paper":
        return im.Sensor()
    if blur == "diffraction":
        return im.Sensor(1.0, [Diffraction(f_number=11.0, wavelength_m=0.55e-6, pixel_pitch_m=4.73e-6), PIXEL])
    if rng.uniform() < 0.5:
        s = float(rng.uniform(0.35, 0.7))
        return im.Sensor(1.0, [GaussianOptics(sigma_x_m=s, sigma_y_m=s), PIXEL])
    n = float(rng.uniform(5.6, 16.0))
    return im.Sensor(1.0, [Diffraction(f_number=n, wavelength_m=0.55e-6, pixel_pitch_m=4.73e-6), PIXEL])


def _one(case, intervals, seed):
    _, kind, rows, snr, ground, blur = case
    rng = np.random.default_rng(seed)
    if rows is None:
        rows = int(rng.integers(40, 201))
        snr = float(np.exp(rng.uniform(np.log(25), np.log(200))))
    angle = float(rng.uniform(3.0, 12.0)) * rng.choice([-1, 1])
    width_given = kind == "pulse"            # "pulse-width-read": the estimator reads it off the profile
    kind = "edge" if kind == "edge" else "pulse"
    target = im.Target(kind, angle, LOW, HIGH, float(rng.uniform(-0.5, 0.5)),
                       PULSE_WIDTH_PX if kind == "pulse" else 0.0)
    width = 100 if blur in ("diffraction", "mixed") else 60
    chip = im.render(_sensor(blur, rng), target, (rows, width), noise_std_dn=(HIGH - LOW) / snr,
                     ground_noise=im.GroundNoise() if ground else None, seed=seed)
    settings = im.Intervals(intervals)
    try:
        if kind == "edge":
            r = im.measure_edge(chip.image, intervals=settings)
        else:
            r = im.measure_pulse(chip.image, width_px=PULSE_WIDTH_PX if width_given else None,
                                 intervals=settings)
    except im.ImgmtfError:
        return None
    true_nyq, true_50 = float(chip.true_mtf(0.5)), chip.true_mtf50_cy_px()
    return (r.mtf_nyquist - true_nyq, true_nyq in r.mtf_nyquist_ci, r.mtf_nyquist_ci.width,
            r.mtf50_cy_px - true_50, true_50 in r.mtf50_ci_cy_px, r.mtf50_ci_cy_px.width)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chips", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--intervals", default="influence", choices=["influence", "bootstrap"])
    parser.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    args = parser.parse_args()
    wanted = [c for c in CASES if not args.cases or c[0] in args.cases.split(",")]
    print(f"95 % {args.intervals} intervals, msg, {args.chips} chips per case")
    print(f"{'case':<30} {'cover Nyq':>9} {'width':>7} {'RMS':>7} {'sd/RMS':>6}   "
          f"{'cover M50':>9} {'width':>7} {'RMS':>7} {'sd/RMS':>6}  refused")
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        for case in wanted:
            base = zlib.crc32(case[0].encode()) % 100_000 * 1000     # a case's chips whatever else runs
            seeds = [base + k for k in range(args.chips)]
            out = [o for o in pool.map(functools.partial(_one, case, args.intervals), seeds) if o is not None]
            a = np.array(out, float)
            cells = []
            for err, cover, width in ((a[:, 0], a[:, 1], a[:, 2]), (a[:, 3], a[:, 4], a[:, 5])):
                rms = np.sqrt(np.nanmean(err ** 2))
                cells.append(f"{100 * np.nanmean(cover):8.1f}% {np.nanmean(width):7.4f} {rms:7.4f} "
                             f"{np.nanmean(width) / 3.92 / rms:6.2f}")
            print(f"{case[0]:<30} {cells[0]}   {cells[1]}  {args.chips - len(out)}")
    print(f"({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()

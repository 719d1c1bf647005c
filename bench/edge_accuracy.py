"""Accuracy of the edge estimator against exact truth, all methods side by side.

Chips come from the generic-sensor renderer, which is exact to 1e-3 DN
before rounding (tests/test_rendering.py checks it against an independent
computation).  Prints:

1. noise-free: worst |error| of MTF at Nyquist (absolute), MTF50 and FWHM
   (relative) over Gaussian+pixel sensors (sigma 0.35, 0.5, 0.7 px) at
   angles 3-12 deg, and the paper's sensor across and along track;
2. the same with each method's own corrections switched off (the paper's
   algorithms as published: its ranking spline < sliding < msg);
3. noisy chips (SNR 200, 100, 50, 25; sigma 0.5 px, 100 x 100 px): bias and
   RMS error of MTF at Nyquist per SNR.

usage: python bench/edge_accuracy.py [--realisations N] [--methods msg,iso]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import imgmtf as im
from imgmtf.estimate.edge import EdgeEstimator


def gaussian_sensor(sigma):
    return im.Sensor(optics_sigma_x_m=sigma, optics_sigma_y_m=sigma, motion_m=0.0,
                     electronics_cutoff_cy_m=0.0)


def noise_free_chips():
    rng = np.random.default_rng(11)
    chips = []
    for sigma in (0.35, 0.5, 0.7):
        renderer = im.Renderer(gaussian_sensor(sigma), 100)
        for angle in (3.0, 5.0, 7.5, 10.0, 12.0, -6.0):
            chips.append(renderer(im.Target("edge", angle, 200.0, 1200.0, float(rng.uniform(-.5, .5)))))
    paper = im.Renderer(im.Sensor(), 100)
    chips += [paper(im.Target("edge", 6.0, 200.0, 1200.0, 0.2)),
              paper(im.Target("edge", 84.0, 200.0, 1200.0, -0.3))]
    return chips


def errors(estimator, chips):
    nyq, m50, fw = [], [], []
    for chip in chips:
        r = estimator(chip.image)
        nyq.append(r.mtf_nyquist - float(chip.true_mtf(0.5)))
        m50.append(r.mtf50_cy_px / chip.true_mtf50_cy_px() - 1)
        fw.append(r.fwhm_px / chip.true_fwhm_px() - 1)
    return np.array(nyq), np.array(m50), np.array(fw)


def noisy_chips(snr, n, seed):
    rng = np.random.default_rng(seed)
    renderer = im.Renderer(gaussian_sensor(0.5), 100)
    out = []
    for _ in range(n):
        angle = float(rng.uniform(3, 12) * rng.choice([-1, 1]))
        target = im.Target("edge", angle, 200.0, 1200.0, float(rng.uniform(-.5, .5)))
        out.append(renderer(target, noise_std_dn=1000.0 / snr, seed=int(rng.integers(2**31))))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--realisations", type=int, default=100, help="noisy chips per SNR")
    p.add_argument("--methods", default="msg,sliding,spline,iso")
    a = p.parse_args()
    methods = a.methods.split(",")
    chips = noise_free_chips()
    print(f"noise-free: {len(chips)} chips; worst |error|: MTF@Nyq absolute, MTF50 and FWHM relative")
    print(f"{'method':10s} {'corrected':>10s} {'MTF@Nyq':>9s} {'MTF50 %':>8s} {'FWHM %':>8s} {'mean MTF@Nyq err':>17s}")
    for correct in (True, False):
        for method in methods:
            nyq, m50, fw = errors(EdgeEstimator(method, correct=correct), chips)
            print(f"{method:10s} {str(correct):>10s} {np.abs(nyq).max():9.4f} {100 * np.abs(m50).max():8.2f} "
                  f"{100 * np.abs(fw).max():8.2f} {nyq.mean():+17.4f}")
    print(f"\nnoisy: sigma 0.5 px + pixel, 100 x 100 px, {a.realisations} chips per SNR, "
          "error of MTF at Nyquist (absolute)")
    print(f"{'method':10s} " + " ".join(f"{'SNR ' + str(s) + ' bias':>13s} {'RMS':>7s}" for s in (200, 100, 50, 25)))
    sets = {snr: noisy_chips(snr, a.realisations, seed=snr) for snr in (200, 100, 50, 25)}
    for method in methods:
        est = EdgeEstimator(method)
        cells = []
        for snr, lst in sets.items():
            e = np.array([est(c.image).mtf_nyquist - float(c.true_mtf(0.5)) for c in lst])
            cells.append(f"{e.mean():+13.4f} {np.sqrt(np.mean(e ** 2)):7.4f}")
        print(f"{method:10s} " + " ".join(cells))


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"\n({time.perf_counter() - t0:.0f} s)")

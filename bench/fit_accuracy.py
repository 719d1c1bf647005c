"""Accuracy of the parametric estimate (imgmtf.fit_sensor) against exact truth.

Chips come from the renderer, exact at every pixel for every stage
(tests/test_rendering.py).  Prints:

1. generic sensors (optics, detector, motion, electronics; not the paper's
   values), an across- and an along-track noise-free 16-bit chip each,
   fitted together with the default stages: each edge's model MTF at
   Nyquist against the truth;
2. single 100 x 100 px chips at SNR 25 (Gaussian optics sigma 0.5 px +
   pixel, 3-12 deg), each fitted alone with stages optics,detector: bias
   and RMS error at Nyquist, beside the non-parametric estimate (msg) of
   the same chips, and the coverage of the fit's 95 % interval;
3. diffraction-limited chips (circular aperture, 550 nm, 5 um pixels, plus
   the pixel aperture), noise-free: fitted with the default stages (the
   wrong model: error, misfit warning?) and with diffraction,detector;
4. the same sensors at SNR 50;
5. when is a wrong model caught: Gaussian + pixel and f/8 diffraction +
   pixel chips at SNR 100, 50 and 25 fitted with the default stages: RMS
   error at Nyquist of the fit and of the non-parametric estimate, and how
   often the misfit warning fires.

usage: python bench/fit_accuracy.py [--realisations N] [--parts 1,2,3,4]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import imgmtf as im
from imgmtf.sensor import stages as st

GENERIC = [
    im.Sensor(1.0, [st.GaussianOptics(0.45, 0.36), st.Detector(0.9, 1.1), st.Motion(0.4), st.Electronics(1.1)]),
    im.Sensor(1.0, [st.GaussianOptics(0.3, 0.3), st.Detector(1.0, 1.0), st.Motion(0.6), st.Electronics(2.0)]),
    im.Sensor(2.0, [st.GaussianOptics(1.2, 1.0), st.Detector(2.0, 2.0), st.Motion(0.3), st.Electronics(0.6)]),
]
F_NUMBERS = (5.6, 8.0, 11.0, 16.0)


def true_nyquist(sensor, angle, gsd):
    return float(abs(sensor.normal_transfer(0.5, angle, gsd)))


def part_generic():
    print("1. generic sensors, across + along noise-free chips (100 x 100, 16 bit), default stages")
    print(f"{'sensor':>6} {'angle':>6} {'true':>7} {'fit':>7} {'error':>8} {'measured':>8} {'chi2':>6}  held/tied")
    worst = 0.0
    for i, sensor in enumerate(GENERIC):
        renderer = im.Renderer(sensor, 100)
        chips = [renderer(im.Target("edge", a, 200.0, 1200.0, o)).image for a, o in ((5.0, 0.3), (84.0, -0.2))]
        fit = im.fit_sensor(chips, gsd_m=sensor.gsd_m)
        held = ", ".join(p.key for p in fit.parameters if p.status != "fitted" and p.note != "not fitted")
        for e in fit.edges:
            truth = true_nyquist(sensor, e.normal_angle_deg, e.gsd_m)
            worst = max(worst, abs(e.mtf_nyquist - truth))
            print(f"{i + 1:>6} {e.normal_angle_deg:6.1f} {truth:7.4f} {e.mtf_nyquist:7.4f} "
                  f"{e.mtf_nyquist - truth:+8.4f} {e.measured_mtf_nyquist:8.4f} {e.reduced_chi_square:6.3f}  "
                  f"{held or '-'}")
    print(f"worst |error| at Nyquist: {worst:.4f} (target 0.002)\n")


def part_noisy(n: int):
    print(f"2. {n} single chips at SNR 25 (sigma 0.5 px + pixel, 100 x 100, 3-12 deg), --stages optics,detector")
    sensor = im.Sensor(optics_sigma_x_m=0.5, optics_sigma_y_m=0.5, motion_m=0.0, electronics_cutoff_cy_m=0.0)
    renderer = im.Renderer(sensor, 100)
    rng = np.random.default_rng(25)
    fit_err, np_err, covered, held, warned = [], [], 0, 0, 0
    started = time.perf_counter()
    for _ in range(n):
        angle = float(rng.uniform(3, 12) * rng.choice([-1, 1]))
        target = im.Target("edge", angle, 200.0, 1200.0, float(rng.uniform(-.5, .5)))
        chip = renderer(target, noise_std_dn=1000.0 / 25, seed=int(rng.integers(2**31)))
        fit = im.fit_sensor([chip.image], stages="optics,detector")
        e = fit.edges[0]
        truth = float(chip.true_mtf(0.5))
        fit_err.append(e.mtf_nyquist - truth)
        np_err.append(e.measured_mtf_nyquist - truth)
        covered += e.mtf_nyquist_ci[0] <= truth <= e.mtf_nyquist_ci[1]
        held += any(p.key == "detector.width_x_m" and p.status == "held" for p in fit.parameters)
        warned += fit.misfit
    seconds = (time.perf_counter() - started) / n
    for name, err in (("fit", fit_err), ("non-parametric (msg)", np_err)):
        err = np.array(err)
        print(f"  {name:22s} bias {err.mean():+.4f}  RMS {np.sqrt(np.mean(err**2)):.4f}  worst {np.abs(err).max():.4f}")
    print(f"  fit: 95 % interval covers the truth on {covered}/{n}; detector width held on {held}/{n}; "
          f"misfit warning (false alarm) on {warned}/{n}; {seconds:.2f} s per chip (measure + fit)\n")


def part_diffraction(snr: float | None):
    label = "noise-free" if snr is None else f"SNR {snr:g}"
    print(f"{3 if snr is None else 4}. diffraction-limited chips (f-number, 550 nm, 5 um pixels, + pixel aperture), "
          f"{label}, 100 x 100, 7 deg")
    print(f"{'f/':>5} {'true':>7} | {'default stages':>14} {'error':>8} {'warn':>5} | "
          f"{'diffraction,detector':>20} {'error':>8} {'warn':>5} | {'measured':>8}")
    for n in F_NUMBERS:
        sensor = im.Sensor(1.0, [st.Diffraction(n), st.Detector()])
        chip = im.render(sensor, im.Target("edge", 7.0, 200.0, 1200.0, 0.17), 100,
                         noise_std_dn=0.0 if snr is None else 1000.0 / snr, seed=3)
        truth = float(chip.true_mtf(0.5))
        cells = []
        for stages in (None, "diffraction,detector"):
            fit = im.fit_sensor([chip.image], stages=stages)
            e = fit.edges[0]
            warned = fit.misfit
            cells.append((e.mtf_nyquist, e.mtf_nyquist - truth, "yes" if warned else "no"))
        print(f"{n:5.1f} {truth:7.4f} | {cells[0][0]:14.4f} {cells[0][1]:+8.4f} {cells[0][2]:>5} | "
              f"{cells[1][0]:20.4f} {cells[1][1]:+8.4f} {cells[1][2]:>5} | {e.measured_mtf_nyquist:8.4f}")
    print()


def part_misfit_rate(n: int):
    print(f"5. {n} chips per row (100 x 100, 3-12 deg): RMS error at Nyquist, misfit warnings")
    print(f"{'blur':>23} {'stages':>20} {'SNR':>5} {'fit RMS':>8} {'warned':>7} {'RMS unwarned':>12} {'msg RMS':>8}")
    gaussian = im.Sensor(1.0, [st.GaussianOptics(0.5, 0.5), st.Detector()])
    airy = im.Sensor(1.0, [st.Diffraction(8.0), st.Detector()])
    rows = [("Gaussian 0.5 px + pixel", gaussian, None), ("f/8 diffraction + pixel", airy, None),
            ("f/8 diffraction + pixel", airy, "diffraction,detector")]
    rng = np.random.default_rng(5)
    for name, sensor, stages in rows:
        renderer = im.Renderer(sensor, 100)
        for snr in (100.0, 50.0, 25.0):
            fit_err, np_err, warned = [], [], []
            for _ in range(n):
                angle = float(rng.uniform(3, 12) * rng.choice([-1, 1]))
                chip = renderer(im.Target("edge", angle, 200.0, 1200.0, float(rng.uniform(-.5, .5))),
                                noise_std_dn=1000.0 / snr, seed=int(rng.integers(2**31)))
                fit = im.fit_sensor([chip.image], stages=stages)
                truth = float(chip.true_mtf(0.5))
                fit_err.append(fit.edges[0].mtf_nyquist - truth)
                np_err.append(fit.edges[0].measured_mtf_nyquist - truth)
                warned.append(fit.misfit)
            fit_err, warned = np.array(fit_err), np.array(warned)
            quiet = fit_err[~warned]
            rms_quiet = f"{np.sqrt(np.mean(quiet**2)):12.4f}" if quiet.size else f"{'-':>12}"
            print(f"{name:>23} {stages or 'default':>20} {snr:5.0f} {np.sqrt(np.mean(fit_err**2)):8.4f} "
                  f"{warned.sum():>3}/{n:<3} {rms_quiet} {np.sqrt(np.mean(np.square(np_err))):8.4f}")
    print()


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--realisations", type=int, default=20, help="noisy chips in part 2")
    p.add_argument("--parts", default="1,2,3,4,5")
    a = p.parse_args()
    parts = {int(x) for x in a.parts.split(",")}
    if 1 in parts:
        part_generic()
    if 2 in parts:
        part_noisy(a.realisations)
    if 3 in parts:
        part_diffraction(None)
    if 4 in parts:
        part_diffraction(50.0)
    if 5 in parts:
        part_misfit_rate(a.realisations)


if __name__ == "__main__":
    main()

"""Accuracy of the pulse (bar) estimator against exact truth, all methods
side by side (the paper's Table 2).

Chips come from the generic-sensor renderer (exact to 1e-3 DN before
rounding): bars of 0.8-2.2 px on Gaussian+pixel sensors and on the paper's
sensor, 100 x 60 px, the width given.  Prints worst errors of MTF at Nyquist
(absolute, where Nyquist is not masked), MTF50 and the recovered LSF's FWHM
(relative), with and without each method's own correction, then noisy bars.

Then sub-pixel bridges (0.5-1.0 px, Gaussian sigma 0.39 px + pixel, SNR 100
and 300 as contrast over noise): with the width given, the noise-free error
and the noisy bias and interval coverage at Nyquist; without it, per width
and SNR, how many chips were refused, how many numbers lay within 0.02 of
the truth, how many intervals covered it, and how many numbers did neither
(the issue's "confident wrong numbers": none allowed); 1.5 and 2.5 px bars
beside them, whose widths the spectrum's zero may tell.

usage: python bench/pulse_accuracy.py [--realisations N] [--seeds N]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import imgmtf as im
from imgmtf.errors import ImgmtfError
from imgmtf.estimate.pulse import PulseEstimator

BRIDGE_WIDTHS = (0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
CONTROL_WIDTHS = (1.5, 2.5)      # wider bars, printed apart: their zero may stand out of the noise
BRIDGE_SIGMA = 0.39
CONTRAST_DN = 1000.0
NOISE_FREE_CONTRAST_DN = 60000.0


def sensor(sigma=None):
    if sigma is None:
        return im.Sensor()
    return im.Sensor(optics_sigma_x_m=sigma, optics_sigma_y_m=sigma, motion_m=0.0,
                     electronics_cutoff_cy_m=0.0)


def chips():
    rng = np.random.default_rng(5)
    out = []
    for sigma in (0.35, 0.5, 0.7, None):
        renderer = im.Renderer(sensor(sigma), (100, 60))
        for width in (0.8, 1.2, 1.6, 2.2):
            angle = float(rng.uniform(4, 10))
            out.append(renderer(im.Target("pulse", angle, 200.0, 1200.0, float(rng.uniform(-.5, .5)), width)))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--realisations", type=int, default=50)
    p.add_argument("--seeds", type=int, default=6, help="chips per width and SNR of the sub-pixel sweeps")
    a = p.parse_args()
    cases = chips()
    print(f"noise-free: {len(cases)} bars (0.8-2.2 px); worst |error|: MTF@Nyq absolute, "
          "MTF50 and recovered-LSF FWHM relative")
    print(f"{'method':10s} {'corrected':>10s} {'MTF@Nyq':>9s} {'MTF50 %':>8s} {'FWHM %':>8s} {'mean MTF@Nyq err':>17s}")
    for correct in (True, False):
        for method in ("msg", "sliding", "spline", "iso"):
            est = PulseEstimator(method, correct=correct, intervals=im.Intervals("none"), force=True)
            nyq, m50, fw = [], [], []
            for chip in cases:
                r = est(chip.image, width_px=chip.target.width_px)
                nyq.append(r.mtf_nyquist - float(chip.true_mtf(0.5)))
                m50.append(r.mtf50_cy_px / chip.true_mtf50_cy_px() - 1)
                fw.append(r.fwhm_px / chip.true_fwhm_px() - 1)
            nyq, m50, fw = (np.array(x) for x in (nyq, m50, fw))
            print(f"{method:10s} {correct!s:>10s} {np.nanmax(np.abs(nyq)):9.4f} "
                  f"{100 * np.nanmax(np.abs(m50)):8.2f} {100 * np.nanmax(np.abs(fw)):8.2f} "
                  f"{np.nanmean(nyq):+17.4f}")
    print(f"\nnoisy: 1.5 px bar, sigma 0.5 px + pixel, {a.realisations} chips per SNR (pulse definition), "
          "error of MTF at Nyquist")
    renderer = im.Renderer(sensor(0.5), (100, 60))
    rng = np.random.default_rng(9)
    for noise in (2.5, 5.0, 10.0, 20.0):
        errs, snrs = [], []
        for _ in range(a.realisations):
            chip = renderer(im.Target("pulse", float(rng.uniform(4, 10)), 200.0, 1200.0,
                                      float(rng.uniform(-.5, .5)), 1.5),
                            noise_std_dn=noise, seed=int(rng.integers(2**31)))
            r = PulseEstimator("msg", intervals=im.Intervals("none"))(chip.image, width_px=1.5)
            errs.append(r.mtf_nyquist - float(chip.true_mtf(0.5)))
            snrs.append(r.snr)
        e = np.array(errs)
        print(f"noise {noise:5.1f} DN (SNR ~{np.median(snrs):4.0f}): bias {e.mean():+.4f} "
              f"RMS {np.sqrt(np.mean(e ** 2)):.4f}")
    bridges_with_width(a.seeds)
    bridges_without_width(a.seeds)


def bridge(renderer, rng, width, snr):
    """A sub-pixel bar at a random tilt and offset, noise CONTRAST_DN / snr;
    for snr None noise-free, on NOISE_FREE_CONTRAST_DN (the 16-bit
    rounding of a 1000 DN bar moves MTF at Nyquist by 3e-4)."""
    contrast = NOISE_FREE_CONTRAST_DN if snr is None else CONTRAST_DN
    target = im.Target("pulse", float(rng.uniform(4, 10)), 200.0, 200.0 + contrast, float(rng.uniform(-.5, .5)),
                       width)
    if snr is None:
        return renderer(target)
    return renderer(target, noise_std_dn=CONTRAST_DN / snr, seed=int(rng.integers(2**31)))


def bridges_with_width(seeds):
    """The width given: noise-free error, and bias and coverage at SNR 100."""
    renderer = im.Renderer(sensor(BRIDGE_SIGMA), (100, 60))
    rng = np.random.default_rng(34)
    est = PulseEstimator("msg")
    print(f"\nsub-pixel bridges, sigma {BRIDGE_SIGMA} px + pixel, the width given: error of MTF at Nyquist")
    for width in BRIDGE_WIDTHS:
        chip = bridge(renderer, rng, width, None)
        exact = est(chip.image, width_px=width).mtf_nyquist - float(chip.true_mtf(0.5))
        errs, covered = [], 0
        for _ in range(seeds):
            chip = bridge(renderer, rng, width, 100.0)
            r, truth = est(chip.image, width_px=width), float(chip.true_mtf(0.5))
            errs.append(r.mtf_nyquist - truth)
            covered += truth in r.mtf_nyquist_ci
        print(f"{width:.1f} px: noise-free ({NOISE_FREE_CONTRAST_DN:.0f} DN) {exact:+.6f}; "
              f"SNR 100 bias {np.mean(errs):+.4f} RMS {np.sqrt(np.mean(np.square(errs))):.4f}, "
              f"intervals covering {covered}/{seeds}")


def bridges_without_width(seeds):
    """The width read off the profile: per width and SNR, refused chips,
    numbers within 0.02, intervals covering, and numbers that do neither."""
    renderer = im.Renderer(sensor(BRIDGE_SIGMA), (100, 60))
    rng = np.random.default_rng(35)
    est = PulseEstimator("msg")
    print(f"\nsub-pixel bridges, sigma {BRIDGE_SIGMA} px + pixel, no width given: {seeds} chips each")
    print(f"{'SNR':>4s} {'width':>6s} {'refused':>8s} {'within .02':>11s} {'covering':>9s} {'wrong':>6s}  "
          "width read / MTF@Nyq error of those measured")
    totals = np.zeros(4, int)
    for snr in (100.0, 300.0):
        for width in BRIDGE_WIDTHS + CONTROL_WIDTHS:
            if width == CONTROL_WIDTHS[0]:
                print("  (wider bars, whose zero the spectrum may show:)")
            refused = within = covered = wrong = 0
            read = []
            for _ in range(seeds):
                chip = bridge(renderer, rng, width, snr)
                truth = float(chip.true_mtf(0.5))
                try:
                    r = est(chip.image)
                except ImgmtfError:
                    refused += 1
                    continue
                close, covers = abs(r.mtf_nyquist - truth) <= 0.02, truth in r.mtf_nyquist_ci
                within += close
                covered += covers
                wrong += not (close or covers)
                read.append(f"{r.pulse_width_px:.2f}/{r.mtf_nyquist - truth:+.3f}")
            if width in BRIDGE_WIDTHS:
                totals += (refused, within, covered, wrong)
            print(f"{snr:4.0f} {width:6.1f} {refused:8d} {within:11d} {covered:9d} {wrong:6d}  {' '.join(read)}")
    print(f"the {2 * len(BRIDGE_WIDTHS) * seeds} bridges of 0.5-1.0 px: refused {totals[0]}, within 0.02 "
          f"{totals[1]}, covering {totals[2]}, neither {totals[3]}")


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    print(f"\n({time.perf_counter() - t0:.0f} s)")

"""Real L0R blur: the Baotou and PAN checkerboards' half-edges under every
candidate sensor model, against the model-free measurement.

For each real chip in ../shared/data/real-scenes (their README says what
is known of them), the half-edges ``imgmtf scan`` accepts are fitted with
each stage set of ``--fit-stages auto``'s candidates
(:data:`imgmtf.estimate.fit.choice.AUTO_CANDIDATES`), and printed:

* per candidate (fitted as ``--stages NAMES`` fits it), the reduced
  chi-square, the BIC, the largest residual structure (% of the step) and
  whether it misfits, the across- and along-track MTF at Nyquist, and the
  model's MTF at Nyquist along each half-edge's normal, beside the
  model-free measurement's interval;
* which candidate ``auto`` keeps and why, and what it reads (auto holds
  nothing for want of need, so its figures differ a little from the
  same stages named).

With ``--figure FILE`` it draws the first chip's half-edges' LSFs on a log
scale against the kept model and the Gaussian core (the figure of
docs/fit.md's real-blur section).

usage: python bench/real_blur.py [--figure FILE]
"""
from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

import imgmtf as im
from imgmtf.estimate.fit.choice import AUTO_CANDIDATES, candidate_summary

REAL = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "real-scenes"
CHIPS = ("baotou_l0r_checkerboard.tif", "pan_l0r_checkerboard.tif")


def half_edges(path: Path) -> list:
    """The measurements behind the scan's accepted half-edges."""
    records = im.scan_scene(str(path))
    return [r.measurement for r in records if r.ok and r.measurement is not None]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--figure", type=Path, help="write the first chip's LSF figure here (PNG)")
    args = parser.parse_args()
    if not REAL.is_dir():
        raise SystemExit(f"no real scenes in {REAL}")
    warnings.simplefilter("ignore")
    for name in CHIPS:
        edges = half_edges(REAL / name)
        print(f"\n{name}: {len(edges)} half-edges, normals "
              + ", ".join(f"{e.normal_angle_deg:.1f}" for e in edges) + " deg; measured MTF at Nyquist "
              + ", ".join(f"{e.mtf_nyquist:.3f} [{e.mtf_nyquist_ci.low:.3f},{e.mtf_nyquist_ci.high:.3f}]"
                          for e in edges))
        print(f"{'stages':<40} {'chi2/dof':>8} {'BIC':>8} {'struct.':>7} {'misfit':>6} {'across':>7} "
              f"{'along':>7}  model along each normal")
        fits = {}
        for candidate in AUTO_CANDIDATES:
            fit = im.fit_sensor(edges, stages=",".join(candidate))
            fits[candidate] = fit
            summary = candidate_summary(fit)
            worst = max(e.misfit_fraction for e in fit.edges)
            along = " ".join(f"{e.mtf_nyquist:.3f}" for e in fit.edges)
            print(f"{'+'.join(candidate):<40} {fit.reduced_chi_square:8.2f} {summary.bic:8.0f} "
                  f"{100 * worst:6.2f}% {'yes' if fit.misfit else 'no':>6} "
                  f"{fit.directions['across']['mtf_nyquist']:7.4f} {fit.directions['along']['mtf_nyquist']:7.4f}"
                  f"  {along}")
        auto = im.fit_sensor(edges, stages="auto")
        print(f"auto keeps {'+'.join(auto.choice.kept)}: {auto.choice.reason}; fitted as auto fits it (nothing "
              f"held for want of need): across {auto.directions['across']['mtf_nyquist']:.4f} "
              f"{[round(v, 4) for v in auto.directions['across']['mtf_nyquist_ci']]}, along "
              f"{auto.directions['along']['mtf_nyquist']:.4f} "
              f"{[round(v, 4) for v in auto.directions['along']['mtf_nyquist_ci']]}; along each normal "
              + " ".join(f"{e.mtf_nyquist:.3f}" for e in auto.edges))
        if args.figure is not None and name == CHIPS[0]:
            from matplotlib.figure import Figure

            from imgmtf.plot import plot_fit_lsf
            figure = Figure(figsize=(4 * len(edges), 4.8), layout="constrained")
            axes = np.atleast_1d(figure.subplots(1, len(edges)))
            for i, ax in enumerate(axes):
                plot_fit_lsf(auto, i, ax, others={"optics+detector": fits[AUTO_CANDIDATES[0]]})
            figure.suptitle(f"{name}: the half-edges' LSFs (log scale) against the sensor models", fontsize="medium")
            figure.savefig(args.figure, dpi=90)
            print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()

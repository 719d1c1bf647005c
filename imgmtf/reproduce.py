"""Reproduce the paper's experiments with the generic sensor, and go beyond:
the estimator tables (paper Tables 1 and 2), the system-noise sweep (Fig.
12), the ground-noise study (Figs. 13-14), and the lowest SNR at which each
method is trustworthy.

Every chip is rendered from its own seed, derived from the study seed and
the chip's place in the study, so results do not depend on the number of
worker processes.  The chips follow the paper: 40 x 40 px, edges 6 deg from
vertical, the paper's sensor.
"""
from __future__ import annotations

import csv
import functools
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import FileWriteError, ImgmtfError
from .estimate.edge import EdgeEstimator
from .estimate.intervals import NO_INTERVALS
from .estimate.resampling import METHODS
from .estimate.results import MTFResult
from .kinds import get_kind
from .metrics import fwhm
from .parallel import run_tasks
from .sensor.model import Sensor
from .sensor.noise import GroundNoise
from .sensor.rendering import Renderer
from .sensor.targets import Target
from .version import __version__

CHIP_PX = 40
ANGLE_DEG = 6.0
PULSE_WIDTH_PX = 1.5
CRITERION_RELATIVE = 0.05       # an estimate is good within +-5 % of the true MTF at Nyquist
CRITERION_FRACTION = 0.95       # ... and a method is trustworthy when 95 % are
THRESHOLD_SNRS = (10, 15, 20, 25, 30, 40, 50, 60, 70, 80, 90, 100, 125, 150, 200)
GROUND_SNRS = (5, 10, 15, 20, 30, 40, 50, 70, 100, 150, 200)
# the paper's Tables 1 and 2 (% difference from the model), per target kind it studies
PAPER_TABLE = {
    "edge": {"spline": (21.6, -51.9), "sliding": (5.8, -12.6), "msg": (0.5, -1.9)},
    "pulse": {"spline": (-1.23, -50.8), "sliding": (-0.26, -10.9), "msg": (-0.07, -4.1)},
}


@dataclass(frozen=True)
class StudySize:
    """How many chips each part of the study renders."""

    system_stds: tuple            # system-noise sweep, DN
    ground_realisations: int      # per transition height
    threshold_realisations: int   # per SNR level


FULL = StudySize(tuple(range(2, 101)), 20, 100)
QUICK = StudySize(tuple(range(2, 101, 14)), 3, 8)


def _seed(study_seed: int, *place: int) -> int:
    return int(np.random.SeedSequence([study_seed, *place]).generate_state(1)[0])


def _measure_all(image, methods) -> dict:
    """MTF at Nyquist and SNR of one edge chip with every method."""
    out = {}
    for method in methods:
        try:
            r = EdgeEstimator(method, correct=True, intervals=NO_INTERVALS, force=True)(image)
            out[method] = (r.mtf_nyquist, r.snr)
        except ImgmtfError:
            out[method] = (float("nan"), float("nan"))
    return out


@functools.lru_cache(maxsize=1)
def _renderer() -> Renderer:
    """The study's renderer, its PSF set up once per process."""
    return Renderer(Sensor(), CHIP_PX)


def _edge_task(task) -> dict:
    """Render one noisy edge chip and measure it; runs in a worker."""
    kind, index, std, high, ground, seed, methods = task
    chip = _renderer()(Target("edge", ANGLE_DEG, 200.0, high), noise_std_dn=std,
                    ground_noise=GroundNoise() if ground else None, seed=seed)
    return {"kind": kind, "index": index, "std_dn": std, "step_dn": high - 200.0,
            "results": _measure_all(chip.image, methods)}


def measure_chips(tasks, workers: int, progress: bool | None = None) -> list[dict]:
    """Render and measure every task's chip in ``workers`` processes (1: in
    this one; :func:`imgmtf.parallel.run_tasks`), results in task order,
    with a progress bar on stderr (``progress`` None: only on a terminal)."""
    return list(run_tasks(_edge_task, tasks, workers=workers, progress=progress, description="simulating chips"))


def estimator_tables(methods) -> tuple[list[dict], dict]:
    """Model vs every method, corrected and as published, on noise-free edge
    and pulse chips (the paper's Tables 1 and 2).  Returns the table rows
    and, for Figs. 9-10, the estimates themselves with the truth:
    ``curves[kind]`` = {"truth": (x_px, profile, f_cy_px, mtf), "as
    published"/"corrected": {method: result}}."""
    sensor = Sensor()
    renderer = Renderer(sensor, CHIP_PX)
    rows: list[dict] = []
    curves: dict = {}
    for kind in PAPER_TABLE:
        target = get_kind(kind)
        width = PULSE_WIDTH_PX if target.has_width else 0.0
        chip = renderer(Target(kind, ANGLE_DEG, 200.0, 1200.0, 0.0, width))
        true_nyq = float(chip.true_mtf(0.5))
        x, profile = _true_profile(sensor, width)
        true_fwhm = fwhm(x, profile)
        f = np.linspace(0.0, 1.0, 201)
        curves[kind] = {"truth": (x, profile, f, chip.true_mtf(f)), "as published": {}, "corrected": {}}
        rows.append({"target": kind, "method": "model", "corrected": "", "fwhm_m": true_fwhm * chip.gsd_m,
                     "mtf_nyquist": true_nyq, "fwhm_diff_pct": 0.0, "mtf_diff_pct": 0.0,
                     "paper_fwhm_diff_pct": "", "paper_mtf_diff_pct": ""})
        for correct in (False, True):
            for method in methods:
                estimator = target.make_estimator(method, correct=correct, intervals=NO_INTERVALS, force=True)
                r: MTFResult = estimator(chip.image, **target.estimator_keywords(width))
                fw = r.lsf_like()[2]        # the paper's FWHM: an edge's LSF's, a bar's pulse response's
                curves[kind]["corrected" if correct else "as published"][method] = r
                paper = PAPER_TABLE[kind].get(method, ("", "")) if not correct else ("", "")
                rows.append({"target": kind, "method": method, "corrected": "yes" if correct else "no",
                             "fwhm_m": fw * chip.gsd_m, "mtf_nyquist": r.mtf_nyquist,
                             "fwhm_diff_pct": 100 * (fw / true_fwhm - 1),
                             "mtf_diff_pct": 100 * (r.mtf_nyquist / true_nyq - 1),
                             "paper_fwhm_diff_pct": paper[0], "paper_mtf_diff_pct": paper[1]})
    return rows, curves


def thresholds(rows: list[dict], true_nyq: float, methods) -> dict:
    """Lowest nominal SNR from which every level meets the criterion, per
    method, with the fraction of good estimates per level."""
    out = {}
    for method in methods:
        fractions = {}
        for snr in THRESHOLD_SNRS:
            values = np.array([r["results"][method][0] for r in rows if r["snr_nominal"] == snr])
            good = np.abs(values / true_nyq - 1) <= CRITERION_RELATIVE
            fractions[snr] = float(np.mean(good & np.isfinite(values)))
        passing = [s for s in THRESHOLD_SNRS
                   if all(fractions[t] >= CRITERION_FRACTION for t in THRESHOLD_SNRS if t >= s)]
        out[method] = {"threshold": min(passing) if passing else float("nan"), "fractions": fractions}
    return out


def _true_profile(sensor: Sensor, width_px: float) -> tuple[np.ndarray, np.ndarray]:
    """(x_px, profile) along the normal: the exact LSF (1/px, area 1) of an
    edge (``width_px`` 0), or the exact pulse response of a bar
    ``width_px`` wide, peak 1."""
    x, lsf = sensor.normal_lsf(ANGLE_DEG)
    if not width_px:
        return x, lsf
    esf = np.cumsum(lsf) * (x[1] - x[0])
    prf = np.interp(x + width_px / 2, x, esf) - np.interp(x - width_px / 2, x, esf)
    return x, prf / prf.max()


def run_study(out: str | Path, *, quick: bool = False, workers: int = 1, seed: int = 0,
              methods=tuple(METHODS), progress: bool | None = None) -> dict:
    """Run the whole study and write ``out``/report.md with figures and CSV
    (progress bars on stderr: ``progress`` None shows them on a terminal).
    Returns the thresholds, the chips per SNR level and the time taken (s)."""
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileWriteError(f"{out}: cannot create the output folder ({exc.strerror or exc})") from None
    size = QUICK if quick else FULL
    sensor = Sensor()
    true_nyq = float(sensor.normal_transfer(0.5, ANGLE_DEG))
    started = time.perf_counter()
    tables, curves = estimator_tables(methods)
    _write_csv(out / "tables_1_2.csv", tables)

    # all the chips in one run of one pool of workers:
    # Fig. 12: one chip per noise std, 1200 -> 200 DN (falling edge)
    tasks = [("system", i, float(std), 1200.0, False, _seed(seed, 1, i), methods)
             for i, std in enumerate(size.system_stds)]
    # ground noise: 11 transition heights x N realisations
    ground_sd = _ground_noise_output_std(seed)
    heights = [round(snr * ground_sd) for snr in GROUND_SNRS]
    tasks += [("ground", i * 1000 + k, 0.0, 200.0 + h, True, _seed(seed, 2, i, k), methods)
              for i, h in enumerate(heights) for k in range(size.ground_realisations)]
    # threshold: N chips per nominal SNR, 1000 DN step
    tasks += [("threshold", i * 1000 + k, 1000.0 / snr, 1200.0, False, _seed(seed, 3, i, k), methods)
              for i, snr in enumerate(THRESHOLD_SNRS) for k in range(size.threshold_realisations)]
    rows = measure_chips(tasks, workers, progress)
    system, ground, threshold_rows = ([row for row in rows if row["kind"] == kind]
                                      for kind in ("system", "ground", "threshold"))
    for row in threshold_rows:
        row["snr_nominal"] = THRESHOLD_SNRS[row["index"] // 1000]
    found = thresholds(threshold_rows, true_nyq, methods)

    _write_sweep_csv(out / "system_noise.csv", system, methods)
    _write_sweep_csv(out / "ground_noise.csv", ground, methods)
    _write_csv(out / "threshold.csv", [{"snr": s, **{m: found[m]["fractions"][s] for m in methods}}
                                       for s in THRESHOLD_SNRS])
    from . import plot
    figures = {
        "fig02_03_sensor.png": plot.plot_sensor(sensor),
        "fig09_edge_estimates.png": plot.plot_estimates("edge", curves["edge"], methods, paper_figure=9),
        "fig10_pulse_estimates.png": plot.plot_estimates("pulse", curves["pulse"], methods, PULSE_WIDTH_PX,
                                                         paper_figure=10),
        "fig12_system_noise.png": plot.plot_noise_sweep(system, methods, true_nyq, "System noise"),
        "fig13_ground_noise_layers.png": plot.plot_ground_noise_layers(GroundNoise(), seed),
        "fig14_ground_noise.png": plot.plot_noise_sweep(ground, methods, true_nyq, "Ground noise"),
        "threshold.png": plot.plot_threshold(found, CRITERION_RELATIVE, CRITERION_FRACTION,
                                             size.threshold_realisations, thresholds=not quick),
    }
    for name, fig in figures.items():
        fig.savefig(out / name, dpi=100)
    elapsed = time.perf_counter() - started
    (out / "report.md").write_text(_report(tables, found, heights, ground_sd, size, quick, seed,
                                           workers, elapsed, methods, sensor))
    return {"thresholds": {m: found[m]["threshold"] for m in methods}, "seconds": elapsed,
            "chips_per_level": size.threshold_realisations}


def _ground_noise_output_std(seed: int) -> float:
    """Standard deviation (DN) of the ground noise in output chips: the
    2000 DN^2 field blurred by the PSF and sampled (a flat scene, 8 chips)."""
    flat = Target("edge", ANGLE_DEG, 1000.0, 1000.0)
    return float(np.mean([_renderer()(flat, ground_noise=GroundNoise(), seed=_seed(seed, 4, k))
                          .image.astype(float).std() for k in range(8)]))


def _write_csv(path: Path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def _write_sweep_csv(path: Path, rows: list[dict], methods) -> None:
    flat = []
    for r in rows:
        for m in methods:
            nyq, snr = r["results"][m]
            flat.append({"index": r["index"], "std_dn": r["std_dn"], "step_dn": r["step_dn"],
                         "method": m, "snr": snr, "mtf_nyquist": nyq})
    _write_csv(path, flat)


def _report(tables, found, heights, ground_sd, size, quick, seed, workers, elapsed, methods,
            sensor) -> str:
    def cell(v, fmt="{:+.1f}"):
        return fmt.format(v) if isinstance(v, (int, float)) and math.isfinite(v) else str(v)
    lines = [f"# Reproduction of Choi & Helder with imgmtf {__version__}", "",
             f"{'Quick' if quick else 'Full'} run, seed {seed}, {workers} worker(s), "
             f"{elapsed:.0f} s. Chips: {CHIP_PX} x {CHIP_PX} px, 16-bit, the paper's sensor, "
             f"edges {ANGLE_DEG:g} deg from vertical.", "",
             "## Figures 2-3: the sensor", "",
             f"Across track: FWHM {sensor.fwhm_m('across'):.4f} m, MTF at Nyquist "
             f"{sensor.mtf_nyquist('across'):.4f}; along track: FWHM {sensor.fwhm_m('along'):.4f} m, "
             f"MTF at Nyquist {sensor.mtf_nyquist('along'):.4f}.", "",
             "![sensor](fig02_03_sensor.png)", "",
             "## Tables 1 and 2: estimators on noise-free chips", "",
             "FWHM is the LSF's for edges and the PRF's for the pulse "
             f"({PULSE_WIDTH_PX} px bar), as in the paper. 'as published' rows leave each method's own "
             "blur in; 'corrected' rows divide it out (imgmtf's default).", "",
             "| target | method | | FWHM (m) | diff % | paper diff % | MTF@Nyq | diff % | paper diff % |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in tables:
        label = {"": "", "no": "as published", "yes": "corrected"}[r["corrected"]]
        lines.append(f"| {r['target']} | {r['method']} | {label} | {r['fwhm_m']:.4f} | "
                     f"{cell(r['fwhm_diff_pct'], '{:+.2f}')} | {cell(r['paper_fwhm_diff_pct'])} | "
                     f"{r['mtf_nyquist']:.4f} | {cell(r['mtf_diff_pct'], '{:+.2f}')} | "
                     f"{cell(r['paper_mtf_diff_pct'])} |")
    lines += ["", "## Figures 9-10: each method's estimates against the truth", "",
              "The LSF (edge) or pulse response (bar) and the MTF of each method on the same noise-free "
              "chips, as published (top rows) and corrected (bottom rows), with the MTF's error. "
              "The paper's figures show the as-published estimates.", "",
              "![edge estimates](fig09_edge_estimates.png)", "",
              "![pulse estimates](fig10_pulse_estimates.png)", "",
              "## Figure 12: system noise", "",
              f"Edge 1200 -> 200 DN, white noise std {size.system_stds[0]} to {size.system_stds[-1]} DN "
              f"({len(size.system_stds)} chips), every method.", "",
              "![system noise](fig12_system_noise.png)", "",
              "## Figures 13-14: ground noise", "",
              "Twenty layers of 1x1 .. 20x20 sub-pixel grains, 100 DN^2 each, added to the scene "
              f"before the PSF; in the output chips their standard deviation is {ground_sd:.1f} DN. "
              f"Transition heights (Table 3), dark level 200 DN, chosen for SNR "
              f"{', '.join(str(s) for s in GROUND_SNRS)}: {', '.join(str(h) for h in heights)} DN; "
              f"{size.ground_realisations} realisations each.", "",
              "![ground noise layers](fig13_ground_noise_layers.png)", "",
              "![ground noise](fig14_ground_noise.png)", "",
              "## The SNR threshold", "",
              f"Criterion: at least {100 * CRITERION_FRACTION:.0f} % of estimates within "
              f"+-{100 * CRITERION_RELATIVE:.0f} % of the true MTF at Nyquist, at that SNR and every "
              f"higher one; {size.threshold_realisations} chips per nominal SNR (step / noise std), "
              f"{CHIP_PX} rows each.", "",
              "| method | threshold SNR | " + " | ".join(f"SNR {s}" for s in THRESHOLD_SNRS) + " |",
              "|---|---|" + "---|" * len(THRESHOLD_SNRS)]
    for m in methods:
        fr = found[m]["fractions"]
        threshold = found[m]["threshold"]
        reached = f"{threshold:g}" if math.isfinite(threshold) else f"not reached by {max(THRESHOLD_SNRS)}"
        lines.append(f"| {m} | {reached} | "
                     + " | ".join(f"{100 * fr[s]:.0f} %" for s in THRESHOLD_SNRS) + " |")
    n = size.threshold_realisations
    spread = math.sqrt(0.25 / n)
    lines += ["", "![threshold](threshold.png)", "",
              f"Each fraction comes from {n} chips, so it is a binomial estimate whose standard error "
              f"is up to sqrt(0.25 / {n}) = {spread:.2f}; that is why the curves are jagged, and the shaded "
              "bands are their 95 % intervals. "
              + (f"This quick run's {n} chips per level are too few to find a threshold: a level meets "
                 f"the criterion only when {math.ceil(CRITERION_FRACTION * n)} of its {n} chips pass, so "
                 "one unlucky chip moves the threshold. Read it from the full run (100 chips per "
                 "level), which takes one to two minutes on 2 cores."
                 if quick else "A level whose fraction dips below the criterion after an earlier one "
                 "met it is within that noise; more chips per level would smooth the curves."), "",
              "The paper's threshold for its MSG was SNR 100. The noise of an MTF estimate falls "
              "as 1 / (SNR sqrt(rows)), so a threshold found on 40-row chips scales as "
              "sqrt(40 / rows) for longer edges.", ""]
    return "\n".join(lines)

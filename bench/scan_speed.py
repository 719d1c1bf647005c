"""Scan speed and yield on a large textured scene, against OpenCV's LSD.

The scene (built once, cached in ``--cache``, default the system's temp
folder): 4096 x 4096 px, 16-bit, rows along track, no CRS.

* a textured field: level 2000 DN plus 600 tilted rectangular "parcels"
  (20-400 px, levels +-700 DN, each with its own texture of 30-200 DN),
  plus a multi-scale texture of 60 DN (:func:`imgmtf.sensor.scenes.texture`),
  all blurred by a Gaussian of 0.8 px;
* 14 edge targets, each a 160-256 px chip rendered by the generic sensor
  (:func:`imgmtf.render`: exact, truth known) at a tilt of 2-12 deg from
  the column or the row axis, levels 500-1500 DN apart, system noise 4-8 DN,
  pasted on a jittered 4 x 4 grid (two cells left empty);
* everything drawn from ``numpy.random.default_rng(SEED)``, SEED = 20240512,
  so the scene is the same on every machine.

The second scene, a chart like MTF Mapper's own (built once in the
cache): 1400 x 1400 px, 16-bit, four dark squares (8000 DN, 380 px
a side) rotated 4, 7.5, 11 and 14.5 deg on a 40000 DN field, each rendered
exactly by the generic sensor (:func:`imgmtf.sensor.scenes.render_quadrants`
with four equal quadrants), 40 DN of noise: 16 edges.

Timed, in this process, after one warm-up run of each, the best of
``--runs``, every figure of a ratio measured in the same run:

1. LSD: the scene read in the same 1024 px tiles (32 px overlap) as scan
   reads them, scaled to 8 bits with the same levels, and
   ``cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD).detect`` on each;
2. ``imgmtf.scene.measure.scan_scene`` (detection, screening, measurement,
   intervals of the accepted, combination) with 1 worker;
3. the ``imgmtf scan`` command (a new process: its start-up, about 0.5 s
   of imports, and its outputs included), as a user runs it (the targets'
   sensor fits included), with ``--fit-stages none`` (the scan as it
   was when its budgets were set, before it fitted targets: like for
   like), with ``--workers 2``, and with both; the package's modules
   compiled first, as an installed imgmtf has them (``_installed.py``);
4. on the chart, ``imgmtf scan CHART`` against ``mtf_mapper -q -l CHART
   DIR`` (MTF Mapper 0.7.38; ``--mtfmapper PATH`` or the ``MTF_MAPPER``
   environment variable, else ``mtf_mapper`` on the PATH; the comparison
   is skipped, saying so, when it is not found), each a new process;
5. the start-up every such process pays before its first pixel, the
   floor of the chart's ratio: a new Python importing the libraries the
   design names (NumPy, OpenCV, rasterio, SciPy's sparse graphs and
   spatial trees: a scan's without fits), then also SciPy's optimizer
   (the fits' least_squares), then also imgmtf's scan and fit modules.

Printed: the load average (the machine is shared: time when it is low),
the times (wall, and CPU of the process and its children: less hostage to
the machine's other work; a worker pool's processes are the fork server's
children, not counted) and their ratios (budgets: ``imgmtf scan`` within 2 x LSD, aim
1.5 x; within 3 x MTF Mapper, aim 2 x), the number of candidates by
reason, how many of the 14 edges were accepted with their MTF at Nyquist
against the truth, and how many of the chart's 16 edges each tool measured.

With ``--scale``, instead (minutes): the dense chart of
:mod:`charts` (2000 x 2000 px, 484 squares, 1936 edges) scanned with
default options, with ``--fit-stages none`` and with ``--bootstrap 50``,
and a batch of 20 four-square charts (seeds SEED to SEED + 19) in one
``imgmtf scan`` command, each against MTF Mapper run on the same images
(a process per chart), once each in turn; then the sweep of the scene
fit's time against the half-edges fitted (16 to 1936, doubling: budget
time(2n) / time(n) at most 2), and ("targets") the per-target work of one
dense scan: its combined rows, across/along sections and sensor fits.

usage: python bench/scan_speed.py [--cache DIR] [--runs N] [--no-cli] [--mtfmapper PATH] [--scale [PARTS]]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from _installed import compile_package
from charts import DENSE_GRID, DENSE_SIZE, FOUR_ANGLES, FOUR_SIZE, dense_chart, four_square_chart

import imgmtf as im
from imgmtf.sensor.scenes import texture

SEED = 20240512
SIZE = 4096
N_EDGES = 14


def _parcels(image: np.ndarray, rng: np.random.Generator, count: int = 600) -> None:
    """Paint ``count`` tilted rectangles of random size, level and texture."""
    rows, cols = image.shape
    for _ in range(count):
        w, h = rng.uniform(20, 400, 2)
        cx, cy = rng.uniform(0, cols), rng.uniform(0, rows)
        a = rng.uniform(0, math.pi)
        r = math.ceil(math.hypot(w, h) / 2) + 1
        x0, x1 = max(int(cx) - r, 0), min(int(cx) + r, cols)
        y0, y1 = max(int(cy) - r, 0), min(int(cy) + r, rows)
        if x1 <= x0 or y1 <= y0:
            continue
        y, x = np.mgrid[y0:y1, x0:x1].astype(float)
        u = (x - cx) * math.cos(a) + (y - cy) * math.sin(a)
        v = -(x - cx) * math.sin(a) + (y - cy) * math.cos(a)
        inside = (np.abs(u) <= w / 2) & (np.abs(v) <= h / 2)
        level = rng.uniform(-700, 700)
        grain = rng.uniform(30, 200) * rng.standard_normal(inside.sum())
        block = image[y0:y1, x0:x1]
        block[inside] = 2000 + level + grain


def build_scene(path: Path) -> list[dict]:
    """Write the scene to ``path`` (GeoTIFF, no CRS); the truth of its 14
    edges (tile, angle, true MTF at Nyquist and MTF50)."""
    import cv2
    rng = np.random.default_rng(SEED)
    image = np.full((SIZE, SIZE), 2000.0, np.float32)
    _parcels(image, rng)
    image += texture((SIZE, SIZE), 60.0, seed=int(rng.integers(1 << 31))).astype(np.float32)
    image = cv2.GaussianBlur(image, (0, 0), 0.8).astype(float)
    sensor = im.Sensor()
    cell = SIZE // 4
    cells = [(r, c) for r in range(4) for c in range(4)]
    truth = []
    for k in rng.permutation(len(cells))[:N_EDGES]:
        r, c = cells[k]
        size = int(rng.integers(160, 257))
        tilt = float(rng.uniform(2, 12)) * (1 if rng.random() < 0.5 else -1)
        angle = tilt if rng.random() < 0.5 else math.copysign(90.0, tilt) - tilt
        low = float(rng.uniform(800, 1800))
        high = low + float(rng.uniform(500, 1500))
        if rng.random() < 0.5:
            low, high = high, low
        chip = im.render(sensor, im.Target("edge", angle, low, high), size,
                         noise_std_dn=float(rng.uniform(4, 8)), seed=int(rng.integers(1 << 31)))
        x0 = c * cell + int(rng.integers(40, cell - size - 40))
        y0 = r * cell + int(rng.integers(40, cell - size - 40))
        image[y0:y0 + size, x0:x0 + size] = chip.image
        truth.append({"tile_xywh": [x0, y0, size, size], "angle_deg": angle,
                      "true_mtf_nyquist": float(chip.true_mtf(0.5)),
                      "true_mtf50_cy_px": chip.true_mtf50_cy_px()})
    image += rng.normal(0, 5, image.shape)
    im.write_geotiff(path, np.clip(np.rint(image), 0, 65535).astype(np.uint16),
                     provenance={"seed": SEED, "edges": truth, "imgmtf_version": im.__version__})
    return truth


def scene(cache: Path) -> tuple[Path, list[dict]]:
    path = cache / f"scan_speed_{SIZE}_{SEED}.tif"
    if not path.exists():
        t = time.perf_counter()
        build_scene(path)
        print(f"built {path} in {time.perf_counter() - t:.1f} s")
    return path, json.loads(im.read_raster(path, window=(0, 0, 1, 1)).tags["IMGMTF"])["edges"]


def lsd_only(path: Path) -> int:
    """Read the scene in scan's tiles at scan's 8-bit levels and run LSD on
    each; the number of segments."""
    import cv2

    from imgmtf.io import raster_info
    from imgmtf.scene.detect import TILE_OVERLAP_PX, display_levels, to_8bit
    from imgmtf.scene.settings import ScanSettings
    info = raster_info(str(path))
    lo, hi = display_levels(str(path), None, info)
    tile_px = ScanSettings().tile_px
    detector = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD)
    step, found = tile_px - TILE_OVERLAP_PX, 0
    for y in range(0, max(info.height - TILE_OVERLAP_PX, 1), step):
        for x in range(0, max(info.width - TILE_OVERLAP_PX, 1), step):
            w, h = min(tile_px, info.width - x), min(tile_px, info.height - y)
            tile = im.read_raster(str(path), window=(x, y, w, h)).data
            lines = detector.detect(to_8bit(tile, lo, hi))[0]
            found += 0 if lines is None else len(lines)
    return found


def mtf_mapper(given: str | None) -> str | None:
    """MTF Mapper's executable: ``given``, else $MTF_MAPPER, else on the PATH; None if none runs."""
    candidate = given or os.environ.get("MTF_MAPPER") or shutil.which("mtf_mapper")
    return candidate if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK) else None


@dataclass
class Timing:
    """A job's best wall time and best CPU time (s, its processes' and
    threads' together) over the rounds, and its last output."""

    wall_s: float = math.inf
    cpu_s: float = math.inf
    out: object = None

    def ratio(self, other: Timing) -> str:
        """This job against ``other``: wall time, then CPU time (less
        hostage to the machine's other work)."""
        return f"{self.wall_s / other.wall_s:5.2f} x (CPU {self.cpu_s / other.cpu_s:5.2f} x)"


def cpu_seconds() -> float:
    """CPU time of this process and of its children waited for (s)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def timed_together(jobs: dict, runs: int, warm: set[str]) -> dict[str, Timing]:
    """Each job's best times over ``runs`` rounds, every round running
    every job in turn, so that the figures of a ratio share the machine's
    load; the jobs in ``warm`` are run once before."""
    for name in warm:
        jobs[name]()
    best = {name: Timing() for name in jobs}
    for _ in range(runs):
        for name, fn in jobs.items():
            wall, cpu = time.perf_counter(), cpu_seconds()
            out = fn()
            wall, cpu = time.perf_counter() - wall, cpu_seconds() - cpu
            best[name] = Timing(min(best[name].wall_s, wall), min(best[name].cpu_s, cpu), out)
    return best


def command(*args: str) -> list[str]:
    """The imgmtf command line with ``args``, run by this Python (its venv's imgmtf)."""
    return [sys.executable, "-m", "imgmtf.cli", *args]


def run_quietly(args: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run(args, capture_output=True, text=True, check=False)


def accepted_edges(run: subprocess.CompletedProcess) -> int:
    """Accepted half-edges in ``imgmtf scan --format json``'s rows."""
    rows = [json.loads(line) for line in run.stdout.splitlines() if line.startswith("{")]
    return sum(r.get("scope") == "edge" and r.get("status") == "accepted" for r in rows)


#: what a scan's process must import before its first pixel: the libraries the design names (and,
#: second, imgmtf's own scan and fit modules): a floor no work done in Python can go below
GRAPH_LIBRARIES = "import numpy, cv2, rasterio, scipy.sparse.csgraph, scipy.spatial"
LIBRARIES = GRAPH_LIBRARIES + ", scipy.optimize"
MODULES = LIBRARIES + "; import imgmtf.cli.main, imgmtf.scene.series, imgmtf.scene.measure, imgmtf.estimate.fit"


def mtf_mapper_edges(out: str) -> int:
    path = Path(out) / "edge_sfr_values.txt"
    return len(path.read_text().splitlines()) if path.exists() else 0


#: half-edges of the fit sweep, doubling; then every half-edge of the dense chart
SWEEP_EDGES = (16, 32, 64, 128, 256, 512, 1024)
#: four-square charts in the batch
BATCH = 20


def fit_sweep(dense: Path, runs: int) -> None:
    """The scene fit's time (``fit_edges``, stages "auto", from the scan's
    own measurements, as ``imgmtf scan`` fits them) against the half-edges
    fitted, the first n of the dense chart's, n doubling from 16 to all of
    them; the ratio time(2n) / time(n) (per doubling for the last step)."""
    from imgmtf.estimate.fit import fit_edges
    from imgmtf.scene.measure import scan_scene
    from imgmtf.scene.targetfit import _from_scan
    halves = [_from_scan(r) for r in scan_scene(str(dense)) if r.ok and r.site.get("target_id") is not None]
    fit_edges(halves[:16], stages="auto")                   # warm-up: SciPy's optimizer loaded
    print(f"fit time against half-edges (stages auto, the dense chart's {len(halves)} half-edges):")
    before = None
    for n in [n for n in SWEEP_EDGES if n < len(halves)] + [len(halves)]:
        best = Timing()
        for _ in range(runs if n <= 256 else 1):
            wall, cpu = time.perf_counter(), time.process_time()
            fit = fit_edges(halves[:n], stages="auto")
            best = Timing(min(best.wall_s, time.perf_counter() - wall), min(best.cpu_s, time.process_time() - cpu))
        ratio = ""
        if before is not None:
            doublings = math.log2(n / before[0])
            ratio = (f"   time(2n)/time(n) {(best.wall_s / before[1].wall_s) ** (1 / doublings):4.2f} "
                     f"(CPU {(best.cpu_s / before[1].cpu_s) ** (1 / doublings):4.2f})   (budget 2)")
        print(f"  {n:5d} half-edges: {best.wall_s:7.2f} s (CPU {best.cpu_s:7.2f} s), "
              f"{'+'.join(fit.choice.kept)}{ratio}", flush=True)
        before = (n, best)


def per_target(dense: Path) -> None:
    """The per-target work of the dense chart's scan, in this process on
    one scan's records: the combined rows (``summarise_scan``), the
    across/along sections of 484 targets (``section_rows``) and the sensor
    fits of every target and of the scene (``fit_targets``, stages auto),
    each with its share of the three."""
    from imgmtf.scene.combine import summarise_scan
    from imgmtf.scene.measure import scan_scene
    from imgmtf.scene.sections import section_rows
    from imgmtf.scene.targetfit import fit_targets
    records = scan_scene(str(dense))
    fit_targets([r for r in records if r.site.get("target_id") == 1])     # warm-up: SciPy's optimizer loaded

    def timed(step):
        wall, cpu = time.perf_counter(), time.process_time()
        out = step()
        return out, Timing(time.perf_counter() - wall, time.process_time() - cpu)
    summaries, combined = timed(lambda: summarise_scan(records))
    times = {"summarise_scan (combined rows)": combined,
             "section_rows (across/along sections)": timed(lambda: section_rows(summaries))[1],
             "fit_targets (targets' and scene's fits)": timed(lambda: fit_targets(records))[1]}
    total = sum(t.wall_s for t in times.values())
    print(f"per-target work of the dense chart's scan (in process, {len(records)} candidates):")
    for label, t in times.items():
        print(f"  {label + ':':52s} {t.wall_s:6.2f} s (CPU {t.cpu_s:6.2f} s)   {100 * t.wall_s / total:4.1f} %")


SCALE_PARTS = ("dense", "bootstrap", "batch", "sweep", "targets")


def scale(cache: Path, runs: int, peer: str | None, parts: set[str]) -> None:
    """Of ``parts``: the dense chart (default options and no fits;
    "bootstrap": with --bootstrap 50) and a batch of 20 four-square charts
    in one command, each against MTF Mapper run on the same images (once
    per chart), timed in the same run; then the fit sweep."""
    dense = dense_chart(cache) if parts & {"dense", "bootstrap", "sweep", "targets"} else None
    batch = [four_square_chart(cache, SEED + k) for k in range(BATCH)] if "batch" in parts else []
    with tempfile.TemporaryDirectory() as work:
        def peer_on(paths: list[Path]) -> int:
            edges = 0
            for k, p in enumerate(paths):
                out = Path(work) / f"mtf_mapper_{k}"
                out.mkdir(exist_ok=True)
                run_quietly([peer, "-q", "-l", str(p), str(out)])
                edges += mtf_mapper_edges(str(out))
            return edges
        jobs = {"dense": lambda: run_quietly(command("scan", str(dense), "--format", "json")),
                "dense_nofit": lambda: run_quietly(command("scan", str(dense), "--format", "json",
                                                           "--fit-stages", "none")),
                "dense_bootstrap": lambda: run_quietly(command("scan", str(dense), "--format", "json",
                                                               "--bootstrap", "50")),
                "batch": lambda: run_quietly(command("scan", *map(str, batch), "--format", "json"))}
        if peer:
            jobs.update(dense_peer=lambda: peer_on([dense]), batch_peer=lambda: peer_on(batch))
        wanted = {"dense": {"dense"}, "dense_nofit": {"dense"}, "dense_peer": {"dense", "bootstrap"},
                  "dense_bootstrap": {"bootstrap"}, "batch": {"batch"}, "batch_peer": {"batch"}}
        times = timed_together({k: v for k, v in jobs.items() if wanted[k] & parts}, 1, warm=set())
    peer_dense, peer_batch = times.get("dense_peer"), times.get("batch_peer")
    if parts & {"dense", "bootstrap"}:
        print(f"dense chart {DENSE_SIZE} x {DENSE_SIZE}, {DENSE_GRID ** 2} squares, {4 * DENSE_GRID ** 2} edges:")
    if parts & {"dense", "bootstrap"} and peer_dense is None:
        print("  MTF Mapper not found (--mtfmapper PATH or MTF_MAPPER=PATH): no comparison")
    elif peer_dense is not None:
        print(f"  {'mtf_mapper -q -l DENSE DIR:':52s} {peer_dense.wall_s:6.2f} s (CPU {peer_dense.cpu_s:6.2f} s)"
              f"   {peer_dense.out} edges measured")
    for name, label, budget in (("dense", "imgmtf scan DENSE (fits)", "   (budget 2 x, aim 1 x)"),
                                ("dense_nofit", "imgmtf scan DENSE --fit-stages none", ""),
                                ("dense_bootstrap", "imgmtf scan DENSE --bootstrap 50", "   (budget 60 s)")):
        if name not in times:
            continue
        t = times[name]
        against = f"   {t.ratio(peer_dense)} MTF Mapper" if peer_dense else ""
        print(f"  {label + ':':52s} {t.wall_s:6.2f} s (CPU {t.cpu_s:6.2f} s){against}{budget}"
              f", {accepted_edges(t.out)} edges accepted")
    if "batch" in parts:
        t = times["batch"]
        print(f"batch of {BATCH} four-square charts ({4 * len(FOUR_ANGLES) * BATCH} edges):")
        if peer_batch is not None:
            print(f"  {'mtf_mapper on each:':52s} {peer_batch.wall_s:6.2f} s (CPU {peer_batch.cpu_s:6.2f} s)"
                  f"   {peer_batch.out} edges measured")
        against = f"   {t.ratio(peer_batch)} MTF Mapper" if peer_batch else ""
        print(f"  {'imgmtf scan CHART1 ... CHART20 (fits):':52s} {t.wall_s:6.2f} s (CPU {t.cpu_s:6.2f} s)"
              f"{against}   (budget 2 x), {accepted_edges(t.out)} edges accepted")
    if dense is not None and "sweep" in parts:
        fit_sweep(dense, runs)
    if dense is not None and "targets" in parts:
        per_target(dense)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()))
    parser.add_argument("--runs", type=int, default=3, help="timed rounds; each figure's best is kept")
    parser.add_argument("--no-cli", action="store_true", help="skip the imgmtf scan command (and the chart)")
    parser.add_argument("--mtfmapper", metavar="PATH",
                        help="MTF Mapper's mtf_mapper (default: $MTF_MAPPER, else on the PATH)")
    parser.add_argument("--scale", nargs="?", const=",".join(SCALE_PARTS), metavar="PARTS",
                        help="only the dense chart, its --bootstrap 50 run, the batch of 20 charts and the fit "
                             f"sweep (minutes; or some of {','.join(SCALE_PARTS)}, comma-separated)")
    args = parser.parse_args()
    compile_package()       # the start-up of an installed imgmtf (see _installed.py)
    if args.scale:
        print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())} ({os.cpu_count()} cores)")
        parts = {p.strip() for p in args.scale.split(",") if p.strip()}
        if parts - set(SCALE_PARTS):
            parser.error(f"--scale: unknown part {sorted(parts - set(SCALE_PARTS))[0]!r}; "
                         f"known: {', '.join(SCALE_PARTS)}")
        scale(args.cache, args.runs, mtf_mapper(args.mtfmapper), parts)
        print(f"load average after:  {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
        return
    from imgmtf.scene.measure import scan_scene
    path, truth = scene(args.cache)
    peer = None if args.no_cli else mtf_mapper(args.mtfmapper)
    chart_path = None if args.no_cli else four_square_chart(args.cache)
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())} ({os.cpu_count()} cores)")
    with tempfile.TemporaryDirectory() as work:
        jobs = {"lsd": lambda: lsd_only(path), "scan_scene": lambda: scan_scene(str(path))}
        if not args.no_cli:
            jobs.update({
                "cli": lambda: run_quietly(command("scan", str(path))),
                "cli_nofit": lambda: run_quietly(command("scan", str(path), "--fit-stages", "none")),
                "cli_workers": lambda: run_quietly(command("scan", str(path), "--workers", "2")),
                "cli_workers_nofit": lambda: run_quietly(command("scan", str(path), "--workers", "2",
                                                                 "--fit-stages", "none")),
                "cli_out": lambda: run_quietly(command("scan", str(path), "--out", work)),
                "chart": lambda: run_quietly(command("scan", str(chart_path), "--format", "json")),
                "chart_nofit": lambda: run_quietly(command("scan", str(chart_path), "--format", "json",
                                                           "--fit-stages", "none")),
            })
            jobs["graph_libraries"] = lambda: run_quietly([sys.executable, "-c", GRAPH_LIBRARIES])
            jobs["libraries"] = lambda: run_quietly([sys.executable, "-c", LIBRARIES])
            jobs["modules"] = lambda: run_quietly([sys.executable, "-c", MODULES])
            if peer:
                jobs["mtf_mapper"] = lambda: (run_quietly([peer, "-q", "-l", str(chart_path), work]),
                                              mtf_mapper_edges(work))
        times = timed_together(jobs, args.runs, warm={"lsd", "scan_scene"})
    lsd, scan = times["lsd"], times["scan_scene"]
    segments, records = lsd.out, scan.out

    def line(label: str, timing: Timing, against: Timing | None = None, what: str = "", more: str = "") -> None:
        ratio = f"{timing.ratio(against)} {what}" if against is not None else ""
        print(f"{label + ':':54s} {timing.wall_s:6.2f} s (CPU {timing.cpu_s:6.2f} s)   {ratio}{more}".rstrip())
    line(f"LSD (read + 8 bits + detect, {segments} segments)", lsd)
    line(f"scan_scene, 1 worker ({len(records)} candidates)", scan, lsd, "LSD")
    if not args.no_cli:
        for name, label in (("cli", "imgmtf scan SCENE (new process, fits, text table)"),
                            ("cli_nofit", "imgmtf scan SCENE --fit-stages none"),
                            ("cli_workers", "imgmtf scan SCENE --workers 2 (CPU: not its workers')"),
                            ("cli_workers_nofit", "imgmtf scan SCENE --workers 2 --fit-stages none"),
                            ("cli_out", "imgmtf scan SCENE --out DIR (CSV, GeoJSON, PNG)")):
            line(label, times[name], lsd, "LSD", "   (budget 2 x, aim 1.5 x)" if name == "cli" else "")
        print(f"chart {FOUR_SIZE} x {FOUR_SIZE}, {len(FOUR_ANGLES)} dark squares, {4 * len(FOUR_ANGLES)} edges:")
        peer_timing = times.get("mtf_mapper")
        if peer_timing is not None:
            line("  mtf_mapper -q -l CHART DIR", peer_timing, more=f"{peer_timing.out[1]} edges measured")
        else:
            print("  MTF Mapper not found (--mtfmapper PATH or MTF_MAPPER=PATH): no comparison")
        for name, label in (("graph_libraries", "Python importing NumPy, OpenCV, rasterio, SciPy graphs"),
                            ("libraries", "... and SciPy's optimizer (the fits')"),
                            ("modules", "... and imgmtf's scan and fit modules")):
            line("  " + label, times[name], peer_timing, "MTF Mapper" if peer_timing else "",
                 "   (start-up: the floor)")
        for name, label in (("chart", "imgmtf scan CHART (fits)"),
                            ("chart_nofit", "imgmtf scan CHART --fit-stages none")):
            timing = times[name]
            edges = f"{accepted_edges(timing.out)} edges accepted"
            if peer_timing is None:
                line("  " + label, timing, more=edges)
            else:
                line("  " + label, timing, peer_timing, "MTF Mapper",
                     f", {edges}" + ("   (budget 3 x, aim 2 x)" if name == "chart" else ""))
    print(f"load average after:  {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    reasons = Counter(r.reason or r.status for r in records)
    print("candidates: " + ", ".join(f"{k} {v}" for k, v in reasons.most_common()))
    found = 0
    for t in truth:
        x, y, w, h = t["tile_xywh"]
        inside = [r for r in records if r.ok and x <= (r.site["x0_px"] + r.site["x1_px"]) / 2 < x + w
                  and y <= (r.site["y0_px"] + r.site["y1_px"]) / 2 < y + h]
        best = min(inside, key=lambda r: r.site["rank"]) if inside else None
        found += best is not None
        got = f"{best.figures['mtf_nyquist']:.4f} (error {best.figures['mtf_nyquist'] - t['true_mtf_nyquist']:+.4f})" \
            if best else "not accepted"
        print(f"  edge at {t['angle_deg']:6.2f} deg in {x},{y},{w},{h}: true {t['true_mtf_nyquist']:.4f}, got {got}")
    print(f"{found} of {len(truth)} edges accepted (target >= 10); "
          f"{sum(r.ok for r in records)} accepted in all")


if __name__ == "__main__":
    main()

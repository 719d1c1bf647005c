"""Speed: rendering and measuring, median of repeated runs on this machine.

1. render a 50 x 50 px edge chip of the paper's sensor at 20x (a 1000 x 1000
   sub-pixel scene plus the PSF's margin) to 16 bits;
2. measure_edge on a 100 x 100 chip (SNR 100), each method;
3. the CLI on 100 chips in one call (JSON Lines), with 1 and 2 workers, and
   the speed-up of 2 workers (target >= 1.6 x on 2 cores);
4. start-up: ``imgmtf --help`` against ``python -c "import numpy"`` (target:
   within 3 x).

The machine's load average is printed first: timings on a loaded machine
are not the code's.

usage: python bench/speed.py [--runs N] [--only cli|startup]
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import imgmtf as im
from imgmtf.estimate.edge import EdgeEstimator
from imgmtf.io import write_geotiff


def median_time(fn, runs):
    fn()
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def startup(runs: int) -> None:
    """Median wall time of ``imgmtf --help`` and of importing NumPy."""
    imgmtf = shutil.which("imgmtf") or "imgmtf"

    def timed(cmd):
        return median_time(lambda: subprocess.run(cmd, capture_output=True, check=True), runs)
    numpy_s = timed([sys.executable, "-c", "import numpy"])
    help_s = timed([imgmtf, "--help"])
    print(f"start-up: python -c 'import numpy' {1000 * numpy_s:6.0f} ms, imgmtf --help "
          f"{1000 * help_s:6.0f} ms ({help_s / numpy_s:.2f} x; target <= 3 x)")


def cli_workers(paths, options=()) -> None:
    """1 and 2 workers on the same chips; each run pays its start-up (the
    libraries' imports, about 0.5-1 s per process) once, so the speed-up is
    the compute's only when the compute dominates."""
    times = {}
    label = " ".join(options) or "defaults"
    for workers in (1, 2):
        t = time.perf_counter()
        run = subprocess.run([sys.executable, "-m", "imgmtf.cli", "measure", "--format", "json", *options,
                              "--workers", str(workers), *paths], capture_output=True, text=True)
        times[workers] = time.perf_counter() - t
        ok = sum(1 for line in run.stdout.splitlines() if '"status": "ok"' in line)
        print(f"CLI: imgmtf measure ({label}), {len(paths)} chips, {workers} worker(s): "
              f"{times[workers]:7.2f} s ({ok} measured)")
    print(f"CLI: ({label}) --workers 2 speed-up {times[1] / times[2]:.2f} x (target >= 1.6 x)")


def chips(folder, n=100) -> list[str]:
    r = im.Renderer(im.Sensor(), 100)
    paths = []
    for i in range(n):
        c = r(im.Target("edge", 4.0 + 0.07 * i, 200.0, 1200.0), noise_std_dn=5.0, seed=i)
        path = Path(folder) / f"chip{i:03d}.tif"
        write_geotiff(path, c.image, gsd_m=c.gsd_m)
        paths.append(str(path))
    return paths


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=50)
    p.add_argument("--only", choices=["cli", "startup"])
    a = p.parse_args()
    print(f"load average (1, 5, 15 min): {', '.join(f'{v:.2f}' for v in os.getloadavg())} "
          f"on {os.cpu_count()} cores")
    if a.only == "startup":
        return startup(max(a.runs // 5, 5))
    if a.only == "cli":
        with tempfile.TemporaryDirectory() as tmp:
            paths = chips(tmp)
            cli_workers(paths)
            return cli_workers(paths, ("--bootstrap", "200"))
    startup(max(a.runs // 5, 5))
    renderer = im.Renderer(im.Sensor(), 50)
    target = im.Target("edge", 6.0, 200.0, 1200.0)
    t = median_time(lambda: renderer(target), a.runs)
    print(f"render 50 x 50 px edge chip at 20x (Renderer reused): {1000 * t:7.1f} ms")
    t = median_time(lambda: im.render(im.Sensor(), target, 50), max(a.runs // 5, 3))
    print(f"render incl. PSF set-up (im.render):                 {1000 * t:7.1f} ms")
    chip = im.Renderer(im.Sensor(), 100)(target, noise_std_dn=10.0, seed=1).image
    for method in ("msg", "sliding", "spline", "iso"):
        est, bare = EdgeEstimator(method), EdgeEstimator(method, bootstrap=im.Bootstrap(0))
        t = median_time(lambda est=est: est(chip), a.runs if method != "spline" else 5)
        t0 = median_time(lambda bare=bare: bare(chip), a.runs)
        print(f"measure_edge 100 x 100 chip, method {method:8s}:        {1000 * t:7.1f} ms "
              f"({1000 * t0:.1f} ms without intervals)")
    with tempfile.TemporaryDirectory() as tmp:
        paths = chips(tmp)
        cli_workers(paths)
        cli_workers(paths, ("--bootstrap", "200"))
        # a 4096 x 2048 px scene: data/scene.tif repeated 8 x 8 times
        scene = np.tile(im.read_raster(Path(__file__).parent.parent / "data" / "scene.tif").data, (8, 8))
        big = Path(tmp) / "big_scene.tif"
        write_geotiff(big, scene.astype(np.uint16), gsd_m=1.0)
        for workers in (1, 2):
            t = time.perf_counter()
            run = subprocess.run([sys.executable, "-m", "imgmtf.cli", "scan", "--format", "json",
                                  "--workers", str(workers), str(big)], capture_output=True, text=True)
            elapsed = time.perf_counter() - t
            lines = run.stdout.splitlines()
            ok = sum(1 for line in lines if '"status": "accepted"' in line)
            print(f"CLI: imgmtf scan, 4096 x 2048 px scene, {workers} worker(s): {elapsed:6.2f} s "
                  f"({len(lines)} candidates, {ok} accepted)")


if __name__ == "__main__":
    main()

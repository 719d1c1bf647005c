"""Speed: rendering and measuring, median of repeated runs on this machine.

1. render a 50 x 50 px edge chip of the paper's sensor at 20x (a 1000 x 1000
   sub-pixel scene plus the PSF's margin) to 16 bits;
2. measure_edge on a 100 x 100 chip (SNR 100), each method;
3. the CLI on 100 chips in one call (one process, JSON Lines).

usage: python bench/speed.py [--runs N]
"""
from __future__ import annotations

import argparse
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


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=50)
    a = p.parse_args()
    renderer = im.Renderer(im.Sensor(), 50)
    target = im.Target("edge", 6.0, 200.0, 1200.0)
    t = median_time(lambda: renderer(target), a.runs)
    print(f"render 50 x 50 px edge chip at 20x (Renderer reused): {1000 * t:7.1f} ms")
    t = median_time(lambda: im.render(im.Sensor(), target, 50), max(a.runs // 5, 3))
    print(f"render incl. PSF set-up (im.render):                 {1000 * t:7.1f} ms")
    chip = im.Renderer(im.Sensor(), 100)(target, noise_std_dn=10.0, seed=1).image
    for method in ("msg", "sliding", "spline", "iso"):
        est, bare = EdgeEstimator(method), EdgeEstimator(method, bootstrap=im.Bootstrap(0))
        t = median_time(lambda: est(chip), a.runs if method != "spline" else 5)
        t0 = median_time(lambda: bare(chip), a.runs)
        print(f"measure_edge 100 x 100 chip, method {method:8s}:        {1000 * t:7.1f} ms "
              f"({1000 * t0:.1f} ms without intervals)")
    with tempfile.TemporaryDirectory() as tmp:
        r = im.Renderer(im.Sensor(), 100)
        paths = []
        for i in range(100):
            c = r(im.Target("edge", 4.0 + 0.07 * i, 200.0, 1200.0), noise_std_dn=5.0, seed=i)
            path = Path(tmp) / f"chip{i:03d}.tif"
            write_geotiff(path, c.image, gsd_m=c.gsd_m)
            paths.append(str(path))
        for workers in (1, 2):
            t = time.perf_counter()
            run = subprocess.run([sys.executable, "-m", "imgmtf.cli", "measure", "--format", "json",
                                  "--workers", str(workers), *paths], capture_output=True, text=True)
            elapsed = time.perf_counter() - t
            ok = sum(1 for line in run.stdout.splitlines() if '"status": "ok"' in line)
            print(f"CLI: imgmtf measure, 100 chips, {workers} worker(s):      {elapsed:7.2f} s ({ok} measured)")
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

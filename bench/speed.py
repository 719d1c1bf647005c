"""Speed: rendering and measuring, median of repeated runs on this machine.

1. render a 50 x 50 px edge chip of the paper's sensor at 20x (a 1000 x 1000
   sub-pixel scene plus the PSF's margin) to 16 bits;
2. measure_edge on a 100 x 100 chip (SNR 100), each method;
3. a noise-free 8-bit 100 x 100 edge (its staircase rebuilt) against a noisy
   16-bit one, in this process, chips interleaved (target <= 1.5 x);
4. the CLI's marginal time per chip: ``imgmtf measure`` on 10 and on 50 chips
   of a mixed set (8/16-bit, noise-free/noisy, 100 x 100), the difference
   per extra chip (target <= 10 ms);
5. fit_sensor of two 100 x 100 edges (across and along track), in this
   process after a first call (target < 0.3 s), and the first call in a
   fresh process, imports included;
6. the CLI on 100 chips in one call (JSON Lines), with 1 and 2 workers, and
   the speed-up of 2 workers (target >= 1.6 x on 2 cores);
7. start-up: ``imgmtf --help`` against ``python -c "import numpy"`` (target:
   within 3 x).

The machine's load average is printed first, and again at the end: timings
on a loaded machine are not the code's (the ratios suffer least).

usage: python bench/speed.py [--runs N] [--only chips|cli|fit|startup]
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _installed import compile_package

import imgmtf as im
from imgmtf.estimate.edge import EdgeEstimator
from imgmtf.io import write_geotiff
from imgmtf.sensor.stages import Detector, GaussianOptics


def median_time(fn, runs, clock=time.perf_counter):
    fn()
    times = []
    for _ in range(runs):
        t = clock()
        fn()
        times.append(clock() - t)
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


def depth_ratio(runs: int) -> None:
    """Median time per chip of noise-free 8-bit edges (30 -> 210 DN, the
    staircase rebuilt) and of noisy 16-bit ones (SNR 100), same sensor,
    angles and offsets, measured alternately."""
    sensor = im.Sensor(1.0, [GaussianOptics(sigma_x_m=0.5, sigma_y_m=0.5), Detector(width_x_m=1.0, width_y_m=1.0)])
    rng = np.random.default_rng(0)
    eight, sixteen = [], []
    for k in range(8):
        target = dict(angle_deg=float(rng.uniform(3.0, 12.0)), offset_px=float(rng.uniform(-0.5, 0.5)))
        eight.append(im.render(sensor, im.Target("edge", low_dn=30.0, high_dn=210.0, **target), 100, bits=8).image)
        sixteen.append(im.render(sensor, im.Target("edge", low_dn=200.0, high_dn=1200.0, **target), 100,
                                 noise_std_dn=10.0, seed=k).image)
    rebuilt = sum(im.measure_edge(c).params["dequantised"] for c in eight)
    times: dict[str, list[float]] = {"8": [], "16": []}
    for _ in range(max(runs // 8, 3)):
        for a, b in zip(eight, sixteen):
            for key, chip in (("8", a), ("16", b)):
                t = time.perf_counter()
                im.measure_edge(chip)
                times[key].append(time.perf_counter() - t)
    t8, t16 = (float(np.median(times[k])) for k in ("8", "16"))
    print(f"measure_edge 100 x 100: noise-free 8-bit {1000 * t8:6.1f} ms ({rebuilt}/8 staircases rebuilt), "
          f"noisy 16-bit {1000 * t16:6.1f} ms: {t8 / t16:.2f} x (target <= 1.5 x)")


def mixed_chips(folder, n: int) -> list[str]:
    """``n`` 100 x 100 edge chips cycling through 8/16-bit and noise-free/
    noisy (SNR 100), angles 3-12 deg."""
    renderers = {bits: im.Renderer(im.Sensor(), 100, bits=bits) for bits in (8, 16)}
    levels = {8: (30.0, 210.0), 16: (200.0, 1200.0)}
    paths = []
    for i in range(n):
        bits, noisy = (8, 16)[i % 2], (i // 2) % 2 == 1
        low, high = levels[bits]
        c = renderers[bits](im.Target("edge", 3.0 + 9.0 * ((i * 0.618) % 1.0), low, high),
                            noise_std_dn=(high - low) / 100 if noisy else 0.0, seed=i)
        path = Path(folder) / f"mixed{i:03d}.tif"
        write_geotiff(path, c.image, gsd_m=c.gsd_m)
        paths.append(str(path))
    return paths


def cli_marginal(folder, runs: int) -> None:
    """``imgmtf measure --workers 1`` on the first 10 and on all 50 mixed
    chips, alternating, median of at least five pairs: what each chip beyond
    the start-up costs in one process (``auto`` would start a pool for the 50
    and not for the 10, and charge its start to the chips)."""
    paths = mixed_chips(folder, 50)

    def run(subset):
        t, cpu = time.perf_counter(), _children_cpu_s()
        out = subprocess.run([sys.executable, "-m", "imgmtf.cli", "measure", "--workers", "1", "--format", "json",
                              *subset],
                             capture_output=True, text=True)
        return (time.perf_counter() - t, _children_cpu_s() - cpu,
                sum(1 for line in out.stdout.splitlines() if '"status": "ok"' in line))
    few, many = [], []
    for _ in range(max(runs // 10, 5)):
        few.append(run(paths[:10]))
        many.append(run(paths))
    t_few, t_many = (float(np.median([r[0] for r in runs_])) for runs_ in (few, many))
    cpu_few, cpu_many = (float(np.median([r[1] for r in runs_])) for runs_ in (few, many))
    print(f"CLI: imgmtf measure, mixed 8/16-bit noise-free/noisy chips: 10 chips {t_few:5.2f} s "
          f"({few[0][2]} measured), 50 chips {t_many:5.2f} s ({many[0][2]} measured): "
          f"{1000 * (t_many - t_few) / 40:5.1f} ms per extra chip (target <= 10 ms); CPU "
          f"{1000 * (cpu_many - cpu_few) / 40:5.1f} ms per extra chip, {cpu_few:4.2f} s for 10 (less hostage to "
          "the machine's load)")


def _children_cpu_s() -> float:
    """CPU time of the children this process has waited for (s)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def fit_time(runs: int) -> None:
    """fit_sensor of an across- and an along-track 100 x 100 edge (SNR 250):
    in this process after a first call, and a first call in a fresh
    process (the imports it needs included)."""
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for k, angle in enumerate((6.0, 84.0)):
            c = im.render(im.Sensor(), im.Target("edge", angle, 200.0, 1200.0), 100, noise_std_dn=4.0, seed=k)
            paths.append(Path(tmp) / f"edge{k}.tif")
            write_geotiff(paths[-1], c.image, gsd_m=c.gsd_m)
        chips = [im.read_raster(p).data for p in paths]
        t = median_time(lambda: im.fit_sensor(chips), max(runs // 10, 3))
        cpu = median_time(lambda: im.fit_sensor(chips), max(runs // 10, 3), clock=time.process_time)
        code = ("import time, imgmtf as im; t = time.perf_counter(); "
                f"im.fit_sensor({[str(p) for p in paths]!r}); print(time.perf_counter() - t)")
        first = float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                     check=True).stdout)
    print(f"fit_sensor of two 100 x 100 edges: {t:6.3f} s in process ({cpu:.3f} s of CPU; target < 0.3 s); "
          f"first call in a fresh process {first:5.2f} s")


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
    p.add_argument("--only", choices=["chips", "cli", "fit", "startup"])
    a = p.parse_args()
    compile_package()       # the start-up of an installed imgmtf (see _installed.py)
    print(f"load average (1, 5, 15 min): {', '.join(f'{v:.2f}' for v in os.getloadavg())} "
          f"on {os.cpu_count()} cores")
    if a.only == "startup":
        return startup(max(a.runs // 5, 5))
    if a.only == "chips":
        return depth_ratio(a.runs)
    if a.only == "fit":
        return fit_time(a.runs)
    if a.only == "cli":
        with tempfile.TemporaryDirectory() as tmp:
            cli_marginal(tmp, a.runs)
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
    depth_ratio(a.runs)
    fit_time(a.runs)
    with tempfile.TemporaryDirectory() as tmp:
        cli_marginal(tmp, a.runs)
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
    print(f"load average (1, 5, 15 min) at the end: {', '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()

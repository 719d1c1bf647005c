"""Restoring a large scene: peak memory of the tiled restoration, and its
seams against a whole-image restoration.

The scene (built once, cached in ``--cache``, default the system's temp
folder): 4096 x 4096 px, level 2000 DN plus a multi-scale texture of 300 DN
(:func:`imgmtf.sensor.scenes.texture`), 400 sharp-edged tilted squares of
+-600 DN and white noise of 5 DN, stored twice: as uint16 and as float32
(the float copy shows the seams unrounded).  Drawn from
``numpy.random.default_rng(SEED)``, the same on every machine.

Measured:

1. ``imgmtf restore`` on the uint16 scene (the generic sensor, target 0.3 at
   Nyquist, the FFT form, 1024 px tiles, one worker, the noise given), in a
   new process, whose peak resident memory (``ru_maxrss``) is compared with
   that of a process that only imports what the command imports: the
   difference is what the restoration holds, printed in MiB and in tiles'
   worth (a tile and its halo as float64) and against the whole image as
   float64 (128 MiB); and the same for the scene's 2048 x 2048 quarter,
   whose memory should be the same (bounded: set by the tile, not the scene);
2. the same on the float32 scene, and its result against the whole image
   restored at once in this process (:class:`imgmtf.RestorationFilter`
   called on the array): the largest difference (budget: below 0.5 DN) and
   where it lies relative to the tile borders;
3. the uint16 result against the whole-image restoration rounded and
   clipped alike: the number of pixels that differ.

The restoration runs in the command's own process (one worker): with workers
the tiles' memory is theirs, one tile in flight and one queued each.

usage: python bench/restore_memory.py [--cache DIR] [--tile PX]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import imgmtf as im
from imgmtf.restore.apply import OutputType
from imgmtf.sensor.scenes import texture

SIZE = 4096
SEED = 20261124
TARGET = 0.3
NOISE_DN, SIGNAL_DN = 5.0, 400.0


def build_scene(folder: Path) -> tuple[Path, Path]:
    u16, f32 = folder / "restore_scene_u16.tif", folder / "restore_scene_f32.tif"
    if u16.exists() and f32.exists():
        return u16, f32
    rng = np.random.default_rng(SEED)
    image = 2000.0 + texture((SIZE, SIZE), 300.0, seed=int(rng.integers(1 << 31)))
    y, x = np.mgrid[0:256, 0:256]
    for _ in range(400):
        side, angle = rng.uniform(30, 200), rng.uniform(0, np.pi / 2)
        cy, cx = rng.integers(128, SIZE - 128, 2)
        u = (x - 128) * np.cos(angle) + (y - 128) * np.sin(angle)
        v = -(x - 128) * np.sin(angle) + (y - 128) * np.cos(angle)
        inside = (np.abs(u) < side / 2) & (np.abs(v) < side / 2)
        image[cy - 128: cy + 128, cx - 128: cx + 128] += rng.choice([-600.0, 600.0]) * inside
    image += rng.normal(0.0, NOISE_DN, image.shape)
    im.write_geotiff(u16, np.clip(np.rint(image), 0, 65535).astype(np.uint16))
    import rasterio
    with rasterio.open(f32, "w", driver="GTiff", width=SIZE, height=SIZE, count=1, dtype="float32",
                       tiled=True, blockxsize=256, blockysize=256,
                       transform=rasterio.transform.Affine(1, 0, 0, 0, -1, 0)) as dst:
        dst.write(image.astype(np.float32), 1)
    return u16, f32


# the peak is the process's VmHWM: ru_maxrss would carry over this process's own peak
# (Linux keeps it across fork and exec)
_PRINT_PEAK = ("print('PEAK_KIB', next(line.split()[1] for line in open('/proc/self/status') "
               "if line.startswith('VmHWM')), file=sys.stderr)\n")
_PEAK = ("import sys, runpy; sys.argv = {argv!r}\n"
         "try:\n    runpy.run_module('imgmtf.cli', run_name='__main__')\n"
         "except SystemExit as exc:\n    code = exc.code\n" + _PRINT_PEAK)
_BASELINE = ("import sys\nimport numpy, scipy.signal, scipy.special, rasterio, imgmtf.restore.restoration\n"
             "import imgmtf.cli.main, imgmtf.estimate.detection\n" + _PRINT_PEAK)


def peak_kib(code: str) -> tuple[int, float, str]:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if done.returncode or 'PEAK_KIB' not in done.stderr:
        raise SystemExit(f"failed: {done.stderr}")
    line = next(text for text in done.stderr.splitlines() if text.startswith("PEAK_KIB"))
    return int(line.split()[1]), seconds, done.stdout


def restore_command(scene: Path, out: Path, tile: int) -> list[str]:
    return ["imgmtf", "restore", str(scene), "--sensor", str(out.parent / "generic.toml"), "--target-nyquist",
            str(TARGET), "--noise-std", str(NOISE_DN), "--signal-std", str(SIGNAL_DN), "--out", str(out),
            "--tile", str(tile), "--format", "json", "--no-progress"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()))
    parser.add_argument("--tile", type=int, default=1024)
    args = parser.parse_args()
    u16, f32 = build_scene(args.cache)
    work = Path(tempfile.mkdtemp(prefix="restore_bench_"))
    sensor = im.Sensor()
    sensor.to_toml(work / "generic.toml")
    restoration = im.design_filter(sensor, TARGET, noise_std_dn=NOISE_DN, signal_std_dn=SIGNAL_DN)
    r = restoration.radius_px

    quarter = work / "quarter.tif"           # the scene's top-left quarter: memory must not follow the size
    im.write_geotiff(quarter, im.read_raster(u16, window=(0, 0, SIZE // 2, SIZE // 2)).data.astype(np.uint16))
    baseline, _, _ = peak_kib(_BASELINE)
    tile_mib = (args.tile + 2 * r) ** 2 * 8 / 2**20
    print(f"filter {restoration.taps.shape[0]} x {restoration.taps.shape[0]} taps (halo {r} px), noise gain "
          f"{restoration.noise_gain:.3f}; tiles {args.tile} px ({tile_mib:.1f} MiB each as float64 with the "
          f"halo), in-process (one worker); imports alone peak at {baseline / 1024:.0f} MiB")
    for name, path in (("2048 x 2048", quarter), (f"{SIZE} x {SIZE}", u16)):
        peak, seconds, stdout = peak_kib(_PEAK.format(argv=restore_command(path, work / f"r_{path.stem}.tif",
                                                                           args.tile)))
        held = (peak - baseline) / 1024
        whole_mib = (SIZE if path == u16 else SIZE // 2) ** 2 * 8 / 2**20
        print(f"{name} uint16 in {json.loads(stdout)['tiles']} tiles: {seconds:.1f} s; peak {peak / 1024:.0f} MiB: "
              f"the restoration held {held:.0f} MiB = {held / tile_mib:.1f} tiles' worth = "
              f"{held / whole_mib:.2f} x the whole image as float64")

    _, seconds32, _ = peak_kib(_PEAK.format(argv=restore_command(f32, work / "r32.tif", args.tile)))
    data = im.read_raster(f32).data
    whole = restoration(data)
    tiled = im.read_raster(work / "r32.tif").data
    difference = np.abs(tiled - whole.astype(np.float32))
    iy, ix = np.unravel_index(np.argmax(difference), difference.shape)
    border = min(iy % args.tile, ix % args.tile, -iy % args.tile, -ix % args.tile)
    where = f" at ({ix}, {iy}), {border} px from a tile border" if difference.max() > 0 else ""
    print(f"float32 scene restored tiled ({seconds32:.1f} s) against whole: largest difference "
          f"{difference.max():.2e} DN (budget 0.5 DN){where}; mean {difference.mean():.1e} DN")
    original = im.read_raster(u16).data
    converted, _, kept = OutputType("uint16", None, (0.0, 65535.0)).convert(restoration(original), original)
    differing = int((im.read_raster(work / f"r_{u16.stem}.tif").data != converted).sum())
    print(f"uint16 result against the whole-image restoration rounded, clipped and its {kept} saturated pixels "
          f"kept alike: {differing} of {SIZE * SIZE} pixels differ")


if __name__ == "__main__":
    main()

"""The benches' test charts of tilted dark squares on a bright field, each
square rendered exactly by the generic sensor
(:func:`imgmtf.sensor.scenes.render_quadrants`, four equal quadrants), in
16-bit GeoTIFFs without a CRS, built once into a cache folder.

* :func:`four_square_chart`: like MTF Mapper's own, 1400 x 1400 px, four
  squares (380 px a side) tilted 4, 7.5, 11 and 14.5 deg: 16 edges.
* :func:`dense_chart`: like a lens-test chart of many squares, 2000 x 2000
  px, a 22 x 22 grid of 484 squares (52 px a side, in cells of 90.9 px)
  tilted 3-14 deg in turn: 1936 edges.

Levels 8000 DN (squares) on 40000 DN (field), 40 DN of white noise;
everything drawn from ``numpy.random.default_rng(seed)``, so a chart is
the same on every machine.

usage: python bench/charts.py [--cache DIR]   (builds both, prints their paths)
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

import imgmtf as im

SEED = 20240512
DARK_DN, FIELD_DN, NOISE_DN = 8000.0, 40000.0, 40.0
FOUR_SIZE, FOUR_ANGLES, FOUR_SQUARE_PX = 1400, (4.0, 7.5, 11.0, 14.5), 380.0
DENSE_SIZE, DENSE_GRID, DENSE_SQUARE_PX = 2000, 22, 52.0
#: the dense chart's tilts, deg, square after square (none within 2 deg of
#: the axes or of 45 deg: every edge a slanted edge)
DENSE_ANGLES = (3.0, 5.5, 8.0, 10.5, 13.0, 14.0, 4.25, 6.75, 9.25, 11.75)


def render_squares(size: int, grid: int, angles: list[float], square_px: float, seed: int) -> np.ndarray:
    """A ``size`` px square 16-bit image of ``grid`` x ``grid`` cells, one
    dark square (``square_px`` a side, tilted by ``angles[k]``) in cell k,
    row by row, its centre jittered by up to 3 px (1 px in a small cell)."""
    from imgmtf.sensor.scenes import QuadrantTarget, render_quadrants
    rng = np.random.default_rng(seed)
    edges = np.linspace(0, size, grid + 1).round().astype(int)
    image = np.zeros((size, size), np.uint16)
    sensor = im.Sensor()
    jitter = min(3.0, (edges[1] - square_px) / 8)
    for k, angle in enumerate(angles):
        row, col = divmod(k, grid)
        (y0, y1), (x0, x1) = edges[row:row + 2], edges[col:col + 2]
        dx, dy = rng.uniform(-jitter, jitter, 2)
        centre = ((x1 - x0) / 2 - 0.5 + dx, (y1 - y0) / 2 - 0.5 + dy)
        square = QuadrantTarget(centre, angle, (DARK_DN,) * 4, square_px / 2)
        image[y0:y1, x0:x1] = render_quadrants(sensor, (y1 - y0, x1 - x0), square, field_dn=FIELD_DN,
                                               noise_std_dn=NOISE_DN, seed=int(rng.integers(1 << 31))).image
    return image


def _write(path: Path, image: np.ndarray, angles: list[float], seed: int) -> Path:
    im.write_geotiff(path, image, provenance={"seed": seed, "angles_deg": angles, "imgmtf_version": im.__version__})
    return path


def four_square_chart(cache: Path, seed: int = SEED) -> Path:
    """The chart of four squares (16 edges) in ``cache``, built when missing."""
    path = Path(cache) / f"scan_speed_chart_{FOUR_SIZE}_{seed}.tif"
    if not path.exists():
        _write(path, render_squares(FOUR_SIZE, 2, list(FOUR_ANGLES), FOUR_SQUARE_PX, seed), list(FOUR_ANGLES), seed)
    return path


def dense_chart(cache: Path, seed: int = SEED) -> Path:
    """The dense chart (484 squares, 1936 edges) in ``cache``, built when missing."""
    path = Path(cache) / f"scan_speed_dense_{DENSE_SIZE}_{seed}.tif"
    if not path.exists():
        angles = [DENSE_ANGLES[k % len(DENSE_ANGLES)] for k in range(DENSE_GRID ** 2)]
        _write(path, render_squares(DENSE_SIZE, DENSE_GRID, angles, DENSE_SQUARE_PX, seed), angles, seed)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()))
    args = parser.parse_args()
    print(four_square_chart(args.cache))
    print(dense_chart(args.cache))


if __name__ == "__main__":
    main()

"""Many models' sections at once (imgmtf.estimate.mtf2d.curves): each row
bit for bit what the one-at-a-time path gives."""
import numpy as np

from imgmtf.estimate.mtf2d.curves import interp_rows, mtf50_rows, transfers
from imgmtf.estimate.mtf2d.inversion import EllipticalModel, SeparableModel
from imgmtf.estimate.mtf2d.sections import _GRID, _mtf50


def test_rows_interpolated_as_numpy_interpolates_each():
    """On and between nodes, below and above them, NaN points, NaN values
    (a tail beyond reach, one in the middle) and equal neighbours: every
    value as np.interp's, NaN where it is NaN."""
    rng = np.random.default_rng(1)
    nodes = np.sort(rng.uniform(0, 1, (6, 9)), axis=1)
    values = rng.normal(size=(6, 9))
    values[1, 6:] = np.nan
    values[2, 4] = np.nan
    values[3, 2:5] = 0.25
    x = np.concatenate([rng.uniform(-0.2, 1.2, (6, 40)), nodes, np.full((6, 1), np.nan)], axis=1)
    out = interp_rows(x, nodes, values)
    for k in range(6):
        assert np.array_equal(out[k], np.interp(x[k], nodes[k], values[k]), equal_nan=True)
    shared = interp_rows(x, nodes[0], values)
    assert all(np.array_equal(shared[k], np.interp(x[k], nodes[0], values[k]), equal_nan=True) for k in range(6))
    same_points = interp_rows(x[0], nodes[0], values)             # one search for every row
    assert all(np.array_equal(same_points[k], np.interp(x[0], nodes[0], values[k]), equal_nan=True)
               for k in range(6))


def test_many_models_sections_are_each_models_own():
    """Separable and elliptical draws (own nodes, own aspects, NaN beyond
    their reach): across and along sections equal to their transfer's,
    and the MTF50 of each as the one-curve rule gives it."""
    rng = np.random.default_rng(2)
    nodes = np.arange(0.0, 0.8 + 1e-9, 0.025)
    separable = []
    for k in range(5):
        log_x, log_y = -rng.uniform(1, 4) * nodes ** 2, -rng.uniform(1, 4) * nodes ** 2
        log_y[nodes > 0.5 + 0.05 * k] = np.nan
        separable.append(SeparableModel(nodes, log_x, log_y))
    elliptical = []
    for k in range(5):
        own = np.linspace(0.0, rng.uniform(0.6, 1.1), 33)
        log_g = -rng.uniform(2, 9) * own ** 2
        log_g[own > 0.55 + 0.1 * k] = np.nan
        elliptical.append(EllipticalModel(own, log_g, rng.uniform(0.5, 2.0)))
    zero = 0.0 * _GRID
    for models in (separable, elliptical):
        for u, v in ((_GRID, zero), (zero, _GRID)):
            rows = transfers(models, u, v)
            assert all(np.array_equal(rows[k], m.transfer(u, v), equal_nan=True) for k, m in enumerate(models))
            assert np.array_equal(mtf50_rows(_GRID, rows), [_mtf50(r) for r in rows], equal_nan=True)
    starts_low = np.vstack([np.full(_GRID.size, 0.4), np.where(_GRID < 0.3, 1.0, np.nan)])
    assert np.isnan(mtf50_rows(_GRID, starts_low)).all()

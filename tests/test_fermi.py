from unittest.mock import patch

import numpy as np

from imgmtf.estimate.fermi import MIN_WIDTH_PX, FermiRows, fermi, fit_fermi, fit_fermi_many


def test_recovers_exact_parameters_for_every_row_at_once():
    rng = np.random.default_rng(0)
    n = 60
    x = np.tile(np.arange(-10.0, 11.0), (n, 1)) + rng.integers(-3, 4, (n, 1))
    truth = np.column_stack([rng.uniform(-900, 900, n), x[:, 10] + rng.uniform(-0.5, 0.5, n),
                             rng.uniform(0.3, 1.2, n), rng.uniform(100, 300, n)])
    truth[:, 0] = np.where(np.abs(truth[:, 0]) < 100, 500.0, truth[:, 0])
    y = fermi(x, truth)
    fit = fit_fermi(x, y, np.ones_like(y), x[:, 10].astype(float))
    assert fit.ok.all()
    np.testing.assert_allclose(fit.location, truth[:, 1], atol=1e-6)
    np.testing.assert_allclose(fit.width, truth[:, 2], rtol=1e-5)
    assert fit.rms.max() < 1e-3


def test_padding_weights_are_ignored():
    x = np.tile(np.arange(-8.0, 9.0), (2, 1))
    y = fermi(x, np.array([[1000.0, 0.3, 0.5, 100.0]] * 2))
    w = np.ones_like(y)
    y[1, :3] = 1e6            # garbage where the weight is zero
    w[1, :3] = 0
    fit = fit_fermi(x, y, w, np.zeros(2))
    np.testing.assert_allclose(fit.location, [0.3, 0.3], atol=1e-6)


def test_flat_row_fails():
    x = np.tile(np.arange(-8.0, 9.0), (1, 1))
    fit = fit_fermi(x, np.full_like(x, 50.0) + np.linspace(0, 1e-9, x.size), np.ones_like(x), np.zeros(1))
    assert not fit.ok[0] or abs(fit.params[0, 0]) < 1e-3


def test_a_row_collapsed_to_a_step_keeps_its_location():
    # a sharpened edge's row: undershoot, step, overshoot, antisymmetric about
    # 0.5 px; a free logistic collapses to a step that may sit anywhere
    # between the samples 0 and 1, the pinned width puts it midway
    x = np.tile(np.arange(-8.0, 10.0), (3, 1))
    y = np.where(x < 0.5, 200.0, 1200.0)
    y[:, [7, 8, 9, 10]] = [100.0, 210.0, 1190.0, 1300.0]
    fit = fit_fermi(x, y, np.ones_like(y), np.array([0.2, 0.5, 0.8]))
    assert fit.ok.all() and fit.pinned.all()
    assert (fit.width == MIN_WIDTH_PX).all()
    np.testing.assert_allclose(fit.location, 0.5, atol=1e-5)


def test_edges_fitted_together_are_each_fitted_as_alone_to_the_bit():
    # noisy edges of different row counts, one with rows collapsed to a step (held), one flat:
    # stacked in one fit (and in stacks of STACK_ROWS), every edge's fit is its own fit's, bit for bit
    rng = np.random.default_rng(3)
    edges = []
    for rows, width in ((40, 0.6), (25, 1.1), (3, None), (60, 0.9), (12, 0.0)):
        x = np.tile(np.arange(-10.0, 11.0), (rows, 1)) + rng.integers(-2, 3, (rows, 1))
        b = x[:, 10] + rng.uniform(-0.5, 0.5, rows)
        if width is None:
            y = np.full(x.shape, 500.0) + rng.normal(0, 1, x.shape)
        elif width == 0.0:
            y = np.where(x < b[:, None], 200.0, 1200.0) + rng.normal(0, 2, x.shape)
        else:
            y = fermi(x, np.column_stack([np.full(rows, -900.0), b, np.full(rows, width), np.full(rows, 1000.0)]))
            y = y + rng.normal(0, 5, x.shape)
        w = np.ones_like(y)
        w[0, :4] = 0.0
        edges.append(FermiRows(x, y, w, x[:, 10].astype(float)))
    alone = [fit_fermi(e.x, e.y, e.weight, e.b0) for e in edges]
    assert any(f.pinned.any() for f in alone)
    for stack in (10_000, 50):
        with patch("imgmtf.estimate.fermi.STACK_ROWS", stack):
            together = fit_fermi_many(edges)
        for a, t in zip(alone, together, strict=True):
            for name in ("params", "rms", "ok", "pinned"):
                assert np.array_equal(getattr(a, name), getattr(t, name), equal_nan=name in ("params", "rms"))


def test_a_fit_of_rows_read_for_it_locates_the_edge_as_the_edge_locates_itself():
    # the rows edge_rows reads carry their image rows through fit_fermi_many, and
    # locate_edge takes them from the fit (not reading them again): the same line, bit for bit
    from imgmtf.estimate.geometry import edge_rows, locate_edge
    rows_n, slope = 30, np.tan(np.radians(6.0))
    seed_x = 15.0 + slope * np.arange(rows_n)
    x = np.tile(np.arange(30.0), (rows_n, 1))
    image = fermi(x, np.column_stack([np.full(rows_n, -800.0), seed_x + 0.3, np.full(rows_n, 0.8),
                                      np.full(rows_n, 900.0)]))
    image += np.random.default_rng(2).normal(0, 2.0, image.shape)
    image[4, :] = np.nan                                  # a row left out: the rows are not all the image's
    usable, rows = edge_rows(image, seed_x)
    (fit,) = fit_fermi_many([rows])
    assert np.array_equal(fit.rows, usable) and not usable.all()
    alone, fitted = locate_edge(image, seed_x), locate_edge(image, seed_x, fit=fit)
    assert (alone.slope, alone.intercept) == (fitted.slope, fitted.intercept)
    assert np.array_equal(alone.rows, fitted.rows) and np.array_equal(alone.kept, fitted.kept)

"""Groups of samples laid end to end, reduced group by group: the sums,
extremes, medians and least squares each group gets alone, to the bit."""
import numpy as np

from imgmtf.estimate.ragged import Groups, least_squares


def test_each_groups_reductions_are_its_own():
    rng = np.random.default_rng(3)
    sizes = [5, 0, 8, 1, 6]
    values = rng.normal(size=sum(sizes))
    values[10] = values[11]                         # a tie for a group's largest: the first wins
    groups = Groups(sizes)
    parts = np.split(values, np.cumsum(sizes)[:-1])
    full = [k for k, part in enumerate(parts) if part.size]
    assert np.allclose(groups.sum(values), [p.sum() for p in parts], rtol=1e-15, atol=1e-15)
    assert groups.extreme(values, True)[full].tolist() == [parts[k].max() for k in full]
    assert groups.extreme(values, False)[full].tolist() == [parts[k].min() for k in full]
    assert np.isnan(groups.extreme(values, True)[1]) and np.isnan(groups.median(values)[1])
    assert groups.median(values)[full].tolist() == [np.median(parts[k]) for k in full]
    assert groups.argmax(values)[full].tolist() == [int(np.argmax(parts[k])) for k in full]
    # a group alone gives its own sums, to the bit
    alone = Groups([sizes[2]])
    assert alone.sum(parts[2])[0] == groups.sum(values)[2]


def test_least_squares_per_group_match_numpy_and_a_dependent_column_gets_zero():
    rng = np.random.default_rng(4)
    sizes = [30, 12, 50]
    groups = Groups(sizes)
    x = rng.uniform(2.0, 20.0, groups.ids.size)
    t = rng.normal(size=x.size)
    t[30:42] = 7.0                                  # one group's t is constant: the ones column's twin
    y = 3.0 + 50.0 / x ** 2 + 0.1 * x - 0.2 * t + rng.normal(0, 0.01, x.size)
    columns = [np.ones_like(x), x ** -2.0, x - 10.0, t]
    coef, resid = least_squares(groups, columns, y)
    for k, (start, size) in enumerate(zip(groups.starts, groups.sizes)):
        part = slice(start, start + size)
        design = np.column_stack([c[part] for c in columns])
        expected, *_ = np.linalg.lstsq(design if k != 1 else design[:, :3], y[part], rcond=None)
        assert np.allclose(coef[k, :expected.size], expected, rtol=1e-9, atol=1e-9)
        assert np.allclose(resid[part], y[part] - design @ coef[k], atol=1e-9)
    assert coef[1, 3] == 0.0
    # a group's answer alone is its answer among others, to the bit
    one, one_resid = least_squares(Groups([sizes[2]]), [c[42:] for c in columns], y[42:])
    assert (one[0] == coef[2]).all() and (one_resid == resid[42:]).all()


def test_least_squares_on_the_padded_grid_gives_the_bincounts_floats():
    from imgmtf.estimate.ragged import Grid, _EndToEnd, _least_squares
    rng = np.random.default_rng(5)
    for sizes in ([40], [25, 0, 60, 3], [7, 90, 88], list(range(20, 60))):     # the last filled by indexing
        groups = Groups(sizes)
        assert Grid.of(groups) is not None
        x = rng.uniform(2.0, 20.0, groups.ids.size)
        columns = [np.ones_like(x), x ** -1.0, x - 10.0, rng.normal(size=x.size)]
        y = 3.0 + 50.0 / x + rng.normal(0, 0.3, x.size)
        grid = Grid.of(groups)
        assert grid.sum(grid.scatter(y))[: groups.count].tobytes() == groups.sum(y).tobytes()
        coef, resid = least_squares(groups, columns, y)
        slow_coef, slow_resid = _least_squares(_EndToEnd(groups), columns, y)
        assert coef.tobytes() == slow_coef.tobytes() and resid.tobytes() == slow_resid.tobytes()
    assert Grid.of(Groups([1000, 1, 1, 1])) is None        # padding would swamp the samples


def test_few_large_groups_medians_by_partition_are_the_sorts():
    rng = np.random.default_rng(6)
    sizes = [300, 0, 301, 1000]
    values = rng.normal(size=sum(sizes)).round(2)            # ties among the middle values
    groups = Groups(sizes)
    parts = np.split(values, np.cumsum(sizes)[:-1])
    medians = groups.median(values)
    assert np.isnan(medians[1])
    assert [medians[k] for k in (0, 2, 3)] == [np.median(parts[k]) for k in (0, 2, 3)]

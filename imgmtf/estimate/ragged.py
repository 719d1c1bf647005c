"""Many groups' samples laid end to end (one group a chip's side, or a
chip's rows) and reduced group by group in one call each, so that the
gate's small fits of a few hundred chips cost a handful of NumPy calls,
not a handful per chip.

Every reduction adds a group's values one after another in their order
(:func:`numpy.bincount`), whatever the other groups hold: a group's result
is the same to the bit alone or among others, which is what lets a chip's
own check be a batch of one.  Least squares go by modified Gram-Schmidt
on the groups' columns (:func:`least_squares`), as accurate as a QR and
built of the same sums.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

PARTITIONED_GROUP_SAMPLES = 256    # groups this large on average: a median is a partition per group
LOOPED_SCATTER_GROUPS = 32          # up to this many groups, a Grid is filled group by group


class Groups:
    """Samples laid end to end in groups (each group's in one run).

    Parameters
    ----------
    sizes : sequence of int
        Each group's number of samples (0 allowed).

    Attributes
    ----------
    count : int
        The number of groups.
    sizes : numpy.ndarray
        Each group's number of samples.
    starts : numpy.ndarray
        Where each group's run begins.
    ids : numpy.ndarray
        Each sample's group.

    Examples
    --------
    >>> g = Groups([2, 0, 3])
    >>> g.sum(np.array([1.0, 2.0, 3.0, 4.0, 5.0])).tolist()
    [3.0, 0.0, 12.0]
    """

    def __init__(self, sizes: ArrayLike):
        self.sizes = np.asarray(sizes, dtype=np.intp).reshape(-1)
        self.count = int(self.sizes.size)
        self.starts = np.zeros(self.count, np.intp)
        np.cumsum(self.sizes[:-1], out=self.starts[1:])
        self.ids = np.repeat(np.arange(self.count), self.sizes)

    def sum(self, values: np.ndarray) -> np.ndarray:
        """Each group's sum of ``values`` (one a sample), added in order;
        0 for an empty group."""
        return np.bincount(self.ids, weights=values, minlength=self.count)

    def spread(self, per_group: np.ndarray) -> np.ndarray:
        """``per_group`` (one a group) repeated for each of its samples
        (a repeat: some 3 x faster than gathering by ``ids``)."""
        return np.repeat(per_group, self.sizes, axis=0)

    def power(self, values: np.ndarray, exponents: Sequence[float]) -> np.ndarray:
        """``values`` to each group's power ``exponents`` (one a group), each
        exponent a scalar as a group alone raises it (NumPy's ``x ** -2.0``
        is not its ``x ** array`` to the bit, nor as fast)."""
        each = np.asarray(exponents, float)
        distinct = np.unique(each)
        if distinct.size == 1:
            return values ** float(distinct[0])
        out = np.empty_like(values)
        for exponent in distinct:
            take = self.spread(each == exponent)
            out[take] = values[take] ** float(exponent)
        return out

    def extreme(self, values: np.ndarray, largest: bool) -> np.ndarray:
        """Each group's largest (or smallest) value; NaN for an empty group."""
        out = np.full(self.count, np.nan)
        full = self.sizes > 0
        if full.any():
            out[full] = (np.maximum if largest else np.minimum).reduceat(values, self.starts[full])
        return out

    def first_at(self, hit: np.ndarray) -> np.ndarray:
        """Each group's first sample where ``hit`` is True, as its index
        within the group; 0 where none is (as :func:`numpy.argmax`)."""
        where = np.flatnonzero(hit)
        first = np.zeros(self.count, np.intp)
        groups, at = np.unique(self.ids[where], return_index=True)
        first[groups] = where[at] - self.starts[groups]
        return first

    def argmax(self, values: np.ndarray) -> np.ndarray:
        """Each group's :func:`numpy.argmax` (index within the group, the
        first of equal largest values); 0 for an empty group."""
        return self.first_at(values == self.spread(self.extreme(values, True)))

    def median(self, values: np.ndarray) -> np.ndarray:
        """Each group's median (the mean of the two middle values for an
        even count, as :func:`numpy.median`); NaN for an empty group."""
        out = np.full(self.count, np.nan)
        full = self.sizes > 0
        if not full.any():
            return out
        width = int(self.sizes.max())
        if values.size >= PARTITIONED_GROUP_SAMPLES * self.count:
            # few large groups: each one's two middle values by a partition of its own (linear, not a sort)
            for k, start, size in zip(np.flatnonzero(full).tolist(), self.starts[full].tolist(),
                                      self.sizes[full].tolist()):
                middle = np.partition(values[start: start + size], [(size - 1) // 2, size // 2])
                out[k] = (middle[(size - 1) // 2] + middle[size // 2]) / 2
            return out
        if self.count * width <= 4 * values.size + 1024:
            # each group sorted in a row of its own, padded past its end (a direct sort: faster than lexsort)
            rows = np.full((self.count, width), np.inf)
            rows[self.ids, np.arange(values.size) - self.starts[self.ids]] = values
            rows.sort(axis=1)
            at = np.flatnonzero(full)
            out[full] = (rows[at, (self.sizes[full] - 1) // 2] + rows[at, self.sizes[full] // 2]) / 2
            return out
        ranked = values[np.lexsort((values, self.ids))]
        low, high = (self.starts + (self.sizes - 1) // 2)[full], (self.starts + self.sizes // 2)[full]
        out[full] = (ranked[low] + ranked[high]) / 2
        return out


class Grid:
    """Groups' samples in the columns of a zero-padded (longest group,
    groups) array, for a computation whose every step is elementwise or a
    group's sum: a column's sum, down the array, adds its group's values
    one after another in their order from 0, as :meth:`Groups.sum` does
    (the same floats, at a quarter of a bincount's time), and a value per
    group spreads over its samples by broadcasting.  At least two columns,
    so that NumPy adds down them rather than along one (pairwise).

    Examples
    --------
    >>> g = Groups([2, 0, 3])
    >>> grid = Grid.of(g)
    >>> x = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    >>> grid.sum(grid.scatter(x))[:3].tolist(), bool(np.array_equal(grid.gather(grid.scatter(x)), x))
    ([3.0, 0.0, 12.0], True)
    """

    def __init__(self, groups: Groups):
        self.count = groups.count
        self.shape = (int(groups.sizes.max()), max(groups.count, 2))
        self.runs = (list(zip(range(groups.count), groups.starts.tolist(), groups.sizes.tolist()))
                     if groups.count <= LOOPED_SCATTER_GROUPS else [])
        self.at = (np.arange(groups.ids.size) - groups.starts[groups.ids]) * self.shape[1] + groups.ids

    @classmethod
    def of(cls, groups: Groups) -> Grid | None:
        """The grid of ``groups``, or None where padding would more than
        double the samples (or there are none)."""
        if groups.count == 0 or groups.ids.size == 0:
            return None
        if groups.sizes.max() * max(groups.count, 2) > 2 * groups.ids.size + 1024:
            return None
        return cls(groups)

    def scatter(self, values: np.ndarray) -> np.ndarray:
        """``values`` (one a sample) in their groups' columns, 0 beyond."""
        out = np.zeros(self.shape)
        if self.count > LOOPED_SCATTER_GROUPS:       # many groups: one indexed assignment
            out.ravel()[self.at] = values
            return out
        for g, start, size in self.runs:            # few: a strided copy each (faster than indexing)
            out[:size, g] = values[start: start + size]
        return out

    def gather(self, grid: np.ndarray) -> np.ndarray:
        """The samples of a scattered array, end to end again."""
        return grid.ravel()[self.at]

    def sum(self, grid: np.ndarray) -> np.ndarray:
        """Each column's sum, in order from 0 (padding columns included)."""
        return np.add.reduce(grid, axis=0, initial=0.0)

    def spread(self, per_column: np.ndarray) -> np.ndarray:
        """A value per column, as it broadcasts down its column."""
        return per_column

    @property
    def columns(self) -> int:
        """Values a group per sum (padding columns included)."""
        return self.shape[1]


class _EndToEnd:
    """The samples end to end, as :class:`Grid` lays them out: each
    group's sum a bincount, a group's value spread by a repeat (for groups
    too unequal to pad)."""

    def __init__(self, groups: Groups):
        self.count = self.columns = groups.count
        self.shape = groups.ids.shape
        self.sum, self.spread = groups.sum, groups.spread

    def scatter(self, values: np.ndarray) -> np.ndarray:
        return np.array(values, float)           # (a copy: the fit works on it in place)

    def gather(self, samples: np.ndarray) -> np.ndarray:
        return samples


def _least_squares(layout: Grid | _EndToEnd, columns: Sequence[np.ndarray], target: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`least_squares` on the samples as ``layout`` holds them: the
    same operations on the same values in the same order whichever it is
    (each group's floats the same)."""
    m = len(columns)
    basis: list[np.ndarray] = []
    # r[i][j]: the triangular factor, one value a group
    r = [[np.zeros(layout.columns) for _ in range(m)] for _ in range(m)]
    rhs = []
    residual = layout.scatter(np.asarray(target, float))
    work = np.empty(layout.shape)       # each product made in place (the arrays are large: no new one a step)
    for j, column in enumerate(columns):
        q = layout.scatter(np.asarray(column, float))
        original = np.sqrt(layout.sum(np.multiply(q, q, out=work)))
        for i, earlier in enumerate(basis):
            r[i][j] = layout.sum(np.multiply(earlier, q, out=work))
            q -= np.multiply(earlier, layout.spread(r[i][j]), out=work)
        norm = np.sqrt(layout.sum(np.multiply(q, q, out=work)))
        independent = norm > 1e-13 * original
        r[j][j] = np.where(independent, norm, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            q *= layout.spread(np.where(independent, 1.0 / norm, 0.0))
        basis.append(q)
        rhs.append(layout.sum(np.multiply(q, residual, out=work)))
        residual -= np.multiply(q, layout.spread(rhs[j]), out=work)
    coef = np.zeros((layout.columns, m))
    for j in range(m - 1, -1, -1):
        value = rhs[j]
        for k in range(j + 1, m):
            value = value - r[j][k] * coef[:, k]
        with np.errstate(divide="ignore", invalid="ignore"):
            coef[:, j] = np.where(r[j][j] > 0, value / np.where(r[j][j] > 0, r[j][j], 1.0), 0.0)
    return coef[: layout.count], layout.gather(residual)


def least_squares(groups: Groups, columns: Sequence[np.ndarray], target: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Each group's least-squares coefficients of ``columns`` (each an array
    over all samples) for ``target``, by modified Gram-Schmidt: a column that
    nothing independent is left of in a group (within 1e-13 of its own
    norm) is given coefficient 0 there, the minimum-norm solution's.

    Returns
    -------
    coef : numpy.ndarray
        (groups, columns).
    residual : numpy.ndarray
        ``target`` less each group's fit, over all samples.

    Examples
    --------
    >>> g = Groups([4, 3])
    >>> x = np.array([0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0])
    >>> coef, resid = least_squares(g, [np.ones(7), x], 1.0 + 2.0 * x)
    >>> np.round(coef, 12).tolist(), bool(np.abs(resid).max() < 1e-12)
    ([[1.0, 2.0], [1.0, 2.0]], True)
    """
    return _least_squares(Grid.of(groups) or _EndToEnd(groups), columns, target)

"""Many edges' line responses interpolated in angle: a scene's thousands
of half-edges lie at a few tilts, and an edge's response is a smooth
function of its tilt, so the responses of a group of edges whose tilts
span at most :data:`MAX_SPAN_DEG` are made at :data:`NODES` Chebyshev
nodes of the span (one inverse FFT per node, not per edge) and each
edge's is their Lagrange combination at its own tilt, on one grid with
one reference for the group.

The interpolation is exact to about 1e-11 of the step for 8 nodes over
20 deg (the paper's sensor, the auto candidates' stages, f/8 diffraction;
tests/test_fit_angles.py), four orders below the grid's own 1e-7: a
fit's optimum moves far below its printed digits.  A group of fewer than
:data:`MIN_EDGES` edges keeps each edge's own response
(:class:`.responses.EdgeResponses`), so a target's fit, a chart's of a
few squares and a real scene's of a dozen half-edges are computed as
before, bit for bit.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...sensor.lines import LineGrid, LineResponse, line_grid, reference_transfer
from ...sensor.model import Sensor
from ...sensor.stages import Stage

#: Chebyshev nodes of a group's span of tilts
NODES = 8
#: the widest span of tilts (deg) one group's nodes interpolate
MAX_SPAN_DEG = 20.0
#: the fewest edges a group interpolates (fewer: each edge its own FFT, as
#: cheap as the nodes' and exact)
MIN_EDGES = 4 * NODES


def chebyshev_nodes(low: float, high: float, count: int = NODES) -> np.ndarray:
    """``count`` Chebyshev nodes (of the first kind) of [``low``, ``high``].

    Examples
    --------
    >>> chebyshev_nodes(-1.0, 1.0, 2).round(6).tolist()
    [0.707107, -0.707107]
    """
    j = np.arange(count)
    return (low + high) / 2 + (high - low) / 2 * np.cos((2 * j + 1) * np.pi / (2 * count))


def lagrange_weights(nodes: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The Lagrange interpolation weights of ``nodes`` at points ``at``:
    row i gives the value at ``at[i]`` of the polynomial through the
    nodes' values (each row sums to 1).

    Examples
    --------
    >>> lagrange_weights(np.array([0.0, 1.0, 2.0]), np.array([0.5])).tolist()
    [[0.375, 0.75, -0.125]]
    """
    nodes = np.asarray(nodes, float)
    at = np.asarray(at, float)
    weights = np.ones((at.size, nodes.size))
    for k in range(nodes.size):
        for m in range(nodes.size):
            if m != k:
                weights[:, k] *= (at - nodes[m]) / (nodes[k] - nodes[m])
    return weights


def angle_groups(angles_deg: Sequence[float], gsds_m: Sequence[float], max_span_deg: float = MAX_SPAN_DEG,
                 min_edges: int | None = None) -> list[list[int]]:
    """Edges (their indices) to interpolate together: of one GSD, their
    tilts within ``max_span_deg``, at least ``min_edges`` of them (default
    :data:`MIN_EDGES`); edges in no group keep their own responses.

    Examples
    --------
    >>> angle_groups([5.0, 95.0, 7.0, 6.0, 96.0], [1.0] * 5, min_edges=2)
    [[0, 3, 2], [1, 4]]
    """
    angles = np.asarray(angles_deg, float)
    min_edges = MIN_EDGES if min_edges is None else min_edges
    groups = []
    for gsd in dict.fromkeys(gsds_m):
        members = [i for i in np.argsort(angles, kind="stable").tolist() if gsds_m[i] == gsd]
        while members:
            first = angles[members[0]]
            count = next((n for n, i in enumerate(members) if angles[i] - first > max_span_deg), len(members))
            if count >= min_edges:
                groups.append(members[:count])
            members = members[count:]
    return groups


def grouped_edges(angles_deg: Sequence[float], gsds_m: Sequence[float], reaches_px: Sequence[float]
                  ) -> tuple[list[tuple[list[int], AngleGroup]], list[int]]:
    """A fit's edges' groups (:func:`angle_groups`), each with its
    :class:`AngleGroup` (the farthest reach of its edges), and the edges in
    none, which keep their own responses.

    Examples
    --------
    >>> groups, own = grouped_edges([5.0, 95.0, 6.0], [1.0] * 3, [10.0, 12.0, 11.0])
    >>> groups, own
    ([], [0, 1, 2])
    """
    groups = [(members, AngleGroup([angles_deg[i] for i in members], gsds_m[members[0]],
                                   max(reaches_px[i] for i in members)))
              for members in angle_groups(angles_deg, gsds_m)]
    grouped = {i for members, _ in groups for i in members}
    return groups, [i for i in range(len(angles_deg)) if i not in grouped]


class AngleGroup:
    """The line responses of edges at nearby tilts, interpolated from
    :data:`NODES` Chebyshev nodes of their span (see the module's notes):
    one grid and reference for all of them, the last sensor's node
    transfers and responses kept (the solver asks for the Jacobian where
    it last asked for the residuals).

    Parameters
    ----------
    angles_deg : sequence of float
        The edges' tilts (their profiles' directions), deg.
    gsd_m : float
        Their pixel, m.
    reach_px : float
        The farthest sample from any of the edges, px.

    Examples
    --------
    >>> group = AngleGroup([5.0, 8.0, 12.0], 1.0, 12.0)
    >>> exact = Sensor().line_response(8.0, 1.0)
    >>> abs(float(group.responses(Sensor())[1].esf(0.4)) - float(exact.esf(0.4))) < 1e-9
    True
    """

    def __init__(self, angles_deg: Sequence[float], gsd_m: float, reach_px: float):
        angles = np.asarray(angles_deg, float)
        self.gsd_m, self.reach_px = gsd_m, reach_px
        low, high = float(angles.min()), float(angles.max())
        span = max(high - low, 1e-3)
        self.nodes = chebyshev_nodes(low - 1e-3 * span, high + 1e-3 * span)
        self.weights = lagrange_weights(self.nodes, angles)
        radians = np.radians(self.nodes)
        self._cos, self._sin = np.cos(radians)[:, None], np.sin(radians)[:, None]
        self._last: tuple | None = None
        self._transfers: dict[tuple[Stage, float], np.ndarray] = {}
        self._on: tuple[float, int] | None = None

    def release(self) -> None:
        """Drop what is kept: the next evaluation makes it again."""
        self._last, self._on = None, None
        self._transfers.clear()

    def responses(self, sensor: Sensor) -> list[LineResponse]:
        """Each edge's line response for ``sensor`` (the same objects for
        the last sensor asked for)."""
        return self._base(sensor)[2]

    def remainders(self, sensor: Sensor) -> tuple[np.ndarray, np.ndarray]:
        """The edges' ESF and LSF remainders for ``sensor``, one row each
        (the arrays its :meth:`responses` are views of)."""
        return self._base(sensor)[3]

    def node_changes(self, sensor: Sensor, shifted: Sequence[Sensor]) -> tuple[np.ndarray, np.ndarray]:
        """The changes of the nodes' ESF and LSF for each of the
        ``shifted`` sensors, on the group's grid: each edge's are their
        :meth:`combine`.

        Returns
        -------
        esf_changes, lsf_changes : numpy.ndarray, shape (nodes, len(shifted), grid size)
            Each node's shifted responses less its own.
        """
        grid, base = self._base(sensor)[:2]
        spectra = np.stack([self._transfer(other, grid, keep=False) - base for other in shifted], axis=1)
        return grid.remainders(spectra)

    def combine(self, values: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """The edges' values interpolated from the nodes' ``values``
        (shape (nodes, ...)): shape (edges, ...), into ``out`` when given."""
        flat = values.reshape(values.shape[0], -1)
        if out is None:
            return (self.weights @ flat).reshape(-1, *values.shape[1:])
        np.matmul(self.weights, flat, out=out.reshape(self.weights.shape[0], -1))
        return out

    def _base(self, sensor: Sensor) -> tuple[LineGrid, np.ndarray, list[LineResponse], tuple[np.ndarray, np.ndarray]]:
        key = (sensor.gsd_m, sensor.stages)
        if self._last is None or self._last[0] != key:
            grid = self._grid(sensor)
            transfer = self._transfer(sensor, grid, keep=True)
            esf, lsf = grid.remainders(transfer - reference_transfer(grid.reference, grid.frequencies_cy_px))
            esf, lsf = self.combine(esf), self.combine(lsf)
            responses = [LineResponse(grid.start_px, grid.step_px, e, s, grid.reference) for e, s in zip(esf, lsf)]
            self._last = (key, grid, transfer, responses, (esf, lsf))
        return self._last[1:]

    def _grid(self, sensor: Sensor) -> LineGrid:
        """One grid for the group: the widest of the nodes' own, with the
        reference of the node nearest the middle of the span."""
        tailed = sensor.tail_length_m() > 0
        grids = [line_grid(sensor, float(a), self.gsd_m, reach_px=self.reach_px if tailed else 0.0)
                 for a in self.nodes]
        middle = grids[len(grids) // 2]
        grid = LineGrid(min(g.step_px for g in grids), max(g.size for g in grids), middle.reference)
        if self._on != (grid.step_px, grid.size):
            self._on = (grid.step_px, grid.size)
            self._transfers.clear()
        return grid

    def _transfer(self, sensor: Sensor, grid: LineGrid, keep: bool) -> np.ndarray:
        """The nodes' transfers along their normals at ``grid``'s
        frequencies, shape (nodes, frequencies): the product of the
        stages', each kept (``keep``) for the next sensor that has it."""
        f = grid.frequencies_cy_px / self.gsd_m
        out = None
        for stage in sensor.stages:
            key = (stage, sensor.gsd_m)
            value = self._transfers.get(key)
            if value is None:
                value = stage.transfer(f * self._cos, f * self._sin, sensor.gsd_m)
                if keep:
                    while len(self._transfers) >= 8:
                        del self._transfers[next(iter(self._transfers))]
                    self._transfers[key] = value
            out = value if out is None else out * value
        return out if out is not None else np.ones((self.nodes.size, f.size))



@dataclass(frozen=True, eq=False)
class GridLayout:
    """A fit's edges' grids side by side (:func:`grid_layout`): where each
    edge's begins, their samples in all, and their ESF and LSF remainders
    so laid out."""

    offsets: list[int]
    size: int
    remainders: tuple[np.ndarray, np.ndarray]


def grid_layout(groups: list[tuple[list[int], AngleGroup]], own: list[int], sensor: Sensor,
                responses: list[LineResponse]) -> GridLayout:
    """The edges' grids side by side when some are a group's: each group's
    rows in turn, as its nodes' combination gives them, then the grids of
    the edges ``own`` (their own ``responses``); and the remainders so laid
    out (for :class:`.responses.StackedResponses`)."""
    offsets = [0] * len(responses)
    esf, lsf = [], []
    start = 0
    for members, group in groups:
        rows = group.remainders(sensor)
        size = rows[0].shape[-1]
        for j, i in enumerate(members):
            offsets[i] = start + j * size
        esf.append(rows[0].ravel())
        lsf.append(rows[1].ravel())
        start += rows[0].size
    for i in own:
        offsets[i] = start
        esf.append(responses[i].esf_remainder)
        lsf.append(responses[i].lsf_remainder)
        start += responses[i].esf_remainder.size
    return GridLayout(offsets, start, (np.concatenate(esf), np.concatenate(lsf)))


def laid_out_changes(groups: list[tuple[list[int], AngleGroup]], sensor: Sensor, shifted: Sequence[Sensor],
                     out: np.ndarray) -> None:
    """The changes of the groups' edges' LSF and ESF for each of the
    ``shifted`` sensors (a row each), combined from their nodes' in place
    into ``out`` (shape (2, len(shifted), samples): LSF, ESF), the groups'
    grids first, in turn, as :func:`grid_layout` lays them."""
    start = 0
    for _, group in groups:
        size = 0
        esf, lsf = group.node_changes(sensor, shifted)
        for both, nodes in zip(out, (lsf, esf)):
            size = nodes.shape[-1] * group.weights.shape[0]
            for row, node_rows in zip(both, nodes.transpose(1, 0, 2)):
                group.combine(node_rows, row[start: start + size])
        start += size

"""Each edge's line response for the fitted stages, and the changes of its
edge response with each free parameter, in one inverse FFT per edge.

The responses of a sensor and of its copies with one parameter shifted
(the Jacobian's finite differences) are made on one grid, the first
sensor's, with one reference: each stage's transfer is computed once on
it (a shift changes one stage), and the differences of the transfers,
not of two responses on two grids, give the derivatives.  Without a
diffraction stage the grid covers the PSF's support only: beyond it the
Gaussian reference is the edge response to below 1e-9, so a sample far
from the edge needs no grid out to it.

A fit asks for the same edge's responses at every evaluation:
:class:`EdgeResponses` keeps, per edge, what the next evaluation can use
again (the last sensor's grid, transfer and response, which the
Jacobian at the point of the last residuals starts from; the transfers
of its stages on the grid, which held stages and unshifted ones reuse),
so an evaluation computes only what its parameters changed.

A fit's edges are evaluated together where that costs fewer NumPy calls
and changes no number: a stage's transfer on every edge's frequencies in
one call (:func:`shared_transfers`), every edge's bins read from their
responses in one pass (:class:`StackedResponses`), the responses of up to
:data:`STACKED_EDGES` edges of alike grids in one inverse FFT
(:func:`edges_responses`; each row transformed as alone).  A Jacobian's
changes stay one inverse FFT per edge, written into their place side by
side: stacked across edges, the transforms ran slower (19 edges' grids of
2048 samples: 1.1 ms against 0.8 ms one by one, their arrays out of cache).
"""
from __future__ import annotations

import math
import operator
from collections.abc import Iterable, Sequence
from functools import reduce
from typing import Any

import numpy as np

from ...sensor.lines import (
    PROBE_CY_PX,
    HermitePlacement,
    LineGrid,
    LineResponse,
    hermite_placement,
    line_grid,
    plus_reference_curvature,
    plus_reference_esf,
    reference_scale,
    reference_transfer,
)
from ...sensor.model import Sensor
from ...sensor.stages import Stage

#: how many stage transfers an edge keeps (the longest unused goes first)
KEPT_TRANSFERS = 8
#: at most this many edges' responses in one inverse FFT (:func:`edges_responses`): their
#: spectra and remainders, 2048 samples each, within a quarter megabyte
STACKED_EDGES = 8


class EdgeResponses:
    """One edge's line responses for the sensors a fit evaluates, with what
    depends only on the edge's geometry and on unchanged stages kept from
    one evaluation to the next (the same responses as a new
    ``EdgeResponses`` makes, bit for bit).

    Parameters
    ----------
    angle_deg : float
        The edge's tilt from the column axis, deg.
    gsd_m : float
        The edge's pixel, m.
    reach_px : float
        The farthest sample from the edge, px: the grid reaches it when a
        Cauchy (diffraction) tail makes the remainder long.

    Notes
    -----
    It keeps the last sensor's grid, transfer and response (the solver
    asks for the Jacobian where it last asked for the residuals) and the
    transfers of the last sensors' stages (at most :data:`KEPT_TRANSFERS`)
    on the last grid's frequencies; a shifted copy's own stage is
    computed and not kept.  A grid of another step or size drops them.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> edge = EdgeResponses(90.0, 1.0, 50.0)
    >>> round(float(edge.response(Sensor()).esf(0.0)), 6)
    0.5
    >>> response, esf, _ = edge.changes(Sensor(), [Sensor(motion_m=0.5)])   # the grid and transfers kept
    >>> response is edge.response(Sensor()), esf.shape[0]
    (True, 1)
    """

    def __init__(self, angle_deg: float, gsd_m: float, reach_px: float):
        self.angle_deg, self.gsd_m, self.reach_px = angle_deg, gsd_m, reach_px
        angle = math.radians(angle_deg)
        self._cos, self._sin = math.cos(angle), math.sin(angle)
        self._last: tuple | None = None
        self._on: tuple[float, int] | None = None
        self._normal: tuple[np.ndarray, np.ndarray] = (np.zeros(0), np.zeros(0))
        self._transfers: dict[tuple[Stage, float], np.ndarray] = {}

    def release(self) -> None:
        """Drop what is kept (the last grid, transfer and response, the
        stages' transfers): the next evaluation makes them again."""
        self._last, self._on = None, None
        self._normal = (np.zeros(0), np.zeros(0))
        self._transfers.clear()

    def response(self, sensor: Sensor, given: Given | None = None) -> LineResponse:
        """The line response of ``sensor`` along the edge's normal.

        Parameters
        ----------
        sensor : Sensor
            The sensor.
        given : dict, optional
            Stages' transfers computed for several edges at once
            (:func:`shared_transfers`), used where on this edge's current
            frequencies.

        Returns
        -------
        LineResponse
            Its edge and line responses (the last one's kept: the same
            object for the same stages and GSD).
        """
        return self._base(sensor, given)[2]

    def changes(self, sensor: Sensor, shifted: Sequence[Sensor], given: Given | None = None,
                out: np.ndarray | None = None) -> tuple[LineResponse, np.ndarray, np.ndarray]:
        """The line response of ``sensor`` and the remainders of the
        ``shifted`` sensors' minus its own on its grid.

        Parameters
        ----------
        sensor : Sensor
            The sensor.
        shifted : sequence of Sensor
            Its shifted copies (same GSD, same chain).
        given : dict, optional
            As for :meth:`response` (the shifted stages' transfers).
        out : numpy.ndarray, shape (2, len(shifted), grid size), optional
            Where to write the LSF and ESF changes (:meth:`LineGrid.remainders`):
            a view of several edges' changes side by side, say.

        Returns
        -------
        response : LineResponse
            The sensor's edge and line responses.
        esf_changes, lsf_changes : numpy.ndarray, shape (len(shifted), grid size)
            Each shifted sensor's ESF and LSF (1/px) less the first's, on the
            grid of ``response``: for :func:`esf_changes`.
        """
        grid, base, response = self._base(sensor, given)
        spectra = np.empty((len(shifted), base.size), base.dtype)       # complex for a one-sided stage
        for row, other in zip(spectra, shifted):
            np.subtract(self._transfer(other, keep=False, given=given)[1:], base, out=row)
        esf, lsf = grid.remainders(spectra, out)
        return response, esf, lsf

    def _base(self, sensor: Sensor, given: Given | None = None) -> tuple[LineGrid, np.ndarray, LineResponse]:
        """The grid, transfer and response of ``sensor``, the last one's kept."""
        made = self._grid_and_transfer(sensor, given)
        if made is not None:
            self._keep(sensor, *made, made[0].response(made[1]))
        assert self._last is not None               # (kept just now, or the last sensor's)
        return self._last[1:]

    def _grid_and_transfer(self, sensor: Sensor, given: Given | None = None) -> tuple[LineGrid, np.ndarray] | None:
        """The grid of ``sensor`` and its transfer on the grid's
        frequencies, which :meth:`_keep` keeps with their response; None
        when they are the last one's."""
        if self._last is not None and self._last[0] == (sensor.gsd_m, sensor.stages):
            return None
        tailed = sensor.tail_length_m() > 0
        reach = self.reach_px if tailed else 0.0
        # without a tail the grid's reference reads the transfer at the probe, which comes with
        # the transfer on the last grid's frequencies: the next grid's, but when its size changes
        transfer = None if tailed or self._on is None else self._transfer(sensor, keep=True, given=given)
        grid = line_grid(sensor, self.angle_deg, self.gsd_m, reach_px=reach,
                         transfer_at_probe=None if transfer is None else float(transfer[0].real))
        if self._use(grid) or transfer is None:
            transfer = self._transfer(sensor, keep=True, given=given)
        return grid, transfer[1:]

    def _keep(self, sensor: Sensor, grid: LineGrid, transfer: np.ndarray, response: LineResponse) -> None:
        """Keep ``sensor``'s grid, transfer and response, the next evaluation's to start from."""
        self._last = ((sensor.gsd_m, sensor.stages), grid, transfer, response)

    def _use(self, grid: LineGrid) -> bool:
        """Make ``grid``'s frequencies those transfers are computed at
        (the probe's first); whether they changed (the kept transfers then
        dropped)."""
        if self._on == (grid.step_px, grid.size):
            return False
        self._on = (grid.step_px, grid.size)
        f = np.concatenate([[PROBE_CY_PX], grid.frequencies_cy_px]) / self.gsd_m
        self._normal = (f * self._cos, f * self._sin)
        self._transfers.clear()
        return True

    def _transfer(self, sensor: Sensor, keep: bool, given: Given | None = None) -> np.ndarray:
        """The transfer of ``sensor`` along the normal at the probe and the
        current grid's frequencies: the product of its stages' (in their
        order), each taken from those kept when there, else from those
        ``given`` on these frequencies; ``keep`` keeps those computed."""
        values = []
        for stage in sensor.stages:
            key = (stage, sensor.gsd_m)
            kept = self._transfers.pop(key, None)
            ready = (given or {}).get(key)
            if kept is not None:
                value = kept
            elif ready is not None and ready[0] == self._on:
                value = ready[1]
            else:
                value = stage.transfer(*self._normal, sensor.gsd_m)
            if kept is None and keep:
                value.flags.writeable = False
                while len(self._transfers) >= KEPT_TRANSFERS:
                    del self._transfers[next(iter(self._transfers))]
            if kept is not None or keep:
                self._transfers[key] = value        # the latest used last: the first to go is the longest unused
            values.append(value)
        return reduce(operator.mul, values)


#: stages' transfers on an edge's frequencies, each with those frequencies'
#: grid (step, size): {(stage, GSD): ((step, size), transfer)}
Given = dict[tuple[Stage, float], tuple[tuple[float, int], np.ndarray]]


def edges_responses(edges: Sequence[EdgeResponses], sensor: Sensor, given: Sequence[Given] | None = None
                    ) -> list[LineResponse]:
    """Each edge's :meth:`EdgeResponses.response` to ``sensor``, the
    inverse FFTs of the edges whose grids are alike (step and size) made
    in one call over their spectra side by side: each row is what the edge
    alone transforms, bit for bit (each edge's own call cost more than its
    transform, 2048 samples).

    Parameters
    ----------
    edges : sequence of EdgeResponses
        The edges.
    sensor : Sensor
        The sensor.
    given : sequence of dict, optional
        Per edge, the stages' transfers :func:`shared_transfers` made.

    Returns
    -------
    list of LineResponse
        Each edge's response (its last one's when the sensor is its last).

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> together = edges_responses([EdgeResponses(a, 1.0, 20.0) for a in (5.0, 80.0)], Sensor())
    >>> alone = EdgeResponses(80.0, 1.0, 20.0).response(Sensor())
    >>> bool(np.array_equal(together[1].esf_remainder, alone.esf_remainder))
    True
    """
    given = given if given is not None else [{} for _ in edges]
    alike: dict[tuple[float, int], list[tuple[EdgeResponses, LineGrid, np.ndarray]]] = {}
    for edge, g in zip(edges, given):
        made = edge._grid_and_transfer(sensor, g)
        if made is not None:
            alike.setdefault((made[0].step_px, made[0].size), []).append((edge, *made))
    for alike_rows in alike.values():
        for first in range(0, len(alike_rows), STACKED_EDGES):
            rows = alike_rows[first: first + STACKED_EDGES]
            spectra = np.stack([transfer - reference_transfer(own.reference, own.frequencies_cy_px)
                                for _, own, transfer in rows])
            esf, lsf = rows[0][1].remainders(spectra)
            for (edge, own, transfer), e, s in zip(rows, esf, lsf):
                edge._keep(sensor, own, transfer, LineResponse(own.start_px, own.step_px, e, s, own.reference))
    return [edge._base(sensor)[2] for edge in edges]            # each now the last one's, kept


def shared_transfers(edges: Sequence[EdgeResponses], stages: Iterable[Stage], gsd_m: float) -> list[Given]:
    """The transfers of ``stages`` at ``gsd_m`` that ``edges`` do not keep,
    on each edge's current frequencies, in one call per stage for all of
    them (their frequencies concatenated) rather than one per edge: for
    their :meth:`EdgeResponses.response` and :meth:`EdgeResponses.changes`.
    A stage's transfer is the same function of each frequency, so each
    edge's part is what it computes alone, bit for bit.

    Parameters
    ----------
    edges : sequence of EdgeResponses
        The edges (those not evaluated yet have no frequencies: nothing).
    stages : iterable of Stage
        The stages (repeats computed once).
    gsd_m : float
        The sensor's GSD, m.

    Returns
    -------
    list of dict
        Per edge, {(stage, GSD): ((step, size), transfer)}: with the grid
        whose frequencies they are on (an edge whose grid changed before
        it reads them computes its own).

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> edges = [EdgeResponses(angle, 1.0, 20.0) for angle in (5.0, 80.0)]
    >>> _ = [edge.response(Sensor()) for edge in edges]                     # their grids
    >>> wider = Sensor(optics_sigma_x_m=0.5)
    >>> given = shared_transfers(edges, wider.stages, wider.gsd_m)
    >>> [len(g) for g in given]                                               # the optics: not kept
    [1, 1]
    >>> edges[0].response(wider, given[0]).esf(0.3) == EdgeResponses(5.0, 1.0, 20.0).response(wider).esf(0.3)
    np.True_
    """
    out: list[Given] = [{} for _ in edges]
    if len(edges) < 2:
        return out                  # one edge's alone: as it would
    for stage in dict.fromkeys(stages):
        key = (stage, gsd_m)
        lacking = []
        for e, edge in enumerate(edges):
            if edge._on is not None and key not in edge._transfers:
                lacking.append((e, edge._on, edge._normal))
        if len(lacking) < 2:
            continue                # one edge's alone: as it would
        values = stage.transfer(np.concatenate([fx for _, _, (fx, _) in lacking]),
                                np.concatenate([fy for _, _, (_, fy) in lacking]), gsd_m)
        start = 0
        for e, on, (fx, _) in lacking:
            out[e][key] = (on, values[start: start + fx.size])
            start += fx.size
    return out


def esf_changes(response: LineResponse | StackedResponses, esf: np.ndarray, lsf: np.ndarray, d_px: np.ndarray,
                placement: HermitePlacement | None = None) -> np.ndarray:
    """The changes of the edge response (:meth:`EdgeResponses.changes`'
    ``esf_changes``, ``lsf_changes``) at signed distances ``d_px``, one
    row each.

    Parameters
    ----------
    response : LineResponse or StackedResponses
        The response whose grid they are on (or several edges' responses,
        the changes' grids then concatenated, as their remainders are).
    esf, lsf : numpy.ndarray, shape (k, grid size)
        The changes of its ESF and LSF (1/px).
    d_px : numpy.ndarray
        Distances from the edge, px.
    placement : HermitePlacement, optional
        ``d_px`` placed on the response's grid (its ``placement``), when the
        caller has it (the residuals' at the same point); default: placed
        here.

    Returns
    -------
    numpy.ndarray, shape (k, len(d_px))
        The ESF's changes there.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> response, esf, lsf = EdgeResponses(90.0, 1.0, 50.0).changes(Sensor(), [Sensor(motion_m=0.5)])
    >>> esf_changes(response, esf, lsf, np.array([-1.0, 0.0, 1.0])).round(3).tolist()   # wider: slower rise
    [[0.004, 0.0, -0.004]]
    """
    if placement is None:
        placement = response.placement(d_px)
    return placement.interpolate(esf, lsf)


class StackedResponses:
    """Several edges' line responses side by side, each read at its own
    distances: their remainders concatenated and, per distance, its
    edge's grid and reference, so that every edge's distances are placed,
    interpolated and their references added in one pass over all of them
    (bit for bit what each response alone gives).

    Parameters
    ----------
    responses : sequence of LineResponse
        The edges' responses (of one sensor: one kind of reference).
    counts : sequence of int
        How many distances each edge has, in the order they come.
    offsets : sequence of int, optional
        Where each response's grid begins among the grids side by side
        (default: one after the other, in turn).
    remainders : (numpy.ndarray, numpy.ndarray), optional
        Their ESF and LSF remainders so laid out, when the caller has them
        (default: concatenated here).

    Raises
    ------
    ValueError
        Responses with references of different kinds.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> responses = [Sensor().line_response(angle) for angle in (5.0, 80.0)]
    >>> stacked = StackedResponses(responses, [2, 1])
    >>> d = np.array([-0.5, 0.5, 0.5])
    >>> esf, _ = stacked.esf_with_curvature(d, stacked.placement(d, curvature=True))
    >>> esf.tolist() == [*responses[0].esf(d[:2]), *responses[1].esf(d[2:])]
    True
    """

    def __init__(self, responses: Sequence[LineResponse], counts: Sequence[int], offsets: Sequence[int] | None = None,
                 remainders: tuple[np.ndarray, np.ndarray] | None = None):
        kinds = {r.reference[0] for r in responses}
        if len(kinds) != 1:
            raise ValueError(f"the responses' references are of several kinds: {', '.join(sorted(kinds))}")
        self.kind = kinds.pop()
        self.responses, self.counts = list(responses), list(counts)
        if offsets is None:
            sizes = [r.esf_remainder.size for r in self.responses]
            offsets = np.cumsum([0, *sizes[:-1]]).tolist()
        self.offsets = list(offsets)
        self._remainders = remainders

    def _each(self, values: list) -> Any:
        """One value per distance, from one per edge (one for all when they agree)."""
        return values[0] if all(v == values[0] for v in values) else np.repeat(values, self.counts)

    def placement(self, d_px: np.ndarray, curvature: bool = False) -> HermitePlacement:
        """The distances (each edge's, in turn) placed on their edges' grids."""
        sizes = [r.esf_remainder.size for r in self.responses]
        return hermite_placement(self._each([r.start_px for r in self.responses]),
                                 self._each([r.step_px for r in self.responses]), self._each(sizes), d_px,
                                 curvature, self._each(self.offsets))

    def remainders(self) -> tuple[np.ndarray, np.ndarray]:
        """The responses' ESF and LSF remainders side by side (each at its offset)."""
        if self._remainders is None:
            self._remainders = (np.concatenate([r.esf_remainder for r in self.responses]),
                                np.concatenate([r.lsf_remainder for r in self.responses]))
        return self._remainders

    def esf(self, d_px: np.ndarray) -> np.ndarray:
        """Each edge's :meth:`LineResponse.esf` at its distances, in turn."""
        d = np.asarray(d_px, float)
        value = self.placement(d).interpolate(*self.remainders())
        return plus_reference_esf(value, self.kind, self._each([r.reference[1] for r in self.responses]), d)

    def esf_with_curvature(self, d_px: np.ndarray,
                           placement: HermitePlacement | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Each edge's :meth:`LineResponse.esf_with_curvature` at its distances, in turn."""
        d = np.asarray(d_px, float)
        if placement is None:
            placement = self.placement(d, curvature=True)
        value, curvature = placement.interpolate(*self.remainders(), curvature=True)
        width = self._each([r.reference[1] for r in self.responses])
        scale = self._each([reference_scale(r.reference) for r in self.responses])
        return (plus_reference_esf(value, self.kind, width, d),
                plus_reference_curvature(curvature, self.kind, width, scale, d))

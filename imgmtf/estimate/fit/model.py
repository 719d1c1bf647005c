"""The model fitted: the sensor's stages in fit coordinates, each edge's
nuisance levels and offset, residuals, Jacobian, covariance and the
model's MTF with its delta-method band.

The residuals are those of each edge's fine bins along its normal
(:func:`.data.bin_profile`): a bin of n samples, mean distance x̄ and
value ȳ and distances' variance m2 gives

    r = sqrt(n) (ȳ - L - (R - L) (ESF(x̄ - x0) + ESF''(x̄ - x0) m2 / 2)) / noise,

the mean of the model over its samples to the third order.  Weighted by
sqrt(n), the sum of r^2 (:meth:`Model.chi_square`, what the fit
minimises) is the samples' chi-square less their residuals' scatter
within the bins, which the parameters move by about a percent or less of
what they move the bins' part (the model's change across a bin, 1/32 px,
against its change across the edge): the optimum and the likelihood-ratio
costs are the samples'.  The reduced chi-square, which scales the
covariance, is the samples' own (:meth:`Model.sample_chi_squares`, over
samples - parameters degrees of freedom).  The bins' alone would not do:
the scatter within a bin is noise, about n - 1 variances, but a misfit's
structure is in the bins' part whole, so over bins - parameters it would
read n (the samples per bin, 3-9) times the samples' excess, as much
larger as the bins are finer."""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...errors import ImgmtfError, ParameterError
from ...sensor.lines import LineResponse
from ...sensor.model import PAPER_STAGES, Sensor
from ...sensor.stages import STAGES, Stage
from .angles import grid_layout, grouped_edges, laid_out_changes
from .arrowhead import NoConvergence, solve_arrowhead
from .choice import AUTO, AUTO_CANDIDATES
from .data import EdgeData, ProfileBins, bin_esf
from .responses import EdgeResponses, StackedResponses, edges_responses, esf_changes, shared_transfers

#: a free parameter is undetermined when its 1-SE range of blur length is
#: wider than this fraction of the length ...
DETERMINED_RELATIVE = 0.5
#: ... and than this many pixels
DETERMINED_PX = 0.2
#: up to this many edges the Jacobian is dense (see :attr:`Model.sparse`):
#: with binned profiles the fits of 4 to 16 of the chart's 300-row edges
#: (bench's scan chart) cost the same either way at 8 edges (0.169 s dense,
#: 0.163 s sparse), dense 10 % less at 4-6, sparse 15-35 % less at 12-16
DENSE_EDGES = 8
#: a few edges' fits solved by ours: a target's (4+ half-edges, <= 4 stage parameters); with more parameters
#: (Baotou's target 1) or fewer edges (one chip) the optimum reached followed the solver's path
OWN_SOLVER_FREE, OWN_SOLVER_EDGES = 4, 4


def stage_names(names, start: Sensor | None) -> list[str]:
    if names is None:
        names = [s.name for s in start.stages] if start is not None else list(PAPER_STAGES)
    elif isinstance(names, str):
        names = [n.strip() for n in names.split(",") if n.strip()]
    names = listed("stages", names)
    if not names:
        raise ParameterError("no stages to fit")
    for name in names:
        if name not in STAGES:
            raise ParameterError(f"unknown stage {name!r}; known: {', '.join(STAGES)}")
        if not STAGES[name].fit_specs():        # a measured MTF: a table, not a model's parameters
            raise ParameterError(f"stage {name!r} has no parameter to fit")
    if len(set(names)) != len(names):
        raise ParameterError(f"a stage is named twice in {', '.join(names)}")
    return names


def listed(name: str, values, kinds: str = "names, or one comma-separated string") -> list:
    """``values`` as a list; a ParameterError naming ``name`` when it is no collection (None, 3)."""
    try:
        return list(values)
    except TypeError:
        raise ParameterError(f"{name} must be a list of {kinds}, got {values!r}") from None


def initial_stages(names: list[str], start: Sensor | None, gsd: float) -> list[Stage]:
    given = {s.name: s for s in (start.stages if start is not None else ())}
    out = []
    for name in names:
        if name in given:
            out.append(given[name])
        else:  # the defaults are for a 1 m GSD: the same blur in pixels
            default = STAGES[name]()
            out.append(default.with_fit_coordinates(default.fit_coordinates(1.0), gsd))
    return out


def check_names(stages: str | Sequence[str] | None = None, hold: str | Sequence[str] = (),
                start: Sensor | None = None) -> list[str]:
    """The stages a fit frees, and the parameters it holds, checked before
    any data are read (the CLI's --stages and --hold: a usage error).

    Parameters
    ----------
    stages : str or sequence of str, optional
        Stage names to fit, as :func:`imgmtf.fit_sensor` takes them
        (``"auto"`` included).
    hold : str or sequence of str, optional
        Parameters held: "stage" or "stage.name".
    start : Sensor, optional
        The starting sensor, whose stages are fitted when ``stages`` is None.

    Returns
    -------
    list of str
        The stages' names (``["auto"]`` for the model the data choose).

    Raises
    ------
    ParameterError
        An unknown stage, one named twice, or a held name that is no
        fitted stage or parameter.

    Examples
    --------
    >>> check_names("optics,detector", "detector.width_x_m")
    ['optics', 'detector']
    """
    if is_auto(stages):
        check_auto_hold(hold)
        return ["auto"]
    names = stage_names(stages, start)
    hold_keys(hold, [f"{name}.{parameter}" for name in names for parameter in STAGES[name].fit_specs()])
    return names


def is_auto(stages) -> bool:
    """Whether ``stages`` asks for the model chosen by the data (:mod:`.choice`)."""
    return isinstance(stages, str) and stages.strip() == AUTO


def check_auto_hold(hold) -> None:
    """With ``auto``, a held name must name a parameter of some candidate."""
    keys = sorted({f"{name}.{parameter}" for candidate in AUTO_CANDIDATES for name in candidate
                   for parameter in STAGES[name].fit_specs()})
    hold_keys(hold, keys)


def hold_keys(hold, fitted: list[str]) -> set[str]:
    if isinstance(hold, str):
        hold = [h.strip() for h in hold.split(",") if h.strip()]
    keys = set()
    for item in listed("hold", hold):
        matches = [k for k in fitted if k == item or k.split(".")[0] == item]
        if not matches:
            raise ParameterError(f"cannot hold {item!r}: not a fitted stage or parameter; "
                                 f"fitted: {', '.join(fitted)}")
        keys.update(matches)
    return keys


class Model:
    """The shared stage parameters and each edge's nuisance parameters as
    one vector z = [free stage coordinates, then L, R, x0 per edge]."""

    def __init__(self, gsd: float, stages: list[Stage], data: list[EdgeData], held_at: list[Stage] | None = None):
        self.gsd, self.stages, self.data = gsd, stages, data
        self.specs, self.keys, self.units = {}, [], {}
        for stage in stages:
            for name, spec in stage.fit_specs().items():
                key = f"{stage.name}.{name}"
                self.specs[key] = spec
                self.keys.append(key)
                self.units[key] = stage.units()[name]
        # each stage's parameters: (key, name), in the order the coordinates are
        self._stage_keys = [[(f"{stage.name}.{name}", name) for name in stage.fit_specs()] for stage in stages]
        self.start = {k: v for s in stages for k, v in stage_coordinates(s, gsd).items()}
        # where a held parameter is held: its start, but for a stage started from the data (a lag's
        # lean, :mod:`.seeds`), the value it had before (none): a guess is no value to hold
        self.held_at = dict(self.start) if held_at is None else {
            k: v for s in held_at for k, v in stage_coordinates(s, gsd).items()}
        # a bin's residual weight: its mean's noise is noise / sqrt(count)
        self.weights = [np.sqrt(d.bins.count) / d.noise for d in data]
        self.counts = [d.bins.x.size for d in data]
        self.starts = np.cumsum([0, *self.counts[:-1]]).tolist()      # each edge's first bin among all
        self._stacked_bins: tuple[ProfileBins, np.ndarray] | None = None
        self._layout: tuple = (None, None, None)
        self.values = dict(self.held_at)         # coordinates of held parameters live here
        self.ties: dict[str, str] = {}
        self.free = list(self.keys)
        self._last_responses: tuple = (None, [], None)
        # each edge's grids, transfers and last response, kept across evaluations (and shared by copies)
        self.edges = [EdgeResponses(d.profile_angle_deg, d.gsd_m, self.reach(d)) for d in data]
        # many edges at nearby tilts: their responses interpolated from a few tilts' (:mod:`.angles`)
        self.groups, self.own = grouped_edges([d.profile_angle_deg for d in data], [d.gsd_m for d in data],
                                              [self.reach(d) for d in data])
        self._last_esfs: tuple = (None, None, None)
        # the responses and ESFs at the last Jacobian's point (:meth:`jacobian`)
        self._solution: tuple = ((None, [], None), (None, None, None))
        self._last_samples: tuple = (None, [])
        self._stages_made: dict[tuple, Stage] = {}
        self._sensor_gsd: float | None = None

    # -- which parameters are free ------------------------------------------------
    def screen_axes(self, held: set[str]) -> dict[str, tuple[str, str]]:
        """Tie or hold what no edge's axis constrains; hold ``held``."""
        notes = {k: ("held", "held by request at its starting value") for k in held}
        seen = {"across" if axis == "x" else "along" for axis in self.seen_axes()}
        axis_of = {"x": "across", "y": "along"}
        for key, spec in self.specs.items():
            if key in held or spec.axis == "xy" or axis_of[spec.axis] in seen:
                continue
            twin = f"{key.split('.')[0]}.{spec.pair}" if spec.pair else next(
                (k for k, s in self.specs.items() if s.pair and f"{k.split('.')[0]}.{s.pair}" == key), None)
            if twin and twin not in held:
                self.ties[key] = twin
                notes[key] = ("tied", f"no {axis_of[spec.axis]}-track edge: taken equal to {twin}")
            else:
                notes[key] = ("held", f"no {axis_of[spec.axis]}-track edge: held at its starting value")
        self.free = [k for k in self.keys if k not in notes]
        return notes

    def copy(self) -> Model:
        other = object.__new__(Model)
        other.__dict__.update(self.__dict__)
        other.values, other.ties, other.free = dict(self.values), dict(self.ties), list(self.free)
        return other

    def seen_axes(self) -> set[str]:
        """Image axes some edge mostly constrains: "x" (across), "y" (along)."""
        return {"x" if abs(d.normal_angle_deg) < 45 else "y" for d in self.data}

    def covers_axes(self, free: list[str]) -> bool:
        """Whether parameters ``free`` (with those tied to them) act on every
        axis an edge sees."""
        axes: set[str] = set()
        for key in free:
            for k in [key] + [t for t, source in self.ties.items() if source == key]:
                axes.update(("x", "y") if self.specs[k].axis == "xy" else (self.specs[k].axis,))
        return self.seen_axes() <= axes

    def hold(self, z: np.ndarray, index: int, covariance: np.ndarray | None = None) -> np.ndarray:
        """Hold free parameter ``index`` at its starting value; ``z`` without
        it.  With the fit's ``covariance`` the others move to their
        linearised optimum given the held value (each by its regression on
        the held one), the refit's starting point: a few steps from its end."""
        key = self.free.pop(index)
        if covariance is not None and covariance[index, index] > 0:
            z = z + covariance[:, index] / covariance[index, index] * (self.held_at[key] - z[index])
        self.values[key] = self.held_at[key]
        return np.delete(z, index)

    @property
    def n_free(self) -> int:
        return len(self.free)

    @property
    def rows(self) -> int:
        """The residuals: every edge's bins."""
        return sum(d.bins.x.size for d in self.data)

    @property
    def dof(self) -> int:
        """Degrees of freedom of the samples' chi-square: samples - parameters."""
        return sum(d.x.size for d in self.data) - self.n_free - 3 * len(self.data)

    def initial_vector(self) -> np.ndarray:
        """The starting vector: the free parameters' starting coordinates,
        then each edge's measured levels and zero offset."""
        return np.array([self.start[k] for k in self.free] + [v for d in self.data for v in (*d.levels, 0.0)], float)

    def bounds(self):
        upper = [self.specs[k].upper_px ** self.specs[k].power for k in self.free]
        big = np.inf
        lower = [self.specs[k].lower for k in self.free] + [-big] * (3 * len(self.data))
        return np.array(lower), np.array(upper + [big] * (3 * len(self.data)))

    def sensor(self, u: np.ndarray) -> Sensor:
        coords = dict(self.values)
        coords.update(zip(self.free, u))
        for key, twin in self.ties.items():
            coords[key] = coords[twin]
        stages = []
        if len(self._stages_made) > 1024:
            self._stages_made.clear()
        for index, stage in enumerate(self.stages):
            own = {name: float(coords[key]) for key, name in self._stage_keys[index]}
            if not own:
                stages.append(stage)
                continue
            # a Jacobian's shifts change one stage each: the others are made once
            made = (index, *own.items())
            if made not in self._stages_made:
                self._stages_made[made] = stage.with_fit_coordinates(own, self.gsd)
            stages.append(self._stages_made[made])
        if self._sensor_gsd is None:           # the first sensor checked; the next ones of the same GSD and stages
            sensor = Sensor(self.gsd, stages)
            self._sensor_gsd = sensor.gsd_m
            return sensor
        return checked_sensor(self._sensor_gsd, tuple(stages))

    def responses(self, u: np.ndarray) -> list[LineResponse]:
        """Each edge's line response for stage coordinates ``u``; the last
        ones kept, since the solver asks for the residuals and then the
        Jacobian at the same point."""
        key = (tuple(self.free), u.tobytes())
        if self._last_responses[0] != key and self._solution[0][0] == key:
            self._last_responses = self._solution[0]
        if self._last_responses[0] != key:
            sensor = self.sensor(u)
            out: list = [None] * len(self.edges)
            for members, group in self.groups:
                for i, response in zip(members, group.responses(sensor)):
                    out[i] = response
            own = [self.edges[i] for i in self.own]
            for i, response in zip(self.own, edges_responses(own, sensor, shared_transfers(own, sensor.stages,
                                                                                           sensor.gsd_m))):
                out[i] = response
            self._last_responses = (key, out, grid_layout(self.groups, self.own, sensor, out) if self.groups else None)
        return self._last_responses[1]

    def release(self) -> None:
        """Drop what the evaluations keep (each edge's grids, transfers
        and responses, the last responses, ESFs, samples' residuals and
        stages made, the edges' bins side by side and the Jacobian's
        layout), which a finished fit no longer uses: what it still asks
        (:func:`.bands.model_mtf_band`, the sensor's transfer) is made afresh.  The
        model evaluates as before, computing them again."""
        for edge in self.edges:
            edge.release()
        for _, group in self.groups:
            group.release()
        self._last_responses = (None, [], None)
        self._last_esfs = (None, None, None)
        self._solution = ((None, [], None), (None, None, None))
        self._last_samples = (None, [])
        self._stages_made.clear()
        self._stacked_bins = None
        self._layout = (None, None, None)

    @property
    def bins(self) -> ProfileBins:
        """Every edge's bins in turn (the residuals' order), evaluated in one
        pass; made when first asked, and again after :meth:`release`."""
        return self._stack_bins()[0]

    @property
    def weight(self) -> np.ndarray:
        """Every edge's bins' residual weights in turn."""
        return self._stack_bins()[1]

    def _stack_bins(self) -> tuple[ProfileBins, np.ndarray]:
        if self._stacked_bins is None:
            self._stacked_bins = (ProfileBins(*(np.concatenate([getattr(d.bins, name) for d in self.data])
                                                for name in ("count", "x", "y", "m2"))),
                                  np.concatenate(self.weights))
        return self._stacked_bins

    @staticmethod
    def reach(d: EdgeData) -> float:
        """How far from the edge its line response must be exact, px."""
        return float(np.abs(d.x).max()) + 2.0

    # -- least squares ------------------------------------------------------------
    def residuals(self, z: np.ndarray, responses=None) -> np.ndarray:
        u = z[: self.n_free]
        lo, hi, x0 = self.levels(z)
        responses = responses or self.responses(u)
        key = (tuple(self.free), z.tobytes())
        if self._solution[1][0] == key and self._last_responses[1] is responses:
            esf, placement = self._solution[1][1:]          # the last Jacobian's point: the solution's, asked again
        else:
            stacked = self.stacked(responses)
            placement = stacked.placement(self.bins.x - x0, curvature=True)
            esf = bin_esf(stacked, self.bins, x0, placement)
        # the solver asks for the Jacobian where it last asked for the residuals: their ESFs are its
        # columns', and their bins' places on the grids those of the changes
        self._last_esfs = (key, esf, placement)
        return self.weight * (self.bins.y - (lo + (hi - lo) * esf))

    def stacked(self, responses: list[LineResponse]) -> LineResponse | StackedResponses:
        """The edges' responses side by side, for their bins in turn (one edge's alone)."""
        return responses[0] if len(responses) == 1 else StackedResponses(responses, self.counts,
                                                                         *self._laid_out(responses))

    def _laid_out(self, responses: list[LineResponse]) -> tuple:
        """Where ``responses``' grids lie side by side, and their remainders, when some are a group's."""
        layout = self._last_responses[2] if self._last_responses[1] is responses else None
        return (layout.offsets, layout.remainders) if layout is not None else ()

    def levels(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each bin's edge's levels L and R (DN) and offset x0 (px) in ``z``
        (:meth:`per_bin`)."""
        lo, hi, x0 = (self.per_bin(z[self.n_free + j::3]) for j in range(3))
        return lo, hi, x0

    def per_bin(self, values: np.ndarray) -> np.ndarray:
        """One row per bin of ``values``' one per edge: each edge's repeated
        over its bins; one edge's as it is (broadcast over them)."""
        return values if len(self.counts) == 1 else np.repeat(values, self.counts, axis=0)

    def side_by_side(self, arrays: list[np.ndarray]) -> np.ndarray:
        """Each edge's ``arrays`` (by bin or grid sample, on the last axis) joined in turn."""
        return arrays[0] if len(arrays) == 1 else np.concatenate(arrays, axis=-1)

    def jacobian(self, z: np.ndarray):
        """The residuals' Jacobian at ``z``, sparse: the stage columns by
        forward differences of each edge's response (all shifts in one
        inverse FFT on the grid of the residuals' response,
        :meth:`.responses.EdgeResponses.changes`), the levels' and
        offset's columns exact.  The stage and offset columns leave out the
        bins' m2 term (:func:`bin_esf`), ESF'' m2 / 2: its changes are about
        m2 / s^2 of the ESF's (s the LSF's width; m2 at most w^2 / 4 for
        bins w = 1/32 px wide, w^2 / 12 where samples spread evenly), under
        0.2 % for s over 0.4 px.  The Jacobian is off by that fraction,
        which costs no iteration, and moves the point where the solver
        stops (where the approximate gradient of the exact residuals
        vanishes) by about that fraction of a standard error."""
        u = z[: self.n_free]
        _, upper = self.bounds()
        steps = np.empty(self.n_free)
        shifted = []
        for k in range(self.n_free):
            h = 1e-3 * max(u[k], 0.05 * upper[k] ** 0.5)
            steps[k] = -h if u[k] + h > upper[k] else h
            moved = u.copy()
            moved[k] += steps[k]
            shifted.append(self.sensor(moved))
        sensor = self.sensor(u)
        base = self.responses(u)
        esf_change, lsf_change = self._changes(sensor, shifted)
        lo, hi, x0 = self.levels(z)
        d = self.bins.x - x0
        stacked = self.stacked(base)
        if self._last_esfs[0] == (tuple(self.free), z.tobytes()):
            esf, placement = self._last_esfs[1:]
        else:
            placement = stacked.placement(d, curvature=True)
            esf = bin_esf(stacked, self.bins, x0, placement)
        # the solver stops at the last point it took a Jacobian at, where the covariance, the chi-square
        # and the report ask for the responses and residuals again after the rejected trials that followed
        self._solution = (self._last_responses, ((tuple(self.free), z.tobytes()), esf, placement))
        changes = esf_changes(stacked, esf_change, lsf_change, d, placement)
        spans = z[self.n_free + 1::3] - z[self.n_free::3]
        lsf = self.side_by_side([r.lsf(d[start: start + count])
                                 for r, start, count in zip(base, self.starts, self.counts)])
        # each row's stage columns, then its edge's levels' and offset's, written in place (a sparse
        # Jacobian's values as they are laid out, :meth:`_jacobian_layout`)
        n = self.n_free
        values = np.empty((self.rows, n + 3))
        np.multiply(changes.T * self.weight[:, None], self.per_bin(-spans[:, None] / steps), out=values[:, :n])
        np.multiply(esf - 1, self.weight, out=values[:, n])
        np.multiply(-esf, self.weight, out=values[:, n + 1])
        np.multiply((hi - lo) * self.weight, lsf, out=values[:, n + 2])
        columns = n + 3 * len(self.counts)
        if not self.sparse:
            jacobian = np.zeros((self.rows, columns))
            jacobian[:, :n] = values[:, :n]
            for e, (start, count) in enumerate(zip(self.starts, self.counts)):
                rows, first = slice(start, start + count), n + 3 * e
                jacobian[rows, first: first + 3] = values[rows, n:]
            return jacobian
        from scipy import sparse
        indices, starts = self._jacobian_layout()
        return sparse.csr_array((values.ravel(), indices.ravel(), starts), shape=(self.rows, columns))

    def _changes(self, sensor: Sensor, shifted: list[Sensor]) -> tuple[np.ndarray, np.ndarray]:
        """Every edge's ESF and LSF changes for each ``shifted`` sensor, grids
        side by side (:meth:`stacked`): each edge's inverse FFT written in
        its place (the responses at ``sensor`` made before)."""
        responses, layout = self._last_responses[1:]
        sizes = [r.esf_remainder.size for r in responses]
        offsets = layout.offsets if layout is not None else np.cumsum([0, *sizes[:-1]]).tolist()
        out = np.empty((2, len(shifted), layout.size if layout is not None else sum(sizes)))
        own = [self.edges[i] for i in self.own]
        given = shared_transfers(own, [stage for other in shifted for stage in other.stages], sensor.gsd_m)
        for i, edge, g in zip(self.own, own, given):
            edge.changes(sensor, shifted, g, out[:, :, offsets[i]: offsets[i] + sizes[i]])
        if self.groups:
            laid_out_changes(self.groups, sensor, shifted, out)
        return out[1], out[0]

    def _jacobian_layout(self) -> tuple[np.ndarray, np.ndarray]:
        """Each row's columns in a sparse Jacobian, the stage columns then
        its edge's levels' and offset's (which act on its own bins only),
        and where each row starts among them: its compressed rows, written
        directly (its size grows with the edges, not with their square);
        made once for the free parameters; 32-bit where they fit (a quarter less to read)."""
        if self._layout[0] != self.n_free:
            nuisance = np.repeat(self.n_free + 3 * np.arange(len(self.counts)), self.counts)[:, None] + np.arange(3)
            indices = np.hstack([np.broadcast_to(np.arange(self.n_free), (nuisance.shape[0], self.n_free)), nuisance])
            kind = np.int32 if indices.size < np.iinfo(np.int32).max else np.intp
            self._layout = (self.n_free, indices.astype(kind),
                            np.arange(0, indices.size + 1, indices.shape[1], dtype=kind))
        return self._layout[1:]

    @property
    def sparse(self) -> bool:
        """Whether the Jacobian is sparse (its arrowhead normal matrix
        solved by blocks, :mod:`.arrowhead`): with many edges.  A few
        edges' dense Jacobian costs about the same (least squares then
        solves it exactly, by its SVD)."""
        return len(self.data) > DENSE_EDGES

    def solve(self, z: np.ndarray, max_iterations: int = 200):
        """Bounded least squares from ``z`` with :meth:`jacobian`, by
        Levenberg-Marquardt steps solved exactly over the arrowhead normal
        matrix (:func:`.arrowhead.solve_arrowhead`): many edges' (a sparse
        Jacobian) to its own tight end, a few edges' of at most
        :data:`OWN_SOLVER_FREE` stage parameters and at least
        :data:`OWN_SOLVER_EDGES` edges (a target's optics and detector)
        stopped where an accepted step lowers the cost by less
        than 1e-9 of it, as SciPy's trust region did (its overhead was a
        quarter of a target's solve).  Other few edges' fits, and those
        it cannot finish, go to SciPy's
        trust-region reflective ``least_squares`` (the columns scaled by
        their norms), which refuses as before.  Returns the solution and
        its Jacobian.

        Raises
        ------
        ImgmtfError
            No convergence within ``max_iterations`` Jacobians.
        """
        lower, upper = self.bounds()
        z = np.clip(z, lower, upper)
        ours = self.sparse or (self.n_free <= OWN_SOLVER_FREE and len(self.data) >= OWN_SOLVER_EDGES)
        if max_iterations > 0 and ours:
            try:
                return solve_arrowhead(self.residuals, self.jacobian, z, self.n_free, self.counts, lower, upper,
                                       max_iterations, layout=self._jacobian_layout()[0] if self.sparse else None,
                                       ftol=None if self.sparse else 1e-9)
            except NoConvergence:
                pass
        if max_iterations > 0 and not self.sparse:
            # a few edges' fit not ours, or one ours could not finish: SciPy's, which refuses as before
            from scipy.optimize import least_squares
            result = least_squares(self.residuals, z, jac=self.jacobian, bounds=(lower, upper), method="trf",
                                   x_scale="jac", ftol=1e-9, xtol=1e-10, gtol=1e-10, max_nfev=max_iterations)
            if result.status > 0:
                return result.x, result.jac
        raise ImgmtfError(f"the fit of {', '.join(s.name for s in self.stages)} did not converge in "
                          f"{max_iterations} iterations; try fewer stages or hold some",
                          reason="fit")

    def chi_square(self, z: np.ndarray) -> float:
        """The bins' chi-square at ``z``: what the fit minimises, and whose
        changes are the likelihood-ratio costs."""
        return float(np.sum(self.residuals(z) ** 2))

    def sample_residuals(self, z: np.ndarray) -> list[np.ndarray]:
        """Each edge's samples' (not bins') residuals at ``z``, data - model
        (DN), in the order of its samples: the model evaluated at every
        sample once (the last ``z``'s kept: the fit's covariance and its
        report ask at the same point)."""
        key = (tuple(self.free), z.tobytes())
        if self._last_samples[0] != key:
            responses = self.responses(z[: self.n_free])
            counts = [d.x.size for d in self.data]
            lo, hi, x0 = (np.repeat(z[self.n_free + j::3], counts) for j in range(3))
            x, y = (np.concatenate([getattr(d, name) for d in self.data]) for name in ("x", "y"))
            # every edge's samples in one pass, each as its own response gives it (:class:`StackedResponses`)
            stacked = StackedResponses(responses, counts, *self._laid_out(responses))
            residuals = y - lo - (hi - lo) * stacked.esf(x - x0)
            self._last_samples = (key, np.split(residuals, np.cumsum(counts)[:-1]))
        return self._last_samples[1]

    def sample_chi_squares(self, z: np.ndarray) -> np.ndarray:
        """Each edge's chi-square of its samples (not bins) at ``z``
        (:meth:`sample_residuals` over the edge's noise)."""
        return np.array([float(np.sum((r / d.noise) ** 2)) for d, r in zip(self.data, self.sample_residuals(z))])

    def reduced_chi_square(self, z: np.ndarray) -> float:
        """The samples' chi-square at ``z`` per degree of freedom."""
        return float(np.sum(self.sample_chi_squares(z)) / max(self.dof, 1))

    def undetermined(self, z: np.ndarray, covariance: np.ndarray) -> dict[int, float]:
        """Index -> 1-SE range (px of blur length) of each free parameter
        the data do not determine."""
        out = {}
        for i, key in enumerate(self.free):
            power = self.specs[key].power
            u, se = z[i], math.sqrt(max(covariance[i, i], 0.0))
            if power == 1:              # a length or share taken as it is (a signed one included)
                length, width = abs(u), se
            else:
                length = u ** (1 / power)
                width = ((u + se) ** (1 / power) - max(u - se, 0.0) ** (1 / power)) / 2
            if not np.isfinite(width) or width > max(DETERMINED_RELATIVE * length, DETERMINED_PX):
                out[i] = width if np.isfinite(width) else math.inf
        return out


def stage_coordinates(stage: Stage, gsd: float) -> dict[str, float]:
    return {f"{stage.name}.{k}": v for k, v in stage.fit_coordinates(gsd).items()}


def checked_sensor(gsd_m: float, stages: tuple[Stage, ...]) -> Sensor:
    """The sensor of a GSD and stages the constructor has checked (a sensor's ``gsd_m``, Stage objects),
    made without checking them again: what a fit makes at its every evaluation."""
    sensor = object.__new__(Sensor)
    object.__setattr__(sensor, "gsd_m", gsd_m)
    object.__setattr__(sensor, "stages", stages)
    return sensor

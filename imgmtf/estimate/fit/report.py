"""The fit reported: parameters with their standard errors, correlations,
each edge's misfit test, the MTF across and along track."""
from __future__ import annotations

import math

import numpy as np

from ...metrics import first_crossing
from ...sensor.model import DIRECTIONS, Sensor, check_angle, direction_angle
from ...sensor.stages import Stage
from ..geometry import direction_label
from .bands import (
    MTF50_FIRST,
    MTF50_GRID_CY_PX,
    band_sensors,
    delta_band,
    model_nyquist_mtf50_bands,
    sensor_transfers,
)
from .choice import other_stages
from .model import Model
from .responses import StackedResponses
from .results import EdgeFit, FittedParameter, SensorFit

#: residual bins along the normal (px) for the misfit test
MISFIT_BIN_PX = 0.25
#: parameter pairs reported when their correlation exceeds this
HIGH_CORRELATION = 0.9


def fit_report(model: Model, z: np.ndarray, covariance: np.ndarray, notes: dict, confidence: float) -> SensorFit:
    n = model.n_free
    u = z[:n]
    sensor = model.sensor(u)
    start = model.sensor(np.array([model.start[k] for k in model.free]))
    responses = model.responses(u)
    residuals = model.residuals(z, responses)
    reduced = model.reduced_chi_square(z)
    sample_chi_squares = model.sample_chi_squares(z)
    sample_residuals = model.sample_residuals(z)
    warnings = []

    parameters = []
    _, upper = model.bounds()
    for stage in sensor.stages:
        units = stage.units()
        for name, value in stage.to_dict(include_name=False).items():
            key = f"{stage.name}.{name}"
            if key in model.free:
                i = model.free.index(key)
                se = value_error(stage, name, u[i], math.sqrt(max(covariance[i, i], 0.0)), model.gsd)
                status, note = "fitted", ""
                if u[i] >= upper[i] * (1 - 1e-6):
                    note = "at the bound of its range"
                    warnings.append(f"{key} is at the bound of its range ({value:.4g} {units[name]}): the model "
                                    "strains to fit the edges, whose blur may have another form; its MTF may be "
                                    f"biased: {other_stages(model.stages)}")
            elif key in notes:
                se, (status, note) = math.nan, notes[key]
            else:  # a parameter the fit does not touch (wavelength, pitch)
                se, status, note = math.nan, "held", "not fitted"
            parameters.append(FittedParameter(stage.name, name, float(value), float(se), units[name], status, note))

    correlations = []
    if n > 1:
        sd = np.sqrt(np.maximum(np.diag(covariance)[:n], 1e-300))
        corr = covariance[:n, :n] / np.outer(sd, sd)
        for i in range(n):
            for j in range(i + 1, n):
                if abs(corr[i, j]) > HIGH_CORRELATION:
                    correlations.append((model.free[i], model.free[j], float(corr[i, j])))

    edges, start_row = [], 0
    reaches = misfit_reaches(model, responses)
    stepped = band_sensors(model, u)
    nyquist_bands, model_mtf50s = edge_model_mtfs(model, u, covariance, stepped, confidence)
    for e, (d, r) in enumerate(zip(model.data, responses)):
        lo, hi, x0 = z[n + 3 * e: n + 3 * e + 3]
        bins = d.bins
        res = residuals[start_row: start_row + bins.x.size] / model.weights[e]   # bin means' data - model, DN
        start_row += bins.x.size
        chi = float(sample_chi_squares[e] / max(d.x.size - 3 - n / len(model.data), 1))
        # on the samples: the fit's bins, formed before x0 was known, straddle the misfit test's
        p, fraction = misfit_test(d.x - x0, sample_residuals[e], d.noise, abs(hi - lo), r, float(reaches[e]))
        value, low, high = nyquist_bands[:, e]
        measured = d.measurement
        edge = EdgeFit(d.source, d.normal_angle_deg, direction_label(d.normal_angle_deg, 0.0),
                       "across" if abs(d.normal_angle_deg) < 45 else "along", d.gsd_m,
                       int(measured.rows_used), float(measured.snr), float(value), (float(low), float(high)),
                       float(model_mtf50s[e]),
                       float(np.interp(0.5, measured.frequencies_cy_px, measured.mtf)), d.noise, float(hi - lo),
                       (float(lo), float(hi)), float(x0), chi, p, fraction, bins.x, res, bins.count, measured)
        edges.append(edge)
        if not edge.misfit_tested:
            warnings.append(f"{d.source}: the misfit test could not run on this edge (no {MISFIT_BIN_PX:g} px bin "
                            "of its residuals over the transition holds 3 samples): whether the model fits it is "
                            "not known")
        elif edge.misfit:
            warnings.append(f"{d.source}: the model does not fit this edge: its residuals are structured "
                            f"along the normal ({100 * fraction:.2f} % of the step, p = {p:.1g}); its MTF may be "
                            f"biased: {other_stages(model.stages)}")

    if not model.covers_axes(model.free):
        warnings.append("no parameter acting on every axis an edge sees could be determined: the MTF there is "
                        "the starting sensor's; give more or sharper edges, or other stages")
    seen = {e.constrains for e in edges}
    directions = {}
    for direction in DIRECTIONS:
        angle = direction_angle(direction)
        (value, low, high), mtf50, mtf50_ci = model_nyquist_mtf50_bands(model, u, covariance, angle, model.gsd,
                                                                         confidence, stepped)
        directions[direction] = {"mtf_nyquist": float(value), "mtf_nyquist_ci": [float(low), float(high)],
                                 "mtf50_cy_px": mtf50, "mtf50_cy_px_ci": list(mtf50_ci),
                                 "constrained": direction in seen}
        if direction not in seen:
            warnings.append(f"no {direction}-track edge: the {direction}-track MTF is an extrapolation "
                            "of the model (tied and held parameters)")
    if not any(d.gsd_known for d in model.data):
        warnings.append(f"no GSD in the inputs: lengths are in units of {model.gsd:g} m per pixel "
                        "(at 1 m, metres are pixels); give the GSD for lengths on the ground")
    # the fit's caches (each edge's line responses: most of a pickled fit) serve no later question
    model.release()
    return SensorFit(sensor, start, tuple(parameters), tuple(correlations), reduced, tuple(edges), directions,
                     confidence, tuple(warnings), model, u, covariance)


#: edges whose model MTFs :func:`edge_model_mtfs` computes in one array (rows of 4001 frequencies)
EDGE_CHUNK = 64


def edge_model_mtfs(model: Model, u: np.ndarray, covariance: np.ndarray,
                    sensors: tuple[Sensor, list[tuple[float, Sensor]]], confidence: float,
                    chunk: int = EDGE_CHUNK) -> tuple[np.ndarray, np.ndarray]:
    """Each of ``model``'s edges' model MTF at Nyquist (0.5 cy/px) along
    its normal with its delta-method band, and its model MTF50 (cy/px):
    what :func:`.bands.model_mtf_band` and :func:`imgmtf.metrics.first_crossing`
    give edge by edge, the same numbers, with the transfers of many edges
    computed in one array (a scene's thousands of edges: one call per
    stage and chunk of edges, not per edge).

    Parameters
    ----------
    model : Model
        The fitted model.
    u : numpy.ndarray
        Its free stage coordinates.
    covariance : numpy.ndarray
        Their covariance (its first ``model.n_free`` rows and columns).
    sensors : tuple
        :func:`.bands.band_sensors` of ``model`` and ``u``.
    confidence : float
        The band's confidence level.
    chunk : int, optional
        Edges per array of MTF50 frequencies (default :data:`EDGE_CHUNK`).

    Returns
    -------
    bands : numpy.ndarray, shape (3, edges)
        The MTF at Nyquist, its band's lower and upper bounds.
    mtf50 : numpy.ndarray, shape (edges,)
        The model's MTF50 along each edge's normal, cy/px (NaN where it
        stays above 0.5 up to 2 cy/px).

    Examples
    --------
    >>> import imgmtf as im
    >>> from imgmtf.estimate.fit.bands import band_sensors
    >>> from imgmtf.estimate.fit.data import edge_data
    >>> from imgmtf.estimate.fit.model import Model, initial_stages
    >>> edges = [im.measure_edge(im.render(im.Sensor(), im.Target("edge", a), 60).image) for a in (5.0, 84.0)]
    >>> model = Model(1.0, initial_stages(["optics", "detector"], None, 1.0),
    ...               [edge_data(e, k, None) for k, e in enumerate(edges)])
    >>> u = model.initial_vector()[: model.n_free]
    >>> bands, mtf50 = edge_model_mtfs(model, u, np.eye(model.n_free) * 1e-4, band_sensors(model, u), 0.95)
    >>> bands.shape, bool(np.all((bands[1] < bands[0]) & (bands[0] < bands[2]))), bool(np.all(mtf50 > 0.0))
    ((3, 2), True, True)
    """
    sensor, steps = sensors
    # as Sensor.normal_transfer forms them, edge by edge: f / GSD times the angle's cosine and sine
    radians = [math.radians(check_angle(d.normal_angle_deg)) for d in model.data]
    cos = np.array([math.cos(a) for a in radians])
    sin = np.array([math.sin(a) for a in radians])
    gsd = np.array([sensor._gsd(d.gsd_m) for d in model.data])

    def mtf(s: Sensor, f: np.ndarray, rows: slice | np.ndarray) -> np.ndarray:
        f = f / (gsd[rows, None] if f.ndim > 1 else gsd[rows])
        return np.abs(s.transfer(f * (cos[rows, None] if f.ndim > 1 else cos[rows]),
                                 f * (sin[rows, None] if f.ndim > 1 else sin[rows])))

    n = model.n_free
    nyquist = np.full(gsd.size, 0.5) / gsd
    # the stepped sensors' unstepped stages computed once (as mtf() gives them, bit for bit)
    value, *stepped = (np.abs(t) for t in sensor_transfers([sensor] + [s for _, s in steps[:n]],
                                                             nyquist * cos, nyquist * sin))
    grads = np.stack([(mtf - value) / h for (h, _), mtf in zip(steps, stepped)], axis=-1) if n else None
    bands = np.stack(delta_band(value, grads, covariance, confidence, each_alone=True))
    # as model_nyquist_mtf50_bands reads them: on the grid's first frequencies, then on all of it for an edge
    # whose MTF has not crossed 0.5 there
    first = MTF50_GRID_CY_PX[:MTF50_FIRST]
    mtf50 = np.empty(gsd.size)
    for start in range(0, gsd.size, chunk):
        rows = slice(start, start + chunk)
        count = gsd[rows].size
        mtf50[rows] = first_crossing(first, mtf(sensor, np.broadcast_to(first, (count, first.size)), rows), 0.5)
    again = np.flatnonzero(np.isnan(mtf50))
    for start in range(0, again.size, chunk):
        picked = again[start: start + chunk]
        f = np.broadcast_to(MTF50_GRID_CY_PX, (picked.size, MTF50_GRID_CY_PX.size))
        mtf50[picked] = first_crossing(MTF50_GRID_CY_PX, mtf(sensor, f, picked), 0.5)
    return bands, mtf50


def value_error(stage: Stage, name: str, u: float, se_u: float, gsd: float) -> float:
    """Standard error of a parameter in its own unit, from that of its fit
    coordinate (linearised; one-sided at the coordinate's zero)."""
    lower = stage.fit_specs()[name].lower
    def value(coordinate):
        return getattr(stage.with_fit_coordinates({name: max(coordinate, lower)}, gsd), name)
    if u - se_u > lower:
        return abs(value(u + se_u) - value(u - se_u)) / 2
    return abs(value(u + se_u) - value(u))


def residual_means(x: np.ndarray, residuals: np.ndarray, counts: np.ndarray, reach_px: float,
                   width_px: float = MISFIT_BIN_PX) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An edge's residuals averaged over its samples in bins ``width_px``
    wide along the normal (from 0 px), within ``reach_px`` of the edge;
    bins of fewer than 3 samples are left out.  Given the samples
    themselves (``counts`` all 1), the bins' means are the samples';
    given groups of samples (the fit's bins), each group counts wholly in
    the bin its mean distance falls in.

    Parameters
    ----------
    x : numpy.ndarray
        Distances from the fitted edge, px: of the samples, or of groups'
        means (the fit's bins').
    residuals : numpy.ndarray
        Their (mean) residuals, data - model, DN.
    counts : numpy.ndarray
        The samples each stands for (1 for a sample).
    reach_px : float
        The farthest distance from the edge taken, px.
    width_px : float, optional
        The bins' width, px (default :data:`MISFIT_BIN_PX`).

    Returns
    -------
    centres, means, counts : numpy.ndarray
        Each bin's centre (px), its samples' mean residual (DN) and their count.

    Examples
    --------
    >>> residual_means(np.array([0.01, 0.1, 0.3]), np.array([1.0, 4.0, 9.0]), np.array([3, 1, 2]), 3.0)
    (array([0.125]), array([1.75]), array([4.]))
    """
    keep = np.abs(x) <= reach_px
    index = np.floor(x[keep] / width_px).astype(int)
    first = int(index.min()) if index.size else 0
    count = np.bincount(index - first, weights=counts[keep])
    total = np.bincount(index - first, weights=counts[keep] * residuals[keep])
    used = count >= 3
    return (np.flatnonzero(used) + first + 0.5) * width_px, total[used] / count[used], count[used]


#: where the misfit test looks for an edge's transition: distances from the edge, px
MISFIT_GRID_PX = np.arange(-50.0, 50.0, MISFIT_BIN_PX / 4)


def transition_reach(esf: np.ndarray) -> np.ndarray:
    """How far from the edge (px, at least 3) the misfit test takes
    residuals: the farthest point of :data:`MISFIT_GRID_PX` where the
    model's edge response is between 0.1 % and 99.9 %, from ``esf`` (its
    values there; one row per edge).

    Examples
    --------
    >>> from scipy.special import ndtr
    >>> transition_reach(ndtr(MISFIT_GRID_PX / 2.0)).round(4).tolist()
    6.125
    """
    inside = (esf > 1e-3) & (esf < 1 - 1e-3)
    far = np.where(inside, np.abs(MISFIT_GRID_PX), 0.0).max(axis=-1, initial=0.0)
    return np.maximum(far, 3.0)


#: above this many edges :func:`misfit_reaches` evaluates their ESFs side by side (a target's 4
#: cost the same either way, 1.3-2 ms)
STACKED_REACH_EDGES = 8


def misfit_reaches(model: Model, responses: list) -> np.ndarray:
    """Each edge's :func:`transition_reach`, many edges' responses' ESFs on
    the grid evaluated side by side in one pass (:meth:`.model.Model.stacked`)."""
    count = len(responses)
    if count <= STACKED_REACH_EDGES:
        return np.array([transition_reach(r.esf(MISFIT_GRID_PX)) for r in responses])
    stacked = StackedResponses(responses, [MISFIT_GRID_PX.size] * count, *model._laid_out(responses))
    return transition_reach(stacked.esf(np.tile(MISFIT_GRID_PX, count)).reshape(count, -1))


def misfit_test(x: np.ndarray, residuals: np.ndarray, noise: float, step: float, response,
                reach: float | None = None):
    """P-value and size (RMS fraction of the step, noise removed) of the
    structure of an edge's samples' residuals (``residuals``, data - model,
    DN, at distances ``x`` px from the fitted edge; of one sample's noise
    ``noise``): their means in bins along the normal
    (:func:`residual_means`), over the transition (where the model's edge
    response is between 0.1 % and 99.9 %, and at least +-3 px).  On the
    samples, not the fit's bins: those are formed on the distances before
    the fitted offset, so at an offset they straddle these bins' edges.
    (NaN, NaN) where no bin holds 3 samples: the test cannot run, which is
    no pass.  ``reach`` is :func:`transition_reach` when known (default
    from ``response``)."""
    if reach is None:
        reach = float(transition_reach(response.esf(MISFIT_GRID_PX)))
    _, means, count = residual_means(x, residuals, np.ones(x.size), reach)
    if not count.size:
        return math.nan, math.nan
    statistic = float(np.sum(count * means**2) / noise**2)
    from scipy.special import chdtrc  # (scipy.stats, for this one tail, costs most of a second to import)
    p = float(chdtrc(count.size, statistic))
    systematic = max(float(np.mean(means**2 - noise**2 / count)), 0.0)
    return p, math.sqrt(systematic) / step

"""The driver: the edges' data made, the model set up, fitted, and its
stages freed or held by the likelihood ratio."""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..._blas import one_blas_thread
from ...errors import ImgmtfError, ParameterError
from ...inputs import check_number
from ...sensor.model import Sensor
from .choice import AUTO_CANDIDATES, ModelChoice, candidate_summary, choose
from .covariance import parameter_covariance
from .data import EdgeImage, edge_data
from .model import (
    Model,
    check_auto_hold,
    hold_keys,
    initial_stages,
    is_auto,
    listed,
    stage_names,
)
from .report import fit_report
from .results import SensorFit
from .seeds import seeded

if TYPE_CHECKING:
    from ..edge import EdgeResult

#: Jacobians a candidate of ``auto`` may take: its larger models (ten
#: parameters, a dozen edges solved by LSMR) took 200-1000 on an L0R
#: campaign's scenes where the paper's four take under 50
AUTO_MAX_ITERATIONS = 1500
#: a parameter stays free only if holding it costs this much chi-square
#: (in units of the reduced chi-square): p = 0.001 for one degree of freedom
LIKELIHOOD_RATIO = 10.8
#: a parameter whose Wald statistic (its distance from its starting value in
#: standard errors, squared: the chi-square holding it costs, to first order,
#: the others following) exceeds this many times the likelihood-ratio
#: threshold stays free without a trial refit: no nonlinearity of the blur
#: models seen brings that cost back under the threshold
WALD_MARGIN = 10.0


def fit_edges(edges: Sequence[np.ndarray | EdgeImage | EdgeResult], *,
              stages: str | Sequence[str] | None = None, start: Sensor | None = None,
              hold: str | Sequence[str] = (), gsd_m: float | None = None,
              confidence: float = 0.95) -> SensorFit:
    """Fit a sensor's stages to the profiles of one or more edges, given as
    images or measurements (:func:`imgmtf.fit_sensor` reads files and
    takes windows, then calls this).

    Parameters
    ----------
    edges : sequence
        Each a 2-D array (DN), an :class:`EdgeImage` (an array with what
        its file said: source, GSD, sample type) or an
        :class:`imgmtf.EdgeResult` already measured; one edge per image.
    stages : str or sequence of str, optional
        Stage names to fit (comma-separated or a list; see
        :data:`imgmtf.sensor.stages.STAGES`), or ``"auto"``: the simplest
        of :data:`.choice.AUTO_CANDIDATES` that fits (see
        :mod:`.choice`); default the stages of ``start``, or the paper's
        four.
    start : Sensor, optional
        Starting (and held) values of the stages it has; other stages
        start from their defaults scaled to the GSD.
    hold : str or sequence of str, optional
        Parameters held at their starting values: "stage" or "stage.name".
    gsd_m : float, optional
        Ground sample distance (m); default the first edge's that knows
        it, else 1 (parameters then in pixels).
    confidence : float, optional
        Of the intervals, in (0, 1) (default 0.95).

    Returns
    -------
    SensorFit
        The fitted sensor, each parameter with its standard error, the
        model's MTF across and along track with intervals, and each edge's
        measured and modelled MTF.

    Raises
    ------
    ParameterError
        Unknown stage or parameter names, no edges, bad ``confidence``.
    ImgmtfError
        An image with no measurable edge (the message names it), or a fit
        that does not converge.

    Examples
    --------
    >>> import imgmtf
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 60).image for a in (6.0, 84.0)]
    >>> fit = fit_edges([imgmtf.measure_edge(chip) for chip in chips])
    >>> abs(fit.edges[0].mtf_nyquist - 0.2667) < 0.002
    True
    """
    auto = is_auto(stages)
    names, gsd_m = checked_arguments(stages, start, gsd_m, confidence)
    if auto:
        check_auto_hold(hold)
    items = listed("edges", edges, "arrays or EdgeResults")
    data = [edge_data(item, k, gsd_m) for k, item in enumerate(items)]
    if not data:
        raise ParameterError("no edges to fit")
    gsd = gsd_m if gsd_m is not None else next((d.gsd_m for d in data if d.gsd_known), 1.0)
    with one_blas_thread(load="scipy.optimize"):     # (the solver's fallback: its BLAS limited too)
        if not auto:
            return run_fit(new_model(gsd, initial_stages(names, start, gsd), data, start), hold, confidence)
        fits, failed, stopped = [], [], False
        for candidate in AUTO_CANDIDATES:
            model = new_model(gsd, initial_stages(list(candidate), start, gsd), data, start)
            try:
                # parsimony is the candidates' order here: within one, a parameter held at a starting value
                # that is no knowledge (the paper's optics) would bias the rest and narrow the intervals
                fits.append(run_fit(model, candidate_hold(hold, model.keys), confidence, hold_unneeded=False,
                                    max_iterations=AUTO_MAX_ITERATIONS))
            except ImgmtfError as exc:          # one that does not converge: the next is tried
                failed.append((candidate, str(exc)))
                continue
            if not fits[-1].misfit:
                break               # the simplest that fits
            stopped = wings_do_not_help(fits)
            if stopped:
                break
    if not fits:
        raise ImgmtfError("no candidate sensor model could be fitted: "
                          + "; ".join(f"{'+'.join(c)}: {message}" for c, message in failed), reason="fit")
    index, reason = choose(fits, tried=len(fits) + len(failed))
    if stopped:
        reason += "; the exponential wings did not lower it, so no richer candidate was tried"
    kept = tuple(s.name for s in fits[index].sensor.stages)
    choice = ModelChoice(tuple(candidate_summary(f) for f in fits), kept, reason, tuple(failed))
    return replace(fits[index], choice=choice)


def wings_do_not_help(fits: list[SensorFit]) -> bool:
    """Whether the Gaussian core and its exponential wings are both fitted
    and the wings lowered the information criterion by nothing: every later
    candidate has the wings, and a structure they do not touch is no blur's
    shape (texture, a second target in the half-edges' profiles), which
    richer stages only chase.  On a textured 4096 px scene's 20 pooled
    half-edges the five candidates' BICs rose 94338-94377 while their fits
    took 16 s; on the real L0R chips the wings alone cut it by a third."""
    if [tuple(s.name for s in f.sensor.stages) for f in fits] != list(AUTO_CANDIDATES[:2]):
        return False
    core, wings = (candidate_summary(f).bic for f in fits)
    return wings >= core


def new_model(gsd: float, stages: list, data: list, start: Sensor | None) -> Model:
    """The model of ``stages``, a lag started where the edges lean
    (:func:`.seeds.seeded`) but held, if held, at none."""
    return Model(gsd, seeded(stages, data, gsd, start), data, held_at=stages)


def held_where(model: Model, key: str) -> str:
    """Where a held parameter is held, in words."""
    return "its starting value" if model.held_at[key] == model.start[key] else "none (0)"


def candidate_hold(hold, keys: list[str]) -> list[str]:
    """The held names that name a stage or parameter of this candidate."""
    if isinstance(hold, str):
        hold = [h.strip() for h in hold.split(",") if h.strip()]
    return [item for item in hold if any(k == item or k.split(".")[0] == item for k in keys)]


def checked_arguments(stages: str | Sequence[str] | None, start: Sensor | None, gsd_m: float | None,
                      confidence: float) -> tuple[list[str], float | None]:
    """The stages' names and the GSD, checked before any data are read.

    Raises
    ------
    ParameterError
        A bad ``confidence``, ``gsd_m`` or ``start``, unknown stages.
    """
    if not (isinstance(confidence, (int, float, np.floating)) and 0 < confidence < 1):
        raise ParameterError(f"confidence must be in (0, 1), got {confidence!r}")
    if gsd_m is not None:
        gsd_m = check_number("gsd_m", gsd_m, positive=True)
    if start is not None and not isinstance(start, Sensor):
        raise ParameterError(f"start must be a Sensor, got {start!r}")
    return (["auto"] if is_auto(stages) else stage_names(stages, start)), gsd_m


def run_fit(model: Model, hold, confidence: float, hold_unneeded: bool = True,
            max_iterations: int = 200) -> SensorFit:
    """Fit ``model`` from its starting values, holding
    what the data do not determine or (``hold_unneeded``) need (see the
    module's notes), each solve within ``max_iterations`` Jacobians, and
    report."""
    notes = model.screen_axes(hold_keys(hold, model.keys))
    z = model.initial_vector()
    while True:
        z, jacobian = model.solve(z, max_iterations)
        scale = max(model.reduced_chi_square(z), 1.0)
        covariance = parameter_covariance(jacobian, scale, model.n_free, model.counts)
        undetermined = model.undetermined(z, covariance)
        if not undetermined:
            break
        worst = max(undetermined, key=lambda i: (model.specs[model.free[i]].rank, undetermined[i]))
        notes[model.free[worst]] = ("held", f"not determined by the data (within one standard error its blur "
                                            f"length spans {undetermined[worst]:.2g} px); "
                                            f"held at {held_where(model, model.free[worst])}")
        z = model.hold(z, worst, covariance)
    # hold, best-known first, each parameter the data do not need (holding it
    # at its starting value costs less than the likelihood-ratio threshold),
    # but keep one free parameter on each axis an edge sees
    for key in sorted(model.free, key=lambda k: -model.specs[k].rank) if hold_unneeded else ():
        if not model.covers_axes([k for k in model.free if k != key]):
            continue            # the last free parameter of an axis: its uncertainty belongs in the intervals
        index = model.free.index(key)
        if (z[index] - model.start[key]) ** 2 > WALD_MARGIN * LIKELIHOOD_RATIO * covariance[index, index]:
            continue            # plainly needed (covariance is scaled, as the cost is)
        trial = model.copy()
        z_held = trial.hold(z, index, covariance)
        try:
            z_held, jacobian_held = trial.solve(z_held, max_iterations)
        except ImgmtfError:
            continue
        cost = (trial.chi_square(z_held) - model.chi_square(z)) / scale
        if cost < LIKELIHOOD_RATIO:
            notes[key] = ("held", f"the data do not need it (freeing it gains chi-square {max(cost, 0):.1f} "
                                  f"< {LIKELIHOOD_RATIO:g}); held at {held_where(model, key)}")
            model, z = trial, z_held
            scale = max(model.reduced_chi_square(z), 1.0)
            covariance = parameter_covariance(jacobian_held, scale, model.n_free, model.counts)
    return fit_report(model, z, covariance, notes, confidence)

"""Is the blur the same all along the target?  An edge whose blur changes
along its length (a tilted focal plane, a field-dependent lens, a scene
whose top is out of focus) gives the MTF of no single place: the estimate
mixes the parts' profiles, and reads between their MTFs with no sign of it
(half the rows at Gaussian sigma 0.5 px, half at 0.9: 0.09 below the
sharper half's truth at Nyquist).

The profile's width is read in groups of rows along the target (the two
halves and the three thirds), each from its own samples by a fit of its own:

- an edge: the scale of a Fermi step fitted with its own levels and
  centre;
- a bar: the scale of a Gaussian fitted likewise.

Groups whose widths disagree beyond their noise and beyond
``MAX_WIDTH_CHANGE`` refuse the chip (reason ``varying-blur``); smaller
significant changes are said.
"""
from __future__ import annotations

import math

import numpy as np

from .evidence import Evidence
from .gate import Check

MIN_REACH_PX = 3.0              # the fit sees at least this far either side of the centre
MIN_GROUP_SAMPLES = 40
MIN_SCALE_PX = 0.02
MIN_GROUP_ROWS = 8
MAX_WIDTH_CHANGE = 0.08        # relative: the parts' MTFs at Nyquist then differ by about 0.03
WARN_WIDTH_CHANGE = 0.03
SIGNIFICANCE = 5.0
WARN_SIGNIFICANCE = 4.0


def uniform_blur(ev: Evidence) -> tuple[list[Check], list[str]]:
    """The largest relative change of the profile's width between the
    halves or the thirds of the target's rows, against its noise.

    Returns the ``varying-blur`` check and a warning for a small but
    significant change.
    """
    rows = np.unique(ev.rows)
    if rows.size < 2 * MIN_GROUP_ROWS:
        return [], []
    worst = None
    for parts in (2, 3):
        if rows.size < parts * MIN_GROUP_ROWS:
            continue
        bounds = np.array_split(rows, parts)
        widths = [_group_width(ev, (ev.rows >= b[0]) & (ev.rows <= b[-1])) for b in bounds]
        if any(w is None for w in widths):
            continue
        for i in range(parts):
            for j in range(i + 1, parts):
                (wi, vi), (wj, vj) = widths[i], widths[j]  # type: ignore[misc]
                change = abs(wi - wj) / (0.5 * (wi + wj))
                z = abs(wi - wj) / math.sqrt(vi + vj) if vi + vj > 0 else math.inf
                if worst is None or (z >= WARN_SIGNIFICANCE, change) > (worst[1] >= WARN_SIGNIFICANCE, worst[0]):
                    worst = (change, z, (bounds[i], wi), (bounds[j], wj))
    if worst is None:
        return [], []
    change, z, (rows_a, width_a), (rows_b, width_b) = worst
    where = (f"{width_a:.3f} px over rows {rows_a[0]}-{rows_a[-1]} and {width_b:.3f} px over rows "
             f"{rows_b[0]}-{rows_b[-1]}")
    failed = z > SIGNIFICANCE and change > MAX_WIDTH_CHANGE
    check = Check("varying-blur", not failed,
                  f"the {ev.name}'s blur changes along it: its width is {where} ({100 * change:.0f} % apart, at "
                  f"most {100 * MAX_WIDTH_CHANGE:g} %): no single MTF describes it; measure its parts apart",
                  change, MAX_WIDTH_CHANGE)
    said = []
    if not failed and z > WARN_SIGNIFICANCE and change > WARN_WIDTH_CHANGE:
        said.append(f"the {ev.name}'s blur changes a little along it: its width is {where} "
                        f"({100 * change:.0f} % apart): the MTF is their mixture")
    return [check], said


def _group_width(ev: Evidence, in_group: np.ndarray) -> tuple[float, float] | None:
    """The width (px) of one group's profile within the plateau of the
    centre, with its variance: the scale c of a Fermi step (an edge) or of
    a Gaussian (a bar) fitted with its own levels and centre, so that
    neither shading nor a slight bend along the target passes for a change
    of blur.  The model need not be the blur's: it is the same for every
    group.  None where the fit fails."""
    s = ev.distance_px[in_group] - ev.centre_px
    near = np.abs(s) <= max(ev.plateau_px, MIN_REACH_PX)
    if np.count_nonzero(near) < MIN_GROUP_SAMPLES:
        return None
    s, v = s[near], ev.values[in_group][near]
    bar = ev.profile == "bar"
    start = np.array([ev.high - ev.low, 0.0, max(ev.scale_px, 0.2) * (0.5 if bar else 0.25), ev.low])
    fitted = _fit(_bar if bar else _step, s, v, start)
    if fitted is None:
        return None
    params, variance = fitted
    if abs(params[2]) < MIN_SCALE_PX:          # a step no blur: no fit to compare (fill, a clip)
        return None
    return abs(float(params[2])), variance


def _step(s, p):
    """A Fermi step and its Jacobian in (amplitude, centre, scale, base)."""
    u = np.clip((s - p[1]) / p[2], -50.0, 50.0)
    f = 1.0 / (1.0 + np.exp(-u))
    slope = f * (1.0 - f)
    return p[3] + p[0] * f, np.column_stack([f, -p[0] * slope / p[2], -p[0] * slope * u / p[2], np.ones_like(f)])


def _bar(s, p):
    """A Gaussian pulse and its Jacobian in (amplitude, centre, scale, base)."""
    u = (s - p[1]) / p[2]
    g = np.exp(-0.5 * u * u)
    return p[3] + p[0] * g, np.column_stack([g, p[0] * g * u / p[2], p[0] * g * u * u / p[2], np.ones_like(g)])


def _fit(model, s, v, start, iterations=60) -> tuple[np.ndarray, float] | None:
    """Levenberg-Marquardt least squares of ``model`` to (s, v) from
    ``start``: the parameters and the variance of the third (the scale),
    scaled by the residual variance.  None where it does not converge to
    finite numbers."""
    p = start.astype(float)
    fit, jac = model(s, p)
    cost = float(np.sum((v - fit) ** 2))
    damping = 1e-3
    for _ in range(iterations):
        normal = jac.T @ jac
        gradient = jac.T @ (v - fit)
        try:
            step = np.linalg.solve(normal + damping * np.diag(np.maximum(np.diag(normal), 1e-12)), gradient)
        except np.linalg.LinAlgError:
            return None
        trial = p + step
        if trial[2] == 0:
            damping *= 4.0
            continue
        trial_fit, trial_jac = model(s, trial)
        trial_cost = float(np.sum((v - trial_fit) ** 2))
        if np.isfinite(trial_cost) and trial_cost < cost:
            converged = abs(step[2]) < 1e-7 * max(abs(trial[2]), 1e-9)
            p, fit, jac, cost, damping = trial, trial_fit, trial_jac, trial_cost, damping / 3.0
            if converged:
                break
        else:
            damping *= 4.0
            if damping > 1e10:
                break
    try:
        covariance = np.linalg.inv(jac.T @ jac) * cost / max(s.size - 4, 1)
    except np.linalg.LinAlgError:
        return None
    if not (np.isfinite(p).all() and math.isfinite(covariance[2, 2])):
        return None
    return p, max(float(covariance[2, 2]), 0.0)

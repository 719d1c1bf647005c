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
import warnings

import numpy as np
from scipy.optimize import OptimizeWarning, curve_fit

from .evidence import Evidence
from .gate import Check

MIN_REACH_PX = 3.0              # the fit sees at least this far either side of the centre
MIN_GROUP_SAMPLES = 40
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
    step = ev.high - ev.low
    model = _bar if ev.profile == "bar" else _step
    start = (step, 0.0, max(ev.scale_px, 0.2) * (0.5 if ev.profile == "bar" else 0.25), ev.low)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", OptimizeWarning)
            params, cov = curve_fit(model, s, v, p0=start, maxfev=2000)
    except (RuntimeError, ValueError):
        return None
    variance = float(cov[2, 2])
    if not (np.isfinite(params).all() and math.isfinite(variance)) or params[2] == 0:
        return None
    return abs(float(params[2])), max(variance, 0.0)


def _step(s, amplitude, centre, scale, base):
    return base + amplitude / (1.0 + np.exp(np.clip(-(s - centre) / scale, -50.0, 50.0)))


def _bar(s, amplitude, centre, scale, base):
    return base + amplitude * np.exp(-0.5 * ((s - centre) / scale) ** 2)

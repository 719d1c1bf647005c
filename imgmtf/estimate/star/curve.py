"""A direction's MTF curve from its rings: a local quadratic regression in
frequency (a Gaussian kernel of :data:`BANDWIDTH_CY_PX`, or of
:data:`SPACINGS_PER_BANDWIDTH` times the rings' spacing where they are
sparser, near the star's centre; each ring weighted
by its inverse variance), with the
standard error of every smoothed value from the rings' (the smoother is
linear: ``var = sum l_j^2 se_j^2``), widened by the rings' scatter about
the curve when it exceeds their errors; under the lowest ring, the full
contrast's extrapolation to 1 at zero frequency."""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...metrics import first_crossing

#: the kernel's standard deviation, cy/px
BANDWIDTH_CY_PX = 0.035
#: where rings are sparse, the kernel's standard deviation is this many of their spacings
SPACINGS_PER_BANDWIDTH = 0.8
#: the curve's frequency step, cy/px
STEP_CY_PX = 0.01
#: rings (by kernel weight) a smoothed value needs; fewer: NaN
MIN_EFFECTIVE_RINGS = 2.5


@dataclass(frozen=True, eq=False)
class Curve:
    """A smoothed MTF curve.

    Attributes
    ----------
    frequencies_cy_px : numpy.ndarray
        0 to the highest ring's frequency, in steps of :data:`STEP_CY_PX`.
    mtf : numpy.ndarray
        The MTF (1 at zero; NaN where too few rings).
    standard_error : numpy.ndarray
        Of each value.
    scatter : float
        The rings' reduced chi-square about the curve (1: as their errors
        say).
    """

    frequencies_cy_px: np.ndarray
    mtf: np.ndarray
    standard_error: np.ndarray
    scatter: float

    def at(self, f_cy_px: float) -> tuple[float, float]:
        """The MTF and its standard error at ``f_cy_px`` (linear between
        the curve's samples; NaN beyond it)."""
        f = self.frequencies_cy_px
        if not f[0] <= f_cy_px <= f[-1]:
            return math.nan, math.nan
        return (float(np.interp(f_cy_px, f, self.mtf)), float(np.interp(f_cy_px, f, self.standard_error)))

    def crossing(self, level: float) -> tuple[float, float]:
        """Where the curve first falls to ``level`` (cy/px) and that
        frequency's standard error (the value's over the curve's slope)."""
        good = np.isfinite(self.mtf)
        f, mtf = self.frequencies_cy_px[good], self.mtf[good]
        at = float(first_crossing(f, mtf, level)) if f.size > 1 else math.nan
        if not math.isfinite(at):
            return math.nan, math.nan
        slope = float(np.interp(at, f[1:-1], (mtf[2:] - mtf[:-2]) / (f[2:] - f[:-2]))) if f.size > 2 else math.nan
        error = float(np.interp(at, f, self.standard_error[good]))
        return at, error / abs(slope) if slope < 0 else math.nan


def smooth(frequencies: np.ndarray, values: np.ndarray, errors: np.ndarray, *,
           below: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None = None) -> Curve:
    """The local quadratic regression of the rings' values (see the module).

    Parameters
    ----------
    frequencies, values, errors : numpy.ndarray
        Each ring's frequency (cy/px), MTF and its standard error (NaN
        rings are left out).
    below : callable, optional
        ``below(f) -> (mtf, error)``: the curve under the lowest ring (the
        full contrast's extrapolation); default 1 at zero, linear to it.

    Returns
    -------
    Curve
        The curve and its errors.

    Examples
    --------
    >>> f = np.linspace(0.1, 0.7, 60)
    >>> curve = smooth(f, np.exp(-4 * f ** 2), np.full(60, 1e-3))
    >>> round(curve.at(0.5)[0], 4), round(float(np.exp(-1.0)), 4)
    (0.3679, 0.3679)
    """
    good = np.isfinite(values) & np.isfinite(errors) & (errors > 0)
    fj, yj, sj = frequencies[good], values[good], errors[good]
    grid = np.round(np.arange(0.0, float(fj.max()) + 1e-9, STEP_CY_PX), 10)
    rows, usable = _smoother(grid, fj, sj)
    mtf = np.where(usable, rows @ yj, np.nan)
    # the rings' scatter about the curve (each ring's leverage taken out), beyond their errors, widens every value's
    own, own_usable = _smoother(fj, fj, sj)
    residual = ((yj - own @ yj) / sj)[own_usable]
    dof = float(np.sum(own_usable)) - float(np.trace(own[own_usable][:, own_usable]))
    scatter = float(residual @ residual) / dof if dof >= 1.0 else math.nan
    factor = math.sqrt(max(1.0, scatter)) if math.isfinite(scatter) else 1.0
    error = np.where(usable, np.sqrt((rows ** 2) @ (sj ** 2)) * factor, np.nan)
    # under the lowest ring no ring speaks: the extrapolation the full contrast was read with
    gap = grid < fj.min()
    if below is not None:
        mtf[gap], error[gap] = below(grid[gap])
    else:
        first = int(np.argmax(usable & ~gap)) if (usable & ~gap).any() else 0
        mtf[gap] = 1.0 + (mtf[first] - 1.0) * grid[gap] / max(grid[first], 1e-9)
        error[gap] = error[first] * grid[gap] / max(grid[first], 1e-9)
    return Curve(grid, mtf, error, scatter)


def _smoother(points: np.ndarray, fj: np.ndarray, sj: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The local quadratic smoother's weights at ``points``: rows ``l`` with
    the value ``l @ y``, and where enough rings are near."""
    d = fj[None, :] - points[:, None]
    # rings thin out towards the centre (each must hold its pixels): the kernel spans a few of them there
    order = np.argsort(fj)
    spacing = np.gradient(fj[order]) if fj.size > 1 else np.ones(1)
    bandwidth = np.maximum(BANDWIDTH_CY_PX, SPACINGS_PER_BANDWIDTH * np.interp(points, fj[order], spacing))
    kernel = np.exp(-0.5 * (d / bandwidth[:, None]) ** 2)
    w = kernel / sj[None, :] ** 2
    design = np.stack([np.ones_like(d), d, d * d], axis=-1)
    normal = np.einsum("gj,gja,gjb->gab", w, design, design)
    effective = kernel.sum(axis=1) ** 2 / np.maximum((kernel ** 2).sum(axis=1), 1e-300)
    usable = effective >= MIN_EFFECTIVE_RINGS
    normal[~usable] = np.eye(3)
    # the first row of (X'WX)^-1 X'W
    rows = np.linalg.solve(normal, np.einsum("gj,gja->gaj", w, design))[:, 0, :]
    return np.where(usable[:, None], rows, 0.0), usable

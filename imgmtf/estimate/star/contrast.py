"""A star's full-contrast modulation: what its rings' modulation would be
with no blur, the divisor that makes them an MTF (1 at zero frequency).

Two ways, one for each profile:

- **extrapolated** (the sinusoidal star): the low-frequency rings of every
  direction fitted together as ``ln |m| = ln c - a_d f^2 - b_d f^4`` (one
  ``c``, each direction ``d`` its own curvature: an MTF is even in ``f``,
  and a Gaussian's logarithm is exactly quadratic) and read at ``f = 0``;
- **levels** (the binary star): the wedges' two levels ``H`` and ``L`` read
  on their plateaus at large radius, where the blur does not reach, and
  the square wave's fundamental ``(4 / pi) (H - L) / (H + L)``.

The binary star's extrapolation is computed too, and a disagreement of the
two is reported (a star that is not binary, or values not linear in light).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .rings import Rings

#: the rings that enter the extrapolation: the fundamental below this, cy/px
EXTRAPOLATION_TOP_CY_PX = 0.22
#: a plateau pixel lies at least this far from a wedge's edge, px
PLATEAU_CLEARANCE_PX = 2.5
#: the least share of the star's radius a plateau pixel lies beyond
PLATEAU_RADIUS_SHARE = 0.5


@dataclass(frozen=True)
class Contrast:
    """The full-contrast modulation and how it was found.

    Attributes
    ----------
    modulation : float
        ``c``: the fundamental's amplitude over the mean with no blur.
    standard_error : float
        Its standard error (relative errors carry to every MTF value).
    phase_rad : float
        The fundamental's phase at low frequency (the MTF's sign reference).
    method : str
        "extrapolated" or "levels".
    lowest_cy_px : float
        The lowest frequency a ring reads, cy/px.
    curvature : numpy.ndarray, shape (d, 2)
        Each direction's ``(a, b)`` of the extrapolation.
    extrapolated : float
        ``c`` by extrapolation (the levels' cross-check for a binary star).
    """

    modulation: float
    standard_error: float
    phase_rad: float
    method: str
    lowest_cy_px: float
    curvature: np.ndarray
    extrapolated: float


def extrapolate(rings: Rings) -> tuple[float, float, np.ndarray, float]:
    """``c`` and its standard error, each direction's curvature and the
    phase, from the rings below :data:`EXTRAPOLATION_TOP_CY_PX` (see the
    module)."""
    f = rings.frequencies_cy_px
    n_dir = rings.modulation.shape[0]
    low = f <= max(EXTRAPOLATION_TOP_CY_PX, float(np.nanmin(f)) + 0.08)
    m = rings.modulation[:, low]
    se = rings.standard_error[:, low]
    ok = np.isfinite(m) & (np.abs(m) > 3.0 * se) & (se > 0)
    phase = float(np.angle(np.nansum(np.where(ok, m / np.where(ok, se, 1.0) ** 2, 0.0))))
    d_index, j_index = np.nonzero(ok)
    ff = f[low][j_index]
    y = np.log(np.abs(m[ok]))
    w = (np.abs(m[ok]) / se[ok]) ** 2                       # 1 / var(ln |m|)
    design = np.zeros((y.size, 1 + 2 * n_dir))
    design[:, 0] = 1.0
    design[np.arange(y.size), 1 + 2 * d_index] = -ff ** 2
    design[np.arange(y.size), 2 + 2 * d_index] = -ff ** 4
    sw = np.sqrt(w)
    beta, *_ = np.linalg.lstsq(design * sw[:, None], y * sw, rcond=None)
    residual = (design @ beta - y) * sw
    dof = max(y.size - design.shape[1], 1)
    scale = max(1.0, float(residual @ residual) / dof)      # the fit's misfit widens its error
    covariance = np.linalg.pinv((design * w[:, None]).T @ design) * scale
    c = float(math.exp(beta[0]))
    return c, c * math.sqrt(max(covariance[0, 0], 0.0)), beta[1:].reshape(n_dir, 2), phase


def wedge_levels(image: np.ndarray, x: float, y: float, cycles: int, phase_rad: float,
                 outer_px: float) -> tuple[float, float, float]:
    """The binary star's bright and dark levels (DN) on its plateaus, and
    the standard error of ``(H - L) / (H + L)``."""
    rows, cols = image.shape
    yy, xx = np.mgrid[0:rows, 0:cols]
    r = np.hypot(xx - x, yy - y)
    # the rings' modulation (a - i b) / D of a cos + b sin is |m| exp(i phase): the crests at N theta = -phase
    wrapped = np.angle(np.exp(1j * (cycles * np.arctan2(yy - y, xx - x) + phase_rad)))
    clearance = r * np.abs(math.pi / 2 - np.abs(wrapped)) / cycles          # arc to the nearest edge, px
    plateau = (r >= PLATEAU_RADIUS_SHARE * outer_px) & (r <= outer_px) & (clearance >= PLATEAU_CLEARANCE_PX)
    values = np.asarray(image, float)
    bright = values[plateau & (np.abs(wrapped) < math.pi / 2)]
    dark = values[plateau & (np.abs(wrapped) > math.pi / 2)]
    if bright.size < 10 or dark.size < 10:
        return math.nan, math.nan, math.nan
    # means, not medians: the plateaus hold few pixels, and the clearance keeps the edges out
    high, low = float(np.mean(bright)), float(np.mean(dark))
    e_high = float(np.std(bright)) / math.sqrt(bright.size)
    e_low = float(np.std(dark)) / math.sqrt(dark.size)
    total = high + low
    error = 2.0 * math.hypot(low * e_high, high * e_low) / total ** 2 if total > 0 else math.nan
    return high, low, error


def full_contrast(rings: Rings, image: np.ndarray, x: float, y: float, cycles: int, profile: str,
                  outer_px: float) -> Contrast:
    """The star's full-contrast modulation (see the module).

    Parameters
    ----------
    rings : Rings
        The rings' modulations.
    image : numpy.ndarray
        The chip, DN (a binary star's levels are read on it).
    x, y : float
        The centre, px.
    cycles : int
        N.
    profile : {"sinusoidal", "binary"}
        Which way.
    outer_px : float
        The largest radius read, px.

    Returns
    -------
    Contrast
        ``c``, its error, the phase and the curvatures.
    """
    c, error, curvature, phase = extrapolate(rings)
    lowest = float(np.nanmin(rings.frequencies_cy_px))
    if profile == "binary":
        high, low, e_ratio = wedge_levels(image, x, y, cycles, phase, outer_px)
        if math.isfinite(high) and high + low > 0:
            levels = 4.0 / math.pi * (high - low) / (high + low)
            return Contrast(levels, 4.0 / math.pi * e_ratio, phase, "levels", lowest, curvature, c)
    return Contrast(c, error, phase, "extrapolated", lowest, curvature, c)

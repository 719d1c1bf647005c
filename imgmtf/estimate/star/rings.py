"""The star's modulation against radius in each direction: every ring of
every pair of opposite sectors fitted with the known sinusoid in angle.

A direction ``alpha`` (of the frequency, from the x axis) is read on the
two opposite sectors of the star where the pattern varies along
``alpha``: about the position angles ``alpha +- 90 deg``, where the
star's frequency ``N / (2 pi r)`` is tangential.  Opposite sectors are
fitted together, so that a centre a little off lengthens one sector's radii
as much as it shortens the other's.  Each ring (``RING_WIDTH_PX`` wide) of
each sector pair is a linear least-squares fit of its pixels

    v = D_side + (a + a' u) cos(N theta) + (b + b' u) sin(N theta)  [+ odd harmonics' pairs]

(one mean a side, which an uneven illumination may part; ``u`` the angle
off the sector's centre, -1/2 to 1/2 of its width, for the MTF's change
across the sector (its curvature is left: its two more unknowns would
widen the rings near Nyquist more than they help); a binary star's odd harmonics, 3 to 9, while they are
resolved), which holds exactly for any sample
positions, so that rings read above Nyquist too, where the pixels alias the
pattern but their positions do not.  Its complex modulation is
``(a - i b) / D`` (D the sides' mean) with the standard error of the fit's
residuals.  Every fit is solved at once from its normal equations,
accumulated pixel by pixel with :func:`numpy.bincount`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: each ring's radial width, px, where it holds enough pixels
RING_WIDTH_PX = 0.5
#: a ring is widened near the centre until its sector pair holds this many pixels an unknown
PIXELS_PER_UNKNOWN = 4
#: a binary star's odd harmonics (3 to 9) enter a ring's fit while their frequency is below this, cy/px
HARMONIC_CY_PX = 0.8
HARMONICS = (3, 5, 7, 9)
#: the fewest pixels a ring of a sector pair is fitted with, beyond its unknowns
MIN_SPARE_PIXELS = 4


@dataclass(frozen=True, eq=False)
class Rings:
    """The modulation of every ring of every direction.

    Attributes
    ----------
    directions_deg : numpy.ndarray, shape (d,)
        Each direction of the frequency, deg from the x axis (0 to 180).
    radii_px : numpy.ndarray, shape (n,)
        Each ring's mean radius, px.
    frequencies_cy_px : numpy.ndarray, shape (n,)
        ``N / (2 pi r)``, cy/px.
    modulation : numpy.ndarray, complex, shape (d, n)
        ``(a - i b) / D`` of each ring (NaN where too few pixels).
    standard_error : numpy.ndarray, shape (d, n)
        Of the modulation's real (and imaginary) part.
    pixels : numpy.ndarray, shape (d, n)
        Pixels fitted.
    mean_dn : numpy.ndarray, shape (d, n)
        D, DN.
    residual_dn : numpy.ndarray, shape (d, n)
        The standard deviation of the fit's residuals, DN (the noise, where
        the model holds).
    """

    directions_deg: np.ndarray
    radii_px: np.ndarray
    frequencies_cy_px: np.ndarray
    modulation: np.ndarray
    standard_error: np.ndarray
    pixels: np.ndarray
    mean_dn: np.ndarray
    residual_dn: np.ndarray


def direction_angles(n_directions: int, first_deg: float = 0.0) -> np.ndarray:
    """``n_directions`` directions of the frequency, evenly spread over 180
    deg from ``first_deg``, in [0, 180).

    Examples
    --------
    >>> direction_angles(4, 10.0).tolist()
    [10.0, 55.0, 100.0, 145.0]
    """
    return np.mod(first_deg + np.arange(n_directions) * (180.0 / n_directions), 180.0)


def harmonics_resolved(frequency_cy_px: np.ndarray | float, profile: str) -> np.ndarray:
    """How many of a binary star's odd harmonics :data:`HARMONICS` are
    resolved (below :data:`HARMONIC_CY_PX`) where its fundamental has
    ``frequency_cy_px``; none for a sinusoidal star."""
    if profile != "binary":
        return np.zeros(np.shape(frequency_cy_px), int)
    f = np.asarray(frequency_cy_px, float)
    return np.sum([(k * f < HARMONIC_CY_PX).astype(int) for k in HARMONICS], axis=0)


def ring_edges(inner_px: float, outer_px: float, n_directions: int, cycles: int, profile: str) -> np.ndarray:
    """The rings' edges, px: :data:`RING_WIDTH_PX` wide where a sector pair
    (two sectors of ``180 / n_directions`` deg) holds
    :data:`PIXELS_PER_UNKNOWN` pixels an unknown of its fit in so narrow a
    ring, wider nearer the centre.

    Examples
    --------
    >>> ring_edges(10.0, 40.0, 8, 32, "sinusoidal")[:4].round(2).tolist()
    [10.0, 13.06, 15.4, 17.38]
    """
    edges = [float(inner_px)]
    arc = 2.0 * math.pi / n_directions                  # the sector pair's angle, rad
    while edges[-1] < outer_px:
        f = cycles / (2.0 * math.pi * edges[-1])
        pixels = PIXELS_PER_UNKNOWN * (6 + 2 * int(harmonics_resolved(f, profile)))
        edges.append(edges[-1] + max(RING_WIDTH_PX, pixels / (arc * edges[-1])))
    edges.pop()                                          # the last ring ends at outer_px: widened, or a ring of its own
    if len(edges) > 1 and outer_px - edges[-1] < RING_WIDTH_PX:
        edges.pop()
    edges.append(float(outer_px))
    return np.asarray(edges)


def fit_rings(image: np.ndarray, x: float, y: float, cycles: int, profile: str, *, inner_px: float,
              outer_px: float, n_directions: int = 8, first_deg: float = 0.0) -> Rings:
    """Fit every ring of every direction's sector pair (see the module).

    Parameters
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The chip, DN.
    x, y : float
        The star's centre, px.
    cycles : int
        N.
    profile : {"sinusoidal", "binary"}
        The star's profile.
    inner_px, outer_px : float
        The radii read, px.
    n_directions : int, optional
        Directions over 180 deg (default 8: sectors of 22.5 deg).
    first_deg : float, optional
        The first direction, deg from the x axis (default 0).

    Returns
    -------
    Rings
        The rings' modulations.
    """
    rows, cols = image.shape
    yy, xx = np.mgrid[0:rows, 0:cols]
    dx, dy = xx - x, yy - y
    r = np.hypot(dx, dy)
    inside = (r >= inner_px) & (r < outer_px)
    dx, dy, r = dx[inside], dy[inside], r[inside]
    values = np.asarray(image, float)[inside]
    theta = np.arctan2(dy, dx)
    edges = ring_edges(inner_px, outer_px, n_directions, cycles, profile)
    n_rings = edges.size - 1
    ring = np.clip(np.searchsorted(edges, r, side="right") - 1, 0, n_rings - 1)
    # the frequency's direction is the tangent's, theta + 90 deg; sectors centred on the directions
    width = math.pi / n_directions
    sector = np.mod(np.round((theta + math.pi / 2 - math.radians(first_deg)) / width).astype(int), 2 * n_directions)
    direction, side = sector % n_directions, sector // n_directions
    group = direction * n_rings + ring
    n_groups = n_directions * n_rings
    psi = cycles * theta
    # the sector's own angle off its centre: the MTF's change across the sector, so that (a, b) are its centre's
    across = np.mod(theta + math.pi / 2 - math.radians(first_deg) + width / 2, width) / width - 0.5
    columns = [(side == 0).astype(float), (side == 1).astype(float), np.cos(psi), np.sin(psi),
               across * np.cos(psi), across * np.sin(psi)]
    ring_radius = 0.5 * (edges[1:] + edges[:-1])
    ring_f = cycles / (2.0 * math.pi * ring_radius)
    if profile == "binary":
        for k in HARMONICS:
            resolved = (k * ring_f < HARMONIC_CY_PX)[ring]    # beyond it, blurred away: no unknown of its own
            columns += [np.where(resolved, np.cos(k * psi), 0.0), np.where(resolved, np.sin(k * psi), 0.0)]
    design = np.column_stack(columns)
    p = design.shape[1]
    normal = np.empty((n_groups, p, p))
    for i in range(p):
        for j in range(i, p):
            normal[:, i, j] = normal[:, j, i] = np.bincount(group, design[:, i] * design[:, j], n_groups)
    right = np.column_stack([np.bincount(group, design[:, i] * values, n_groups) for i in range(p)])
    squares = np.bincount(group, values * values, n_groups)
    count = np.bincount(group, minlength=n_groups).astype(float)
    radius = np.bincount(group, r, n_groups) / np.maximum(count, 1.0)
    # a column no pixel of a group uses (a side it lacks, a harmonic blurred away) is held at zero
    empty = np.diagonal(normal, axis1=1, axis2=2) <= 0
    normal[:, np.arange(p), np.arange(p)] += empty
    unknowns = p - empty.sum(axis=1)
    usable = count >= unknowns + MIN_SPARE_PIXELS
    normal[~usable] = np.eye(p)
    beta = np.linalg.solve(normal, right[..., None])[..., 0]
    residual = np.maximum(squares - np.einsum("gi,gi->g", beta, right), 0.0)
    variance = residual / np.maximum(count - unknowns, 1.0)
    inverse = np.linalg.inv(normal)
    mean = np.where(empty[:, 0], beta[:, 1], np.where(empty[:, 1], beta[:, 0], 0.5 * (beta[:, 0] + beta[:, 1])))
    with np.errstate(invalid="ignore", divide="ignore"):
        modulation = (beta[:, 2] - 1j * beta[:, 3]) / mean
        error = np.sqrt(variance * 0.5 * (inverse[:, 2, 2] + inverse[:, 3, 3])) / np.abs(mean)
    bad = ~usable | ~(mean > 0)
    modulation[bad], error[bad] = np.nan, np.nan
    shape = (n_directions, n_rings)
    weights = np.where(usable, count, 0.0).reshape(shape)
    radii = np.where(weights.sum(axis=0) > 0, (radius.reshape(shape) * weights).sum(axis=0)
                     / np.maximum(weights.sum(axis=0), 1e-300), ring_radius)
    return Rings(direction_angles(n_directions, first_deg), radii, cycles / (2.0 * math.pi * radii),
                 modulation.reshape(shape), error.reshape(shape), count.reshape(shape), mean.reshape(shape),
                 np.where(bad, np.nan, np.sqrt(variance)).reshape(shape))

"""Sub-pixel edge geometry: a Fermi fit per row, a robust least-squares
line through the row locations, and every pixel's signed distance to it.

Works in the *vertical frame*: the edge runs roughly down the rows
(|tilt| < 45 deg) and each row crosses it once.  A near-horizontal edge is
handled by transposing the image first; :class:`TargetGeometry` remembers
that and reports angles in the original image.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import TargetNotFoundError, UnsuitableTargetError
from ._order import median, quantile
from .detection import Line
from .fermi import FermiFit, FermiRows, fit_fermi
from .resampling import sample_gap

MIN_ANGLE_DEG = 1.0            # closer to an axis, rows share their phase
MAX_ANGLE_DEG = 44.0           # closer to 45 deg, phases repeat every 2 px
MAX_SAMPLE_GAP_PX = 0.25       # at least 4 sample positions per pixel
EDGE_FIT_HALF_WINDOW_PX = 10      # each row's Fermi fit sees this far either side of the seed
MAX_HALF_RANGE_PX = 96.0       # profile samples kept within this distance (a long tail's reach)
MIN_HALF_RANGE_PX = 4.0        # and at least this much on each side


@dataclass(frozen=True, eq=False)
class TargetGeometry:
    """The fitted edge line x = slope * y + intercept in the vertical frame.

    ``rows`` are the rows that were fitted, ``locations`` their Fermi edge
    positions (px), ``kept`` which of them the line fit accepted;
    ``transposed`` is True when the vertical frame is the image transposed;
    ``location_sd_px`` is how far a row's location strays through pixel
    noise alone (the median over rows), what a straight target's scatter
    is judged against.
    """

    slope: float
    intercept: float
    rows: np.ndarray
    locations: np.ndarray
    kept: np.ndarray
    transposed: bool
    location_sd_px: float = 0.0

    @property
    def tilt_deg(self) -> float:
        """Angle (deg, 0 to 45) between the target and the nearest image axis."""
        return abs(math.degrees(math.atan(self.slope)))

    @property
    def angle_deg(self) -> float:
        """Tilt of the edge from the column axis of the original image, in
        (-90, 90] (the angle of its normal from the x axis)."""
        vertical = -math.degrees(math.atan(self.slope))
        if not self.transposed:
            return vertical
        angle = 90.0 - vertical
        return angle - 180.0 if angle > 90.0 else angle

    def distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Signed perpendicular distance (px) from the line, positive to the
        right (+x) in the vertical frame."""
        return (x - self.slope * y - self.intercept) / math.hypot(1.0, self.slope)


def locate_edge(image: np.ndarray, seed_x: np.ndarray, half_window: int = EDGE_FIT_HALF_WINDOW_PX,
                transposed: bool = False, fit: FermiFit | None = None) -> TargetGeometry:
    """Fit the Fermi model in every row around ``seed_x`` (the seed edge
    column per row) and a robust line through the locations.

    Rows whose fit fails are dropped; the line is refitted after discarding
    locations more than 4 robust standard deviations (and 0.05 px) off it.
    ``fit``: the rows' fit already made (:func:`edge_rows`, fitted among
    other chips' by :func:`.fermi.fit_fermi_many`).
    """
    rows = np.arange(image.shape[0])
    if fit is not None and fit.rows is not None:
        usable = fit.rows           # the rows were read for the fit already
    else:
        usable, fitted = edge_rows(image, seed_x, half_window)
        if fit is None:
            fit = fit_fermi(fitted.x, fitted.y, fitted.weight, fitted.b0)
    # a Fermi step a with width c under noise s locates its edge to about
    # s sqrt(30 c) / |a| (the location's Cramer-Rao bound on a 1-px grid)
    a, c = np.abs(fit.params[fit.ok, 0]), np.abs(fit.params[fit.ok, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        sd = fit.rms[fit.ok] * np.sqrt(30.0 * np.maximum(c, 0.05)) / a
    expected = float(median(sd)) if sd.size else 0.0
    return fit_line(rows[usable][fit.ok], fit.location[fit.ok], transposed, expected)


def edge_rows(image: np.ndarray, seed_x: np.ndarray,
              half_window: int = EDGE_FIT_HALF_WINDOW_PX) -> tuple[np.ndarray, FermiRows]:
    """The rows :func:`locate_edge` fits (those with ``half_window`` + 4
    pixels in their window about ``seed_x``) and what it fits in them.

    Raises
    ------
    TargetNotFoundError
        Fewer than 5 such rows.
    """
    cols, values, inside = row_windows(image, seed_x, half_window)
    usable = inside.sum(axis=1) >= half_window + 4
    if usable.sum() < 5:
        raise TargetNotFoundError("the edge does not cross enough rows of the image")
    return usable, FermiRows(cols[usable].astype(float), values[usable], inside[usable].astype(float), seed_x[usable],
                             usable)


def fit_line(y: np.ndarray, x: np.ndarray, transposed: bool = False,
             location_sd_px: float = 0.0) -> TargetGeometry:
    """Robust least-squares line x = m y + k through per-row locations:
    refitted after discarding locations more than 4 robust standard
    deviations (and 0.05 px) off it."""
    if y.size < 5:
        raise TargetNotFoundError("the per-row fits failed: no clear target profile in the rows")
    keep = np.ones(y.size, bool)
    for _ in range(4):
        slope, intercept = _straight_line(y[keep], x[keep])
        resid = x - (slope * y + intercept)
        mad = 1.4826 * median(np.abs(resid[keep] - median(resid[keep])))
        new_keep = np.abs(resid) <= max(4.0 * mad, 0.05)
        if np.array_equal(new_keep, keep) or new_keep.sum() < 5:
            break
        keep = new_keep
    slope, intercept = _straight_line(y[keep], x[keep])
    return TargetGeometry(float(slope), float(intercept), y, x, keep, transposed, location_sd_px)


def _straight_line(y: np.ndarray, x: np.ndarray) -> tuple[float, float]:
    """The least-squares line x = m y + k, (m, k), in closed form about the
    mean of ``y`` (rows: distinct, so never degenerate), as np.polyfit
    gives it to rounding without its SVD."""
    mean_y = float(y.sum()) / y.size
    centred = y - mean_y
    slope = float(centred @ x) / float(centred @ centred)
    return slope, float(x.sum()) / x.size - slope * mean_y


def row_windows(image: np.ndarray, centre_x: np.ndarray,
                half_window: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each row's pixels within ``half_window`` of ``centre_x``: (cols,
    values, inside), arrays of n_rows x (2 half_window + 1), ``inside``
    False where the window leaves the image or meets a left-out (NaN)
    pixel, whose value is then 0."""
    rows_n, cols_n = image.shape
    cols = np.rint(centre_x).astype(int)[:, None] + np.arange(-half_window, half_window + 1)[None, :]
    inside = (cols >= 0) & (cols < cols_n)
    values = image[np.arange(rows_n)[:, None], np.clip(cols, 0, cols_n - 1)]
    inside &= np.isfinite(values)
    return cols, np.where(inside, values, 0.0), inside


def vertical_frame(image: np.ndarray, line: Line) -> tuple[np.ndarray, np.ndarray, bool]:
    """The image in the vertical frame of ``line`` (transposed when the line
    is nearer horizontal), the line's column in every row of that frame, and
    whether it was transposed."""
    t = math.radians(line.theta_deg)
    c, s = math.cos(t), math.sin(t)
    transposed = abs(s) > abs(c)
    work = image.T if transposed else image
    a, b = (s, c) if transposed else (c, s)        # the line: a x + b y = rho
    return work, (line.rho_px - np.arange(work.shape[0]) * b) / a, transposed


def check_angle(geometry: TargetGeometry, name: str) -> None:
    """Refuse a target too close to an axis or to 45 deg for sub-pixel
    sampling."""
    a = abs(math.degrees(math.atan(geometry.slope)))
    advice = f"(tilt it by {MIN_ANGLE_DEG:g} to {MAX_ANGLE_DEG:g} deg)"
    if a < MIN_ANGLE_DEG:
        raise UnsuitableTargetError(f"the {name} is {a:.2f} deg from the image axis: too close "
                                    f"for sub-pixel sampling {advice}", reason="angle")
    if a > MAX_ANGLE_DEG:
        raise UnsuitableTargetError(f"the {name} is {a:.2f} deg from the image axis, too close "
                                    f"to 45 deg for sub-pixel sampling {advice}", reason="angle")


def profile_samples(work: np.ndarray, geometry: TargetGeometry,
                    name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Every pixel of the kept rows as a profile sample: ``(d, v, row,
    half_range)``, the signed distance (px) to the line, the value, the
    sample's row (vertical frame), and the distance D within which samples
    are kept (the distance 3 rows in 4
    reach on both sides, at most ``MAX_HALF_RANGE_PX``).

    Refuses a target too near the border or whose samples leave a gap wider
    than ``MAX_SAMPLE_GAP_PX`` within 2 px of the line."""
    rows = geometry.rows[geometry.kept]
    cols = np.arange(work.shape[1], dtype=float)
    d = geometry.distance(cols[None, :], rows[:, None].astype(float))
    v = work[rows]
    row = np.broadcast_to(rows[:, None], d.shape)
    valid = np.isfinite(v)
    # how far each row's data reach on either side of the line (left-out pixels skipped)
    reach = np.minimum(-np.where(valid, d, np.inf).min(axis=1), np.where(valid, d, -np.inf).max(axis=1))
    half_range = min(float(quantile(reach, 0.25)), MAX_HALF_RANGE_PX)
    if half_range < MIN_HALF_RANGE_PX:
        raise UnsuitableTargetError(
            f"the {name} is {max(half_range, 0):.1f} px from the image border; at least "
            f"{MIN_HALF_RANGE_PX:g} px of flat level are needed on each side", reason="border")
    inside = (np.abs(d) <= half_range) & valid
    d, v, row = d[inside], v[inside], row[inside]
    if np.count_nonzero(np.abs(d) < 2.0) < 20:
        raise UnsuitableTargetError(f"too few samples near the {name}")
    gap = sample_gap(d)
    if gap > MAX_SAMPLE_GAP_PX:
        raise UnsuitableTargetError(
            f"the {name} at {geometry.angle_deg:.2f} deg samples sub-pixel phases with a gap of "
            f"{gap:.2f} px (at most {MAX_SAMPLE_GAP_PX} allowed): too few rows, or an angle "
            "whose phases repeat every 1-3 rows (near 45, 26.6, 18.4 deg)")
    return d, v, row, half_range


DIRECTION_TOLERANCE_DEG = 10.0


#: the directions of an image with no georeference and no track information (a camera's photo): its
#: own axes, which rows along track would call across and along track (the normal along x is
#: "horizontal": the MTF across the image's columns, from a near-vertical edge)
IMAGE_AXES = {"across-track": "horizontal", "along-track": "vertical"}
#: the directions named by an axis (of the track or of the image), not by a normal's angle
AXIS_DIRECTIONS = (*IMAGE_AXES, *IMAGE_AXES.values())


def image_axis_label(label: str) -> str:
    """A direction measured with rows taken along track, named by the
    image's axes instead ("horizontal", "vertical"; "oblique" stays).

    Examples
    --------
    >>> image_axis_label(direction_label(5.0, 0.0)), image_axis_label("oblique")
    ('horizontal', 'oblique')
    """
    return IMAGE_AXES.get(label, label)


def direction_label(normal_angle_deg: float, track_azimuth_deg: float | None) -> str:
    """"along-track" when the normal lies within 10 deg of the ground
    track, "across-track" within 10 deg of its perpendicular, "oblique"
    otherwise, "unknown" without a track.

    ``track_azimuth_deg`` is the track's direction clockwise from the
    image's up (0: rows along track); the normal angle is measured from
    +x towards +y (down), so the track lies at azimuth - 90 on that scale.

    Examples
    --------
    >>> direction_label(5.0, 0.0), direction_label(84.0, 0.0), direction_label(30.0, 0.0)
    ('across-track', 'along-track', 'oblique')
    """
    if track_azimuth_deg is None:
        return "unknown"
    offset = abs((normal_angle_deg - (track_azimuth_deg - 90.0) + 90.0) % 180.0 - 90.0)
    if offset <= DIRECTION_TOLERANCE_DEG:
        return "along-track"
    if offset >= 90.0 - DIRECTION_TOLERANCE_DEG:
        return "across-track"
    return "oblique"

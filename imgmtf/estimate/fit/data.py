"""What each edge gives the fit: its samples' distances and values binned
finely along its normal (:func:`bin_profile`), its noise; from an image (an
array, or an :class:`EdgeImage` with what its file said) or a measurement.
No file is opened here: :func:`imgmtf.fit_sensor` reads them."""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import DTypeLike

from ...errors import ImgmtfError, ParameterError

if TYPE_CHECKING:
    from ...sensor.lines import HermitePlacement, LineResponse
    from ..edge import EdgeResult
    from .responses import StackedResponses


@dataclass(frozen=True, eq=False)
class EdgeImage:
    """An image of one edge and what its file said of it: an input of the
    fit where an array alone does not say enough (what
    :func:`imgmtf.fit_sensor` makes of a file).

    Attributes
    ----------
    image : numpy.ndarray, shape (rows, cols)
        The pixels, DN.
    source : str
        What messages and results name it by (the file).
    gsd_m : float or None
        The pixel, m, when known.
    dtype : numpy dtype or str, optional
        The stored sample type when ``image`` is not in it (a file's pixels
        read as floats): an integer type sets the saturation levels and the
        quantisation's noise floor (default ``image``'s own).

    Examples
    --------
    >>> import numpy as np
    >>> EdgeImage(np.zeros((2, 2)), "chip.tif", 0.5, "uint16").source
    'chip.tif'
    """

    image: np.ndarray
    source: str
    gsd_m: float | None = None
    dtype: DTypeLike | None = None


@dataclass(frozen=True, eq=False)
class MeasuredEdge:
    """An edge already measured from a file, as ``imgmtf measure`` reads
    and measures it (its window, nodata, transfer curve, forced checks),
    with the name its file gives it: what :func:`imgmtf.fit_sensor` makes
    of a file.

    Attributes
    ----------
    result : EdgeResult
        The measurement (its samples, levels and geometry are what the fit takes).
    source : str
        What messages and results name it by (the file, with its ROI).
    integer : bool
        True when its samples are a file's integer DN as stored (their
        rounding, 1/sqrt(12) DN, is then the noise floor).
    """

    result: EdgeResult
    source: str
    integer: bool = False


#: the fit's bins along the normal, px.  The model of a bin is the mean of
#: the ESF over its samples, f(x̄) + f''(x̄) m2 / 2 (:func:`bin_esf`);
#: it leaves out the third and fourth moments' terms, at most f''' w^3 / 48
#: and f'''' w^4 / 384 for bins w wide.  Measured on noise-free slanted-edge
#: samples (5 deg, 100 and 300 rows; tests/test_fit_bins.py), for a step of
#: 1: at 1/32 px the bins' model is within 3.3e-7 of the samples' mean model
#: for Gaussian optics of 0.3 px + pixel and the paper's sensor, 1.2e-6 for
#: f/8 diffraction and 4.5e-6 for f/5.6 (their sharp cores), where without
#: the m2 term it is 5-7e-5 off.  In units of a bin mean's noise at the
#: noise floor of noise-free floats (1e-5 / sqrt(n)) that is 0.007 RMS
#: (0.022 at f/5.6), against 0.9-1.9 without the m2 term.  A 300-row edge of
#: the scan (300 samples per px) gives 9 x fewer residuals, a 100-row chip
#: 3 x.  1/16 px (19 x, 6 x) made the chart's fits only 10 % faster (what
#: remains is each edge's line response, not its samples) but lost what
#: lies within a bin: on a noise-free f/5.6 chip the likelihood-ratio cost
#: of its detector width fell from 11.2 to 10.6 (11.2 at 1/32 px).
FIT_BIN_PX = 1 / 32


@dataclass(frozen=True, eq=False)
class ProfileBins:
    """An edge's samples binned along its normal (:func:`bin_profile`):
    per non-empty bin, its samples' count, their mean distance from the
    edge and mean value, and their distances' variance.

    Attributes
    ----------
    count : numpy.ndarray of int
        Samples in each bin.
    x : numpy.ndarray
        Their mean signed distance from the edge, px (ascending).
    y : numpy.ndarray
        Their mean value, DN.
    m2 : numpy.ndarray
        The variance of their distances about ``x``, px^2.
    """

    count: np.ndarray
    x: np.ndarray
    y: np.ndarray
    m2: np.ndarray


def bin_profile(x: np.ndarray, y: np.ndarray, width_px: float = FIT_BIN_PX) -> ProfileBins:
    """Profile samples binned along the normal: bins ``width_px`` wide from
    0 px (empty ones dropped), each with its count, mean distance, mean
    value and the variance of its distances.

    Parameters
    ----------
    x : numpy.ndarray
        Samples' signed distances from the edge, px.
    y : numpy.ndarray
        Their values, DN.
    width_px : float, optional
        The bins' width, px (default :data:`FIT_BIN_PX`).

    Returns
    -------
    ProfileBins
        The non-empty bins, by distance.

    Examples
    --------
    >>> bins = bin_profile(np.array([0.1, 0.3, 0.2, 1.5]), np.array([1.0, 3.0, 2.0, 7.0]), 1.0)
    >>> bins.count.tolist(), bins.x.round(6).tolist(), bins.y.tolist(), bins.m2.round(6).tolist()
    ([3, 1], [0.2, 1.5], [2.0, 7.0], [0.006667, 0.0])
    """
    order = np.argsort(x, kind="stable")
    return sorted_bins(np.asarray(x, float)[order], np.asarray(y, float)[order], width_px)


def sorted_bins(x: np.ndarray, y: np.ndarray, width_px: float = FIT_BIN_PX) -> ProfileBins:
    """:func:`bin_profile` of float samples ``x`` (px) already in ascending
    order, ``y`` (DN) in theirs: the same bins, without sorting them again
    (a stable sort of sorted distances keeps every sample in its place;
    :func:`edge_data` sorts its samples before it bins them)."""
    if not x.size:
        return ProfileBins(np.zeros(0, np.intp), x, y, x.copy())
    keys = np.floor(x / width_px)
    starts = np.flatnonzero(np.concatenate(([True], keys[1:] != keys[:-1])))
    count = np.diff(np.append(starts, x.size))
    mean_x = np.add.reduceat(x, starts) / count
    spread = x - np.repeat(mean_x, count)             # about the mean: no cancellation
    return ProfileBins(count, mean_x, np.add.reduceat(y, starts) / count,
                       np.add.reduceat(spread * spread, starts) / count)


@dataclass(frozen=True, eq=False)
class EdgeData:
    """What one edge gives the fit: its samples (distances px, ascending,
    and values DN), binned (what the model is fitted to), their noise (DN,
    of one sample), levels (DN, as measured) and geometry.

    ``profile_angle_deg`` is the direction the samples' distances grow
    along, from the x axis: the normal's (``normal_angle_deg``, in
    (-90, 90]) or, ``reversed_profile``, the opposite one.  A near-horizontal edge's distances
    grow toward increasing row whatever its normal's sign, so for a normal
    that points toward decreasing row it is the normal + 180 deg.  Only a
    one-sided stage (a complex transfer, an asymmetric LSF) tells the two
    apart.
    """

    source: str
    x: np.ndarray
    y: np.ndarray
    bins: ProfileBins
    normal_angle_deg: float
    gsd_m: float
    gsd_known: bool
    noise: float
    levels: tuple[float, float]
    measurement: EdgeResult
    reversed_profile: bool = False

    @property
    def profile_angle_deg(self) -> float:
        """The direction (deg from the x axis) the samples' distances grow along."""
        return self.normal_angle_deg + 180.0 if self.reversed_profile else self.normal_angle_deg


def edge_data(item: np.ndarray | EdgeImage | MeasuredEdge | EdgeResult, k: int, gsd_m: float | None) -> EdgeData:
    """What edge ``k`` (0-based) gives the fit: an image measured (its
    geometry only), or a measurement taken as it is."""
    from ...inputs import saturation_levels
    from ..edge import EdgeResult, measure_edge
    from ..intervals import Bootstrap
    from ..results import MTFResult
    if isinstance(item, MTFResult) and not isinstance(item, EdgeResult):
        raise ParameterError(f"edge {k + 1}: a {type(item).__name__}; the fit takes edges (an EdgeResult, "
                             "an image array or a file)")
    if isinstance(item, (str, os.PathLike)):
        raise ParameterError(f"edge {k + 1}: a file ({item}); the fit takes images and measurements: "
                             "imgmtf.fit_sensor reads files")
    if isinstance(item, MeasuredEdge):
        source, result, integer = item.source, item.result, item.integer
    elif isinstance(item, EdgeResult):
        source, result, integer = f"edge {k + 1}", item, False
    else:
        if not isinstance(item, EdgeImage):
            item = EdgeImage(np.asarray(item), f"array {k + 1}")
        source = item.source
        dtype = np.dtype(item.dtype if item.dtype is not None else item.image.dtype)
        try:
            result = measure_edge(item.image, gsd_m=gsd_m if gsd_m is not None else item.gsd_m,
                                  saturation=saturation_levels(dtype), bootstrap=Bootstrap(0))
        except ImgmtfError as exc:
            # name the input, keeping the error's class, reason and checks
            exc.args = (f"{source}: {exc}",)
            raise
        integer = np.issubdtype(dtype, np.integer)
    x = np.asarray(result.samples_x_px, float)
    y = np.asarray(result.samples_dn, float)
    order = np.argsort(x, kind="stable")
    x, y = x[order], y[order]
    levels = (float(result.levels_dn[0]), float(result.levels_dn[1]))
    step = abs(levels[1] - levels[0])
    if x.size < 20 or not step > 0:
        raise ImgmtfError(f"{source}: too few edge samples to fit", reason="unsuitable")
    # quantisation (1 DN) for integer data, else a floor for noise-free floats
    floor = 1 / math.sqrt(12) if integer else 1e-5 * step
    noise = max(profile_noise(x, y), floor)           # of one sample, from the samples themselves
    gsd = result.gsd_m if result.gsd_m else (gsd_m or 1.0)
    normal = float(result.normal_angle_deg)
    return EdgeData(source, x, y, sorted_bins(x, y), normal, float(gsd), bool(result.gsd_m),
                    noise, levels, result, profile_angle_deg(result) != normal)


def profile_angle_deg(result: EdgeResult) -> float:
    """The direction (deg from the x axis) an edge measurement's sample
    distances (and its LSF's) grow along: its normal, or for a
    near-horizontal edge whose normal points toward decreasing row the
    opposite one (the vertical frame's distances grow toward +x, a
    transposed frame's toward +y)."""
    normal = float(result.normal_angle_deg)
    return normal + 180.0 if result.orientation == "horizontal" and normal < 0 else normal


def profile_noise(x: np.ndarray, y: np.ndarray) -> float:
    """Noise standard deviation (DN) of profile samples ``y`` at sorted
    positions ``x``, without a model: each sample against the straight line
    through its two neighbours, robust (median absolute deviation), so the
    few samples where the profile curves do not count."""
    left, right = x[1:-1] - x[:-2], x[2:] - x[1:-1]
    span = left + right
    ok = span > 0
    w = np.where(ok, right / np.where(ok, span, 1.0), 0.5)
    misfit = y[1:-1] - (w * y[:-2] + (1 - w) * y[2:])
    scale = np.sqrt(1 + w**2 + (1 - w) ** 2)
    return float(1.4826 * np.median(np.abs(misfit / scale)))


def bin_esf(response: LineResponse | StackedResponses, bins: ProfileBins, x0: float | np.ndarray,
            placement: HermitePlacement | None = None) -> np.ndarray:
    """The mean of the edge response over each bin's samples, for an edge
    at ``x0`` px: ESF(x̄ - x0) + ESF''(x̄ - x0) m2 / 2, exact but for the
    third and higher moments' terms (see :data:`FIT_BIN_PX`).
    Several edges' bins in turn take their :class:`.responses.StackedResponses`
    and each bin's edge's ``x0``; ``placement``, when given, is the bins'
    distances placed on the response's grid with the curvature's weights."""
    value, curvature = response.esf_with_curvature(bins.x - x0, placement)
    return value + 0.5 * bins.m2 * curvature

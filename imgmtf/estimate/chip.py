"""The pipeline's first stage: the chip's pixels checked and prepared for
measuring (cropped, masked, linearised), with what is known of them (the
sensor's limits, the values' quantum, the pixel noise) and the pixels left
out (nodata, isolated hot and dead pixels)."""
from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from ..errors import ParameterError
from ..inputs import as_array, check_number, prepare_image, quantum, saturation_levels
from ..transfer import full_scale, noise_gain
from . import gate
from .detection import robust_noise
from .outliers import isolated_outliers
from .settings import Settings
from .state import Chip


def prepare_chip(image: ArrayLike, settings: Settings, *, roi: tuple[int, int, int, int] | None = None,
                 mask: np.ndarray | None = None, gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None, dtype: DTypeLike | None = None,
                 track_azimuth_deg: float | None = 0.0) -> Chip:
    """The chip of ``image`` to measure, and what is known of its pixels.

    Parameters
    ----------
    image : array_like
        2-D image, DN.
    settings : Settings
        The estimator's settings (their ``transfer`` linearises the values).
    roi : (int, int, int, int), optional
        (x, y, width, height) crop, px.
    mask : numpy.ndarray of bool, optional
        Of the image's shape, True for the pixels that belong to the chip.
    gsd_m : float, optional
        Ground sample distance, m.
    saturation : (float, float), optional
        (low, high) DN the sensor records; None for an integer type's range.
    dtype : numpy dtype, optional
        The type the values were stored as when ``image`` is a float copy.
    track_azimuth_deg : float or None, optional
        The ground track's direction, degrees clockwise from the image's up.

    Returns
    -------
    Chip
        The prepared pixels (linear light, NaN where left out), their
        limits, quantum and noise, the fill check and what must be said.

    Raises
    ------
    ParameterError, ImageContentError
        Unusable input: a bad crop, mask, number or saturation pair, an
        image too small or without finite values.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.settings import make_settings
    >>> image = np.zeros((40, 40), np.uint8)
    >>> image[:, 20:] = 200
    >>> image[5, 5] = 255                                  # a hot pixel
    >>> chip = prepare_chip(image, make_settings(), roi=(0, 0, 40, 30))
    >>> chip.roi, chip.limits, chip.quantum_dn, chip.left_out_px
    ((0, 0, 40, 30), (0.0, 255.0), 1.0, {'outlier_px': 1})
    """
    array = as_array(image)
    stored = np.dtype(dtype) if dtype is not None else array.dtype
    pixels, (x0, y0) = prepare_image(array, roi, mask)
    gsd_m = None if gsd_m is None else check_number("gsd_m", gsd_m, positive=True)
    if track_azimuth_deg is not None:
        track_azimuth_deg = check_number("track_azimuth_deg", track_azimuth_deg, signed=True)
    limits = _saturation(saturation) if saturation is not None else saturation_levels(stored)
    decoded = []
    gain, stored_noise = None, math.nan
    if not settings.transfer.is_linear:
        # the noise of the values as stored, and how linearising them scales it at each level
        scale = full_scale(stored)
        stored_noise = max(robust_noise(pixels), quantum(pixels, stored) / math.sqrt(12.0))
        gain = functools.partial(_noise_gain, settings.transfer, scale)
        # linear light in the same DN scale; the type's limits stay put, its
        # quantum does not (the decoded steps are uneven)
        scale = full_scale(stored)
        pixels = settings.transfer.linearise(pixels, scale)
        limits = None if limits is None else (float(settings.transfer.linearise(np.array(limits[0]), scale)),
                                              float(settings.transfer.linearise(np.array(limits[1]), scale)))
        stored = np.dtype(np.float64)
        decoded.append(f"the values were linearised ({settings.transfer}, full scale {scale:g} DN) before "
                       "measuring")
    quantum_dn = quantum(pixels, stored)
    fill = gate.fill_check(pixels, stored)
    noise_dn = robust_noise(pixels)
    rows, cols = pixels.shape
    chosen = None if mask is None else np.asarray(mask)[y0:y0 + rows, x0:x0 + cols]
    left_out, said = _left_out_pixels(pixels, chosen, noise_dn)
    return Chip(pixels, (x0, y0), limits, quantum_dn, noise_dn, gsd_m, track_azimuth_deg, (fill,),
                tuple(said + decoded), left_out, gain, stored_noise)


def _noise_gain(transfer, scale: float, level_dn: float) -> float:
    """How linearising with ``transfer`` (full scale ``scale``, DN) scales
    the stored values' noise at the linear level ``level_dn``."""
    return float(noise_gain(transfer, np.array([level_dn]), scale)[0])


def _left_out_pixels(data: np.ndarray, mask: np.ndarray | None, noise: float) -> tuple[dict[str, int], list[str]]:
    """Leave isolated hot and dead pixels out of ``data`` (set to NaN, in
    place) and count them and the NaN or nodata pixels among those the
    caller's ``mask`` (cropped to ``data``) keeps: (params, warnings)
    saying so."""
    nodata = int(np.count_nonzero(np.isnan(data) if mask is None else np.isnan(data) & mask))
    hot = isolated_outliers(data, noise)
    data[hot] = np.nan
    counts = {"nodata_px": nodata, "outlier_px": int(hot.sum())}
    said = []
    if nodata:
        said.append(f"{nodata} NaN or nodata pixel(s) inside the chip are left out of the estimate")
    if hot.any():
        said.append(f"{int(hot.sum())} isolated outlying pixel(s) (hot or dead) are left out of the estimate")
    return {k: v for k, v in counts.items() if v}, said


def _saturation(value) -> tuple[float, float]:
    try:
        low, high = value
    except (TypeError, ValueError):
        raise ParameterError(f"saturation must be two numbers (low, high) in DN, got {value!r}") from None
    low = check_number("saturation low", low, signed=True)
    high = check_number("saturation high", high, signed=True)
    if not low < high:
        raise ParameterError(f"saturation low must be below high, got ({low:g}, {high:g})")
    return low, high

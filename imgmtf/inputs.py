"""Checks and crops shared by the estimators: what makes an array a chip
that can be measured."""
from __future__ import annotations

import math
import os

import numpy as np
from numpy.typing import ArrayLike

from .errors import ImageContentError, ParameterError

MIN_SIZE_PX = 16
MAX_ABS_DN = 1e15                 # no sensor records more; beyond, squares overflow
MIN_RANGE_DN = 1e-6               # a smaller spread of values meets the fits' absolute tolerances
# Rec. 709 luma weights (red, green, blue), applied to the stored values
LUMA_WEIGHTS = (0.2126, 0.7152, 0.0722)
MIN_BAR_WIDTH_PX = 0.2              # narrower, a bar's signal is below any noise
MIN_FIRST_ZERO_CY_PX = 0.1      # a wider bar leaves too little usable band


def luminance(rgb: ArrayLike, channel_axis: int = -1) -> np.ndarray:
    """The Rec. 709 luminance of a colour image, as ``imgmtf measure``
    computes it for an RGB(A) file: 0.2126 R + 0.7152 G + 0.0722 B of the
    stored values (gamma-encoded values stay encoded: no linearisation),
    alpha ignored.

    Parameters
    ----------
    rgb : array_like, shape (H, W, 3) or (H, W, 4)
        Red, green, blue (and alpha) along ``channel_axis``, any real dtype
        (DN).
    channel_axis : int, optional
        The axis holding the channels (default the last; 0 for rasterio's
        band-first arrays).

    Returns
    -------
    numpy.ndarray, shape (H, W), float64
        The luminance in the input's DN.

    Raises
    ------
    ImageContentError
        The array is not 3-D with 3 or 4 channels, or its values are not
        real numbers.
    ParameterError
        ``channel_axis`` is not an axis of a 3-D array.

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> rgba = np.zeros((20, 30, 4), np.uint8)
    >>> rgba[..., 1] = 100                       # green only
    >>> gray = imgmtf.luminance(rgba)
    >>> gray.shape, float(gray[0, 0])
    ((20, 30), 71.52)
    """
    array = np.asarray(rgb)
    if not (np.issubdtype(array.dtype, np.number) and not np.iscomplexobj(array)):
        raise ImageContentError(f"expected real pixel values, got dtype {array.dtype}")
    if isinstance(channel_axis, (bool, np.bool_)) or not isinstance(channel_axis, (int, np.integer)) \
            or not -3 <= channel_axis < 3:
        raise ParameterError(f"channel_axis must be an axis of a 3-D array (-3 to 2), got {channel_axis!r}")
    if array.ndim != 3 or array.shape[channel_axis] not in (3, 4):
        raise ImageContentError(f"expected a colour image of shape (H, W, 3) or (H, W, 4) with the channels "
                                f"on axis {channel_axis}, got an array of shape {array.shape}")
    colours = np.moveaxis(array, channel_axis, 0)[:3].astype(np.float64)
    return np.tensordot(np.asarray(LUMA_WEIGHTS), colours, axes=1)


def check_number(name: str, value, *, positive: bool = False, allow_inf: bool = False,
                 low: float | None = None, high: float | None = None, integer: bool = False,
                 signed: bool = False) -> float:
    """``value`` as a float (an int with ``integer``) if it is a finite real
    number >= 0 (> 0 with ``positive``; any sign with ``signed``; inf
    allowed with ``allow_inf``; within [``low``, ``high``] when given),
    NumPy scalars and 0-d arrays included; else a :class:`ParameterError` naming ``name``.

    Examples
    --------
    >>> check_number("gsd_m", 0.5, positive=True)
    0.5
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]                  # a 0-d array (np.asarray(2.0)) is its one number
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    try:
        number = float(value)
    except OverflowError:                  # an int beyond any float (a TOML integer of 400 digits)
        raise ParameterError(f"{name} must be finite, got an integer of {len(str(abs(value)))} digits") from None
    bad = math.isnan(number) or (math.isinf(number) and not (allow_inf and number > 0))
    if bad or (number < 0 and not signed):
        raise ParameterError(f"{name} must be finite{'' if signed else ' and >= 0'}, got {value!r}")
    if positive and number <= 0:
        raise ParameterError(f"{name} must be > 0, got {value!r}")
    if integer and number != int(number):
        raise ParameterError(f"{name} must be a whole number, got {value!r}")
    if (low is not None and number < low) or (high is not None and number > high):
        bounds = (f"lie in [{low:g}, {high:g}]" if low is not None and high is not None
                  else f"be at least {low:g}" if low is not None else f"be at most {high:g}")
        raise ParameterError(f"{name} must {bounds}, got {value!r}")
    return int(number) if integer else number


def as_array(image) -> np.ndarray:
    """``image`` as a NumPy array; a file's path is refused with the way to
    read it (it would otherwise become a 0-d array of one string).

    Raises
    ------
    ParameterError
        ``image`` is a path (str or os.PathLike).

    Examples
    --------
    >>> as_array([[1, 2], [3, 4]]).shape
    (2, 2)
    """
    if isinstance(image, (str, os.PathLike)):
        raise ParameterError(f"expected an image array, got the path {str(image)!r}: read it with "
                             "imgmtf.read_raster(path).data (or measure files with `imgmtf measure`)")
    return np.asarray(image)


def prepare_image(image, roi=None, mask=None) -> tuple[np.ndarray, tuple[int, int]]:
    """Validate a 2-D image and crop it to ``roi`` = (x, y, width, height).

    ``mask`` (a boolean array of the image's shape, True where a pixel
    belongs to the chip) leaves the other pixels out: they come back as NaN,
    which every stage skips.  NaN pixels (a file's declared nodata, a
    cloud mask) are left out alike; whether enough of the target remains
    is the estimator's to judge (its rows, its sides).  Returns the float64 crop and the (x, y) of its
    top-left pixel in the image.

    Raises
    ------
    ParameterError
        A bad ROI or mask.
    ImageContentError
        An image that cannot be measured (nothing but NaN or nodata,
        infinite values, too small, flat, values no sensor records).
    """
    array = as_array(image)
    if array.ndim == 3 and array.shape[-1] in (3, 4):
        raise ImageContentError(f"expected a 2-D image, got an array of shape {array.shape}: for a colour "
                                "image measure its luminance, imgmtf.luminance(image) (what the CLI does "
                                "for RGB files), or one channel, image[..., 1]")
    if array.ndim != 2:
        raise ImageContentError(f"expected a 2-D image, got an array of shape {array.shape}")
    if not (np.issubdtype(array.dtype, np.number) and not np.iscomplexobj(array)):
        raise ImageContentError(f"expected real pixel values, got dtype {array.dtype}")
    if mask is not None:
        mask = np.asarray(mask)
        if mask.shape != array.shape or mask.dtype != bool:
            raise ParameterError(f"the mask must be a boolean array of the image's shape {array.shape}, "
                                 f"got {mask.dtype} {mask.shape}")
    x0, y0 = 0, 0
    if roi is not None:
        x0, y0, w, h = check_roi(roi, array.shape)
        array = array[y0:y0 + h, x0:x0 + w]
        mask = None if mask is None else mask[y0:y0 + h, x0:x0 + w]
    data = array.astype(np.float64)
    used = np.ones(data.shape, bool) if mask is None else mask
    infinite = np.isinf(data) & used
    if infinite.any():
        raise ImageContentError(f"{int(infinite.sum())} pixel(s) are infinite: not values a sensor records")
    # NaN (a declared nodata, a cloud mask) is left out as a mask leaves pixels out
    used = used & ~np.isnan(data)
    if not used.any():
        raise ImageContentError("every pixel is NaN or nodata: nothing to measure")
    if min(data.shape) < MIN_SIZE_PX:
        raise ImageContentError(f"the image is {data.shape[1]} x {data.shape[0]} pixels; "
                                f"at least {MIN_SIZE_PX} x {MIN_SIZE_PX} are needed")
    values = data[used]
    check_magnitude(values)
    if values.max() == values.min():
        raise ImageContentError("the image is flat: no contrast to measure")
    if values.max() - values.min() < MIN_RANGE_DN:
        raise ImageContentError(f"the pixel values span only {values.max() - values.min():.3g}: below "
                                f"{MIN_RANGE_DN:g} the fits lose their precision; rescale the image "
                                "(multiply it by a power of ten)")
    data[~used] = np.nan
    return data, (x0, y0)


def check_magnitude(values: np.ndarray, where: str = "") -> None:
    """Refuse finite ``values`` beyond :data:`MAX_ABS_DN` (an image in the
    wrong units); ``where`` (a file) prefixes the message."""
    peak = float(np.abs(values).max()) if values.size else 0.0
    if peak > MAX_ABS_DN:
        raise ImageContentError(f"{where + ': ' if where else ''}pixel values reach {peak:.3g}: beyond "
                                f"{MAX_ABS_DN:g} they are not DN an imaging sensor records; rescale the image")


def quantum(data: np.ndarray, dtype) -> float:
    """The DN step of the recorded values: 1 for integer types and for
    floats that hold only whole numbers, else 0 (not quantised).  Its
    rounding noise, quantum / sqrt(12), is the floor of any noise estimate."""
    if np.issubdtype(np.dtype(dtype), np.integer):
        return 1.0
    values = data[np.isfinite(data)]
    whole = np.round(values)
    # whole numbers spanning at least one step: values all within 1e-6 of 0
    # (a float image in tiny units) are not counts
    if values.size and np.allclose(values, whole, rtol=0, atol=1e-6) and whole.max() > whole.min():
        return 1.0
    return 0.0


def check_roi(roi, shape: tuple[int, int], where: str = "") -> tuple[int, int, int, int]:
    """``roi`` = (x, y, width, height) as integers, checked to lie inside an
    image of ``shape`` = (rows, cols); ``where`` (a file) prefixes errors."""
    prefix = f"{where}: " if where else ""
    try:
        numbers = [float(v) for v in roi]
        if not all(n.is_integer() for n in numbers):        # 60.5 px is a typo, not a width to truncate
            raise ValueError
        x, y, w, h = (int(n) for n in numbers)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(f"{prefix}ROI must be four integers x, y, width, height; got {roi!r}") from None
    rows, cols = shape
    if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > cols or y + h > rows:
        raise ParameterError(f"{prefix}ROI x={x}, y={y}, width={w}, height={h} is not inside "
                             f"the {cols} x {rows} image")
    return x, y, w, h


def saturation_levels(dtype) -> tuple[float, float] | None:
    """(min, max) representable by an integer dtype, None for floats."""
    dtype = np.dtype(dtype)
    if np.issubdtype(dtype, np.integer):
        info = np.iinfo(dtype)
        return float(info.min), float(info.max)
    return None


def check_width(width_px: float) -> float:
    """A bar's width (px) as a float.

    Raises
    ------
    ParameterError
        A width that is not a number of at least ``MIN_BAR_WIDTH_PX``, or one
        whose sinc has its first zero below ``MIN_FIRST_ZERO_CY_PX``.

    Examples
    --------
    >>> check_width(3)
    3.0
    """
    if isinstance(width_px, (int, float, np.integer, np.floating)) and not width_px > 0:
        raise ParameterError(f"the pulse width must be > 0 px, got {width_px!r}")
    width_px = check_number("the pulse width (px)", width_px, positive=True)
    if width_px < MIN_BAR_WIDTH_PX:
        raise ParameterError(f"a {width_px:g} px wide bar is narrower than {MIN_BAR_WIDTH_PX} px: its signal "
                             "would be below any noise (is the unit right?)")
    if 1.0 / width_px < MIN_FIRST_ZERO_CY_PX:
        raise ParameterError(
            f"a {width_px:g} px wide bar puts the first zero of its sinc at {1 / width_px:.3f} cy/px, "
            f"below {MIN_FIRST_ZERO_CY_PX} cy/px: too little of the MTF can be recovered")
    return width_px


LENGTH_UNITS = ("px", "m")


def parse_length(value, default_unit: str = "px") -> tuple[float, str]:
    """A length (a bar's width) as ``(value, unit)``, from what the CLI
    takes ("1.4", "1.4px", "18.3m"), a number (in ``default_unit``) or a
    ``(value, unit)`` pair; unit "px" (pixels) or "m" (metres on the ground).

    Raises
    ------
    ParameterError
        Not a number with an optional px or m suffix, or not finite.

    Examples
    --------
    >>> parse_length("18.3m"), parse_length(" 1.4PX "), parse_length(2)
    ((18.3, 'm'), (1.4, 'px'), (2.0, 'px'))
    """
    if isinstance(value, (tuple, list)) and len(value) == 2 and value[1] in LENGTH_UNITS:
        number, unit = value
    elif isinstance(value, str):
        text = value.strip().lower()
        unit = next((u for u in LENGTH_UNITS if text.endswith(u)), default_unit)
        number = text[: -len(unit)] if text.endswith(unit) else text
        try:
            number = float(number)
        except ValueError:
            raise ParameterError(f"expected a number with an optional px or m suffix, got {value!r}") from None
    else:
        number, unit = value, default_unit
    if isinstance(number, bool) or not isinstance(number, (int, float, np.integer, np.floating)):
        raise ParameterError(f"expected a length: a number, '1.4px' or '18.3m', got {value!r}")
    if not math.isfinite(number):
        raise ParameterError(f"expected a finite width, got {value!r}")
    return float(number), unit

"""Convolve an image with a restoration filter's taps: the whole array at
once, or a padded piece (a file's tile with its halo), by FFT convolution
of strips of rows."""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ImageContentError
from ..inputs import as_array

#: output rows convolved at once: FFT working copies of about this many rows
STRIP_ROWS = 256


def restore_array(image: ArrayLike, taps: np.ndarray, *, fill: float | None = None) -> np.ndarray:
    """Convolve a 2-D image with ``taps``, its borders mirrored
    (half-sample symmetric); NaN pixels hold ``fill`` (default: the median
    of the others) while filtering and are NaN in the result.

    Raises
    ------
    ImageContentError
        Not a 2-D array of real numbers, or no finite pixel.
    """
    array = as_array(image)
    if array.ndim != 2 or not np.issubdtype(array.dtype, np.number) or np.iscomplexobj(array):
        raise ImageContentError(f"expected a 2-D image of real numbers, got {array.dtype} of shape {array.shape}")
    values = array.astype(np.float64)
    valid = np.isfinite(values)
    if not valid.any():
        raise ImageContentError("every pixel is NaN or nodata: nothing to restore")
    if fill is None:
        fill = float(np.median(values[valid]))
    values[~valid] = fill
    r = taps.shape[0] // 2
    out = convolve_padded(np.pad(values, r, mode="symmetric"), taps)
    out[~valid] = np.nan
    return out


def convolve_padded(padded: np.ndarray, taps: np.ndarray) -> np.ndarray:
    """The part of ``padded`` * ``taps`` that needs no further padding
    (shape less the kernel's side less 1 in each axis), by FFT convolution
    of strips of :data:`STRIP_ROWS` output rows: the transforms' working
    copies are a strip's, not the whole array's."""
    from scipy.signal import fftconvolve
    side = taps.shape[0]
    out = np.empty((padded.shape[0] - side + 1, padded.shape[1] - side + 1))
    for start in range(0, out.shape[0], STRIP_ROWS):
        stop = min(start + STRIP_ROWS, out.shape[0])
        out[start:stop] = fftconvolve(padded[start: stop + side - 1], taps, mode="valid")
    return out

"""The chip a 2-D kind's estimator measures (point targets, stars): the
window of the image it names, linearised by the configured transfer curve
(its saturation levels with it), and the result placed back in the image
with what was done said in its parameters and warnings."""
from __future__ import annotations

from dataclasses import replace
from typing import Any, TypeVar

import numpy as np

from ..transfer import Transfer, full_scale

R = TypeVar("R")  # a frozen dataclass result with params, warnings and roi


def linear_window(image: np.ndarray, roi: tuple[int, int, int, int] | None, dtype: Any,
                  saturation: tuple[float, float] | None, transfer: Transfer
                  ) -> tuple[np.ndarray, tuple[float, float] | None, tuple[str, ...]]:
    """``image`` cut to ``roi`` (x, y, w, h px; None: whole) and, when
    ``transfer`` is not linear, linearised at the full scale of ``dtype``
    (the stored type; default the array's): the values, the saturation
    levels (DN) on the same scale, and the note saying so.

    Examples
    --------
    >>> from imgmtf.transfer import parse_transfer
    >>> data, levels, notes = linear_window(np.full((4, 6), 255, np.uint8), (1, 1, 3, 2), None, (0, 255),
    ...                                     parse_transfer("gamma:2.2"))
    >>> data.shape, float(data.max()), levels, notes[0].split(" (")[0]
    ((2, 3), 255.0, (0.0, 255.0), 'the values were linearised')
    """
    data = np.asarray(image)
    if roi is not None:
        x, y, w, h = roi
        data = data[y: y + h, x: x + w]
    if transfer.is_linear:
        return data, saturation, ()
    scale = full_scale(np.dtype(dtype) if dtype is not None else data.dtype)
    data = transfer.linearise(np.asarray(data, float), scale)
    if saturation is not None:
        saturation = (float(transfer.linearise(np.array(saturation[0]), scale)),
                      float(transfer.linearise(np.array(saturation[1]), scale)))
    return data, saturation, (f"the values were linearised ({transfer}, full scale {scale:g} DN) before measuring",)


def placed(result: R, roi: tuple[int, int, int, int] | None, method: str, transfer: Transfer,
           notes: tuple[str, ...]) -> R:
    """``result`` (a frozen result with ``params``, ``warnings`` and an
    ``roi`` in the window's coordinates) with its ROI in the image's, the
    resampling ``method`` and the ``transfer`` in its parameters, and the
    ``notes`` of :func:`linear_window` first among its warnings."""
    found: Any = result
    params = {**found.params, "resampling": method, "transfer": str(transfer)}
    origin = (0, 0) if roi is None else roi[:2]
    return replace(found, params=params, warnings=(*notes, *found.warnings),
                   roi=(origin[0], origin[1], found.roi[2], found.roi[3]))

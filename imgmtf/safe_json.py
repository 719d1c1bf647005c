"""JSON text of figures as records write it: NaN and infinities as null,
-0.0 as 0.0 (:func:`json_safe`), NumPy scalars and arrays as plain JSON,
written by json's C encoder at once and made safe only where needed
(:func:`dumps_safe`); curves rounded to 6 decimals at once
(:func:`finite_values`)."""
from __future__ import annotations

import json
import math
import re

import numpy as np
from numpy.typing import ArrayLike

#: beyond this, a value times 10^6 no longer holds its fraction to within the guard below
_ROUNDING_MAX = 1e9
_HALF_GUARD = 1e-5


def finite_values(values: ArrayLike) -> list[float | None]:
    """:func:`imgmtf.estimate.results.finite` of each value, a curve at
    once: rounded to 6 decimals, None where not finite; the very floats
    Python's ``round(v, 6)`` gives, in a fraction of its time (a dense
    chart's summaries round a hundred thousand values).

    ``round`` rounds the value's exact decimal expansion; here the value
    times 10^6 is rounded to the nearest integer (ties to even, as
    ``round``), then divided by 10^6 (correctly rounded: the double nearest
    that decimal, as ``round`` returns).  The product's own rounding can
    only change the integer for a value within its error of a tie: those
    (and values too large to hold a fraction) go through ``round`` itself.

    Examples
    --------
    >>> finite_values([0.12345649999, 1 / 3, float("nan"), -1e-9, 2.5e-6])
    [0.123456, 0.333333, None, -0.0, 3e-06]
    """
    x = np.asarray(values, float).ravel()
    with np.errstate(invalid="ignore", over="ignore"):
        scaled = x * 1e6
        whole = np.rint(scaled)
        out = (whole / 1e6).tolist()
        exact = (np.abs(scaled) < _ROUNDING_MAX) & (np.abs(np.abs(scaled - whole) - 0.5) > _HALF_GUARD)
    for i in np.flatnonzero(~exact).tolist():
        v = float(x[i])
        out[i] = round(v, 6) if math.isfinite(v) else None
    return out


def _json_default(value):
    """NumPy scalars and arrays, which records may hold, as plain JSON."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


# json's own encoder (in C) writes a row at once, with NaN, the infinities and -0.0 as Python spells
# them; a row where one of them stands as a value (after ": ", ", " or "[", before ",", "]" or "}") is
# written again through json_safe.  Walking every row's 200-odd values in Python first cost more than
# the encoding itself: a dense chart's 5816 rows took 1.5 s before the encoder's 1.2 s
ENCODER = json.JSONEncoder(default=_json_default)
_UNSAFE_VALUE = re.compile(r"(?:[:,] |\[)(?:NaN|-?Infinity|-0\.0)(?=[,\]}])")
# what such a value's text holds; searched for first (a substring search is some 50 times faster than
# the expression's, and rows seldom hold one)
_UNSAFE_PARTS = ("NaN", "Infinity", "-0.0,", "-0.0]", "-0.0}")


def has_unsafe_value(text: str) -> bool:
    """Whether JSON text written by json's encoder holds a NaN, an
    infinity or a -0.0 as a value (not within a string)."""
    return any(part in text for part in _UNSAFE_PARTS) and _UNSAFE_VALUE.search(text) is not None


SORTED_ENCODER = json.JSONEncoder(sort_keys=True, default=_json_default)


def dumps_sorted(value) -> str:
    """``json.dumps(json_safe(value), sort_keys=True)``, as :func:`dumps_safe` (a CSV cell's list or mapping)."""
    text = SORTED_ENCODER.encode(value)
    if has_unsafe_value(text):
        return json.dumps(json_safe(value), sort_keys=True, default=_json_default)
    return text


def dumps_safe(value) -> str:
    """``json.dumps(json_safe(value))`` (NumPy scalars and arrays as plain
    JSON), without walking ``value`` in Python unless it holds a NaN, an
    infinity or a -0.0.

    Examples
    --------
    >>> dumps_safe({"mtf": [0.5, float("nan")], "normal_angle_deg": -0.0, "note": "NaN, -0.0]"})
    '{"mtf": [0.5, null], "normal_angle_deg": 0.0, "note": "NaN, -0.0]"}'
    """
    text = ENCODER.encode(value)
    if has_unsafe_value(text):
        return json.dumps(json_safe(value), default=_json_default)
    return text


def json_safe(value):
    """``value`` with NaN and infinities (at any depth) as None, and -0.0 as
    0.0 (a normal at -0.00 deg is at 0), for JSON and CSV.

    Examples
    --------
    >>> json_safe({"normal_angle_deg": -0.0, "mtf": [0.5, float("nan")], "misfit": np.bool_(False)})
    {'normal_angle_deg': 0.0, 'mtf': [0.5, None], 'misfit': False}
    """
    kind = type(value)      # the leaves that need nothing, by their exact type, before any isinstance
    if kind is str or kind is int or kind is bool or value is None:
        return value
    if isinstance(value, np.generic):           # a NumPy scalar (bool, integer) as the Python one JSON writes
        value = value.item()
    if isinstance(value, float):
        return value + 0.0 if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    return value

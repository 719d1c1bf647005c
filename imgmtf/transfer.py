"""Transfer curves: how stored values relate to the light that made them.

An MTF is a property of a linear system: measured on gamma-encoded values
(most 8-bit camera images, JPEGs, PNGs from a raw developer) the edge is
not the light's and the MTF reads wrong (an 8-bit sRGB edge reads about
0.04 low at Nyquist).  imgmtf takes values as linear unless told
(``transfer="linear"``, the default for data files); ``"srgb"`` decodes
the sRGB curve (IEC 61966-2-1) and ``"gamma:G"`` a pure power law V^G,
each on the values as a fraction of the type's full scale (255 for 8-bit,
65535 for 16-bit, 1 for floats), the result in the same DN scale.

Other tools: MTF Mapper takes 8-bit input as sRGB unless told it is linear
(``-l``) and 16-bit input as linear; Imatest applies its gamma setting
(default 0.5 encoding, that is a decoding exponent of 2) unless told the
file is linear.

Examples
--------
>>> t = parse_transfer("gamma:2.2")
>>> t.name, t.gamma
('gamma', 2.2)
>>> float(parse_transfer("srgb").linearise(np.array([255.0]), 255.0)[0])
255.0
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ParameterError

NAMES = ("linear", "srgb", "gamma")
GAMMA_RANGE = (0.2, 5.0)


@dataclass(frozen=True)
class Transfer:
    """A transfer curve: ``name`` one of "linear", "srgb", "gamma";
    ``gamma`` the decoding exponent G of "gamma" (linear = V^G)."""

    name: str = "linear"
    gamma: float | None = None

    @property
    def is_linear(self) -> bool:
        return self.name == "linear"

    def __str__(self) -> str:
        return f"gamma:{self.gamma:g}" if self.name == "gamma" else self.name

    def linearise(self, values: np.ndarray, full_scale: float) -> np.ndarray:
        """``values`` (DN, 0 to ``full_scale``) decoded to linear light in
        the same DN scale (0 and full scale stay where they are); values
        outside that range are clipped to it first (a negative sRGB value
        has no decoding)."""
        v = np.clip(np.asarray(values, np.float64) / full_scale, 0.0, 1.0)
        if self.name == "srgb":
            out = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
        elif self.name == "gamma":
            out = v ** float(self.gamma)   # type: ignore[arg-type]
        else:
            return np.asarray(values, np.float64)
        return out * full_scale


def noise_gain(transfer: Transfer, linear_values, full_scale: float) -> np.ndarray:
    """How linearisation scales the noise of the stored values at each
    linear value (DN): the slope d(linear) / d(stored) of ``transfer`` at
    the stored value that decodes to it.  Noise uniform in the stored
    values becomes this much larger (bright) or smaller (dark) in linear
    light; 1 for "linear".

    Examples
    --------
    >>> [round(float(g), 3) for g in noise_gain(parse_transfer("gamma:2"), np.array([25.0, 100.0]), 100.0)]
    [1.0, 2.0]
    """
    u = np.clip(np.asarray(linear_values, np.float64) / full_scale, 0.0, 1.0)
    if transfer.name == "srgb":
        encoded = np.where(u <= 0.0031308, 12.92 * u, 1.055 * u ** (1 / 2.4) - 0.055)
        return np.where(encoded <= 0.04045, 1 / 12.92, 2.4 / 1.055 * ((encoded + 0.055) / 1.055) ** 1.4)
    if transfer.name == "gamma":
        gamma = float(transfer.gamma)  # type: ignore[arg-type]
        return gamma * u ** ((gamma - 1.0) / gamma)
    return np.ones_like(u)


def parse_transfer(value) -> Transfer:
    """A :class:`Transfer` from "linear", "srgb" or "gamma:G" (G, the
    decoding exponent, in [0.2, 5]), or a Transfer as it is.

    Raises
    ------
    ParameterError
        Any other value.
    """
    if isinstance(value, Transfer):
        return value
    if value is None:
        return Transfer()
    text = str(value).strip().lower() if isinstance(value, str) else None
    if text in ("linear", "srgb"):
        return Transfer(text)
    if text and text.startswith("gamma:"):
        try:
            gamma = float(text.split(":", 1)[1])
        except ValueError:
            gamma = float("nan")
        if GAMMA_RANGE[0] <= gamma <= GAMMA_RANGE[1]:
            return Transfer("gamma", gamma)
        raise ParameterError(f"the gamma of transfer {value!r} must be a number in "
                             f"[{GAMMA_RANGE[0]:g}, {GAMMA_RANGE[1]:g}] (2.2 is common)")
    raise ParameterError(f"transfer must be 'linear', 'srgb' or 'gamma:G' (e.g. gamma:2.2), got {value!r}")


def full_scale(dtype) -> float:
    """The value of full light in a type: its maximum for integers, 1 for
    floats."""
    dtype = np.dtype(dtype)
    return float(np.iinfo(dtype).max) if np.issubdtype(dtype, np.integer) else 1.0

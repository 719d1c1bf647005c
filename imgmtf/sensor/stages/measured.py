"""The MeasuredMTF stage ('measured'): a 2-D MTF measured without a model,
tabulated: see :mod:`imgmtf.sensor.stages`."""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ParameterError
from .base import Stage, register

#: the combinations of the across- and along-track sections a measured MTF takes
COMBINATIONS = ("separable", "elliptical")
#: beyond the sections' last frequency the MTF rolls off as a Gaussian of this width (cy/px): a
#: tabulated transfer cut bare there would ring in every line response
ROLL_OFF_CY_PX = 0.1
#: the PSF's support, px: a measured system's blur is a few px (the sections are read to 0.8 cy/px)
SUPPORT_PX = 12.0


def _curve(name: str, value) -> tuple[float, ...]:
    try:
        array = np.asarray(value, float)
    except (TypeError, ValueError):
        raise ParameterError(f"measured {name} must be a list of numbers, got {value!r}") from None
    if array.ndim != 1 or array.size < 2 or not np.all(np.isfinite(array)):
        raise ParameterError(f"measured {name} must be a list of at least 2 finite numbers")
    return tuple(float(v) for v in array)


@register
@dataclass(frozen=True)
class MeasuredMTF(Stage):
    """A system MTF measured without a model: its across-track (x) and
    along-track (y) sections, tabulated, combined into the 2-D MTF as a
    product (``separable``: M(u, v) = Mx(u) My(v)) or as a square pixel
    times an elliptical remainder (``elliptical``: M = sinc(u) sinc(v)
    g(sqrt(u^2 + v^2 / a^2)), g = Mx / sinc), the two assumptions under
    which :func:`imgmtf.estimate.mtf2d.mtf2d_from_sections` inverts the
    sections along measured normals.  Linear between the samples; past
    the last, a Gaussian roll-off from the last value.  Real (no phase is
    measured): what a restoration designed from it undoes is the MTF.

    Parameters
    ----------
    frequencies_cy_px : sequence of float
        The sections' frequencies, cy/px, ascending from 0.
    across, along : sequence of float
        The MTF across and along track at those frequencies (1 at 0).
    combination : {"separable", "elliptical"}
        How the sections make the 2-D MTF (default separable).
    aspect : float
        The elliptical remainder's aspect a (> 0; default 1).

    Raises
    ------
    ParameterError
        Curves of other lengths, not starting at 0, or not finite; an
        unknown combination or a bad aspect.

    Examples
    --------
    >>> from imgmtf.sensor.stages import MeasuredMTF
    >>> stage = MeasuredMTF((0.0, 0.5, 1.0), (1.0, 0.4, 0.1), (1.0, 0.3, 0.05))
    >>> round(float(stage.transfer(0.5, 0.5, 1.0)), 4)                      # 0.4 x 0.3
    0.12
    """

    name: ClassVar[str] = "measured"
    title: ClassVar[str] = "measured MTF (no model)"
    frequencies_cy_px: tuple[float, ...] = field(default=(0.0, 1.0), metadata={"unit": "cy/px"})
    across: tuple[float, ...] = field(default=(1.0, 1.0), metadata={"unit": ""})
    along: tuple[float, ...] = field(default=(1.0, 1.0), metadata={"unit": ""})
    combination: str = field(default="separable", metadata={"unit": ""})
    aspect: float = field(default=1.0, metadata={"unit": ""})

    def __post_init__(self):
        f = _curve("frequencies_cy_px", self.frequencies_cy_px)
        across, along = _curve("across", self.across), _curve("along", self.along)
        if not (len(f) == len(across) == len(along)):
            raise ParameterError(f"measured frequencies, across and along must be as long: {len(f)}, "
                                 f"{len(across)}, {len(along)}")
        if f[0] != 0.0 or np.any(np.diff(f) <= 0):
            raise ParameterError("measured frequencies_cy_px must rise from 0")
        if self.combination not in COMBINATIONS:
            raise ParameterError(f"measured combination must be one of {', '.join(COMBINATIONS)}, "
                                 f"got {self.combination!r}")
        if not (isinstance(self.aspect, (int, float)) and math.isfinite(self.aspect) and self.aspect > 0):
            raise ParameterError(f"measured aspect must be > 0, got {self.aspect!r}")
        for name, value in (("frequencies_cy_px", f), ("across", across), ("along", along),
                            ("aspect", float(self.aspect))):
            object.__setattr__(self, name, value)

    def _section(self, values: tuple[float, ...], f: np.ndarray) -> np.ndarray:
        grid = np.asarray(self.frequencies_cy_px)
        inside = np.interp(f, grid, values)
        beyond = values[-1] * np.exp(-(((f - grid[-1]) / ROLL_OFF_CY_PX) ** 2))
        return np.where(f <= grid[-1], inside, beyond)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        u = np.abs(np.asarray(fx, float)) * gsd_m
        v = np.abs(np.asarray(fy, float)) * gsd_m
        if self.combination == "separable":
            return self._section(self.across, u) * self._section(self.along, v)
        pixel = np.sinc(u) * np.sinc(v)
        rho = np.hypot(u, v / self.aspect)
        sinc = np.sinc(rho)
        # g = Mx / sinc where the pixel passes signal; past its first zero the remainder alone
        remainder = np.where(np.abs(sinc) > 0.05, self._section(self.across, rho) / np.where(
            np.abs(sinc) > 0.05, sinc, 1.0), 0.0)
        return pixel * remainder

    def support_radius_m(self, gsd_m: float) -> float:
        return SUPPORT_PX * gsd_m

    def to_dict(self, include_name: bool = True) -> dict:
        values = {f.name: list(v) if isinstance((v := getattr(self, f.name)), tuple) else v for f in fields(self)}
        return {"stage": self.name, **values} if include_name else values

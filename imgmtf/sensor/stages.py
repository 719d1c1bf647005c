"""Stages of the imaging chain, each an object with its analytic transfer function.

A stage is a frozen dataclass whose fields are its physical parameters.
Every stage gives

* ``transfer(fx, fy, gsd_m)``: its real 2-D transfer function at spatial
  frequencies in cycles per metre on the ground (``fx`` across track, image
  columns; ``fy`` along track, image rows), 1 at zero frequency.  ``gsd_m``
  is the sensor's ground sample distance, which maps focal-plane lengths
  (the diffraction stage's pixel pitch) to the ground; stages given in ground
  metres ignore it.
* ``support_radius_m(gsd_m)``: a radius (m) outside which its PSF is
  negligible on a sampled 2-D grid (all but about 1e-9 of the energy; for
  diffraction, whose energy outside a radius falls only as 1/r, the core
  that holds 99 %: see :meth:`Diffraction.support_radius_m`).
* ``tail_length_m(gsd_m)``: the length ``b`` of the Cauchy tail of its LSF
  (transfer ~ 1 - 2 pi b |f| near zero), which the line responses of
  :mod:`.model` add in closed form so that long tails cost no grid; 0 for
  stages whose tails fall faster than any power.
* ``to_dict()`` / :func:`stage_from_dict`: the TOML form, ``{"stage": name,
  parameter: value, ...}``.

Every PSF here is non-negative and symmetric about both axes, so every
transfer function is real and even in ``fx`` and in ``fy``.  A new stage is
one class in this file with the :func:`register` decorator; the fit
(:mod:`imgmtf.estimate.fit`) reads what it needs to fit it from the fields'
``FitSpec`` metadata.

Examples
--------
>>> from imgmtf.sensor.stages import GaussianOptics, stage_from_dict
>>> optics = GaussianOptics(sigma_x_m=0.39, sigma_y_m=0.39)
>>> round(float(optics.transfer(0.5, 0.0, 1.0)), 4)
0.4721
>>> stage_from_dict(optics.to_dict()) == optics
True
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError
from ..inputs import check_number

#: largest finite stage parameter (m, cy/m, or an f-number): a light-year is 9.5e15 m, and beyond
#: 1e154 a parameter's square overflows in the transfer functions
MAX_PARAMETER = 1e15

#: name -> stage class, in the order the stages were registered
STAGES: dict[str, type[Stage]] = {}


def register(cls: type[Stage]) -> type[Stage]:
    """Class decorator: make a stage known by its ``name`` (TOML, CLI, fit)."""
    if cls.name in STAGES:
        raise ValueError(f"stage name {cls.name!r} registered twice")
    STAGES[cls.name] = cls
    return cls


@dataclass(frozen=True)
class FitSpec:
    """How the fit treats one parameter.

    The fit works in a coordinate ``u`` that is 0 when the stage has no
    effect and to which the low-frequency MTF responds about linearly: the
    blur length in pixels (a width, ``kind="length"``, or 1 / (cut-off x
    GSD), ``kind="frequency"``) raised to ``power`` (2 for the widths, whose
    effect grows as their square; 1 for diffraction, whose MTF falls
    linearly).  ``upper_px`` bounds the blur length; ``axis`` is the image axis it acts on ("x"
    across track, "y" along track, "xy" both); ``pair`` names the parameter
    of the other axis it is tied to when the edges see only one axis;
    ``rank`` orders what to hold when the data cannot constrain everything
    (higher: better known in advance, held first).
    """

    kind: str = "length"
    power: int = 2
    upper_px: float = 4.0
    axis: str = "xy"
    pair: str | None = None
    rank: int = 1


def _param(default: float, unit: str, fit: FitSpec | None = None, **flags) -> Any:
    return field(default=default, metadata={"unit": unit, "fit": fit, **flags})


@dataclass(frozen=True)
class Stage:
    """Base of all stages; see the module docstring."""

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    #: False when the PSF is a set of points, which has no FWHM
    has_width: ClassVar[bool] = True

    def __post_init__(self):
        for f in fields(self):
            value = check_number(f"{self.name} {f.name}", getattr(self, f.name),
                                 positive=f.metadata.get("positive", False),
                                 allow_inf=f.metadata.get("allow_inf", False))
            if math.isfinite(value) and value > MAX_PARAMETER:
                raise ParameterError(f"{self.name} {f.name} must be at most {MAX_PARAMETER:g} "
                                     f"{f.metadata['unit']}, got {value:g}".rstrip())
            object.__setattr__(self, f.name, value)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        """The stage's transfer function, real and 1 at zero frequency.

        Parameters
        ----------
        fx, fy : array_like
            Spatial frequencies across track (x, image columns) and along
            track (y, image rows), cy/m on the ground; broadcast together.
        gsd_m : float
            The sensor's ground sample distance, m (what maps focal-plane
            lengths to the ground; stages given in ground metres ignore it).

        Returns
        -------
        numpy.ndarray
            The transfer at each (``fx``, ``fy``), of their broadcast shape.

        Examples
        --------
        >>> from imgmtf.sensor.stages import Detector
        >>> Detector(1.0, 1.0).transfer([0.0, 1.0], 0.0, 1.0).round(6)     # zero at 1 / width
        array([1., 0.])
        """
        raise NotImplementedError

    def support_radius_m(self, gsd_m: float) -> float:
        """A radius (m) outside which the stage's PSF is negligible on a
        sampled grid at ``gsd_m`` (see the module docstring)."""
        raise NotImplementedError

    def tail_length_m(self, gsd_m: float) -> float:
        """The length b (m) of the Cauchy tail b / (pi x^2) of the stage's
        LSF at ``gsd_m``; 0 when its tails fall faster than any power."""
        return 0.0

    # -- parameters ---------------------------------------------------------
    @classmethod
    def units(cls) -> dict[str, str]:
        """Parameter name -> unit."""
        return {f.name: f.metadata["unit"] for f in fields(cls)}

    @classmethod
    def fit_specs(cls) -> dict[str, FitSpec]:
        """The parameters the fit can free, with how it treats them."""
        return {f.name: f.metadata["fit"] for f in fields(cls) if f.metadata.get("fit")}

    def fit_coordinates(self, gsd_m: float) -> dict[str, float]:
        """Each fittable parameter in the fit's coordinate (see :class:`FitSpec`)."""
        out = {}
        for name, spec in self.fit_specs().items():
            value = getattr(self, name)
            length = value / gsd_m if spec.kind == "length" else 1.0 / (value * gsd_m)
            out[name] = length**spec.power
        return out

    def with_fit_coordinates(self, coordinates: dict[str, float], gsd_m: float) -> Stage:
        """A copy with the given parameters set from fit coordinates."""
        values = {}
        for name, u in coordinates.items():
            spec = self.fit_specs()[name]
            length = max(u, 0.0) ** (1.0 / spec.power)
            values[name] = length * gsd_m if spec.kind == "length" else (
                1.0 / (length * gsd_m) if length > 0 else math.inf)
        return type(self)(**{**self.to_dict(include_name=False), **values})

    def to_dict(self, include_name: bool = True) -> dict:
        """``{"stage": name, parameter: value, ...}`` (JSON and TOML ready)."""
        values = {f.name: float(getattr(self, f.name)) for f in fields(self)}
        return {"stage": self.name, **values} if include_name else values

    @classmethod
    def from_dict(cls, values: dict) -> Stage:
        """The stage from its parameters (``stage`` key optional); unknown
        keys are a :class:`ParameterError`."""
        values = {k: v for k, v in values.items() if k != "stage"}
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise ParameterError(f"unknown {cls.name} parameter(s) {', '.join(unknown)}; "
                                 f"known: {', '.join(known)}")
        return cls(**values)


def stage_from_dict(values: dict) -> Stage:
    """The stage a table ``{"stage": name, parameter: value, ...}``
    describes (the TOML and JSON form, :meth:`Stage.to_dict`).

    Raises
    ------
    ParameterError
        Not a table, an unknown stage name, unknown parameters or bad
        values (each named).

    Examples
    --------
    >>> from imgmtf.sensor.stages import stage_from_dict
    >>> stage_from_dict({"stage": "detector", "width_x_m": 1.0, "width_y_m": 1.0})
    Detector(width_x_m=1.0, width_y_m=1.0)
    """
    if not isinstance(values, dict):
        raise ParameterError(f"a stage must be a table, got {values!r}")
    name = values.get("stage")
    if name not in STAGES:
        raise ParameterError(f"unknown stage {name!r}; known: {', '.join(STAGES)}")
    return STAGES[name].from_dict(values)


def _gaussian_radius(sigma: float) -> float:
    """Radius outside which a 2-D Gaussian of largest standard deviation
    ``sigma`` holds less than 1e-9 of its energy: exp(-r^2 / 2 sigma^2)."""
    return sigma * math.sqrt(2.0 * math.log(1e9))


@register
@dataclass(frozen=True)
class GaussianOptics(Stage):
    """Optics as a 2-D Gaussian PSF: T = exp(-2 pi^2 (sx^2 fx^2 + sy^2 fy^2)).

    Parameters
    ----------
    sigma_x_m, sigma_y_m : float
        Standard deviations of the PSF across track (x) and along track
        (y), metres on the ground, >= 0 (default 0.39, the paper's).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import GaussianOptics
    >>> round(float(GaussianOptics(0.39, 0.39).transfer(0.5, 0.0, 1.0)), 4)   # at 0.5 cy/m across
    0.4721
    """

    name: ClassVar[str] = "optics"
    title: ClassVar[str] = "Gaussian optics"
    sigma_x_m: float = _param(0.39, "m", FitSpec(axis="x", rank=1))
    sigma_y_m: float = _param(0.39, "m", FitSpec(axis="y", pair="sigma_x_m", rank=1))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fx, fy = np.asarray(fx, float), np.asarray(fy, float)
        return np.exp(-2.0 * np.pi**2 * (self.sigma_x_m**2 * fx**2 + self.sigma_y_m**2 * fy**2))

    def support_radius_m(self, gsd_m: float) -> float:
        return _gaussian_radius(max(self.sigma_x_m, self.sigma_y_m))


@register
@dataclass(frozen=True)
class Detector(Stage):
    """Detector aperture (the GIFOV) as a rect: T = sinc(fx wx) sinc(fy wy),
    sinc(t) = sin(pi t) / (pi t).

    Parameters
    ----------
    width_x_m, width_y_m : float
        Widths of the aperture across and along track, metres on the
        ground, >= 0 (default 1, the paper's GIFOV).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Detector
    >>> round(float(Detector(1.0, 1.0).transfer(0.5, 0.0, 1.0)), 4)         # 2 / pi at Nyquist
    0.6366
    """

    name: ClassVar[str] = "detector"
    title: ClassVar[str] = "detector aperture"
    width_x_m: float = _param(1.0, "m", FitSpec(axis="x", upper_px=3.0, rank=6))
    width_y_m: float = _param(1.0, "m", FitSpec(axis="y", upper_px=3.0, pair="width_x_m", rank=6))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        return np.sinc(np.asarray(fx, float) * self.width_x_m) * np.sinc(np.asarray(fy, float) * self.width_y_m)

    def support_radius_m(self, gsd_m: float) -> float:
        return math.hypot(self.width_x_m, self.width_y_m) / 2.0


@register
@dataclass(frozen=True)
class Motion(Stage):
    """Along-track smear during integration, a rect along y only:
    T = sinc(fy S).

    Parameters
    ----------
    length_m : float
        The smear S, metres on the ground, >= 0 (default 0.25, the
        paper's).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Motion
    >>> stage = Motion(0.25)
    >>> float(stage.transfer(0.5, 0.0, 1.0)), round(float(stage.transfer(0.0, 0.5, 1.0)), 4)
    (1.0, 0.9745)
    """

    name: ClassVar[str] = "motion"
    title: ClassVar[str] = "along-track motion"
    length_m: float = _param(0.25, "m", FitSpec(axis="y", upper_px=3.0, rank=2))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fy = np.asarray(fy, float)
        return np.broadcast_to(np.sinc(fy * self.length_m), np.broadcast(np.asarray(fx), fy).shape)

    def support_radius_m(self, gsd_m: float) -> float:
        return self.length_m / 2.0


@register
@dataclass(frozen=True)
class Electronics(Stage):
    """First-order 2-D Butterworth low-pass of the detector electronics:
    T = 1 / (1 + (D / D0)^2), D = sqrt(fx^2 + fy^2).

    Parameters
    ----------
    cutoff_cy_m : float
        The cut-off D0, cycles per metre on the ground, > 0; ``math.inf``
        for no filter (default 1.4, the paper's).

    Raises
    ------
    ParameterError
        A cut-off that is not > 0 or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Electronics
    >>> round(float(Electronics(1.4).transfer(0.5, 0.0, 1.0)), 4)
    0.8869
    """

    name: ClassVar[str] = "electronics"
    title: ClassVar[str] = "electronics (Butterworth)"
    cutoff_cy_m: float = _param(1.4, "cy/m", FitSpec(kind="frequency", upper_px=3.0, rank=4),
                                positive=True, allow_inf=True)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        fx, fy = np.asarray(fx, float), np.asarray(fy, float)
        return 1.0 / (1.0 + (fx**2 + fy**2) / self.cutoff_cy_m**2)

    def support_radius_m(self, gsd_m: float) -> float:
        # the PSF is 2 pi D0^2 K0(2 pi D0 r); the energy outside r is u K1(u),
        # u = 2 pi D0 r, below sqrt(pi u / 2) exp(-u) (1 + 3 / 8u): solve for 1e-9
        if math.isinf(self.cutoff_cy_m):
            return 0.0
        u = math.log(1e9)
        for _ in range(4):
            u = math.log(1e9 * math.sqrt(math.pi * u / 2.0) * (1.0 + 3.0 / (8.0 * u)))
        return u / (2.0 * math.pi * self.cutoff_cy_m)


@register
@dataclass(frozen=True)
class Diffraction(Stage):
    """Diffraction by an aberration-free circular aperture, incoherent light.

    The cut-off is 1 / (wavelength x f-number) cycles per metre in the
    focal plane, ``pixel_pitch_m`` / (wavelength x f-number) cycles per
    pixel, and so pitch / (wavelength x N x GSD) cycles per metre on the
    ground.  T = (2/pi) (acos v - v sqrt(1 - v^2)) for v = f / f_c <= 1, 0
    beyond; f is the radial frequency.

    Parameters
    ----------
    f_number : float
        The working f-number N, > 0 (default 8).
    wavelength_m : float
        The wavelength, metres, > 0 (default 550e-9).
    pixel_pitch_m : float
        The detector pitch in the focal plane, metres, > 0 (default 5e-6):
        it maps the focal plane onto the GSD.

    Raises
    ------
    ParameterError
        A parameter that is not > 0 or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Diffraction
    >>> stage = Diffraction(f_number=8.0, wavelength_m=550e-9, pixel_pitch_m=5e-6)
    >>> round(stage.cutoff_cy_m(gsd_m=1.0), 4)                   # cy/m on the ground at a 1 m GSD
    1.1364
    """

    name: ClassVar[str] = "diffraction"
    title: ClassVar[str] = "diffraction"
    f_number: float = _param(8.0, "", FitSpec(kind="f-number", power=1, upper_px=10.0, rank=2), positive=True)
    wavelength_m: float = _param(550e-9, "m", positive=True)
    pixel_pitch_m: float = _param(5e-6, "m", positive=True)

    def cutoff_cy_m(self, gsd_m: float) -> float:
        """Incoherent cut-off on the ground, cycles per metre."""
        return self.pixel_pitch_m / (self.wavelength_m * self.f_number * gsd_m)

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        v = np.minimum(np.hypot(np.asarray(fx, float), np.asarray(fy, float)) / self.cutoff_cy_m(gsd_m), 1.0)
        return (2.0 / np.pi) * (np.arccos(v) - v * np.sqrt(1.0 - v * v))

    def support_radius_m(self, gsd_m: float) -> float:
        # energy outside r: J0^2 + J1^2 of x = pi r f_c ~ 2 / (pi x) = 2 / (pi^2 r f_c);
        # the 1 % core, 20 lambda N; the line responses add the tails in closed form
        return 2.0 / (math.pi**2 * 0.01 * self.cutoff_cy_m(gsd_m))

    def tail_length_m(self, gsd_m: float) -> float:
        # T = 1 - (4 / pi) f / f_c + O(f^3) = 1 - 2 pi b |f|
        return 2.0 / (math.pi**2 * self.cutoff_cy_m(gsd_m))

    def fit_coordinates(self, gsd_m: float) -> dict[str, float]:
        # the blur length 1 / f_c in pixels: the MTF responds linearly to it (the cusp)
        return {"f_number": self.wavelength_m * self.f_number / self.pixel_pitch_m}

    def with_fit_coordinates(self, coordinates: dict[str, float], gsd_m: float) -> Stage:
        u = max(coordinates["f_number"], 1e-6)
        return type(self)(u * self.pixel_pitch_m / self.wavelength_m, self.wavelength_m, self.pixel_pitch_m)


@register
@dataclass(frozen=True)
class Defocus(Stage):
    """Defocus as a uniform disk PSF (geometric optics):
    T = 2 J1(2 pi r f) / (2 pi r f), f the radial frequency.

    Parameters
    ----------
    radius_m : float
        The disk's radius r, metres on the ground, >= 0 (default 0.5).

    Raises
    ------
    ParameterError
        A radius that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Defocus
    >>> round(float(Defocus(0.5).transfer(0.5, 0.0, 1.0)), 4)
    0.7217
    """

    name: ClassVar[str] = "defocus"
    title: ClassVar[str] = "defocus disk"
    radius_m: float = _param(0.5, "m", FitSpec(rank=2))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        from scipy.special import j1
        z = 2.0 * np.pi * self.radius_m * np.hypot(np.asarray(fx, float), np.asarray(fy, float))
        safe = np.where(z == 0, 1.0, z)
        return np.where(z == 0, 1.0, 2.0 * j1(safe) / safe)

    def support_radius_m(self, gsd_m: float) -> float:
        return self.radius_m


@register
@dataclass(frozen=True)
class OLPF(Stage):
    """Four-spot birefringent optical low-pass filter, four equal points at
    (+-d/2, +-d/2): T = cos(pi d fx) cos(pi d fy).

    Parameters
    ----------
    split_m : float
        The split d, metres on the ground, >= 0 (default 0.5).

    Raises
    ------
    ParameterError
        A split that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import OLPF
    >>> round(float(OLPF(1.0).transfer(0.5, 0.0, 1.0)), 12)      # a 1-px split nulls Nyquist
    0.0
    """

    name: ClassVar[str] = "olpf"
    title: ClassVar[str] = "4-spot OLPF"
    has_width: ClassVar[bool] = False
    split_m: float = _param(0.5, "m", FitSpec(upper_px=2.0, rank=5))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        d = self.split_m
        return np.cos(np.pi * d * np.asarray(fx, float)) * np.cos(np.pi * d * np.asarray(fy, float))

    def support_radius_m(self, gsd_m: float) -> float:
        return self.split_m / math.sqrt(2.0)


@register
@dataclass(frozen=True)
class Jitter(Stage):
    """Random line-of-sight jitter during integration, a Gaussian.  Its
    transfer has the form of the Gaussian optics', so a fit cannot tell
    the two apart: it holds one of them.

    Parameters
    ----------
    sigma_x_m, sigma_y_m : float
        Standard deviations across and along track, metres on the ground,
        >= 0 (default 0.1).

    Raises
    ------
    ParameterError
        A parameter that is negative, not finite or not a number.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Jitter
    >>> round(float(Jitter(0.0, 0.2).transfer(0.0, 0.5, 1.0)), 4)
    0.8209
    """

    name: ClassVar[str] = "jitter"
    title: ClassVar[str] = "jitter"
    sigma_x_m: float = _param(0.1, "m", FitSpec(axis="x", rank=3))
    sigma_y_m: float = _param(0.1, "m", FitSpec(axis="y", pair="sigma_x_m", rank=3))

    transfer = GaussianOptics.transfer
    support_radius_m = GaussianOptics.support_radius_m

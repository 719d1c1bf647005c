"""The base of every stage: :class:`Stage`, its parameters' :class:`FitSpec`, the
registry :data:`STAGES` and :func:`stage_from_dict` (see the package's docstring)."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ParameterError
from ...inputs import check_number

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
    linearly), or a share of the energy as it is (``kind="fraction"``,
    ``power`` 1).  ``upper_px`` bounds the blur length (a fraction's
    largest share); ``signed`` lets the coordinate take either sign, within
    +-``upper_px`` (a one-sided response pointing either way along its
    axis); ``axis`` is the image axis it acts on ("x"
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
    signed: bool = False

    @property
    def lower(self) -> float:
        """The coordinate's lower bound: -upper for a signed one, else 0."""
        return -(self.upper_px**self.power) if self.signed else 0.0


def param(default: float, unit: str, fit: FitSpec | None = None, **flags) -> Any:
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
            object.__setattr__(self, f.name, _checked(self, f, getattr(self, f.name)))

    def transfer(self, fx: ArrayLike, fy: ArrayLike, gsd_m: float) -> np.ndarray:
        """The stage's transfer function, 1 at zero frequency: real for a
        PSF symmetric about both axes, complex (Hermitian, T(-f) = conj T(f))
        for a one-sided one; its modulus is the MTF, its argument the PTF.

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
        return dict(_fit_specs(cls))

    def fit_coordinates(self, gsd_m: float) -> dict[str, float]:
        """Each fittable parameter in the fit's coordinate (see :class:`FitSpec`)."""
        out = {}
        for name, spec in self.fit_specs().items():
            value = getattr(self, name)
            if spec.kind == "fraction":
                out[name] = value
                continue
            length = value / gsd_m if spec.kind == "length" else 1.0 / (value * gsd_m)
            out[name] = math.copysign(abs(length) ** spec.power, length) if spec.signed else length**spec.power
        return out

    def with_fit_coordinates(self, coordinates: dict[str, float], gsd_m: float) -> Stage:
        """A copy with the given parameters set from fit coordinates."""
        specs = _fit_specs(type(self))
        values = {}
        for name, u in coordinates.items():
            spec = specs[name]
            if spec.kind == "fraction":
                values[name] = max(u, 0.0)
                continue
            if spec.signed:
                values[name] = math.copysign(abs(u) ** (1.0 / spec.power), u) * gsd_m
                continue
            length = max(u, 0.0) ** (1.0 / spec.power)
            values[name] = length * gsd_m if spec.kind == "length" else (
                1.0 / (length * gsd_m) if length > 0 else math.inf)
        return self._replaced(values)

    def _replaced(self, values: dict[str, float]) -> Stage:
        """A copy with ``values`` for some of its parameters, each checked as
        the constructor checks it (the same errors), the others taken as
        they are, already checked: what a fit's every evaluation makes,
        without the constructor's checks of every field.  A stage with its
        own ``__post_init__`` is made by its constructor."""
        cls = type(self)
        if cls.__post_init__ is not Stage.__post_init__:
            return cls(**{**self.to_dict(include_name=False), **values})
        other = object.__new__(cls)
        state = dict(self.__dict__)
        for name, value in values.items():
            state[name] = _checked(self, _fields_by_name(cls)[name], value)
        object.__setattr__(other, "__dict__", state)
        return other

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


def _checked(stage: Stage, f, value) -> float:
    """A parameter's ``value`` checked (a ParameterError naming it) and as a float."""
    # a fit's every evaluation: a float in (0, MAX_PARAMETER] and its field's bound, which every check passes as
    # it is (check_number's float() of a float is itself)
    if type(value) is float and 0.0 < value <= MAX_PARAMETER:
        high = f.metadata.get("high")
        if high is None or value <= high:
            return value
    number = check_number(f"{stage.name} {f.name}", value, positive=f.metadata.get("positive", False),
                          allow_inf=f.metadata.get("allow_inf", False), signed=f.metadata.get("signed", False),
                          high=f.metadata.get("high"))
    if math.isfinite(number) and number > MAX_PARAMETER:
        raise ParameterError(f"{stage.name} {f.name} must be at most {MAX_PARAMETER:g} "
                             f"{f.metadata['unit']}, got {number:g}".rstrip())
    return number


#: per stage class, its fit specs and its fields by name (:func:`_fit_specs`, :func:`_fields_by_name`)
_SPECS: dict[type, dict[str, FitSpec]] = {}
_FIELDS: dict[type, dict[str, Any]] = {}


def _fit_specs(cls: type[Stage]) -> dict[str, FitSpec]:
    """:meth:`Stage.fit_specs`, made once per class (a fit asks for it at every evaluation)."""
    specs = _SPECS.get(cls)
    if specs is None:
        specs = _SPECS[cls] = {f.name: f.metadata["fit"] for f in fields(cls) if f.metadata.get("fit")}
    return specs


def _fields_by_name(cls: type[Stage]) -> dict[str, Any]:
    """The dataclass fields of ``cls`` by name, made once per class."""
    by_name = _FIELDS.get(cls)
    if by_name is None:
        by_name = _FIELDS[cls] = {f.name: f for f in fields(cls)}
    return by_name


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


def nonzero_transfer(stages: Sequence[Stage], fx: np.ndarray, fy: np.ndarray, gsd_m: float) -> np.ndarray:
    """The product of ``stages``' transfers (in their order, as
    :meth:`imgmtf.Sensor.transfer` forms it) at 1-D frequencies ``fx``,
    ``fy`` (cy/m), each stage's computed only where those before it leave
    the product non-zero, 0 elsewhere: the same numbers but for the sign
    of a zero (0 x T of a finite T), which an inverse FFT's sums and a
    modulus do not see.  A FWHM's fine grid (16385 frequencies to
    200 cy/px) lies beyond a Gaussian optics' underflow at over nine
    tenths of them, where the detector's sines were half its transfer's time.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> f = np.linspace(0.0, 200.0, 16385)
    >>> bool(np.array_equal(nonzero_transfer(Sensor().stages, f, f / 3, 1.0), Sensor().transfer(f, f / 3)))
    True
    """
    out = np.ones(fx.shape)
    kept: np.ndarray | None = None            # where the product so far is not zero; None: everywhere
    for stage in stages:
        if kept is None:
            out = out * stage.transfer(fx, fy, gsd_m)
        else:
            part = out[kept] * stage.transfer(fx[kept], fy[kept], gsd_m)
            out = np.zeros(fx.shape, part.dtype)
            out[kept] = part
        nonzero = out != 0                    # (NaN kept: it stays NaN, as it would)
        kept = None if nonzero.all() else np.flatnonzero(nonzero)
    return out


def exponential_radius(length_x: float, length_y: float) -> float:
    """Radius outside which an exponential tail per axis, exp(-|x| / L)
    (two-sided or one-sided), leaves less than 1e-9 of its energy:
    ln(1e9) lengths, the two axes' together."""
    return math.log(1e9) * math.hypot(length_x, length_y)


def gaussian_radius(sigma: float) -> float:
    """Radius outside which a 2-D Gaussian of largest standard deviation
    ``sigma`` holds less than 1e-9 of its energy: exp(-r^2 / 2 sigma^2)."""
    return sigma * math.sqrt(2.0 * math.log(1e9))

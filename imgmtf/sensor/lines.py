"""A line response: the edge and line spread functions along one normal,
a closed-form reference plus a remainder sampled on a fine grid (what
:meth:`imgmtf.sensor.model.Sensor.line_response` returns), and that grid
(:class:`LineGrid`), on which the remainders of many transfers are made
in one inverse FFT."""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Literal, Protocol, overload

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError

#: largest 1-D line (samples) a sensor may ask for
MAX_LINE_SAMPLES = 1 << 23
#: the longest grid (samples) whose inverse-FFT factors are kept (16 grids
#: at most, about 1 MB each at this size): a fit's grids, up to 2^15 for
#: 300-row edges of f/5.6-8 diffraction; a render's longer ones, made once,
#: are not
CACHED_LINE_SAMPLES = 1 << 16
#: the frequency along the normal (cy/px) at which a sensor's transfer
#: gives its LSF's variance, 1 - T = 2 pi^2 variance f^2 (the Gaussian
#: reference's width)
PROBE_CY_PX = 1e-3


@dataclass(frozen=True, eq=False)
class LineResponse:
    """Edge (ESF) and line (LSF) spread functions along one normal, in
    pixels: a closed-form reference (a Cauchy LSF b / pi (b^2 + x^2) for a
    sensor with diffraction, else a Gaussian of about the LSF's width) plus
    a remainder sampled every ``step_px`` from ``start_px``, zero beyond its
    grid.  The ESF rises from 0 to 1; both are exact to about 1e-7."""

    start_px: float
    step_px: float
    esf_remainder: np.ndarray
    lsf_remainder: np.ndarray
    reference: tuple[str, float]

    def esf(self, d_px: ArrayLike) -> np.ndarray:
        """Edge response at signed distances ``d_px`` (cubic Hermite between
        grid samples, whose slopes are the LSF)."""
        d = np.asarray(d_px, float)
        return self._plus_reference_esf(hermite(self.start_px, self.step_px, self.esf_remainder,
                                                self.lsf_remainder, d), d)

    def lsf(self, d_px: ArrayLike) -> np.ndarray:
        """Line spread function (1/px) at signed distances ``d_px``."""
        return line_spread(self.start_px, self.step_px, self.lsf_remainder, self.reference, d_px)

    def esf_with_curvature(self, d_px: ArrayLike,
                           placement: HermitePlacement | None = None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`esf` (the same values) and its second derivative, the
        LSF's slope, at signed distances ``d_px``, the distances placed on
        the grid once.  The curvature is exactly that of the cubic Hermite
        interpolant :meth:`esf` evaluates (linear between grid samples),
        plus the reference's closed form: what a mean of the ESF over
        nearby distances needs beyond its value at their mean
        (:mod:`imgmtf.estimate.fit`'s bins).

        Parameters
        ----------
        d_px : array_like
            Signed distances from the edge, px.
        placement : HermitePlacement, optional
            ``d_px`` placed on this response's grid with the curvature's
            weights (:meth:`placement`), when the caller keeps it for other
            functions on the grid (default: placed here).

        Returns
        -------
        esf, curvature : numpy.ndarray
            The edge response and its second derivative (1/px^2) there.

        Examples
        --------
        >>> from imgmtf import Sensor
        >>> esf, curvature = Sensor().line_response(0.0).esf_with_curvature([0.0, 1.0])
        >>> esf.round(4).tolist(), bool(curvature[1] < 0)
        ([0.5, 0.9756], True)
        """
        d = np.asarray(d_px, float)
        if placement is None:
            placement = self.placement(d, curvature=True)
        value, curvature = placement.interpolate(self.esf_remainder, self.lsf_remainder, curvature=True)
        return self._plus_reference_esf(value, d), self._plus_reference_curvature(curvature, d)

    def placement(self, d_px: ArrayLike, curvature: bool = False) -> HermitePlacement:
        """Signed distances ``d_px`` placed on this response's grid
        (:func:`hermite_placement`), for :meth:`esf_with_curvature` and for
        other functions on the grid (the changes of a fit's Jacobian)."""
        return hermite_placement(self.start_px, self.step_px, self.esf_remainder.size, d_px, curvature)

    def _plus_reference_esf(self, value: np.ndarray, d: np.ndarray) -> np.ndarray:
        """``value``, the remainder's ESF at ``d``, plus the reference's."""
        return plus_reference_esf(value, self.reference[0], self.reference[1], d)

    def _plus_reference_curvature(self, value: np.ndarray, d: np.ndarray) -> np.ndarray:
        """``value``, the remainder's ESF curvature at ``d``, plus the reference's."""
        kind, width = self.reference
        return plus_reference_curvature(value, kind, width, reference_scale(self.reference), d)


def line_spread(start_px: float, step_px: float, lsf_remainder: np.ndarray, reference: tuple[str, float],
                d_px: ArrayLike) -> np.ndarray:
    """The LSF (1/px) at signed distances ``d_px`` of a remainder sampled
    every ``step_px`` from ``start_px`` (linear between samples, zero
    beyond them) plus its closed-form ``reference``: :meth:`LineResponse.lsf`,
    for a caller with the remainder alone (:meth:`LineGrid.lsf_remainder`)."""
    d = np.asarray(d_px, float)
    grid = start_px + step_px * np.arange(lsf_remainder.size)
    value = np.interp(d, grid, lsf_remainder, left=0.0, right=0.0)
    kind, width = reference
    if kind == "cauchy":
        return value + width / (np.pi * (width**2 + d**2))
    return value + np.exp(-0.5 * (d / width) ** 2) / (width * math.sqrt(2 * math.pi))


def plus_reference_esf(value: np.ndarray, kind: str, width: float | np.ndarray, d: np.ndarray) -> np.ndarray:
    """``value`` (a remainder's ESF at ``d`` px) plus the ESF of a
    reference of kind ``kind`` ("cauchy" or "gaussian") and ``width`` px,
    one for all distances or one per distance (each as its own line
    response gives it, bit for bit)."""
    if kind == "cauchy":
        return value + 0.5 + np.arctan(d / width) / np.pi
    from scipy.special import ndtr
    return value + ndtr(d / width)


def reference_scale(reference: tuple[str, float]) -> float:
    """The constant of a reference's ESF curvature
    (:func:`plus_reference_curvature`): a Gaussian's s^3 sqrt(2 pi), a
    Cauchy LSF's b^2."""
    kind, width = reference
    return width**2 if kind == "cauchy" else width**3 * math.sqrt(2 * math.pi)


def plus_reference_curvature(value: np.ndarray, kind: str, width: float | np.ndarray, scale: float | np.ndarray,
                             d: np.ndarray) -> np.ndarray:
    """``value`` (a remainder's ESF curvature at ``d`` px, 1/px^2) plus
    that of a reference of kind ``kind``, ``width`` px and
    :func:`reference_scale` ``scale``, one for all distances or one per
    distance."""
    if kind == "cauchy":
        return value - 2 * width * d / (np.pi * (scale + d**2) ** 2)
    return value - d * np.exp(-0.5 * (d / width) ** 2) / scale


def reference_transfer(reference: tuple[str, float], f: np.ndarray) -> np.ndarray:
    """Transfer (1 at zero) of a line response's closed-form reference at
    ``f`` cy/px: a Cauchy LSF's exp(-2 pi b f), a Gaussian's
    exp(-2 pi^2 s^2 f^2)."""
    kind, width = reference
    exponent = -2 * np.pi * width * f if kind == "cauchy" else -2 * np.pi**2 * width**2 * f**2
    return underflowing_exp(exponent)


#: below this exponent exp is 0 exactly (it is under half the smallest subnormal from -745.14)
EXP_ZERO_BELOW = -746.0


def underflowing_exp(exponent: np.ndarray) -> np.ndarray:
    """``np.exp(exponent)``, bit for bit, without calling it where the
    result is 0: there the C library takes its slow underflow path (a
    Gaussian transfer on a fine grid's frequencies, zero over half of
    them, spent two thirds of its time there).

    Examples
    --------
    >>> x = np.array([0.0, -1.0, -745.0, -746.0, -1e5, np.nan])
    >>> bool(np.array_equal(underflowing_exp(x), np.exp(x), equal_nan=True))
    True
    """
    exponent = np.asarray(exponent, float)
    out = np.zeros(exponent.shape)
    np.exp(exponent, out=out, where=~(exponent < EXP_ZERO_BELOW))         # NaN stays NaN
    return out[()] if out.ndim == 0 else out


@dataclass(frozen=True, eq=False)
class LineGrid:
    """The fine grid of a line response (what
    :meth:`imgmtf.sensor.model.Sensor.line_grid` sizes): ``size`` samples
    every ``step_px`` px, centred on the edge, and the closed-form
    ``reference`` whose transfer is taken out of the sensor's before the
    inverse FFT.

    Examples
    --------
    >>> grid = LineGrid(0.25, 8, ("gaussian", 1.0))
    >>> grid.start_px, grid.frequencies_cy_px.tolist()
    (-1.0, [0.0, 0.5, 1.0, 1.5, 2.0])
    """

    step_px: float
    size: int
    reference: tuple[str, float]

    @property
    def start_px(self) -> float:
        """The first sample's signed distance from the edge, px."""
        return -(self.size // 2) * self.step_px

    @cached_property
    def frequencies_cy_px(self) -> np.ndarray:
        """The grid's non-negative DFT frequencies, cy/px (``size // 2 + 1``;
        read-only, shared by every grid of this step and size)."""
        return _inverse_factors(self.step_px, self.size)[0]

    def response(self, transfer: np.ndarray) -> LineResponse:
        """The line response of a sensor whose transfer along the normal at
        :attr:`frequencies_cy_px` is ``transfer``.

        Parameters
        ----------
        transfer : numpy.ndarray
            The transfer (1 at zero), one value per frequency.

        Returns
        -------
        LineResponse
            Its edge and line spread functions.
        """
        esf, lsf = self.remainders(transfer - reference_transfer(self.reference, self.frequencies_cy_px))
        return LineResponse(self.start_px, self.step_px, esf, lsf, self.reference)

    def lsf_remainder(self, transfer: np.ndarray) -> np.ndarray:
        """The LSF remainder (1/px) alone of a sensor whose transfer at
        :attr:`frequencies_cy_px` is ``transfer``: :meth:`response`'s
        ``lsf_remainder``, bit for bit, in half its inverse FFTs (a FWHM
        reads the LSF only, on a grid of tens of thousands of samples).

        Examples
        --------
        >>> grid = LineGrid(0.25, 8, ("gaussian", 1.0))
        >>> transfer = np.exp(-grid.frequencies_cy_px)
        >>> bool(np.array_equal(grid.lsf_remainder(transfer), grid.response(transfer).lsf_remainder))
        True
        """
        _, to_lsf, _ = _inverse_factors(self.step_px, self.size)
        spectra = np.asarray(transfer - reference_transfer(self.reference, self.frequencies_cy_px))
        if not np.iscomplexobj(spectra):
            spectra = spectra.astype(float, copy=False)
        lsf = np.empty(spectra.shape, complex)            # as :meth:`remainders` forms it
        np.multiply(spectra, to_lsf, out=lsf)
        return np.fft.irfft(lsf, self.size)

    def remainders(self, spectra: np.ndarray, out: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The ESF and LSF (1/px) on the grid of the spectra ``spectra``
        (each row's zero-frequency value 0), all in one inverse FFT; each
        ESF starts from 0 at the grid's first sample.

        Parameters
        ----------
        spectra : numpy.ndarray, shape (..., size // 2 + 1)
            Transfers (or their differences) at :attr:`frequencies_cy_px`.
        out : numpy.ndarray, shape (2, ..., size), optional
            Where to write the LSF (``out[0]``) and ESF (``out[1]``), a view
            into a larger array included (the same numbers; default new).

        Returns
        -------
        esf, lsf : numpy.ndarray, shape (..., size)
            Their edge and line spread functions on the grid (views of
            ``out`` when given).

        Examples
        --------
        >>> grid = LineGrid(0.25, 8, ("gaussian", 1.0))
        >>> spectra = np.exp(-grid.frequencies_cy_px) - 1.0
        >>> side_by_side = np.zeros((2, 20))
        >>> esf, lsf = grid.remainders(spectra, out=side_by_side[:, 4:12])
        >>> bool(np.array_equal(esf, grid.remainders(spectra)[0])), bool(side_by_side[1, 4:12].any())
        (True, True)
        """
        _, to_lsf, to_esf = _inverse_factors(self.step_px, self.size)
        spectra = np.asarray(spectra)
        if not np.iscomplexobj(spectra):
            spectra = spectra.astype(float, copy=False)
        both = np.empty((2, *spectra.shape), complex)
        np.multiply(spectra, to_lsf, out=both[0])
        np.multiply(spectra, to_esf, out=both[1])
        lsf, esf = np.fft.irfft(both, self.size, out=out)
        esf -= esf[..., :1]             # in place: the transform's own array, no copy
        return esf, lsf


def _inverse_factors(step_px: float, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_make_inverse_factors`, kept for grids of up to
    :data:`CACHED_LINE_SAMPLES` samples (a fit's, evaluated again and
    again) and made afresh for longer ones (a render's, once: kept, one
    2^20-sample grid would hold 16.8 MB for the process)."""
    if size <= CACHED_LINE_SAMPLES:
        return _cached_inverse_factors(step_px, size)
    return _make_inverse_factors(step_px, size)


def _make_inverse_factors(step_px: float, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A grid's frequencies (cy/px) and what its spectra are multiplied by
    before the inverse real FFT to give the LSF (1/px) and the ESF
    centred on the grid: the phase of a shift by ``size // 2`` samples,
    which moves the origin from the first sample to the middle one (the
    ``fftshift`` of the output without its copy; (-1)^k, exactly, for an
    even size), over the step; for the ESF, the LSF's integral, over
    2 pi i f too (0 at f = 0).  Read-only: every grid of this step and
    size shares them."""
    f = np.fft.rfftfreq(size, d=step_px)
    k = np.arange(f.size)
    shift = np.where(k % 2 == 0, 1.0, -1.0) if size % 2 == 0 else np.exp(-2j * np.pi * k * (size // 2) / size)
    to_lsf = shift / step_px
    to_esf = np.zeros(f.size, complex)
    to_esf[1:] = to_lsf[1:] / (2j * np.pi * f[1:])
    for array in (f, to_lsf, to_esf):
        array.flags.writeable = False
    return f, to_lsf, to_esf


_cached_inverse_factors = lru_cache(maxsize=16)(_make_inverse_factors)


@dataclass(frozen=True, eq=False)
class HermitePlacement:
    """Distances placed on a grid (:func:`hermite_placement`): each one's
    interval and the cubic Hermite weights of its ends' values and slopes,
    what every function interpolated on that grid at those distances
    shares (a fit's residuals and its Jacobian's columns, at one point).

    Attributes
    ----------
    shape : tuple of int
        The distances' shape.
    inside : numpy.ndarray or None
        The flat indices of the distances on their grid; None when all are.
    index : numpy.ndarray
        The left sample of each one's interval (with its grid's offset).
    weights : tuple
        The weights of the interval's left value and slope, right value and
        slope: for the values, and when placed with ``curvature`` for their
        second derivatives (per px^2) too.
    """

    shape: tuple[int, ...]
    inside: np.ndarray | None
    index: np.ndarray
    weights: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], ...]

    @overload
    def interpolate(self, values: np.ndarray, slopes: np.ndarray,
                    curvature: Literal[False] = False) -> np.ndarray: ...

    @overload
    def interpolate(self, values: np.ndarray, slopes: np.ndarray,
                    curvature: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...

    @overload
    def interpolate(self, values: np.ndarray, slopes: np.ndarray,
                    curvature: bool) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...

    def interpolate(self, values: np.ndarray, slopes: np.ndarray,
                    curvature: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """:func:`hermite` of ``values`` and ``slopes`` (shape (..., size),
        or the grids' concatenated) at the placed distances: the values, and
        with ``curvature`` (when placed with it) their second derivatives
        too."""
        if curvature and len(self.weights) < 2:
            raise ValueError("these distances were placed without the curvature's weights")
        k = self.index
        right = k + 1
        # np.take gathers along the last axis faster than fancy indexing; the sum is accumulated in
        # place, in the same order (((w0 v0 + w1 s0) + w2 v1) + w3 s1): the same numbers, fewer temporaries
        near = (values.take(k, axis=-1), slopes.take(k, axis=-1),
                values.take(right, axis=-1), slopes.take(right, axis=-1))
        outputs = []
        term: np.ndarray | None = None
        for weights in self.weights[: 2 if curvature else 1]:
            value = np.multiply(weights[0], near[0])
            for w, n in zip(weights[1:], near[1:]):
                term = np.multiply(w, n, out=term if term is not None and term.dtype == value.dtype else None)
                value += term
            if self.inside is not None:
                placed = np.zeros((*values.shape[:-1], math.prod(self.shape)), value.dtype)
                placed[..., self.inside] = value
                value = placed
            outputs.append(value.reshape(values.shape[:-1] + self.shape))
        return (outputs[0], outputs[1]) if curvature else outputs[0]


def hermite_placement(start_px: float | np.ndarray, step_px: float | np.ndarray, size: int | np.ndarray,
                      d_px: ArrayLike, curvature: bool = False, offset: int | np.ndarray = 0) -> HermitePlacement:
    """Distances ``d_px`` placed on a grid of ``size`` samples from
    ``start_px`` every ``step_px`` px, with the weights of cubic Hermite
    interpolation there (and with ``curvature`` those of its second
    derivative): for :meth:`HermitePlacement.interpolate`, once for every
    function on that grid.  Several grids side by side (their samples
    concatenated) take per-distance ``start_px``, ``step_px``, ``size`` and
    ``offset`` (where its grid begins among the concatenated samples),
    each distance then placed as on its grid alone, bit for bit.

    Parameters
    ----------
    start_px, step_px : float or numpy.ndarray
        The grid's first sample and step, px; or each distance's grid's
        (shaped like ``d_px``).
    size : int or numpy.ndarray
        The grid's samples (at least 2); or each distance's grid's.
    d_px : array_like
        Where to interpolate, px.
    curvature : bool, optional
        Also the weights of the interpolant's second derivative (default
        False).
    offset : int or numpy.ndarray, optional
        Where the (each distance's) grid's first sample is among the
        values interpolated (default 0).

    Returns
    -------
    HermitePlacement
        The placement.

    Examples
    --------
    >>> grid = np.arange(5.0)
    >>> placement = hermite_placement(0.0, 1.0, 5, [1.5, 9.0])
    >>> placement.interpolate(grid**2, 2 * grid).tolist(), placement.interpolate(grid**3, 3 * grid**2).tolist()
    ([2.25, 0.0], [3.375, 0.0])
    >>> both = np.concatenate([grid**2, grid**3]), np.concatenate([2 * grid, 3 * grid**2])
    >>> hermite_placement(0.0, 1.0, 5, [1.5, 1.5], offset=np.array([0, 5])).interpolate(*both).tolist()
    [2.25, 3.375]
    """
    d = np.asarray(d_px, float)
    t = ((d - start_px) / step_px).ravel()
    inside = (t >= 0) & (t <= size - 1)
    placed = None
    if not bool(inside.all()):        # beyond the grid: zero, nothing to compute
        placed = np.flatnonzero(inside)
        t = t[placed]
        if np.ndim(step_px):
            step_px = np.ravel(step_px)[placed]
        if np.ndim(size):
            size = np.ravel(size)[placed]
        if np.ndim(offset):
            offset = np.ravel(offset)[placed]
    k = np.minimum(t.astype(np.intp), size - 2)
    u = t - k
    h = step_px
    falling, squared = (1 - u) ** 2, u * u
    weights = [((1 + 2 * u) * falling, u * falling * h, squared * (3 - 2 * u), squared * (u - 1) * h)]
    if curvature:             # the basis's second derivatives, by d_px
        twelve, six = 12 * u, 6 * u
        weights.append(((twelve - 6) / h**2, (six - 4) / h, (6 - twelve) / h**2, (six - 2) / h))
    index = k + offset if np.ndim(offset) or offset else k
    return HermitePlacement(d.shape, placed, index, tuple(weights))


@overload
def hermite(start_px: float, step_px: float, values: np.ndarray, slopes: np.ndarray,
            d_px: np.ndarray, curvature: Literal[False] = False) -> np.ndarray: ...


@overload
def hermite(start_px: float, step_px: float, values: np.ndarray, slopes: np.ndarray,
            d_px: np.ndarray, curvature: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...


def hermite(start_px: float, step_px: float, values: np.ndarray, slopes: np.ndarray,
            d_px: np.ndarray, curvature: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Cubic Hermite interpolation of gridded ``values`` with their
    ``slopes`` (per px) at ``d_px``, and with ``curvature`` the
    interpolant's second derivative (per px^2) too; zero beyond the grid.

    Parameters
    ----------
    start_px, step_px : float
        The grid's first sample and step, px.
    values, slopes : numpy.ndarray, shape (..., n)
        Samples on the grid, and their derivatives, one row per function.
    d_px : numpy.ndarray
        Where to interpolate, px.
    curvature : bool, optional
        Also the interpolant's second derivative (linear between grid
        samples, the cubic's), the distances placed on the grid once
        (default False).

    Returns
    -------
    numpy.ndarray, shape (..., len(d_px)), or a tuple of two
        Each row's values at ``d_px`` (the shared weights computed once:
        :func:`hermite_placement`); with ``curvature``, ``(values, second
        derivatives)``.

    Examples
    --------
    >>> grid = np.arange(5.0)
    >>> hermite(0.0, 1.0, grid**2, 2 * grid, np.array([1.5, 9.0])).tolist()   # exact for a cubic
    [2.25, 0.0]
    >>> [a.tolist() for a in hermite(0.0, 1.0, grid**3, 3 * grid**2, np.array([1.5, 2.25]), curvature=True)]
    [[3.375, 11.390625], [9.0, 13.5]]
    """
    placement = hermite_placement(start_px, step_px, values.shape[-1], d_px, curvature)
    return placement.interpolate(values, slopes, curvature)


class _Blur(Protocol):
    """What :func:`line_grid` reads of a sensor."""

    def tail_length_m(self) -> float: ...

    def support_radius_m(self) -> float: ...

    def normal_transfer(self, f_cy_px: ArrayLike, angle_deg: float, gsd_m: float | None = None) -> np.ndarray: ...


def line_grid(sensor: _Blur, angle_deg: float, gsd: float, *, reach_px: float = 0.0,
              step_px: float = 1.0 / 64.0, transfer_at_probe: float | None = None) -> LineGrid:
    """The grid a sensor's line response along the normal of an edge tilted
    ``angle_deg`` is sampled on: its step, its size (the PSF's support plus
    ``reach_px`` on each side, rounded up to a power of two, at least 256)
    and the closed-form reference that takes the LSF's tails.

    Parameters
    ----------
    sensor : Sensor
        The sensor (:class:`imgmtf.Sensor`).
    angle_deg : float
        The edge's tilt from the column axis, deg.
    gsd : float
        The pixel, m.
    reach_px : float, optional
        Distance from the edge, px, the grid must cover beyond the PSF's
        support (default 0).
    step_px : float, optional
        The grid's step, px (default 1/64; finer where a Cauchy tail
        needs it).
    transfer_at_probe : float, optional
        The sensor's transfer along the normal at :data:`PROBE_CY_PX`,
        when the caller has it (default: computed here); read only
        without a Cauchy tail.

    Returns
    -------
    LineGrid
        The grid.

    Raises
    ------
    ParameterError
        When the grid would exceed ``MAX_LINE_SAMPLES``.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> grid = line_grid(Sensor(), 0.0, 1.0)
    >>> grid.step_px, grid.size, grid.reference[0]
    (0.015625, 2048, 'gaussian')
    """
    tail_px = sensor.tail_length_m() / gsd
    if tail_px > 0:
        # the Cauchy reference must have decayed (to 1e-9) at the grid's Nyquist
        step_px = min(step_px, math.pi * tail_px / math.log(1e9))
        reference = ("cauchy", tail_px)
    else:
        # any smooth reference of about the LSF's width keeps the remainder small
        if transfer_at_probe is None:
            transfer_at_probe = float(np.real(sensor.normal_transfer(PROBE_CY_PX, angle_deg, gsd)))
        variance = (1.0 - transfer_at_probe) / (2 * math.pi**2 * PROBE_CY_PX**2)
        reference = ("gaussian", min(max(math.sqrt(max(variance, 0.0)), 0.1), 10.0))
    half = reach_px + sensor.support_radius_m() / gsd + 8 * reference[1] + 4.0
    n = 1 << max(int(math.ceil(math.log2(2 * half / step_px))), 8)
    if n > MAX_LINE_SAMPLES:
        raise ParameterError(
            f"the sensor's blur spans {half:.3g} px of {gsd:g} m: its line response would need "
            f"{n:.3g} samples (over {MAX_LINE_SAMPLES}); check the stage parameters against the GSD")
    return LineGrid(step_px, n, reference)

"""From a uniformly resampled profile to the MTF and its figures.

Conventions: distances in pixels along the target normal, frequencies in
cycles per pixel along the normal, MTF normalised to 1 at zero frequency.

Corrections applied (each divides the measured modulus):

* central difference, LSF_i = (E_(i+1) - E_(i-1)) / (2 D):
  transfer sin(2 pi f D) / (2 pi f D) = sinc(2 f D);
* the resampling method's own blur, its transfer H_method(f)
  (:mod:`imgmtf.estimate.resampling`): sinc(f B) for bins of B px, the equivalent
  kernel of a local polynomial, 1 / (1 + (f / f_c)^4) for the spline;
* the LSF window is flat (1) over the LSF's core and only tapers beyond
  it, so it needs no correction; it removes the noise of the flat tails.

Beyond the core the window does not throw the LSF's tails away: there
the estimators (:mod:`.pipeline`) replace the noisy data by a smooth
model fitted to it, so the tails are kept out to the end of the data
without their noise.

A correction factor is never allowed to exceed 1 / ``MIN_TRANSFER``:
frequencies where a divisor is smaller are reported as NaN.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from ..metrics import first_crossing

MIN_TRANSFER = 0.1
NYQUIST = 0.5
MAX_MTF_FREQUENCY = 4.0       # cy/px: an MTF is reported and searched no further


def central_difference(grid: np.ndarray, esf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """LSF by central difference of a uniformly sampled ESF: ``(x, lsf)``
    on the interior grid points (1/px for an ESF normalised to a unit step).
    ``esf`` may stack profiles on its leading axes."""
    step = grid[1] - grid[0]
    return grid[1:-1], (esf[..., 2:] - esf[..., :-2]) / (2 * step)


def flat_top_window(x: np.ndarray, center: float, half_width: float, taper: float) -> np.ndarray:
    """1 within ``half_width`` of ``center``, a raised-cosine fall to 0 over
    the next ``taper`` px, 0 beyond."""
    r = np.abs(x - center)
    w = np.zeros_like(x, dtype=float)
    w[r <= half_width] = 1.0
    t = (r > half_width) & (r < half_width + taper)
    w[t] = 0.5 * (1 + np.cos(np.pi * (r[t] - half_width) / taper))
    return w


def spectrum(lsf: np.ndarray, step: float, resolution: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """|Fourier transform| of a sampled LSF on a frequency grid of about
    ``resolution`` cy/px (zero-padded FFT): ``(f, modulus)``.  With the
    default 0.05 px step every multiple of 0.001 cy/px, Nyquist included,
    is an exact bin."""
    n = _transform_length(lsf.size, step, resolution)
    return np.fft.rfftfreq(n, d=step), np.abs(np.fft.rfft(lsf, n=n)) * step


def _transform_length(size: int, step: float, resolution: float = 1e-3) -> int:
    """The zero-padded transform's length for bins ``resolution`` cy/px apart."""
    return max(int(round(1.0 / (step * resolution))), size)


def with_transfer(own: Callable[[np.ndarray], np.ndarray],
                  transfer: Callable | None) -> Callable[[np.ndarray], np.ndarray]:
    """The transfer ``own(f)`` times ``transfer(f)`` (the resampling
    method's, when given), for f in cy/px."""
    def divisor(f):
        f = np.atleast_1d(np.asarray(f, float))
        value = own(f)
        return value * transfer(f) if transfer is not None else value
    return divisor


def edge_divisor(step: float, transfer: Callable | None) -> Callable[[np.ndarray], np.ndarray]:
    """Transfer of an edge estimator's own steps: the central difference
    with ``step`` (sinc(2 f step)) times the resampling ``transfer``.

    Edges of one scan share their step and their resampling's transfer
    (one per window width), and read the divisor on the same frequencies
    (the transform's bins, the gate's grids): one divisor serves them all
    and keeps its last values (:func:`remembered`)."""
    return _edge_divisor(step, transfer)


@functools.lru_cache(maxsize=64)
def _edge_divisor(step: float, transfer: Callable | None) -> Callable[[np.ndarray], np.ndarray]:
    return remembered(with_transfer(lambda f: np.sinc(2 * f * step), transfer))


REMEMBERED = 8          # a divisor's frequency grids whose values it keeps


def remembered(function: Callable[[np.ndarray], np.ndarray], size: int = REMEMBERED
               ) -> Callable[[np.ndarray], np.ndarray]:
    """``function`` of an array of frequencies (cy/px), elementwise, with
    its values on the last ``size`` grids it was asked for kept: asked
    again for the same frequencies it returns a copy of the same values.

    Examples
    --------
    >>> calls = []
    >>> square = remembered(lambda f: calls.append(1) or f * f)
    >>> [float(v) for v in square(np.array([1.0, 2.0]))], [float(v) for v in square(np.array([1.0, 2.0]))]
    ([1.0, 4.0], [1.0, 4.0])
    >>> len(calls)
    1
    """
    kept: dict[tuple, np.ndarray] = {}

    def values(f):
        f = np.atleast_1d(np.asarray(f, float))
        key = (f.shape, f.tobytes())
        found = kept.get(key)
        if found is None:
            found = kept[key] = function(f)
            while len(kept) > size:
                kept.pop(next(iter(kept)), None)
        return found.copy()
    return values


def restore_lsf(profile: np.ndarray, x: np.ndarray, divisor: Callable,
                noise_limit_cy_px: float = math.inf, out_step: float = 0.05,
                min_divisor: float = MIN_TRANSFER) -> tuple[np.ndarray, np.ndarray]:
    """The LSF behind a windowed profile (an LSF or a pulse response sampled
    at the uniform positions ``x``, px, zero outside its window): its
    spectrum, referenced to x = 0, divided by ``divisor`` (signed), rolled off
    (raised cosine) from min(f_n, 1.5) to min(2 f_n, 3) cy/px, f_n the
    noise limit, and transformed back on a grid no coarser than ``out_step``
    px (band-limited interpolation).  Returns ``(x, lsf)``, centred on 0,
    the LSF normalised to unit area (1/px).

    Where |divisor| < ``min_divisor`` (near a zero of a pulse's sinc) the
    spectrum is interpolated linearly from its neighbours instead of being
    divided.  An imaging LSF sampled at 1 px has almost nothing above
    1.5 cy/px, while the resampled profile's noise grows with frequency:
    the roll-off removes that noise from the FWHM without shifting it
    (< 0.05 % on the sensors tested)."""
    found = restore_lsf_many([RestoreRequest(profile, x, divisor, noise_limit_cy_px, out_step, min_divisor)])[0]
    if isinstance(found, Exception):
        raise found
    return found


class RestoreRequest(NamedTuple):
    """One profile's :func:`restore_lsf` (its arguments)."""

    profile: np.ndarray
    x: np.ndarray
    divisor: Callable
    noise_limit_cy_px: float = math.inf
    out_step: float = 0.05
    min_divisor: float = MIN_TRANSFER


def restore_lsf_many(requests: list[RestoreRequest]) -> list[tuple[np.ndarray, np.ndarray] | Exception]:
    """:func:`restore_lsf` of many profiles, their transforms of one length
    as the rows of one FFT (:func:`_fft_rows`): each result the same, to the
    bit, as the profile's restored alone, or the exception it raises.

    Examples
    --------
    >>> x = np.arange(-100, 101) * 0.05
    >>> lsf = np.exp(-x ** 2)
    >>> (x_out, restored), = restore_lsf_many([RestoreRequest(lsf, x, lambda f: np.ones_like(f))])
    >>> round(float(restored.sum() * (x_out[1] - x_out[0])), 12)
    1.0
    """
    return _fft_rows([_restore_steps(*request) for request in requests])


def _restore_steps(profile: np.ndarray, x: np.ndarray, divisor: Callable, noise_limit_cy_px: float,
                   out_step: float, min_divisor: float) -> Generator[tuple, np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """:func:`restore_lsf` as a generator of its transforms: it yields
    (``np.fft.rfft`` or ``np.fft.irfft``, values, length) and takes the
    transform back."""
    support = np.nonzero(profile)[0]
    profile, x = (a[support[0]: support[-1] + 1] for a in (profile, x))
    step = x[1] - x[0]
    n = 2 * profile.size
    k = max(int(np.ceil(step / out_step - 1e-9)), 1)
    f = np.fft.rfftfreq(n, d=step)
    lo, hi = min(noise_limit_cy_px, 1.5), min(2.0 * noise_limit_cy_px, 3.0)
    spec = (yield np.fft.rfft, profile, n) * np.exp(-2j * np.pi * f * x[0])
    passed = f < hi
    div = divisor(f[passed])
    good = np.abs(div) >= min_divisor
    restored = np.zeros_like(spec)
    fp, sp = f[passed], spec[passed]
    restored[passed] = np.where(good, sp / np.where(good, div, 1.0), 0.0)
    if good.any() and not good.all():
        bad = ~good
        restored[passed] = np.where(bad, np.interp(fp, fp[good], restored[passed][good].real)
                                    + 1j * np.interp(fp, fp[good], restored[passed][good].imag),
                                    restored[passed])
    restored *= 0.5 - 0.5 * np.cos(np.pi * np.clip((hi - f) / (hi - lo), 0.0, 1.0))
    out = np.fft.fftshift((yield np.fft.irfft, restored, n * k) * k)
    out_step_px = step / k
    return (np.arange(n * k) - n * k // 2) * out_step_px, out / (out.sum() * out_step_px)


def _fft_rows(steps: list[Generator[Any, Any, Any]]) -> list:
    """Run generators of transforms (each yields ``(np.fft.rfft or
    np.fft.irfft, values, length)`` and takes the transform of ``values``
    to ``length`` points) in lockstep, the transforms of one function and
    length made as the rows of one call, :func:`_rows_at_once` at a time
    (its plan made once); each generator's value, or the exception it raised."""
    out: list = [None] * len(steps)
    pending: dict[int, tuple] = {}

    def advance(k: int, sent) -> None:
        try:
            pending[k] = steps[k].send(sent)
        except StopIteration as stop:
            out[k] = stop.value
        except Exception as exc:        # its own run raises it: returned in its place
            out[k] = exc

    for k in range(len(steps)):
        advance(k, None)
    while pending:
        groups: dict[tuple, list[int]] = {}
        for k, (function, _, length) in pending.items():
            groups.setdefault((function, length), []).append(k)
        asked, pending = pending, {}
        for (function, length), members in groups.items():
            # a real FFT reads length points, an inverse one length // 2 + 1: zeros beyond the values
            width = length if function is np.fft.rfft else length // 2 + 1
            at_once = _rows_at_once(length)
            for start in range(0, len(members), at_once):
                part = members[start: start + at_once]
                rows = np.zeros((len(part), width), dtype=np.result_type(*(asked[k][1] for k in part)))
                for row, k in zip(rows, part):
                    values = asked[k][1][:width]
                    row[: values.size] = values
                for k, transformed in zip(part, function(rows, n=length, axis=-1)):
                    advance(k, transformed)
    return out


def corrected_mtf(profile: np.ndarray, step: float,
                  divisor: Callable) -> TabulatedMTF:
    """MTF(f) of a windowed profile (LSF, or pulse response) sampled every
    ``step`` px: |FT| normalised at 0, divided by |divisor(f)|, the transfer
    of everything between the system's LSF and this profile.  NaN where
    |divisor| < ``MIN_TRANSFER``.  Between FFT bins (0.001 cy/px apart) the
    modulus is interpolated linearly."""
    return tabulated_mtf(*spectrum(supported(profile), step), divisor)


def supported(profile: np.ndarray) -> np.ndarray:
    """A windowed profile from its first non-zero value to its last (the
    whole profile where every value is 0): what its transform needs."""
    support = np.nonzero(profile)[0]
    return profile[support[0]: support[-1] + 1] if support.size else profile


def tabulated_mtf(freqs: np.ndarray, modulus: np.ndarray, divisor: Callable) -> TabulatedMTF:
    """:func:`corrected_mtf` from the profile's :func:`spectrum` ``(freqs,
    modulus)``."""
    # the correction on the transform's own bins, once (frequencies beyond
    # MAX_MTF_FREQUENCY are of no use and cost the divisor's evaluation)
    kept = freqs <= MAX_MTF_FREQUENCY
    freqs = freqs[kept]
    div = np.abs(divisor(freqs) / divisor(np.zeros(1)))
    with np.errstate(divide="ignore", invalid="ignore"):
        corrected = np.where(div >= MIN_TRANSFER, modulus[kept] / modulus[0] / div, np.nan)

    return TabulatedMTF(freqs, corrected)


#: points transformed in one FFT call (rows of profiles of one length): the plan made once, the rows in cache
#: (4 zero-padded profiles of 20000 points gain 1.5 x on one each; 16 of them lose it again)
SPECTRUM_POINTS = 80_000


def _rows_at_once(length: int) -> int:
    """Rows of ``length`` points transformed in one call: up to 32."""
    return max(1, min(32, SPECTRUM_POINTS // length))


def spectrum_many(requests: list[tuple[np.ndarray, float]]) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`spectrum` of many profiles (``requests``: each a profile and
    its step, px), those of one transform length as the rows of one FFT
    (:func:`_fft_rows`): NumPy's FFT makes its plan on every call, which for a single
    zero-padded profile costs about as much as the transform.  Each row's
    result is the same, to the bit, as the profile's transformed alone.

    Examples
    --------
    >>> lsf = np.exp(-np.linspace(-3.0, 3.0, 121) ** 2)
    >>> (f, m), = spectrum_many([(lsf, 0.05)])
    >>> bool(np.array_equal(m, spectrum(lsf, 0.05)[1])), f.size
    (True, 10001)
    """
    return _fft_rows([_spectrum_steps(lsf, step) for lsf, step in requests])


def _spectrum_steps(lsf: np.ndarray, step: float) -> Generator[tuple, np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """:func:`spectrum` as a generator of its transform (as :func:`_fft_rows` runs them)."""
    n = _transform_length(lsf.size, step)
    transformed = yield np.fft.rfft, lsf, n
    return np.fft.rfftfreq(n, d=step), np.abs(transformed) * step


@dataclass(frozen=True, eq=False)
class TabulatedMTF:
    """An MTF tabulated on the transform's bins, read between them by
    linear interpolation; even (MTF(-f) = MTF(f)), NaN beyond the table.
    A value, not a closure, so that a result holding it can be sent to
    another process (a scan's worker hands its estimates to the fit).

    Examples
    --------
    >>> TabulatedMTF(np.array([0.0, 1.0]), np.array([1.0, 0.5]))(-0.5)
    array([0.75])
    """

    frequencies_cy_px: np.ndarray
    mtf: np.ndarray

    def __call__(self, f: np.ndarray | float) -> np.ndarray:
        f = np.atleast_1d(np.asarray(f, float))
        return np.interp(np.abs(f), self.frequencies_cy_px, self.mtf, right=np.nan)


def noise_limited_frequency(mtf: Callable, noise: Callable, f_max: float = 3.0) -> float:
    """First frequency (cy/px) where the MTF falls below 3 times its own
    noise ``noise(f)`` (its standard deviation), or inf if it never does
    below ``f_max``.  Masked frequencies (NaN, near a divisor's zeros) are
    skipped."""
    f = np.arange(0.02, f_max + 1e-9, 0.02)
    values = mtf(f)
    below = np.nonzero(np.isfinite(values) & (values < 3 * noise(f)))[0]
    return float(f[below[0]]) if below.size else float("inf")


def white_noise_mtf_sd(snr: float, window_px: float, density: float, gain: Callable) -> Callable:
    """Standard deviation of an MTF estimate at f under white sample noise:
    noise of relative level 1/``snr`` on profile samples of ``density`` per
    pixel, transformed over a window of ``window_px``, gives |FT| a standard
    deviation of sqrt(window / (2 density)) / snr (the in-phase half of
    the noise's power), times ``gain(f)``: 2 pi f for a differentiated ESF,
    1 / (the pulse's area) for a pulse response.  Zero noise for an
    infinite SNR."""
    scale = math.sqrt(window_px / (2 * density)) / snr if math.isfinite(snr) and snr > 0 else 0.0

    def sd(f):
        return scale * gain(np.asarray(f, float))
    return sd


def mtf50(mtf: Callable, f_max: float = 2.0, coarse: float = 0.02) -> float:
    """Frequency (cy/px) where the MTF first falls to 0.5: bracketed on a
    ``coarse`` grid, then interpolated linearly on a 1/50-finer grid inside
    the bracket (interpolation error below 1e-6 cy/px for smooth MTFs)."""
    f = np.arange(0.0, f_max + coarse / 2, coarse)
    m = mtf(f)
    below = np.nonzero(m < 0.5)[0]
    if below.size == 0 or below[0] == 0:
        return float("nan")
    fine = np.linspace(f[below[0] - 1], f[below[0]], 51)
    return first_crossing(fine, mtf(fine), 0.5)


def mtf_area(mtf: Callable, f_max: float = NYQUIST) -> float:
    """Area under the MTF from 0 to ``f_max`` (cy/px)."""
    f = np.linspace(0.0, f_max, 101)
    return float(np.trapezoid(mtf(f), f))


def level_crossing(grid: np.ndarray, esf01: np.ndarray, level: float, centre: float) -> float:
    """Where a rising normalised ESF passes ``level``, searching outward
    from ``centre`` (so noise in the far tails cannot produce a crossing):
    the last sample below the level on the left of ``centre`` for levels
    under the centre's value, the first above it on the right otherwise."""
    i0 = int(np.clip(np.searchsorted(grid, centre), 1, grid.size - 1))
    if level <= esf01[i0]:
        below = np.nonzero(esf01[:i0] < level)[0]
        if below.size == 0:
            return float("nan")
        i = below[-1]
    else:
        above = np.nonzero(esf01[i0:] > level)[0]
        if above.size == 0:
            return float("nan")
        i = i0 + above[0] - 1
    y0, y1 = esf01[i], esf01[i + 1]
    return float(grid[i] + (level - y0) / (y1 - y0) * (grid[i + 1] - grid[i]))


def relative_edge_response(grid: np.ndarray, esf01: np.ndarray, centre: float) -> float:
    """RER: normalised ESF at +0.5 px minus at -0.5 px from ``centre``, its
    50 % point."""
    return float(np.interp(centre + 0.5, grid, esf01) - np.interp(centre - 0.5, grid, esf01))


def rise_distance(grid: np.ndarray, esf01: np.ndarray, centre: float,
                  lo: float = 0.1, hi: float = 0.9) -> float:
    """Distance (px) over which a normalised ESF rises from ``lo`` to ``hi``
    around its 50 % point ``centre``."""
    return level_crossing(grid, esf01, hi, centre) - level_crossing(grid, esf01, lo, centre)

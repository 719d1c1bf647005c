"""Bootstrap intervals: the rows redrawn with replacement, every replicate
re-estimated, the percentile interval of the re-estimates."""
from __future__ import annotations

import functools
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from ...metrics import first_crossing
from ..spectrum import MIN_TRANSFER, NYQUIST, flat_top_window
from .interval import Estimate, FigureIntervals, Interval

FREQUENCY_STEP_CY_PX = 0.0025   # a bootstrap replicate's MTF50 is read on this grid


def row_weights(rows: np.ndarray, replicates: int, rng: np.random.Generator):
    """Bootstrap weights: ``weights_of(mask)`` -> array (replicates,
    mask.sum()), each selected sample weighted by how often its row
    (``rows`` labels each sample's row) was drawn when as many rows as there
    are were drawn with replacement, the same draws for every mask."""
    ids, inverse = np.unique(rows, return_inverse=True)
    n = ids.size
    draws = rng.integers(0, n, size=(replicates, n)) + n * np.arange(replicates)[:, None]
    counts = np.bincount(draws.ravel(), minlength=replicates * n).reshape(replicates, n).astype(float)

    def weights_of(mask: np.ndarray) -> np.ndarray:
        return counts[:, inverse[mask]]
    return weights_of


def spectral_figures(profiles: np.ndarray, step: float, divisor, *, start: int = 0, length: int | None = None,
                     amplitudes: np.ndarray | None = None, shapes: np.ndarray | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """MTF at Nyquist and MTF50 (cy/px) of every windowed profile, sampled
    every ``step`` px: |DFT| normalised at zero, divided by |divisor(f)|
    (NaN where it is below ``MIN_TRANSFER``), as
    :func:`imgmtf.estimate.spectrum.corrected_mtf` does for one profile.

    A profile is the row of ``profiles`` on the samples ``start`` to
    ``start + profiles.shape[1]`` of a lattice of ``length`` samples (by
    default those of ``profiles``, from 0), zero elsewhere, plus
    ``amplitudes @ shapes`` (replicates, k) times (k, length): the parts
    whose shapes every replicate shares (the tails' model), transformed once
    rather than once a replicate.
    """
    length = profiles.shape[-1] + start if length is None else length
    f, cosine, sine = _fourier_basis(length, step)
    on = slice(start, start + profiles.shape[-1])
    # the real profiles' transform as real products: a complex one would multiply zeros too
    real, imaginary = profiles @ cosine[on], profiles @ sine[on]
    if amplitudes is not None and shapes is not None:
        real += amplitudes @ (shapes @ cosine)
        imaginary += amplitudes @ (shapes @ sine)
    modulus = np.hypot(real, imaginary)
    div = np.abs(divisor(f) / divisor(np.zeros(1)))
    with np.errstate(invalid="ignore", divide="ignore"):
        mtf = np.where(div >= MIN_TRANSFER, modulus / modulus[:, :1] / np.where(div > 0, div, 1), np.nan)
    nyquist = mtf[:, int(round(NYQUIST / FREQUENCY_STEP_CY_PX))]
    return nyquist, first_crossing(f, mtf, 0.5)


@functools.lru_cache(maxsize=16)
def _fourier_basis(n: int, step: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The bootstrap's frequency grid (cy/px) and the DFT matrix of ``n``
    samples ``step`` px apart on it, exp(-2 pi i x f), as its real and
    imaginary parts cos(2 pi x f) and -sin(2 pi x f), shape (n,
    frequencies): made once per profile length and step (a scan's edges
    share a few), not once per edge, where its exponentials cost as much as
    the product they enter.  Read-only, being shared."""
    f = np.arange(0.0, 1.0 + 1e-9, FREQUENCY_STEP_CY_PX)
    x = np.arange(n) * step
    basis = np.exp(-2j * np.pi * x[:, None] * f[None, :])
    cosine, sine = np.ascontiguousarray(basis.real), np.ascontiguousarray(basis.imag)
    f.flags.writeable = cosine.flags.writeable = sine.flags.writeable = False
    return f, cosine, sine


def percentile_interval(samples: np.ndarray, confidence: float) -> Interval:
    """Central percentile interval of the finite ``samples``; NaN when fewer
    than 90 % of them are finite (the figure is not defined often enough
    for an interval to mean anything)."""
    samples = np.asarray(samples, float)
    finite = samples[np.isfinite(samples)]
    if finite.size < 0.9 * samples.size or finite.size == 0:
        return Interval.none()
    tail = 50.0 * (1.0 - confidence)
    low, high = np.percentile(finite, [tail, 100.0 - tail])
    return Interval(float(low), float(high))


class Windowed(NamedTuple):
    """Every replicate's windowed profile on a lattice of n samples:
    ``inner`` (replicates, m) on samples ``start`` to ``start + m`` (where
    the window holds the measured profile), zero elsewhere, plus
    ``amplitudes @ shapes`` ((replicates, k) times (k, n): the model of the
    tails where the window lets it in); ``complete`` says which replicates
    have every value finite."""

    inner: np.ndarray
    start: int
    amplitudes: np.ndarray
    shapes: np.ndarray
    complete: np.ndarray


def bootstrap_figures(distance: np.ndarray, rows: np.ndarray, span_px: float, resample: Callable,
                      windowed_profile: Callable, step: float, divisor: Callable, *, confidence: float = 0.95,
                      replicates: int = 200, seed: int = 0) -> tuple[Interval, Interval]:
    """Intervals for MTF at Nyquist and MTF50 (cy/px) by resampling rows.

    Parameters
    ----------
    distance : numpy.ndarray
        Every profile sample's distance from the target line (px).
    rows : numpy.ndarray
        Every sample's row.
    span_px : float
        The profile is needed within +-span_px of the line.
    resample : callable
        ``resample(keep, weights, half_range)`` -> Resampled, the
        estimator's own resampling of the samples selected by ``keep``
        under a stack of ``weights``.
    windowed_profile : callable
        ``(grid, values, weights_of) -> Windowed``: the estimator's
        windowed LSF (or PRF) of each replicate; ``weights_of(mask)``
        gives the replicates' weights of the samples selected by ``mask``
        (see :func:`row_weights`).
    step : float
        The profile's sample step (px).
    divisor : callable
        The estimator's transfer correction (see :mod:`.spectrum`).
    confidence : float, optional
        Coverage the intervals aim at, in (0, 1).
    replicates : int, optional
        How many times the rows are redrawn.
    seed : int, optional
        The redrawing's random seed.

    Returns
    -------
    mtf_nyquist_ci, mtf50_ci_cy_px : Interval
        The intervals of the MTF at Nyquist and of MTF50 (cy/px).
    """
    rng = np.random.default_rng(seed)
    keep = np.abs(distance) <= span_px + 2.0
    weights_of = row_weights(rows, replicates, rng)
    resampled = resample(keep, weights_of(keep), span_px)
    found = windowed_profile(resampled.grid, resampled.values, weights_of)
    complete = found.complete
    nyquist, fifty = spectral_figures(np.where(complete[:, None], found.inner, 0.0), step, divisor,
                                      start=found.start, length=found.shapes.shape[-1],
                                      amplitudes=np.where(complete[:, None], found.amplitudes, 0.0),
                                      shapes=found.shapes)
    nyquist[~complete] = np.nan
    fifty[~complete] = np.nan
    return percentile_interval(nyquist, confidence), percentile_interval(fifty, confidence)


def _tail_fits(u: np.ndarray, values: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Every replicate's weighted least-squares line ``values ~ c0 + c1 u``
    (a side's level and tail, u = 1 / |s|^p), shape (replicates, 2): the
    weighted sums of the samples in one product, the 2 x 2 normal equations
    (with 1e-12 added to their diagonal, as a guard against an empty side)
    solved in closed form for all replicates at once."""
    sums = weights @ np.stack([np.ones_like(u), u, u * u, values, u * values], axis=1)
    s0, s1, s2 = sums[:, 0] + 1e-12, sums[:, 1], sums[:, 2] + 1e-12
    det = s0 * s2 - s1 * s1
    return np.stack([(s2 * sums[:, 3] - s1 * sums[:, 4]) / det, (s0 * sums[:, 4] - s1 * sums[:, 3]) / det], axis=1)


def bootstrap_intervals(estimate: Estimate, *, confidence: float = 0.95, replicates: int = 200,
                        seed: int = 0) -> FigureIntervals:
    """Bootstrap intervals for MTF at Nyquist and MTF50: every replicate
    re-resamples the rows it drew (as far out as the profile reaches),
    refits its sides' levels and tails, and is windowed onto the estimate's
    lattice as the estimate is.  A width read off the profile is held
    fixed (a warning says so).

    Parameters
    ----------
    estimate : Estimate
        The estimate (:attr:`imgmtf.estimate.pipeline.Measurement.estimate`).
    confidence : float, optional
        Coverage the intervals aim at, in (0, 1).
    replicates : int, optional
        How many times the rows are redrawn.
    seed : int, optional
        The redrawing's random seed, so that one image always gets one interval.

    Returns
    -------
    FigureIntervals
        The percentile intervals of the MTF at Nyquist and of MTF50 (cy/px).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=5.0, seed=1)
    >>> estimate = run(EdgeKind(), chip.image, make_settings(intervals="none")).estimate
    >>> found = bootstrap_intervals(estimate, replicates=50)
    >>> float(chip.true_mtf(0.5)) in found.mtf_nyquist, found.mtf_nyquist.width < 0.05
    (True, True)
    """
    samples, lsf, window = estimate.samples, estimate.lsf, estimate.window
    distance, values, centre = samples.distance_px, samples.values_dn, estimate.centre_px
    offsets = distance - centre
    masks = [offsets <= -lsf.tail_starts_px[0], offsets >= lsf.tail_starts_px[1]]
    to_amplitude = lsf.to_amplitude
    x = lsf.x_px
    step = float(x[1] - x[0])
    from_centre = x - centre

    def windowed(grid_b, values_b, weights_of):
        coefs = []
        for mask in masks:
            coefs.append(_tail_fits(np.abs(offsets[mask]) ** -float(estimate.tail_power), values[mask],
                                    weights_of(mask)))
        background = 0.5 * (coefs[0][:, 0] + coefs[1][:, 0])
        x_data, lsf_data, _ = estimate.lsf_of(grid_b, values_b, background[:, None])
        first = int(round((x_data[0] - x[0]) / step))
        in_data = np.zeros(x.size, bool)
        in_data[first: first + x_data.size] = True
        amplitudes = np.stack([coefs[i] @ to_amplitude[i] for i in range(2)], axis=1)
        w = flat_top_window(x, centre, window.core_px, window.taper_px) * in_data
        # the profile w * lsf + (1 - w) * model, the model a tail shape times each side's amplitude:
        # the measured part only where the window holds it, the model's two shapes shared by every replicate
        held = np.flatnonzero(w)
        lo, hi = (held[0], held[-1] + 1) if held.size else (first, first)
        inner = w[lo:hi] * lsf_data[:, lo - first: hi - first]
        shapes = (1.0 - w) * lsf.tail_shape * np.stack([from_centre < 0, from_centre >= 0])
        complete = np.isfinite(lsf_data).all(axis=1) & np.isfinite(amplitudes).all(axis=1)
        return Windowed(inner, int(lo), amplitudes, shapes, complete)
    nyquist, fifty = bootstrap_figures(distance, samples.rows, float(estimate.profile.grid[-1]),
                                       estimate.resample, windowed, step, estimate.spectrum.divisor,
                                       confidence=confidence, replicates=replicates, seed=seed)
    warnings: tuple[str, ...] = ()
    read = estimate.shape_profile.resampled
    if estimate.width is not None and read.adjoint is not None:
        warnings = (f"the bootstrap holds the {estimate.target}'s width ({estimate.width.width_px:.3f} px, read "
                    "off its profile) fixed, so its intervals leave out the width's uncertainty: "
                    "give the width if it is known, or use the default (influence) intervals",)
    return FigureIntervals(nyquist, fifty, warnings)

"""The pipeline's state: what each of its stages (:mod:`.pipeline`)
produces, one frozen record a stage.

A record holds arrays and numbers only, never the settings; the stages
read the records before them.  The intervals (:mod:`.intervals`) read
:class:`Samples`, :class:`Profile`, :class:`Window`, :class:`TailedLSF` and
:class:`Spectrum`, so this module sits below them and imports none of the
stages.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .gate import Check
from .resampling import Resampled
from .tails import SideFit

if TYPE_CHECKING:           # the geometry imports OpenCV, which a batch's parent never loads
    from .geometry import TargetGeometry

#: the profile is resampled to this far (px) short of where its samples end
REACH_MARGIN_PX = 0.6


@dataclass(frozen=True, eq=False)
class Chip:
    """The pixels to measure and what is known of them (stage
    :func:`.chip.prepare_chip`).

    Attributes
    ----------
    pixels : numpy.ndarray
        The cropped chip (DN, linear light), NaN where a pixel is left out
        (nodata, outside the mask, an isolated hot or dead pixel).
    origin : (int, int)
        (x, y) of the chip's first pixel in the image, px.
    limits : (float, float) or None
        The (low, high) DN the sensor records, None where none is known.
    quantum_dn : float
        The values' step (0: not quantised), DN.
    noise_dn : float
        The robust pixel noise, DN.
    gsd_m : float or None
        Ground sample distance, m.
    track_azimuth_deg : float or None
        The ground track's direction, degrees clockwise from the image's up.
    checks : tuple of Check
        The gate's checks of the chip itself (its fill).
    warnings : tuple of str
        What was done to the pixels that the result must say.
    left_out_px : dict
        How many pixels were left out, by cause (provenance).
    noise_gain : callable or None
        Where the values were linearised: how that scaled the stored
        values' noise at a linear level (DN), and ``stored_noise_dn`` that
        noise; None where the values are measured as stored.
    stored_noise_dn : float
        The robust pixel noise of the values as stored, DN.
    """

    pixels: np.ndarray
    origin: tuple[int, int]
    limits: tuple[float, float] | None
    quantum_dn: float
    noise_dn: float
    gsd_m: float | None
    track_azimuth_deg: float | None
    checks: tuple[Check, ...]
    warnings: tuple[str, ...]
    left_out_px: dict[str, int]
    noise_gain: Callable[[float], float] | None = None
    stored_noise_dn: float = math.nan

    def noise_at(self, level_dn: float) -> float:
        """The pixel noise (DN) expected at a level (DN): ``noise_dn``
        for values measured as stored; for linearised values the stored
        noise as linearisation shapes it there (larger on a bright side,
        smaller on a dark one)."""
        if self.noise_gain is None or not math.isfinite(self.stored_noise_dn):
            return self.noise_dn
        return float(self.stored_noise_dn * self.noise_gain(level_dn))

    @property
    def roi(self) -> tuple[int, int, int, int]:
        """(x, y, width, height) of the chip in the image, px."""
        return (self.origin[0], self.origin[1], self.pixels.shape[1], self.pixels.shape[0])


@dataclass(frozen=True, eq=False)
class Samples:
    """Every kept pixel as a profile sample, in the vertical frame.

    Attributes
    ----------
    distance_px : numpy.ndarray
        Each sample's signed distance from the target's line, px.
    values_dn : numpy.ndarray
        The values the profile is built from, DN: as recorded, or a
        quantised edge's staircase rebuilt as the ESF it samples.
    raw_dn : numpy.ndarray
        The values as recorded, DN (the gate reads these).
    rows : numpy.ndarray
        Each sample's row along the target.
    half_range_px : float
        Samples are kept within this distance of the line, px.
    dequantised : bool
        Whether ``values_dn`` is a rebuilt staircase.
    """

    distance_px: np.ndarray
    values_dn: np.ndarray
    raw_dn: np.ndarray
    rows: np.ndarray
    half_range_px: float
    dequantised: bool = False

    @property
    def reach_px(self) -> float:
        """How far from the line (px) the profile can be resampled."""
        return self.half_range_px - REACH_MARGIN_PX


@dataclass(frozen=True, eq=False)
class Located:
    """The target found and followed row by row (stage
    :func:`.pipeline.locate_target`).

    Attributes
    ----------
    geometry : TargetGeometry
        The robust line through the per-row locations, in the vertical frame.
    transposed : bool
        Whether the vertical frame is the chip transposed (a near-horizontal target).
    rows_total : int
        The rows of the vertical frame.
    samples : Samples
        The profile's samples, their values as recorded.
    checks : tuple of Check
        The gate's checks so far: the chip's, the seed's, the line's and the rows'.
    """

    geometry: TargetGeometry
    transposed: bool
    rows_total: int
    samples: Samples
    checks: tuple[Check, ...]

    @property
    def rows_used(self) -> int:
        """The rows whose locations the line kept."""
        return int(self.geometry.kept.sum())


@dataclass(frozen=True, eq=False)
class Profile:
    """The samples resampled onto a uniform grid, over the central run of
    finite values about the target.

    Attributes
    ----------
    resampled : Resampled
        The resampling's whole output (its grid, values, transfer, adjoint).
    span : (int, int)
        The [start, stop) indices of the central run on ``resampled.grid``.
    """

    resampled: Resampled
    span: tuple[int, int]

    @property
    def grid(self) -> np.ndarray:
        """Positions along the normal, px."""
        return self.resampled.grid[self.span[0]: self.span[1]]

    @property
    def values(self) -> np.ndarray:
        """The profile's values, DN."""
        return self.resampled.values[self.span[0]: self.span[1]]


@dataclass(frozen=True)
class Noise:
    """The profile's noise and contrast (stage :func:`.window.measure_noise`).

    Attributes
    ----------
    noise_dn : float
        The sides' scatter about their level and tail model (at least the
        quantisation floor q / sqrt(12)), DN.
    contrast_dn : float
        The step (edge) or height (bar), DN.
    snr : float
        ``contrast_dn / noise_dn``.
    """

    noise_dn: float
    contrast_dn: float
    snr: float


@dataclass(frozen=True)
class Window:
    """The LSF window (stage :func:`.window.choose_window`).

    Attributes
    ----------
    core_px : float
        Its flat half-width, px.
    taper_px : float
        Its raised-cosine taper beyond the core, px.
    narrowed : float
        How much narrower than the clean window's core the noise made it
        (a fraction, 0 for none).
    cut : bool
        A half-width the caller gave is narrower than the target's width.
    """

    core_px: float
    taper_px: float
    narrowed: float
    cut: bool


@dataclass(frozen=True, eq=False)
class TailedLSF:
    """The LSF-like profile out to the data's reach: as measured within the
    window, the sides' tail model beyond it, blended under the taper
    (stage :func:`.window.blend_tails`).

    Attributes
    ----------
    x_px : numpy.ndarray
        The lattice (the profile grid's step) the profile is laid on, px.
    measured_at : slice
        Where the measured LSF-like profile lies on ``x_px``.
    measured : numpy.ndarray
        The kind's LSF-like profile on ``x_px`` (0 beyond the data).
    adjoint : callable
        Maps weights on ``measured_at`` back to weights on the profile's grid.
    weights : numpy.ndarray
        The window on ``x_px`` (0 beyond the data).
    sides : (SideFit, SideFit)
        The left and right sides' level + A / |s|^p fits.
    tail_starts_px : (float, float)
        Where the left and right fits start, px from the centre.
    to_amplitude : (numpy.ndarray, numpy.ndarray)
        Per side, the map from its (level, A) to the tail's amplitude a (a / s^2).
    amplitudes : (float, float)
        The tails' amplitudes a, left and right.
    tail_shape : numpy.ndarray
        1 / s^2 on ``x_px`` (0 at the centre).
    combined : numpy.ndarray
        The windowed profile: window x measured + (1 - window) x tail model.
    step_px : float
        The profile grid's step, px.
    tail_share : float
        The tail model's share of the profile's area.
    """

    x_px: np.ndarray
    measured_at: slice
    measured: np.ndarray
    adjoint: Callable[[np.ndarray], np.ndarray]
    weights: np.ndarray
    sides: tuple[SideFit, SideFit]
    tail_starts_px: tuple[float, float]
    to_amplitude: tuple[np.ndarray, np.ndarray]
    amplitudes: tuple[float, float]
    tail_shape: np.ndarray
    combined: np.ndarray
    step_px: float
    tail_share: float

    @property
    def side_levels_dn(self) -> tuple[float, float]:
        """The left and right sides' levels, DN."""
        return self.sides[0].coef[0], self.sides[1].coef[0]


@dataclass(frozen=True, eq=False)
class Spectrum:
    """The MTF and what is read off it (stage :func:`.pipeline.transform`).

    Attributes
    ----------
    divisor : callable
        The transfer between the system's LSF and the LSF-like profile,
        divided out of the MTF (f in cy/px).
    mtf : callable
        MTF(f), f in cy/px along the normal; 1 at zero frequency.
    noise_sd : callable
        The MTF's standard deviation under white sample noise at f (cy/px).
    noise_limit_cy_px : float
        Where the MTF falls below 3 times its own noise, cy/px.
    lsf_x_px, lsf : numpy.ndarray
        The recovered system LSF and its positions, px.
    mtf_nyquist : float
        MTF at 0.5 cy/px.
    mtf50_cy_px : float
        Where the MTF falls to 0.5, cy/px.
    fwhm_px : float
        The recovered LSF's full width at half maximum, px.
    """

    divisor: Callable[[np.ndarray], np.ndarray]
    mtf: Callable[[np.ndarray], np.ndarray]
    noise_sd: Callable[[np.ndarray], np.ndarray]
    noise_limit_cy_px: float
    lsf_x_px: np.ndarray
    lsf: np.ndarray
    mtf_nyquist: float
    mtf50_cy_px: float
    fwhm_px: float

"""A restoration (MTF compensation) filter designed from a sensor's 2-D transfer.

The filter is the normalised Wiener (regularised inverse) filter

    W(fx, fy) = T(fx, fy) conj(H(fx, fy)) (1 + K) / (|H(fx, fy)|^2 + K)

where ``H`` is the sensor's 2-D transfer at the image's pixel
(:meth:`imgmtf.Sensor.transfer`; complex for a sensor with a one-sided
stage, whose MTF is ``|H|``), ``T`` the target transfer and ``K`` the
regulariser, the noise-to-signal power ratio ``(noise_std / signal_std)^2``
of a scene with a white spectrum.  The restored system ``H W = T |H|^2 (1 +
K) / (|H|^2 + K)`` is real: the filter undoes the sensor's phase with its
blur.  It follows the target where the sensor passes signal well above the
noise (``|H|^2 >> K``) and falls to zero where it does not, so an exact zero
of ``H`` (motion, an OLPF) is never divided by: ``|W| <= T (1 + K) / (2 sqrt
K)``.  The factor ``1 + K`` keeps the DC gain at exactly 1 (the image's
radiometry).  ``H`` is the transfer of a real PSF, Hermitian (``H(-f) =
conj(H(f))``), and so is ``W``: its taps are real.

A real filter's transfer is real at Nyquist (``W(0.5) = W(-0.5) =
conj(W(0.5))``), where a one-sided stage's phase is not: no real filter
undoes a phase there.  ``conj(H)`` is therefore taken as ``R exp(-i c psi)``,
``H = R exp(i psi)`` with ``R`` real (signed) and ``psi`` in (-pi/2, pi/2],
``c = p(fx) p(fy)`` and ``p`` 1 up to :data:`PHASE_FULL_CY_PX` and falling
as a raised cosine to 0 at Nyquist: exactly ``conj(H)`` below 0.4 cy/px in
both axes, the phase undone less and less beyond, not at all at Nyquist.  The
restored system keeps its modulus ``T |H|^2 (1 + K) / (|H|^2 + K)`` at
every frequency (the target is met at Nyquist too) and is real below 0.4
cy/px; ``W`` is continuous across Nyquist and its taps decay.  A real ``H``
(``psi = 0``) is unchanged.

The target is smooth, separable and never above 1: ``T(fx, fy) = g(fx)
g(fy)`` with ``g(f) = V ** ((f / 0.5) ** 2)``, a Gaussian whose value at
Nyquist (0.5 cy/px) is ``V`` in both axes.

The filter's taps are the inverse DFT of ``W`` on a grid fine enough that
they have decayed at its border (the FFT form; taps that have not decayed
on the largest grid, of a transfer that jumps across Nyquist, are tapered by
a Tukey window over the outer half of their reach rather than ringing about
the design at every frequency), or those taps cut to a small
``N x N`` kernel as operational MTFC applies (the spatial form; the cut
is the least-squares fit of ``W`` with the DC gain held at 1).  Its
white-noise gain is the root of the sum of its squared taps.  A noise-gain
limit, when given and exceeded, raises ``K`` until the gain meets it: the
limit wins over the target.

Frequencies are in cycles per pixel; rows (y) are along track, columns (x)
across track, as everywhere in imgmtf.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..atomic import atomic_output
from ..errors import FileWriteError, ParameterError
from ..inputs import check_number
from ..sensor.model import Sensor, check_gsd

#: below this frequency (cy/px, in both axes) the filter undoes the sensor's phase in full; beyond,
#: less and less, and not at all at Nyquist, where a real filter's transfer is real
PHASE_FULL_CY_PX = 0.4
#: the smallest regulariser K: a noise-free image still has its sensor's zeros bounded
#: (|W| <= (1 + K) / (2 sqrt K) = 500)
MIN_REGULARISER = 1e-6
#: sides of the design grid tried in turn until the taps have decayed at its border
DESIGN_GRIDS = (65, 129, 257)
#: energy (fraction of the sum of squared taps) the FFT form may leave out when cropped
CROP_TOLERANCE = 1e-7
#: the spatial kernel sizes allowed (odd)
KERNEL_SIZES = (3, 63)
#: largest noise-gain limit honoured, and the most bisection steps spent on one
_MAX_REGULARISER = 1e6
_BISECTION_STEPS = 60


def target_transfer(f_cy_px: ArrayLike, target_nyquist: float) -> np.ndarray:
    """The 1-D target transfer ``g(f) = V ** ((f / 0.5) ** 2)``: 1 at zero
    frequency, ``V`` at Nyquist (0.5 cy/px), smooth and never above 1.

    Examples
    --------
    >>> from imgmtf.restore.design import target_transfer
    >>> [round(float(v), 4) for v in target_transfer([0.0, 0.25, 0.5], 0.25)]
    [1.0, 0.7071, 0.25]
    """
    f = np.asarray(f_cy_px, float)
    return np.exp(math.log(target_nyquist) * (f / 0.5) ** 2)


@dataclass(frozen=True, eq=False)
class RestorationFilter:
    """A designed restoration filter (what :func:`design_filter` returns);
    call it on an image to restore it.

    Attributes
    ----------
    taps : numpy.ndarray, shape (n, n), n odd
        The convolution kernel, summing to 1; the centre tap is its origin.
    sensor : Sensor
        The sensor it compensates.
    gsd_m : float
        The pixel it was designed for, metres.
    target_nyquist : float
        The target MTF at Nyquist, both axes.
    regulariser : float
        The K used (the design's, raised when the noise-gain limit won).
    noise_std_dn, signal_std_dn : float
        The noise and scene contrast K came from, DN (signal_std_dn is NaN
        when not given: K was the floor).
    max_noise_gain : float or None
        The noise-gain limit asked for.
    kernel_size : int or None
        The spatial kernel's side, px; None for the FFT form.
    limited : bool
        True when the noise-gain limit raised K (the target is then not met).

    Examples
    --------
    >>> import numpy as np
    >>> from imgmtf import Sensor, design_filter
    >>> filt = design_filter(Sensor(), 0.3, kernel_size=7)
    >>> filt.taps.shape, round(float(filt.taps.sum()), 6)
    ((7, 7), 1.0)
    >>> flat = np.full((20, 20), 500.0)
    >>> bool(np.allclose(filt(flat), 500.0))
    True
    """

    taps: np.ndarray
    sensor: Sensor
    gsd_m: float
    target_nyquist: float
    regulariser: float
    noise_std_dn: float = 0.0
    signal_std_dn: float = math.nan
    max_noise_gain: float | None = None
    kernel_size: int | None = None
    limited: bool = False

    @property
    def noise_gain(self) -> float:
        """White-noise gain: the root of the sum of the squared taps (the
        ratio of the restored to the input noise standard deviation for
        white noise)."""
        return float(np.sqrt(np.sum(self.taps ** 2)))

    @property
    def radius_px(self) -> int:
        """Half the kernel's side, px: how far a pixel's restoration reaches."""
        return self.taps.shape[0] // 2

    @property
    def form(self) -> str:
        """``"fft"`` or ``"spatial"`` (a kernel of ``kernel_size``)."""
        return "fft" if self.kernel_size is None else "spatial"

    def transfer(self, fx: ArrayLike, fy: ArrayLike) -> np.ndarray:
        """The filter's (periodic) transfer at (``fx``, ``fy``) cy/px: real
        for point-symmetric taps (a sensor whose transfer is real), complex
        otherwise (its modulus is the filter's gain).

        Parameters
        ----------
        fx, fy : array_like
            Frequencies across track (x) and along track (y), cy/px;
            broadcast together.

        Returns
        -------
        numpy.ndarray
            The transfer, of their broadcast shape (1 at zero).
        """
        fx, fy = np.broadcast_arrays(np.asarray(fx, float), np.asarray(fy, float))
        offsets = np.arange(self.taps.shape[0]) - self.radius_px
        # the taps' DFT, tap (j, k) at (y, x) = (j, k) - radius: W = sum t e^(-2 pi i (fy y + fx x)),
        # the sign of a convolution's (and of a PSF's) transfer
        ex = np.exp(-2j * np.pi * fx[..., None] * offsets)
        ey = np.exp(-2j * np.pi * fy[..., None] * offsets)
        w = np.einsum("...i,ij,...j->...", ey, self.taps, ex)
        # point-symmetric taps (t(-y, -x) = t(y, x), to rounding): a sum of cosines, real
        return w.real if self.point_symmetric else w

    @property
    def point_symmetric(self) -> bool:
        """True when the taps are point-symmetric (to 1e-12 of the largest):
        the filter's transfer is real (a sensor whose transfer is real)."""
        return bool(np.allclose(self.taps, self.taps[::-1, ::-1], rtol=0.0,
                                atol=1e-12 * float(np.abs(self.taps).max())))

    def axis_transfer(self, f_cy_px: ArrayLike, direction: str = "across") -> np.ndarray:
        """The filter's transfer along one axis: across track (fx, fy = 0) or
        along track (fy, fx = 0), at ``f_cy_px`` cy/px.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies, cy/px.
        direction : {"across", "along"}, optional
            The axis (default across track).

        Returns
        -------
        numpy.ndarray
            The transfer at each frequency.
        """
        f = np.asarray(f_cy_px, float)
        zero = np.zeros_like(f)
        return self.transfer(f, zero) if _axis(direction) == "x" else self.transfer(zero, f)

    def system_transfer(self, f_cy_px: ArrayLike, direction: str = "across") -> np.ndarray:
        """The sensor's transfer along one axis at ``f_cy_px`` cy/px of this pixel.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies, cy/px of the filter's pixel (``gsd_m``).
        direction : {"across", "along"}, optional
            The axis (default across track).

        Returns
        -------
        numpy.ndarray
            The sensor's transfer at each frequency.
        """
        f = np.asarray(f_cy_px, float) / self.gsd_m
        zero = np.zeros_like(f)
        return self.sensor.transfer(f, zero) if _axis(direction) == "x" else self.sensor.transfer(zero, f)

    def __call__(self, image: ArrayLike, *, fill: float | None = None) -> np.ndarray:
        """Restore a whole 2-D image (float64 DN out; the borders mirrored,
        NaN pixels filled with ``fill``, default the median, while filtering
        and NaN again in the output).

        Raises
        ------
        ImageContentError
            An image that is not 2-D real numbers.
        """
        from .convolve import restore_array
        return restore_array(image, self.taps, fill=fill)

    def to_dict(self) -> dict:
        """The filter's parameters and its noise gain (JSON-ready; taps left out)."""
        return {"form": self.form, "kernel_px": int(self.taps.shape[0]), "target_nyquist": self.target_nyquist,
                "regulariser": self.regulariser, "noise_std_dn": self.noise_std_dn,
                "signal_std_dn": None if math.isnan(self.signal_std_dn) else self.signal_std_dn,
                "max_noise_gain": self.max_noise_gain, "limited_by_noise_gain": self.limited,
                "noise_gain": self.noise_gain, "gsd_m": self.gsd_m, "sensor": self.sensor.to_dict()}

    def save(self, path: str | Path) -> None:
        """Write the taps for a ground segment: ``.npy`` (NumPy) or ``.txt``
        (text, one row of taps per line, the design as ``#`` comments),
        atomically.

        Parameters
        ----------
        path : str or pathlib.Path
            The file, ``.npy`` or ``.txt``.

        Raises
        ------
        ParameterError
            Another suffix.
        FileWriteError
            The file cannot be written.
        """
        suffix = Path(path).suffix.lower()
        if suffix not in (".npy", ".txt"):
            raise ParameterError(f"{path}: a kernel is written as .npy (NumPy) or .txt (text); "
                                 f"got {suffix or 'no suffix'}")
        with atomic_output(path) as partial:
            try:
                if suffix == ".npy":
                    with open(partial, "wb") as fh:
                        np.save(fh, self.taps)
                else:
                    d = self.to_dict()
                    header = (f"imgmtf restoration kernel, {self.taps.shape[0]} x {self.taps.shape[0]} taps, "
                              f"origin at the centre, summing to 1\ntarget MTF at Nyquist {self.target_nyquist:g}, "
                              f"regulariser {self.regulariser:.6g}, noise gain {self.noise_gain:.6g}\n"
                              f"sensor: {d['sensor']}")
                    np.savetxt(partial, self.taps, fmt="%.9e", header=header)
            except OSError as exc:
                raise FileWriteError(f"{path}: cannot write the kernel: {exc.strerror or exc}") from None


def design_filter(sensor: Sensor, target_nyquist: float, *, noise_std_dn: float = 0.0,
                  signal_std_dn: float | None = None, max_noise_gain: float | None = None,
                  kernel_size: int | None = None, gsd_m: float | None = None) -> RestorationFilter:
    """Design the restoration filter that brings ``sensor``'s MTF to a
    target MTF at Nyquist in both axes, regularised by the noise.

    Parameters
    ----------
    sensor : Sensor
        The system to compensate (a fitted one: ``imgmtf fit --out``).
    target_nyquist : float
        The restored MTF at Nyquist (0.5 cy/px), in (0, 1].
    noise_std_dn : float, optional
        The image's noise standard deviation, DN (default 0: K is then
        :data:`MIN_REGULARISER`).
    signal_std_dn : float, optional
        The scene's standard deviation, DN: the regulariser is
        ``K = (noise_std_dn / signal_std_dn) ** 2`` (at least
        :data:`MIN_REGULARISER`).  Needed with a non-zero noise.
    max_noise_gain : float, optional
        Upper bound (>= 1) of the filter's white-noise gain; when the target
        would exceed it, K is raised until it does not (the target is then
        not reached: see ``limited``).
    kernel_size : int, optional
        Side (odd, 3 to 63 px) of a spatial kernel; None for the FFT form
        (taps as far as they reach).
    gsd_m : float, optional
        The image's pixel, m (default the sensor's).

    Returns
    -------
    RestorationFilter
        The filter: its kernel (``taps``) and the regulariser it took.

    Raises
    ------
    ParameterError
        A value out of range (named).

    Examples
    --------
    >>> from imgmtf import Sensor, design_filter
    >>> filt = design_filter(Sensor(), 0.3, noise_std_dn=2.0, signal_std_dn=400.0)
    >>> round(float(filt.system_transfer(0.5) * filt.axis_transfer(0.5)), 2)
    0.3
    >>> round(filt.noise_gain, 2)
    1.08
    """
    if not isinstance(sensor, Sensor):
        raise ParameterError(f"expected a Sensor to design the filter from, got {type(sensor).__name__}")
    target = check_number("target MTF at Nyquist", target_nyquist, positive=True, high=1.0)
    noise = check_number("noise_std_dn", noise_std_dn)
    if signal_std_dn is None:
        if noise > 0:
            raise ParameterError("a noise_std_dn needs the scene's signal_std_dn: the regulariser is their "
                                 "squared ratio")
        signal = math.nan
        regulariser = MIN_REGULARISER
    else:
        signal = check_number("signal_std_dn", signal_std_dn, positive=True)
        regulariser = max((noise / signal) ** 2, MIN_REGULARISER)
    limit = None if max_noise_gain is None else check_number("max_noise_gain", max_noise_gain, low=1.0)
    if kernel_size is not None:
        kernel_size = int(check_number("kernel_size", kernel_size, low=KERNEL_SIZES[0], high=KERNEL_SIZES[1],
                                       integer=True))
        if kernel_size % 2 == 0:
            raise ParameterError(f"kernel_size must be odd (the kernel is centred on a pixel), got {kernel_size}")
    gsd = sensor.gsd_m if gsd_m is None else check_gsd("gsd_m", gsd_m)

    grid = _DesignGrid(sensor, gsd, target, kernel_size)
    taps = grid.taps(regulariser)
    limited = False
    if limit is not None and _gain(taps) > limit:
        regulariser = grid.regulariser_for_gain(regulariser, limit)
        taps, limited = grid.taps(regulariser), True
    taps.flags.writeable = False         # the filter is frozen, its taps with it
    return RestorationFilter(taps, sensor, gsd, target, regulariser, noise, signal, limit, kernel_size, limited)


class _DesignGrid:
    """The sensor and target transfers on the smallest DFT grid on which the
    filter's taps decay before its border."""

    def __init__(self, sensor: Sensor, gsd_m: float, target: float, kernel_size: int | None):
        self.kernel_size = kernel_size
        for n in DESIGN_GRIDS:
            f = np.fft.fftfreq(n)
            h = sensor.transfer(f[None, :] / gsd_m, f[:, None] / gsd_m)
            self.power = np.abs(h) ** 2
            self.inverse = phase_tapered_conjugate(h, phase_weight(f)[None, :] * phase_weight(f)[:, None])
            g = target_transfer(f, target)
            self.t = g[None, :] * g[:, None]
            # the smallest regulariser's taps reach furthest: a grid they fit fits every design
            taps = self._full_taps(MIN_REGULARISER)
            if _border_fraction(taps) < CROP_TOLERANCE:
                break
        # taps that have not decayed even on the largest grid come from a transfer that jumps at
        # Nyquist (a phase there, which a real filter's transfer cannot have): cut bare, they ring
        # about the design at every frequency; tapered, they follow it to Nyquist's neighbourhood
        self.window = None if _border_fraction(taps) < CROP_TOLERANCE else _tukey(taps.shape[0])

    def _full_taps(self, regulariser: float) -> np.ndarray:
        # conj(H) / (|H|^2 + K): on the odd grid every frequency has its negative, W is Hermitian and
        # its inverse DFT real to rounding (the imaginary part dropped is that rounding)
        w = self.t * self.inverse * (1 + regulariser) / (self.power + regulariser)
        return np.fft.fftshift(np.fft.ifft2(w).real)

    def taps(self, regulariser: float) -> np.ndarray:
        taps = self._full_taps(regulariser)
        centre = taps.shape[0] // 2
        if self.kernel_size is None:
            if self.window is not None:
                taps = taps * self.window
            half = _crop_half_width(taps)
        else:
            half = self.kernel_size // 2
        taps = taps[centre - half: centre + half + 1, centre - half: centre + half + 1]
        # the least-squares cut with the DC gain held at 1: the same constant added to every tap
        return taps + (1.0 - taps.sum()) / taps.size

    def regulariser_for_gain(self, start: float, limit: float) -> float:
        """The smallest K >= ``start`` whose taps' noise gain is at most
        ``limit`` (the gain falls as K grows), by bisection in log K."""
        low, high = math.log(start), math.log(start)
        while _gain(self.taps(math.exp(high))) > limit:
            if high >= math.log(_MAX_REGULARISER):
                raise ParameterError(f"no regulariser brings this filter's noise gain to {limit:g}; "
                                     "raise the limit or lower the target")
            low, high = high, min(high + math.log(100.0), math.log(_MAX_REGULARISER))
        for _ in range(_BISECTION_STEPS):
            middle = 0.5 * (low + high)
            if _gain(self.taps(math.exp(middle))) > limit:
                low = middle
            else:
                high = middle
            if high - low < 1e-4:          # K to 0.01 %: the gain to about 1e-5
                break
        return math.exp(high)


def phase_weight(f_cy_px: ArrayLike) -> np.ndarray:
    """How much of the sensor's phase the filter undoes at ``f_cy_px``
    along one axis: 1 up to :data:`PHASE_FULL_CY_PX`, a raised cosine to 0
    at Nyquist (and beyond).

    Examples
    --------
    >>> from imgmtf.restore.design import phase_weight
    >>> [round(float(v), 3) for v in phase_weight([0.0, 0.4, 0.45, 0.5])]
    [1.0, 1.0, 0.5, 0.0]
    """
    x = np.clip((np.abs(np.asarray(f_cy_px, float)) - PHASE_FULL_CY_PX) / (0.5 - PHASE_FULL_CY_PX), 0.0, 1.0)
    return 0.5 * (1.0 + np.cos(np.pi * x))


def phase_tapered_conjugate(h: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """``conj(h)`` with its phase scaled by ``weight``: ``R exp(-i weight
    psi)`` for ``h = R exp(i psi)``, ``R`` real (signed) and ``psi`` in
    (-pi/2, pi/2] (a real ``h`` is returned as it is, its sign kept)."""
    if not np.iscomplexobj(h):
        return h
    psi = np.arctan2(h.imag, h.real)
    psi = np.where(psi > np.pi / 2, psi - np.pi, np.where(psi <= -np.pi / 2, psi + np.pi, psi))
    signed = h.real * np.cos(psi) + h.imag * np.sin(psi)
    return signed * np.exp(-1j * weight * psi)


def _tukey(n: int, flat: float = 0.5) -> np.ndarray:
    """A separable n x n Tukey window: 1 over the inner ``flat`` of the
    half-width, a raised cosine to 0 beyond the outermost tap."""
    x = np.abs(np.arange(n) - n // 2) / (n // 2 + 1)
    w = np.where(x <= flat, 1.0, 0.5 * (1 + np.cos(np.pi * (x - flat) / (1 - flat))))
    return w[:, None] * w[None, :]


def _gain(taps: np.ndarray) -> float:
    return float(np.sqrt(np.sum(taps ** 2)))


def _rings(taps: np.ndarray) -> np.ndarray:
    """Energy of the taps on each square ring about the centre, innermost first."""
    n = taps.shape[0]
    idx = np.abs(np.arange(n) - n // 2)
    ring = np.maximum(idx[:, None], idx[None, :])
    return np.bincount(ring.ravel(), weights=(taps ** 2).ravel())


def _border_fraction(taps: np.ndarray) -> float:
    """Energy fraction on the outer quarter of the grid's half-width: what wraps around."""
    rings = _rings(taps)
    return float(rings[-(len(rings) // 4):].sum() / rings.sum())


def _crop_half_width(taps: np.ndarray) -> int:
    """The smallest half-width outside which less than CROP_TOLERANCE of the energy lies (at least 1)."""
    rings = _rings(taps)
    outside = 1.0 - np.cumsum(rings) / rings.sum()
    return max(int(np.argmax(outside < CROP_TOLERANCE)), 1)


def _axis(direction: str) -> str:
    if direction not in ("across", "along"):
        raise ParameterError(f"direction must be 'across' or 'along', got {direction!r}")
    return "x" if direction == "across" else "y"

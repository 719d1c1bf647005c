"""A sensor: a ground sample distance and a chain of stages.

The system transfer function is the product of the stages' analytic
transfer functions (:mod:`.stages`); the default chain is the generic
pushbroom sensor of Choi and Helder (Gaussian optics, detector rect,
along-track motion rect, first-order Butterworth electronics).  Lengths are
metres on the ground, frequencies cycles per metre; rows (y) are along
track, columns (x) across track.

Spatial functions come from the transfer function, never from sampled
convolutions:

* the line response along an edge normal (:meth:`Sensor.line_response`) is
  an inverse FFT of the 1-D transfer on a fine grid, with the Cauchy tail
  of a diffraction stage (its MTF's cusp at zero) taken out first and added
  back in closed form, so long tails are exact without a long grid;
* the 2-D PSF (:meth:`Sensor.psf`) is the inverse FFT of the 2-D transfer:
  its samples have exactly the analytic transfer at every DFT frequency,
  which a point-sampled convolution of the stages cannot give (the
  Butterworth PSF is singular at its centre).

Every grid is sized before it is allocated, and a sensor whose grid would
be absurd (a blur of thousands of pixels) is refused with a
:class:`ParameterError`.
"""
from __future__ import annotations

import math
import tomllib
from collections.abc import Iterable
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ConfigError, ParameterError
from ..inputs import check_number
from ..metrics import first_crossing, fwhm
from .lines import LineResponse, line_grid, line_spread
from .stages import STAGES, Detector, Electronics, GaussianOptics, Motion, Stage, stage_from_dict
from .stages.base import nonzero_transfer
from .toml_text import sensor_toml_lines, write_toml_lines

DIRECTIONS = ("across", "along")
#: the GSDs a sensor is rendered or read at, m: a picometre to a light-year (beyond, the
#: frequencies in cy/m square to overflow, or the stages' sizes in px do)
GSD_RANGE_M = (1e-12, 1e15)
#: the paper's stages, what ``imgmtf fit`` fits by default
PAPER_STAGES = ("optics", "detector", "motion", "electronics")
#: largest 2-D grid (cells) a sensor may ask for (its 1-D lines: :data:`.lines.MAX_LINE_SAMPLES`)
MAX_GRID_CELLS = 1 << 24

# keyword of the generic sensor -> (stage, parameter); a stage whose
# parameters are all 0 is left out (cut-off 0 meant no electronics filter)
_PAPER_KEYWORDS = {
    "optics_sigma_x_m": (GaussianOptics, "sigma_x_m"),
    "optics_sigma_y_m": (GaussianOptics, "sigma_y_m"),
    "detector_width_x_m": (Detector, "width_x_m"),
    "detector_width_y_m": (Detector, "width_y_m"),
    "motion_m": (Motion, "length_m"),
    "electronics_cutoff_cy_m": (Electronics, "cutoff_cy_m"),
}


@dataclass(frozen=True, init=False)
class Sensor:
    """A ground sample distance and a chain of stages; the defaults are the
    paper's generic sensor.

    Parameters
    ----------
    gsd_m : float
        Ground sample distance, metres per pixel (> 0).
    stages : sequence of Stage, optional
        The chain (:mod:`imgmtf.sensor.stages`).  Without it the paper's
        four stages are built from the keywords below.
    **keywords : float
        The generic sensor's parameters: ``optics_sigma_x_m``,
        ``optics_sigma_y_m``, ``detector_width_x_m``, ``detector_width_y_m``
        and ``motion_m``, metres (default 0.39, 0.39, 1, 1, 0.25), and
        ``electronics_cutoff_cy_m``, the Butterworth cut-off D0, cycles per
        metre (default 1.4; 0 for none); a stage whose parameters are all 0
        is left out.

    Raises
    ------
    ParameterError
        A parameter that is not a finite number >= 0 (named), a keyword
        that is not one of the above, both ``stages`` and keywords, or no
        stage at all.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> round(Sensor().mtf_nyquist("across"), 4)
    0.2665
    >>> [s.name for s in Sensor(motion_m=0).stages]
    ['optics', 'detector', 'electronics']
    """

    gsd_m: float
    stages: tuple[Stage, ...]

    def __init__(self, gsd_m: float = 1.0, stages: Iterable[Stage] | None = None, **keywords: float):
        gsd = check_gsd("sensor gsd_m", gsd_m)
        if stages is None:
            stages = _paper_stages(keywords)
        elif keywords:
            raise ParameterError("give a sensor either stages or the generic sensor's keywords "
                                 f"({', '.join(sorted(keywords))}), not both")
        stages = tuple(stages)
        for stage in stages:
            if not isinstance(stage, Stage):
                raise ParameterError(f"a sensor stage must be a Stage, got {stage!r}")
        if not stages:
            raise ParameterError("a sensor needs at least one stage")
        object.__setattr__(self, "gsd_m", gsd)
        object.__setattr__(self, "stages", stages)

    # -- transfer functions -------------------------------------------------
    def transfer(self, fx: ArrayLike, fy: ArrayLike) -> np.ndarray:
        """System transfer function at (``fx``, ``fy``) cycles per metre:
        the product of the stages' (1 at zero).

        Parameters
        ----------
        fx, fy : array_like
            Frequencies across track (x) and along track (y), cy/m on the
            ground; broadcast together.

        Returns
        -------
        numpy.ndarray
            The transfer, of their broadcast shape.
        """
        out = np.ones(np.broadcast(np.asarray(fx), np.asarray(fy)).shape)
        for stage in self.stages:
            out = out * stage.transfer(fx, fy, self.gsd_m)
        return out

    def normal_transfer(self, f_cy_px: ArrayLike, angle_deg: float, gsd_m: float | None = None) -> np.ndarray:
        """Transfer along the normal of an edge tilted ``angle_deg`` from the
        column axis, at ``f_cy_px`` cycles per pixel of ``gsd_m`` (default the
        sensor's): T(f cos a / gsd, f sin a / gsd).  This is the MTF an ideal
        slanted-edge estimator returns for that edge.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies along the normal, cy/px.
        angle_deg : float
            The edge's tilt from the column axis, deg (0: a vertical edge,
            its normal across track).
        gsd_m : float, optional
            The pixel, m (default the sensor's).

        Returns
        -------
        numpy.ndarray
            The transfer at each frequency (real; 1 at zero).
        """
        gsd = self._gsd(gsd_m)
        a = math.radians(check_angle(angle_deg))
        f = np.asarray(f_cy_px, float) / gsd
        return self.transfer(f * math.cos(a), f * math.sin(a))

    def mtf(self, f_cy_px: ArrayLike, direction: str = "across") -> np.ndarray:
        """MTF across track (x) or along track (y) at ``f_cy_px`` cycles/pixel.

        Parameters
        ----------
        f_cy_px : array_like
            Frequencies, cy/px.
        direction : {"across", "along"}, optional
            Across track (x, the default) or along track (y).

        Returns
        -------
        numpy.ndarray
            The MTF at each frequency.
        """
        return np.abs(self.normal_transfer(f_cy_px, direction_angle(direction)))

    def mtf_nyquist(self, direction: str = "across") -> float:
        """MTF at the Nyquist frequency, 0.5 cycles/pixel.

        Parameters
        ----------
        direction : {"across", "along"}, optional
            Across track (x, the default) or along track (y).

        Returns
        -------
        float
            The MTF at 0.5 cy/px.
        """
        return float(self.mtf(0.5, direction))

    def mtf50_cy_px(self, direction: str = "across") -> float:
        """Frequency (cycles/pixel) where the MTF first falls to 0.5 (NaN if
        it does not below 2 cy/px).

        Parameters
        ----------
        direction : {"across", "along"}, optional
            Across track (x, the default) or along track (y).

        Returns
        -------
        float
            MTF50, cy/px.
        """
        f = np.linspace(0.0, 2.0, 8001)
        return first_crossing(f, self.mtf(f, direction), 0.5)

    # -- spatial functions --------------------------------------------------
    def tail_length_m(self) -> float:
        """Length b (m) of the system LSF's Cauchy tail b / (pi x^2), from
        its stages (0 when no stage has a power-law tail).

        Returns
        -------
        float
            b, m.
        """
        # kept: a fit's every edge asks for it at every evaluation (the fields are frozen)
        length = self.__dict__.get("_tail_length_m")
        if length is None:
            length = sum(stage.tail_length_m(self.gsd_m) for stage in self.stages)
            object.__setattr__(self, "_tail_length_m", length)
        return length

    def support_radius_m(self) -> float:
        """A radius (m) outside which the sampled PSF is negligible: the sum
        of the stages' radii, at least one GSD.

        Returns
        -------
        float
            The radius, m.
        """
        radius = self.__dict__.get("_support_radius_m")
        if radius is None:
            radius = max(sum(stage.support_radius_m(self.gsd_m) for stage in self.stages), self.gsd_m)
            object.__setattr__(self, "_support_radius_m", radius)
        return radius

    def line_response(self, angle_deg: float, gsd_m: float | None = None, *, reach_px: float = 0.0,
                      step_px: float = 1.0 / 64.0) -> LineResponse:
        """Edge and line spread functions along the normal of an edge tilted
        ``angle_deg`` from the column axis, in pixels of ``gsd_m`` (default
        the sensor's), exact at any distance; the fine grid behind them
        covers ``reach_px`` on each side plus the PSF's support.

        Parameters
        ----------
        angle_deg : float
            The edge's tilt from the column axis, deg.
        gsd_m : float, optional
            The pixel, m (default the sensor's).
        reach_px : float, optional
            Distance from the edge, px, the grid must cover beyond the PSF's
            support (default 0).
        step_px : float, optional
            The grid's step, px (default 1/64; finer where a Cauchy tail
            needs it).

        Returns
        -------
        LineResponse
            The edge and line spread functions, callable at any signed
            distance (px) from the edge.

        Raises
        ------
        ParameterError
            When the grid would exceed ``MAX_LINE_SAMPLES``.
        """
        gsd = self._gsd(gsd_m)
        grid = line_grid(self, angle_deg, gsd, reach_px=reach_px, step_px=step_px)
        return grid.response(self.normal_transfer(grid.frequencies_cy_px, angle_deg, gsd))

    def normal_lsf(self, angle_deg: float, gsd_m: float | None = None,
                   samples_per_px: int = 400) -> tuple[np.ndarray, np.ndarray]:
        """LSF along the normal of an edge tilted ``angle_deg`` from the
        column axis: ``(x_px, lsf)``, positions in pixels of ``gsd_m`` and the
        LSF in 1/px (it integrates to 1 less its tail beyond the grid), on a
        grid of ``samples_per_px`` per pixel over four PSF radii.

        Parameters
        ----------
        angle_deg : float
            The edge's tilt from the column axis, deg.
        gsd_m : float, optional
            The pixel, m (default the sensor's).
        samples_per_px : int, optional
            The grid's density, samples per px (default 400).

        Returns
        -------
        x_px : numpy.ndarray
            Positions along the normal, px, centred on 0.
        lsf : numpy.ndarray
            The LSF there, 1/px.
        """
        gsd = self._gsd(gsd_m)
        half = 4 * self.support_radius_m() / gsd
        # the line response's LSF (its ESF unused: half the inverse FFTs of :meth:`line_response`)
        grid = line_grid(self, angle_deg, gsd, reach_px=half, step_px=1.0 / samples_per_px)
        # the transfer where it is not zero only: most of the fine grid's frequencies lie beyond the optics' underflow
        a, f = math.radians(check_angle(angle_deg)), grid.frequencies_cy_px / gsd
        remainder = grid.lsf_remainder(nonzero_transfer(self.stages, f * math.cos(a), f * math.sin(a), self.gsd_m))
        n = 2 * int(math.ceil(half * samples_per_px)) + 1
        x = (np.arange(n) - n // 2) / samples_per_px
        return x, line_spread(grid.start_px, grid.step_px, remainder, grid.reference, x)

    def lsf(self, direction: str = "across") -> tuple[np.ndarray, np.ndarray]:
        """Line spread function across or along track: ``(x_m, lsf)``,
        positions in metres centred on 0 and the LSF in 1/m.

        Parameters
        ----------
        direction : {"across", "along"}, optional
            Across track (x, the default) or along track (y).

        Returns
        -------
        x_m : numpy.ndarray
            Positions, m on the ground, centred on 0.
        lsf : numpy.ndarray
            The LSF there, 1/m.
        """
        x, values = self.normal_lsf(direction_angle(direction))
        return x * self.gsd_m, values / self.gsd_m

    def fwhm_m(self, direction: str = "across") -> float:
        """FWHM of the line spread function across or along track (metres).

        Parameters
        ----------
        direction : {"across", "along"}, optional
            Across track (x, the default) or along track (y).

        Returns
        -------
        float
            The FWHM, m on the ground.
        """
        return fwhm(*self.lsf(direction))

    def psf(self, oversampling: int = 20, tolerance: float = 1e-7,
            gsd_m: float | None = None, deconvolve_cell: bool = False) -> SampledPSF:
        """System PSF sampled ``oversampling`` times per GSD (``gsd_m``, default
        the sensor's) in each axis.

        With ``deconvolve_cell`` the samples are those of the PSF divided (in
        frequency) by the sub-pixel cell's own box transfer: the kernel that,
        convolved with a field of cell averages and point-sampled, gives the
        continuous field convolved with the PSF (the renderer's ground noise).

        The grid is square with an odd side, centred on the PSF, spans the
        stages' support radii, and is trimmed to the smallest square outside
        which less than ``tolerance`` of the energy lies; samples are
        renormalised to sum to 1.  A diffraction stage's tails beyond its
        99 % core are left out of this grid (not out of the line responses).

        Parameters
        ----------
        oversampling : int, optional
            Samples per GSD in each axis (default 20).
        tolerance : float, optional
            Fraction of the energy the trimmed grid may leave out (default
            1e-7).
        gsd_m : float, optional
            The pixel, m (default the sensor's).
        deconvolve_cell : bool, optional
            Divide out the sub-pixel cell's box transfer (default False).

        Returns
        -------
        SampledPSF
            The samples, summing to 1, and their spacing, m.

        Raises
        ------
        ParameterError
            A bad ``oversampling``, or a grid over ``MAX_GRID_CELLS``.
        """
        if isinstance(oversampling, (bool, np.bool_)) or not (
                isinstance(oversampling, (int, np.integer)) and oversampling >= 1):
            raise ParameterError(f"oversampling must be a positive integer, got {oversampling!r}")
        gsd = self._gsd(gsd_m)
        step = gsd / int(oversampling)
        half = int(math.ceil(self.support_radius_m() / step))
        n = 2 * half + 1
        if n * n > MAX_GRID_CELLS:
            raise ParameterError(
                f"the sensor's PSF spans {2 * self.support_radius_m() / gsd:.3g} px of {gsd:g} m: sampled "
                f"{oversampling} times per pixel it needs a {n} x {n} grid (over {MAX_GRID_CELLS} cells); "
                "lower the oversampling or check the stage parameters against the GSD")
        f = np.fft.fftfreq(n, d=step)
        t = self.transfer(f[None, :], f[:, None])
        if deconvolve_cell:
            t = t / (np.sinc(f * step)[None, :] * np.sinc(f * step)[:, None])
        grid = np.fft.fftshift(np.fft.ifft2(t).real)
        # mass inside the centred square of half-side k, for every k at once
        idx = np.abs(np.arange(n) - half)
        ring = np.maximum(idx[:, None], idx[None, :])
        inner = np.cumsum(np.bincount(ring.ravel(), weights=grid.ravel()))
        inside = np.abs(inner[-1] - inner) < tolerance * abs(inner[-1])
        keep = int(np.argmax(inside))
        data = grid[half - keep: half + keep + 1, half - keep: half + keep + 1]
        return SampledPSF(data / data.sum(), step)

    def components(self) -> dict[str, Sensor]:
        """Each stage alone, as a sensor of the same GSD, keyed by stage
        name (a repeated name gets " 2", " 3", ...).

        Returns
        -------
        dict of str to Sensor
            One sensor per stage, in the chain's order.
        """
        out: dict[str, Sensor] = {}
        for stage in self.stages:
            key, k = stage.name, 1
            while key in out:
                k += 1
                key = f"{stage.name} {k}"
            out[key] = Sensor(self.gsd_m, [stage])
        return out

    # -- files --------------------------------------------------------------
    def to_dict(self) -> dict:
        """The sensor as plain values, JSON and TOML ready.

        Returns
        -------
        dict
            ``{"gsd_m": ..., "stages": [{"stage": name, ...}, ...]}``.
        """
        return {"gsd_m": self.gsd_m, "stages": [stage.to_dict() for stage in self.stages]}

    @classmethod
    def from_dict(cls, values: dict) -> Sensor:
        """The sensor from :meth:`to_dict`'s form, or from the generic
        sensor's keywords (the old ``[sensor]`` table); missing keywords take
        the paper's defaults.

        Parameters
        ----------
        values : dict
            ``{"gsd_m": ..., "stages": [...]}``, or the keywords of
            :class:`Sensor`.

        Returns
        -------
        Sensor
            The sensor they describe.

        Raises
        ------
        ParameterError
            Unknown keys, unknown stages or bad values (named).
        """
        if not isinstance(values, dict):
            raise ParameterError(f"a sensor must be a table, got {values!r}")
        if "stages" not in values:
            return cls(**values)
        unknown = sorted(set(values) - {"gsd_m", "stages"})
        if unknown:
            raise ParameterError(f"unknown sensor key(s) {', '.join(unknown)} beside stages; known: gsd_m, stages")
        if not isinstance(values["stages"], list):
            raise ParameterError("stages must be an array of stage tables")
        return cls(values.get("gsd_m", 1.0), [stage_from_dict(s) for s in values["stages"]])

    def to_toml(self, path: str | Path, comment: str = "") -> None:
        """Write the sensor as TOML: ``gsd_m`` and an array of ``[[stages]]``
        tables, each naming its ``stage``; ``comment`` lines go on top.

        Parameters
        ----------
        path : str or pathlib.Path
            The file to write (replaced if it exists).
        comment : str, optional
            Lines written as TOML comments above the values.

        Raises
        ------
        FileWriteError
            The file cannot be written.
        """
        lines = [f"# {line}" for line in comment.splitlines()]
        lines += ["# imgmtf sensor: metres on the ground, cycles/metre for frequencies",
                  f"# stages: {', '.join(STAGES)}", *sensor_toml_lines(self.gsd_m, self.stages)]
        write_toml_lines(path, lines)

    @classmethod
    def from_toml(cls, path: str | Path) -> Sensor:
        """Read a sensor from TOML: ``gsd_m`` and ``[[stages]]`` tables as
        :meth:`to_toml` writes them, or the old form, the generic sensor's
        keywords at the top level or in a ``[sensor]`` table.

        Parameters
        ----------
        path : str or pathlib.Path
            The TOML file.

        Returns
        -------
        Sensor
            The sensor it describes.

        Raises
        ------
        ConfigError
            The file cannot be read, is not UTF-8 TOML, or holds unknown
            keys or bad values; the message names the file.
        """
        try:
            with open(path, "rb") as fh:
                doc = tomllib.loads(fh.read().decode("utf-8"))
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read sensor file: {exc.strerror or exc}") from None
        except UnicodeDecodeError:
            raise ConfigError(f"{path}: not a text (UTF-8) TOML file") from None
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"{path}: malformed TOML: {exc}") from None
        table = doc.get("sensor", doc)
        if not isinstance(table, dict):
            raise ConfigError(f"{path}: [sensor] must be a table")
        try:
            return cls.from_dict(table)
        except ParameterError as exc:
            raise ConfigError(f"{path}: {exc}") from None

    def _gsd(self, gsd_m: float | None) -> float:
        return self.gsd_m if gsd_m is None else check_gsd("gsd_m", gsd_m)


def check_gsd(name: str, gsd_m: object) -> float:
    """``gsd_m`` as a float in :data:`GSD_RANGE_M`, else a ParameterError naming ``name``."""
    check_number(name, gsd_m, positive=True)
    return check_number(name, gsd_m, low=GSD_RANGE_M[0], high=GSD_RANGE_M[1])


@dataclass(frozen=True, eq=False)
class SampledPSF:
    """A PSF on a square grid (what :meth:`Sensor.psf` returns).

    Attributes
    ----------
    data : numpy.ndarray, shape (n, n), n odd
        The PSF's samples, summing to 1; the centre sample is its origin.
    step_m : float
        The sample spacing, metres on the ground.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> psf = Sensor().psf(oversampling=10)
    >>> psf.step_m, round(float(psf.data.sum()), 6), psf.data.shape[0] % 2
    (0.1, 1.0, 1)
    """

    data: np.ndarray
    step_m: float


def direction_angle(direction: str) -> float:
    """Angle (deg from the column axis) of the edge whose normal points in
    ``direction``: across track is x (a vertical edge), along track is y."""
    if direction not in DIRECTIONS:
        raise ParameterError(f"direction must be one of {DIRECTIONS}, got {direction!r}")
    return 0.0 if direction == "across" else 90.0


def check_angle(angle_deg: object) -> float:
    """``angle_deg`` as a finite float, else a :class:`ParameterError`."""
    if isinstance(angle_deg, (bool, np.bool_)) or not isinstance(angle_deg, (int, float, np.integer, np.floating)) \
            or not math.isfinite(angle_deg):
        raise ParameterError(f"angle must be a finite number of degrees, got {angle_deg!r}")
    return float(angle_deg)


def _paper_stages(keywords: dict) -> list[Stage]:
    unknown = sorted(set(keywords) - set(_PAPER_KEYWORDS))
    if unknown:
        raise ParameterError(f"unknown sensor parameter(s) {', '.join(unknown)}; "
                             f"known: gsd_m, stages, {', '.join(_PAPER_KEYWORDS)}")
    values: dict[type, dict[str, float]] = {}
    for key, (cls, name) in _PAPER_KEYWORDS.items():
        default = {f.name: f.default for f in fields(cls)}[name]
        values.setdefault(cls, {})[name] = check_number(f"sensor parameter {key}", keywords.get(key, default))
    return [cls(**params) for cls, params in values.items() if any(params.values())]

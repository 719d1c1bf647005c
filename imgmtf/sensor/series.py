"""A calibration site imaged again and again by a sensor that degrades at
a known rate: the synthetic campaign, with its exact truth.

Each acquisition is a Baotou-like scene (:mod:`.scenes`: a four-quadrant
target tilted 16.8 deg on a uniform field, placed a little differently
each time) rendered through a square pixel and a blur that grows
``degradation`` more (as a fraction of its width at the start) every
year: anisotropic Gaussian optics (``blur="gaussian"``), or the blur of a
real L0R sensor (``blur="l0r"``): a small Gaussian core, exponential wings
per axis (:class:`.stages.Diffusion`), a scatter halo (:class:`.stages.Halo`)
and a one-sided lag along track (:class:`.stages.Lag`), the core and the
wings growing.  The truth of each acquisition is that sensor's exact
MTF across and along track; the true drift per year is the least-squares
slope of those values over the acquisitions' times, what a trend over
the campaign estimates.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta

import numpy as np

from ..errors import ParameterError
from .model import Sensor
from .scenes import QuadrantScene, QuadrantTarget, render_quadrants
from .stages import Detector, Diffusion, GaussianOptics, Halo, Lag

#: a year, days: the unit of the drift (as a trend over a campaign reports it)
YEAR_DAYS = 365.25
#: the blurs a campaign's sensor can have
BLURS = ("gaussian", "l0r")
#: the L0R blur beside the Gaussian core, px: the wings' lengths across and
#: along track (growing with the core), the halo's share and radius and the
#: lag along track (fixed): MTF at Nyquist 0.17 / 0.12 at the start, 0.10 /
#: 0.06 after five years of 6 % (the Baotou chip's half-edges read 0.10-0.12)
L0R_WINGS_PX = (0.4, 0.35)
L0R_HALO = (0.05, 2.5)
L0R_LAG_PX = 0.35
#: the L0R blur's core, px (the Gaussian blur's is ``optics_sigma_px``)
L0R_CORE_PX = (0.25, 0.3)
#: the quadrants' levels and the field's at 16 bits (DN); the smallest step
#: between quadrants (4500 DN) over the SNR gives the noise
LEVELS_16_DN = (9000.0, 2500.0, 9000.0, 4500.0)
FIELD_16_DN = 6000.0
#: ... and at 8 bits
LEVELS_8_DN = (230.0, 64.0, 230.0, 115.0)
FIELD_8_DN = 154.0


@dataclass(frozen=True)
class SyntheticCampaign:
    """A series of acquisitions of a calibration site by a degrading sensor.

    Parameters
    ----------
    acquisitions : int
        How many (>= 2).
    start_utc : str
        The first acquisition's time, ISO 8601 UTC (``2020-06-01T03:30:00Z``).
    interval_days : float
        Days between acquisitions (> 0; default 365: a year, at the same time of day).
    degradation : float
        The optics' blur grows by this fraction of its starting width each
        year (>= 0; 0.06: 6 % a year).
    optics_sigma_px : (float, float)
        The optics' Gaussian standard deviations across (x) and along (y)
        track at the start, px (with ``blur="l0r"``, default
        :data:`L0R_CORE_PX`).
    snr : float
        The smallest step between quadrants over the noise (> 0).
    size_px : int
        Side of each scene (>= 96).
    bits : int
        8 or 16.
    seed : int
        Of the noise and of each target's placement.
    gsd_m : float
        Ground sample distance, m.
    fill : bool
        Set every pixel outside the target to 0, as an L0R chip cuts a
        target out of its scene: only its four inner half-edges remain.
    blur : {"gaussian", "l0r"}
        Gaussian optics and a pixel (default), or a real L0R sensor's blur
        (see the module's docstring).

    Raises
    ------
    ParameterError
        A parameter out of range.

    Examples
    --------
    >>> campaign = SyntheticCampaign(acquisitions=3)
    >>> [round(campaign.truth(k)["mtf_nyquist_across"], 4) for k in range(3)]
    [0.3841, 0.3608, 0.3378]
    >>> round(campaign.true_slopes_per_year()["across"], 4)
    -0.0232
    >>> real = SyntheticCampaign(acquisitions=6, blur="l0r")
    >>> [round(real.truth(k)["mtf_nyquist_along"], 4) for k in (0, 5)]
    [0.1182, 0.0632]
    """

    acquisitions: int = 6
    start_utc: str = "2020-06-01T03:30:00Z"
    interval_days: float = 365.0
    degradation: float = 0.06
    optics_sigma_px: tuple[float, float] | None = None
    snr: float = 180.0
    size_px: int = 320
    bits: int = 16
    seed: int = 0
    gsd_m: float = 1.0
    fill: bool = False
    blur: str = "gaussian"

    def __post_init__(self):
        if self.blur not in BLURS:
            raise ParameterError(f"blur must be one of {', '.join(BLURS)}, got {self.blur!r}")
        if self.optics_sigma_px is None:
            object.__setattr__(self, "optics_sigma_px", L0R_CORE_PX if self.blur == "l0r" else (0.32, 0.42))
        if not (isinstance(self.acquisitions, int) and self.acquisitions >= 2):
            raise ParameterError(f"a campaign needs at least 2 acquisitions, got {self.acquisitions!r}")
        _start(self.start_utc)
        checks = {"interval_days": self.interval_days > 0, "degradation": 0 <= self.degradation < 10,
                  "snr": self.snr > 0, "gsd_m": self.gsd_m > 0}
        for name, ok in checks.items():
            if not (math.isfinite(getattr(self, name)) and ok):
                raise ParameterError(f"{name} out of range: {getattr(self, name)!r}")
        if not (len(self.optics_sigma_px) == 2 and all(0 <= s <= 5 for s in self.optics_sigma_px)):
            raise ParameterError(f"optics_sigma_px must be two widths of 0 to 5 px, got {self.optics_sigma_px!r}")
        if not (isinstance(self.size_px, int) and 96 <= self.size_px <= 4096):
            raise ParameterError(f"scenes are 96 to 4096 px a side, got {self.size_px!r}")
        if self.bits not in (8, 16):
            raise ParameterError(f"bits must be 8 or 16, got {self.bits!r}")

    def acquired_utc(self, k: int) -> str:
        """The ``k``-th acquisition's time, ISO 8601 UTC to the second."""
        when = _start(self.start_utc) + timedelta(days=k * self.interval_days)
        return when.strftime("%Y-%m-%dT%H:%M:%SZ")

    def years(self, k: int) -> float:
        """Years from the first acquisition to the ``k``-th."""
        return k * self.interval_days / YEAR_DAYS

    def sensor(self, k: int) -> Sensor:
        """The sensor at the ``k``-th acquisition: optics (and an L0R blur's
        wings) blurred (1 + degradation x years) times their starting width,
        a square pixel (and an L0R blur's halo and lag)."""
        grow = 1.0 + self.degradation * self.years(k)
        g = self.gsd_m
        sx, sy = (s * grow * g for s in self.optics_sigma_px)  # type: ignore[union-attr]
        stages = [GaussianOptics(sx, sy), Detector(g, g)]
        if self.blur == "l0r":
            stages += [Diffusion(L0R_WINGS_PX[0] * grow * g, L0R_WINGS_PX[1] * grow * g),
                       Halo(L0R_HALO[0], L0R_HALO[1] * g), Lag(0.0, L0R_LAG_PX * g)]
        return Sensor(g, stages)

    def target(self, k: int) -> QuadrantTarget:
        """The ``k``-th scene's target: tilted 16.8 deg, centred within a
        few px of the middle (a different sub-pixel phase each time),
        reaching 30 % of the scene either side."""
        rng = np.random.default_rng([self.seed, k, 1])
        middle = (self.size_px - 1) / 2.0
        cx, cy = middle + rng.uniform(-3.0, 3.0, 2)
        levels = LEVELS_16_DN if self.bits == 16 else LEVELS_8_DN
        return QuadrantTarget((float(cx), float(cy)), 16.8, levels, 0.3 * self.size_px)

    def noise_std_dn(self) -> float:
        """The white noise (DN) that, with the rounding's own (1/sqrt(12)
        DN), makes the smallest step over the noise the SNR."""
        levels = LEVELS_16_DN if self.bits == 16 else LEVELS_8_DN
        step = min(abs(levels[0] - levels[3]), abs(levels[0] - levels[1]))
        return math.sqrt(max((step / self.snr) ** 2 - 1.0 / 12.0, 0.0))

    def render(self, k: int) -> QuadrantScene:
        """The ``k``-th acquisition's scene (uint16, or uint8 at 8 bits)."""
        if not 0 <= k < self.acquisitions:
            raise ParameterError(f"acquisition {k} is not one of 0 to {self.acquisitions - 1}")
        field = FIELD_16_DN if self.bits == 16 else FIELD_8_DN
        scene = render_quadrants(self.sensor(k), (self.size_px, self.size_px), self.target(k), field_dn=field,
                                 fill=self.fill, noise_std_dn=self.noise_std_dn(), seed=self.seed * 100003 + k)
        if self.bits == 8:
            image = np.clip(scene.image, 0, 255).astype(np.uint8)
            scene = QuadrantScene(image, scene.target, scene.sensor, scene.fill, scene.noise_std_dn, scene.seed,
                                  scene.provenance)
        return scene

    def truth(self, k: int) -> dict:
        """The ``k``-th acquisition's exact figures: its time, years since
        the start, the optics' widths (m) and the MTF at Nyquist and MTF50
        (cy/px) across and along track."""
        sensor = self.sensor(k)
        optics = sensor.stages[0]
        return {"acquired_utc": self.acquired_utc(k), "years": self.years(k),
                "stages": [s.name for s in sensor.stages],
                "optics_sigma_x_m": optics.sigma_x_m, "optics_sigma_y_m": optics.sigma_y_m,  # type: ignore[attr-defined]
                **{f"mtf_nyquist_{d}": float(sensor.mtf_nyquist(d)) for d in ("across", "along")},
                **{f"mtf50_{d}_cy_px": float(sensor.mtf50_cy_px(d)) for d in ("across", "along")}}

    def true_slopes_per_year(self) -> dict[str, float]:
        """The least-squares slope per year of the true MTF at Nyquist over
        the acquisitions, across and along track."""
        t = np.array([self.years(k) for k in range(self.acquisitions)])
        out = {}
        for d in ("across", "along"):
            values = np.array([self.truth(k)[f"mtf_nyquist_{d}"] for k in range(self.acquisitions)])
            out[d] = float(np.polyfit(t, values, 1)[0])
        return out

    def as_dict(self) -> dict:
        return {"acquisitions": self.acquisitions, "start_utc": self.start_utc, "interval_days": self.interval_days,
                "degradation_per_year": self.degradation, "optics_sigma_px": list(self.optics_sigma_px or ()),
                "snr": self.snr, "size_px": self.size_px, "bits": self.bits, "seed": self.seed,
                "gsd_m": self.gsd_m, "fill": self.fill, "blur": self.blur}


def _start(text: str) -> datetime:
    try:
        when = datetime.fromisoformat(str(text).replace("Z", "+00:00"))
    except ValueError:
        raise ParameterError(f"the start must be an ISO 8601 time (2020-06-01T03:30:00Z), got {text!r}") from None
    return when.replace(tzinfo=UTC) if when.tzinfo is None else when.astimezone(UTC)

"""How a chip is measured: the settings every estimate reads, their bounds
checked once (each resampling method checks its own options)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..inputs import check_number
from ..transfer import Transfer, parse_transfer
from .intervals import Intervals, as_intervals
from .resampling import METHODS, check_method

DEFAULT_FREQUENCIES = np.round(np.arange(0.0, 1.0 + 1e-9, 0.01), 10)
STEP_RANGE_PX = (0.005, 0.25)     # finer costs time for nothing; coarser misses the LSF's shape
MAX_FREQUENCY_CY_PX = 4.0


@dataclass(frozen=True, eq=False)
class Settings:
    """How an over-sampled-profile estimator measures (shared by edges and
    bars).

    Parameters
    ----------
    method : str
        Resampling method, a key of :data:`imgmtf.estimate.resampling.METHODS`
        ("msg", "sliding", "spline", "iso").
    step_px : float
        Resampled profile grid step (px), 0.005 to 0.25; "iso" always uses
        its 1/4-px bins.
    correct : bool
        Divide out the blur of the estimator's own steps.  False
        reproduces the uncorrected classic algorithms.
    frequencies_cy_px : array_like
        Where the reported MTF curve is sampled (cy/px, 0 to 4).
    snr_threshold : float or None
        Below this SNR the result carries a warning; None uses the
        measured threshold for the target's length.
    method_options : dict
        Overrides of the method's defaults (e.g. ``window_px``).
    lsf_half_width_px : float or None
        Half-width of the flat core of the LSF window (px); None chooses
        it from the target's width and the SNR.
    lsf_window_factor : float or None
        That half-width in units of the 10-90 % rise (edges); None adapts
        it to the SNR.
    intervals : Intervals or str or int
        Confidence-interval settings (:class:`imgmtf.estimate.intervals.Intervals`),
        or a method's name as ``--intervals`` takes it ("influence",
        "bootstrap", "none"), or a number of bootstrap replicates (0: none).
    force : bool
        Measure even when a quality check fails (each failure becomes a
        warning) instead of refusing.
    transfer : str or Transfer
        How the stored values relate to light (:mod:`imgmtf.transfer`):
        "linear" (default: as stored), "srgb" or "gamma:G"; the values are
        linearised before measuring.

    Raises
    ------
    ParameterError
        For any value out of its range or of the wrong kind.
    """

    method: str = "msg"
    step_px: float = 0.05
    correct: bool = True
    frequencies_cy_px: np.ndarray = field(default_factory=lambda: DEFAULT_FREQUENCIES)
    snr_threshold: float | None = None
    method_options: dict = field(default_factory=dict)
    lsf_half_width_px: float | None = None
    lsf_window_factor: float | None = None
    intervals: Intervals = field(default_factory=Intervals)
    force: bool = False
    transfer: Transfer = field(default_factory=Transfer)

    def __post_init__(self):
        check_method(self.method)
        set_ = object.__setattr__
        set_(self, "step_px", check_number("step_px", self.step_px, low=STEP_RANGE_PX[0], high=STEP_RANGE_PX[1]))
        if not isinstance(self.correct, (bool, np.bool_)):
            raise ParameterError(f"correct must be True or False, got {self.correct!r}")
        try:
            f = np.asarray(self.frequencies_cy_px, float).ravel()
        except (TypeError, ValueError):
            raise ParameterError(f"frequencies_cy_px must be numbers, got {self.frequencies_cy_px!r}") from None
        if f.size == 0 or not np.all(np.isfinite(f)) or f.min() < 0 or f.max() > MAX_FREQUENCY_CY_PX:
            raise ParameterError(f"frequencies_cy_px must be finite, in [0, {MAX_FREQUENCY_CY_PX:g}] cy/px")
        set_(self, "frequencies_cy_px", f)
        if self.snr_threshold is not None:
            set_(self, "snr_threshold", check_number("snr_threshold", self.snr_threshold, positive=True))
        if not isinstance(self.method_options, dict):
            raise ParameterError(f"method_options must be a dict, got {self.method_options!r}")
        _check_method_options(self.method, self.method_options)
        if self.lsf_half_width_px is not None:
            set_(self, "lsf_half_width_px", check_number("lsf_half_width_px", self.lsf_half_width_px,
                                                         low=0.5, high=64.0))
        if self.lsf_window_factor is not None:
            set_(self, "lsf_window_factor", check_number("lsf_window_factor", self.lsf_window_factor,
                                                         low=0.5, high=10.0))
        set_(self, "intervals", as_intervals(self.intervals))
        if not isinstance(self.force, (bool, np.bool_)):
            raise ParameterError(f"force must be True or False, got {self.force!r}")
        set_(self, "transfer", parse_transfer(self.transfer))

    def as_dict(self) -> dict:
        out = {"method": self.method, "step_px": self.step_px, "correct": self.correct,
               "intervals": self.intervals.as_dict(), "force": self.force, "transfer": str(self.transfer)}
        for key in ("snr_threshold", "lsf_half_width_px", "lsf_window_factor"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.method_options:
            out["method_options"] = dict(self.method_options)
        return out


def _check_method_options(method: str, options: dict) -> None:
    """Bounds of the resampling methods' options (unknown names are the
    dispatcher's to refuse)."""
    bounds = {"window_px": (0.05, 8.0), "order": (0, 8), "cutoff_cy_px": (0.1, 20.0), "bin_px": (0.02, 1.0)}
    for name, value in options.items():
        if name in bounds:
            low, high = bounds[name]
            check_number(name, value, low=low, high=high, integer=name == "order")
    unknown = set(options) - set(METHODS[method].defaults)
    if unknown:
        raise ParameterError(f"method {method!r} takes no option(s) {', '.join(sorted(unknown))}; "
                             f"it takes {', '.join(METHODS[method].defaults)}")


def make_settings(method: str = "msg", *, bootstrap=None, **options) -> Settings:
    """:class:`Settings` from keywords, with ``bootstrap=N`` meaning N
    bootstrap replicates (0: no intervals) and unknown keywords refused by
    name."""
    known = set(Settings.__dataclass_fields__)
    unknown = sorted(set(options) - known)
    if unknown:
        raise ParameterError(f"unknown option(s) {', '.join(unknown)}; valid: bootstrap, "
                             f"{', '.join(sorted(known - {'method'}))}")
    if bootstrap is not None:
        if "intervals" in options:
            raise ParameterError("give intervals= or bootstrap=, not both")
        options["intervals"] = as_intervals(bootstrap)
    return Settings(method, **options)

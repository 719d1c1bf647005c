"""The point-target estimator configured once and called per chip, as the
kind registry makes every kind's (:meth:`imgmtf.kinds.Kind.make_estimator`):
the file's values linearised, a window cut, :func:`.points.measure_points`
run."""
from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import ParameterError
from ..intervals import Intervals, as_intervals
from ..linear_window import linear_window, placed
from .points import PointsResult, measure_points


class PointsEstimator:
    """The point-target estimator configured once and applied to many chips,
    as the kind registry calls estimators (:meth:`imgmtf.kinds.Kind.make_estimator`).

    Parameters
    ----------
    method : str, optional
        The 1-D pipeline's resampling method, which a point stack does not
        use (it has its own transform): accepted so that every kind's
        estimator is made alike, recorded as ``params["resampling"]``.
    intervals : Intervals, str or int, optional
        "none" for none; any other method (the edges' default "influence"
        among them) is a bootstrap over the targets, with its confidence,
        replicates and seed.
    force : bool, optional
        Accepted alike; a point stack has no gate to overrule (its targets
        are refused one by one, with their reasons).
    transfer : str, optional
        How the stored values relate to light ("linear", "srgb",
        "gamma:G"): linearised before measuring.
    **options
        Keywords of :func:`measure_points` (``polarity``,
        ``stamp_radius_px``, ``min_snr``, ``min_separation_px``).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.points import PointArray, render_points
    >>> chip = render_points(imgmtf.Sensor(), PointArray(4, 4), 64)
    >>> estimate = PointsEstimator(intervals="none")
    >>> result = estimate(chip.image, gsd_m=1.0)
    >>> abs(result.directions[1].mtf_nyquist - float(chip.true_mtf(0.5, "along"))) < 0.005
    True
    """

    def __init__(self, method: str = "msg", *, intervals: Intervals | str | int | None = None, force: bool = False,
                 transfer: str = "linear", **options: Any):
        from ...transfer import parse_transfer
        unknown = sorted(set(options) - {"polarity", "stamp_radius_px", "min_snr", "min_separation_px"})
        if unknown:
            raise ParameterError(f"unknown point-target setting(s) {', '.join(unknown)}")
        settings = as_intervals(intervals)
        if settings.method not in ("none", "bootstrap"):
            settings = Intervals("bootstrap", settings.confidence, settings.replicates, settings.seed)
        self.method, self.intervals, self.force = method, settings, force
        self.transfer = parse_transfer(transfer)
        self.options = options

    def __call__(self, image: np.ndarray, *, point_size_px: float | None = None, gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None, dtype: Any = None,
                 track_azimuth_deg: float | None = 0.0, roi: tuple[int, int, int, int] | None = None) -> PointsResult:
        """Measure the point targets on ``image`` (see :func:`measure_points`)."""
        data, saturation, notes = linear_window(image, roi, dtype, saturation, self.transfer)
        result = measure_points(data, point_size_px=point_size_px or 0.0, saturation=saturation,
                                intervals=self.intervals, gsd_m=gsd_m, track_azimuth_deg=track_azimuth_deg,
                                **self.options)
        return placed(result, roi, self.method, self.transfer, notes)

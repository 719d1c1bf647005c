"""The Siemens-star estimator configured once and called per chip, as the
kind registry makes every kind's (:meth:`imgmtf.kinds.Kind.make_estimator`):
the file's values linearised, a window cut, :func:`.measure.measure_star`
run."""
from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import ParameterError
from ..intervals import Intervals, as_intervals
from ..linear_window import linear_window, placed
from .measure import measure_star
from .result import StarResult

#: the keywords of :func:`measure_star` an estimator may be configured with
OPTIONS = ("profile", "cycles", "n_directions")


class StarEstimator:
    """The Siemens-star estimator configured once and applied to many chips.

    Parameters
    ----------
    method : str, optional
        The 1-D pipeline's resampling method, which a star does not use (its
        rings are fitted where the pixels lie): accepted so that every
        kind's estimator is made alike, recorded as ``params["resampling"]``.
    intervals : Intervals, str or int, optional
        "none" for none; any other method gives the intervals from the
        rings' residuals at its confidence.
    force : bool, optional
        Accepted alike; a star has no gate to overrule.
    transfer : str, optional
        How the stored values relate to light ("linear", "srgb",
        "gamma:G"): linearised before measuring.
    **options
        Keywords of :func:`measure_star` (``profile``, ``cycles``,
        ``n_directions``).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.sensor.star import SiemensStar, render_star
    >>> chip = render_star(imgmtf.Sensor(), SiemensStar(cycles=48), 161)
    >>> result = StarEstimator(intervals="none")(chip.image, gsd_m=1.0)
    >>> abs(result.directions[0].mtf_nyquist - float(chip.true_mtf(0.5, 0.0))) < 0.01
    True
    """

    def __init__(self, method: str = "msg", *, intervals: Intervals | str | int | None = None, force: bool = False,
                 transfer: str = "linear", **options: Any):
        from ...transfer import parse_transfer
        unknown = sorted(set(options) - set(OPTIONS))
        if unknown:
            raise ParameterError(f"unknown star setting(s) {', '.join(unknown)}")
        self.method, self.intervals, self.force = method, as_intervals(intervals), force
        self.transfer = parse_transfer(transfer)
        self.options = options

    def __call__(self, image: np.ndarray, *, gsd_m: float | None = None,
                 saturation: tuple[float, float] | None = None, dtype: Any = None,
                 track_azimuth_deg: float | None = 0.0, roi: tuple[int, int, int, int] | None = None) -> StarResult:
        """Measure the star filling ``image`` (see :func:`measure_star`)."""
        data, saturation, notes = linear_window(image, roi, dtype, saturation, self.transfer)
        result = measure_star(data, intervals=self.intervals, gsd_m=gsd_m, track_azimuth_deg=track_azimuth_deg,
                              saturation=saturation, **self.options)
        return placed(result, roi, self.method, self.transfer, notes)

"""Many chips' profiles resampled at once (the ``resample`` ask of
:mod:`.asks`): each answer the same as :func:`.resampling.resample_profile`
gives that chip's samples alone."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .resampling import Resampled, resample_profile


@dataclass(frozen=True, eq=False)
class ResampleRequest:
    """One profile's resampling (:func:`.resampling.resample_profile`'s
    arguments, one weighting).

    Attributes
    ----------
    distance : numpy.ndarray
        Each sample's signed distance from the target line, px.
    values : numpy.ndarray
        Each sample's value, DN.
    half_range : float
        The grid spans +-``half_range`` px.
    method : str
        A key of :data:`.resampling.METHODS`.
    step : float
        Grid step, px.
    options : dict
        Overrides of the method's defaults.
    """

    distance: np.ndarray
    values: np.ndarray
    half_range: float
    method: str = "msg"
    step: float = 0.05
    options: dict = field(default_factory=dict)


def resample_many(requests: list[ResampleRequest]) -> list[Resampled | Exception]:
    """Every request resampled: each a :class:`.resampling.Resampled`, or
    the exception its own resampling raises.

    Parameters
    ----------
    requests : list of ResampleRequest
        The profiles.

    Returns
    -------
    list of Resampled or Exception
        One per request, in order.

    Examples
    --------
    >>> d = np.linspace(-3.0, 3.0, 600)
    >>> [r.grid.size for r in resample_many([ResampleRequest(d, d, 1.0), ResampleRequest(d, d, 2.0)])]
    [41, 81]
    """
    out: list[Resampled | Exception] = []
    for r in requests:
        try:
            out.append(resample_profile(r.distance, r.values, method=r.method, step=r.step,
                                        half_range=r.half_range, **r.options))
        except Exception as exc:        # its own resampling raises it: returned in its place
            out.append(exc)
    return out

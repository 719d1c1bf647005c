"""Two parallel bars seen in one bar's profile (Storey's causeway: two
spans of a bridge).  A single bar's pulse response has one peak; a pair's,
two, with a dip between them that no single bar through a blur makes.
Measured as one bar, a pair's MTF comes out times the pair's
|cos(pi f s)| (s their centres' distance): a silent wrong number, or an
"MTF above one" where the width is read off the profile.  So a bar's
profile that holds two is refused (reason ``double-bar``), never measured
as one: :mod:`imgmtf.estimate.double_bar` measures it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: the reason code of a bar refused as two (the double-bar kind's name too: the kind that measures it)
PAIR_REASON = "double-bar"
#: a dip between two peaks counts when it falls below this share of the lower
#: peak (a sharpened wide bar's overshoots at its sides dip to 0.85-0.9 of them;
#: two 0.6 px bars 1.2 px apart through sigma 0.39 px + pixel to 0.47)
MAX_DIP_SHARE = 0.75
#: ... and by this many times the profile's noise below it
MIN_DIP_NOISE = 5.0
#: a peak counts when it reaches this share of the highest
MIN_PEAK_SHARE = 0.5


@dataclass(frozen=True)
class BarPair:
    """Two bars in one profile: their peaks' positions (px, along the
    normal) and the dip between them as a share of the lower peak."""

    left_px: float
    right_px: float
    dip_share: float

    @property
    def apart_px(self) -> float:
        """Their peaks' distance, px (the bars' centres', for equal bars)."""
        return self.right_px - self.left_px

    def message(self, instead: str = "one bar") -> str:
        """The refusal's words: what was seen, ``instead`` of what was asked
        for ("one bar", "an edge"), and what measures it."""
        return (f"two parallel bars {self.apart_px:.1f} px apart (the profile dips to "
                f"{self.dip_share:.0%} of its peaks between them), not {instead} but a double bar")


def bar_pair(grid: np.ndarray, prf01: np.ndarray, noise: float = 0.0) -> BarPair | None:
    """The two bars a bar's profile holds, or None for one.

    Parameters
    ----------
    grid : numpy.ndarray
        Positions along the normal, px (uniform, ascending).
    prf01 : numpy.ndarray
        The profile above its background, its peak 1.
    noise : float, optional
        The profile's noise in the same units (0: noise-free).

    Returns
    -------
    BarPair or None
        The two highest peaks with a deep dip between them, or None.

    Examples
    --------
    >>> x = np.linspace(-5, 5, 201)
    >>> one = np.exp(-x ** 2 / 0.5)
    >>> two = np.exp(-(x - 0.9) ** 2 / 0.5) + np.exp(-(x + 0.9) ** 2 / 0.5)
    >>> bar_pair(x, one) is None, round(bar_pair(x, two / two.max()).apart_px, 1)
    (True, 1.8)
    """
    values = np.asarray(prf01, float)
    if values.size < 5:
        return None
    inner = values[1:-1]
    peaks = np.nonzero((inner > values[:-2]) & (inner >= values[2:]) & (inner >= MIN_PEAK_SHARE * values.max()))[0] + 1
    if peaks.size < 2:
        return None
    best: BarPair | None = None
    for i, left in enumerate(peaks[:-1]):
        for right in peaks[i + 1:]:
            lower = min(values[left], values[right])
            dip = float(values[left: right + 1].min())
            share = dip / lower
            if share <= MAX_DIP_SHARE and lower - dip >= MIN_DIP_NOISE * noise and (
                    best is None or share < best.dip_share):
                best = BarPair(float(grid[left]), float(grid[right]), share)
    return best


def pair_in_profile(grid: np.ndarray, values: np.ndarray, noise_dn: float = 0.0) -> BarPair | None:
    """The two bars a raw profile across a bar holds (DN, not yet above its
    background), or None: its background the mean of its outer eighths,
    its excursion from there (bright or dark) scaled to a unit peak, then
    :func:`bar_pair`.  What another kind of target (an edge) uses to say
    that the bar it met is two.

    Parameters
    ----------
    grid : numpy.ndarray
        Positions along the normal, px (uniform, ascending).
    values : numpy.ndarray
        The profile, DN.
    noise_dn : float, optional
        Its noise, DN (0: noise-free).

    Returns
    -------
    BarPair or None
        As :func:`bar_pair`.

    Examples
    --------
    >>> x = np.linspace(-8, 8, 321)
    >>> two = 200 + 900 * (np.exp(-(x - 1.5) ** 2 / 0.5) + np.exp(-(x + 1.5) ** 2 / 0.5))
    >>> round(pair_in_profile(x, two, noise_dn=5.0).apart_px, 1), pair_in_profile(x, 1100 - two) is not None
    (3.0, True)
    """
    values = np.asarray(values, float)
    ends = max(values.size // 8, 2)
    background = float(np.mean(np.r_[values[:ends], values[-ends:]]))
    excursion = values - background
    peak = excursion if excursion.max() >= -excursion.min() else -excursion
    height = float(peak.max())
    if not height > 0:
        return None
    return bar_pair(grid, peak / height, noise_dn / height)

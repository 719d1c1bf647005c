"""The quality gate: every check that decides whether a chip's MTF can be
trusted, each with a machine-readable reason and a one-line message.

``measure`` and ``scan`` run the same checks through the same pipeline
(:mod:`.pipeline`), so one chip gets one verdict.  A failed check refuses
the chip (:class:`QualityError`, naming every failed check); a caller who
insists (``force=True``) gets the number with each failed check in its
warnings.  Reasons:

========================  ===================================================
``fill``                  fill or nodata (0 or an integer type's limit with a
                          hard, unblurred boundary) inside the chip
``saturated``             a side or the bar's peak clipped (integer limits, a
                          given saturation range, or a pile-up at one value)
                          (:mod:`.saturation`)
``not-straight``          the per-row locations do not lie on one line (no
                          edge at all, a curved edge, texture)
``two-targets``           a second edge or bar beside the target
``non-uniform``           a side with a level trend or texture (:mod:`.sides`), a level
                          that curves or never settles
                          (:mod:`.settling`)
``varying-blur``          the blur changes along the target
                          (:mod:`.blur_along`)
``compression``           8 x 8 blocks of a lossy codec shape the target
                          (:mod:`.blocks`)
``too-short``             too few rows for a stable estimate
``mtf-above-one``         the MTF rises above 1 by more than its noise
``mtf-undefined``         MTF50, MTF at Nyquist or FWHM cannot be read off
``snr``                   noise too strong to measure anything
``not-an-edge``,          the profile is a bar where an edge was asked for,
``not-a-bar``             or a step where a bar was
``double-bar``            the bar is two parallel bars (:mod:`.bar_pair`)
========================  ===================================================
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import MultipleTargetsError, UnsuitableTargetError
from ._order import median
from .bar_pair import PAIR_REASON, pair_in_profile
from .phase import phase_bias_many

MIN_ROWS = 20                   # fewer rows: the row-location line and the profile are unstable
MIN_SNR = 8.0                   # below this an edge's MTF at Nyquist is mostly noise (about +-0.1)
MAX_SIDE_TREND = 0.10           # level change across a side, fraction of the contrast
MAX_SIDE_TEXTURE = 0.05         # texture standard deviation beyond the pixel noise, fraction of contrast
MAX_SECOND_FEATURE = 0.08       # a 1-px band of a side off its model by this fraction: another feature
MAX_LINE_SCATTER_PX = 0.3       # robust scatter of row locations about the line, at the least
MIN_ROWS_ON_LINE = 0.7          # fraction of rows the line must hold
MAX_SAGITTA_PX = 0.3            # bow of the row locations over the edge's length
FILL_BOUNDARY = 0.05            # a fill region's neighbours differ from it by this fraction of the contrast
MIN_FILL_FRACTION = 0.005
MIN_FILL_CLUSTERED = 0.5        # the share of fill pixels with a fill neighbour: fill is a region
MAX_MTF_EXCESS = 0.05           # MTF above 1 + this (plus 3 noise sd) refuses the chip
MIXED_SHARE = 0.25              # a profile with a step and a bar each this share of its range: two targets
EDGE_STEP_RATIO = 0.5           # |right - left| / largest excursion: above it a step, below a bar

# the profile shapes classify_profile tells apart (a kind wants one), and the refusal of the other
STEP_PROFILE, BAR_PROFILE = "edge", "bar"
WRONG_PROFILE = {STEP_PROFILE: ("not-an-edge", "the profile rises and falls back: a bar, not an edge"),
                 BAR_PROFILE: ("not-a-bar", "the profile is a step, not a bar")}

@dataclass(frozen=True)
class Check:
    """The outcome of one quality check.

    ``reason`` is the machine-readable code, ``message`` one line saying
    what was measured against what limit; ``value`` and ``limit`` are the
    numbers (units in the message); ``share`` the fraction of the chip a
    failure covers, where that is known (fill).  ``ran`` is False for a
    check that could not run on this chip (too few samples, no side left
    to judge): it is no pass (``passed`` False), and no refusal either
    (``failed`` False); its message says why it could not run
    (:func:`not_run`).  Where being unable to judge is itself a fault
    (a side whose plateau never arrives within the chip), the check
    fails instead.  ``explained_by`` names a known cause that makes what
    would fail the check pass (a sharpening kernel's MTF above 1).
    """

    reason: str
    passed: bool
    message: str
    value: float | None = None
    limit: float | None = None
    share: float | None = None
    ran: bool = True
    explained_by: str | None = None

    @property
    def failed(self) -> bool:
        """Did the check run and refuse the chip?"""
        return self.ran and not self.passed

    @property
    def outcome(self) -> str:
        """"passed", "failed" or "not-run"."""
        return "not-run" if not self.ran else "passed" if self.passed else "failed"

    def to_dict(self) -> dict:
        """JSON-ready: reason, outcome, passed, message, value and limit
        (None where not known)."""
        def number(x):
            return round(float(x), 6) if x is not None and math.isfinite(float(x)) else None
        out = {"reason": self.reason, "outcome": self.outcome, "passed": bool(self.passed and self.ran),
               "message": self.message, "value": number(self.value), "limit": number(self.limit)}
        return {**out, "explained_by": self.explained_by} if self.explained_by else out


def not_run(reason: str, why: str) -> Check:
    """The record of a check that could not run on a chip, and ``why``
    (one line): neither a pass nor a refusal.

    Examples
    --------
    >>> check = not_run("compression", "too few rows to see an 8-row block grid")
    >>> check.outcome, check.passed, check.failed
    ('not-run', False, False)
    """
    return Check(reason, False, f"not run: {why}", ran=False)


class QualityError(UnsuitableTargetError):
    """A chip refused by the quality gate; ``checks`` lists the failed
    checks, the first one's reason is the error's.  ``force=True`` (the
    CLI's ``--force``) measures such a chip anyway, each failed check a
    warning.

    Parameters
    ----------
    failed : list of Check
        The failed checks, the first the one the message and reason give.

    Examples
    --------
    >>> import imgmtf
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, bits=8)    # 1200 DN clips at 255
    >>> try:
    ...     imgmtf.measure_edge(chip.image)
    ... except imgmtf.QualityError as error:
    ...     print(error.reason, [check.reason for check in error.checks])
    saturated ['saturated']
    """

    def __init__(self, failed: list[Check]):
        others = [r for r in dict.fromkeys(c.reason for c in failed[1:]) if r != failed[0].reason]
        extra = f" (also failed: {', '.join(others)})" if others else ""
        super().__init__(f"{failed[0].message}{extra}", reason=failed[0].reason)
        self.checks = tuple(failed)


#: the reasons a user may overrule with ``force=True``
FORCIBLE = frozenset({"fill", "saturated", "not-straight", "two-targets", "non-uniform", "too-short", "snr",
                      "mtf-above-one", "mtf-undefined", "varying-blur", "compression"})


class TwoTargetsError(QualityError, MultipleTargetsError):
    """A chip refused because it holds a second edge or bar.

    Parameters
    ----------
    failed : list of Check
        The failed checks, the first the one that found the second target.

    Examples
    --------
    >>> import numpy as np
    >>> import imgmtf
    >>> band = np.full((60, 60), 200.0)
    >>> band[:, 20:40] = 1200.0                      # a wide bar: two edges
    >>> try:
    ...     imgmtf.measure_edge(band)
    ... except imgmtf.TwoTargetsError as error:
    ...     print(error.reason, isinstance(error, imgmtf.MultipleTargetsError))
    two-targets True
    """


MOSTLY_FILL = 0.5               # a forced chip more than this much fill measures the fill's boundary


def untrusted_when_forced(checks) -> Check | None:
    """The check that makes a forced number unusable, or None: an MTF above
    1 beyond its noise (even within the gate's allowance) that no
    sharpening kernel explains, figures that
    cannot be read off (not an MTF), or fill that is most of the chip or
    comes with a second target (whose edge is then the fill's boundary).
    A caller reports such a number as a failure, printed with its reason."""
    failed = {c.reason: c for c in checks if c.failed}
    for check in checks:
        if (check.reason == "mtf-above-one" and check.value is not None and check.value > 0
                and check.explained_by is None):
            return Check("mtf-above-one", False, check.message, check.value, 0.0)
    if "mtf-undefined" in failed:
        return failed["mtf-undefined"]
    fill = failed.get("fill")
    if fill is not None and ((fill.share or 0.0) > MOSTLY_FILL or "two-targets" in failed):
        return fill
    return None


def enforce(checks: list[Check], force: bool) -> tuple[str, ...]:
    """Raise :class:`QualityError` for failed checks, unless ``force``:
    then return them as warnings."""
    failed = [c for c in checks if c.failed]
    if failed and not force:
        raise (TwoTargetsError if failed[0].reason == "two-targets" else QualityError)(failed)
    return tuple(f"{c.reason}: {c.message} (measured anyway: forced)" for c in failed)


# -- before the profile ---------------------------------------------------------
def fill_check(image: np.ndarray, dtype) -> Check:
    """Fill or nodata that no tag declared: a sizeable region at exactly one
    fill value whose boundary is hard (its neighbours differ from it by a
    large part of the contrast, where a blurred or clipped plateau meets
    values close to it).  Fill values: 0, an integer type's limits, and a
    negative minimum where the rest is not negative (-9999); all but 0
    must also lie well outside the rest's range (a sentinel, not a clipped
    target's level)."""
    used = np.isfinite(image)          # left-out pixels (NaN) are not part of the chip
    if not used.all():
        image = np.where(used, image, np.nan)
    values = image[used]
    for value in fill_values(values, dtype):
        mask = image == value
        count = int(mask.sum())
        if count < 8 or count < MIN_FILL_FRACTION * values.size or count == values.size:
            continue
        contrast = fill_contrast(value, image[~mask & used])
        if contrast <= 0:
            continue
        beside_fill = np.zeros_like(mask)
        beside_fill[1:, :] |= mask[:-1, :]
        beside_fill[:-1, :] |= mask[1:, :]
        beside_fill[:, 1:] |= mask[:, :-1]
        beside_fill[:, :-1] |= mask[:, 1:]
        if (mask & beside_fill).sum() < MIN_FILL_CLUSTERED * count:
            continue        # scattered pixels at that value (noise, texture): fill comes in regions
        border = beside_fill & ~mask & used
        if not border.any():
            continue
        jump = float(np.median(np.abs(image[border] - value))) / contrast
        if jump > FILL_BOUNDARY:
            return Check("fill", False, f"{100 * count / values.size:.1f} % of the chip is fill at "
                         f"{value:g} DN with a hard boundary (no nodata tag declares it): crop the "
                         "ROI away from it", jump, FILL_BOUNDARY, count / values.size)
    return Check("fill", True, "no fill in the chip")


def fill_values(values: np.ndarray, dtype) -> list[float]:
    """The values (DN, ascending) that undeclared fill may take among
    ``values``, a chip's finite pixels stored as ``dtype``: 0, an integer
    type's limits, and a negative minimum where the rest is not negative
    (-9999).

    Examples
    --------
    >>> fill_values(np.array([-9999.0, 5.0, 7.0]), "float32")
    [-9999.0, 0.0]
    """
    candidates = {0.0}
    if np.issubdtype(np.dtype(dtype), np.integer):
        info = np.iinfo(np.dtype(dtype))
        candidates |= {float(info.min), float(info.max)}
    low = float(values.min())
    if low < 0 <= np.median(values):
        candidates.add(low)
    return sorted(candidates)


def fill_contrast(value: float, rest: np.ndarray) -> float:
    """The contrast (DN) of ``rest``, the pixels beside a fill candidate
    ``value``; 0 where ``value`` cannot be fill: 0 always can, any other
    value only well outside the rest's range (a sentinel, not a clipped
    target's level)."""
    lo, hi = float(rest.min()), float(rest.max())
    contrast = hi - lo
    if value != 0 and lo - 0.5 * contrast <= value <= hi + 0.5 * contrast:
        return 0.0
    return contrast


def line_checks(geometry, expected_scatter_px: float, name: str) -> list[Check]:
    """Does the target run straight through the rows?  The kept fraction of
    rows, their robust scatter about the line beyond what their sub-pixel
    phase explains (against what the pixel noise explains), and the bow of
    a quadratic through them.  A batch of one of :func:`line_checks_many`."""
    return line_checks_many([(geometry, expected_scatter_px, name)])[0]


def line_checks_many(calls) -> list[list[Check]]:
    """:func:`line_checks` of many targets, their rows' biases with the
    sub-pixel phase fitted together (:func:`.phase.phase_bias_many`): each
    target's checks the same, to the bit, as alone.

    Parameters
    ----------
    calls : sequence of tuple
        Each target's arguments of :func:`line_checks` (its geometry, the
        scatter its noise explains, px, and its name).

    Returns
    -------
    list of list of Check
        Each target's checks, in order.
    """
    lines = [geometry.slope * geometry.rows[geometry.kept] + geometry.intercept for geometry, _, _ in calls]
    away = [geometry.locations[geometry.kept] - line for (geometry, _, _), line in zip(calls, lines)]
    biases = phase_bias_many([(resid, line, None) for resid, line in zip(away, lines)])
    return [_line_checks(geometry, expected, name, resid - bias)
            for (geometry, expected, name), resid, bias in zip(calls, away, biases)]


def _line_checks(geometry, expected_scatter_px: float, name: str, resid: np.ndarray) -> list[Check]:
    """:func:`line_checks` given the kept rows' residuals about the line
    less their bias with the sub-pixel phase (px)."""
    rows, loc, kept = geometry.rows, geometry.locations, geometry.kept
    fraction = kept.sum() / max(rows.size, 1)
    scatter = float(1.4826 * median(np.abs(resid))) if resid.size else math.inf
    limit = max(MAX_LINE_SCATTER_PX, 3.0 * expected_scatter_px)
    checks = [
        Check("not-straight", fraction >= MIN_ROWS_ON_LINE,
              f"only {100 * fraction:.0f} % of the rows hold the {name} on one line (at least "
              f"{100 * MIN_ROWS_ON_LINE:.0f} % needed): no straight {name}", fraction, MIN_ROWS_ON_LINE),
        Check("not-straight", scatter <= limit,
              f"the per-row {name} locations scatter {scatter:.2f} px about the line (at most "
              f"{limit:.2f} px expected from the noise): no straight {name}", scatter, limit),
    ]
    if kept.sum() >= 10:
        y, x = rows[kept].astype(float), loc[kept]
        t = (y - y.mean()) / max(np.ptp(y) / 2, 1.0)
        design = np.column_stack([np.ones_like(t), t, t * t - np.mean(t * t)])
        # ten or more distinct rows, centred and scaled to [-1, 1]: a regular, well-conditioned
        # normal matrix, inverted once for the fit and its covariance
        inverse = np.linalg.inv(design.T @ design)
        coef = inverse @ (design.T @ x)
        sigma = math.sqrt(max(np.sum((x - design @ coef) ** 2) / max(x.size - 3, 1), 1e-12))
        sagitta, sd = abs(coef[2]), math.sqrt(inverse[2, 2] * sigma ** 2)
        bowed = sagitta > MAX_SAGITTA_PX and sagitta > 4 * sd
        checks.append(Check("not-straight", not bowed,
                            f"the {name} bows by {sagitta:.2f} px over its length (at most "
                            f"{MAX_SAGITTA_PX} px): a curved {name}", sagitta, MAX_SAGITTA_PX))
    else:
        checks.append(not_run("not-straight", f"only {int(kept.sum())} rows on the line: too few (10) to see "
                              f"the {name} bow"))
    return checks


def rows_check(rows_used: int, name: str) -> Check:
    return Check("too-short", rows_used >= MIN_ROWS,
                 f"the {name} crosses {rows_used} usable rows (at least {MIN_ROWS} needed)",
                 rows_used, MIN_ROWS)


# -- on the profile -------------------------------------------------------------
def classify_profile(values: np.ndarray) -> str:
    """``STEP_PROFILE`` or ``BAR_PROFILE``: a step keeps most of its largest
    excursion between its two ends; a bar returns to where it started.
    ``values`` is the resampled profile across the target."""
    n_side = max(values.size // 8, 2)
    left, right = values[:n_side].mean(), values[-n_side:].mean()
    excursion = np.max(np.abs(values - left))
    return STEP_PROFILE if excursion > 0 and abs(right - left) >= EDGE_STEP_RATIO * excursion else BAR_PROFILE


def mixed_profile(values: np.ndarray) -> bool:
    """Does the profile hold both a step and a bar (an edge with a road or a
    shadow beside it)?  Its ends differ by at least ``MIXED_SHARE`` of its
    range, and it also reaches that far beyond both ends, or turns back
    that far between them."""
    n_side = max(values.size // 8, 2)
    left, right = values[:n_side].mean(), values[-n_side:].mean()
    span = float(values.max() - values.min())
    if span <= 0:
        return False
    beyond = max(values.max() - max(left, right), min(left, right) - values.min())
    # or turns back between them (a bar between the edge's levels)
    rising = values if right >= left else -values
    turned = float(np.max(np.maximum.accumulate(rising) - rising))
    return abs(right - left) >= MIXED_SHARE * span and max(beyond, turned) >= MIXED_SHARE * span


def kind_check(kind: str, wanted: str, values: np.ndarray | None = None, grid: np.ndarray | None = None,
               noise_dn: float = 0.0) -> Check:
    """Is the profile's shape ``kind`` (:func:`classify_profile`) the one the
    target asked for wants?  Where it is not and it holds a step and a bar
    at once (``values`` given), the reason is the second feature beside the
    target, not the kind; where a step was wanted and the bar is two
    (``grid``, px, given: :func:`.bar_pair.pair_in_profile`, the pulse
    kind's own test), the reason is the pair (``double-bar``), so that one
    refusal names what measures it."""
    reason, message = WRONG_PROFILE[wanted]
    if kind == wanted:
        return Check(reason, True, f"the profile is a {kind}")
    if values is not None and mixed_profile(values):
        return Check("two-targets", False, f"the profile holds a step and a bar: a second feature (a road, a "
                     f"shadow, another {kind}) lies beside the target")      # of two shapes, the other
    if wanted == STEP_PROFILE and values is not None and grid is not None:
        pair = pair_in_profile(grid, values, noise_dn)
        if pair is not None:
            return Check(PAIR_REASON, False, pair.message("an edge"))
    return Check(reason, False, message)


#: a share of the contrast below this is the arithmetic's rounding (a noise-free side's trend, band
#: mean or departure): taken as none, so that what a message says of it (its sign, where it peaks,
#: which of two is larger) cannot move with a change of the arithmetic before it
ROUNDING_SHARE = 1e-12


def beyond_rounding(share: float) -> float:
    """``share`` (of the contrast), or 0.0 where it is within the
    arithmetic's rounding (``ROUNDING_SHARE``).

    Examples
    --------
    >>> beyond_rounding(3e-17), beyond_rounding(-3e-17), beyond_rounding(0.02)
    (0.0, 0.0, 0.02)
    """
    return float(share) if abs(share) > ROUNDING_SHARE else 0.0


def snr_checks(snr: float, threshold: float, rows: int, name: str) -> tuple[list[Check], list[str]]:
    """Refuse an SNR that cannot be measured or is below ``MIN_SNR``; warn
    below ``threshold``, the lowest at which the estimate is confident."""
    if not math.isfinite(snr) and not snr > 0:
        return [Check("snr", False, f"the {name}'s SNR cannot be measured (its sides hold too few samples)")], []
    checks = [Check("snr", snr >= MIN_SNR, f"SNR {snr:.1f} is below {MIN_SNR:g}: the MTF would be noise",
                    snr, MIN_SNR)]
    warnings = []
    if snr < threshold:
        warnings.append(f"SNR {snr:.0f} is below {threshold:.0f}, the lowest at which 95 % of estimates "
                        f"from a {rows}-row {name} fall within 5 % of the truth")
    return checks, warnings


def mtf_excess_check(mtf, noise_sd, limit_cy_px: float) -> Check:
    """The MTF of an imaging system does not exceed 1; sharpening or a
    wrong profile does.  Checked up to the noise limit (and 1 cy/px)."""
    f = np.arange(0.01, min(limit_cy_px, 1.0) + 1e-9, 0.01)
    if f.size == 0:
        return not_run("mtf-above-one", f"the MTF falls into its noise below 0.01 cy/px ({limit_cy_px:.3f}): "
                       "nothing to compare with 1")
    excess = mtf(f) - 1.0 - 3.0 * noise_sd(f)
    if not np.isfinite(excess).any():
        return not_run("mtf-above-one", "the MTF or its noise is not finite at any frequency up to its noise "
                       "limit: nothing to compare with 1")
    worst = int(np.nanargmax(excess))
    over = float(excess[worst])
    return Check("mtf-above-one", over <= MAX_MTF_EXCESS,
                 f"the MTF reaches {float(mtf(f[worst:worst + 1])[0]):.2f} at {f[worst]:.2f} cy/px, above 1 "
                 "beyond its noise: a sharpened image or not a clean target", over, MAX_MTF_EXCESS)


def figures_check(mtf_nyquist: float, mtf50: float, fwhm_px: float, nyquist_masked: bool = False,
                  mtf50_masked: bool = False) -> Check:
    """The figures a report quotes must exist: an MTF that never falls to
    0.5 below 2 cy/px, or an LSF without a half maximum, is not an imaging
    system's.  ``nyquist_masked``, ``mtf50_masked``: a bar's sinc hides
    that figure (said in the warnings), so its NaN is expected."""
    figures = ([("FWHM", fwhm_px)] + ([] if mtf50_masked else [("MTF50", mtf50)])
               + ([] if nyquist_masked else [("MTF at Nyquist", mtf_nyquist)]))
    missing = [name for name, value in figures if not (math.isfinite(value) and value >= 0)]
    return Check("mtf-undefined", not missing,
                 f"{', '.join(missing) or 'no figure'} cannot be read off this profile (the MTF never "
                 "falls to 0.5 below 2 cy/px, or the LSF has no half maximum): not a clean target")

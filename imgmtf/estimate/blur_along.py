"""Is the blur the same all along the target?  An edge whose blur changes
along its length (a tilted focal plane, a field-dependent lens, a scene
whose top is out of focus) gives the MTF of no single place: the estimate
mixes the parts' profiles, and reads between their MTFs with no sign of it
(half the rows at Gaussian sigma 0.5 px, half at 0.9: 0.09 below the
sharper half's truth at Nyquist).

The profile's width is read in groups of rows along the target (the two
halves and the three thirds), each from its own samples by a fit of its own:

- an edge: the scale of a Fermi step fitted with its own levels and
  centre;
- a bar: the scale of a Gaussian fitted likewise.

Groups whose widths disagree beyond their noise and beyond
``MAX_WIDTH_CHANGE`` refuse the chip (reason ``varying-blur``); smaller
significant changes are said.
"""
from __future__ import annotations

import math

import numpy as np

from ._order import distinct
from .evidence import Evidence
from .gate import Check, not_run

MIN_REACH_PX = 3.0              # the fit sees at least this far either side of the centre
MIN_GROUP_SAMPLES = 40
MIN_SCALE_PX = 0.02
MIN_GROUP_ROWS = 8
MAX_WIDTH_CHANGE = 0.08        # relative: the parts' MTFs at Nyquist then differ by about 0.03
WARN_WIDTH_CHANGE = 0.03
SIGNIFICANCE = 5.0
WARN_SIGNIFICANCE = 4.0


def uniform_blur(ev: Evidence) -> tuple[list[Check], list[str]]:
    """The largest relative change of the profile's width between the
    halves or the thirds of the target's rows, against its noise.

    Returns the ``varying-blur`` check and a warning for a small but
    significant change.
    """
    rows = distinct(ev.rows)
    if rows.size < 2 * MIN_GROUP_ROWS:
        return [not_run("varying-blur", f"the {ev.name} crosses {rows.size} rows (at least "
                        f"{2 * MIN_GROUP_ROWS} needed to compare its halves)")], []
    splits = _splits(rows)
    # the five groups' fits run together (one fit's iterations on small
    # arrays cost mostly the interpreter's time), or with other chips' (group_widths_many)
    widths = iter(ev.blur_widths if ev.blur_widths is not None else _group_widths(ev, _group_masks(ev, splits)))
    worst = None
    for bounds in splits:
        parts = len(bounds)
        group = [next(widths) for _ in range(parts)]
        if any(w is None for w in group):
            continue
        for i in range(parts):
            for j in range(i + 1, parts):
                (wi, vi), (wj, vj) = group[i], group[j]
                change = abs(wi - wj) / (0.5 * (wi + wj))
                z = abs(wi - wj) / math.sqrt(vi + vj) if vi + vj > 0 else math.inf
                if worst is None or (z >= WARN_SIGNIFICANCE, change) > (worst[1] >= WARN_SIGNIFICANCE, worst[0]):
                    worst = (change, z, (bounds[i], wi), (bounds[j], wj))
    if worst is None:
        return [not_run("varying-blur", f"the {ev.name}'s width could not be fitted in its halves or thirds "
                        f"(fewer than {MIN_GROUP_SAMPLES} samples within {max(ev.plateau_px, MIN_REACH_PX):.1f} px "
                        "of its centre, or a fit that did not converge)")], []
    change, z, (rows_a, width_a), (rows_b, width_b) = worst
    where = (f"{width_a:.3f} px over rows {rows_a[0]}-{rows_a[-1]} and {width_b:.3f} px over rows "
             f"{rows_b[0]}-{rows_b[-1]}")
    failed = z > SIGNIFICANCE and change > MAX_WIDTH_CHANGE
    check = Check("varying-blur", not failed,
                  f"the {ev.name}'s blur changes along it: its width is {where} ({100 * change:.0f} % apart, at "
                  f"most {100 * MAX_WIDTH_CHANGE:g} %): no single MTF describes it; measure its parts apart",
                  change, MAX_WIDTH_CHANGE)
    said = []
    if not failed and z > WARN_SIGNIFICANCE and change > WARN_WIDTH_CHANGE:
        said.append(f"the {ev.name}'s blur changes a little along it: its width is {where} "
                        f"({100 * change:.0f} % apart): the MTF is their mixture")
    return [check], said


def group_widths_many(evidence: list[Evidence]) -> list[list | None]:
    """What :func:`uniform_blur` fits in each chip's halves and thirds
    (:attr:`.evidence.Evidence.blur_widths`; None for a chip of too few
    rows), the groups of chips whose samples are as many fitted together:
    each width the same, to the bit, as its chip's own fit gives.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.evidence import evidence_of
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60, noise_std_dn=2.0, seed=1)
    >>> m = run(EdgeKind(), chip.image, make_settings())
    >>> ev = evidence_of(EdgeKind(), m.chip, m.located, m.estimate.samples, m.shape, m.noise)
    >>> len(group_widths_many([ev])[0])         # two halves and three thirds
    5
    """
    out: list[list | None] = [None] * len(evidence)
    inputs = {}
    for k, ev in enumerate(evidence):
        rows = distinct(ev.rows)
        if rows.size >= 2 * MIN_GROUP_ROWS:
            groups = _group_masks(ev, _splits(rows))
            inputs[k] = (len(groups), _group_inputs(ev, groups))
    buckets: dict[tuple[int, bool], list[int]] = {}
    for k, (count, fitted) in inputs.items():
        if fitted is None:
            out[k] = [None] * count
        else:       # stacked only with chips whose groups are padded alike: each fit's sums as alone
            buckets.setdefault((fitted[1].shape[1], fitted[5]), []).append(k)
    for (_, bar), members in buckets.items():
        stacked = [inputs[k][1] for k in members]
        fits = iter(_fit(_bar if bar else _step, *(np.concatenate([f[i] for f in stacked]) for i in (1, 2, 3, 4))))
        for k, f in zip(members, stacked):
            out[k] = _widths(inputs[k][0], f[0], [next(fits) for _ in f[0]])
    return out


def _splits(rows: np.ndarray) -> list[list[np.ndarray]]:
    """The target's rows in halves and, with enough, in thirds."""
    return [np.array_split(rows, parts) for parts in (2, 3) if rows.size >= parts * MIN_GROUP_ROWS]


def _group_masks(ev: Evidence, splits: list[list[np.ndarray]]) -> list[np.ndarray]:
    """Which samples lie in each group of rows."""
    return [(ev.rows >= b[0]) & (ev.rows <= b[-1]) for bounds in splits for b in bounds]


def _group_widths(ev: Evidence, groups: list[np.ndarray]) -> list[tuple[float, float] | None]:
    """The width (px) of each group's profile within the plateau of the
    centre, with its variance: the scale c of a Fermi step (an edge) or of
    a Gaussian (a bar) fitted with its own levels and centre, so that
    neither shading nor a slight bend along the target passes for a change
    of blur.  The model need not be the blur's: it is the same for every
    group.  None where the fit fails."""
    fitted = _group_inputs(ev, groups)
    if fitted is None:
        return [None] * len(groups)
    selected, s, v, w, start, bar = fitted
    return _widths(len(groups), selected, _fit(_bar if bar else _step, s, v, w, start))


def _group_inputs(ev: Evidence, groups: list[np.ndarray]):
    """What :func:`_fit` fits for the groups with enough samples: their
    indices, samples (s, v, w: padded to the longest with zero weights),
    each one's start and whether the model is a bar's; None for none."""
    reach = max(ev.plateau_px, MIN_REACH_PX)
    offsets = ev.distance_px - ev.centre_px
    near = np.abs(offsets) <= reach        # (each sample's offset the same whichever group reads it)
    selected = []
    for g, in_group in enumerate(groups):
        take = in_group & near
        if np.count_nonzero(take) >= MIN_GROUP_SAMPLES:
            selected.append((g, offsets[take], ev.values[take]))
    if not selected:
        return None
    # the groups side by side, padded to the longest with zero weights
    longest = max(s.size for _, s, _ in selected)
    s, v, w = (np.zeros((len(selected), longest)) for _ in range(3))
    for k, (_, sk, vk) in enumerate(selected):
        s[k, : sk.size], v[k, : sk.size], w[k, : sk.size] = sk, vk, 1.0
    bar = ev.profile == "bar"
    start = np.array([ev.high - ev.low, 0.0, max(ev.scale_px, 0.2) * (0.5 if bar else 0.25), ev.low])
    return [g for g, _, _ in selected], s, v, w, np.tile(start.astype(float), (len(selected), 1)), bar


def _widths(groups: int, selected: list[int], fits: list) -> list[tuple[float, float] | None]:
    """Each group's width and its variance from the fits of those selected."""
    widths: list[tuple[float, float] | None] = [None] * groups
    for g, fitted in zip(selected, fits):
        # a step with no blur leaves no fit to compare (fill, a clip)
        if fitted is not None and abs(fitted[0][2]) >= MIN_SCALE_PX:
            widths[g] = abs(float(fitted[0][2])), fitted[1]
    return widths


def _step(s, p):
    """A Fermi step and its Jacobian in (amplitude, centre, scale, base);
    ``s`` (groups, samples), ``p`` (groups, 4)."""
    a, b, c, d = (p[:, k, None] for k in range(4))
    u = (s - b) / c
    np.maximum(u, -50.0, out=u)
    np.minimum(u, 50.0, out=u)
    jac = np.empty((*s.shape, 4))
    # f = 1 / (1 + exp(-u)), made in the Jacobian's first column (the same operations, fewer arrays)
    f = jac[..., 0]
    np.negative(u, out=f)
    np.exp(f, out=f)
    f += 1.0
    np.divide(1.0, f, out=f)
    slope = f * (1.0 - f)
    slope *= -a                     # -a f (1 - f), as -a * slope
    np.divide(slope, c, out=jac[..., 1])
    slope *= u
    np.divide(slope, c, out=jac[..., 2])
    jac[..., 3] = 1.0
    return d + a * f, jac


def _bar(s, p):
    """A Gaussian pulse and its Jacobian in (amplitude, centre, scale, base);
    ``s`` (groups, samples), ``p`` (groups, 4)."""
    a, b, c, d = (p[:, k, None] for k in range(4))
    u = (s - b) / c
    g = np.exp(-0.5 * u * u)
    return d + a * g, np.stack([g, a * g * u / c, a * g * u * u / c, np.ones_like(g)], axis=-1)


def _solve_each(matrices: np.ndarray, vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``solve(matrices[k], vectors[k])`` for every k, and which were
    regular (a singular one's solution is left NaN)."""
    try:
        return np.linalg.solve(matrices, vectors[..., None])[..., 0], np.ones(len(matrices), bool)
    except np.linalg.LinAlgError:
        out, ok = np.full(vectors.shape, np.nan), np.ones(len(matrices), bool)
        for k, (m, b) in enumerate(zip(matrices, vectors)):
            try:
                out[k] = np.linalg.solve(m, b)
            except np.linalg.LinAlgError:
                ok[k] = False
        return out, ok


def _fit(model, s, v, w, start, iterations=60) -> list[tuple[np.ndarray, float] | None]:
    """Levenberg-Marquardt least squares of ``model`` to each group's
    (s, v) (rows of equal length, weights ``w`` 1 for a sample and 0 for
    padding) from its row of ``start``, each group with its own damping and its own
    stop: per group the parameters and the variance of the third (the
    scale), scaled by the residual variance.  None where it does not
    converge to finite numbers."""
    groups = s.shape[0]
    p = np.array(start, float)
    fit, jac = model(s, p)
    resid = v - fit
    cost = np.einsum("gn,gn->g", w * resid, resid)
    damping = np.full(groups, 1e-3)
    active = np.ones(groups, bool)
    failed = np.zeros(groups, bool)
    identity = np.eye(4)
    for _ in range(iterations):
        if not active.any():
            break
        # every group is computed, a stopped one left as it is (the groups
        # are few: fewer, larger operations cost less than selecting them)
        weighted = np.swapaxes(jac * w[..., None], 1, 2)
        normal = weighted @ jac
        gradient = (weighted @ resid[..., None])[..., 0]
        diagonal = np.maximum(np.einsum("gii->gi", normal), 1e-12)
        damped = np.where(active[:, None, None], normal + damping[:, None, None] * (diagonal[:, :, None] * identity),
                          identity)
        step, regular = _solve_each(damped, gradient)
        failed |= active & ~regular
        active &= regular
        trial = p + step
        # a zero scale is no model: a longer step's turn
        zero = active & (trial[:, 2] == 0)
        damping[zero] *= 4.0
        tried = active & ~zero
        trial_fit, trial_jac = model(s, np.where(tried[:, None], trial, p))
        trial_resid = v - trial_fit
        trial_cost = np.einsum("gn,gn->g", w * trial_resid, trial_resid)
        better = tried & np.isfinite(trial_cost) & (trial_cost < cost)
        if better.all():        # the selections below, made whole (the common first steps)
            p, resid, jac, cost = trial, trial_resid, trial_jac, trial_cost
        elif better.any():
            p = np.where(better[:, None], trial, p)
            resid = np.where(better[:, None], trial_resid, resid)
            jac = np.where(better[:, None, None], trial_jac, jac)
            cost = np.where(better, trial_cost, cost)
        lost = tried & ~better
        damping = np.where(better, damping / 3.0, np.where(lost, damping * 4.0, damping))
        converged = np.abs(step[:, 2]) < 1e-7 * np.maximum(np.abs(trial[:, 2]), 1e-9)
        active &= ~(better & converged) & ~(lost & (damping > 1e10))
    # the normal equations at the solution (as each step makes them) give the scale's variance
    weighted = np.swapaxes(jac * w[..., None], 1, 2)
    covariance, regular = _solve_each(weighted @ jac, np.tile(np.eye(4)[2], (groups, 1)))
    variance = covariance[:, 2] * cost / np.maximum(w.sum(axis=1) - 4, 1)
    return [(p[k], max(float(variance[k]), 0.0)) if regular[k] and not failed[k] and np.isfinite(p[k]).all()
            and math.isfinite(variance[k]) else None for k in range(groups)]

"""Which assumption the measured sections support: with two orientations,
whether an elliptical model lays them onto one curve (a separable one fits
any two); with more, each assumption's prediction of the orientations it
was not fitted to, against their measurement."""
from __future__ import annotations

import math
import warnings

import numpy as np

from .curves import transfers
from .inversion import (
    MIN_MTF,
    MIN_SEPARATION_DEG,
    REACH_CY_PX,
    SD_FLOOR,
    EllipticalModel,
    EllipticalProblem,
    drawn_models,
    fitted_model,
    stacked_inputs,
)

SEPARABLE, ELLIPTICAL, BRACKET = "separable", "elliptical", "bracket"
ASSUMPTIONS = (SEPARABLE, ELLIPTICAL)
TEST_ALPHA = 0.05           # a prediction whose p-value falls below is rejected
TEST_DRAWS = 30             # draws for a prediction's own spread


def base_pair(normals: np.ndarray) -> tuple[int, int]:
    """The two normals to invert from: at least ``MIN_SEPARATION_DEG``
    apart, nearest the axes, then farthest apart."""
    best, key = (0, 1), (math.inf, math.inf)
    for i in range(normals.size):
        for j in range(i + 1, normals.size):
            apart = abs((normals[i] - normals[j] + 90.0) % 180.0 - 90.0)
            if apart < MIN_SEPARATION_DEG:
                continue
            off_axis = sum(min(n % 90.0, 90.0 - n % 90.0) for n in (normals[i], normals[j]))
            if (off_axis, -apart) < key:
                best, key = (i, j), (off_axis, -apart)
    return best


def prediction_tests(inputs, base, others, draws: int, seed: int) -> dict[str, float]:
    """Each assumption's p-value for the orientations ``others``: its
    prediction from the ``base`` pair against their measurement, at the
    frequency where the two assumptions' predictions differ most."""
    normals, f, m, sd = inputs
    pair = list(base)
    rng = np.random.default_rng(seed + 1)
    shifts = rng.standard_normal((TEST_DRAWS, 2))
    chi2 = dict.fromkeys(ASSUMPTIONS, 0.0)
    for k in others:
        theta = math.radians(normals[k])
        u, v = f * abs(math.cos(theta)), f * abs(math.sin(theta))
        predictions, spreads = {}, {}
        for a in ASSUMPTIONS:
            central = fitted_model(a, normals[pair], f, m[pair], sd[pair])
            predictions[a] = central.transfer(u, v)
            drawn = transfers(drawn_models(a, central, normals[pair], f, m[pair], sd[pair], shifts), u, v) \
                if sd.any() else None
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)       # all-NaN beyond the reach
                spreads[a] = np.zeros_like(f) if drawn is None else np.nanstd(drawn, axis=0)
        total = {a: np.sqrt(spreads[a] ** 2 + sd[k] ** 2 + SD_FLOOR ** 2) for a in ASSUMPTIONS}
        gap = np.abs(predictions[SEPARABLE] - predictions[ELLIPTICAL]) / np.maximum(total[SEPARABLE],
                                                                                    total[ELLIPTICAL])
        usable = np.isfinite(gap) & (f > 0) & (m[k] >= MIN_MTF) & (f <= REACH_CY_PX)
        if not usable.any():
            continue
        at = int(np.flatnonzero(usable)[np.argmax(gap[usable])])
        for a in ASSUMPTIONS:
            chi2[a] += float(((predictions[a][at] - m[k, at]) / total[a][at]) ** 2)
    return {a: chi2_survival(chi2[a], len(others)) for a in ASSUMPTIONS}


def chi2_survival(x: float, dof: int) -> float:
    """P(X >= x) for X chi-square with ``dof`` (integer) degrees of freedom,
    in closed form (no SciPy on the scan's path).

    Examples
    --------
    >>> round(chi2_survival(3.841, 1), 3), round(chi2_survival(5.991, 2), 3), round(chi2_survival(7.815, 3), 3)
    (0.05, 0.05, 0.05)
    """
    half = x / 2.0
    if dof % 2 == 0:
        return math.exp(-half) * sum(half ** i / math.factorial(i) for i in range(dof // 2))
    tail = math.erfc(math.sqrt(half))
    return tail + math.exp(-half) * sum(half ** (i + 0.5) / math.gamma(i + 1.5) for i in range((dof - 1) // 2))


def decision(tests: dict[str, float], others) -> tuple[str, str]:
    where = "/".join(f"{n:.0f}" for n in others) + " deg"
    fits = [a for a in ASSUMPTIONS if tests[a] >= TEST_ALPHA]
    p = ", ".join(f"{a} p={tests[a]:.2g}" for a in ASSUMPTIONS)
    if len(fits) == 2:
        return BRACKET, f"the {where} section agrees with both ({p})"
    if len(fits) == 1:
        return fits[0], f"the {where} section rejects the other ({p})"
    closer = max(ASSUMPTIONS, key=lambda a: tests[a])
    return closer, f"the {where} section rejects both; {closer} is closer ({p})"


def pair_decision(elliptical_p: float) -> tuple[str, str]:
    """Two orientations: a separable model fits any two sections, an
    elliptical one only sections whose remainders are one curve stretched."""
    if elliptical_p < TEST_ALPHA:
        return SEPARABLE, (f"the two sections are not one curve stretched (elliptical p={elliptical_p:.2g}); "
                           "separable fits any two")
    return BRACKET, f"two orientations cannot tell separable from elliptical (elliptical p={elliptical_p:.2g})"


def overlay_tests(inputs, model: EllipticalModel, seed: int, draws: int = 100) -> np.ndarray:
    """Each target's p-value of its elliptical model's fit to its sections:
    how often sections drawn from the fitted model (within their
    uncertainty and ``SD_FLOOR``, as whole-curve shifts) lay onto one
    curve worse than the measured ones do.  ``inputs``: many targets'
    (normals (T, n), frequencies (T, F), MTFs and standard deviations
    (T, n, F)), ``model`` their models stacked: (T,)."""
    normals, f, m, sd = inputs
    problem = EllipticalProblem(*stacked_inputs(normals, f, m, sd))
    log_aspect = np.array([math.log(a) for a in np.asarray(model.aspect).tolist()])
    observed = problem.costs(log_aspect[:, None], problem.log_r)[:, 0]
    theta = np.radians(normals)[..., None]
    u, v = f[:, None] * np.abs(np.cos(theta)), f[:, None] * np.abs(np.sin(theta))
    predicted = transfers(model, u.reshape(len(u), -1), v.reshape(len(v), -1)).reshape(m.shape)
    predicted = np.where(np.isfinite(predicted), predicted, m)
    spread = np.hypot(sd, SD_FLOOR * f[:, None] / 0.5)
    shifts = np.random.default_rng(seed + 2).standard_normal((draws, normals.shape[1]))
    null = EllipticalProblem(*stacked_inputs(normals, f, predicted, sd))
    targets = null.remainders(predicted[:, None] + shifts[None, :, :, None] * spread[:, None])
    costs = np.min(null.costs(log_aspect[:, None] + np.linspace(-0.3, 0.3, 13), targets), axis=1)
    return np.mean(costs >= observed[:, None], axis=1)

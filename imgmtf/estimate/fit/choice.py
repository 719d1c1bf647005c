"""The sensor model chosen by the data: candidate stage sets fitted in
turn, simplest first, the simplest that fits kept (``stages="auto"``).

Real L0R edges are not Gaussian: a tent-shaped core with exponential
wings, a broad foot and a lean to one side.  The paper's stages (optics,
detector) fit a synthetic chip exactly and misfit every real satellite
target we hold; the stages real blur needs (``diffusion``, ``halo``,
``lag``) fit those but, freed on an edge that does not need them, cost
time and precision.  So the data choose: each candidate of
:data:`AUTO_CANDIDATES` is fitted to the same edges (their data made
once), and the first the misfit test passes is kept; when none passes,
the one with the lowest Bayesian information criterion (the samples'
chi-square + free parameters x ln(samples)) is kept and reported as a
misfit.  The candidates tried, their criterion and verdicts travel with
the fit (:class:`ModelChoice`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

#: what ``stages`` says for the model chosen by the data
AUTO = "auto"
#: the stage sets ``auto`` tries, simplest first: the Gaussian core and the
#: pixel, then the exponential wings, the one-sided lag and the scatter halo
#: that real L0R blur adds (each a superset of the one before but the lag's
#: and the halo's, tried alone before together)
AUTO_CANDIDATES: tuple[tuple[str, ...], ...] = (
    ("optics", "detector"),
    ("optics", "detector", "diffusion"),
    ("optics", "detector", "diffusion", "lag"),
    ("optics", "detector", "diffusion", "halo"),
    ("optics", "detector", "diffusion", "halo", "lag"),
)


@dataclass(frozen=True)
class CandidateFit:
    """One candidate stage set fitted: its chi-square over the samples,
    free stage parameters, Bayesian information criterion and verdict.

    Attributes
    ----------
    stages : tuple of str
        The candidate's stages.
    chi_square : float
        The samples' chi-square at its optimum.
    free_parameters : int
        Its stages' parameters left free (the edges' levels and offsets,
        the same for every candidate, not counted).
    samples : int
        The profile samples fitted.
    bic : float
        chi_square + free_parameters x ln(samples): lower is better.
    misfit : bool
        Whether the misfit test (:attr:`SensorFit.misfit`) fails it.
    """

    stages: tuple[str, ...]
    chi_square: float
    free_parameters: int
    samples: int
    bic: float
    misfit: bool

    def to_dict(self) -> dict:
        return {"stages": list(self.stages), "chi_square": self.chi_square,
                "free_parameters": self.free_parameters, "samples": self.samples, "bic": self.bic,
                "misfit": self.misfit}


@dataclass(frozen=True)
class ModelChoice:
    """The candidates ``auto`` fitted, in order, and the one it kept.

    Attributes
    ----------
    candidates : tuple of CandidateFit
        Those fitted (it stops at the first that fits).
    kept : tuple of str
        The kept candidate's stages.
    reason : str
        Why, in a phrase ("the simplest that fits, 2 of 5 tried").
    failed : tuple of (tuple of str, str)
        Candidates whose fit did not converge, with why (the next one was
        tried).
    """

    candidates: tuple[CandidateFit, ...]
    kept: tuple[str, ...]
    reason: str
    failed: tuple[tuple[tuple[str, ...], str], ...] = ()

    def to_dict(self) -> dict:
        return {"kept": list(self.kept), "reason": self.reason,
                "candidates": [c.to_dict() for c in self.candidates],
                "failed": [{"stages": list(c), "error": message} for c, message in self.failed]}


def candidate_summary(fit) -> CandidateFit:
    """:class:`CandidateFit` of a :class:`SensorFit`."""
    model = fit._model
    samples = sum(d.x.size for d in model.data)
    chi_square = float(fit.reduced_chi_square) * max(model.dof, 1)
    return CandidateFit(tuple(s.name for s in fit.sensor.stages), chi_square, model.n_free, samples,
                        chi_square + model.n_free * math.log(max(samples, 2)), bool(fit.misfit))


def choose(fits, tried: int | None = None) -> tuple[int, str]:
    """Index of the fit to keep among candidates fitted in order (``tried``
    of :data:`AUTO_CANDIDATES` tried, those that failed included), and why:
    the first that fits, else the lowest information criterion."""
    summaries = [candidate_summary(f) for f in fits]
    tried = len(fits) if tried is None else tried
    for index, summary in enumerate(summaries):
        if not summary.misfit:
            return index, f"the simplest that fits ({tried} of {len(AUTO_CANDIDATES)} tried)"
    best = min(range(len(summaries)), key=lambda i: summaries[i].bic)
    return best, (f"none of the {tried} candidates fits: the lowest information criterion "
                  f"(BIC {summaries[best].bic:.0f})")


def other_stages(stages) -> str:
    """What to try when the model misfits: the long-tailed stages it lacks,
    or, with all of them in, the non-parametric estimate."""
    have = {s.name for s in stages}
    real = [name for name in ("diffusion", "halo", "lag") if name not in have]
    optical = [name for name in ("diffraction", "defocus", "olpf") if name not in have]
    if real:
        return (f"try the stages real blur adds ({', '.join(real)}; stages 'auto' tries them)"
                + (f" or others (e.g. {', '.join(optical)})" if optical else ""))
    if optical:
        return f"try other stages (e.g. {', '.join(optical)}), or quote the rows measured without a model"
    return "quote the rows measured without a model, which assume no form of blur"

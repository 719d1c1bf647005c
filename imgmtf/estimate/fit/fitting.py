"""The driver: the model fitted, and its stages freed or held by the
likelihood ratio."""
from __future__ import annotations

from ...errors import ImgmtfError
from .model import Model, hold_keys, parameter_covariance
from .report import fit_report
from .results import SensorFit

#: a parameter stays free only if holding it costs this much chi-square
#: (in units of the reduced chi-square): p = 0.001 for one degree of freedom
LIKELIHOOD_RATIO = 10.8


def run_fit(model: Model, hold, confidence: float) -> SensorFit:
    """Fit ``model``, holding what the data do not determine or need (see
    the module's notes), and report."""
    notes = model.screen_axes(hold_keys(hold, model.keys))
    z = model.initial_vector()
    while True:
        z, jacobian = model.solve(z)
        scale = max(model.chi_square(z) / max(model.dof, 1), 1.0)
        covariance = parameter_covariance(jacobian, scale)
        undetermined = model.undetermined(z, covariance)
        if not undetermined:
            break
        worst = max(undetermined, key=lambda i: (model.specs[model.free[i]].rank, undetermined[i]))
        notes[model.free[worst]] = ("held", f"not determined by the data (within one standard error its blur "
                                            f"length spans {undetermined[worst]:.2g} px); "
                                            "held at its starting value")
        z = model.hold(z, worst, covariance)
    # hold, best-known first, each parameter the data do not need (holding it
    # at its starting value costs less than the likelihood-ratio threshold),
    # but keep one free parameter on each axis an edge sees
    for key in sorted(model.free, key=lambda k: -model.specs[k].rank):
        if not model.covers_axes([k for k in model.free if k != key]):
            continue            # the last free parameter of an axis: its uncertainty belongs in the intervals
        index = model.free.index(key)
        trial = model.copy()
        z_held = trial.hold(z, index, covariance)
        try:
            z_held, jacobian_held = trial.solve(z_held)
        except ImgmtfError:
            continue
        cost = (trial.chi_square(z_held) - model.chi_square(z)) / scale
        if cost < LIKELIHOOD_RATIO:
            notes[key] = ("held", f"the data do not need it (freeing it gains chi-square {max(cost, 0):.1f} "
                                  f"< {LIKELIHOOD_RATIO:g}); held at its starting value")
            model, z = trial, z_held
            scale = max(model.chi_square(z) / max(model.dof, 1), 1.0)
            covariance = parameter_covariance(jacobian_held, scale)
    return fit_report(model, z, covariance, notes, confidence)

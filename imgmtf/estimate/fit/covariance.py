"""The fitted parameters' covariance from the weighted Jacobian of the
residuals."""
from __future__ import annotations

import numpy as np


def parameter_covariance(jacobian, reduced_chi_square: float) -> np.ndarray:
    """Parameter covariance from the weighted (sparse) Jacobian, scaled up by
    the reduced chi-square when the residuals exceed the noise (never down:
    on noise-free integer chips the noise is the quantisation's, 1/sqrt(12)
    DN, which flat plateaus do not show)."""
    normal = jacobian.T @ jacobian
    return np.linalg.pinv(normal.toarray() if hasattr(normal, "toarray") else normal) * max(reduced_chi_square, 1.0)

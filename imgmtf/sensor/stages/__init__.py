"""Stages of the imaging chain, each an object with its analytic transfer function.

A stage is a frozen dataclass whose fields are its physical parameters.
Every stage gives

* ``transfer(fx, fy, gsd_m)``: its 2-D transfer function at spatial
  frequencies in cycles per metre on the ground (``fx`` across track, image
  columns; ``fy`` along track, image rows), 1 at zero frequency.  ``gsd_m``
  is the sensor's ground sample distance, which maps focal-plane lengths
  (the diffraction stage's pixel pitch) to the ground; stages given in ground
  metres ignore it.
* ``support_radius_m(gsd_m)``: a radius (m) outside which its PSF is
  negligible on a sampled 2-D grid (all but about 1e-9 of the energy; for
  diffraction, whose energy outside a radius falls only as 1/r, the core
  that holds 99 %: see :meth:`Diffraction.support_radius_m`).
* ``tail_length_m(gsd_m)``: the length ``b`` of the Cauchy tail of its LSF
  (transfer ~ 1 - 2 pi b |f| near zero), which the line responses of
  :mod:`.model` add in closed form so that long tails cost no grid; 0 for
  stages whose tails fall faster than any power.
* ``to_dict()`` / :func:`stage_from_dict`: the TOML form, ``{"stage": name,
  parameter: value, ...}``.

Every PSF here is non-negative.  Most are symmetric about both axes, so
their transfer functions are real and even in ``fx`` and in ``fy``; the
one-sided :class:`Lag` is not: its transfer is complex (Hermitian,
T(-f) = conj T(f)), the sensor gains a phase transfer function and an
asymmetric PSF, and its MTF is the transfer's modulus.  The stages real
L0R blur needs beside the paper's: :class:`Diffusion` (exponential wings
per axis), :class:`Halo` (a share of the energy scattered into a broad
kernel) and :class:`Lag`.  A new stage is one module of this package
with the :func:`register` decorator and its import below; the fit
(:mod:`imgmtf.estimate.fit`) reads what it needs to fit it from the fields'
``FitSpec`` metadata.

Examples
--------
>>> from imgmtf.sensor.stages import GaussianOptics, stage_from_dict
>>> optics = GaussianOptics(sigma_x_m=0.39, sigma_y_m=0.39)
>>> round(float(optics.transfer(0.5, 0.0, 1.0)), 4)
0.4721
>>> stage_from_dict(optics.to_dict()) == optics
True
"""
from __future__ import annotations

from .base import MAX_PARAMETER, STAGES, FitSpec, Stage, register, stage_from_dict

# each module registers its stage on import, in this order (the order of STAGES)
# isort: off
from .optics import GaussianOptics
from .detector import Detector
from .motion import Motion
from .electronics import Electronics
from .diffraction import Diffraction
from .defocus import Defocus
from .olpf import OLPF
from .jitter import Jitter
from .diffusion import Diffusion
from .halo import Halo
from .lag import Lag
from .measured import MeasuredMTF
# isort: on

__all__ = [
           "MAX_PARAMETER",
           "OLPF",
           "STAGES",
           "Defocus",
           "Detector",
           "Diffraction",
           "Diffusion",
           "Electronics",
           "FitSpec",
           "GaussianOptics",
           "Halo",
           "Jitter",
           "Lag",
           "MeasuredMTF",
           "Motion",
           "Stage",
           "register",
           "stage_from_dict",
]

"""Each edge's line response for the fitted stages, and the changes of its
edge response with each free parameter, in one inverse FFT per edge.

The responses of a sensor and of its copies with one parameter shifted
(the Jacobian's finite differences) are made on one grid, the first
sensor's, with one reference: each stage's transfer is computed once on
it (a shift changes one stage), and the differences of the transfers,
not of two responses on two grids, give the derivatives.  Without a
diffraction stage the grid covers the PSF's support only: beyond it the
Gaussian reference is the edge response to below 1e-9, so a sample far
from the edge needs no grid out to it.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ...sensor.lines import LineResponse, hermite, line_grid, reference_transfer
from ...sensor.model import Sensor
from ...sensor.stages import Stage


def line_responses(sensors: Sequence[Sensor], angle_deg: float, gsd_m: float,
                   reach_px: float) -> tuple[LineResponse, np.ndarray, np.ndarray]:
    """The line response of ``sensors[0]`` along the normal of an edge
    tilted ``angle_deg`` (pixels of ``gsd_m``), and the remainders of the
    others' minus its own on its grid.

    Parameters
    ----------
    sensors : sequence of Sensor
        The sensor, then its shifted copies (same GSD, same chain).
    angle_deg : float
        The edge's tilt from the column axis, deg.
    gsd_m : float
        The edge's pixel, m.
    reach_px : float
        The farthest sample from the edge, px: the grid reaches it when a
        Cauchy (diffraction) tail makes the remainder long.

    Returns
    -------
    response : LineResponse
        The first sensor's edge and line responses.
    esf_changes, lsf_changes : numpy.ndarray, shape (len(sensors) - 1, grid size)
        Each other sensor's ESF and LSF (1/px) less the first's, on the
        grid of ``response`` (zero beyond it): for :func:`esf_changes`.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> response, esf, _ = line_responses([Sensor(), Sensor(motion_m=0.5)], 90.0, 1.0, 50.0)
    >>> round(float(response.esf(0.0)), 6), esf.shape[0]
    (0.5, 1)
    """
    base = sensors[0]
    grid = line_grid(base, angle_deg, gsd_m, reach_px=reach_px if base.tail_length_m() > 0 else 0.0)
    angle = math.radians(angle_deg)
    f = grid.frequencies_cy_px / gsd_m
    fx, fy = f * math.cos(angle), f * math.sin(angle)
    known: dict[Stage, np.ndarray] = {}

    def transfer(sensor: Sensor) -> np.ndarray:
        out = np.ones(f.shape)
        for stage in sensor.stages:
            if stage not in known:
                known[stage] = stage.transfer(fx, fy, base.gsd_m)
            out = out * known[stage]
        return out

    spectra = np.stack([transfer(sensor) for sensor in sensors])
    spectra[1:] -= spectra[0]
    spectra[0] -= reference_transfer(grid.reference, grid.frequencies_cy_px)
    esf, lsf = grid.remainders(spectra)
    return LineResponse(grid.start_px, grid.step_px, esf[0], lsf[0], grid.reference), esf[1:], lsf[1:]


def esf_changes(response: LineResponse, esf: np.ndarray, lsf: np.ndarray, d_px: np.ndarray) -> np.ndarray:
    """The changes of the edge response (:func:`line_responses`'
    ``esf_changes``, ``lsf_changes``) at signed distances ``d_px``, one
    row each.

    Parameters
    ----------
    response : LineResponse
        The response whose grid they are on.
    esf, lsf : numpy.ndarray, shape (k, grid size)
        The changes of its ESF and LSF (1/px).
    d_px : numpy.ndarray
        Distances from the edge, px.

    Returns
    -------
    numpy.ndarray, shape (k, len(d_px))
        The ESF's changes there.

    Examples
    --------
    >>> from imgmtf import Sensor
    >>> response, esf, lsf = line_responses([Sensor(), Sensor(motion_m=0.5)], 90.0, 1.0, 50.0)
    >>> esf_changes(response, esf, lsf, np.array([-1.0, 0.0, 1.0])).round(3).tolist()   # wider: slower rise
    [[0.004, 0.0, -0.004]]
    """
    return hermite(response.start_px, response.step_px, esf, lsf, d_px)

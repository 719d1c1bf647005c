"""Many chips measured together (a scan's candidates in one window of the
scene): each chip's estimate runs its own pipeline (:func:`.pipeline.run_steps`),
and what costs the interpreter more than the arithmetic on one chip's small
arrays is made for all of them at once:

- the chips' first stages and their edges' per-row Fermi fits, stacked
  into one Levenberg-Marquardt (:mod:`.prefit`);
- every stage the pipeline asks for (:mod:`.asks`: the resamplings, the
  blur check's fits of each chip's halves and thirds...), the generators
  advanced in lockstep and each round's asks of a name answered by one call
  (:func:`.asks.drive`).

Every result is the same, to the bit, as the chip's measured alone, and
every refusal the same refusal (the same exception, returned in its place).
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .asks import drive
from .kind import TargetKind
from .pipeline import Measurement, run_steps
from .prefit import prefit_chips
from .settings import Settings

CHUNK = 256         # chips advanced in lockstep at once: the state of a few hundred small chips


def run_many(kind: TargetKind, images: Sequence[np.ndarray], settings: Settings,
             options: Sequence[dict[str, Any]]) -> list[Measurement | Exception]:
    """:func:`.pipeline.run` of every image, the work alike across them
    made together: each a measurement, or the exception its own run raises.

    Parameters
    ----------
    kind : TargetKind
        The targets' kind.
    images : sequence of numpy.ndarray
        The chips, DN.
    settings : Settings
        The estimator's settings.
    options : sequence of dict
        Each chip's keywords of :func:`.pipeline.run` (``mask``, ``gsd_m``,
        ``saturation``, ``dtype``, ``track_azimuth_deg``, ``roi``).

    Returns
    -------
    list of Measurement or Exception
        One per image, in order.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 40, noise_std_dn=2.0, seed=1).image
    ...          for a in (5.0, 8.0)]
    >>> settings = make_settings()
    >>> together = run_many(EdgeKind(), chips, settings, [{}, {}])
    >>> [m.estimate.spectrum.mtf_nyquist for m in together] == [
    ...     run(EdgeKind(), c, settings).estimate.spectrum.mtf_nyquist for c in chips]
    True
    """
    out: list[Measurement | Exception] = []
    for start in range(0, len(images), CHUNK):
        out += _run_chunk(kind, images[start: start + CHUNK], settings, options[start: start + CHUNK])
    return out


def _run_chunk(kind: TargetKind, images: Sequence[np.ndarray], settings: Settings,
               options: Sequence[dict[str, Any]]) -> list[Measurement | Exception]:
    """:func:`run_many` of a few hundred chips at most."""
    return drive([run_steps(kind, image, settings, prefit=prefit, **keywords)
                  for image, keywords, prefit in zip(images, options, prefit_chips(kind, images, settings, options))])

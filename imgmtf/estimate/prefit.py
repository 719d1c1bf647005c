"""The pipeline's first stages for many chips at once (a scan's candidates
in one window of the scene): each chip prepared and its target seeded as
:func:`.pipeline.run` would, and the per-row Fermi fits of all their edges
stacked into one Levenberg-Marquardt (:func:`.fermi.fit_fermi_many`).  One
edge's fit iterates on arrays of some forty rows of 21 samples, where each
operation costs the interpreter more than the arithmetic; stacked, the
rows of a few hundred edges cost about as much as those of a few.

What it hands :func:`.pipeline.run` (``prefit=``) gives the same result,
to the bit, as the chip measured alone: the stacked fit computes every
row as its edge's own fit does, and anything that fails here is left for
the chip's own run to fail the same way.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .chip import prepare_chip
from .fermi import FermiFit, FermiRows, fit_fermi_many
from .geometry import vertical_frame

if TYPE_CHECKING:
    from .detection import Line
    from .gate import Check
    from .kind import TargetKind
    from .settings import Settings
    from .state import Chip


@dataclass(frozen=True, eq=False)
class Prefit:
    """A chip's first stages, made among other chips': the prepared chip,
    its seed (the line and the gate's checks, or the error seeding raised)
    and its rows' Fermi fit (None where its kind fits none, or where its
    rows are left for :meth:`.kind.TargetKind.locate` to refuse)."""

    chip: Chip
    seed: tuple[Line, list[Check]] | Exception
    fit: FermiFit | None = None

    def seeded(self) -> tuple[Line, list[Check]]:
        """The seed as :meth:`.kind.TargetKind.seed` gave it (its error raised again)."""
        if isinstance(self.seed, Exception):
            raise self.seed
        line, checks = self.seed
        return line, list(checks)


def prefit_chips(kind: TargetKind, images: Sequence[np.ndarray], settings: Settings,
                 options: Sequence[dict[str, Any]]) -> list[Prefit | None]:
    """Every image's first stages (:class:`Prefit`), its edges' rows fitted
    all together; None for a chip whose preparation failed (its own run
    fails the same way).

    Parameters
    ----------
    kind : TargetKind
        The targets' kind.
    images : sequence of numpy.ndarray
        The chips, DN.
    settings : Settings
        The estimator's settings.
    options : sequence of dict
        Each chip's keywords of :func:`.chip.prepare_chip` (``mask``,
        ``gsd_m``, ``saturation``, ``dtype``, ``track_azimuth_deg``, ``roi``).

    Returns
    -------
    list of Prefit or None
        One per chip, for :func:`.pipeline.run`'s ``prefit``.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run
    >>> from imgmtf.estimate.settings import make_settings
    >>> chips = [imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", a), 40, noise_std_dn=2.0, seed=1).image
    ...          for a in (5.0, 8.0)]
    >>> settings = make_settings()
    >>> prefits = prefit_chips(EdgeKind(), chips, settings, [{}, {}])
    >>> together = run(EdgeKind(), chips[1], settings, prefit=prefits[1]).estimate.spectrum.mtf_nyquist
    >>> together == run(EdgeKind(), chips[1], settings).estimate.spectrum.mtf_nyquist
    True
    """
    out: list[Prefit | None] = []
    rows: list[tuple[int, FermiRows]] = []
    for image, keywords in zip(images, options):
        try:
            chip = prepare_chip(image, settings, **keywords)
        except Exception:           # its own run raises it
            out.append(None)
            continue
        try:
            seed = kind.seed(chip.pixels, chip.noise_dn)
        except Exception as exc:    # raised again where its own run would raise it
            out.append(Prefit(chip, exc))
            continue
        out.append(Prefit(chip, seed))
        try:
            frame, seed_x, _ = vertical_frame(chip.pixels, seed[0])
            fitted = kind.fermi_rows(frame, seed_x)
        except Exception:           # too few rows: its own locate refuses it
            fitted = None
        if fitted is not None:
            rows.append((len(out) - 1, fitted))
    for (i, _), fit in zip(rows, fit_fermi_many([r for _, r in rows])):
        out[i] = replace(out[i], fit=fit)   # type: ignore[type-var]
    return out

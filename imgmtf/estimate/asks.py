"""What a chip's pipeline asks for, answered for many chips at once.

:func:`.pipeline.run_steps` is a generator: at each stage whose arithmetic
is alike across chips it yields an :class:`Ask` (a name and the chip's
payload) and receives the answer.  One registry, :data:`ANSWERS`, maps each
name to a function over a LIST of payloads (many chips' asks) returning a
list of answers, so that a chunk of chips (:func:`.many.run_many`) pays the
interpreter once per stage and not once per chip.  :func:`drive` advances
generators in lockstep, grouping their asks by name; :func:`alone` is the
same for one chip (batches of one): one code path for one chip and many.

An answer that is an exception is raised in its chip's generator where it
asked (its own run would have raised it there); a chip whose generator
raised gets its exception in its place.  An answering function must give
each chip's answer as its own (the same to the bit whatever else is in the
list), so that one chip's result never depends on its company.

A new batchable stage: its function over a list of payloads in the module
of its arithmetic (which does not import this one: arrows point down), one
entry in :data:`ANSWERS`, and ``answer = yield Ask(name, payload)`` in the
stage's generator (:mod:`.pipeline`, :mod:`.profile`: ``yield from`` down
to it).

Asks
----
blur-widths   the blur check's widths of a chip's halves and thirds
              (:func:`.blur_along.group_widths_many`; payload: the chip's
              :class:`.evidence.Evidence`).
resample      a profile's samples resampled onto a grid
              (:func:`.stacked_resampling.resample_many`; payload: a
              :class:`.stacked_resampling.ResampleRequest`).
block-boundaries  the block compression check of a chip's row locations
              (:func:`.blocks.block_boundaries_many`; payload: the chip's
              :class:`.evidence.Evidence`).
line-checks   the checks of a target's line through its rows
              (:func:`.gate.line_checks_many`; payload: the chip's
              arguments of :func:`.gate.line_checks`).
restore-lsf   the LSF restored from a windowed profile
              (:func:`.spectrum.restore_lsf_many`; payload: a
              :class:`.spectrum.RestoreRequest`).
saturation    the saturation checks of a chip's sides and peak
              (:func:`.saturation.saturation_checks_many`; payload: the
              chip's keywords of :func:`.saturation.saturation_checks`).
settled-sides the settling check of a chip's sides
              (:func:`.settling.settled_sides_many`; payload: the chip's
              :class:`.evidence.Evidence`).
spectrum      the windowed profile's zero-padded transform
              (:func:`.spectrum.spectrum_many`; payload: the profile's
              support and its step, px).
side-checks   the uniformity checks of a chip's sides
              (:func:`.sides.side_checks_many`; payload: the chip's
              arguments of :func:`.sides.side_checks`).
"""
from __future__ import annotations

from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from .blocks import block_boundaries_many
from .blur_along import group_widths_many
from .gate import line_checks_many
from .saturation import saturation_checks_many
from .settling import settled_sides_many
from .sides import side_checks_many
from .spectrum import restore_lsf_many, spectrum_many
from .stacked_resampling import resample_many

T = TypeVar("T")


@dataclass(frozen=True, eq=False)
class Ask:
    """One chip's request to a batchable stage.

    Attributes
    ----------
    name : str
        A key of :data:`ANSWERS`.
    payload : object
        What the stage needs of this chip.
    """

    name: str
    payload: Any


#: ask name -> function of a list of payloads returning one answer (or exception) per payload, in order
ANSWERS: dict[str, Callable[[list], list]] = {
    "blur-widths": group_widths_many,
    "block-boundaries": block_boundaries_many,
    "resample": resample_many,
    "restore-lsf": restore_lsf_many,
    "line-checks": line_checks_many,
    "saturation": saturation_checks_many,
    "settled-sides": settled_sides_many,
    "side-checks": side_checks_many,
    "spectrum": spectrum_many,
}

Steps = Generator[Ask, Any, T]


def answer(name: str, payloads: list) -> list:
    """The answers of :data:`ANSWERS` ``[name]`` to ``payloads``, one per
    payload (an exception where that payload's stage fails).

    Raises
    ------
    KeyError
        ``name`` is not registered (a bug, never data).

    Examples
    --------
    >>> import numpy as np
    >>> from imgmtf.estimate.stacked_resampling import ResampleRequest
    >>> d = np.linspace(-3.0, 3.0, 600)
    >>> [r.grid.size for r in answer("resample", [ResampleRequest(d, d, half_range=2.0)])]
    [81]
    """
    answers = ANSWERS[name](payloads)
    if len(answers) != len(payloads):       # pragma: no cover - a bug, never data
        raise RuntimeError(f"the {name!r} ask answered {len(answers)} of {len(payloads)} payloads")
    return answers


def drive(steps: Sequence[Steps[T]]) -> list[T | Exception]:
    """Run generators of asks to their ends in lockstep: each round, the
    pending asks are grouped by name and each group answered by one call
    (:func:`answer`).

    Parameters
    ----------
    steps : sequence of generator
        Each yields :class:`Ask` and receives its answer; returns its result.

    Returns
    -------
    list
        Each generator's result, or the exception it raised, in order.

    Examples
    --------
    >>> import numpy as np
    >>> from imgmtf.estimate.stacked_resampling import ResampleRequest
    >>> d = np.linspace(-3.0, 3.0, 600)
    >>> def grid_size(half_range):
    ...     resampled = yield Ask("resample", ResampleRequest(d, d, half_range=half_range))
    ...     return resampled.grid.size
    >>> drive([grid_size(1.0), grid_size(2.0)])       # one call answers both asks
    [41, 81]
    """
    out: list[Any] = [None] * len(steps)
    pending: dict[int, Ask] = {}

    def advance(k: int, reply: Any) -> None:
        try:
            ask = steps[k].throw(reply) if isinstance(reply, BaseException) else steps[k].send(reply)
        except StopIteration as done:
            out[k] = done.value
        except Exception as exc:        # its own run raises it: returned in its place
            out[k] = exc
        else:
            pending[k] = ask

    for k in range(len(steps)):
        advance(k, None)
    while pending:
        groups: dict[str, list[int]] = {}
        for k, ask in pending.items():
            groups.setdefault(ask.name, []).append(k)
        asked, pending = pending, {}
        for name, members in groups.items():
            for k, reply in zip(members, answer(name, [asked[k].payload for k in members])):
                advance(k, reply)
    return out


def alone(steps: Steps[T]) -> T:
    """One generator of asks run to its end, each ask answered as a batch
    of one (:func:`drive`); its exception raised.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.edge import EdgeKind
    >>> from imgmtf.estimate.pipeline import run_steps
    >>> from imgmtf.estimate.settings import make_settings
    >>> chip = imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60)
    >>> alone(run_steps(EdgeKind(), chip.image, make_settings())).located.rows_used
    60
    """
    result = drive([steps])[0]
    if isinstance(result, Exception):
        raise result
    return result

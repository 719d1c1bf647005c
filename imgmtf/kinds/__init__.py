"""The registry of target kinds: the one place that maps a kind's name
("edge", "pulse") to what it is and where its parts live (its
:class:`Kind`), as colour-science keeps interchangeable methods behind
one dispatcher.  Nothing else in the package compares a kind's name: it
asks :func:`get_kind` for the kind and reads its facts.

Adding a kind (a Siemens star): a module beside :mod:`.edge`,
:mod:`.pulse` and :mod:`.points` defining its :class:`Kind`, and one entry
in :data:`KINDS`; docs/architecture.md says what its parts are.

This package sits below :mod:`imgmtf.sensor` and imports nothing of the
package but its errors: the estimator and its result are named, and
imported when first used (:meth:`Kind.load`).
"""
from __future__ import annotations

from ..errors import ParameterError
from .double_bar import DOUBLE_BAR
from .edge import EDGE
from .kind import Column, Kind
from .points import POINTS
from .pulse import PULSE
from .star import STAR

__all__ = ["KINDS", "Column", "Kind", "get_kind", "kind_names", "kinds_with_width"]

#: every kind of target, by name, in the order commands list them
KINDS: dict[str, Kind] = {kind.name: kind for kind in (EDGE, PULSE, POINTS, DOUBLE_BAR, STAR)}


def kind_names() -> tuple[str, ...]:
    """The registered kinds' names, in :data:`KINDS`' order.

    Returns
    -------
    tuple of str
        The names ``--target`` and :class:`imgmtf.Target` accept.

    Examples
    --------
    >>> kind_names()
    ('edge', 'pulse', 'points', 'double-bar', 'star')
    """
    return tuple(KINDS)


def get_kind(name: str, what: str = "target kind") -> Kind:
    """The kind of target called ``name``.

    Parameters
    ----------
    name : str
        A registered kind's name ("edge", "pulse").
    what : str, optional
        What the caller calls the value, for the error's message.

    Returns
    -------
    Kind
        Its facts and parts.

    Raises
    ------
    ParameterError
        (a ValueError) ``name`` is no registered kind; the message names
        the kinds there are.

    Examples
    --------
    >>> get_kind("pulse").noun
    'bar'
    >>> get_kind("spoke")
    Traceback (most recent call last):
    imgmtf.errors.ParameterError: target kind must be one of ('edge', ..., 'star'), got 'spoke'
    """
    kind = KINDS.get(name) if isinstance(name, str) else None
    if kind is None:
        raise ParameterError(f"{what} must be one of {kind_names()}, got {name!r}")
    return kind


def kinds_with_width() -> tuple[Kind, ...]:
    """The kinds whose targets have a width (a bar's).

    Returns
    -------
    tuple of Kind
        In :data:`KINDS`' order.

    Examples
    --------
    >>> [kind.name for kind in kinds_with_width()]
    ['pulse', 'double-bar']
    """
    return tuple(kind for kind in KINDS.values() if kind.has_width)

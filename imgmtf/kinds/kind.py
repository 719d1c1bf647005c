"""What a kind of target is (:class:`Kind`): its name, its words, the column
it adds and where its estimator, result and pipeline part live."""
from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..errors import ParameterError


@dataclass(frozen=True)
class Column:
    """The figure a kind adds to the text table (its last column) and to the
    CSV: ``field`` the record's key, ``heading`` and ``unit`` the table's
    two header lines."""

    field: str
    heading: str
    unit: str = ""


@dataclass(frozen=True)
class Kind:
    """One kind of target: what it is and where its parts live.

    Parts above the package's lowest layer (the estimator, its result, the
    pipeline's part) are named as "module:attribute" and imported when
    first asked for, so that the registry stays importable by
    :mod:`imgmtf.sensor` and by ``imgmtf --help`` without loading NumPy.

    Attributes
    ----------
    name : str
        The kind as a user names it: ``--target``, :class:`imgmtf.Target`'s
        ``kind``, the records' ``target``.
    noun : str
        What messages and figures call one ("edge", "bar").
    has_width : bool
        Whether the target has a width along its normal (a bar's
        ``width_px``, ``--pulse-width``); the estimator then takes
        ``width_px``.
    column : Column
        The figure of the kind's own the text table prints last.
    record_fields : tuple of str
        The result's figures the CSV holds for this kind
        (:data:`imgmtf.records.SUMMARY_COLUMNS`).
    estimator, result : str
        "module:attribute" of its estimator class (configured once, called
        per chip) and of its result type.
    measuring : str or None
        "module:attribute" of its part of the shared 1-D pipeline (a
        :class:`imgmtf.estimate.kind.TargetKind`); None for a kind with a
        pipeline of its own (points: :mod:`imgmtf.estimate.mtf2d`).
    scene_response : callable or None
        ``scene_response(d_px, esf, width_px)``: the target's image, 0 to 1,
        at signed distances ``d_px`` (px) from its line, seen through a
        sensor whose edge response along the normal is ``esf``; None for a
        target that is no line (its ``renderer`` draws it).
    profile_label : str
        The title of its profile's figure, formatted with ``width_px``.
    lsf_label, lsf_scale : str
        What its LSF-like profile is called, and its scale (the paper's
        figures: "LSF" in 1/px, "pulse response" of peak 1).
    described : str
        The target in a figure's title, formatted with ``width_px``.
    masked_by : str or None
        What masks frequencies of its MTF (NaN there), or None.
    lone_line : (str, str) or None
        A scan's verdict (reason, message) on a lone straight line (one
        edge) when this kind is sought, or None where a lone line is a
        candidate.
    fits_sensor : bool
        Whether a scan fits the sensor model to its accepted candidates
        (:mod:`imgmtf.scene.targetfit`, which reads half-edges' ESFs).
    size_keyword : str or None
        The keyword its estimator takes for a known size of each target
        (points: ``point_size_px``, ``--point-size``), or None.
    renderer : str or None
        "module:attribute" of its own renderer when it is no line (None:
        :class:`imgmtf.Target` and :func:`imgmtf.render` draw it).
    figure : str or None
        "module:attribute" of its measurement figure when it is not
        :func:`imgmtf.plot.plot_measurement`'s.
    rows_per_result : str or None
        Why one result gives several records (points: one per direction),
        or None for one record per result.
    gap_keyword : str or None
        The keyword its estimator, its ``scene_response`` and
        :class:`imgmtf.Target` take for the edge-to-edge gap between its
        two bars (double bars: ``gap_px``, ``--gap``), or None.
    scanner : str or None
        "module:attribute" of its own scene scan when it is no line
        (``scanner(path, settings)`` returning the records and the scene's
        summaries; points: :func:`imgmtf.scene.points.scan_point_arrays`),
        or None: ``imgmtf scan`` searches the scene for lines.

    Examples
    --------
    >>> from imgmtf.kinds import get_kind
    >>> pulse = get_kind("pulse")
    >>> pulse.noun, pulse.has_width, pulse.column.heading
    ('bar', True, 'W')
    >>> pulse.described.format(width_px=1.5)
    '1.5 px bar'
    """

    name: str
    noun: str
    has_width: bool
    column: Column
    record_fields: tuple[str, ...]
    estimator: str
    result: str
    measuring: str | None
    scene_response: Callable[[Any, Callable[[Any], Any], float], Any] | None
    profile_label: str
    lsf_label: str
    lsf_scale: str
    described: str
    masked_by: str | None = None
    lone_line: tuple[str, str] | None = None
    fits_sensor: bool = False
    size_keyword: str | None = None
    renderer: str | None = None
    figure: str | None = None
    rows_per_result: str | None = None
    gap_keyword: str | None = None
    scanner: str | None = None

    def load(self, part: str) -> Any:
        """The object one of the kind's "module:attribute" parts names,
        imported on first use.

        Parameters
        ----------
        part : {"estimator", "result", "measuring", "renderer", "figure", "scanner"}
            Which part.

        Returns
        -------
        object
            The class (or function) the part names.

        Raises
        ------
        ParameterError
            The kind has no such part (points have no part of the 1-D
            pipeline).

        Examples
        --------
        >>> from imgmtf.kinds import get_kind
        >>> get_kind("edge").load("result").__name__
        'EdgeResult'
        """
        name = getattr(self, part)
        if name is None:
            raise ParameterError(f"a {self.name} target has no {part} part")
        module, _, attribute = name.partition(":")
        return getattr(importlib.import_module(module), attribute)

    def make_estimator(self, method: str = "msg", **settings: Any) -> Any:
        """The kind's estimator, configured once and called per chip.

        Parameters
        ----------
        method : str, optional
            The resampling method (default "msg").
        **settings
            Settings of :class:`imgmtf.estimate.settings.Settings`.

        Returns
        -------
        callable
            ``estimator(image, **keywords)``, returning the kind's result;
            see :meth:`estimator_keywords` for what it takes beyond the
            keywords every kind's takes.

        Examples
        --------
        >>> from imgmtf.kinds import get_kind
        >>> type(get_kind("edge").make_estimator("msg")).__name__
        'EdgeEstimator'
        """
        return self.load("estimator")(method, **settings)

    def estimator_keywords(self, width_px: float | None, size_px: float | None = None,
                           gap_px: float | None = None) -> dict[str, float | None]:
        """The keywords this kind's estimator takes beyond those every
        kind's takes: a width (px; None to estimate it) for a kind with
        one, a known size (px) for a kind that takes one, none otherwise.

        Parameters
        ----------
        width_px : float or None
            The target's width, px (None: unknown).
        size_px : float or None, optional
            Each target's known size, px (None: none given).
        gap_px : float or None, optional
            The gap between its two bars, px, for a kind with one.

        Returns
        -------
        dict
            ``{"width_px": width_px}``, ``{"point_size_px": size_px}`` or
            ``{}``.

        Examples
        --------
        >>> from imgmtf.kinds import get_kind
        >>> get_kind("pulse").estimator_keywords(1.5), get_kind("edge").estimator_keywords(None)
        ({'width_px': 1.5}, {})
        """
        keywords: dict[str, float | None] = {"width_px": width_px} if self.has_width else {}
        if self.size_keyword is not None:
            keywords[self.size_keyword] = size_px
        if self.gap_keyword is not None:
            keywords[self.gap_keyword] = gap_px
        return keywords

"""One typed row for every outcome of ``measure``, batches and ``scan``, its
CSV schema, and writers that stream rows to disk as they come.

A :class:`Record` is what one target gave: the figures of an estimate
(``status`` ``ok``, or ``accepted`` in a scan), or why there are none
(``error``/``rejected``, with a machine-readable ``reason`` and a one-line
message naming the file).  Every record carries its provenance: the input
``path`` and ``band``, ``target`` and ``method``, ``params`` (the
estimator's settings with the run's: bootstrap, ROI, scan thresholds...),
``imgmtf_version`` and ``run_utc``, the start of the run in UTC (ISO 8601).

The JSON form (:meth:`Record.to_dict`) is flat: the estimate's own keys
(:meth:`imgmtf.estimate.results.MTFResult.to_dict`, units in the names)
beside the provenance.  The CSV schema is :data:`CSV_COLUMNS`; a scan's CSV
adds the columns of :data:`SCAN_COLUMNS` (where the target lies, and the
per-target and per-scene summaries).

Reason codes of failed records: those of :mod:`imgmtf.errors`
(``unreadable``, ``too-large``, ``unsupported-type``, ``image``,
``no-target``, ``two-targets``, ``unsuitable``, ``parameter``...), the
scan's screening codes (``angle``, ``too-short``, ``fill``, ``non-uniform``...), and
``internal`` for an unexpected failure of the software on that input.
"""
from __future__ import annotations

import csv
import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from typing import IO, Any

import numpy as np

from .atomic import atomic_output
from .errors import FileWriteError, ImgmtfError
from .kinds import KINDS
from .safe_json import (  # json_safe and dumps_safe are imported from here too
    ENCODER,
    dumps_safe,
    dumps_sorted,
    finite_values,
    has_unsafe_value,
    json_safe,
)
from .version import __version__

OK_STATUSES = ("ok", "accepted", "combined", "fitted")
INTERNAL = "internal"

# keys of an estimate's dict that are the record's own fields
_OWN_KEYS = frozenset({"path", "band", "target", "method", "status", "reason", "error", "plot",
                       "params", "imgmtf_version", "run_utc"})


def utc_now() -> str:
    """The current time in UTC, ISO 8601 to the second (``2024-05-01T09:30:00Z``)."""
    return datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


@dataclass(frozen=True)
class Record:
    """The outcome of measuring one target: a file (or one of its bands), or
    a scan candidate; one JSON Lines line or CSV row of ``measure``.

    Attributes
    ----------
    path : str
        The input file.
    band : int, str or None
        1-based band, ``"luminance"`` for RGB, None when not known.
    target : str
        ``"edge"``, ``"pulse"`` or ``"points"`` (a kind of
        :data:`imgmtf.kinds.KINDS`; points give one record per direction).
    method : str
        The resampling method (``"points"`` for the point stack).
    status : str
        ``ok``/``error`` (measure), ``accepted``/``rejected`` (a scan
        candidate), ``combined`` or ``fitted`` (a scan's summary of a
        target or scene: its half-edges combined, or the sensor model
        fitted to them).
    reason : str or None
        Machine-readable code of a failure (``unreadable``, ``two-targets``,
        ``saturated``...; None when ok).
    error : str or None
        One-line message naming the file (None when ok).
    figures : mapping
        The estimate's JSON summary (units in the names: ``mtf50_cy_px``,
        ``fwhm_px``...), empty for a failure.
    site : mapping
        Where a scan candidate lies (``id``, ``rank``, ``scope``,
        ``target_id``, ``x0_px``...), or what a scan summary covers; for a
        window from a vector layer (``--roi-file``), its ``feature_id`` and
        ``feature`` (the attributes); else empty for ``measure``.
    plot : str or None
        The figure written for this record, if any.
    params : mapping
        Settings of the estimate and of the run.
    run_utc : str
        Start of the run, UTC, ISO 8601.
    imgmtf_version : str
        The version that made the record.
    measurement : object or None
        The estimator's result behind an accepted scan candidate (an
        :class:`imgmtf.EdgeResult` or :class:`imgmtf.PulseResult`: its
        samples, profile and MTF), what the target's sensor fit starts
        from; in memory only: never written, not compared, None once read
        back from a file or a store.

    Raises
    ------
    TypeError
        A missing field (the constructors :meth:`measured` and
        :meth:`failed` fill them).

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.errors import ImageReadError
    >>> record = imgmtf.Record.failed("a.tif", None, "edge", "msg", ImageReadError("a.tif: no such file"),
    ...                               params={}, run_utc="2024-05-01T09:30:00Z")
    >>> record
    Record('a.tif', error, unreadable: a.tif: no such file)
    >>> record.csv_row()["reason"], record.ok
    ('unreadable', False)
    """

    path: str
    band: int | str | None
    target: str
    method: str
    status: str
    reason: str | None = None
    error: str | None = None
    figures: Mapping[str, Any] = field(default_factory=dict)
    site: Mapping[str, Any] = field(default_factory=dict)
    plot: str | None = None
    params: Mapping[str, Any] = field(default_factory=dict)
    run_utc: str = ""
    imgmtf_version: str = __version__
    measurement: Any = field(default=None, repr=False, compare=False)

    @classmethod
    def measured(cls, path: str, band: int | str | None, summary: Mapping[str, Any], *,
                 params: Mapping[str, Any], run_utc: str, status: str = "ok", **fields: Any) -> Record:
        """A record of an estimate whose JSON summary is ``summary``; the
        run's ``params`` are merged with the estimator's own.

        Parameters
        ----------
        path : str
            The input file.
        band : int, str or None
            1-based band, ``"luminance"`` for RGB, None when not known.
        summary : mapping
            The estimate's JSON summary (``to_dict()`` of a result).
        params : mapping
            The run's settings.
        run_utc : str
            The run's start, UTC, ISO 8601.
        status : str, optional
            ``ok`` (default) or ``accepted``.
        **fields
            Other fields of the record (``site``, ``plot``...).

        Returns
        -------
        Record
            The record, its figures the summary's.
        """
        figures = {k: v for k, v in summary.items() if k not in _OWN_KEYS}
        return cls(str(path), band, summary.get("target", ""), summary.get("method", ""), status,
                   figures=figures, params={**params, **(summary.get("params") or {})},
                   run_utc=run_utc, **fields)

    @classmethod
    def failed(cls, path: str, band: int | str | None, target: str, method: str, exc: BaseException, *,
               params: Mapping[str, Any], run_utc: str, status: str = "error", **fields: Any) -> Record:
        """A record of a target that could not be measured: the reason code
        of an imgmtf error, ``internal`` for any other exception; the
        message names the file (prefixed when it does not).

        Parameters
        ----------
        path : str
            The input file.
        band : int, str or None
            1-based band, ``"luminance"`` for RGB, None when not known.
        target : str
            ``"edge"`` or ``"pulse"``.
        method : str
            The resampling method.
        exc : BaseException
            What the measurement raised.
        params : mapping
            The run's settings.
        run_utc : str
            The run's start, UTC, ISO 8601.
        status : str, optional
            ``error`` (default) or ``rejected``.
        **fields
            Other fields of the record (``site``...).

        Returns
        -------
        Record
            The record, with its reason and message.
        """
        message = " ".join(str(exc).split())
        if isinstance(exc, ImgmtfError):
            reason = exc.reason
        else:
            reason = INTERNAL
            message = f"internal error: {type(exc).__name__}: {message or 'no message'}"
        if not message.startswith(str(path)):
            where = f"{path}: band {band}" if isinstance(band, int) else str(path)
            message = f"{where}: {message}"
        return cls(str(path), band, target, method, status, reason, message, params=params,
                   run_utc=run_utc, **fields)

    def __repr__(self) -> str:
        band = "" if self.band in (None, 1, "luminance") else f", band {self.band}"
        if self.ok:
            figures = self.figures
            outcome = (f"MTF@Nyquist {figures.get('mtf_nyquist')}, MTF50 {figures.get('mtf50_cy_px')} cy/px"
                       if figures else "no figures")
        else:
            outcome = f"{self.reason}: {self.error}"
        return f"Record({self.path!r}{band}, {self.status}, {outcome})"

    @property
    def ok(self) -> bool:
        """True for a measured (``ok``) or accepted record."""
        return self.status in OK_STATUSES

    def get(self, key: str, default: Any = None) -> Any:
        """A value of the flat JSON form (a field, a figure or a site key),
        or of a CSV column (an interval's bound, ``mtf_nyquist_ci_low``; a
        point of the curve, ``mtf_at_0.25_cy_px``) by the CSV's name.

        Parameters
        ----------
        key : str
            The key (``mtf_nyquist``, ``status``, ``x0_px``...) or CSV column.
        default : object, optional
            What a missing key gives (default None).

        Returns
        -------
        object
            The value.

        Examples
        --------
        >>> r = Record("a.tif", 1, "edge", "msg", "ok", figures={"mtf_nyquist": 0.3, "mtf_nyquist_ci": [0.28, 0.32]})
        >>> r.get("mtf_nyquist_ci"), r.get("mtf_nyquist_ci_low"), r.get("mtf50_ci_low_cy_px", "-")
        ([0.28, 0.32], 0.28, '-')
        """
        flat = self.to_dict()
        if key in flat:
            return flat[key]
        source = _CSV_SOURCES.get(key)
        if isinstance(source, tuple):
            pair = flat.get(source[0])
            return default if pair is None else pair[source[1]]
        if source is not None:
            return flat.get(source, default)
        if key in _CURVE_COLUMN_FREQUENCY:
            value = curve_values(flat.get("frequencies_cy_px"), flat.get("mtf"))[key]
            return default if value is None else value
        return default

    def with_(self, **changes: Any) -> Record:
        """A copy with fields changed (``figures``/``site`` given as
        mappings are merged into the current ones).

        Parameters
        ----------
        **changes
            The fields to change, by name.

        Returns
        -------
        Record
            The copy.
        """
        for name in ("figures", "site"):
            if name in changes:
                changes[name] = {**getattr(self, name), **changes[name]}
        return replace(self, **changes)

    def to_dict(self) -> dict:
        """The flat, JSON-ready form (one JSON Lines line)."""
        return {**self.site, "path": self.path, "band": self.band, "target": self.target,
                "method": self.method, "status": self.status, "reason": self.reason,
                "error": self.error, **self.figures, "plot": self.plot, "params": dict(self.params),
                "imgmtf_version": self.imgmtf_version, "run_utc": self.run_utc}

    def csv_row(self, columns: Sequence[str] | None = None) -> dict:
        """The record flattened to ``columns`` (default :data:`CSV_COLUMNS`):
        intervals split into their bounds, lists and mappings as JSON,
        missing values empty.

        Parameters
        ----------
        columns : sequence of str, optional
            The CSV's columns (default :data:`CSV_COLUMNS`).

        Returns
        -------
        dict
            Column -> value.
        """
        flat = self.to_dict()
        plan, curve = _csv_plan(tuple(columns or CSV_COLUMNS))
        if curve:
            flat.update(curve_values(flat.get("frequencies_cy_px"), flat.get("mtf")))
        row = {}
        for column, key, index in plan:
            value: Any = flat.get(key) if index is None else (flat.get(key) or (None, None))[index]
            kind = type(value)          # the plain types first, by their exact type: 120 columns a row
            if kind is float:
                value = value + 0.0 if math.isfinite(value) else None       # as json_safe
            elif kind is list or kind is tuple or kind is dict:
                value = dumps_sorted(value)
            elif not (value is None or kind is str or kind is int or kind is bool):
                if isinstance(value, (list, tuple, dict)):
                    value = dumps_sorted(value)
                elif isinstance(value, float):
                    value = json_safe(value)
            row[column] = "" if value is None else value
        return row


# The summary columns of measure and batch rows: provenance, outcome,
# figures (units in the names; MTF values are dimensionless, 1 at zero
# frequency).
SUMMARY_COLUMNS: tuple[str, ...] = (
    "path", "band", "target", "method", "status", "reason", "error",
    "direction", "normal_angle_deg", "tilt_deg", "polarity", "rows_used", "snr",
    "mtf_nyquist", "mtf_nyquist_ci_low", "mtf_nyquist_ci_high",
    "mtf50_cy_px", "mtf50_ci_low_cy_px", "mtf50_ci_high_cy_px",
    "fwhm_px", "mtfa", "rer", "gsd_m", "mtf50_cy_m", "fwhm_m", "noise_limit_cy_px", "mtf_peak", "mtf_peak_cy_px",
    "sharpened",
    "pulse_width_px", "roi_px", "feature_id", "feature", "feature_window_px",
    "radial_distance_px", "radial_angle_deg", "field_direction",
    "warnings", "plot", "params", "imgmtf_version", "run_utc",
)
# each kind of target's own figures (imgmtf.kinds.Kind.record_fields) are
# columns too: the edge's and the bar's sit among the figures above, where
# they always were; a kind registered later adds its own after them
SUMMARY_COLUMNS += tuple(name for kind in KINDS.values() for name in kind.record_fields
                         if name not in SUMMARY_COLUMNS)
# The MTF curve, one column per frequency along the normal: 0 to 1 cy/px
# in steps of 0.05 (0.25 and 0.5 cy/px among them), so that a spreadsheet
# can plot and compare the rows; JSON Lines carry the whole curve (0.01 cy/px).
CURVE_FREQUENCIES_CY_PX = tuple(round(0.05 * i, 2) for i in range(21))
CURVE_COLUMNS = tuple(f"mtf_at_{f:.2f}_cy_px" for f in CURVE_FREQUENCIES_CY_PX)
# The CSV schema of measure and batch rows
CSV_COLUMNS = SUMMARY_COLUMNS + CURVE_COLUMNS
# what a scan adds: the candidate's rank and where it lies in the scene
# (pixel coordinates, x right, y down; map coordinates in the scene's CRS
# units), its screening figures and which stage gave its verdict
# (``verdict_by``: ``screen`` or ``gate``); ``scope`` tells a candidate
# (``edge``) from a summary that combines the accepted half-edges of a
# target or of the scene per direction (``target``, ``scene``), with its
# ``n_edges``, ``edge_ids`` (the candidates' ids), ``consistency`` (the
# Birge ratio of their MTF at Nyquist), the lowest SNR among them
# (``snr_min``) and a target's centre (``x_px``, ``y_px``); its ``fwhm_px``
# and ``rer`` are its half-edges' averaged with the weights of the MTF at
# Nyquist.  ``summary`` tells a combination along a measured normal
# (``combined``) from the sensor model fitted to the half-edges and read
# across and along track (``fit``, :mod:`imgmtf.scene.targetfit`), whose
# rows add the ``stages`` fitted, their ``reduced_chi_square``, whether the
# model does not fit (``misfit``, with the smallest p-value of the
# half-edges' residual structure, ``misfit_p``) and from the 2-D MTF's
# sections without a model (``sections``, :mod:`imgmtf.scene.sections`),
# whose rows name the ``assumption`` they hold under (separable, elliptical,
# or the bracket spanning both); of every across/along row one per scope,
# target and direction is ``recommended`` (``recommended_because`` says why;
# a misfit fit never is)
#: a scan row's ``scope``: one candidate (a half-edge, or a bar: named
#: "edge" whatever the target kind), or a summary of a target or of the scene
CANDIDATE_SCOPE = "edge"
TARGET_SCOPE = "target"
SCENE_SCOPE = "scene"
SCAN_COLUMNS = (
    "id", "rank", "scope", "target_id", "x0_px", "y0_px", "x1_px", "y1_px", "length_px", "line_length_px",
    "map_x0", "map_y0", "map_x1", "map_y1", "bar_width_px", "line_rms_px", "side_variation", "verdict_by",
    "summary", "n_edges", "edge_ids", "consistency", "weights", "snr_min", "x_px", "y_px",
    "stages", "reduced_chi_square", "misfit", "misfit_p", "assumption", "recommended", "recommended_because",
)

# a scan's CSV: id and rank first, then the summary, the site's columns, the curve
SCAN_CSV_COLUMNS = SCAN_COLUMNS[:2] + SUMMARY_COLUMNS + SCAN_COLUMNS[2:] + CURVE_COLUMNS

# CSV columns that are not a key of the flat record: (key, index) of a pair, or the key
_CSV_SOURCES = {
    "mtf_nyquist_ci_low": ("mtf_nyquist_ci", 0), "mtf_nyquist_ci_high": ("mtf_nyquist_ci", 1),
    "mtf50_ci_low_cy_px": ("mtf50_ci_cy_px", 0), "mtf50_ci_high_cy_px": ("mtf50_ci_cy_px", 1),
    "roi_px": "roi",
}
_CURVE_COLUMN_FREQUENCY = dict(zip(CURVE_COLUMNS, CURVE_FREQUENCIES_CY_PX))


@functools.lru_cache(maxsize=16)
def _csv_plan(columns: tuple[str, ...]) -> tuple[tuple[tuple[str, str, int | None], ...], bool]:
    """Each CSV column's source in the flat record (its key, and the index
    of an interval's bound), and whether the columns hold the curve's:
    worked out once per schema rather than per row."""
    plan = []
    for column in columns:
        source = _CSV_SOURCES.get(column, column)
        plan.append((column, *source) if isinstance(source, tuple) else (column, source, None))
    return tuple(plan), any(c in _CURVE_COLUMN_FREQUENCY for c in columns)


def curve_values(frequencies_cy_px, mtf) -> dict[str, float | None]:
    """The MTF curve at :data:`CURVE_FREQUENCIES_CY_PX`, keyed by CSV
    column (linear between the curve's samples; None outside the curve or
    where it is undefined, e.g. at a bar's sinc zeros)."""
    if not frequencies_cy_px or not mtf:
        return dict.fromkeys(CURVE_COLUMNS)
    f = np.asarray(frequencies_cy_px, float)
    m = np.array([np.nan if v is None else v for v in mtf], float)
    wanted = np.asarray(CURVE_FREQUENCIES_CY_PX)
    values = np.where((wanted >= f[0] - 1e-9) & (wanted <= f[-1] + 1e-9), np.interp(wanted, f, m), np.nan)
    return dict(zip(CURVE_COLUMNS, finite_values(values)))


def to_json(record: Record) -> str:
    """One JSON Lines line (no newline); NaN and infinities as null, -0.0
    as 0.0 (:func:`json_safe`)."""
    return dumps_safe(record.to_dict())


class JsonRows:
    """Records as JSON Lines (:func:`to_json`, the same text), the
    frequency grid that every row of a run repeats (101 values, a third of
    a dense chart's encoding) encoded once.

    Examples
    --------
    >>> rows = JsonRows()
    >>> r = Record("a.tif", 1, "edge", "msg", "ok", figures={"frequencies_cy_px": [0.0, 0.5], "mtf": [1.0, 0.3]})
    >>> rows.line(r) == to_json(r) == rows.line(r)
    True
    """

    #: keys whose value, a list of floats, is the same in row after row
    REPEATED = ("frequencies_cy_px",)

    def __init__(self) -> None:
        self._known: dict[str, tuple[list, str]] = {}

    def line(self, record: Record) -> str:
        """One JSON Lines line (no newline), as :func:`to_json` writes it."""
        row = record.to_dict()
        if not any(key in row for key in self.REPEATED):
            return dumps_safe(row)
        pieces, run = [], {}
        for key, value in row.items():
            known = self._text(key, value) if key in self.REPEATED else None
            if known is None:
                run[key] = value
                continue
            if run:
                pieces.append(ENCODER.encode(run)[1:-1])
                run = {}
            pieces.append(known)
        if run:
            pieces.append(ENCODER.encode(run)[1:-1])
        text = "{" + ", ".join(pieces) + "}"
        # a NaN, infinity or -0.0 among the other values: the whole row the safe way (made safe first:
        # dumps_safe(row) would encode the row again only to find what this text already shows)
        return dumps_safe(json_safe(row)) if has_unsafe_value(text) else text

    def _text(self, key: str, value) -> str | None:
        """``"key": value`` as JSON when ``value`` is a list of floats,
        from the last such list under ``key`` when it is equal (floats
        only: 1 == 1.0 == True, which JSON writes apart; -0.0 == 0.0, which
        json_safe writes alike), else None."""
        if type(value) is not list or not value or set(map(type, value)) != {float}:
            return None
        known = self._known.get(key)
        if known is None or known[0] != value:
            known = (list(value), f"{ENCODER.encode(key)}: {dumps_safe(value)}")
            self._known[key] = known
        return known[1]


class CsvWriter:
    """Write records as CSV rows as they come, each flushed to disk, into a
    file that appears in place atomically when closed.  An interrupt (Ctrl-C,
    SIGTERM) keeps the rows written so far (see
    :func:`imgmtf.atomic.atomic_output`).

    Examples
    --------
    >>> with CsvWriter("summary.csv") as out:        # doctest: +SKIP
    ...     for record in records:
    ...         out.write(record)
    """

    def __init__(self, path: str, columns=CSV_COLUMNS):
        self.path, self.columns, self.rows = str(path), tuple(columns), 0
        self._output = atomic_output(self.path, keep_partial=True)

    def __enter__(self) -> CsvWriter:
        partial = self._output.__enter__()
        try:
            self._file = open(partial, "w", newline="", encoding="utf-8")
        except OSError as exc:
            self._output.__exit__(type(exc), exc, exc.__traceback__)
            raise FileWriteError(f"{self.path}: cannot write: {exc.strerror or exc}") from None
        # rows as lists in the columns' order (csv.DictWriter's check of each row's keys cost as much as
        # the writing): what DictWriter writes
        self._writer = csv.writer(self._file)
        self._guarded(self._writer.writerow, self.columns)
        return self

    def write(self, record: Record) -> None:
        row = record.csv_row(self.columns)
        self._guarded(self._writer.writerow, [row[column] for column in self.columns])
        self.rows += 1

    def _guarded(self, action, *args) -> None:
        try:
            action(*args)
            self._file.flush()
        except OSError as exc:
            raise FileWriteError(f"{self.path}: cannot write: {exc.strerror or exc}") from None

    def __exit__(self, kind, exc, tb):
        self._file.close()
        return self._output.__exit__(kind, exc, tb)


class JsonLinesWriter:
    """Write records as JSON Lines to an open text stream (stdout), one
    line per record, flushed at once."""

    def __init__(self, stream: IO[str]):
        self.stream = stream
        self._rows = JsonRows()

    def write(self, record: Record) -> None:
        write_whole(self.stream, self._rows.line(record) + "\n")


def write_whole(stream: IO[str], text: str) -> None:
    """``text`` written to ``stream`` in full and flushed: to a file's
    descriptor, each partial write followed by the rest.  Through Python's
    buffered writer, a signal arriving while a long line waited on a full
    pipe (a scan's rows, 10-20 KB each, read by a slow consumer) lost the
    rest of that line, and the next line followed on it: a row cut in two
    is a row lost."""
    import os
    try:
        fd = stream.fileno()
    except (AttributeError, OSError, ValueError):       # not a file (a StringIO, a test's runner)
        stream.write(text)
        stream.flush()
        return
    stream.flush()
    view = memoryview(text.encode("utf-8"))
    while view:
        view = view[os.write(fd, view):]


def write_csv(records, path: str, columns=CSV_COLUMNS) -> None:
    """All ``records`` as one CSV file (atomically)."""
    with CsvWriter(path, columns) as out:
        for record in records:
            out.write(record)

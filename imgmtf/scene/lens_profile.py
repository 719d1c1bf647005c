"""A lens profile from a scanned chart: MTF50 and the MTF at chosen
frequencies against the distance from the optical centre, sagittal and
meridional apart, as MTF Mapper's lens profile gives them.

It reads the accepted candidates of a scan run with an optical centre
(:class:`imgmtf.ScanSettings` ``optical_centre``: each candidate's
``radial_distance_px`` and ``field_direction``), and groups them into rings
of equal width from the centre to the farthest edge: per ring and
direction, the number of edges and the medians of their MTF50 and of their
MTF at each frequency (a median, so that one poor edge does not move it).
"""
from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..estimate.field import MERIDIONAL, SAGITTAL
from ..records import Record

#: the frequencies a profile reads by default, cy/px (a quarter and half of Nyquist)
DEFAULT_FREQUENCIES_CY_PX = (0.125, 0.25)
DEFAULT_RINGS = 5


@dataclass(frozen=True)
class ProfileEdge:
    """One edge of the profile: its distance from the optical centre (px),
    ``field_direction``, MTF50 (cy/px) and MTF at the profile's frequencies."""

    radius_px: float
    field_direction: str
    mtf50_cy_px: float
    mtf: tuple[float, ...]


@dataclass(frozen=True)
class ProfileRing:
    """One ring of the profile and one direction: its radii (px), the
    number of edges in it and their median MTF50 and MTF at each frequency."""

    field_direction: str
    inner_px: float
    outer_px: float
    n_edges: int
    mtf50_cy_px: float
    mtf: tuple[float, ...]

    @property
    def radius_px(self) -> float:
        """The ring's middle radius, px."""
        return (self.inner_px + self.outer_px) / 2


@dataclass(frozen=True)
class LensProfile:
    """MTF50 and MTF at ``frequencies_cy_px`` against the distance from the
    optical centre, per edge and per ring, sagittal and meridional.

    Attributes
    ----------
    frequencies_cy_px : tuple of float
        The frequencies the MTF is read at, cy/px.
    centre_px : (float, float)
        The optical centre, px.
    edges : tuple of ProfileEdge
        Every accepted edge with a field direction, by radius.
    rings : tuple of ProfileRing
        Per ring (from the centre out) and direction, sagittal first.
    """

    frequencies_cy_px: tuple[float, ...]
    centre_px: tuple[float, float]
    edges: tuple[ProfileEdge, ...]
    rings: tuple[ProfileRing, ...]

    def rows(self) -> list[dict]:
        """The rings as table rows (units in the keys; MTF 1 at zero frequency)."""
        return [{"field_direction": r.field_direction, "inner_px": round(r.inner_px, 1),
                 "outer_px": round(r.outer_px, 1), "n_edges": r.n_edges,
                 "mtf50_cy_px": _rounded(r.mtf50_cy_px),
                 **{f"mtf_at_{f:g}_cy_px": _rounded(m) for f, m in zip(self.frequencies_cy_px, r.mtf)}}
                for r in self.rings]


def lens_profile(records: Iterable[Record], frequencies_cy_px: Sequence[float] = DEFAULT_FREQUENCIES_CY_PX,
                 rings: int = DEFAULT_RINGS) -> LensProfile:
    """The lens profile of a scan's accepted edges.

    Parameters
    ----------
    records : iterable of Record
        A scan's records (:func:`imgmtf.scan_scene` with an
        ``optical_centre``); those accepted with a field direction count.
    frequencies_cy_px : sequence of float, optional
        Where the MTF is read, cy/px (0 to 1; default 0.125 and 0.25).
    rings : int, optional
        How many rings of equal width the field is cut into, from the
        centre to the farthest edge (default 5).

    Returns
    -------
    LensProfile
        Per edge and per ring, sagittal and meridional.

    Raises
    ------
    ParameterError
        Frequencies outside 0 to 1 cy/px, fewer than one ring, or no
        accepted edge placed in the field (a scan without an optical
        centre, or nothing accepted).

    Examples
    --------
    >>> from imgmtf.records import Record
    >>> def edge(r, direction, mtf50):
    ...     site = {"radial_distance_px": r, "field_direction": direction, "optical_centre_px": [0, 0]}
    ...     figures = {"mtf50_cy_px": mtf50, "frequencies_cy_px": [0.0, 0.5], "mtf": [1.0, 1 - mtf50]}
    ...     return Record("chart.png", 1, "edge", "msg", "accepted", site=site, figures=figures)
    >>> profile = lens_profile([edge(10.0, "sagittal", 0.3), edge(90.0, "sagittal", 0.2),
    ...                         edge(80.0, "meridional", 0.1)], frequencies_cy_px=[0.25], rings=2)
    >>> [(r.field_direction, r.n_edges, r.mtf50_cy_px) for r in profile.rings]
    [('sagittal', 1, 0.3), ('sagittal', 1, 0.2), ('meridional', 1, 0.1)]
    """
    frequencies = tuple(float(f) for f in frequencies_cy_px)
    if not frequencies or not all(0.0 < f <= 1.0 for f in frequencies):
        raise ParameterError(f"a lens profile's frequencies must lie in (0, 1] cy/px, got {list(frequencies)}")
    if not (isinstance(rings, int) and rings >= 1):
        raise ParameterError(f"a lens profile needs at least one ring, got {rings!r}")
    placed = [r for r in records if r.ok and r.get("field_direction") in (SAGITTAL, MERIDIONAL)]
    if not placed:
        raise ParameterError("no accepted edge has a place in a lens's field: the scan was given no optical "
                             "centre, or accepted no edge")
    edges = tuple(sorted((_edge(r, frequencies) for r in placed), key=lambda e: e.radius_px))
    outer = max(e.radius_px for e in edges) * (1 + 1e-9)
    bounds = np.linspace(0.0, outer, rings + 1)
    out = []
    for direction in (SAGITTAL, MERIDIONAL):
        for inner, outer_px in itertools.pairwise(bounds):
            members = [e for e in edges if e.field_direction == direction and inner <= e.radius_px < outer_px]
            if members:
                out.append(ProfileRing(direction, float(inner), float(outer_px), len(members),
                                       _median([e.mtf50_cy_px for e in members]),
                                       tuple(_median([e.mtf[k] for e in members]) for k in range(len(frequencies)))))
    centre = tuple(placed[0].get("optical_centre_px") or (math.nan, math.nan))
    return LensProfile(frequencies, (float(centre[0]), float(centre[1])), edges, tuple(out))


def _edge(record: Record, frequencies: tuple[float, ...]) -> ProfileEdge:
    f = np.asarray(record.get("frequencies_cy_px") or [], float)
    m = np.array([np.nan if v is None else v for v in record.get("mtf") or []], float)
    values = tuple(float(np.interp(x, f, m)) if f.size and f[0] <= x <= f[-1] else math.nan for x in frequencies)
    mtf50 = record.get("mtf50_cy_px")
    return ProfileEdge(float(record.get("radial_distance_px")), record.get("field_direction"),
                       math.nan if mtf50 is None else float(mtf50), values)


def _median(values) -> float:
    finite = [v for v in values if math.isfinite(v)]
    return float(np.median(finite)) if finite else math.nan


def _rounded(value: float) -> float | None:
    return round(value, 4) if math.isfinite(value) else None


def write_lens_profile(profile: LensProfile, path: str) -> str:
    """The profile's rings as a CSV table (written atomically); its path.

    Raises
    ------
    FileWriteError
        The file cannot be written.
    """
    import csv

    from ..atomic import atomic_output
    from ..errors import FileWriteError
    rows = profile.rows()
    try:
        with atomic_output(path) as partial, open(partial, "w", newline="", encoding="utf-8") as out:
            writer = csv.DictWriter(out, fieldnames=list(rows[0]) if rows else ["field_direction"])
            writer.writeheader()
            writer.writerows({k: "" if v is None else v for k, v in row.items()} for row in rows)
    except OSError as exc:
        raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None
    return path

"""The segment graph: how the straight segments of a scene meet.

1. merge (:func:`merge_segments`, :func:`merge_pieces`): pieces of one line
   (across tiles too) with the same orientation are joined;
2. junctions (:func:`find_junctions`): where a segment ends on another or
   crosses it (the centre of a checkerboard or four-quadrant target, the
   corners of a rectangle or a cross); segments are split there into
   half-edges, each knowing the junctions at its ends and the segments it
   meets, so that its ROI can stop short of them;
3. bars (:func:`pair_bars`): two parallel segments a few pixels apart are
   the two sides of one bar.

Contacts between segments are found with a grid of cells over points
sampled along them (:func:`contacts`, :mod:`.neighbours`), so merging,
junctions and pairing cost about the number of segments times their
neighbours, never their square.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np

from .geometry import SAMPLE_STEP_PX, sample_points, segment_lengths, unit_vectors
from .neighbours import close_pairs, components, pairs_within

MERGE_ANGLE_DEG = 2.0        # pieces of one line differ by less than this in direction
MERGE_OFFSET_PX = 1.5        # ... lie within this of each other's line
MERGE_GAP_PX = 6.0           # ... and leave at most this gap between them
BAR_MAX_SEPARATION_PX = 8.0  # two parallel sides closer than this are one bar
JUNCTION_REACH_PX = 6.0      # a segment ending this close to another meets it (LSD stops short of corners)
JUNCTION_ANGLE_DEG = 20.0    # segments closer in direction do not make a junction
JUNCTION_MERGE_PX = 4.0      # meeting points closer than this are one junction
SPLIT_MARGIN_PX = 8.0        # a junction this far inside a segment splits it
MIN_SEGMENT_PX = 8.0         # shorter LSD output is noise, never a partner at a junction


@dataclass(frozen=True)
class Segment:
    """A straight segment from (x0, y0) to (x1, y1), pixel coordinates of
    the scene (x to the right, y down, pixel centres at integers), in LSD's
    orientation (its gradient on one hand).  ``width_px`` is 0 for an edge
    and the separation of its sides for a bar.

    Examples
    --------
    >>> s = Segment(10.0, 0.0, 12.0, 80.0)
    >>> round(s.length_px, 2), round(s.tilt_deg, 2), round(s.normal_angle_deg, 2)
    (80.02, 1.43, -1.43)
    """

    x0: float
    y0: float
    x1: float
    y1: float
    width_px: float = 0.0

    @property
    def length_px(self) -> float:
        return math.hypot(self.x1 - self.x0, self.y1 - self.y0)

    @property
    def tilt_deg(self) -> float:
        """Smallest angle (deg) between the segment and an image axis."""
        a = abs(math.degrees(math.atan2(self.y1 - self.y0, self.x1 - self.x0))) % 90.0
        return min(a, 90.0 - a)

    @property
    def normal_angle_deg(self) -> float:
        """Angle (deg, in (-90, 90]) of the segment's normal from the x axis
        towards +y, as the estimators report it (0: a vertical segment)."""
        angle = math.degrees(math.atan2(self.x1 - self.x0, -(self.y1 - self.y0)))
        return (angle + 90.0) % 180.0 - 90.0 if (angle + 90.0) % 180.0 != 0.0 else 90.0


@dataclass(frozen=True)
class HalfEdge:
    """A candidate target: a segment between junctions (or free ends).

    ``segment`` runs from end 0 to end 1, each end moved onto its junction
    when it has one; ``junctions`` are the junction ids at the two ends
    (None for a free end); ``partners`` the other segments that meet it
    there (its ROI keeps clear of them); ``line_length_px`` is the length
    of the straight line it was split from (for a bar, of its sides);
    ``fill_fraction`` how much of that line has fill or nodata beside it.
    """

    segment: Segment
    line_length_px: float
    junctions: tuple[int | None, int | None] = (None, None)
    partners: tuple[Segment, ...] = field(default=(), repr=False)
    fill_fraction: float = 0.0


@dataclass(frozen=True)
class Junction:
    """Where segments meet: ``x_px``, ``y_px`` and how many segments meet there."""

    x_px: float
    y_px: float
    degree: int


# -- LSD ----------------------------------------------------------------------------


# -- contacts between segments ------------------------------------------------------
def segment_rows(segments: list[Segment] | tuple[Segment, ...]) -> np.ndarray:
    """Segments as rows (x0, y0, x1, y1), n x 4 (without a NumPy array
    for each on the way)."""
    return np.array([(s.x0, s.y0, s.x1, s.y1) for s in segments], float).reshape(-1, 4)


@dataclass(frozen=True, eq=False)
class SampledSegments:
    """Segments (rows x0, y0, x1, y1) with points sampled every ``step``
    px or closer along each (:func:`sample_points`: ``points``, and
    ``owner``, the segment of each): sampled once, for every search of
    contacts with the same segments (the scan's junctions, straight lines
    and neighbours alike)."""

    segments: np.ndarray
    points: np.ndarray
    owner: np.ndarray
    step: float
    found: dict = field(default_factory=dict, init=False, repr=False)     # end_contacts, by radius

    @classmethod
    def of(cls, segments: np.ndarray, step: float = SAMPLE_STEP_PX) -> SampledSegments:
        segments = np.asarray(segments, float).reshape(-1, 4)
        points, owner = sample_points(segments, step)
        return cls(segments, points, owner, step)

    def end_contacts(self, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Which segments pass within about ``radius`` px of an end of
        which (:func:`contacts`): (segment, segment) pairs, each once, a
        segment with itself included; found once for each radius, for
        every step that asks (the junctions' reach and the straight
        lines' merging gap are one).  Read only: the arrays are shared."""
        if radius not in self.found:
            ends = self.segments.reshape(-1, 2)
            self.found[radius] = contacts(ends, self, radius, by=np.arange(len(ends)) // 2)
        return self.found[radius]


def rows_of(segments: np.ndarray | SampledSegments) -> np.ndarray:
    """The segments' rows (x0, y0, x1, y1), whether sampled or not."""
    if isinstance(segments, SampledSegments):
        return segments.segments
    return np.asarray(segments, float).reshape(-1, 4)


def contacts(queries: np.ndarray, s: np.ndarray | SampledSegments, radius: float,
             step: float = SAMPLE_STEP_PX, by: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Which segments pass within about ``radius`` px of which query
    points: (query index, segment index) pairs, each pair once; with
    ``by`` (one index per query: the segment it was sampled from), (that
    index, segment index) pairs, each once.  A grid over points
    sampled along the segments (every ``step`` px, or as sampled already
    when ``s`` is a :class:`SampledSegments`): the cost grows with the
    number of contacts, not with the square of the number of segments."""
    n = len(rows_of(s))
    if len(queries) == 0 or n == 0:
        return np.zeros(0, int), np.zeros(0, int)
    sampled = s if isinstance(s, SampledSegments) else SampledSegments.of(s, step)
    i, j = pairs_within(queries, sampled.points, radius + sampled.step / 2)
    first = i if by is None else np.asarray(by)[i]
    key = np.unique(first.astype(np.int64) * n + sampled.owner[j])
    return key // n, key % n


def _unique_pairs(a: np.ndarray, b: np.ndarray, n: int, ordered: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Distinct (a, b) index pairs (indices below ``n``); with ``ordered``
    false, (a, b) and (b, a) are one pair, given as (min, max)."""
    a, b = np.asarray(a, np.int64), np.asarray(b, np.int64)
    if not ordered:
        a, b = np.minimum(a, b), np.maximum(a, b)
    key = np.unique(a * n + b)
    return key // n, key % n


def _line_frame(s: np.ndarray, index: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t, d): positions of ``points`` along segments ``index`` from their
    start and signed distances from their lines (px)."""
    u = unit_vectors(s)[index]
    rel = points - s[index, :2]
    return np.einsum("ij,ij->i", rel, u), rel[:, 0] * -u[:, 1] + rel[:, 1] * u[:, 0]


# -- merging ------------------------------------------------------------------------
def merge_segments(pieces: np.ndarray) -> np.ndarray:
    """Join pieces (rows x0, y0, x1, y1) that lie on one line with the same
    orientation (so the same polarity): parallel within
    ``MERGE_ANGLE_DEG``, the shorter's ends within ``MERGE_OFFSET_PX`` of the
    longer's line, at most ``MERGE_GAP_PX`` apart along it (or
    overlapping).  Chains of such pieces become one segment through their
    length-weighted centre, along their mean direction, spanning all their
    ends.  Returns the segments (rows), longest first.

    Examples
    --------
    >>> merged = merge_segments(np.array([[10, 0, 11, 40], [11.1, 42, 12.2, 80], [30, 0, 30.5, 50]], float))
    >>> len(merged), round(float(np.hypot(*(merged[0, 2:] - merged[0, :2]))))
    (2, 80)
    """
    pieces = np.asarray(pieces, float).reshape(-1, 4)
    if len(pieces) < 2:
        return pieces.copy()
    merged = _joined(pieces, _merge_labels(pieces))
    return merged[np.argsort(-segment_lengths(merged), kind="stable")]


def merge_pieces(pieces: np.ndarray, beside_fill: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pieces of every tile merged into lines (:func:`merge_segments`),
    each with the length-weighted fraction of it that has fill beside it,
    longest first, those shorter than ``MIN_SEGMENT_PX`` left out."""
    label = _merge_labels(pieces)
    merged = _joined(pieces, label)
    lengths = segment_lengths(pieces)
    fill = np.bincount(label, lengths * beside_fill) / np.maximum(np.bincount(label, lengths), 1e-12)
    order = np.argsort(-segment_lengths(merged), kind="stable")
    merged, fill = merged[order], fill[order]
    keep = segment_lengths(merged) >= MIN_SEGMENT_PX
    return merged[keep], fill[keep]


def line_lengths(segments: np.ndarray | SampledSegments) -> np.ndarray:
    """For each segment, the length (px) of the straight line it lies on
    whatever the polarity: collinear segments that meet end to end (the
    two halves of a checkerboard's inner line, whose polarity flips at its
    centre) count as one line.  ``segments``: rows (x0, y0, x1, y1), or
    :class:`SampledSegments` of them (whose samples this reuses)."""
    sampled = segments if isinstance(segments, SampledSegments) else None
    segments = rows_of(segments)
    if len(segments) < 2:
        return segment_lengths(segments)
    units = unit_vectors(segments)
    flip = (units[:, 0] < 0) | ((units[:, 0] == 0) & (units[:, 1] < 0))
    canonical = np.where(flip[:, None], segments[:, [2, 3, 0, 1]], segments)
    # a segment turned round passes by the same points: the contacts of its ends are the same
    label = _merge_labels(canonical, sampled)
    return segment_lengths(_joined(canonical, label))[label]


def _merge_labels(pieces: np.ndarray, sampled: SampledSegments | None = None) -> np.ndarray:
    """Which merged line each piece belongs to (connected components of
    the pairs :func:`merge_segments` joins); ``sampled``: the same
    segments sampled (turned round or not: their ends are the same points),
    whose contacts this reuses."""
    lengths, units = segment_lengths(pieces), unit_vectors(pieces)
    a, b = (sampled or SampledSegments.of(pieces)).end_contacts(MERGE_GAP_PX)
    keep = a != b
    a, b = a[keep], b[keep]
    parallel = np.einsum("ij,ij->i", units[a], units[b]) >= math.cos(math.radians(MERGE_ANGLE_DEG))
    a, b = a[parallel], b[parallel]
    long_, short = np.where(lengths[a] >= lengths[b], a, b), np.where(lengths[a] >= lengths[b], b, a)
    t0, d0 = _line_frame(pieces, long_, pieces[short, :2])
    t1, d1 = _line_frame(pieces, long_, pieces[short, 2:])
    offset = np.maximum(np.abs(d0), np.abs(d1))
    gap = np.maximum(np.minimum(t0, t1) - lengths[long_], -np.maximum(t0, t1))
    join = (offset <= MERGE_OFFSET_PX) & (gap <= MERGE_GAP_PX)
    return components(len(pieces), a[join], b[join])[1]


def _joined(pieces: np.ndarray, label: np.ndarray) -> np.ndarray:
    """One segment per label: through the pieces' length-weighted centre,
    along their mean direction, spanning all their ends."""
    groups = int(label.max()) + 1 if label.size else 0
    lengths, units = segment_lengths(pieces), unit_vectors(pieces)
    weight = np.bincount(label, lengths, groups)
    direction = np.column_stack([np.bincount(label, lengths * units[:, k], groups) for k in (0, 1)])
    direction = direction / np.maximum(np.linalg.norm(direction, axis=1), 1e-12)[:, None]
    mid = (pieces[:, :2] + pieces[:, 2:]) / 2
    centre = np.column_stack([np.bincount(label, lengths * mid[:, k], groups)
                              for k in (0, 1)]) / np.maximum(weight, 1e-12)[:, None]
    t_ends = np.concatenate([np.einsum("ij,ij->i", pieces[:, :2] - centre[label], direction[label]),
                             np.einsum("ij,ij->i", pieces[:, 2:] - centre[label], direction[label])])
    both = np.concatenate([label, label])
    lo = np.full(groups, np.inf)
    hi = np.full(groups, -np.inf)
    np.minimum.at(lo, both, t_ends)
    np.maximum.at(hi, both, t_ends)
    return np.column_stack([centre + lo[:, None] * direction, centre + hi[:, None] * direction])


# -- junctions ----------------------------------------------------------------------
def _crossing(s: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Where the lines of segments ``a`` and ``b`` cross (n x 2; not
    parallel by construction)."""
    ua, ub = unit_vectors(s)[a], unit_vectors(s)[b]
    rel = s[b, :2] - s[a, :2]
    det = ua[:, 0] * ub[:, 1] - ua[:, 1] * ub[:, 0]
    t = (rel[:, 0] * ub[:, 1] - rel[:, 1] * ub[:, 0]) / np.where(np.abs(det) > 1e-12, det, 1e-12)
    return s[a, :2] + t[:, None] * ua


def find_junctions(segments: np.ndarray | SampledSegments) -> tuple[list[Junction], np.ndarray]:
    """Where segments meet: an end within ``JUNCTION_REACH_PX`` of another
    segment, or two segments crossing, at least ``JUNCTION_ANGLE_DEG``
    apart in direction.  Meeting points closer than ``JUNCTION_MERGE_PX``
    are one junction.

    ``segments``: rows (x0, y0, x1, y1), or :class:`SampledSegments` of
    them (whose samples this reuses).

    Returns the junctions and the events (rows: segment, partner, junction
    id, t of the junction along the segment in px from its start), one per
    segment and partner.
    """
    empty = np.zeros((0, 4))
    if len(rows_of(segments)) < 2:
        return [], empty
    sampled = segments
    if not isinstance(sampled, SampledSegments) or sampled.step != SAMPLE_STEP_PX:
        sampled = SampledSegments.of(rows_of(segments))
    segments = sampled.segments
    lengths, units = segment_lengths(segments), unit_vectors(segments)
    a, b = sampled.end_contacts(JUNCTION_REACH_PX)
    owner = sampled.owner
    near = close_pairs(sampled.points, SAMPLE_STEP_PX)
    a, b = _unique_pairs(np.concatenate([a, owner[near[:, 0]]]), np.concatenate([b, owner[near[:, 1]]]),
                         len(segments), ordered=False)
    a, b = a[a != b], b[a != b]
    cos = np.abs(np.einsum("ij,ij->i", units[a], units[b]))
    a, b = a[cos <= math.cos(math.radians(JUNCTION_ANGLE_DEG))], b[cos <= math.cos(math.radians(JUNCTION_ANGLE_DEG))]
    x = _crossing(segments, a, b)
    ta, _ = _line_frame(segments, a, x)
    tb, _ = _line_frame(segments, b, x)
    reach = JUNCTION_REACH_PX
    on_both = ((ta >= -reach) & (ta <= lengths[a] + reach) & (tb >= -reach) & (tb <= lengths[b] + reach))
    a, b, x, ta, tb = a[on_both], b[on_both], x[on_both], ta[on_both], tb[on_both]
    if len(a) == 0:
        return [], empty
    close = close_pairs(x, JUNCTION_MERGE_PX)
    count, label = components(len(x), close[:, 0], close[:, 1])
    members_n = np.bincount(label, None, count)[:, None]
    centre = np.column_stack([np.bincount(label, x[:, k], count) for k in (0, 1)]) / members_n
    events = np.vstack([np.column_stack([a, b, label, ta]), np.column_stack([b, a, label, tb])])
    members = np.unique(events[:, [0, 2]].astype(int), axis=0)
    degree = np.bincount(members[:, 1], None, count).astype(int)
    junctions = [Junction(float(cx), float(cy), int(d)) for (cx, cy), d in zip(centre, degree)]
    # each segment's position of each junction: its own projection of the junction's centre
    seg, jid = events[:, 0].astype(int), events[:, 2].astype(int)
    events[:, 3], _ = _line_frame(segments, seg, centre[jid])
    return junctions, events


def split_at_junctions(segments: np.ndarray | SampledSegments, junctions: list[Junction], events: np.ndarray,
                       fill_fraction: np.ndarray | None = None) -> list[HalfEdge]:
    """Every segment as half-edges: split where a junction lies more than
    ``SPLIT_MARGIN_PX`` inside it, its ends moved onto the junctions they
    reach.  Each half-edge carries the junction ids at its ends and the
    segments met there (its partners), the other halves of its own line
    included; ``fill_fraction`` (per segment, from :func:`detect_segments`)
    passes on to its halves.  ``segments``: rows (x0, y0, x1, y1), or
    :class:`SampledSegments` of them (whose samples this reuses)."""
    lines = line_lengths(segments).tolist()
    segments = rows_of(segments)
    lengths = segment_lengths(segments).tolist()
    fill = np.zeros(len(segments)) if fill_fraction is None else np.asarray(fill_fraction, float)
    fill = fill.tolist()
    rows_of_segments = segments.tolist()         # (plain floats: the half-edges' arithmetic is per segment)
    out = []
    by_segment: dict[int, list[tuple[int, float]]] = {}
    members: dict[int, set[int]] = {}
    for i, _, jid, t in events.tolist():        # (plain numbers: thousands of rows cost less out of NumPy)
        by_segment.setdefault(int(i), []).append((int(jid), t))
        members.setdefault(int(jid), set()).add(int(i))
    reached: dict[tuple[int, int], Segment] = {}

    def reaching(p: int, jid: int) -> Segment:
        """Partner ``p`` reaching junction ``jid`` (:func:`_reaching`), once for all who meet it there."""
        if (p, jid) not in reached:
            reached[p, jid] = _reaching(rows_of_segments[p], junctions[jid])
        return reached[p, jid]
    for i, row in enumerate(rows_of_segments):
        line = Segment(*row)
        cut_at = by_segment.get(i)
        if not cut_at:
            out.append(HalfEdge(line, lines[i], fill_fraction=fill[i]))
            continue
        x0, y0, x1, y1 = row
        ux, uy = (x1 - x0) / max(lengths[i], 1e-12), (y1 - y0) / max(lengths[i], 1e-12)
        # junctions on this segment, by position (the projection of their centre), and who meets there
        cuts = dict(cut_at)
        partners = {jid: sorted(members[jid] - {i}) for jid in cuts}
        # a junction near an end moves that end onto it (the innermost, if several); one
        # farther inside splits the segment there
        near_start = [(t, jid) for jid, t in cuts.items() if t < SPLIT_MARGIN_PX]
        near_end = [(t, jid) for jid, t in cuts.items() if t > lengths[i] - SPLIT_MARGIN_PX]
        inside = sorted((t, jid) for jid, t in cuts.items() if SPLIT_MARGIN_PX <= t <= lengths[i] - SPLIT_MARGIN_PX)
        stops = [(max(near_start)[0], max(near_start)[1], [jid for _, jid in near_start]) if near_start
                 else (0.0, None, [])]
        stops += [(t, jid, [jid]) for t, jid in inside]
        stops.append((min(near_end)[0], min(near_end)[1], [jid for _, jid in near_end]) if near_end
                     else (lengths[i], None, []))
        stops = [stop for k, stop in enumerate(stops) if k == 0 or stop[0] > stops[k - 1][0]]
        halves = [Segment(x0 + a[0] * ux, y0 + a[0] * uy, x0 + b[0] * ux, y0 + b[0] * uy) for a, b in pairwise(stops)]
        for k, (a, b) in enumerate(pairwise(stops)):
            met = [reaching(p, j) for j in a[2] + b[2] for p in partners[j]]
            met += [halves[m] for m in (k - 1, k + 1) if 0 <= m < len(halves)]
            out.append(HalfEdge(halves[k], lines[i], (a[1], b[1]), tuple(met), fill[i]))
    return out


def _reaching(s, junction: Junction) -> Segment:
    """Segment ``s`` with its end nearer ``junction`` moved onto it when the
    junction lies beyond that end (LSD stops short of where edges meet).
    (Plain floats: thousands of calls on two-element arrays cost more in
    NumPy's overhead than in arithmetic.)"""
    x0, y0, x1, y1 = (float(v) for v in s)
    length = math.hypot(x1 - x0, y1 - y0)
    ux, uy = (x1 - x0) / max(length, 1e-12), (y1 - y0) / max(length, 1e-12)
    t = (junction.x_px - x0) * ux + (junction.y_px - y0) * uy
    if t < 0:
        x0, y0 = x0 + t * ux, y0 + t * uy
    elif t > length:
        x1, y1 = x0 + t * ux, y0 + t * uy
    return Segment(x0, y0, x1, y1)


def parallel_clearance(candidates: list[Segment], segments: np.ndarray | SampledSegments,
                       reach_px: float) -> np.ndarray:
    """For each candidate, the distance (px) from its line to the nearest
    other segment that runs beside it: parallel within
    ``JUNCTION_ANGLE_DEG``, alongside it over part of its length, and
    farther than its own half-width (a bar's own sides do not count);
    ``inf`` when none lies within ``reach_px``.  ``segments``: rows (x0,
    y0, x1, y1), or :class:`SampledSegments` of them (whose samples this
    reuses)."""
    c = segment_rows(candidates)
    out = np.full(len(c), np.inf)
    near = segments
    segments = rows_of(segments)
    if len(c) == 0 or len(segments) == 0:
        return out
    widths = np.array([seg.width_px for seg in candidates])
    points, owner = sample_points(c, reach_px / 2)
    a, b = contacts(points, near, reach_px, by=owner)
    parallel = np.abs(np.einsum("ij,ij->i", unit_vectors(c)[a], unit_vectors(segments)[b])) >= math.cos(
        math.radians(JUNCTION_ANGLE_DEG))
    a, b = a[parallel], b[parallel]
    t0, d0 = _line_frame(c, a, segments[b, :2])
    t1, d1 = _line_frame(c, a, segments[b, 2:])
    length = segment_lengths(c)[a]
    lo, hi = np.maximum(np.minimum(t0, t1), 0.0), np.minimum(np.maximum(t0, t1), length)
    beside = hi - lo >= np.minimum(0.25 * length, 10.0)
    # the neighbour's distance where it runs beside the candidate (its line at the overlap's ends)
    span = np.where(np.abs(t1 - t0) > 1e-9, t1 - t0, 1e-9)
    at_lo = d0 + (d1 - d0) * (lo - t0) / span
    at_hi = d0 + (d1 - d0) * (hi - t0) / span
    distance = np.minimum(np.abs(at_lo), np.abs(at_hi))
    keep = beside & (distance > widths[a] / 2 + 1.0)
    np.minimum.at(out, a[keep], distance[keep])
    return out


# -- bars ---------------------------------------------------------------------------
def pair_bars(segments: list[Segment]) -> tuple[list[int], list[tuple[int, int, Segment]]]:
    """Pairs of parallel segments (within ``MERGE_ANGLE_DEG``, either
    orientation) 0.5 to ``BAR_MAX_SEPARATION_PX`` apart that overlap along
    half the shorter: the two sides of a bar.  Each segment pairs with its
    nearest such neighbour when that one's nearest is it too.

    Returns the indices of the lone segments and, per bar, the indices of
    its two sides and the bar as one segment along its centre line (over
    their overlap) with ``width_px`` the separation.

    Examples
    --------
    >>> lone, bars = pair_bars([Segment(10, 0, 12, 80), Segment(13, 0, 15, 80), Segment(40, 0, 41, 80)])
    >>> lone, [(i, j, round(bar.width_px, 2)) for i, j, bar in bars]
    ([2], [(0, 1, 3.0)])
    """
    s = segment_rows(segments)
    n = len(s)
    if n < 2:
        return list(range(n)), []
    lengths, units = segment_lengths(s), unit_vectors(s)
    points, owner = sample_points(s, BAR_MAX_SEPARATION_PX / 2)
    a, b = _unique_pairs(*contacts(points, s, BAR_MAX_SEPARATION_PX, by=owner), n, ordered=False)
    keep = (a != b) & (np.abs(np.einsum("ij,ij->i", units[a], units[b]))
                       >= math.cos(math.radians(MERGE_ANGLE_DEG)))
    a, b = a[keep], b[keep]
    t0, d0 = _line_frame(s, a, s[b, :2])
    t1, d1 = _line_frame(s, a, s[b, 2:])
    separation = np.abs((d0 + d1) / 2)
    overlap = np.minimum(np.maximum(t0, t1), lengths[a]) - np.maximum(np.minimum(t0, t1), 0.0)
    ok = ((separation > 0.5) & (separation <= BAR_MAX_SEPARATION_PX)
          & (overlap >= 0.5 * np.minimum(lengths[a], lengths[b])))
    a, b, separation = a[ok], b[ok], separation[ok]
    t0, t1, d0, d1 = t0[ok], t1[ok], d0[ok], d1[ok]
    best = np.full(n, np.inf)
    np.minimum.at(best, a, separation)
    np.minimum.at(best, b, separation)
    mutual = (separation == best[a]) & (separation == best[b])
    taken = np.zeros(n, bool)
    bars = []
    for k in np.nonzero(mutual)[0]:
        i, j = int(a[k]), int(b[k])
        if taken[i] or taken[j]:
            continue
        taken[i] = taken[j] = True
        u = units[i]
        normal = np.array([-u[1], u[0]])
        shift = (d0[k] + d1[k]) / 4
        start, end = max(min(t0[k], t1[k]), 0.0), min(max(t0[k], t1[k]), lengths[i])
        c0 = s[i, :2] + start * u + shift * normal
        c1 = s[i, :2] + end * u + shift * normal
        bars.append((i, j, Segment(float(c0[0]), float(c0[1]), float(c1[0]), float(c1[1]),
                                   width_px=float(2 * abs(shift)))))
    return [i for i in range(n) if not taken[i]], bars

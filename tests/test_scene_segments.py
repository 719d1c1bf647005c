"""The segment graph: merging by polarity, junctions and half-edges, bars,
segments running beside each other."""
import math

import numpy as np
import pytest

from imgmtf.scene.segments import (
    SampledSegments,
    Segment,
    find_junctions,
    line_lengths,
    merge_segments,
    pair_bars,
    parallel_clearance,
    split_at_junctions,
)


def length(row):
    return float(np.hypot(row[2] - row[0], row[3] - row[1]))


def test_merge_joins_collinear_pieces_of_one_polarity_only():
    pieces = np.array([[10, 0, 11, 40], [11.1, 42, 12.2, 80], [30, 0, 30.5, 50]], float)
    merged = merge_segments(pieces)
    assert len(merged) == 2 and length(merged[0]) == pytest.approx(80.0, abs=0.1)
    # the second piece reversed: LSD's orientation says its polarity flipped, as at a checkerboard's centre
    flipped = pieces.copy()
    flipped[1] = flipped[1, [2, 3, 0, 1]]
    assert len(merge_segments(flipped)) == 3
    # ... and both halves still count as one straight line 80 px long
    assert line_lengths(flipped) == pytest.approx([80.0, 80.0, 50.0], abs=0.2)


def test_merge_joins_overlapping_duplicates_from_neighbouring_tiles():
    pieces = np.array([[100, 900, 110, 1020], [108.3, 994, 117, 1100]], float)
    (merged,) = merge_segments(pieces)
    assert merged[1] == pytest.approx(900, abs=0.5) and merged[3] == pytest.approx(1100, abs=0.5)


def checkerboard_segments(centre=(50.0, 50.0), angle_deg=12.0, half=40.0, gap=1.5):
    """The four inner half-edges of a four-quadrant target as LSD gives
    them: each stops ``gap`` px short of the centre, alternate ones
    reversed (the polarity flips at the centre)."""
    a = math.radians(angle_deg)
    out = []
    for k, (ux, uy) in enumerate([(-math.sin(a), math.cos(a)), (math.cos(a), math.sin(a)),
                                  (math.sin(a), -math.cos(a)), (-math.cos(a), -math.sin(a))]):
        start = (centre[0] + gap * ux, centre[1] + gap * uy)
        end = (centre[0] + half * ux, centre[1] + half * uy)
        out.append([*start, *end] if k % 2 else [*end, *start])
    return np.array(out)


def test_a_checkerboard_centre_is_one_junction_of_four_half_edges():
    segments = checkerboard_segments()
    junctions, events = find_junctions(segments)
    assert len(junctions) == 1 and junctions[0].degree == 4
    assert (junctions[0].x_px, junctions[0].y_px) == pytest.approx((50.0, 50.0), abs=0.05)
    halves = split_at_junctions(segments, junctions, events)
    assert len(halves) == 4
    for half in halves:
        assert 0 in half.junctions and len(half.partners) == 3
        ends = [(half.segment.x0, half.segment.y0), (half.segment.x1, half.segment.y1)]
        # the end at the junction moved onto it; the line runs on through it: 2 x 40 px
        assert min(math.dist(e, (50.0, 50.0)) for e in ends) == pytest.approx(0.0, abs=0.05)
        assert half.line_length_px == pytest.approx(80.0, abs=0.5)


def test_a_line_crossing_another_is_split_into_two_half_edges():
    segments = np.array([[50, 0, 54, 100], [0, 40, 100, 46]], float)      # a cross: two straight lines
    junctions, events = find_junctions(segments)
    halves = split_at_junctions(segments, junctions, events)
    assert len(junctions) == 1 and len(halves) == 4
    # x = 50 + 0.04 y and y = 40 + 0.06 x meet at x = 51.6 / 0.9976
    crossing = (51.6 / 0.9976, 40 + 0.06 * 51.6 / 0.9976)
    assert (junctions[0].x_px, junctions[0].y_px) == pytest.approx(crossing, abs=0.05)
    ends = [(50, 0), (54, 100), (0, 40), (100, 46)]
    assert sorted(h.segment.length_px for h in halves) == pytest.approx(
        sorted(math.dist(e, crossing) for e in ends), abs=0.1)


def test_parallel_lines_and_distant_ends_make_no_junction():
    segments = np.array([[10, 0, 12, 80], [30, 0, 32, 80], [60, 0, 70, 80], [90, 95, 130, 100]], float)
    junctions, events = find_junctions(segments)
    assert junctions == [] and len(events) == 0
    assert all(h.junctions == (None, None) for h in split_at_junctions(segments, junctions, events))


def test_pairs_make_bars_and_their_width_is_the_separation():
    lone, bars = pair_bars([Segment(10, 0, 12, 80), Segment(13, 0, 15, 80), Segment(40, 0, 41, 80)])
    assert lone == [2] and [(i, j) for i, j, _ in bars] == [(0, 1)]
    assert bars[0][2].width_px == pytest.approx(3.0 * 80 / np.hypot(80, 2), abs=0.01)


def test_a_segment_beside_another_reports_how_far():
    segments = np.array([[10, 0, 12, 80], [22.25, 10, 23.75, 70], [60, 0, 62, 80]], float)
    near = parallel_clearance([Segment(10, 0, 12, 80)], segments, 20.0)
    assert near[0] == pytest.approx(12.0 * 80 / np.hypot(80, 2), abs=0.05)
    # a bar's own sides do not count
    assert parallel_clearance([Segment(10, 0, 12, 80, width_px=24.0)], segments, 20.0)[0] == np.inf


def test_sampled_segments_find_what_their_rows_find():
    # a checkerboard's four half-edges (its line's halves reversed) with a line crossing and one beside
    segments = np.vstack([checkerboard_segments(), [[20, 70, 90, 75], [61, 10, 69, 48]]])
    sampled = SampledSegments.of(segments)
    junctions, events = find_junctions(segments)
    assert find_junctions(sampled) == (junctions, pytest.approx(events)) and len(junctions) == 2
    assert split_at_junctions(sampled, junctions, events) == split_at_junctions(segments, junctions, events)
    assert list(line_lengths(sampled)) == pytest.approx(line_lengths(segments))
    candidates = [Segment(*row) for row in segments]
    assert list(parallel_clearance(candidates, sampled, 20.0)) == list(parallel_clearance(candidates, segments, 20.0))


def test_segment_angles_follow_the_estimators():
    s = Segment(10.0, 0.0, 12.0, 80.0)
    assert s.normal_angle_deg == pytest.approx(-math.degrees(math.atan(2 / 80)))
    # a near-horizontal line: its normal at 91.43 deg is the direction of -88.57 deg
    assert Segment(0, 5, 80, 7).normal_angle_deg == pytest.approx(math.degrees(math.atan(2 / 80)) - 90.0)
    assert s.tilt_deg == pytest.approx(math.degrees(math.atan(2 / 80)))

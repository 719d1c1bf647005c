"""The sides' uniformity checks made for many chips at once: each chip's
checks the ones it gets alone, a side too short to fit among them."""
from imgmtf.estimate.sides import side_checks, side_checks_many


def test_many_chips_sides_are_checked_as_each_alone(mixed_evidence):
    calls = [(ev.distance_px, ev.values, ev.rows.astype(float), ev.centre_px, ev.plateau_px, ev.contrast,
              (ev.pixel_noise, 1.5 * ev.pixel_noise), ev.tail_power, ev.side_names) for ev in mixed_evidence]
    short = (*calls[1][:4], 40.0, *calls[1][5:])          # no side holds 20 samples 40 px out
    together = side_checks_many([*calls, short])
    assert together == [side_checks(*call) for call in [*calls, short]]
    assert [c.outcome for c in together[-1]] == ["not-run", "not-run"]
    assert len({str(checks) for checks in together}) == len(together)

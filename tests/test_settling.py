"""The sides' settling check made for many chips at once: each chip's
outcome the one it gets alone."""
from imgmtf.estimate.settling import _side_fits, settled_sides, settled_sides_many


def test_many_chips_settle_as_each_alone(mixed_evidence):
    together = settled_sides_many(mixed_evidence + mixed_evidence[:2])
    assert together == [settled_sides(ev) for ev in mixed_evidence + mixed_evidence[:2]]
    # the chips differ where the check looks: fitted sides, a departure measured, and not
    fits = _side_fits(mixed_evidence)
    assert any(isinstance(fit, dict) and fit["departure"] is not None for fit in fits)
    assert len({str(c) for c, _ in together}) == len(mixed_evidence)

"""Many chips measured together (their first stages made, their edges' rows
and their blur check's groups fitted in stacks): every estimate the same,
to the bit, as the chip's alone, and every refusal the same refusal."""
import numpy as np

import imgmtf as im
from imgmtf.errors import ImgmtfError


def outcome(result):
    """The estimate's figures and curves, or its refusal (reason, message)."""
    if isinstance(result, ImgmtfError):
        return result.reason, str(result)
    return result.mtf_nyquist, result.mtf50_cy_px, result.mtf_nyquist_ci, result.esf.tolist(), result.warnings


def alone(estimate, chip, mask):
    try:
        return estimate(chip, mask=mask)
    except ImgmtfError as exc:
        return exc


def test_chips_measured_together_measure_as_alone_refusals_included():
    rng = np.random.default_rng(2)
    chips = [im.render(im.Sensor(), im.Target("edge", angle), rows, noise_std_dn=3.0, seed=seed).image
             for angle, rows, seed in ((5.0, 36, 1), (81.0, 36, 3), (7.0, 20, 4))]   # (transposed; no thirds)
    chips.append(rng.normal(1000.0, 5.0, (20, 20)))             # no edge: its seed's refusal
    chips.append(chips[0][:4])                                   # too small: refused before any seed
    masks = [None, np.ones(chips[1].shape, bool), None, None, None]
    estimate = im.EdgeEstimator(intervals=im.Intervals("influence"))
    together = estimate.measure_many(chips, masks)
    assert [isinstance(r, ImgmtfError) for r in together] == [False, False, False, True, True]
    for chip, mask, result in zip(chips, masks, together, strict=True):
        assert outcome(result) == outcome(alone(estimate, chip, mask))


def test_a_kind_without_row_fits_is_prefitted_without_them():
    from imgmtf.estimate.prefit import prefit_chips
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, width_px=3.0), 36, noise_std_dn=2.0, seed=4).image
    (prefit,) = prefit_chips(PulseKind(), [chip], make_settings(), [{}])
    assert prefit.fit is None and prefit.chip.pixels.shape == chip.shape


def test_the_blur_checks_of_many_chips_fitted_together_are_each_their_own_to_the_bit():
    # chips of one geometry (their groups padded alike: one stack), an edge whose blur changes along it,
    # and a bar's (its own stack): each chip's widths as its own check fits them
    from dataclasses import replace

    from imgmtf.estimate.blur_along import _group_masks, _group_widths, _splits, group_widths_many
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.evidence import evidence_of
    from imgmtf.estimate.pipeline import run
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    settings, rng = make_settings(), np.random.default_rng(5)
    evidence = []
    for kind, target in ((EdgeKind(), im.Target("edge", 6.0)), (PulseKind(), im.Target("pulse", 6.0, width_px=3.0))):
        m = run(kind, im.render(im.Sensor(), target, 48, noise_std_dn=2.0, seed=1).image, settings)
        ev = evidence_of(kind, m.chip, m.located, m.estimate.samples, m.shape, m.noise)
        evidence += [ev, replace(ev, values=ev.values + rng.normal(0, 20.0, ev.values.size))]
    evidence.insert(1, replace(evidence[0], values=evidence[0].values * (1 + 0.3 * (evidence[0].rows > 24))))
    together = group_widths_many(evidence)
    for ev, widths in zip(evidence, together, strict=True):
        assert widths == _group_widths(ev, _group_masks(ev, _splits(np.unique(ev.rows))))
    assert together[0] != together[2] and all(w is not None for w in together[0])

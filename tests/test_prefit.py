"""Many chips' first stages made together (their edges' rows fitted in one
stack): every estimate the same, to the bit, as the chip's alone, and every
refusal the same refusal."""
import numpy as np

import imgmtf as im
from imgmtf.errors import ImgmtfError


def outcome(estimate, chip, **keywords):
    """The estimate's figures and curves, or its refusal (reason, message)."""
    try:
        result = estimate(chip, **keywords)
    except ImgmtfError as exc:
        return exc.reason, str(exc)
    return result.mtf_nyquist, result.mtf50_cy_px, result.mtf_nyquist_ci, result.esf.tolist(), result.warnings


def test_chips_prefitted_together_measure_as_alone_refusals_included():
    rng = np.random.default_rng(2)
    chips = [im.render(im.Sensor(), im.Target("edge", angle), 36, noise_std_dn=3.0, seed=seed).image
             for angle, seed in ((5.0, 1), (81.0, 3))]            # (the second transposed)
    chips.append(rng.normal(1000.0, 5.0, (20, 20)))             # no edge: its seed's refusal
    chips.append(chips[0][:4])                                   # too few rows: refused before any seed
    masks = [None, np.ones(chips[1].shape, bool), None, None]
    estimate = im.EdgeEstimator(intervals=im.Intervals("influence"))
    prefits = estimate.prefit(chips, masks)
    assert prefits[0].fit is not None and prefits[1].fit is not None and prefits[3] is None
    assert isinstance(prefits[2].seed, ImgmtfError)
    for chip, mask, prefit in zip(chips, masks, prefits, strict=True):
        together = outcome(estimate, chip, mask=mask, **({} if prefit is None else {"prefit": prefit}))
        assert together == outcome(estimate, chip, mask=mask)


def test_a_kind_without_row_fits_is_prefitted_without_them():
    from imgmtf.estimate.prefit import prefit_chips
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings
    chip = im.render(im.Sensor(), im.Target("pulse", 6.0, width_px=3.0), 36, noise_std_dn=2.0, seed=4).image
    (prefit,) = prefit_chips(PulseKind(), [chip], make_settings(), [{}])
    assert prefit.fit is None and prefit.chip.pixels.shape == chip.shape

"""The saturation checks made for many chips at once: each chip's checks
the ones it gets alone, clipped and unclipped, noisy and noise-free."""
import numpy as np

from imgmtf.estimate.saturation import saturation_checks, saturation_checks_many


def test_many_chips_saturation_is_checked_as_each_alone(mixed_evidence):
    calls = []
    for ev in mixed_evidence:
        s = ev.distance_px - ev.centre_px
        sides = [(name, mask, None) for name, mask in zip(ev.side_names, (s <= -ev.plateau_px, s >= ev.plateau_px))]
        edge = ev.profile == "edge"
        calls.append(dict(distance=ev.distance_px, values=ev.values, centre=ev.centre_px, rise_px=ev.scale_px,
                          sides=sides, limits=(0.0, 65535.0), quantum=ev.quantum, noise_free=ev.pixel_noise < 0.1,
                          bright_core=None if edge else np.abs(s) < 0.5, monotone=edge, contrast=ev.contrast))
    rng = np.random.default_rng(5)
    d = np.sort(rng.uniform(-12.0, 12.0, 2000))
    edge = 200.0 + 1000.0 / (1.0 + np.exp(-d / 0.6))
    for values, noise_free in ((np.minimum(edge, 1000.0), True),                        # a held plateau
                               (np.minimum(np.rint(edge + rng.normal(0, 20, d.size)), 1190.0), False)):  # a pile-up
        calls.append(dict(distance=d, values=values, centre=0.0, rise_px=2.0, limits=None, quantum=1.0,
                          noise_free=noise_free, sides=[("dark", d <= -3.0, None), ("bright", d >= 3.0, None)]))
    together = saturation_checks_many(calls)
    assert together == [saturation_checks(**call) for call in calls]
    assert [c.outcome for c in together[-2]] == ["failed"] and "holds exactly 1000" in together[-2][0].message
    assert "failed" in [c.outcome for c in together[-1]] and "sit at exactly 1190" in together[-1][-1].message
    assert len({str(checks) for checks in together}) == len(together)

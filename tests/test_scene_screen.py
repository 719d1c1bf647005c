"""Scan screens: the geometry and the quick look's contrast and uniformity,
each with a case that trips it and one that passes."""
import numpy as np
import pytest

from imgmtf.scene.screen import quick_look


def band(levels=(300.0, 1500.0), noise=6.0, ramp=0.0, texture=0.0, seed=0, half=12, length=60):
    """The pixels of a band across an edge: (values, d, t)."""
    rng = np.random.default_rng(seed)
    t, d = np.meshgrid(np.arange(length, dtype=float), np.arange(-half, half + 1, dtype=float))
    values = np.where(d < 0, levels[0], levels[1]) + rng.normal(0, noise, d.shape)
    values += ramp * np.clip(d, 0, None) / half * (levels[1] - levels[0])
    values += texture * (levels[1] - levels[0]) * np.sin(t / 3.0) * (d > 0)
    return values.ravel(), d.ravel(), t.ravel()


def test_quick_look_passes_a_clean_edge():
    assert quick_look(*band(), noise_dn=6.0, half_width_px=12) is None


@pytest.mark.parametrize("kind, reason", [
    ({"ramp": 0.25}, "non-uniform"),             # the bright side brightens by 25 % of the contrast
    ({"texture": 0.12}, "non-uniform"),          # texture of 12 % of the contrast beyond the noise
    ({"levels": (300.0, 320.0), "noise": 6.0}, "snr"),
])
def test_quick_look_rejects_what_the_gate_would(kind, reason):
    verdict = quick_look(*band(**kind), noise_dn=kind.get("noise", 6.0), half_width_px=12)
    assert verdict is not None and verdict[0] == reason


def test_a_half_edge_is_as_long_as_the_longer_of_its_line_and_its_reach_to_the_junctions():
    from imgmtf.scene.screen import geometry_screen
    from imgmtf.scene.segments import HalfEdge, Segment
    from imgmtf.scene.settings import ScanSettings
    # LSD saw 36 px of the line; its ends, moved onto their junctions, span 46 px
    half = HalfEdge(Segment(10.0, 0.0, 16.0, 45.6), line_length_px=36.0, junctions=(1, 2))
    assert geometry_screen(half, ScanSettings()) is None
    short = HalfEdge(Segment(10.0, 0.0, 14.0, 39.6), line_length_px=36.0)
    reason, message = geometry_screen(short, ScanSettings())
    assert reason == "too-short" and "39.8 px long, shorter than the minimum 40 px" in message


def test_quick_looks_at_many_rois_give_each_its_own_verdict():
    from imgmtf.scene.screen import quick_looks
    # the last too small to judge
    kinds = [{}, {"ramp": 0.25}, {"levels": (300.0, 320.0)}, {"texture": 0.12, "seed": 3}, {"length": 1}]
    bands = [band(**kind) for kind in kinds]
    which = np.repeat(np.arange(len(bands)), [b[0].size for b in bands])
    values, d, t = (np.concatenate([b[k] for b in bands]) for k in range(3))
    got = quick_looks(values, d, t, which, [6.0] * len(bands), [12] * len(bands), [0.0] * len(bands))
    assert got == [quick_look(*b, noise_dn=6.0, half_width_px=12) for b in bands]
    assert [None if v is None else v[0] for v in got] == [None, "non-uniform", "snr", "non-uniform", None]


def test_quick_looks_at_bars_take_the_contrast_of_their_core():
    from imgmtf.scene.screen import quick_looks
    values, d, t = band(levels=(300.0, 300.0))
    strong, faint = values + 1200.0 * (np.abs(d) <= 1.5), values + 20.0 * (np.abs(d) <= 1.5)
    which = np.repeat([0, 1, 2], values.size)
    got = quick_looks(np.concatenate([strong, faint, values]), np.tile(d, 3), np.tile(t, 3), which,
                      [6.0] * 3, [12] * 3, [3.0, 3.0, 0.0])
    # the faint bar's 20 DN and the edge of no contrast are under MIN_SNR x 6 DN of noise
    assert got[0] is None and got[1][0] == "snr" and got[2][0] == "snr"

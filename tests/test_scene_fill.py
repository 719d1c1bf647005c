"""Fill and nodata: a region at a fill value with a hard boundary is fill, a
side clipped at the same value is not; a segment along fill is its boundary."""
import numpy as np

from imgmtf.scene.fill import fill_mask, fill_screen


def test_zero_fill_with_a_hard_boundary_is_fill_a_dark_side_clipped_at_zero_is_not():
    rng = np.random.default_rng(0)
    window = 900.0 + rng.normal(0, 5, (40, 40))
    window[:, 25:] = 0.0
    assert fill_mask(window, "uint16")[:, 25:].all() and not fill_mask(window, "uint16")[:, :25].any()
    # an 8-bit dark side clipped at 0 meets values close to 0: saturation, not fill
    clipped = np.clip(np.round(np.linspace(-20, 200, 40))[None, :].repeat(40, 0) + rng.normal(0, 2, (40, 40)), 0, 255)
    assert not fill_mask(np.round(clipped), "uint8").any()


def test_nodata_and_a_negative_sentinel_are_fill_a_saturated_side_is_not():
    window = np.where(np.arange(30)[None, :] < 15, 300.0, 900.0).repeat(30, 0)
    window[:5] = np.nan
    window[-5:] = -9999.0
    fill = fill_mask(window, "float32")
    assert fill[:5].all() and fill[-5:].all() and not fill[5:-5].any()
    saturated = np.where(np.arange(30)[None, :] < 15, 300.0, 65535.0).repeat(30, 0)
    saturated[:, 14:17] = [20000.0, 40000.0, 60000.0]            # the blurred rise up to the clip
    assert not fill_mask(saturated, "uint16").any()


def test_a_segment_with_fill_along_half_its_length_is_a_fill_boundary():
    assert fill_screen(0.5)[0] == "fill" and fill_screen(0.3) is None


def test_a_window_may_hold_fill_wherever_any_part_of_it_is_fill():
    from imgmtf.scene.fill import may_hold_fill
    rng = np.random.default_rng(1)
    ground = 900.0 + rng.normal(0, 5, (40, 40))
    assert not may_hold_fill(ground, "uint16") and not may_hold_fill(ground, "float32")
    for value, dtype in [(0.0, "uint16"), (np.nan, "float32"), (np.inf, "float32"), (-9999.0, "float32"),
                         (65535.0, "uint16")]:
        window = ground.copy()
        window[30:, 30:] = value                 # a corner of fill: part of the window is fill
        assert fill_mask(window[20:, 20:], dtype)[10:, 10:].all()
        assert may_hold_fill(window, dtype)
    # an integer type's greatest value is fill only in an integer scene
    window = ground.copy()
    window[30:, 30:] = 65535.0
    assert not may_hold_fill(window, "float32")

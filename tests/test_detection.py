import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ImageContentError, TargetNotFoundError
from imgmtf.estimate.detection import find_edge, parallel_within


@pytest.mark.parametrize("angle", [2.0, 6.0, -17.0, 38.0, 84.0, -70.0])
def test_finds_the_edge_within_a_degree(angle):
    img = im.render(im.Sensor(), im.Target("edge", angle), 80, noise_std_dn=20, seed=1).image
    line, rival = find_edge(img.astype(float))
    assert rival is None
    diff = (line.theta_deg - angle + 90) % 180 - 90
    assert abs(diff) <= 1.0


def test_a_second_edge_is_reported_as_a_rival():
    img = im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, 0, 8.0), 60).image
    line, rival = find_edge(img.astype(float))
    assert rival is not None
    assert parallel_within(line, rival, img.shape, 9.0) and not parallel_within(line, rival, img.shape, 7.0)


def test_noise_only_and_flat_images():
    noise = np.random.default_rng(0).normal(500, 20, (60, 60))
    with pytest.raises(TargetNotFoundError):
        find_edge(noise)
    with pytest.raises(ImageContentError, match="flat"):
        find_edge(np.full((40, 40), 7.0))


@pytest.mark.parametrize("size, at, angle", [(160, 100, 16.8), (200, 140, 73.2), (240, 180, 12.0)])
def test_a_short_edge_far_from_the_origin_is_one_line_not_a_bend(size, at, angle):
    # its 30-44 px of edge pixels also elect lines a few degrees off, whose rho differs by more
    # than the peak suppression's 5 px that far out; taking back a line's votes leaves one line
    shape = (30, 44) if abs(angle) < 45 else (44, 30)
    chip = im.render(im.Sensor(), im.Target("edge", angle, 2000, 9000), shape, noise_std_dn=20, seed=1).image
    frame, mask = np.zeros((size, size)), np.zeros((size, size), bool)
    frame[at:at + shape[0], at - 30:at - 30 + shape[1]] = chip
    mask[at:at + shape[0], at - 30:at - 30 + shape[1]] = True
    framed, alone = im.measure_edge(frame, mask=mask), im.measure_edge(chip.astype(float))
    assert framed.mtf_nyquist == pytest.approx(alone.mtf_nyquist, abs=0.001)


def test_robust_noise_is_the_mad_of_horizontal_differences_exactly():
    # its medians come from np.partition: exactly np.median's, odd and even counts, NaN pairs skipped
    from imgmtf.estimate.detection import robust_noise
    rng = np.random.default_rng(11)
    for shape in ((7, 8), (8, 9), (30, 31), (2, 2)):
        image = np.round(rng.normal(1000, 25, shape))
        image[rng.random(shape) < 0.2] = np.nan
        diff = np.diff(image, axis=1)
        diff = diff[np.isfinite(diff)]
        mad = np.median(np.abs(diff - np.median(diff)))
        assert robust_noise(image) == max(float(1.4826 * mad / np.sqrt(2.0)), 1e-12)
    assert robust_noise(np.full((5, 5), 7.0)) == 1e-12
    # integer pixels: their differences taken as floats, never wrapped (int16 32000 - -32000 overflows)
    wide = np.clip(np.round(rng.normal(0, 20000, (20, 21))), -32768, 32767)
    assert robust_noise(wide.astype(np.int16)) == robust_noise(wide) > 10000


@pytest.mark.parametrize("shape", [(48, 34), (3, 9), (2, 5)])
def test_a_chip_with_every_pixel_valid_is_weighted_and_bounded_as_its_mask_would_be(shape):
    # the smoothed mask and the interior kept by shape are what the masked path makes of an all-True mask
    import cv2

    from imgmtf.estimate import detection
    valid = np.ones(shape, bool)
    weight = cv2.GaussianBlur(valid.astype(np.float32), (17, 17), 2.0, borderType=cv2.BORDER_CONSTANT)
    assert np.array_equal(detection._full_weight(shape, 2.0), weight + np.float32(1e-12))
    eroded = cv2.erode(valid.astype(np.uint8), np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT,
                       borderValue=0).astype(bool)
    assert np.array_equal(detection._interior(valid), eroded)
    assert not detection._interior(valid).flags.writeable

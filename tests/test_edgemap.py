"""The seed search's Canny edge map and Hough accumulator give what
scikit-image's give on rendered chips, noise and photographs (they replace
them to keep SciPy out of a measurement's start-up; only floating-point ties
could part them), and the hysteresis keeps exactly the weak chains touching a
strong pixel."""
import numpy as np
import pytest
from skimage import data
from skimage.feature import canny as skimage_canny
from skimage.transform import hough_line as skimage_hough_line

import imgmtf as im
from imgmtf.estimate.detection import _THETAS
from imgmtf.estimate.edgemap import _hysteresis, canny, hough_line


def images():
    rng = np.random.default_rng(3)
    chips = [im.Renderer(im.Sensor(), 90)(im.Target("edge", angle, 200.0, 1200.0), noise_std_dn=25.0,
                                          seed=k).image for k, angle in enumerate((4.0, 37.0, -81.0))]
    for image in [*chips, rng.normal(size=(70, 110)), data.coins()[::2, ::2], data.camera()[::4, ::4]]:
        image = image.astype(float)
        lo, hi = np.percentile(image, [1, 99])
        yield (image - lo) / (hi - lo)


@pytest.mark.parametrize("options", [dict(low_threshold=0.1, high_threshold=0.2),
                                     dict(low_threshold=0.5, high_threshold=0.8, use_quantiles=True)])
@pytest.mark.parametrize("masked", [False, True])
def test_canny_is_scikit_images(options, masked):
    rng = np.random.default_rng(5)
    for image in images():
        mask = rng.random(image.shape) > 0.03 if masked else None
        expected = skimage_canny(image, sigma=2.0, mask=mask, **options)
        assert expected.sum() > 20
        np.testing.assert_array_equal(canny(image, 2.0, mask=mask, **options), expected)


def test_hough_accumulator_is_scikit_images():
    for image in images():
        edges = skimage_canny(image, sigma=2.0, low_threshold=0.1, high_threshold=0.2)
        expected, _, expected_rhos = skimage_hough_line(edges, theta=_THETAS)
        accumulator, _, rhos = hough_line(edges, _THETAS)
        np.testing.assert_array_equal(accumulator, expected)
        np.testing.assert_array_equal(rhos, expected_rhos)
        assert accumulator.sum() == edges.sum() * _THETAS.size       # one vote per pixel and angle


def test_hysteresis_keeps_the_chains_touching_a_strong_pixel():
    low = np.zeros((12, 12), bool)
    low[1, 1:8] = True               # a chain with a strong end ...
    low[2:9, 8] = True               # ... turning a corner, and continuing diagonally
    low[9, 9], low[10, 10] = True, True
    low[5, 1:5] = True               # a weak chain on its own
    low[11, 0] = True                # a lone weak pixel
    high = np.zeros_like(low)
    high[1, 1] = True
    kept = _hysteresis(low, high)
    expected = low.copy()
    expected[5, 1:5] = expected[11, 0] = False
    np.testing.assert_array_equal(kept, expected)
    assert not _hysteresis(low, np.zeros_like(low)).any()

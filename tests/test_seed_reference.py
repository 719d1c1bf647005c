"""The seed search (OpenCV's Canny and Hough transform) finds the line
scikit-image's ``feature.canny`` + ``transform.hough_line`` find, within the
1 deg it promises, on rendered chips, photographs and a masked chip; on
noise, where no line exists, its strongest line has the same support."""
import math

import numpy as np
import pytest
from skimage import data
from skimage.feature import canny
from skimage.transform import hough_line, hough_line_peaks

import imgmtf as im
from imgmtf.estimate.detection import find_lines

THETAS = np.deg2rad(np.arange(-90.0, 90.0, 0.5))


def reference_lines(image, mask=None):
    """scikit-image's strongest lines (theta deg, rho px, votes) on the
    image scaled to its 1st-99th percentile, as the seed search scales it."""
    valid = np.isfinite(image) if mask is None else mask
    lo, hi = np.percentile(image[valid], [1, 99])
    edges = canny(np.where(valid, (image - lo) / (hi - lo), 0.0), sigma=2.0, low_threshold=0.1,
                  high_threshold=0.2, mask=None if valid.all() else valid)
    accumulator, thetas, rhos = hough_line(edges, theta=THETAS)
    votes, theta, rho = hough_line_peaks(accumulator, thetas, rhos, num_peaks=4, min_distance=5,
                                         min_angle=16, threshold=0.25 * accumulator.max())
    return [(math.degrees(t), float(r), int(v)) for v, t, r in zip(votes, theta, rho)]


def angle_between(a, b):
    return abs((a - b + 90.0) % 180.0 - 90.0)


def chip(angle, seed):
    return im.Renderer(im.Sensor(), 90)(im.Target("edge", angle, 200.0, 1200.0), noise_std_dn=25.0,
                                        seed=seed).image.astype(float)


@pytest.mark.parametrize("image", [chip(4.0, 0), chip(37.0, 1), chip(-81.0, 2), chip(-17.0, 3),
                                   im.render(im.Sensor(), im.Target("pulse", 6.0, 200, 1200, 0, 8.0),
                                             60).image.astype(float),
                                   data.coins()[::2, ::2].astype(float), data.camera()[::4, ::4].astype(float)],
                         ids=["edge 4", "edge 37", "edge -81", "edge -17", "bar", "coins", "camera"])
def test_the_seed_is_scikit_images_strongest_line(image):
    # the reference's strongest line, or one as strong (a bar's two sides tie)
    seed, reference = find_lines(image)[0], reference_lines(image)
    strongest = [line for line in reference if line[2] >= 0.9 * reference[0][2]]
    assert any(same_line(seed, theta, rho) and seed.votes == pytest.approx(votes, rel=0.1)
               for theta, rho, votes in strongest), (seed, reference)


def same_line(seed, theta, rho):
    """Within 1 deg and 1.5 px (a normal near +-90 deg may be written
    either way: (theta, rho) and (theta -+ 180, -rho) are one line)."""
    flipped = abs(seed.theta_deg - theta) > 90
    return angle_between(seed.theta_deg, theta) <= 1.0 and abs(seed.rho_px - (-rho if flipped else rho)) <= 1.5


def test_a_masked_chip_with_left_out_pixels_is_seeded_alike():
    image = chip(23.0, 4)
    mask = np.random.default_rng(5).random(image.shape) > 0.03
    mask[:, :12] = False
    seed = find_lines(np.where(mask, image, np.nan))[0]
    theta, _, _ = reference_lines(image, mask)[0]
    assert angle_between(seed.theta_deg, theta) <= 1.0 and angle_between(seed.theta_deg, 23.0) <= 1.0


def test_noise_has_no_line_stronger_than_scikit_images():
    noise = np.random.default_rng(3).normal(size=(70, 110))
    seed, reference = find_lines(noise)[0], reference_lines(noise)[0]
    assert seed.votes == pytest.approx(reference[2], rel=0.25)

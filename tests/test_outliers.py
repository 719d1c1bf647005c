import numpy as np

from imgmtf.estimate.outliers import OUTLIER_CONTRAST, OUTLIER_NOISE, isolated_outliers


def by_definition(data, noise):
    """isolated_outliers pixel by pixel: beyond every other finite pixel of
    its 5 x 5 block by the margin and the block's range, no such neighbour."""
    finite = np.isfinite(data)
    low, high = np.percentile(data[finite], [1.0, 99.0])
    margin = max(OUTLIER_NOISE * noise, OUTLIER_CONTRAST * (high - low))
    rows, cols = data.shape
    out = np.zeros(data.shape, bool)
    for r in range(rows):
        for c in range(cols):
            block = data[max(r - 2, 0):r + 3, max(c - 2, 0):c + 3].copy()
            block[min(r, 2), min(c, 2)] = np.nan            # the pixel itself
            others = block[np.isfinite(block)]
            if not finite[r, c]:
                continue
            if others.size == 0:
                out[r, c] = True
                continue
            beyond = max(margin, others.max() - others.min())
            out[r, c] = data[r, c] > others.max() + beyond or data[r, c] < others.min() - beyond
    clustered = np.zeros(data.shape, bool)
    for r, c in zip(*np.nonzero(out)):
        ring = out[max(r - 1, 0):r + 2, max(c - 1, 0):c + 2].copy()
        ring[min(r, 1), min(c, 1)] = False
        clustered[r, c] = ring.any()
    return out & ~clustered


def test_hot_and_dead_pixels_are_found_as_defined_whichever_margin_decides():
    # the noise's margin (8 x 2 DN) or the contrast's (10 % of 1000 DN) the larger;
    # spikes below, between and above them, pairs (a feature), and NaN pixels
    rng = np.random.default_rng(7)
    found = 0
    for _ in range(12):
        data = np.where(np.arange(14) < 7, 100.0, 1100.0)[None, :] + rng.normal(0, 2.0, (12, 14))
        for height in rng.choice([-1, 1], 5) * rng.choice([10.0, 60.0, 400.0, 3000.0], 5):
            data[rng.integers(12), rng.integers(14)] += height
        data[rng.integers(12), rng.integers(14)] = np.nan
        noise = float(rng.choice([2.0, 20.0]))
        expected = by_definition(data, noise)
        assert np.array_equal(isolated_outliers(data, noise), expected)
        found += expected.sum()
    assert found > 0


def test_no_pixel_beyond_the_noise_margin_means_none():
    data = np.where(np.arange(20) < 10, 100.0, 1100.0)[None, :] + np.random.default_rng(1).normal(0, 2.0, (16, 20))
    data[5, 5] += 12.0              # within 8 noise sd of its block
    assert not isolated_outliers(data, 2.0).any()

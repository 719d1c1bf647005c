"""The row locator's bias with the sub-pixel phase: removed where it
repeats with the phase, noise and a bend left as they are."""
import numpy as np

from imgmtf.estimate.phase import phase_bias, phase_bias_many, without_phase_bias


def test_a_bias_that_repeats_with_the_phase_is_removed_and_noise_is_not():
    line = 0.105 * np.arange(100.0)                           # a 6 deg edge's phases, 100 rows
    bias = 0.25 * np.sin(2 * np.pi * line) + 0.08 * np.cos(4 * np.pi * line)
    noise = np.random.default_rng(1).normal(0, 0.2, line.size)
    left = without_phase_bias(bias + noise, line)
    assert np.std(left - noise) < 0.06                        # the bias gone, to the noise's own error
    assert abs(np.std(without_phase_bias(noise, line)) / np.std(noise) - 1) < 0.1
    # a bow along the rows does not repeat with the phase: it stays
    bow = 0.5 * ((np.arange(100.0) - 49.5) / 49.5) ** 2
    assert np.ptp(without_phase_bias(bow, line)) > 0.8 * np.ptp(bow)
    # a wild row does not take the model, and too few rows give none
    wild = bias.copy()
    wild[10] += 5.0
    assert abs(phase_bias(wild, line)[20] - bias[20]) < 0.02
    assert not phase_bias(bias[:10], line[:10]).any()


def test_many_targets_biases_are_each_alone():
    rng = np.random.default_rng(2)
    calls = []
    for slope, rows in ((0.105, 100), (0.2, 60), (0.03, 15), (0.07, 80)):
        line = slope * np.arange(float(rows))
        fit = rng.uniform(size=rows) > 0.1
        calls.append((0.2 * np.sin(2 * np.pi * line) + rng.normal(0, 0.1, rows), line, fit))
    together = phase_bias_many(calls)
    assert all(np.array_equal(a, phase_bias(*call)) for a, call in zip(together, calls))
    assert not together[2].any() and all(a.any() for k, a in enumerate(together) if k != 2)

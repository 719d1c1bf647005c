"""A bar's width read off its pulse response, against closed forms: a box's
and a blurred bar's spectrum zeros, a zero the noise made, and how a
reading moves with the profile."""
import math
import re

import numpy as np
import pytest

from imgmtf.errors import UnsuitableTargetError
from imgmtf.estimate.bar_width import ZERO_EVIDENCE_SD, estimate_width, sinc_log_slope, width_reading


def test_a_zero_the_noise_made_is_no_width_and_the_refusal_says_what_it_leaves_open():
    from scipy.optimize import brentq

    assert ZERO_EVIDENCE_SD == 2.5
    x = np.arange(-16, 16.0001, 0.05)
    sigma, ripple, f_ripple, envelope, noise = 0.6, 0.0024, 0.85, 4.0, 0.002

    def spectrum(f):      # a Gaussian pulse response (no zero) less a ripple crossing it near 0.83 cy/px
        return (math.sqrt(2 * math.pi) * sigma * np.exp(-2 * np.pi ** 2 * sigma ** 2 * f ** 2)
                - ripple * envelope * math.sqrt(2 * math.pi) / 2
                * np.exp(-2 * np.pi ** 2 * envelope ** 2 * (f - f_ripple) ** 2))
    prf = (np.exp(-x ** 2 / (2 * sigma ** 2))
           - ripple * np.cos(2 * np.pi * f_ripple * x) * np.exp(-x ** 2 / (2 * envelope ** 2)))
    zero = brentq(spectrum, 0.7, 0.85)
    assert estimate_width(x, prf) == pytest.approx(1 / zero, abs=2e-3)        # noise unknown: any zero is read
    with pytest.raises(UnsuitableTargetError, match="cannot be told from the noise") as info:
        estimate_width(x, prf, noise)
    assert info.value.reason == "bar-width"
    # the widest bar the noise could hide: where the spectrum falls to 2.5 sd of its noise, noise * sqrt(L / 2)
    f_low = brentq(lambda f: spectrum(f) - ZERO_EVIDENCE_SD * noise * math.sqrt(x.size * 0.05 / 2), 0.5, zero)
    widest, line, top = (float(v) for v in re.search(
        r"up to ([\d.]+) px wide, which puts the MTF at Nyquist anywhere from about ([\d.]+) \(a line\) to "
        r"([\d.]+)", str(info.value)).groups())
    assert widest == pytest.approx(1 / f_low, abs=0.006)                    # f on a 0.0025 cy/px grid
    assert line == pytest.approx(math.exp(-2 * np.pi ** 2 * sigma ** 2 * 0.25), abs=0.006)
    assert top == pytest.approx(line / np.sinc(0.5 * widest), abs=0.006)
    # a bar's zero, its negative lobe clear of that noise, is read
    assert estimate_width(x, (np.abs(x) <= 1.25).astype(float), noise) == pytest.approx(2.5, rel=1e-3)


def test_estimate_width_closed_form():
    x = np.arange(-10, 10.0001, 0.05)
    box = (np.abs(x) <= 1.25).astype(float)
    assert estimate_width(x, box) == pytest.approx(2.5, rel=0.02)


def test_the_width_reading_predicts_how_the_read_width_moves():
    from scipy.special import erf

    x = np.arange(-400, 401) * 0.05

    def blurred_bar(w, sigma=0.5):    # a bar of width w through a Gaussian PSF, in closed form
        return 0.5 * (erf((x + w / 2) / (math.sqrt(2) * sigma)) - erf((x - w / 2) / (math.sqrt(2) * sigma)))
    prf = blurred_bar(1.5)
    width = estimate_width(x, prf)
    assert width == pytest.approx(1.5, abs=1e-3)
    change = blurred_bar(1.52) - prf                   # the same bar 0.02 px wider
    reading = width_reading(x, prf, width, 1.0)
    assert reading.width_change(reading.on_grid[0] @ change) == pytest.approx(0.02, rel=0.02)
    assert reading.values[0] == pytest.approx(0.0, abs=1e-4)           # R(f0) = 0: the zero read


def test_sinc_log_slope_is_the_derivative_of_the_sincs_log():
    f, w, h = np.array([0.0, 0.2, 0.5, 0.9]), 1.5, 1e-6
    numeric = (np.log(np.abs(np.sinc(f * (w + h)))) - np.log(np.abs(np.sinc(f * (w - h))))) / (2 * h)
    assert sinc_log_slope(f, w) == pytest.approx(numeric, abs=1e-6)

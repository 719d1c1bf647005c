"""Shared helpers: exact edge responses computed independently of the
renderer (inverse FFT of an analytic 1-D transfer function)."""
import math

import numpy as np
import pytest

import imgmtf as im


def exact_esf(transfer, dx=1 / 512, n=1 << 16):
    """(x, esf) of a unit edge whose LSF has the 1-D transfer ``transfer(f)``
    (f in cycles per unit of x); esf[i] is the edge response at x[i]."""
    f = np.fft.rfftfreq(n, d=dx)
    lsf = np.fft.fftshift(np.fft.irfft(transfer(f), n=n)) / dx
    x = (np.arange(n) - n // 2) * dx
    esf = np.cumsum(lsf) * dx
    esf = (esf - esf[0]) / (esf[-1] - esf[0])
    return x + dx / 2, esf


def gaussian_pixel_transfer(sigma_px, angle_deg):
    """Transfer along the normal of Gaussian optics (sigma px) and a square
    1-px pixel, for an edge tilted ``angle_deg`` from the column axis."""
    a = math.radians(angle_deg)
    return lambda f: (np.exp(-2 * np.pi**2 * sigma_px**2 * f**2)
                      * np.sinc(f * math.cos(a)) * np.sinc(f * math.sin(a)))


def exact_edge_chip(transfer, angle_deg, shape=(100, 100), offset=0.0, low=200.0, high=1200.0,
                    noise_std=0.0, seed=0, dtype=np.uint16):
    """A chip whose every pixel is the exact edge response at its centre's
    signed distance from the edge (no renderer involved)."""
    rows, cols = shape
    a = math.radians(angle_deg)
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    d = (x - (cols - 1) / 2) * math.cos(a) + (y - (rows - 1) / 2) * math.sin(a) - offset
    fx, esf = exact_esf(transfer)
    img = low + (high - low) * np.interp(d, fx, esf)
    if noise_std:
        img = img + np.random.default_rng(seed).normal(0, noise_std, img.shape)
    if not np.issubdtype(dtype, np.integer):
        return img.astype(dtype)
    top = np.iinfo(dtype).max
    return np.clip(np.rint(img), 0, top).astype(dtype)


def true_mtf50(transfer):
    f = np.linspace(0, 1, 100001)
    m = np.abs(transfer(f))
    i = np.nonzero(m < 0.5)[0][0]
    return f[i - 1] + (m[i - 1] - 0.5) / (m[i - 1] - m[i]) * (f[i] - f[i - 1])


def true_fwhm(transfer):
    fx, esf = exact_esf(transfer)
    lsf = np.gradient(esf, fx)
    from imgmtf.metrics import fwhm
    return fwhm(fx, lsf)


@pytest.fixture(scope="session")
def paper_sensor():
    return im.Sensor()


@pytest.fixture(scope="session")
def gaussian_sensor():
    """Gaussian optics (0.5 px) and a square pixel only."""
    return im.Sensor(optics_sigma_x_m=0.5, optics_sigma_y_m=0.5, motion_m=0.0,
                     electronics_cutoff_cy_m=0.0)

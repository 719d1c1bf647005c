"""Shared helpers: exact edge responses computed independently of the
renderer (inverse FFT of an analytic 1-D transfer function)."""
import math
import os
import signal
from pathlib import Path

import numpy as np
import pytest

import imgmtf as im

#: the real scenes the project may read but not copy (../shared/data/real-scenes beside the
#: repository, or wherever IMGMTF_SHARED_DATA points: the folder holding real-scenes/)
SHARED_DATA_VARIABLE = "IMGMTF_SHARED_DATA"
SHARED_DATA = Path(os.environ.get(SHARED_DATA_VARIABLE) or Path(__file__).resolve().parents[2] / "shared" / "data")
REAL_SCENES = SHARED_DATA / "real-scenes"


def ctrl_c_as_at_a_terminal() -> None:
    """``preexec_fn`` for a command a test interrupts with SIGINT: the
    command starts with Ctrl-C's default action, as typed at a terminal.
    A process inherits an ignored SIGINT (a shell ignores it in a job it
    starts in the background without job control, as scripts and agents
    run the suite), and Python then leaves it ignored: the command would
    run to its end whatever the test sends."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def ctrl_c_raises():
    """Ctrl-C raises KeyboardInterrupt in this process during the test,
    even when the suite was started with SIGINT ignored (see
    :func:`ctrl_c_as_at_a_terminal`)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def real_scene(name: str, provenance: str = "") -> Path:
    """The path of a real scene, the test skipped when the shared data are
    absent; a folder IMGMTF_SHARED_DATA names must hold it (a failure, not
    a skip: whoever sets the variable wants these tests run)."""
    path = REAL_SCENES / name
    if not path.is_file():
        if os.environ.get(SHARED_DATA_VARIABLE):
            pytest.fail(f"{SHARED_DATA_VARIABLE}={os.environ[SHARED_DATA_VARIABLE]}: no real-scenes/{name} there")
        pytest.skip(f"{path} absent{f' (from {provenance})' if provenance else ''}: "
                    f"set {SHARED_DATA_VARIABLE} to the folder holding real-scenes/")
    return path


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


def diffraction_transfer(cutoff_cy_px):
    """A circular aperture's incoherent MTF, cut-off ``cutoff_cy_px``:
    (2/pi)(acos v - v sqrt(1 - v^2)), v = f / cut-off."""
    def transfer(f):
        v = np.clip(np.abs(f) / cutoff_cy_px, 0.0, 1.0)
        return (2 / np.pi) * (np.arccos(v) - v * np.sqrt(1.0 - v * v))
    return transfer


def defocus_transfer(radius_px):
    """A uniform defocus disk of ``radius_px``: 2 J1(2 pi r f) / (2 pi r f)."""
    from scipy.special import j1

    def transfer(f):
        z = np.maximum(2 * np.pi * radius_px * np.abs(f), 1e-12)
        return np.where(z > 1e-9, 2 * j1(z) / z, 1.0)
    return transfer


def olpf_transfer(split_px, angle_deg):
    """A 4-dot birefringent low-pass filter of split ``split_px`` along the
    normal of an edge tilted ``angle_deg``: cos(pi d fx) cos(pi d fy)."""
    a = math.radians(angle_deg)
    return lambda f: np.cos(np.pi * split_px * f * math.cos(a)) * np.cos(np.pi * split_px * f * math.sin(a))


def product(*transfers):
    return lambda f: np.prod([t(f) for t in transfers], axis=0)


@pytest.fixture(scope="session")
def mixed_evidence():
    """What the gate reads (:class:`imgmtf.estimate.evidence.Evidence`) of a
    few unlike chips: noise-free and noisy edges, a shaded side, a bar, an
    8-bit edge; for checks made for many chips at once against each alone."""
    from imgmtf.estimate.asks import answer
    from imgmtf.estimate.edge import EdgeKind
    from imgmtf.estimate.pipeline import run_steps
    from imgmtf.estimate.pulse import PulseKind
    from imgmtf.estimate.settings import make_settings

    def edge(angle, noise, seed=1, bits=16, shade=0.0):
        image = im.render(im.Sensor(), im.Target("edge", angle), 60, noise_std_dn=noise, seed=seed,
                          bits=bits).image.astype(float)
        return image + shade * np.arange(image.shape[1])[None, :]

    bar = im.render(im.Sensor(), im.Target("pulse", 4.0, width_px=3.0), 60, noise_std_dn=2.0, seed=2).image
    chips = [(EdgeKind(), edge(5.0, 0.0)), (EdgeKind(), edge(8.0, 2.0)), (EdgeKind(), edge(3.0, 4.0, shade=2.0)),
             (PulseKind(), bar), (EdgeKind(), np.clip(edge(7.0, 1.0) / 6.0, 0, 255))]
    evidence = []
    for kind, image in chips:
        steps = run_steps(kind, image, make_settings(force=True))
        ask = next(steps)
        while ask.name != "settled-sides":          # its asks answered alone up to the gate's
            ask = steps.send(answer(ask.name, [ask.payload])[0])
        evidence.append(ask.payload)
    return evidence

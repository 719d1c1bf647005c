"""Self-test: render generic-sensor chips with known MTF, measure them with
the estimators, and compare measured with true against stated tolerances.
This is the product's main job on an embedded default."""
from __future__ import annotations

from dataclasses import dataclass, field

from .estimate.results import MTFResult
from .kinds import get_kind
from .metrics import fwhm
from .sensor.model import Sensor
from .sensor.points import PointArray
from .sensor.rendering import Renderer
from .sensor.targets import Target

# Tolerances each case must meet (absolute for MTF at Nyquist, relative for
# MTF50 and FWHM).  Noise-free: the accuracy the estimator promises on exact
# chips.  Noisy (SNR 100): about 3 standard deviations of the estimate.
NOISE_FREE_TOLERANCE = {"mtf_nyquist": 0.003, "mtf50": 0.005, "fwhm": 0.005}
PULSE_TOLERANCE = {"mtf_nyquist": 0.005, "mtf50": 0.005, "fwhm": 0.01}
NOISY_TOLERANCE = {"mtf_nyquist": 0.03, "mtf50": 0.03, "fwhm": 0.05}
#: a 4 x 4 array of points at quarter-pixel offsets, noise-free: its stack is exact but for the
#: 16-bit rounding of its pixels and the 0.01 px grid its LSF's width is read on
POINTS_TOLERANCE = {"mtf_nyquist": 0.003, "mtf50": 0.005, "fwhm": 0.01}


@dataclass(frozen=True)
class SelftestCase:
    """One chip of the self-test: its target, its noise, and the tolerances
    (:data:`NOISE_FREE_TOLERANCE`, :data:`PULSE_TOLERANCE`) its figures
    meet without noise; with noise they meet :data:`NOISY_TOLERANCE`."""

    name: str
    target: Target
    noise_std_dn: float = 0.0
    seed: int = 0
    noise_free_tolerance: dict = field(default_factory=lambda: NOISE_FREE_TOLERANCE)
    #: its chip's side, px, where not the run's (None)
    size_px: int | None = None

    @property
    def tolerance(self) -> dict:
        return NOISY_TOLERANCE if self.noise_std_dn else self.noise_free_tolerance


CASES = (
    SelftestCase("edge across-track (6 deg)", Target("edge", 6.0, 200.0, 1200.0, 0.23)),
    SelftestCase("edge along-track (84 deg)", Target("edge", 84.0, 200.0, 1200.0, -0.31)),
    SelftestCase("edge falling, -11 deg", Target("edge", -11.0, 1200.0, 200.0, 0.11)),
    SelftestCase("edge across-track, SNR 100", Target("edge", 6.0, 200.0, 1200.0, 0.4),
                 noise_std_dn=10.0, seed=7),
    SelftestCase("pulse 1.5 px across-track", Target("pulse", 6.0, 200.0, 1200.0, 0.17, 1.5),
                 noise_free_tolerance=PULSE_TOLERANCE),
    SelftestCase("dark pulse 1.2 px along-track", Target("pulse", 85.0, 1200.0, 300.0, -0.2, 1.2),
                 noise_free_tolerance=PULSE_TOLERANCE),
    # the pair's transfer is zero at Nyquist: MTF at Nyquist is the fitted model's (Storey's method);
    # a 32 px chip: the fit costs about 20 % less than in a 48 px one (its bins span the profile)
    SelftestCase("double bar 1 px, 2 px gap", Target("double-bar", 6.0, 200.0, 1200.0, 0.17, 1.0, 2.0),
                 noise_free_tolerance=PULSE_TOLERANCE, size_px=32),
)


#: the point-target case: one row per direction (the stack gives both from one chip), 64 x 64 px
POINT_CASE = ("4x4 points", PointArray(4, 4, spacing_px=12.0, low_dn=200.0, high_dn=1200.0))
POINT_CHIP_PX = 64


@dataclass(frozen=True)
class SelftestRow:
    """One case of the self-test: true and measured figures (``mtf_nyquist``;
    ``mtf50``, cy/px; ``fwhm``, px), whether each is in tolerance, and the
    chip's measured SNR."""

    name: str
    true: dict
    measured: dict
    passed: dict
    snr: float

    @property
    def ok(self) -> bool:
        return all(self.passed.values())


def run_selftest(sensor: Sensor = Sensor(), size_px: int = 100, method: str = "msg") -> list[SelftestRow]:
    """Render every case of :data:`CASES` (edges and bars across and along
    track, noise-free and at SNR 100, a double bar whose MTF at Nyquist the
    fitted model reads, in a 32 px chip) and the point case
    (:data:`POINT_CASE`, a 64 x 64 px chip) through ``sensor``, measure them
    and compare the measured MTF at Nyquist, MTF50 and FWHM with the truth.

    Parameters
    ----------
    sensor : Sensor, optional
        The sensor (default the paper's generic sensor).
    size_px : int, optional
        Chip side, px (default 100), but for a case with its own.
    method : str, optional
        The resampling method (a key of :data:`imgmtf.METHODS`).

    Returns
    -------
    list of SelftestRow
        One per case: ``true`` and ``measured`` figures (``mtf_nyquist``,
        ``mtf50`` in cy/px, ``fwhm`` in px), ``passed`` per figure against
        its tolerance, ``ok``.

    Raises
    ------
    ParameterError
        An unknown method or a bad size.

    Examples
    --------
    >>> import imgmtf
    >>> rows = imgmtf.run_selftest()
    >>> all(row.ok for row in rows), rows[0].name
    (True, 'edge across-track (6 deg)')
    """
    renderers = {size_px: Renderer(sensor, size_px)}
    rows = []
    for case in CASES:
        size = case.size_px or size_px
        renderer = renderers.setdefault(size, Renderer(sensor, size))
        chip = renderer(case.target, noise_std_dn=case.noise_std_dn, seed=case.seed)
        kind = get_kind(case.target.kind)
        keywords = kind.estimator_keywords(case.target.width_px, gap_px=case.target.gap_px)
        # (no intervals: the self-test compares the figures alone, as the point case does)
        result: MTFResult = kind.make_estimator(method, intervals="none")(chip.image, gsd_m=chip.gsd_m, **keywords)
        true = {"mtf_nyquist": float(chip.true_mtf(0.5)), "mtf50": chip.true_mtf50_cy_px(),
                "fwhm": chip.true_fwhm_px()}
        got = {"mtf_nyquist": result.mtf_nyquist, "mtf50": result.mtf50_cy_px,
               "fwhm": result.fwhm_px}
        tol = case.tolerance
        passed = {"mtf_nyquist": abs(got["mtf_nyquist"] - true["mtf_nyquist"]) <= tol["mtf_nyquist"],
                  "mtf50": abs(got["mtf50"] / true["mtf50"] - 1) <= tol["mtf50"],
                  "fwhm": abs(got["fwhm"] / true["fwhm"] - 1) <= tol["fwhm"]}
        rows.append(SelftestRow(case.name, true, got, passed, result.snr))
    return rows + point_rows(sensor)


def point_rows(sensor: Sensor) -> list[SelftestRow]:
    """The point case (:data:`POINT_CASE`), rendered exactly and measured by
    the point stack: one row across and one along track, against
    :data:`POINTS_TOLERANCE`."""
    from .estimate.mtf2d import measure_points
    from .sensor.points import render_points
    name, array = POINT_CASE
    chip = render_points(sensor, array, POINT_CHIP_PX)
    result = measure_points(chip.image, intervals="none", gsd_m=chip.gsd_m)
    snr = float(min(s.peak_snr for s in result.used))
    rows = []
    for section, direction in zip(result.directions, ("across", "along")):
        true = {"mtf_nyquist": float(chip.true_mtf(0.5, direction)), "mtf50": chip.true_mtf50_cy_px(direction),
                "fwhm": fwhm(*sensor.normal_lsf(section.angle_deg, chip.gsd_m))}
        got = {"mtf_nyquist": section.mtf_nyquist, "mtf50": section.mtf50_cy_px, "fwhm": section.fwhm_px}
        tol = POINTS_TOLERANCE
        passed = {"mtf_nyquist": abs(got["mtf_nyquist"] - true["mtf_nyquist"]) <= tol["mtf_nyquist"],
                  "mtf50": abs(got["mtf50"] / true["mtf50"] - 1) <= tol["mtf50"],
                  "fwhm": abs(got["fwhm"] / true["fwhm"] - 1) <= tol["fwhm"]}
        rows.append(SelftestRow(f"{name} {section.direction}", true, got, passed, snr))
    return rows

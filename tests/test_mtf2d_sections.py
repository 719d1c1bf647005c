"""The 2-D MTF's across/along-track sections from sections along measured
normals: each assumption inverts its own kind of truth exactly, two
orientations bracket the truth, a third one chooses, intervals cover."""
import numpy as np
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.estimate.mtf2d import mtf2d_from_sections, sd_from_nyquist
from imgmtf.sensor.stages import Detector, Electronics

F = np.round(np.linspace(0.0, 1.0, 101), 2)
BAOTOU = [16.8, -73.2]          # the normals of Baotou's checkerboard
THIRD = 40.0


def separable_truth(u, v):
    """Square pixel, an exponential-tailed (Lorentzian) blur across and a
    Gaussian along: separable, not elliptical."""
    return np.sinc(u) * np.sinc(v) / (1 + (np.pi * u) ** 2) * np.exp(-2 * np.pi ** 2 * 0.45 ** 2 * v ** 2)


def elliptical_truth(u, v):
    """Square pixel times an elliptical exponential remainder (aspect 0.7):
    not separable."""
    return np.sinc(u) * np.sinc(v) * np.exp(-2 * np.pi * 0.35 * np.hypot(u, v / 0.7))


def sections(truth, normals):
    t = np.radians(normals)
    return np.array([truth(F * np.cos(a), F * np.sin(a)) for a in t])


@pytest.mark.parametrize("truth, assumption", [(separable_truth, "separable"), (elliptical_truth, "elliptical")])
def test_each_assumption_inverts_its_own_truth_from_two_normals(truth, assumption):
    result = mtf2d_from_sections(BAOTOU, F, sections(truth, BAOTOU))
    across, along = result.alternatives[assumption]
    grid = across.frequencies_cy_px
    assert abs(across.mtf_nyquist - truth(0.5, 0.0)) < 0.002 and abs(along.mtf_nyquist - truth(0.0, 0.5)) < 0.002
    up_to_nyquist = grid <= 0.5
    assert np.max(np.abs(across.mtf - truth(grid, 0.0))[up_to_nyquist]) < 0.005
    assert np.max(np.abs(along.mtf - truth(0.0, grid))[up_to_nyquist]) < 0.005
    if assumption == "elliptical":
        assert result.aspect == pytest.approx(0.7, abs=0.01)
    # the other assumption is wrong by more than the test's tolerance; any two sections are separable, but
    # only sections whose remainders are one curve stretched are elliptical: two orientations reject an
    # elliptical model of a separable truth, and cannot reject a separable one of an elliptical truth
    other = result.alternatives["elliptical" if assumption == "separable" else "separable"][0]
    assert abs(other.mtf_nyquist - truth(0.5, 0.0)) > 0.02
    if assumption == "separable":
        assert result.assumption == "separable" and "not one curve stretched" in result.because
        assert result.tests["elliptical"] < 0.05
    else:
        assert result.assumption == "bracket" and "two orientations cannot tell" in result.because


@pytest.mark.parametrize("truth", [separable_truth, elliptical_truth])
def test_the_bracket_of_two_normals_spans_the_truth_and_its_intervals_cover_it(truth):
    # of both truths, chosen or not: the bracket is what two orientations give when the elliptical fits
    sd = sd_from_nyquist([0.006, 0.006], F)
    result = mtf2d_from_sections(BAOTOU, F, sections(truth, BAOTOU), sd, draws=25)
    bracket = result.alternatives["bracket"]
    for section, exact in ((bracket[0], truth(0.5, 0.0)), (bracket[1], truth(0.0, 0.5))):
        low, high = section.mtf_nyquist_ci
        assert low < exact < high
        assert low < section.mtf_nyquist < high
    for across, along in (result.alternatives[a] for a in ("separable", "elliptical")):
        assert bracket[0].mtf_nyquist_ci[0] <= across.mtf_nyquist_ci[0]
        assert bracket[1].mtf_nyquist_ci[1] >= along.mtf_nyquist_ci[1]
    # the 2-D MTF of the chosen assumption: 1 at zero frequency, its across-track section along u
    assert result.transfer(0.0, 0.0) == pytest.approx(1.0)
    assert result.transfer(0.5, 0.0) == pytest.approx(result.across.mtf_nyquist, abs=1e-9)


@pytest.mark.parametrize("truth, assumption", [(separable_truth, "separable"), (elliptical_truth, "elliptical")])
def test_a_third_orientation_chooses_the_assumption_that_predicts_it(truth, assumption):
    normals = [*BAOTOU, THIRD]
    sd = sd_from_nyquist([0.004] * 3, F)
    result = mtf2d_from_sections(normals, F, sections(truth, normals), sd, draws=20)
    assert result.assumption == assumption, result.because
    assert result.tests[assumption] > 0.05 and min(result.tests.values()) < 0.05
    assert f"the {THIRD:.0f} deg section rejects the other" in result.because
    assert abs(result.across.mtf_nyquist - truth(0.5, 0.0)) < 0.003
    assert abs(result.along.mtf_nyquist - truth(0.0, 0.5)) < 0.003
    assert result.across.mtf_nyquist_ci[0] < truth(0.5, 0.0) < result.across.mtf_nyquist_ci[1]


def l0r_like_truth(u, v, tail_x=0.5, tail_y=0.6, lag=0.5):
    """What issue #31 finds in real L0R blur: a square pixel, a small Gaussian core, exponential-tailed
    LSFs per axis, a scatter halo (8 % of the energy) and a one-sided lag along track (its modulus):
    neither separable nor elliptical."""
    core = np.exp(-2 * np.pi ** 2 * 0.3 ** 2 * (u ** 2 + v ** 2))
    tails = 1 / (1 + (2 * np.pi * tail_x * u) ** 2) / (1 + (2 * np.pi * tail_y * v) ** 2)
    halo = 0.92 + 0.08 * np.exp(-2 * np.pi * 3.0 * np.hypot(u, v))
    return np.sinc(u) * np.sinc(v) * core * tails * halo * np.abs(1 / (1 + 2j * np.pi * lag * v))


@pytest.mark.parametrize("blur", [{}, {"tail_x": 0.7, "tail_y": 0.4, "lag": 0.8}])
def test_an_l0r_like_blur_is_bracketed_from_two_normals(blur):
    # the truth is neither assumption: the data cannot tell, the bracket covers it across and along,
    # and the separable reading is within 0.01 (the halo and the round core are not separable)
    m = sections(lambda u, v: l0r_like_truth(u, v, **blur), BAOTOU)
    result = mtf2d_from_sections(BAOTOU, F, m, sd_from_nyquist([0.006, 0.006], F), draws=30)
    assert result.assumption == "bracket"
    for k, exact in enumerate((l0r_like_truth(0.5, 0.0, **blur), l0r_like_truth(0.0, 0.5, **blur))):
        low, high = result.alternatives["bracket"][k].mtf_nyquist_ci
        assert low < exact < high
        assert abs(result.alternatives["separable"][k].mtf_nyquist - exact) < 0.01


def test_intervals_cover_the_truth_of_noisy_sections():
    # each section shifted by a draw of its own uncertainty, as an edge's noise does: 95 % intervals
    # cover the truth in (nearly) every trial
    rng = np.random.default_rng(7)
    exact = sections(separable_truth, BAOTOU)
    sd = sd_from_nyquist([0.01, 0.01], F)
    covered = 0
    for _ in range(6):
        noisy = exact + rng.standard_normal((2, 1)) * sd
        bracket = mtf2d_from_sections(BAOTOU, F, noisy, sd, draws=30)
        low, high = bracket.across.mtf_nyquist_ci
        covered += low < separable_truth(0.5, 0.0) < high
    assert covered >= 5


def test_measured_chips_a_third_edge_chooses_the_assumption():
    # noise-free edges rendered through two sensors, at Baotou's normals and a third at 40 deg: a
    # square pixel and an isotropic Butterworth blur is elliptical (aspect 1), not separable; a
    # detector wider across track than along is separable, not elliptical (its pixel is not square)
    elliptical = im.Sensor(1.0, [Detector(1.0, 1.0), Electronics(0.45)])
    separable = im.Sensor(1.0, [Detector(1.0, 1.0), Detector(1.6, 0.0)])
    for sensor, assumption in ((elliptical, "elliptical"), (separable, "separable")):
        normals = [*BAOTOU, THIRD]
        edges = [im.measure_edge(im.render(sensor, im.Target("edge", a), 48).image, intervals="none")
                 for a in normals]
        assert [round(e.normal_angle_deg, 1) for e in edges] == normals
        result = mtf2d_from_sections(normals, edges[0].frequencies_cy_px, [e.mtf for e in edges])
        assert result.assumption == assumption, result.because
        assert abs(result.across.mtf_nyquist - float(sensor.transfer(0.5, 0.0))) < 0.01
        assert abs(result.along.mtf_nyquist - float(sensor.transfer(0.0, 0.5))) < 0.01


def test_sections_it_cannot_invert_are_refused():
    with pytest.raises(ParameterError, match="at least two normals 30 deg apart"):
        mtf2d_from_sections([16.8], F, sections(separable_truth, [16.8]))
    with pytest.raises(ParameterError, match="at least two normals 30 deg apart"):
        mtf2d_from_sections([16.8, 26.8], F, sections(separable_truth, [16.8, 26.8]))
    with pytest.raises(ParameterError, match="mtfs must be"):
        mtf2d_from_sections(BAOTOU, F, sections(separable_truth, BAOTOU)[:, :50])
    with pytest.raises(ParameterError, match="assumption must be"):
        mtf2d_from_sections(BAOTOU, F, sections(separable_truth, BAOTOU), assumption="round")
    forced = mtf2d_from_sections(BAOTOU, F, sections(separable_truth, BAOTOU), assumption="separable")
    assert forced.assumption == "separable" and forced.because == "asked for"


def test_the_draws_elliptical_models_solved_together_are_each_ones_own():
    """The redrawn sections' elliptical models, every draw's normal
    equations solved in one call (by bands), are those solved draw by
    draw (nodes, reach and log g to 1e-12), and so are the misfits
    of many aspects, of many targets at once and of each alone."""
    from imgmtf.estimate.mtf2d.inversion import EllipticalProblem, _one, prepared
    f = np.linspace(0, 1, 101)
    normals = [16.8, -73.2, 40.0]
    c, s = np.cos(np.radians(normals))[:, None], np.sin(np.radians(normals))[:, None]
    m = np.sinc(f * c) * np.sinc(f * s) / (1 + 9 * f ** 2 * (c ** 2 + (s / 0.7) ** 2))
    sd = np.full_like(m, 0.01)
    problem = EllipticalProblem(*_one(prepared(normals, f, m, sd)))
    rng = np.random.default_rng(3)
    targets = problem.remainders((m[None] + rng.standard_normal((60, 3))[:, :, None] * sd[None])[None])
    log_aspects = np.log(0.7) + rng.uniform(-0.3, 0.3, (1, 60))
    together = problem.each_model(log_aspects, targets)
    for k, a in enumerate(log_aspects[0]):
        alone = problem.each_model(np.array([[a]]), targets[:, :, k:k + 1])
        assert together.aspect[k] == alone.aspect[0]
        assert np.allclose(together.nodes[k], alone.nodes[0], rtol=0, atol=1e-12)
        assert np.array_equal(np.isnan(together.log_g[k]), np.isnan(alone.log_g[0]))
        assert np.allclose(together.log_g[k], alone.log_g[0], rtol=0, atol=1e-12, equal_nan=True)
    # and the misfits of many aspects at once, of many right-hand sides and of one, are each aspect's own
    many = problem.costs(log_aspects[:, :13], targets[:, :, :5])
    for k in range(5):
        assert np.allclose(many[:, :, k], problem.costs(log_aspects[:, :13], targets[:, :, k]), rtol=1e-10, atol=0)


def test_the_misfits_of_sections_a_model_fits_almost_exactly_keep_their_digits(monkeypatch):
    """Many right-hand sides' misfits come from the normal equations
    (g.g - 2 b.x + x.Gx); noise-free elliptical sections at their own
    aspect leave a misfit of 3e-6 of g.g, and one below ``CANCELLATION``
    is summed sample by sample: both the one right-hand side's misfit."""
    import imgmtf.estimate.mtf2d.inversion as inversion
    f = np.linspace(0, 1, 101)
    normals = [16.8, -73.2, 40.0]
    c, s = np.cos(np.radians(normals))[:, None], np.sin(np.radians(normals))[:, None]
    m = np.sinc(f * c) * np.sinc(f * s) / (1 + 9 * f ** 2 * (c ** 2 + (s / 0.7) ** 2))
    problem = inversion.EllipticalProblem(*inversion._one(inversion.prepared(normals, f, m, np.full_like(m, 0.01))))
    log_aspects = np.log(0.7) + np.linspace(-0.3, 0.3, 13)[None]
    one = problem.costs(log_aspects, problem.log_r)
    twice = problem.log_r[:, :, None].repeat(2, axis=2)
    assert np.allclose(problem.costs(log_aspects, twice)[:, :, 1], one, rtol=1e-9, atol=0)
    monkeypatch.setattr(inversion, "CANCELLATION", 1.0)         # every misfit summed sample by sample
    assert np.allclose(problem.costs(log_aspects, twice)[:, :, 1], one, rtol=1e-12, atol=0)

def test_many_targets_inverted_together_are_each_alone():
    """Targets of mixed shapes (two and three orientations, other
    frequencies, no intervals, one refused) inverted in one call: each
    result is the one its target gives alone, and the refusal its error."""
    from imgmtf.estimate.mtf2d import mtf2d_from_sections_many
    rng = np.random.default_rng(11)

    def target(normals, f, width):
        t = np.radians(normals)[:, None]
        u, v = f * np.cos(t), f * np.sin(t)
        m = np.sinc(u) * np.sinc(v) * np.exp(-2 * np.pi ** 2 * (width * u) ** 2 - 5 * v ** 2)
        m = m + rng.normal(0, 0.004, m.shape)
        return normals, f, m, sd_from_nyquist([0.01] * len(normals), f)

    coarse = np.linspace(0, 1, 51)
    inputs = [target(BAOTOU, F, 0.3), target([5.0, 80.0], F, 0.5), target([16.8, -73.2, 40.0], F, 0.35),
              target(BAOTOU, coarse, 0.4)[:3], target([16.8], F, 0.3), target([-10.0, 70.0], F, 0.2)]
    together = mtf2d_from_sections_many(inputs, draws=20)
    with pytest.raises(ParameterError, match="two normals"):
        mtf2d_from_sections(*inputs[4], draws=20)
    assert isinstance(together[4], ParameterError)
    for k, item in enumerate(inputs):
        if k == 4:
            continue
        alone, both = mtf2d_from_sections(*item, draws=20), together[k]
        assert (both.assumption, both.because, both.tests, both.aspect) == \
            (alone.assumption, alone.because, alone.tests, alone.aspect)
        for name in alone.alternatives:
            for one, other in zip(alone.alternatives[name], both.alternatives[name]):
                for field in ("mtf", "low", "high"):
                    assert np.array_equal(getattr(one, field), getattr(other, field), equal_nan=True)
                figures = [[*s.mtf_nyquist_ci, s.mtf50_cy_px, *s.mtf50_ci_cy_px, s.fwhm_px] for s in (one, other)]
                assert np.array_equal(*figures, equal_nan=True)


def test_the_intervals_of_many_rows_are_numpys_quantiles_of_each():
    """Each row's interval from its finite draws, widened to its centre:
    numpy.quantile's numbers to the bit (NaN and inf draws left out; no
    finite draw or no finite centre: NaN)."""
    from imgmtf.estimate.mtf2d.sections import _interval_rows
    rng = np.random.default_rng(5)
    values = rng.normal(0.3, 0.02, (6, 100))
    values[1, ::3] = np.nan
    values[2, :5] = np.inf
    values[3] = np.nan
    values[4, 1:] = np.nan                                     # a single finite draw
    central = np.array([0.3, 0.25, 0.4, 0.3, 0.3, np.nan])
    rows = _interval_rows(values, 0.025, central)
    for k in range(6):
        finite = values[k][np.isfinite(values[k])]
        if not finite.size or not np.isfinite(central[k]):
            assert np.isnan(rows[k]).all()
            continue
        low, high = np.quantile(finite, [0.025, 0.975])
        assert rows[k].tolist() == [min(low, central[k]), max(high, central[k])]

"""The sensor model chosen by the data (stages="auto") and the one-sided
lag fitted on either side of either kind of edge."""
import pytest

import imgmtf as im
from imgmtf.errors import ParameterError
from imgmtf.estimate.fit.choice import AUTO_CANDIDATES
from imgmtf.sensor import stages as st

#: Baotou-like blur: a small Gaussian core, exponential wings per axis and a
#: one-sided lag along track over a 1 px pixel (no halo: quick to fit)
REAL_LIKE = im.Sensor(1.0, [st.GaussianOptics(0.3, 0.3), st.Detector(1.0, 1.0), st.Diffusion(0.5, 0.4),
                            st.Lag(0.0, 0.5)])


def chips(sensor, size=60, noise=0.0):
    renderer = im.Renderer(sensor, size)
    return [renderer(im.Target("edge", a, lo, hi, o), noise_std_dn=noise, seed=k).image
            for k, (a, lo, hi, o) in enumerate(((16.8, 200.0, 1200.0, 0.3), (-73.2, 1200.0, 200.0, -0.2)))]


@pytest.mark.parametrize("length", [0.6, -0.6])
def test_the_lag_is_found_on_its_side_whatever_the_edges_normal(length):
    truth = im.Sensor(1.0, [st.GaussianOptics(0.3, 0.3), st.Detector(1.0, 1.0), st.Lag(0.0, length)])
    edges = [im.measure_edge(image, force=True) for image in chips(truth)]
    fit = im.fit_sensor(edges, stages="optics,detector,lag", hold="detector")
    values = {p.key: p.value for p in fit.parameters}
    assert values["lag.length_y_m"] == pytest.approx(length, abs=0.02)
    assert fit.directions["along"]["mtf_nyquist"] == pytest.approx(truth.mtf_nyquist("along"), abs=0.003)


def test_auto_keeps_the_paper_core_on_a_gaussian_chip():
    truth = im.Sensor(1.0, [st.GaussianOptics(0.45, 0.35), st.Detector(1.0, 1.0)])
    fit = im.fit_sensor(chips(truth), stages="auto")
    assert fit.choice.kept == ("optics", "detector") and len(fit.choice.candidates) == 1
    assert "simplest that fits" in fit.choice.reason and not fit.misfit
    assert fit.to_dict()["model_choice"]["kept"] == ["optics", "detector"]


def test_auto_learns_exponential_wings_and_a_lag_the_gaussian_cannot_fit():
    edges = [im.measure_edge(image, force=True) for image in chips(REAL_LIKE, noise=2.0)]
    gaussian = im.fit_sensor(edges, stages="optics,detector")
    assert gaussian.misfit
    fit = im.fit_sensor(edges, stages="auto")
    assert not fit.misfit and {"diffusion", "lag"} <= set(fit.choice.kept)
    tried = [c.stages for c in fit.choice.candidates]
    assert tried == list(AUTO_CANDIDATES[: len(tried)]) and tried[0] == ("optics", "detector")
    assert fit.choice.candidates[0].misfit and fit.choice.candidates[0].bic > fit.choice.candidates[-1].bic
    for direction in ("across", "along"):
        assert fit.directions[direction]["mtf_nyquist"] == pytest.approx(REAL_LIKE.mtf_nyquist(direction), abs=0.01)


def test_auto_checks_its_held_names_against_every_candidate():
    with pytest.raises(ParameterError, match="cannot hold 'motion'"):
        im.fit_sensor(chips(REAL_LIKE)[:1], stages="auto", hold="motion")
    assert im.estimate.fit.check_names("auto", "lag") == ["auto"]


def test_fit_auto_says_which_model_it_kept_and_what_it_tried(tmp_path):
    from click.testing import CliRunner

    from imgmtf.cli import main
    runner = CliRunner()
    for name, angle in (("across.tif", "6"), ("along.tif", "84")):
        assert runner.invoke(main, ["simulate", "--angle", angle, "--size", "60",
                                    "--out", str(tmp_path / name)]).exit_code == 0
    result = runner.invoke(main, ["fit", str(tmp_path / "across.tif"), str(tmp_path / "along.tif"), "--stages", "auto"])
    assert result.exit_code == 0, result.output
    assert "stages auto: the simplest that fits (1 of 5 tried) (optics+detector: BIC" in result.output


def test_auto_stops_when_the_wings_do_not_lower_the_criterion(monkeypatch):
    # a structure the exponential wings do not touch (texture, a second target) is no blur's shape:
    # the richer candidates, all with the wings, would only chase it (16 s on a textured scene's 20 edges)
    from types import SimpleNamespace

    from imgmtf.estimate.fit import fitting

    def fit_of(names, bic):
        return SimpleNamespace(sensor=SimpleNamespace(stages=[SimpleNamespace(name=n) for n in names]), bic=bic)
    monkeypatch.setattr(fitting, "candidate_summary", lambda fit: fit)
    core, wings = AUTO_CANDIDATES[:2]
    assert fitting.wings_do_not_help([fit_of(core, 100.0), fit_of(wings, 100.5)])
    assert not fitting.wings_do_not_help([fit_of(core, 100.0), fit_of(wings, 90.0)])
    assert not fitting.wings_do_not_help([fit_of(wings, 100.0)])            # the core failed to converge
    assert not fitting.wings_do_not_help([fit_of(core, 100.0)])

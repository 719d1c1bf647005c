import json
import re

import numpy as np
import pytest
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main
from imgmtf.errors import ImageContentError, ImgmtfError, ParameterError
from imgmtf.estimate import fit as fit_module
from imgmtf.sensor import stages as st

TRUTH = im.Sensor(1.0, [st.GaussianOptics(0.45, 0.35), st.Detector(1.0, 1.0)])


@pytest.fixture(scope="module")
def pair():
    """Noise-free across- and along-track chips of a Gaussian + pixel sensor."""
    renderer = im.Renderer(TRUTH, 60)
    return [renderer(im.Target("edge", a, 200.0, 1200.0, o)) for a, o in ((5.0, 0.3), (-84.0, -0.2))]


def test_recovers_the_parameters_and_each_edges_mtf(pair):
    fit = im.fit_sensor([c.image for c in pair], stages="optics,detector", hold="detector")
    values = {p.key: p for p in fit.parameters}
    assert values["optics.sigma_x_m"].value == pytest.approx(0.45, rel=0.01)
    assert values["optics.sigma_y_m"].value == pytest.approx(0.35, rel=0.01)
    assert values["optics.sigma_x_m"].status == "fitted" and values["detector.width_x_m"].status == "held"
    for chip, edge in zip(pair, fit.edges):
        assert abs(edge.mtf_nyquist - float(chip.true_mtf(0.5))) < 0.002
        assert edge.constrains == ("across" if abs(chip.target.angle_deg) < 45 else "along")
        assert edge.direction == ("across-track" if abs(chip.target.angle_deg) < 45 else "along-track")
    assert fit.directions["along"]["mtf_nyquist"] == pytest.approx(TRUTH.mtf_nyquist("along"), abs=0.002)
    assert not fit.misfit and not any("does not fit" in w for w in fit.warnings)


def test_one_direction_ties_the_other_axis_and_says_so(pair):
    fit = im.fit_sensor(pair[0].image, stages="optics,detector,motion")
    status = {p.key: (p.status, p.note) for p in fit.parameters}
    assert status["optics.sigma_y_m"][0] == "tied" and "optics.sigma_x_m" in status["optics.sigma_y_m"][1]
    assert status["motion.length_m"][0] == "held" and "no along-track edge" in status["motion.length_m"][1]
    assert fit.directions["along"]["constrained"] is False
    assert any("no along-track edge" in w for w in fit.warnings)
    assert abs(fit.edges[0].mtf_nyquist - float(pair[0].true_mtf(0.5))) < 0.002


def test_diffraction_is_recovered_and_a_wrong_model_warns():
    sensor = im.Sensor(1.0, [st.Diffraction(11.0), st.Detector()])     # the fit starts at f/8
    chip = im.render(sensor, im.Target("edge", 7.0, 200.0, 1200.0, 0.17), 60)
    right = im.fit_sensor(chip.image, stages="diffraction,detector", hold="detector")
    f_number = next(p for p in right.parameters if p.key == "diffraction.f_number")
    assert f_number.value == pytest.approx(11.0, rel=0.01) and f_number.standard_error < 0.1
    assert abs(right.edges[0].mtf_nyquist - float(chip.true_mtf(0.5))) < 0.002
    wrong = im.fit_sensor(chip.image, stages="optics,detector", hold="detector")
    assert wrong.misfit and any("does not fit" in w for w in wrong.warnings)
    assert wrong.edges[0].misfit_p < 1e-3
    # and its figure says so in its title, the right one does not
    from imgmtf.plot import plot_fit
    figure = plot_fit(wrong)
    assert figure._suptitle.get_text().startswith("MISFIT: the model does not fit 1 of its 1 edges")
    assert "MISFIT" in figure.axes[0].get_title()
    assert "MISFIT" not in plot_fit(right)._suptitle.get_text()
    # the advice names stages the model lacks, never one it has
    from imgmtf.estimate.fit.choice import other_stages as _other_stages
    assert _other_stages(wrong.sensor.stages) == ("try the stages real blur adds (diffusion, halo, lag; stages "
                                                  "'auto' tries them) or others (e.g. diffraction, defocus, olpf)")
    assert _other_stages(right.sensor.stages).endswith("or others (e.g. defocus, olpf)")
    real = [st.GaussianOptics(), st.Detector(), st.Diffusion(), st.Halo(), st.Lag()]
    assert _other_stages(real) == "try other stages (e.g. diffraction, defocus, olpf), or quote the rows measured " \
                                  "without a model"
    everything = [st.Diffraction(8.0), st.Defocus(1.0), st.OLPF(0.7), *real]
    assert _other_stages(everything) == "quote the rows measured without a model, which assume no form of blur"


def test_profile_noise_needs_no_model():
    rng = np.random.default_rng(4)
    x = np.sort(rng.uniform(-20, 20, 4000))
    y = 1000 * (0.5 + np.arctan(x / 0.7) / np.pi) + rng.normal(0, 7.0, x.size)
    assert fit_module.profile_noise(x, y) == pytest.approx(7.0, rel=0.06)


def test_a_fit_that_does_not_converge_is_an_imgmtf_error(pair):
    from imgmtf.estimate.fit.data import edge_data
    from imgmtf.estimate.fit.model import Model, initial_stages
    data = [edge_data(pair[0].image, 0, None)]
    model = Model(1.0, initial_stages(["optics"], None, 1.0), data)
    with pytest.raises(ImgmtfError, match="did not converge"):
        model.solve(model.initial_vector(), max_iterations=0)


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(stages="optics,lens"), ParameterError, "unknown stage 'lens'"),
    (dict(stages="optics,optics"), ParameterError, "named twice"),
    (dict(hold="motion"), ParameterError, "cannot hold 'motion'"),
    (dict(gsd_m=-1.0), ParameterError, "gsd_m must be"),
    (dict(confidence=1.5), ParameterError, "confidence"),
    (dict(stages=3), ParameterError, "stages must be a list of names, or one comma-separated string, got 3"),
    (dict(hold=None), ParameterError, "hold must be a list of names"),
])
def test_bad_fit_arguments(pair, kwargs, error, message):
    with pytest.raises(error, match=message):
        im.fit_sensor([pair[0].image], **{"stages": "optics,detector", **kwargs})


def test_edges_of_the_wrong_kind_are_named():
    with pytest.raises(ParameterError, match="edges must be a list of files, arrays or EdgeResults, got None"):
        im.fit_sensor(None)
    bar = im.measure_pulse(im.render(TRUTH, im.Target("pulse", 6.0, width_px=3.0), 64).image)
    with pytest.raises(ParameterError, match="edge 1: a PulseResult; the fit takes edges"):
        im.fit_sensor([bar])


def test_an_image_without_an_edge_is_named():
    with pytest.raises(ImageContentError, match="array 2"):
        im.fit_sensor([im.render(TRUTH, im.Target("edge", 6.0), 40).image, np.full((40, 40), 500, np.uint16)])


def test_a_missing_gsd_is_said_and_a_given_one_is_not(pair):
    images = [c.image for c in pair]           # arrays carry no GSD
    unknown = im.fit_sensor(images, stages="optics,detector", hold="detector")
    assert any("no GSD in the inputs" in w for w in unknown.warnings)
    given = im.fit_sensor(images, stages="optics,detector", hold="detector", gsd_m=1.0)
    assert not any("no GSD" in w for w in given.warnings)


def test_a_refused_file_is_named_and_keeps_the_gates_reason(tmp_path):
    from imgmtf.estimate.gate import QualityError
    from imgmtf.io import write_png
    path = tmp_path / "filled.png"
    image = im.render(TRUTH, im.Target("edge", 6.0, 30.0, 200.0), 60, bits=8).image
    image[:, :12] = 0                          # a 0-filled border the gate refuses
    write_png(path, image)
    with pytest.raises(QualityError, match="filled.png: ") as refused:
        im.fit_sensor([path])
    assert refused.value.reason == refused.value.checks[0].reason == "fill"


def test_an_oblique_edge_is_labelled_as_measure_labels_it():
    """Labelled by its normal, as measure does ("oblique" past 10 deg from an
    axis), whatever axis it mostly constrains."""
    chip = im.Renderer(TRUTH, 60)(im.Target("edge", 30.0, 200.0, 1200.0))
    edge = im.fit_sensor(chip.image, stages="optics,detector", hold="detector").edges[0]
    assert (edge.direction, edge.constrains) == ("oblique", "across")
    assert edge.direction == im.measure_edge(chip.image, track_azimuth_deg=0).direction


def test_roi_takes_the_same_window_of_files_and_arrays(pair, tmp_path):
    """A window holding the edge gives what the cropped chip gives; one
    outside the input is refused, naming it."""
    from imgmtf.io import write_geotiff
    image = pair[0].image
    padded = np.pad(image, ((0, 0), (0, 40)))          # 0-fill to the right: the whole is refused
    path = tmp_path / "wide.tif"
    roi = (0, 0, image.shape[1], image.shape[0])
    padded = np.round(padded).astype(np.uint16)
    write_geotiff(path, padded)
    cropped = im.fit_sensor(padded[:, :image.shape[1]], stages="optics,detector",
                            hold="detector").edges[0].mtf_nyquist
    for item in (padded, path):
        fit = im.fit_sensor(item, stages="optics,detector", hold="detector", roi=roi)
        assert fit.edges[0].mtf_nyquist == pytest.approx(cropped, abs=1e-6)
    with pytest.raises(ImgmtfError, match="array 1"):
        im.fit_sensor(padded)
    with pytest.raises(ParameterError, match="array 1"):
        im.fit_sensor(image, roi=(0, 0, image.shape[1] + 5, 20))
    with pytest.raises(ParameterError, match="already measured"):
        im.fit_sensor(im.measure_edge(image), roi=roi)
    result = CliRunner().invoke(main, ["fit", str(path), "--stages", "optics,detector", "--hold", "detector",
                                       "--roi", ",".join(map(str, roi)), "--format", "json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["edges"][0]["mtf_nyquist"] == pytest.approx(cropped, abs=1e-6)


def test_cli_json_contract_toml_and_plot(pair, tmp_path):
    from imgmtf.io import write_geotiff
    paths = []
    for k, chip in enumerate(pair):
        paths.append(tmp_path / f"edge{k}.tif")
        write_geotiff(paths[-1], chip.image, gsd_m=1.0)
    out, png = tmp_path / "fitted.toml", tmp_path / "fit.png"
    result = CliRunner().invoke(main, ["fit", *map(str, paths), "--stages", "optics,detector", "--hold",
                                       "detector", "--format", "json", "--out", str(out), "--plot", str(png)])
    assert result.exit_code == 0, result.output
    record = json.loads(result.stdout)                 # one JSON object
    assert [e["path"] for e in record["edges"]] == list(map(str, paths))
    for edge, chip in zip(record["edges"], pair):
        assert abs(edge["mtf_nyquist"] - float(chip.true_mtf(0.5))) < 0.002
        assert edge["mtf_nyquist_ci"][0] <= edge["mtf_nyquist"] <= edge["mtf_nyquist_ci"][1]
    assert {"parameters", "reduced_chi_square", "directions", "warnings", "sensor"} <= set(record)
    assert set(record["directions"]["across"]) >= {"mtf_nyquist", "mtf_nyquist_ci", "mtf50_cy_px"}
    assert png.stat().st_size > 20_000
    fitted = im.Sensor.from_toml(out)
    assert fitted.mtf_nyquist("across") == pytest.approx(record["directions"]["across"]["mtf_nyquist"])
    text = CliRunner().invoke(main, ["sensor", "--sensor", str(out)])
    assert text.exit_code == 0 and "optics" in text.stdout
    assert CliRunner().invoke(main, ["simulate", "--sensor", str(out), "--size", "20",
                                     "--out", str(tmp_path / "again.tif")]).exit_code == 0


def test_the_text_table_shortens_long_paths_and_keeps_its_columns_within_120(capsys):
    from types import SimpleNamespace

    from imgmtf.cli.tables import print_fit
    deep = "/archive/" + "a_folder_with_a_long_name_" * 3
    edges = [SimpleNamespace(source=f"{deep}/a_long_file_name_for_an_edge_of_the_sensor_{k}.tif[0,0,60,60]",
                             normal_angle_deg=angle, direction=d, constrains=d, mtf_nyquist=0.27,
                             mtf_nyquist_ci=(0.26, 0.28), measured_mtf_nyquist=0.27, reduced_chi_square=1.0,
                             misfit_fraction=0.0) for k, (angle, d) in enumerate(((5.0, "across"), (-84.0, "along")))]
    result = SimpleNamespace(edges=edges, sensor=TRUTH, reduced_chi_square=1.0, choice=None, parameters=[],
                             pixel_units=False,
                             correlations=[], confidence=0.95, warnings=[],
                             directions={"across": {"mtf_nyquist": 0.27, "mtf_nyquist_ci": (0.26, 0.28),
                                                    "mtf50_cy_px": 0.36, "constrained": True}})
    print_fit(result)
    lines = capsys.readouterr().out.splitlines()
    header = next(k for k, line in enumerate(lines) if line.startswith("edge "))
    assert lines[header - 1] == f"edges below {deep}/"
    rows = lines[header: header + 3]
    assert all(len(line) <= 120 for line in rows) and rows[1].split()[0] != rows[2].split()[0]
    for row in rows[1:]:                # right-aligned: the headings end where the figures do
        assert rows[0].index("normal") + len("normal") == re.search(r" (-?\d+\.\d\d) ", row).end(1)
        assert len(rows[0]) == len(row)


@pytest.mark.parametrize("args, message", [
    (["fit", "{tmp}/flat.tif"], "flat.tif"),
    (["fit", "{tmp}/missing.tif"], "missing.tif"),
    (["fit", "{tmp}"], "no image files"),
])
def test_cli_bad_input_is_one_line_and_exit_1(tmp_path, args, message):
    from imgmtf.io import write_geotiff
    (tmp_path / "sub").mkdir()
    write_geotiff(tmp_path / "flat.tif", np.full((32, 32), 700, np.uint16))
    if args[1] == "{tmp}":
        args = ["fit", "{tmp}/sub"]
    result = CliRunner().invoke(main, [a.format(tmp=tmp_path) for a in args])
    assert result.exit_code == 1 and message in result.stderr
    assert "Traceback" not in result.output and len(result.stderr.strip().splitlines()) == 1


def test_the_estimator_takes_images_and_measurements_and_opens_no_file(pair, tmp_path):
    """estimate/fit takes arrays, EdgeImages (an array with its file's GSD
    and sample type) and EdgeResults; imgmtf.fit_sensor reads the files."""
    from imgmtf.estimate.fit import EdgeImage, fit_edges
    from imgmtf.io import write_geotiff
    image = np.round(pair[0].image).astype(np.uint16)
    path = tmp_path / "edge.tif"
    write_geotiff(path, image, gsd_m=2.0)
    with pytest.raises(ParameterError, match="edge 1: a file .*imgmtf.fit_sensor reads files"):
        fit_edges([str(path)])
    from_file = im.fit_sensor([path], stages="optics,detector", hold="detector")
    given = fit_edges([EdgeImage(image.astype(float), str(path), 2.0, "uint16")], stages="optics,detector",
                      hold="detector")
    assert given.edges[0].source == from_file.edges[0].source == str(path)
    assert given.edges[0].gsd_m == from_file.edges[0].gsd_m == 2.0
    assert given.edges[0].noise_dn == from_file.edges[0].noise_dn           # the uint16 quantisation floor alike
    assert given.edges[0].mtf_nyquist == from_file.edges[0].mtf_nyquist


def test_a_fit_keeps_no_evaluation_caches_and_its_band_still_works(pair):
    """fit_report releases the model's caches (each edge's grids, transfers
    and responses; the last ESFs and samples' residuals): a two-edge fit
    pickles within 80 kB of its edges' data (measured 53 kB: its EdgeFits and
    weights; 302 kB with the caches kept), and its MTF band, made afresh,
    is the one the report gave, also after a round trip through pickle."""
    import pickle
    fit = im.fit_sensor([c.image for c in pair], stages="optics,detector", hold="detector")
    model = fit._model
    caches = (model.edges, model._last_samples, model._last_esfs, model._last_responses, model._stages_made)
    assert len(pickle.dumps(caches)) < 2000                  # 315 kB kept
    assert len(pickle.dumps(fit)) - len(pickle.dumps(model.data)) < 80_000
    for other in (fit, pickle.loads(pickle.dumps(fit))):
        for direction, angle in (("across", 0.0), ("along", 90.0)):
            value, low, high = other.mtf_band(0.5, angle)
            reported = fit.directions[direction]
            assert float(value) == reported["mtf_nyquist"] and [float(low), float(high)] == reported["mtf_nyquist_ci"]
        for edge in fit.edges:                  # each edge's, its band's sensors made once for all of them
            value, low, high = other.mtf_band(0.5, edge.normal_angle_deg, edge.gsd_m)
            assert float(value) == edge.mtf_nyquist and (float(low), float(high)) == edge.mtf_nyquist_ci

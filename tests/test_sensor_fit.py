"""imgmtf.fit_sensor reads files as measure does (a window per file, nodata,
the transfer curve, forced checks), measures a file named twice once, and
its fitted sensor's TOML says whether the model fits."""
import dataclasses
import json

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main
from imgmtf.estimate.fit.record import FitRecord, read_fit_record
from imgmtf.sensor_fit import edge_sources

STAGES = "optics,detector"


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def chips(tmp_path_factory):
    """An across-track and an along-track edge side by side in one file (two
    windows), the across one alone, and an 8-bit sRGB-encoded copy of it."""
    folder = tmp_path_factory.mktemp("sensor_fit")
    across = im.render(im.Sensor(), im.Target("edge", 6.0, 200.0, 1200.0), 80, noise_std_dn=2.0, seed=1).image
    along = im.render(im.Sensor(), im.Target("edge", 84.0, 200.0, 1200.0), 80, noise_std_dn=2.0, seed=2).image
    im.write_geotiff(folder / "pair.tif", np.hstack([across, along]))
    im.write_geotiff(folder / "across.tif", across)
    light = (across.astype(float) - 100.0) / 1200.0
    srgb = np.where(light <= 0.0031308, 12.92 * light, 1.055 * light ** (1 / 2.4) - 0.055)
    im.write_geotiff(folder / "across8.tif", np.rint(255 * srgb).astype(np.uint8))
    return folder


def test_a_window_per_file_fits_two_edges_of_one_file(chips):
    pair = str(chips / "pair.tif")
    windows = [(0, 0, 80, 80), (80, 0, 80, 80)]
    fit = im.fit_sensor([pair, pair], roi=windows, stages=STAGES)
    assert [e.source for e in fit.edges] == edge_sources([pair, pair], windows) == \
        [f"{pair}[0,0,80,80]", f"{pair}[80,0,80,80]"]
    assert [e.constrains for e in fit.edges] == ["across", "along"]
    # the same edges as two files give the same fit
    alone = im.fit_sensor([chips / "across.tif"], stages=STAGES)
    assert fit.edges[0].measured_mtf_nyquist == alone.edges[0].measured_mtf_nyquist
    with pytest.raises(im.ParameterError, match="one window per edge; got 1 for 2"):
        im.fit_sensor([pair, pair], roi=[windows[0]])


def test_a_file_named_twice_is_measured_once_and_said_so(chips):
    path = str(chips / "across.tif")
    twice = im.fit_sensor([path, path], stages=STAGES)
    once = im.fit_sensor([path], stages=STAGES)
    assert len(twice.edges) == 1 and twice.reduced_chi_square == once.reduced_chi_square
    assert twice.warnings[0] == f"{path}: named twice (edges 1 and 2): measured once"
    # on the command line too, where it is a warning of the fit
    result = run("fit", path, path, "--stages", STAGES)
    assert result.exit_code == 0        # the warning wrapped at 120 columns where the path is long
    assert f"warning: {path}: named twice (edges 1 and 2): measured once" in " ".join(result.output.split())


def test_files_are_measured_as_measure_measures_them(chips, tmp_path):
    """The same measurement, hence the same samples, as imgmtf measure: the
    transfer curve, nodata and the quality gate with --force."""
    path = chips / "across8.tif"
    for transfer in ("linear", "srgb"):
        fit = im.fit_sensor([path], stages=STAGES, transfer=transfer)
        measured = im.measure_file(path, transfer=transfer, intervals="none")[0]
        # (to the record's 6 digits)
        assert fit.edges[0].measured_mtf_nyquist == pytest.approx(measured.get("mtf_nyquist"), abs=5e-7)
    # statistics as NumPy floats (as a fit gives them at p = 0): the verdict a bool JSON writes
    numpy_stats = dataclasses.replace(fit.edges[0], misfit_p=np.float64(0.0), misfit_fraction=np.float64(0.5))
    assert numpy_stats.misfit is True and json.loads(json.dumps(numpy_stats.to_dict()))["misfit"] is True
    assert im.fit_sensor([path], stages=STAGES, transfer="srgb").edges[0].measured_mtf_nyquist != \
        im.fit_sensor([path], stages=STAGES).edges[0].measured_mtf_nyquist
    # nodata declared by the file: measured around, as measure does
    image = im.read_raster(chips / "across.tif").data.astype(np.uint16)
    image[:, :6] = 0
    profile = dict(driver="GTiff", width=80, height=80, count=1, dtype="uint16", nodata=0,
                   transform=rasterio.Affine(1.0, 0.0, 0.0, 0.0, -1.0, 80.0))
    with rasterio.open(tmp_path / "nodata.tif", "w", **profile) as dst:
        dst.write(image, 1)
    measured = im.measure_file(tmp_path / "nodata.tif", intervals="none")[0]
    assert measured.ok
    fit = im.fit_sensor([tmp_path / "nodata.tif"], stages=STAGES)
    assert fit.edges[0].measured_mtf_nyquist == pytest.approx(measured.get("mtf_nyquist"), abs=5e-7)
    # a check that fails refuses the file, unless forced: then a warning of the fit
    with pytest.raises(im.ImgmtfError, match="across.tif: .*saturat") as refused:
        im.fit_sensor([chips / "across.tif"], stages=STAGES, saturation=(0.0, 1100.0))
    assert refused.value.reason == "saturated"
    forced = im.fit_sensor([chips / "across.tif"], stages=STAGES, saturation=(0.0, 1100.0), force=True)
    assert any("across.tif: saturated: " in w and "forced" in w for w in forced.warnings)


def test_fit_on_the_command_line_takes_measure_s_reading_options(chips, tmp_path):
    pair = chips / "pair.tif"
    result = run("fit", pair, pair, "--roi", "0,0,80,80", "--roi", "80,0,80,80", "--stages", STAGES,
                 "--out", tmp_path / "s.toml", "--format", "json")
    assert result.exit_code == 0, result.output
    assert [e["path"] for e in json.loads(result.stdout)["edges"]] == [f"{pair}[0,0,80,80]", f"{pair}[80,0,80,80]"]
    assert read_fit_record(tmp_path / "s.toml").sources == (f"{pair}[0,0,80,80]", f"{pair}[80,0,80,80]")
    result = run("fit", pair, pair, pair, "--roi", "0,0,80,80", "--roi", "80,0,80,80")
    assert result.exit_code == 2 and "--roi given 2 times for 3 file(s)" in result.output
    result = run("fit", chips / "across.tif", "--transfer", "gamma:x")
    assert result.exit_code == 2
    result = run("fit", chips / "across.tif", "--stages", STAGES, "--saturation", "0,1100")
    assert result.exit_code == 1 and "--force measures it anyway" in result.output
    result = run("fit", chips / "across.tif", "--stages", STAGES, "--saturation", "0,1100", "--force")
    assert result.exit_code == 0 and "(measured anyway: forced)" in result.output


def test_the_fitted_toml_records_whether_the_model_fits(chips, tmp_path):
    fit = im.fit_sensor([chips / "across.tif"], stages=STAGES)
    fit.to_toml(tmp_path / "s.toml", comment="a test")
    record = read_fit_record(tmp_path / "s.toml")
    assert record == FitRecord(False, fit.reduced_chi_square, fit.edges[0].misfit_p, fit.edges[0].misfit_fraction,
                               ("optics", "detector"), (str(chips / "across.tif"),), record.imgmtf_version)
    assert record.imgmtf_version == im.__version__
    # the sensor reads back as it was, wherever sensors are read
    sensor = im.Sensor.from_toml(tmp_path / "s.toml")
    assert sensor.to_dict() == fit.sensor.to_dict()
    # a sensor written without a fit makes no claim; a malformed record is named
    im.Sensor().to_toml(tmp_path / "plain.toml")
    assert read_fit_record(tmp_path / "plain.toml") is None
    text = (tmp_path / "s.toml").read_text().replace("misfit = false", 'misfit = "no"')
    (tmp_path / "bad.toml").write_text(text)
    with pytest.raises(im.ConfigError, match=r"bad.toml: \[fit\] misfit must be true or false, got 'no'"):
        read_fit_record(tmp_path / "bad.toml")

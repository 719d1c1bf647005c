"""Camera conventions: an image with no georeference and no track is told
in its own axes (horizontal, vertical) and in px; with an optical centre,
each edge is sagittal or meridional, and a chart of tilted squares whose
blur grows across the field gives a lens profile matching its truth."""
import csv
import math
import warnings

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner
from rasterio.errors import NotGeoreferencedWarning

import imgmtf as im
from imgmtf.cli import main
from imgmtf.estimate.field import field_position
from imgmtf.scene.lens_profile import lens_profile
from imgmtf.sensor.chart import FieldBlur, square_chart

from conftest import exact_edge_chip, gaussian_pixel_transfer

pytestmark = pytest.mark.filterwarnings(f"ignore::{NotGeoreferencedWarning.__module__}.NotGeoreferencedWarning")
BLUR = FieldBlur(centre_sigma_px=0.6, sagittal_sigma_px=0.9, meridional_sigma_px=1.5, reference_px=150.0)


@pytest.fixture(scope="module")
def photos(tmp_path_factory):
    """Two 8-bit PNGs (no georeference): a near-vertical and a near-horizontal edge."""
    folder = tmp_path_factory.mktemp("photos")
    paths = []
    for angle in (6.0, 84.0):
        chip = exact_edge_chip(gaussian_pixel_transfer(0.6, angle), angle, (64, 64), low=40.0, high=220.0,
                               noise_std=1.0, seed=int(angle))
        paths.append(folder / f"edge{angle:g}.png")
        im.write_png(paths[-1], np.round(chip).astype(np.uint8))
    return paths


def test_a_photo_is_told_in_its_own_axes_and_a_track_azimuth_restores_the_track(photos, tmp_path):
    vertical_edge, horizontal_edge = photos
    [record] = im.measure_file(vertical_edge, intervals="none")
    assert record.get("direction") == "horizontal" and record.get("orientation") == "vertical"
    assert im.measure_file(horizontal_edge, intervals="none")[0].get("direction") == "vertical"
    [l0] = im.measure_file(vertical_edge, intervals="none", track_azimuth_deg=0.0)
    assert l0.get("direction") == "across-track"
    # a file with a pixel size in metres (imgmtf's chips, L1 products) keeps the track's words
    chip = tmp_path / "chip.tif"
    im.write_geotiff(chip, np.round(exact_edge_chip(gaussian_pixel_transfer(0.6, 6.0), 6.0, (64, 64))).astype(
        np.uint16), gsd_m=2.0)
    assert im.measure_file(chip, intervals="none")[0].get("direction") == "across-track"
    result = CliRunner().invoke(main, ["measure", str(vertical_edge), str(horizontal_edge), "--intervals", "none"])
    assert "horiz" in result.output and "vert" in result.output and "across" not in result.output


def test_a_fit_of_photos_is_in_px_and_image_axes(photos, capsys):
    from imgmtf.cli.tables import print_fit
    from imgmtf.plot import plot_fit
    fit = im.fit_sensor(photos, stages="optics,detector", hold="detector")
    assert fit.pixel_units and {p.unit for p in fit.parameters} == {"px"}
    assert [e.direction for e in fit.edges] == ["horizontal", "vertical"]
    assert not any("track" in w for w in fit.warnings)
    psf = plot_fit(fit).axes[-2]          # the PSF panel (its colour bar is the last axes)
    assert (psf.get_xlabel(), psf.get_ylabel()) == ("x (px)", "y (px)")
    print_fit(fit)
    printed = capsys.readouterr().out
    assert "no GSD: lengths in px" in printed and "horizontal" in printed
    assert " m     " not in printed          # no parameter in metres


@pytest.mark.parametrize("x, y, normal_deg, expected", [
    (500.0, 300.0, 0.0, "meridional"),        # right of the centre, normal radial
    (500.0, 300.0, 90.0, "sagittal"),         # right of it, normal tangential
    (300.0, 500.0, 95.0, "meridional"),       # below it, normal nearly radial
    (441.4, 441.4, 45.0 + 44.0, "meridional"),   # on the diagonal, 44 deg off radial
    (441.4, 441.4, 45.0 + 46.0, "sagittal"),
])
def test_sagittal_and_meridional_follow_the_normal_against_the_radius(x, y, normal_deg, expected):
    place = field_position(x, y, normal_deg, (300.0, 300.0))
    assert place["field_direction"] == expected
    assert place["radial_distance_px"] == pytest.approx(math.hypot(x - 300.0, y - 300.0), abs=0.01)


def test_measure_places_each_edge_about_the_optical_centre(photos):
    vertical_edge, _ = photos
    # the edge runs down the middle of the 64 px chip: (31.5, 31.5)
    [left] = im.measure_file(vertical_edge, intervals="none", optical_centre=(0.0, 31.5))
    [above] = im.measure_file(vertical_edge, intervals="none", optical_centre=(31.5, 0.0))
    assert left.get("field_direction") == "meridional" and above.get("field_direction") == "sagittal"
    assert left.get("radial_distance_px") == pytest.approx(31.5, abs=0.5)
    [centred] = im.measure_file(vertical_edge, intervals="none", optical_centre="centre")
    assert centred.get("field_direction") is None and centred.get("radial_distance_px") < 1.0


@pytest.fixture(scope="module")
def chart(tmp_path_factory):
    """A 2 x 3 chart of tilted squares, blurred more meridionally than sagittally away from its centre."""
    path = tmp_path_factory.mktemp("chart") / "chart.tif"
    image = square_chart((200, 300), BLUR, grid=(2, 3), side_px=40.0, noise_dn=10.0, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path, "w", driver="GTiff", width=300, height=200, count=1, dtype="uint16") as out:
            out.write(np.round(image).astype(np.uint16)[None])
    return path


def test_each_chart_edge_is_placed_and_measured_as_its_truth(chart, tmp_path):
    from imgmtf.plot import plot_lens_profile
    from imgmtf.scene.lens_profile import write_lens_profile
    records = im.scan_scene(str(chart), im.ScanSettings(min_length_px=30.0, optical_centre="centre",
                                                        intervals="none"))
    assert len(records) == 24 and all(r.ok for r in records)
    for r in records:       # the generator blurs each edge by the sigma of its place and direction
        truth = BLUR.mtf50_cy_px(r.get("radial_distance_px"), r.get("field_direction"))
        assert r.get("mtf50_cy_px") == pytest.approx(truth, rel=0.01)
    profile = lens_profile(records, (0.125, 0.25))
    outer = {r.field_direction: r for r in profile.rings if r.outer_px > 120}
    # far from the centre the meridional blur (1.5 px at 150 px) is wider than the sagittal (0.9 px)
    assert outer["meridional"].mtf50_cy_px < outer["sagittal"].mtf50_cy_px - 0.05
    assert outer["meridional"].mtf[1] < outer["sagittal"].mtf[1]
    with open(write_lens_profile(profile, str(tmp_path / "lens.csv")), newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(profile.rings) and "mtf_at_0.25_cy_px" in rows[0]
    figure = plot_lens_profile(profile, truth=BLUR.mtf50_cy_px)
    assert [ax.get_xlabel() for ax in figure.axes[:2]] == ["distance from the optical centre (px)"] * 2


def test_the_scan_of_a_chart_prints_its_lens_profile_in_image_axes(chart):
    result = CliRunner().invoke(main, ["scan", str(chart), "--optical-centre", "centre", "--min-length", "30",
                                       "--fit-stages", "none", "--intervals", "none"])
    assert result.exit_code == 0, result.output
    assert "lens profile about the optical centre (149.5, 99.5) px" in result.output
    assert "meridional" in result.output and "sagittal" in result.output
    # the tables' words are the image's, the chosen assumption still said beneath its rows
    assert " horiz " in result.output and " vert " in result.output
    assert "horizontal and vertical without a model" in result.output and "across and along" not in result.output
    assert "bracket: two orientations cannot tell" in result.output


def test_a_lens_profile_needs_edges_placed_in_the_field():
    with pytest.raises(im.ParameterError, match="optical centre"):
        lens_profile([im.Record("a.tif", 1, "edge", "msg", "accepted", figures={"mtf50_cy_px": 0.3})])


def test_a_photo_of_point_targets_gives_a_horizontal_and_a_vertical_record(tmp_path):
    from imgmtf.sensor.points import PointArray, render_points
    from imgmtf.sensor.stages import Detector, GaussianOptics
    sensor = im.Sensor(stages=[GaussianOptics(0.45, 0.55), Detector(1.0, 1.0)])
    chip = render_points(sensor, PointArray(3, 3, spacing_px=12.0), 40, noise_std_dn=3.0, seed=2)
    im.write_png(tmp_path / "points.png", chip.image.astype(np.uint16))
    records = im.measure_file(tmp_path / "points.png", target="points", intervals="none")
    assert [r.get("direction") for r in records] == ["horizontal", "vertical"]


def test_the_measurement_figure_says_where_the_edge_lies_in_the_field(photos, monkeypatch, tmp_path):
    import imgmtf.batch
    drawn = []
    monkeypatch.setattr(imgmtf.batch, "with_figure", lambda record, draw, path: drawn.append(draw()) or record)
    im.measure_file(photos[0], plot_path=str(tmp_path / "edge.png"), intervals="none", optical_centre=(0.0, 31.5))
    title = drawn[0]._suptitle.get_text()
    assert "meridional, 31.5 px from the optical centre" in title and "horizontal" in title


@pytest.mark.parametrize("args, words", [
    (["measure", "--optical-centre", "1,x"], "expected X,Y (two numbers, px) or 'centre'"),
    (["scan", "--optical-centre", "centre", "--lens-frequencies", "0,2"], "must lie in (0, 1] cy/px"),
])
def test_malformed_camera_options_are_usage_errors(args, words):
    result = CliRunner().invoke(main, [*args, "data/edge_16bit.tif"])
    assert result.exit_code == 2 and words in result.output

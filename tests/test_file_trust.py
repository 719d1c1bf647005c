"""What a file says about a number: lossy compression (from the file and
from its 8 x 8 blocks), 8-bit values taken as linear, forced numbers that
are no success, and the refusals a scan would solve."""
import json

import numpy as np
import pytest
import rasterio
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli import main
from imgmtf.io import read_raster

from conftest import exact_edge_chip, gaussian_pixel_transfer, real_scene

H = gaussian_pixel_transfer(0.4, 6.0)


def write(path, image, driver="GTiff", **options):
    with rasterio.open(path, "w", driver=driver, width=image.shape[1], height=image.shape[0], count=1,
                       dtype=image.dtype, **options) as dst:
        dst.write(image, 1)
    return path


def measure(*args):
    result = CliRunner().invoke(main, ["measure", "--format", "json", *map(str, args)])
    return result.exit_code, [json.loads(line) for line in result.stdout.splitlines()]


@pytest.fixture(scope="module")
def edge8():
    return exact_edge_chip(H, 6.0, offset=0.2, low=30, high=210, noise_std=1.0, dtype=np.uint8, shape=(96, 96))


def test_lossy_files_are_known_and_every_result_says_so(tmp_path, edge8):
    jpeg = write(tmp_path / "edge.jpg", edge8, driver="JPEG", QUALITY=75)
    tiff_jpeg = write(tmp_path / "edge.tif", edge8, COMPRESS="JPEG", JPEG_QUALITY=75)
    lossless = write(tmp_path / "deflate.tif", edge8, COMPRESS="DEFLATE")
    assert read_raster(jpeg).compression == read_raster(tiff_jpeg).compression == "JPEG"
    assert read_raster(lossless).compression is None
    code, (row,) = measure(jpeg)
    assert code == 0 and abs(row["mtf_nyquist"] - H(0.5)) < 0.02
    assert any("JPEG compression" in w and "codec's loss" in w for w in row["warnings"])
    code, (row,) = measure(lossless)
    assert not any("compression" in w for w in row["warnings"])


def test_heavy_block_compression_is_refused_for_what_it_is(tmp_path, edge8):
    for quality in (50, 20):
        path = write(tmp_path / f"q{quality}.jpg", edge8, driver="JPEG", QUALITY=quality)
        raster = read_raster(path)
        with pytest.raises(im.ImgmtfError) as info:               # from the pixels alone, no file needed
            im.measure_edge(raster.data, dtype=raster.dtype)
        assert info.value.reason == "compression"
    assert im.measure_edge(edge8).mtf_nyquist == pytest.approx(H(0.5), abs=0.01)


def test_8bit_values_taken_as_linear_say_how_to_linearise(tmp_path, edge8):
    _, (row,) = measure(write(tmp_path / "edge8.tif", edge8))
    assert any("taken as linear" in w and "sRGB" in w for w in row["warnings"])
    _, (row,) = measure("--transfer", "srgb", tmp_path / "edge8.tif")
    assert row["params"]["transfer"] == "srgb" and not any("taken as linear" in w for w in row["warnings"])
    chip = im.render(im.Sensor(), im.Target("edge", 6.0, 30.0, 210.0), 64, bits=8)   # imgmtf's own: linear
    im.write_geotiff(tmp_path / "own.tif", chip.image, provenance=chip.provenance())
    _, (row,) = measure(tmp_path / "own.tif")
    assert not any("taken as linear" in w for w in row["warnings"])


def test_a_forced_number_from_fill_is_printed_and_fails_and_refusals_point_to_scan():
    path = real_scene("baotou_l0r_checkerboard.tif")
    code, (row,) = measure("--force", path)
    assert code == 1 and row["status"] == "untrusted" and row["mtf_nyquist"] is not None
    assert row["reason"] in ("fill", "mtf-undefined", "mtf-above-one") and "not to be trusted" in row["error"]
    text = CliRunner().invoke(main, ["measure", str(path)])
    assert text.exit_code == 1 and f"imgmtf scan {path}" in text.output
    forced = CliRunner().invoke(main, ["measure", "--force", str(path)])
    assert f"{row['mtf_nyquist']:.4f}" in forced.output and "not to be trusted" in forced.output


def test_a_clean_forced_number_is_a_success(tmp_path):
    chip = im.render(im.Sensor(), im.Target("edge", 6.0), 64, noise_std_dn=2.0, seed=1)
    im.write_geotiff(tmp_path / "edge.tif", chip.image)
    code, (row,) = measure("--force", tmp_path / "edge.tif")
    assert code == 0 and row["status"] == "ok"


@pytest.mark.parametrize("width", ["8px", "10px"])
def test_noise_free_wide_bars_from_simulate_are_measured(tmp_path, width):
    path = tmp_path / "bar.tif"
    made = CliRunner().invoke(main, ["simulate", "--target", "pulse", "--pulse-width", width, "--out", str(path)])
    assert made.exit_code == 0, made.output
    code, (row,) = measure("--target", "pulse", "--pulse-width", width, path)
    assert code == 0 and row["status"] == "ok", row.get("error")


def test_noise_is_no_block_grid():
    """The largest of the 8 row phases' mean jumps stands out by chance; on
    noisy edges (SNR 25) and noisy bars it never passes for compression."""
    for seed in range(8):
        angle = 3.0 + seed
        noisy = exact_edge_chip(H, angle, offset=0.2, noise_std=40.0, seed=seed, dtype=np.float64)
        bar = im.render(im.Sensor(), im.Target("pulse", angle, 200, 1200, 0.1, 1.5), (100, 60), noise_std_dn=20.0,
                        seed=seed).image
        for result in (im.measure_edge(noisy, force=True), im.measure_pulse(bar, width_px=1.5, force=True)):
            assert all(c.passed for c in result.checks if c.reason == "compression")
            assert not any("block" in w for w in result.warnings)


def test_refusals_a_scan_solves_point_to_it_and_others_do_not(tmp_path):
    from imgmtf.cli.hints import refusal_hint
    assert "imgmtf scan a.tif" in refusal_hint("fill", "", "a.tif") and "--force" in refusal_hint("fill", "", "a.tif")
    assert "imgmtf scan" in refusal_hint("not-straight", "the edge bends: two straight pieces meet inside the chip")
    assert "imgmtf scan" not in refusal_hint("not-straight", "the per-row edge locations scatter")
    assert refusal_hint("unreadable") == ""
    first = exact_edge_chip(H, 6.0, offset=-12.5, low=200, high=700)
    second = exact_edge_chip(H, 6.0, offset=12.5, low=0, high=500)
    path = tmp_path / "two.tif"
    im.write_geotiff(path, (first.astype(float) + second).astype(np.uint16))
    result = CliRunner().invoke(main, ["measure", str(path)])
    assert result.exit_code == 1 and f"imgmtf scan {path}" in result.output


@pytest.mark.parametrize("name, options", [("gamma.tif", {}), ("gamma.jpg", {"driver": "JPEG", "QUALITY": 90})])
def test_scan_and_measure_give_one_edge_the_same_warnings(tmp_path, name, options):
    from imgmtf.batch import measure_file
    from imgmtf.measure_settings import MeasureSettings
    from imgmtf.scene.measure import scan_scene
    from imgmtf.scene.settings import ScanSettings
    linear = exact_edge_chip(H, 6.0, offset=0.2, low=0.05, high=0.8, noise_std=0.002, dtype=np.float64,
                             shape=(128, 128))
    encoded = np.clip(np.rint(255 * linear ** (1 / 2.2)), 0, 255).astype(np.uint8)     # 8-bit, gamma 2.2
    path = str(write(tmp_path / name, encoded, **options))
    accepted = [r.to_dict() for r in scan_scene(path, ScanSettings(track_azimuth_deg=0.0)) if r.status == "accepted"]
    assert accepted
    scanned = accepted[0]
    (measured,) = measure_file(path, MeasureSettings(roi=tuple(scanned["roi"])))
    assert measured.status == "ok"
    assert scanned["warnings"] == measured.to_dict()["warnings"]
    assert any(w.startswith("8-bit values are measured as stored") for w in scanned["warnings"])
    assert any("JPEG compression" in w for w in scanned["warnings"]) == name.endswith(".jpg")


def test_a_number_forced_past_any_refusal_is_untrusted_in_its_record_and_figure(tmp_path):
    # SNR 5: refused (snr and others); forced, printed as untrusted with the refusal's reason, exit 1
    chip = exact_edge_chip(H, 6.0, offset=0.2, noise_std=200.0, seed=2, shape=(40, 40))
    im.write_geotiff(tmp_path / "noisy.tif", chip)
    code, (row,) = measure("--force", "--intervals", "none", tmp_path / "noisy.tif")
    assert code == 1 and row["status"] == "untrusted" and row["mtf_nyquist"] is not None
    assert row["reason"] in {c["reason"] for c in row["checks"] if c["outcome"] == "failed"}
    assert "forced, but not to be trusted" in row["error"]
    import matplotlib.pyplot as plt

    from imgmtf.batch import _measurement_figure
    figure = _measurement_figure(im.measure_edge(chip, force=True, intervals=im.Intervals("none")),
                                 read_raster(tmp_path / "noisy.tif"), [], row["reason"])
    assert f"NOT TO BE TRUSTED (forced past the refusal {row['reason']})" in figure._suptitle.get_text()
    plt.close(figure)

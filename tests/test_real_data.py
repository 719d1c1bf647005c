"""Real images, measured as a user would.

The camera crops in data/ come from the public-domain (CC0 1.0) repository
carlasplund/SFR_calculation_code, folder edge_samples/ (data/README.md); the
MTF50 bands are the three peers' (MTF Mapper, sfrmat5, sfrmat3) widened by
1 % each side, as the accuracy issue quotes them.  The scenes are read from
../shared/data/real-scenes/, or from real-scenes/ in the folder the
environment variable IMGMTF_SHARED_DATA names (see its README for provenance
and licences; the GPL-3.0 files are read there, never copied); the tests are
skipped when that folder is absent and IMGMTF_SHARED_DATA is unset."""
import re
from pathlib import Path

import pytest

import imgmtf as im
from imgmtf.io import read_raster

from conftest import real_scene

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.mark.parametrize("name, low, high", [("x2084_y0616_F2", 0.2909, 0.3037),
                                             ("x2088_y0616_F2_8", 0.4604, 0.4781),
                                             ("x0552_y1976_F16", 0.1525, 0.1585)])
def test_real_camera_edges_read_within_the_peers_band(name, low, high):
    raster = read_raster(DATA / f"{name}.png")           # the Rec. 709 luminance of the stored values
    r = im.measure_edge(raster.data, dtype=raster.dtype)
    assert low <= r.mtf50_cy_px <= high


def test_the_mtf_estimator_synthetic_edge_reads_its_known_mtf():
    """MTF_Estimator's own synthetic edge (GPL-3.0, read in place): a
    Gaussian of FWHM 2.1013 px along each row, 16.7766 deg from vertical,
    so along the normal a Gaussian LSF of FWHM 2.0118 px: MTF at Nyquist
    0.0273, MTF50 0.2194 cy/px."""
    raster = read_raster(real_scene("mtf_estimator_synthetic_edge_angle16.7766_fwhm2.1013.tif"))
    r = im.measure_edge(raster.data, dtype=raster.dtype)
    assert r.fwhm_px == pytest.approx(2.0118, rel=0.005)
    assert r.mtf50_cy_px == pytest.approx(0.2194, rel=0.005)
    assert abs(r.mtf_nyquist - 0.0273) < 0.002
    assert r.normal_angle_deg == pytest.approx(-16.7766, abs=0.05) or r.normal_angle_deg == pytest.approx(
        16.7766, abs=0.05)


def test_a_hand_roi_that_takes_in_the_baotou_chips_fill_is_refused_as_fill():
    """The Baotou L0R chip (GPL-3.0, read in place): every pixel outside the
    four-quadrant target is 0 and no nodata tag says so."""
    path = real_scene("baotou_l0r_checkerboard.tif")
    raster = read_raster(path, window=(58, 40, 36, 30))
    with pytest.raises(im.ImgmtfError) as info:
        im.measure_edge(raster.data, dtype=raster.dtype)
    assert info.value.reason == "fill"


def test_a_map_projected_scene_has_no_track_direction():
    """Sentinel-2 B04 (Apache-2.0, qgis-image-quality-toolset): EPSG:32632,
    rows are not along track.  This forced ROI's MTF rises above 1 (a
    sharpened product): its number is reported as untrusted, with its
    geometry."""
    from imgmtf.batch import MeasureSettings, measure_file
    (record,) = measure_file(str(real_scene("sentinel2_b04_bagnolo.tif")),
                             MeasureSettings(roi=(145, 470, 40, 45), force=True))
    assert record.status == "untrusted" and record.reason == "mtf-above-one"
    assert record.figures["direction"] == "unknown"


def test_a_photo_with_no_edge_is_refused():
    from skimage import data
    with pytest.raises(im.ImgmtfError) as info:
        im.measure_edge(data.coins())
    # coins' outlines hold short straight-looking chords: two of them far apart are two targets
    # (the message names both), or the rows' scatter about one says no straight edge
    assert info.value.reason in ("not-straight", "no-target", "not-an-edge", "two-targets")
    if info.value.reason == "two-targets":
        assert str(info.value).count("px from the top-left pixel") == 2


def test_the_shared_data_variable_points_the_tests_at_a_copy(tmp_path, monkeypatch):
    """IMGMTF_SHARED_DATA names the folder holding real-scenes/ wherever it
    lies; unset, the tests look beside the repository (../shared/data)."""
    import subprocess
    import sys
    copy = tmp_path / "elsewhere"
    (copy / "real-scenes").mkdir(parents=True)
    tests = Path(__file__).parent
    code = ("import conftest, sys; print(conftest.REAL_SCENES)")
    found = subprocess.run([sys.executable, "-c", code], cwd=tests, capture_output=True, text=True, check=True,
                           env={**__import__("os").environ, "IMGMTF_SHARED_DATA": str(copy)}).stdout.strip()
    assert found == str(copy / "real-scenes")
    default = subprocess.run([sys.executable, "-c", code], cwd=tests, capture_output=True, text=True, check=True,
                             env={k: v for k, v in __import__("os").environ.items() if k != "IMGMTF_SHARED_DATA"})
    assert default.stdout.strip() == str(tests.resolve().parents[1] / "shared" / "data" / "real-scenes")
    # set but missing a scene: the test fails rather than skips
    import conftest
    monkeypatch.setenv("IMGMTF_SHARED_DATA", str(copy))
    monkeypatch.setattr(conftest, "REAL_SCENES", copy / "real-scenes")
    with pytest.raises(pytest.fail.Exception, match="no real-scenes/missing.tif there"):
        conftest.real_scene("missing.tif")


def test_every_test_finds_the_shared_data_where_the_variable_says():
    """No test file but conftest builds the shared data's path itself (one
    that did ignored IMGMTF_SHARED_DATA and always skipped elsewhere)."""
    here = Path(__file__).parent
    own = [p.name for p in sorted(here.glob("test_*.py")) if p.name != Path(__file__).name
           and re.search(r"""["']shared["']""", p.read_text())]
    assert own == []


@pytest.mark.parametrize("name, reason, said", [
    # in light the bright side's level falls by 13 % of the contrast towards the crop's bottom rows
    ("x0552_y1976_F16", "non-uniform", "the bright side's level drifts by 13 % of the contrast along"),
    # and here by 16 % along the edge (as stored, the encoding squeezes both under the 10 % allowed)
    ("x2084_y0616_F2", "non-uniform", "the bright side's level drifts by 16 % of the contrast along"),
    # the bright side darkens away from the edge: an MTF above 1 at the lowest frequencies
    ("x2088_y0616_F2_8", "mtf-above-one", "the lowest frequencies"),
])
def test_the_real_camera_edges_linearised_are_refused_for_what_they_are(name, reason, said):
    raster = read_raster(DATA / f"{name}.png")
    with pytest.raises(im.ImgmtfError) as info:
        im.measure_edge(raster.data, dtype=raster.dtype, transfer="srgb")
    assert info.value.reason == reason and said in str(info.value)

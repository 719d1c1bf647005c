"""The synthetic campaign: scenes of a degrading sensor, their tags, and a
truth that is the sensor model's exact MTF."""
import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

import imgmtf as im
from imgmtf.cli.main import main
from imgmtf.errors import ParameterError
from imgmtf.scene.measure import scan_scene
from imgmtf.scene.targetfit import fit_targets
from imgmtf.sensor.series import SyntheticCampaign
from imgmtf.synthetic import write_campaign


def test_the_truth_is_the_degraded_sensors_exact_mtf():
    campaign = SyntheticCampaign(acquisitions=3, degradation=0.1, optics_sigma_px=(0.3, 0.5))
    for k in range(3):
        grow = 1 + 0.1 * k * 365 / 365.25
        # Gaussian optics times the pixel's sinc, at 0.5 cy/px
        for axis, sigma in (("across", 0.3), ("along", 0.5)):
            exact = math.exp(-2 * math.pi**2 * (sigma * grow) ** 2 * 0.25) * 2 / math.pi
            assert campaign.truth(k)[f"mtf_nyquist_{axis}"] == pytest.approx(exact, rel=1e-9)
    years = [campaign.years(k) for k in range(3)]
    for axis in ("across", "along"):
        values = [campaign.truth(k)[f"mtf_nyquist_{axis}"] for k in range(3)]
        assert campaign.true_slopes_per_year()[axis] == pytest.approx(np.polyfit(years, values, 1)[0])
    assert campaign.acquired_utc(2) == "2022-06-01T03:30:00Z"


@pytest.mark.parametrize("bad", [dict(acquisitions=1), dict(start_utc="soon"), dict(bits=12),
                                 dict(degradation=-0.1), dict(size_px=50)])
def test_a_campaign_out_of_range_is_refused(bad):
    with pytest.raises(ParameterError):
        SyntheticCampaign(**bad)


def test_a_written_campaign_carries_its_tags_and_truth_and_the_fit_recovers_it(tmp_path):
    # cut out of their scenes (an L0R chip's 0-fill): the four inner half-edges, a quick fit
    campaign = SyntheticCampaign(acquisitions=2, size_px=128, interval_days=730.0, degradation=0.1, seed=2, fill=True)
    paths = write_campaign(tmp_path, campaign, platform="SAT-9", instrument="CAM", band_name="B1")
    assert [p.name for p in paths] == ["site_20200601T033000.tif", "site_20220601T033000.tif"]
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert (tmp_path / "truth.csv").read_text().count("\n") == 3
    for k, path in enumerate(paths):
        raster = im.read_raster(path)
        assert {key: raster.tags[key] for key in ("ACQUISITION_DATETIME", "PLATFORM", "INSTRUMENT", "BAND_NAME")} \
            == {"ACQUISITION_DATETIME": campaign.acquired_utc(k), "PLATFORM": "SAT-9", "INSTRUMENT": "CAM",
                "BAND_NAME": "B1"}
        assert raster.provenance["truth"] == {key: v for key, v in truth["acquisitions"][k].items() if key != "file"}
    # the degraded sensor's across- and along-track MTF, read off the tilted target by the fit
    rows = fit_targets(scan_scene(str(paths[1])))
    assert len(rows) == 2
    for row in rows:
        axis = row.figures["direction"].split("-")[0]
        low, high = row.figures["mtf_nyquist_ci"]
        assert low <= campaign.truth(1)[f"mtf_nyquist_{axis}"] <= high


def test_cli_simulate_campaign_prints_the_truth_and_refuses_what_a_campaign_is_not(tmp_path):
    result = CliRunner().invoke(main, ["simulate", "--campaign", str(tmp_path / "c"), "--acquisitions", "2",
                                       "--size", "96", "--bits", "8"])
    assert result.exit_code == 0, result.output
    assert "site_20210601T033000.tif     2021-06-01T03:30:00Z               0.3608  0.2394" in result.output
    assert im.read_raster(tmp_path / "c" / "site_20200601T033000.tif").dtype == "uint8"
    result = CliRunner().invoke(main, ["simulate", "--campaign", str(tmp_path / "d"), "--start", "soon"])
    assert result.exit_code == 1 and "ISO 8601" in result.output and "Traceback" not in result.output
    result = CliRunner().invoke(main, ["simulate", "--campaign", str(tmp_path / "d"), "--angle", "5"])
    assert result.exit_code == 2 and "--angle makes a single chip: not with --campaign" in result.output
    result = CliRunner().invoke(main, ["simulate", "--out", str(tmp_path / "e.tif"), "--degradation", "0.1"])
    assert result.exit_code == 2 and "--degradation describes a campaign" in result.output
    result = CliRunner().invoke(main, ["simulate"])
    assert result.exit_code == 2 and "--out FILE" in result.output


def test_an_l0r_campaign_has_exponential_wings_a_halo_and_a_lag_its_scenes_show(tmp_path):
    # (bench/campaign.py scans a whole L0R campaign and checks the fit's rows against this truth)
    campaign = SyntheticCampaign(acquisitions=2, size_px=128, seed=3, fill=True, blur="l0r")
    assert [s.name for s in campaign.sensor(1).stages] == ["optics", "detector", "diffusion", "halo", "lag"]
    assert campaign.truth(0)["stages"] == ["optics", "detector", "diffusion", "halo", "lag"]
    assert 0.05 < campaign.truth(1)["mtf_nyquist_along"] < campaign.truth(0)["mtf_nyquist_across"] < 0.2
    assert campaign.as_dict()["blur"] == "l0r" and campaign.optics_sigma_px == (0.25, 0.3)
    scene = campaign.render(1)
    path = write_campaign(tmp_path, campaign, platform="P", instrument="I", band_name="B")[1]
    records = [r for r in scan_scene(str(path)) if r.ok]
    assert len(records) == 4
    for record in records:
        truth = float(scene.true_mtf(0.5, record.figures["normal_angle_deg"]))
        low, high = record.figures["mtf_nyquist_ci"]
        assert low - 0.01 <= truth <= high + 0.01
    with pytest.raises(ParameterError, match="blur"):
        SyntheticCampaign(blur="motion")

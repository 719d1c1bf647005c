import csv

import pytest
from click.testing import CliRunner

from imgmtf.cli import main
from imgmtf.reproduce import QUICK, StudySize, _seed, measure_chips, thresholds


def read(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """``imgmtf reproduce --quick`` on a study made smaller still (the
    figures, tables and report are all there; few chips: two noise levels
    of each sweep, one chip each, 6 chips where the quick study has 28)."""
    out = tmp_path_factory.mktemp("quick")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("imgmtf.reproduce.QUICK", StudySize(QUICK.system_stds[:2], 1, 1))
        patch.setattr("imgmtf.reproduce.GROUND_SNRS", (10, 100))
        patch.setattr("imgmtf.reproduce.THRESHOLD_SNRS", (20, 100))
        result = CliRunner().invoke(main, ["reproduce", "--quick", "--workers", "1", "--no-progress",
                                           "--out", str(out)])
    return out, result


def test_results_do_not_depend_on_the_number_of_workers():
    tasks = [("system", i, float(std), 1200.0, False, _seed(3, 1, i), ("msg",)) for i, std in enumerate((2, 9))]
    tasks.append(("ground", 0, 0.0, 1500.0, True, _seed(3, 2, 0, 0), ("msg",)))
    assert measure_chips(tasks, 1) == measure_chips(tasks, 2)


def test_cli_quick_run_reports_and_says_it_is_quick(quick_run):
    out, r = quick_run
    assert r.exit_code == 0, r.output
    assert "thresholds: n/a (a quick run: 1 chips per SNR level are too few" in r.stdout
    assert "trustworthy" not in r.stdout                     # no threshold from a handful of chips
    assert not r.stderr                                       # --no-progress: no bars
    assert len(read(out / "system_noise.csv")) == 2 * 4       # 2 chips x every method


def test_report_and_figures_are_written(quick_run):
    one = quick_run[0]
    report = (one / "report.md").read_text()
    for heading in ("Tables 1 and 2", "Figures 9-10", "Figure 12", "Figures 13-14", "SNR threshold",
                    "too few to find a threshold"):
        assert heading in report
    for png in ("fig02_03_sensor.png", "fig09_edge_estimates.png", "fig10_pulse_estimates.png",
                "fig12_system_noise.png", "fig13_ground_noise_layers.png", "fig14_ground_noise.png",
                "threshold.png"):
        assert (one / png).stat().st_size > 5000
    rows = read(one / "tables_1_2.csv")
    model = [r for r in rows if r["method"] == "model"]
    assert {r["target"] for r in model} == {"edge", "pulse"}
    msg = [r for r in rows if r["method"] == "msg" and r["corrected"] == "yes"]
    assert all(abs(float(r["mtf_diff_pct"])) < 1.0 for r in msg)


def test_threshold_rule():
    import imgmtf.reproduce as r
    true = 0.25
    levels = r.THRESHOLD_SNRS
    rows = []
    for snr in levels:
        value = true * (1.2 if snr < 40 else 1.01)          # good from SNR 40 on
        rows.append({"snr_nominal": snr, "results": {"m": (value, snr)}})
    found = thresholds(rows, true, ("m",))
    assert found["m"]["threshold"] == 40
    assert found["m"]["fractions"][30] == 0.0 and found["m"]["fractions"][40] == 1.0


def test_cli_reports_unwritable_folder(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    r = CliRunner().invoke(main, ["reproduce", "--quick", "--out", str(blocker / "sub")])
    assert r.exit_code == 1 and "cannot create" in r.stderr

import csv

import pytest
from click.testing import CliRunner

from imgmtf.cli import main
from imgmtf.reproduce import QUICK, StudySize, run_study, thresholds


def read(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def quick_runs(tmp_path_factory):
    """The quick study with one method, in one process and in two."""
    one = tmp_path_factory.mktemp("one")
    two = tmp_path_factory.mktemp("two")
    small = StudySize(QUICK.system_stds[:4], 2, 3)
    import imgmtf.reproduce as r
    old = r.QUICK
    r.QUICK = small
    try:
        a = run_study(one, quick=True, workers=1, seed=3, methods=("msg",))
        b = run_study(two, quick=True, workers=2, seed=3, methods=("msg",))
    finally:
        r.QUICK = old
    return one, two, a, b


def test_results_do_not_depend_on_the_number_of_workers(quick_runs):
    one, two, a, b = quick_runs
    for name in ("system_noise.csv", "ground_noise.csv", "threshold.csv", "tables_1_2.csv"):
        assert read(one / name) == read(two / name)
    assert a["thresholds"] == b["thresholds"]


def test_report_and_figures_are_written(quick_runs):
    one = quick_runs[0]
    report = (one / "report.md").read_text()
    for heading in ("Tables 1 and 2", "Figure 12", "Figures 13-14", "SNR threshold"):
        assert heading in report
    for png in ("fig02_03_sensor.png", "fig12_system_noise.png", "fig13_ground_noise_layers.png",
                "fig14_ground_noise.png", "threshold.png"):
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


def test_cli_quick_run(tmp_path):
    r = CliRunner().invoke(main, ["reproduce", "--quick", "--workers", "2", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    assert "msg      trustworthy from SNR" in r.stdout
    assert (tmp_path / "report.md").exists() and len(read(tmp_path / "system_noise.csv")) == 8 * 4

"""Drift per year against closed forms: weighted least squares, Student-t
intervals, Birge scaling; the grouping of a store's rows."""
import csv
import math

import numpy as np
import pytest

from imgmtf._stats import t_quantile
from imgmtf.campaign.trend import TREND_COLUMNS, fit_line, trends, write_trend_csv, years_since
from imgmtf.errors import ParameterError

T975 = {2: 4.302652729911275, 3: 3.182446305284263, 4: 2.7764451051977987}


def test_the_t_quantiles_used_are_the_tables():
    for dof, value in T975.items():
        assert t_quantile(0.975, dof) == pytest.approx(value, rel=1e-6)


def test_an_exact_line_gives_its_slope_and_the_intervals_own_width():
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    line = fit_line(t, 0.30 - 0.012 * t, sd=np.full(5, 0.004))
    half = T975[3] * 0.004 / math.sqrt(np.sum((t - 2.0) ** 2))          # sd / sqrt(sum (t - mean)^2)
    assert line.slope == pytest.approx(-0.012, abs=1e-15) and line.intercept == pytest.approx(0.30, abs=1e-15)
    assert (line.low, line.high) == (pytest.approx(-0.012 - half, rel=1e-6), pytest.approx(-0.012 + half, rel=1e-6))
    assert line.consistency == pytest.approx(0.0, abs=1e-9) and line.weights == "inverse-variance"


def test_scatter_beyond_the_intervals_widens_the_slopes_interval_by_the_birge_ratio():
    t = np.arange(5.0)
    wiggle = 0.01 * np.array([1.0, -1.0, 0.0, -1.0, 1.0])     # orthogonal to 1 and t: the slope stays exact
    line = fit_line(t, 0.2 + 0.005 * t + wiggle, sd=np.full(5, 0.001))
    # chi^2 = sum r^2 / sd^2; se^2 = chi^2 / 3 / sum((t - 2)^2 / sd^2) = sum r^2 / 3 / 10, free of sd
    half = T975[3] * math.sqrt(4e-4 / 3 / 10)
    assert line.slope == pytest.approx(0.005, abs=1e-14)
    assert line.high - line.slope == pytest.approx(half, rel=1e-6)
    assert line.consistency == pytest.approx(math.sqrt(4e-4 / 1e-6 / 3))


def test_without_intervals_the_residuals_alone_set_the_width():
    t = np.arange(5.0)
    wiggle = 0.01 * np.array([1.0, -1.0, 0.0, -1.0, 1.0])
    line = fit_line(t, 0.2 + 0.005 * t + wiggle, sd=[0.001, 0.001, math.nan, 0.001, 0.001])
    assert line.weights == "equal" and line.high - line.slope == pytest.approx(T975[3] * math.sqrt(4e-4 / 3 / 10))


def test_a_point_with_a_wide_interval_hardly_counts():
    t = np.arange(5.0)
    y = 0.3 - 0.01 * t
    y[2] += 0.2
    line = fit_line(t, y, sd=[0.002, 0.002, 1e4, 0.002, 0.002])
    assert line.slope == pytest.approx(-0.01, abs=1e-9)


def test_two_points_give_a_slope_without_interval_and_one_time_none():
    line = fit_line([0.0, 2.0], [0.3, 0.28], sd=[0.01, 0.01])
    assert line.slope == pytest.approx(-0.01) and math.isnan(line.low) and math.isnan(line.high)
    with pytest.raises(ParameterError, match="two acquisitions at different times"):
        fit_line([1.0, 1.0], [0.3, 0.2])


def row(k, when, value, *, direction="across-track", method="fit", scope="scene", half=0.005, **extra):
    return {"acquisition_id": f"a{k}", "acquired_utc": when, "platform": "Simsat", "band_name": "pan",
            "direction": direction, "method": method, "scope": scope, "mtf_nyquist": value,
            "mtf_nyquist_ci_low": value - half, "mtf_nyquist_ci_high": value + half,
            "mtf50_cy_px": None, "fwhm_px": None, "rer": None, **extra}


def test_trends_per_platform_band_direction_and_method_from_scene_rows_first():
    years = [2020, 2021, 2022, 2023, 2024, 2025]
    rows = [row(k, f"{y}-07-02T00:00:00Z", 0.30 - 0.01 * (y - 2020)) for k, y in enumerate(years)]
    rows += [row(k, f"{y}-07-02T00:00:00Z", 0.9, scope="target") for k, y in enumerate(years)]  # scene rows win
    rows += [row(9, None, 0.0)]                                                         # no time: left out
    rows += [row(k, f"{y}-07-02", 0.25, direction="along-track", method="combined", scope="target")
             for k, y in enumerate(years[:3])]                                            # targets only: used
    found = {(t.direction, t.method): t for t in trends(rows) if t.figure == "mtf_nyquist"}
    assert set(found) == {("across-track", "fit"), ("along-track", "combined")}
    across = found["across-track", "fit"]
    t = years_since([f"{y}-07-02T00:00:00Z" for y in years], "2020-07-02T00:00:00Z")
    slope = np.polyfit(t, [0.30 - 0.01 * (y - 2020) for y in years], 1)[0]    # the calendar's leap days
    half = T975[4] * (0.005 / 1.959963984540054) / math.sqrt(np.sum((t - t.mean()) ** 2))
    assert across.slope_per_year == pytest.approx(slope, rel=1e-9)
    assert across.slope_ci_high - across.slope_per_year == pytest.approx(half, rel=1e-6)
    assert across.drift and across.n_acquisitions == 6 and across.first_utc == "2020-07-02T00:00:00Z"
    assert across.value_at_first == pytest.approx(0.30, abs=1e-4)
    along = found["along-track", "combined"]
    assert along.slope_per_year == 0.0 and not along.drift and along.n_points == 3


def test_a_stable_sensor_is_not_flagged():
    values = [0.30, 0.31, 0.29, 0.30, 0.31, 0.29]
    rows = [row(k, f"{2020 + k}-01-01", v, half=0.02) for k, v in enumerate(values)]
    [trend] = [t for t in trends(rows) if t.figure == "mtf_nyquist"]
    assert trend.slope_ci_low < 0 < trend.slope_ci_high and not trend.drift


def test_trend_csv_has_the_documented_columns(tmp_path):
    rows = [row(k, f"{2020 + k}-01-01", 0.3 - 0.01 * k, fwhm_px=1.2 + 0.01 * k) for k in range(4)]
    path = tmp_path / "trend.csv"
    write_trend_csv(trends(rows), str(path))
    with open(path, newline="") as fh:
        got = list(csv.DictReader(fh))
    assert tuple(got[0]) == TREND_COLUMNS
    assert {"platform", "band_name", "direction", "method", "n_acquisitions", "first_utc", "last_utc",
            "slope_per_year", "slope_ci_low", "slope_ci_high", "drift"} <= set(TREND_COLUMNS)
    assert [(r["figure"], r["drift"]) for r in got] == [("mtf_nyquist", "True"), ("fwhm_px", "True")]


def test_a_targets_two_oblique_directions_make_two_trends():
    rows = []
    for k in range(3):
        rows.append(row(k, f"{2020 + k}-01-01", 0.30 - 0.01 * k, direction="oblique", method="combined",
                        normal_angle_deg=16.8 + 0.1 * k))
        rows.append(row(k, f"{2020 + k}-01-01", 0.20 - 0.02 * k, direction="oblique", method="combined",
                        normal_angle_deg=-73.2 - 0.1 * k))
    found = {t.direction: t for t in trends(rows) if t.figure == "mtf_nyquist"}
    assert set(found) == {"oblique (normal 17 deg)", "oblique (normal -73 deg)"}
    assert found["oblique (normal 17 deg)"].slope_per_year == pytest.approx(-0.01, rel=0.01)
    assert found["oblique (normal -73 deg)"].slope_per_year == pytest.approx(-0.02, rel=0.01)


def test_two_unnamed_sensors_are_never_one_trend():
    # the real Baotou and PAN chips name no platform: before, they made one line between two sensors
    rows = [row(0, "2021-06-01", 0.11, platform=None, sensor_key="101 x 101 px uint16"),
            row(1, "2022-06-01", 0.09, platform=None, sensor_key="80 x 80 px uint16, SSTL Terra v1.1.4.0")]
    found = [t for t in trends(rows) if t.figure == "mtf_nyquist"]
    assert sorted(t.sensor for t in found) == ["unnamed: 101 x 101 px uint16",
                                               "unnamed: 80 x 80 px uint16, SSTL Terra v1.1.4.0"]
    assert all(not t.has_slope and t.note == "one acquisition: no slope" and not t.drift for t in found)
    same = [row(k, f"{2021 + k}-06-01", 0.11 - 0.01 * k, platform=None, sensor_key="101 x 101 px uint16")
            for k in range(3)]
    [joined] = [t for t in trends(same) if t.figure == "mtf_nyquist"]
    assert joined.n_acquisitions == 3 and joined.slope_per_year == pytest.approx(-0.01, rel=1e-2)
    alone = [row(k, f"{2021 + k}-06-01", 0.11, platform=None) for k in range(2)]       # an older store
    assert len([t for t in trends(alone) if t.figure == "mtf_nyquist"]) == 2


def test_misfit_rows_are_listed_but_never_trended_and_never_recommended():
    rows = [row(k, f"{2020 + k}-01-01", 0.002 + 0.001 * k, misfit=1) for k in range(4)]
    rows += [row(k, f"{2020 + k}-01-01", 0.12 - 0.01 * k, method="sections", assumption="bracket",
                 recommended=1) for k in range(4)]
    found = {t.method: t for t in trends(rows) if t.figure == "mtf_nyquist"}
    fit, sections = found["fit"], found["sections"]
    assert fit.misfit and not fit.recommended and not fit.has_slope and fit.note.startswith("misfit: not trended")
    assert fit.n_acquisitions == 4 and fit.latest == pytest.approx(0.005)
    assert sections.recommended and sections.assumption == "bracket" and sections.drift
    assert sections.slope_per_year == pytest.approx(-0.01, rel=1e-2)


def test_a_method_recommended_in_some_years_only_makes_two_series():
    rows = [row(k, f"{2020 + k}-01-01", 0.12, method="sections", recommended=int(k < 2)) for k in range(4)]
    found = sorted((t.recommended, t.n_acquisitions) for t in trends(rows) if t.figure == "mtf_nyquist")
    assert found == [(False, 2), (True, 2)]


def test_the_requirement_is_judged_on_the_latest_acquisitions_interval():
    from imgmtf.campaign.trend import requirement_verdict
    rows = [row(k, f"{2020 + k}-01-01", 0.30 - 0.05 * k, half=0.01) for k in range(3)]   # latest 0.20 +- 0.01
    [t] = [t for t in trends(rows) if t.figure == "mtf_nyquist"]
    assert (t.latest, t.latest_ci_low, t.latest_ci_high) == (pytest.approx(0.20), pytest.approx(0.19),
                                                             pytest.approx(0.21))
    assert [requirement_verdict(t, r) for r in (0.18, 0.185, 0.205, 0.22, None)] == [
        "pass", "pass", "undecided", "fail", ""]
    [fwhm] = [t for t in trends([row(0, "2020-01-01", 0.3, fwhm_px=1.4)]) if t.figure == "fwhm_px"]
    assert requirement_verdict(fwhm, 1.3) == "pass" and requirement_verdict(fwhm, 1.5) == "fail"  # value alone
    misfit = [t for t in trends([row(0, "2020-01-01", 0.3, misfit=1)]) if t.figure == "mtf_nyquist"]
    assert requirement_verdict(misfit[0], 0.1) == ""


def test_a_requirement_per_direction_is_read_and_applied():
    from imgmtf.campaign.trend import Requirement, requirement_verdict
    need = Requirement.parse("0.1, along=0.3, oblique (normal 17 deg)=0.05")
    assert (need.for_direction("across-track"), need.for_direction("along-track"),
            need.for_direction("oblique (normal 17 deg)")) == (0.1, 0.3, 0.05)
    assert Requirement.parse("across-track=0.2").for_direction("along-track") is None
    assert Requirement.of(0.25) == Requirement(0.25) and Requirement.of(None) is None
    rows = [row(0, "2020-01-01", 0.2, half=0.01), row(0, "2020-01-01", 0.2, direction="along-track", half=0.01)]
    verdicts = {t.direction: requirement_verdict(t, need) for t in trends(rows) if t.figure == "mtf_nyquist"}
    assert verdicts == {"across-track": "pass", "along-track": "fail"}
    for bad in ("1.5", "across=", "=0.1", "across=0.1,across=0.2", "0.1,0.2", "nan", "fast"):
        with pytest.raises(ParameterError, match="requirement"):
            Requirement.parse(bad)

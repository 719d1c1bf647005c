"""Records: one typed row, its JSON and CSV forms, provenance, and the
streaming CSV writer that keeps rows on an interrupt."""
import csv
import json
import math
import re

import pytest

import imgmtf as im
from imgmtf.errors import FileWriteError, ImageReadError
from imgmtf.records import CSV_COLUMNS, SCAN_CSV_COLUMNS, CsvWriter, Record, curve_values, to_json, utc_now

SUMMARY = {"target": "edge", "method": "msg", "angle_deg": 6.0, "snr": 120.0, "mtf_nyquist": 0.27,
           "mtf_nyquist_ci": [0.26, 0.28], "mtf50_cy_px": 0.36, "mtf50_ci_cy_px": [0.35, 0.37],
           "fwhm_px": 1.2, "roi": [0, 0, 64, 64], "warnings": ["a warning"], "noise_limit_cy_px": math.inf,
           "params": {"order": 4}, "imgmtf_version": "x"}


def test_measured_record_is_flat_json_with_provenance():
    record = Record.measured("a.tif", 1, SUMMARY, params={"bootstrap": {"replicates": 200}},
                             run_utc="2024-05-01T09:30:00Z")
    row = json.loads(to_json(record))
    assert row["status"] == "ok" and row["reason"] is None and row["error"] is None
    assert row["mtf50_cy_px"] == 0.36 and row["noise_limit_cy_px"] is None      # inf is not JSON
    assert row["params"] == {"bootstrap": {"replicates": 200}, "order": 4}
    assert row["imgmtf_version"] == im.__version__ and row["run_utc"] == "2024-05-01T09:30:00Z"


def test_failed_record_has_a_reason_and_a_message_naming_the_file():
    exc = ImageReadError("b.tif: no such file")
    record = Record.failed("b.tif", None, "edge", "msg", exc, params={}, run_utc=utc_now())
    assert (record.reason, record.error) == ("unreadable", "b.tif: no such file")
    other = Record.failed("c.tif", 2, "edge", "msg", KeyError("mtf50"), params={}, run_utc="")
    assert other.reason == "internal" and other.error == "c.tif: band 2: internal error: KeyError: 'mtf50'"
    decode = UnicodeDecodeError("utf-8", b"\x80", 0, 1, "invalid start byte")   # has a .reason of its own
    assert Record.failed("d.tif", None, "edge", "msg", decode, params={}, run_utc="").reason == "internal"


def test_csv_schema_names_units_and_scan_extends_it():
    assert CSV_COLUMNS[:7] == ("path", "band", "target", "method", "status", "reason", "error")
    assert set(CSV_COLUMNS) < set(SCAN_CSV_COLUMNS) and SCAN_CSV_COLUMNS[:2] == ("id", "rank")
    record = Record.measured("a.tif", 1, SUMMARY, params={}, run_utc="t")
    row = record.csv_row()
    assert row["mtf_nyquist_ci_low"] == 0.26 and row["mtf50_ci_high_cy_px"] == 0.37
    assert row["roi_px"] == "[0, 0, 64, 64]" and json.loads(row["warnings"]) == ["a warning"]
    assert row["noise_limit_cy_px"] == "" and row["rer"] == ""
    # the record answers every CSV column by the CSV's name, as the CSV holds it
    for column in ("mtf_nyquist_ci_low", "mtf_nyquist_ci_high", "mtf50_ci_low_cy_px", "mtf50_ci_high_cy_px"):
        assert record.get(column) == row[column]
    assert record.get("roi_px") == [0, 0, 64, 64] and record.get("mtf_at_0.50_cy_px", "-") == "-"


def test_utc_timestamp_is_iso_8601():
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", utc_now())


def test_csv_rows_are_on_disk_as_written_and_the_file_appears_whole(tmp_path):
    path = tmp_path / "out.csv"
    record = Record.measured("a.tif", 1, SUMMARY, params={}, run_utc="t")
    with CsvWriter(path) as out:
        out.write(record)
        assert not path.exists()                       # in place only when complete
        partial, = tmp_path.glob(".out.csv.*")
        assert len(list(csv.DictReader(partial.open()))) == 1
    assert [r["path"] for r in csv.DictReader(path.open())] == ["a.tif"]
    assert not list(tmp_path.glob(".out.csv.*"))


def test_an_interrupt_keeps_the_rows_and_an_error_keeps_the_old_file(tmp_path):
    path = tmp_path / "out.csv"
    record = Record.measured("a.tif", 1, SUMMARY, params={}, run_utc="t")
    with pytest.raises(KeyboardInterrupt):
        with CsvWriter(path) as out:
            out.write(record)
            raise KeyboardInterrupt
    assert len(list(csv.DictReader(path.open()))) == 1
    with pytest.raises(ValueError):
        with CsvWriter(path) as out:
            raise ValueError("a bug")
    assert len(list(csv.DictReader(path.open()))) == 1  # the earlier complete file is untouched
    assert not list(tmp_path.glob(".out.csv.*"))


def test_unwritable_csv_is_named(tmp_path):
    blocker = tmp_path / "afile.txt"
    blocker.write_text("x")
    with pytest.raises(FileWriteError, match="afile.txt/sub/out.csv: cannot write"):
        with CsvWriter(blocker / "sub" / "out.csv"):
            pass


def test_csv_rows_carry_the_mtf_curve_on_a_fixed_grid():
    from imgmtf.records import CURVE_COLUMNS, curve_values
    f = [i / 100 for i in range(101)]
    summary = {**SUMMARY, "frequencies_cy_px": f, "mtf": [1 - x / 2 for x in f[:60]] + [None] * 41}
    row = Record.measured("a.tif", 1, summary, params={}, run_utc="t").csv_row()
    assert set(CURVE_COLUMNS) <= set(CSV_COLUMNS) and CURVE_COLUMNS[10] == "mtf_at_0.50_cy_px"
    assert row["mtf_at_0.50_cy_px"] == 0.75 and row["mtf_at_0.25_cy_px"] == 0.875
    assert row["mtf_at_0.70_cy_px"] == ""                  # undefined there (a bar's sinc zero)
    record = Record.measured("a.tif", 1, summary, params={}, run_utc="t")
    assert record.get("mtf_at_0.50_cy_px") == 0.75 and record.get("mtf_at_0.70_cy_px") is None
    assert all(v is None for v in curve_values(None, None).values())   # failures: empty cells


def test_json_and_csv_hold_no_negative_zero():
    """A normal at -0.0 deg is written 0.0 in JSON and CSV, as the text
    table prints 0.00; NaN is null in JSON, empty in CSV."""
    record = Record.measured("a.tif", 1, {"normal_angle_deg": -0.0, "mtf_nyquist": float("nan"),
                                          "mtf_nyquist_ci": [-0.0, 0.1], "target": "edge", "method": "msg"},
                             params={}, run_utc="2024-05-01T09:30:00Z")
    line = to_json(record)
    assert "-0.0" not in line and '"normal_angle_deg": 0.0' in line and '"mtf_nyquist": null' in line
    row = record.csv_row()
    assert str(row["normal_angle_deg"]) == "0.0" and row["mtf_nyquist_ci_low"] == 0.0
    assert str(row["mtf_nyquist_ci_low"]) == "0.0" and row["mtf_nyquist"] == ""


def test_json_lines_match_the_values_made_safe_first():
    """The encoder writes a row at once and makes it safe only when it holds a NaN, an infinity or a -0.0
    as a value: the same text as json_safe before json.dumps, whatever the row holds (NumPy scalars and
    arrays, such tokens inside strings, a repeated frequency grid equal but for -0.0, or of ints)."""
    import numpy as np

    from imgmtf.records import JsonRows, json_safe
    from imgmtf.safe_json import _json_default
    grid = [0.0, 0.25, 0.5]
    figures = [
        {"frequencies_cy_px": grid, "mtf": [1.0, 0.5, 0.1], "note": "a NaN, -0.0] and -Infinity} in text"},
        {"frequencies_cy_px": [-0.0, 0.25, 0.5], "mtf": [1.0, float("nan"), -0.0], "tilt_deg": np.float64(-0.0)},
        {"frequencies_cy_px": [0, 0.25, 0.5], "mtf": np.array([1.0, -0.0]), "misfit": np.bool_(True)},
        {"frequencies_cy_px": grid, "n": np.int64(3), "levels_dn": (np.float32(-np.inf), 2.5), "x": -0.01},
        {"frequencies_cy_px": list(grid), "mtf": [1.0, 0.4, 0.05], "checks": [{"value": None, "limit": 0.3}]},
    ]
    rows = JsonRows()
    for extra in figures:
        record = Record("a.tif", 1, "edge", "msg", "ok", figures=extra, params={"order": 4})
        safe = json.dumps(json_safe(record.to_dict()), default=_json_default)
        assert to_json(record) == safe
        assert rows.line(record) == safe


def test_finite_values_are_the_floats_round_gives():
    """A curve rounded at once: the very floats of round(v, 6) (signed zeros too), None where not finite,
    near ties (where the product's own rounding could move the integer) and ties included."""
    import numpy as np

    from imgmtf.records import finite_values
    rng = np.random.default_rng(5)
    ties = (rng.integers(0, 10**7, 2000) + 0.5) / 1e6
    values = np.concatenate([rng.uniform(-2, 2, 2000), 10.0 ** rng.uniform(-12, 12, 2000), ties,
                             ties + rng.uniform(-1e-12, 1e-12, 2000), np.arange(4096) / 4096,
                             [np.nan, np.inf, -np.inf, -0.0, 0.0, 1e300, -5e-7, 5e-7, 2.5e-6, -1e-9]])
    got = finite_values(values)
    want = [round(v, 6) if math.isfinite(v) else None for v in values.tolist()]
    assert [(g, math.copysign(1, g)) if g is not None else None for g in got] == \
           [(w, math.copysign(1, w)) if w is not None else None for w in want]


def test_csv_cells_are_the_values_made_safe_first():
    """A CSV row's cells as json_safe and json.dumps(sort_keys=True) make them, whatever the row holds."""
    import numpy as np

    from imgmtf.records import json_safe
    from imgmtf.safe_json import _json_default
    figures = {"mtf_nyquist": np.float64(-0.0), "mtf_nyquist_ci": (0.25, float("nan")), "snr": float("inf"),
               "rows_used": np.int64(40), "sharpened": np.bool_(False), "warnings": ["NaN, -0.0]"],
               "levels_dn": [2.0, -0.0], "feature": {"b": 1, "a": float("nan")}, "fwhm_px": -0.0,
               "frequencies_cy_px": [0.0, 0.5, 1.0], "mtf": [1.0, 0.25, None]}
    record = Record("a.tif", 1, "edge", "msg", "ok", figures=figures, params={"order": 4})
    flat = record.to_dict()
    flat.update(curve_values(flat["frequencies_cy_px"], flat["mtf"]))
    for column, cell in record.csv_row(SCAN_CSV_COLUMNS).items():
        source = {"mtf_nyquist_ci_low": ("mtf_nyquist_ci", 0), "mtf_nyquist_ci_high": ("mtf_nyquist_ci", 1),
                  "mtf50_ci_low_cy_px": ("mtf50_ci_cy_px", 0), "mtf50_ci_high_cy_px": ("mtf50_ci_cy_px", 1),
                  "roi_px": "roi"}.get(column, column)
        value = (flat.get(source[0]) or (None, None))[source[1]] if isinstance(source, tuple) else flat.get(source)
        if isinstance(value, (list, tuple, dict)):
            value = json.dumps(json_safe(value), sort_keys=True, default=_json_default)
        elif isinstance(value, float):
            value = json_safe(value)
        assert repr(cell) == repr("" if value is None else value), column       # -0.0 == 0.0, not alike in CSV

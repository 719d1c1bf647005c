"""One exit-code convention in every command: a value outside the range
--help prints, or options that contradict each other, exit 2 (a usage
error, before any work); a problem found in an input exits 1."""
import math

import click
import pytest
from click.testing import CliRunner

from imgmtf.cli import main
from imgmtf.cli.main import COMMANDS

#: what each command needs besides the option under test (inputs are never
#: read: the option fails first)
REQUIRED = {"measure": ["x.tif"], "scan": ["x.tif"], "fit": ["x.tif"], "simulate": ["--out", "x.tif"],
            "reproduce": ["--out", "out"], "sensor": [], "selftest": [],
            "restore": ["x.tif", "--sensor", "s.toml", "--target-nyquist", "0.4", "--out", "o.tif"],
            "report": ["s.gpkg", "--out", "o"]}


def out_of_range(kind: click.ParamType) -> list[str]:
    """Values just outside a click range type's bounds, and NaN for floats."""
    values = []
    if isinstance(kind, click.FloatRange):
        values.append("nan")
    step = 1 if isinstance(kind, click.IntRange) else 1e-9
    if kind.min is not None:
        values.append(str(kind.min if kind.min_open else kind.min - max(step, abs(kind.min) * 1e-9)))
    if kind.max is not None:
        values.append(str(kind.max if kind.max_open else kind.max + max(step, abs(kind.max) * 1e-9)))
    if isinstance(kind, click.FloatRange) and not math.isinf(kind.max or 0.0):
        values.append("inf")
    return values


RANGED = [(command.name, option.opts[0], value)
          for command in COMMANDS for option in command.params
          if isinstance(option, click.Option) and isinstance(option.type, (click.IntRange, click.FloatRange))
          for value in out_of_range(option.type)]


def test_every_ranged_option_is_covered():
    # the options checked by a click range type, in every command (those
    # checked by a callback are listed below)
    assert {(c, o) for c, o, _ in RANGED} >= {
        ("measure", "--workers"), ("measure", "--bootstrap"), ("measure", "--confidence"),
        ("measure", "--track-azimuth"), ("scan", "--min-length"), ("scan", "--max-length"), ("scan", "--margin"),
        ("scan", "--band"), ("fit", "--gsd"), ("fit", "--band"), ("fit", "--confidence"), ("simulate", "--angle"),
        ("simulate", "--size"), ("simulate", "--oversampling"), ("simulate", "--seed"), ("simulate", "--gsd"),
        ("simulate", "--noise-std"), ("reproduce", "--workers"), ("reproduce", "--seed")}


@pytest.mark.parametrize("command, option, value", RANGED)
def test_a_value_outside_the_range_help_prints_exits_2(command, option, value):
    result = CliRunner().invoke(main, [command, *REQUIRED[command], option, value])
    assert result.exit_code == 2, (command, option, value, result.output)
    assert "Traceback" not in result.output


# options checked by a callback or by the settings they build, with a value out of range
CHECKED = [
    ("measure", "--bootstrap", "10", "0 or 20<=x<=5000"),
    ("scan", "--bootstrap", "19", "0 or 20<=x<=5000"),
    ("measure", "--target pulse --pulse-width", "-1", "must be > 0"),
    ("measure", "--target pulse --pulse-width", "0.1", "narrower than 0.2 px"),
    ("measure", "--target pulse --pulse-width", "15px", "below 0.1 cy/px"),
    ("measure", "--target pulse --pulse-width", "inf", "finite"),
    ("scan", "--target pulse --pulse-width", "0.1px", "narrower than 0.2 px"),
    ("scan", "--target pulse --pulse-width", "11", "below 0.1 cy/px"),
    ("simulate", "--target pulse --pulse-width", "0.1", "narrower than the 0.2 px"),
    ("measure", "--roi", "0,0,8,8", "W, H >= 16 px"),
    ("measure", "--roi", "-1,0,20,20", "X, Y >= 0"),
    ("fit", "--roi", "0,0,20", "four integers"),
    ("measure", "--band", "0", "numbered from 1"),
    ("measure", "--saturation", "10,5", "LO < HI"),
    ("scan", "--saturation", "nan,5", "LO < HI"),
    ("measure", "--method", "median", "is not one of"),
    ("selftest", "--method", "median", "is not one of"),
    ("fit", "--stages", "optics,lens", "unknown stage 'lens'"),
    ("fit", "--stages", "optics,optics", "named twice"),
    ("measure", "--plot", "figure.txt", "a figure is written as png"),
    ("sensor", "--plot", "figure.doc", "a figure is written as png"),
    ("simulate", "--out", "chip.jpg", "GeoTIFF (.tif, .tiff)"),
]


@pytest.mark.parametrize("command, option, value, words", CHECKED)
def test_a_value_its_check_refuses_exits_2_naming_the_limit(command, option, value, words, tmp_path,
                                                             monkeypatch):
    monkeypatch.chdir(tmp_path)
    required = [a for a in REQUIRED[command] if option != "--out"]
    result = CliRunner().invoke(main, [command, *required, *option.split(), value])
    assert result.exit_code == 2, (command, option, value, result.output)
    assert words in result.output and "Traceback" not in result.output


# options that contradict each other
CONTRADICTIONS = [
    ("measure", ["a.tif", "--plot", "p.png", "--plot-dir", "plots"], "--plot or --plot-dir"),
    ("measure", ["a.tif", "--pulse-width", "2"], "--target pulse or --target double-bar only"),
    ("measure", ["a.tif", "--intervals", "none", "--bootstrap", "200"], "give one"),
    ("measure", ["a.tif", "--intervals", "influence", "--bootstrap", "0"], "give one"),
    ("scan", ["a.tif", "--pulse-width", "2"], "--target pulse or --target double-bar only"),
    ("scan", ["a.tif", "--min-length", "100", "--max-length", "50"], "below --min-length"),
    ("scan", ["a.tif", "--edge-figures"], "give --out DIR"),
    ("scan", ["a.tif", "--intervals", "bootstrap", "--bootstrap", "0"], "give one"),
    ("simulate", ["--out", "a.tif", "--pulse-width", "2"], "--target pulse or --target double-bar only"),
    ("simulate", ["--out", "a.tif", "--target", "pulse"], "needs --pulse-width"),
    ("restore", ["a.tif", "b.tif", "--sensor", "s.toml", "--target-nyquist", "0.4", "--out", "o.tif",
                 "--plot", "p.png"], "take a single image"),
    ("simulate", ["--out", "a.tif", "--target", "pulse", "--pulse-width", "60", "--size", "50"],
     "wider than the chip"),
    ("simulate", ["--out", "a.tif", "--offset", "100", "--size", "50"], "outside the 50 x 50 px chip"),
    ("simulate", ["--out", "a.tif", "--ground-noise", "--size", "100", "--oversampling", "50"],
     "render a smaller chip or lower the oversampling"),
    ("fit", ["a.tif", "--stages", "optics", "--hold", "detector"], "cannot hold 'detector'"),
    ("fit", ["a.tif", "--hold", "optics.width_m"], "cannot hold 'optics.width_m'"),
    ("scan", ["a.tif", "--platform", "X"], "give --campaign STORE.gpkg"),
    ("scan", ["a.tif", "--fit-stages", "optics,lens"], "unknown stage 'lens'"),
    ("scan", ["a.tif", "--campaign", "s.gpkg", "--acquired", "last spring"], "is not an ISO 8601 date"),
]


@pytest.mark.parametrize("command, args, words", CONTRADICTIONS)
def test_options_that_contradict_each_other_exit_2(command, args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, [command, *args])
    assert result.exit_code == 2, (command, args, result.output)
    assert words in result.output and "Traceback" not in result.output
    assert not (tmp_path / "a.tif").exists()


def test_plot_with_several_inputs_is_a_contradiction_found_once_folders_are_expanded(tmp_path):
    data = __import__("pathlib").Path(__file__).parent.parent / "data"
    result = CliRunner().invoke(main, ["measure", str(data / "edge_16bit.tif"), str(data / "edge_8bit_noisy.tif"),
                                       "--plot", str(tmp_path / "one.png")])
    assert result.exit_code == 2 and "--plot takes a single input, got 2 files" in result.output
    result = CliRunner().invoke(main, ["measure", str(data), "--plot", str(tmp_path / "one.png")])
    assert result.exit_code == 2 and "use --plot-dir for several" in result.output
    assert not (tmp_path / "one.png").exists()


def test_a_problem_found_in_an_input_still_exits_1(tmp_path):
    result = CliRunner().invoke(main, ["measure", str(tmp_path / "missing.tif")])
    assert result.exit_code == 1 and "missing.tif: no such file" in result.output
    toml = tmp_path / "bad.toml"
    toml.write_text("gsd_m = -1\n")
    result = CliRunner().invoke(main, ["simulate", "--sensor", str(toml), "--out", str(tmp_path / "a.tif")])
    assert result.exit_code == 1 and "bad.toml" in result.output


def test_the_replicate_bounds_are_the_estimators():
    from imgmtf.cli import options
    from imgmtf.estimate import intervals
    assert options.MAX_REPLICATES == intervals.MAX_REPLICATES
    with pytest.raises(intervals.ParameterError):
        intervals.Intervals("bootstrap", replicates=options.MIN_REPLICATES - 1)
    intervals.Intervals("bootstrap", replicates=options.MIN_REPLICATES)


def test_the_pulse_widths_help_prints_are_the_estimators():
    from imgmtf.inputs import MIN_BAR_WIDTH_PX, MIN_FIRST_ZERO_CY_PX
    bounds = f"{MIN_BAR_WIDTH_PX:g} to {1 / MIN_FIRST_ZERO_CY_PX:g} px"
    for command in ("measure", "scan"):
        help_text = CliRunner().invoke(main, [command, "--help"], terminal_width=400).output
        assert bounds in " ".join(help_text.split())

"""The split between the library and the command line: a library message says
what is wrong with the data, the CLI adds the option that answers it from the
reason code."""
import ast
import importlib.util
import pathlib
import pkgutil
import re

import numpy as np
import pytest
from click.testing import CliRunner

import imgmtf
from imgmtf.cli import main
from imgmtf.cli.hints import (
    CHIP,
    HINTS,
    OPTION,
    SCAN,
    WARNING,
    Command,
    hinted_warning,
    option_hints,
    refusal_hint,
    rejection_hint,
)
from imgmtf.cli.main import COMMANDS

PACKAGE = pathlib.Path(imgmtf.__file__).parent
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z-]+")


def _message_strings(path):
    """Every string constant of a module but its docstrings and comments."""
    tree = ast.parse(path.read_text())
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
                  and node.body and isinstance(node.body[0], ast.Expr)
                  and isinstance(node.body[0].value, ast.Constant)}
    return [node.value for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings]


def test_no_library_message_names_a_command_line_option():
    # the package's modules as Python finds them (not every file below it: a
    # build left a module's old copy beside the package that replaced it)
    modules = [importlib.util.find_spec(m.name).origin for m in pkgutil.walk_packages(imgmtf.__path__, "imgmtf.")
               if ".cli" not in m.name]
    named = {f"{pathlib.Path(path).relative_to(PACKAGE)}: {text!r}"
             for path in modules for text in _message_strings(pathlib.Path(path)) if FLAG.search(text)}
    assert len(modules) > 50 and not named


@pytest.mark.parametrize("reason, option", [
    ("two-targets", "--roi"), ("not-an-edge", "--target pulse"), ("not-a-bar", "--target edge"),
    ("too-large", "--roi"), ("bands", "--band"), ("bar-width", "--pulse-width"), ("fit", "--stages"),
])
def test_the_cli_answers_a_reason_with_its_option(reason, option):
    message = "a message; " + next(h.words for h in HINTS if h.command == CHIP and h.reason == reason)
    answers = option_hints(CHIP, reason, message)
    # one answer per refusal, per command ("--band all" only where --band takes it)
    assert option in refusal_hint(reason, message) and option in answers[0]
    assert len(answers) == len({h.only for h in HINTS if h.command == CHIP and h.reason == reason})


def test_a_reason_no_option_answers_gets_no_option():
    assert refusal_hint("unreadable", "cannot read") == ""


def test_a_window_too_large_is_not_told_to_give_a_window():
    whole = "a.tif: the image is 6000 x 6000 px (36.0 million pixels), ...; measure a window of it"
    window = "a.tif: the window is 5000 x 5000 px (25.0 million pixels), ...; measure a smaller window"
    assert "--roi" in refusal_hint("too-large", whole) and refusal_hint("too-large", window) == ""


def test_a_warning_names_the_option_that_answers_it_where_the_command_has_it():
    unknown = "the image is not in sensor geometry (map-projected): ...; give the track's azimuth to label it"
    measure, fit = (Command.of(next(c for c in COMMANDS if c.name == name)) for name in ("measure", "fit"))
    assert hinted_warning(unknown, running=measure) == unknown + " (--track-azimuth DEG gives it)"
    assert hinted_warning(unknown, running=fit) == unknown
    assert hinted_warning("another warning", running=measure) == "another warning"


def test_a_wrong_kind_is_told_every_other_registered_kind():
    from imgmtf.kinds import kind_names
    for reason, kind in (("not-a-star", "star"), ("not-points", "points")):
        [hint] = option_hints(CHIP, reason)
        assert all(name in hint for name in kind_names() if name != kind) and f" {kind}" not in hint


def test_a_double_bar_refusal_says_once_what_measures_it_with_its_spacing():
    message = "two parallel bars 3.0 px apart (the profile dips to 7% of its peaks between them), not one bar"
    hint = refusal_hint("double-bar", message)
    assert "--target double-bar --pulse-width W --gap G" in hint and "W + G near 3.0 px" in hint
    from imgmtf.estimate.bar_pair import BarPair
    assert "measure" not in BarPair(0.0, 3.0, 0.1).message()       # the hint says it, once


def test_a_gamma_encoded_file_is_told_the_transfer_option():
    from imgmtf.file_notes import file_notes
    from imgmtf.io import Raster
    measure = Command.of(next(c for c in COMMANDS if c.name == "measure"))
    for band in (1, "luminance"):
        raster = Raster(np.zeros((4, 4)), "edge.png", band=band, gsd_m=None, dtype="uint8")
        [note] = [n for n in file_notes(raster) if "gamma" in n]
        assert hinted_warning(note, running=measure).endswith("(--transfer srgb or --transfer gamma:G linearises them)")
        assert hinted_warning(note, running=Command("x", frozenset())) == note


@pytest.mark.parametrize("reason, message, option", [
    ("too-short", "the line is 12 px long, shorter than the minimum 20 px", "--min-length"),
    ("two-targets", "its ROI reaches another edge", "--margin"),
    ("not-an-edge", "a bar, not an edge", "--target pulse"), ("not-a-bar", "a lone edge", "--target edge"),
])
def test_a_scan_answers_a_rejection_with_the_option_that_moves_its_limit(reason, message, option):
    assert option in rejection_hint(reason, message) and "imgmtf scan" not in rejection_hint(reason, message)


def test_a_scan_names_no_option_where_none_moves_the_limit():
    # too few rows clear of the junctions shares its reason with a too-short line
    assert rejection_hint("too-short", "too few rows clear of the junctions") == ""
    assert rejection_hint("fill", "the ROI holds fill") == ""


def test_every_hint_is_for_a_command_that_shows_it_and_names_an_option():
    assert {h.command for h in HINTS} == {CHIP, SCAN, WARNING}
    assert all(FLAG.search(h.text) for h in HINTS)
    assert len({(h.command, h.reason, h.words, h.only) for h in HINTS}) == len(HINTS)   # one answer per refusal


def _every_refusal():
    """(reason, message) of every refusal a hint may answer: the reasons the
    hints, the gate's forcible checks and a scan's remedies name, each with
    every message a hint looks for."""
    from imgmtf.cli.hints import SCAN_SOLVES
    from imgmtf.estimate.gate import FORCIBLE
    reasons = {h.reason for h in HINTS} | FORCIBLE | SCAN_SOLVES | {"misfit", "noise-dominated", "untrusted"}
    messages = {h.words for h in HINTS} | {"", "two straight pieces meet inside the chip"}
    return [(r, m) for r in sorted(reasons) for m in sorted(messages)]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c.name)
def test_every_hint_a_command_gives_names_only_options_it_has(command):
    running = Command.of(command)
    for reason, message in _every_refusal():
        for hint in (refusal_hint(reason, message, "x.tif", running=running),
                     rejection_hint(reason, message, running=running)):
            named = set(OPTION.findall(hint))
            assert named <= running.options, (command.name, reason, message, hint)


def test_every_hint_reaches_some_command_and_only_measure_takes_band_all():
    running = [Command.of(c) for c in COMMANDS]
    for h in HINTS:
        assert any(r.gives(h.text, h.only) for r in running), h
    fit = Command.of(next(c for c in COMMANDS if c.name == "fit"))
    assert refusal_hint("bands", "", running=fit) == " (--band N chooses one)"
    assert refusal_hint("fit", "", running=fit) == " (--stages fits fewer, --hold holds some)"
    assert refusal_hint("fill", "", "a.tif", running=fit) == (
        " (--roi X,Y,W,H once per file fits the edges imgmtf scan finds; imgmtf scan a.tif finds and measures "
        "each edge in it; --force measures it anyway)")
    restore = Command.of(next(c for c in COMMANDS if c.name == "restore"))
    assert refusal_hint("fill", "", "a.tif", running=restore) == \
        " (imgmtf scan a.tif finds and measures each edge in it)"
    assert refusal_hint("misfit", "", running=restore) == " (--allow-misfit restores with it anyway)"
    assert refusal_hint("misfit", "", running=fit) == ""


def test_a_command_s_refusal_names_its_own_options_end_to_end(tmp_path):
    # a two-band file that is not RGB: fit is told of --band N, never of measure's --band all
    image = np.zeros((2, 60, 60), np.uint16)
    import rasterio
    with rasterio.open(tmp_path / "two.tif", "w", driver="GTiff", width=60, height=60, count=2, dtype="uint16",
                       transform=rasterio.Affine(1.0, 0.0, 0.0, 0.0, -1.0, 60.0)) as dst:
        dst.write(image)
    fit = CliRunner().invoke(main, ["fit", str(tmp_path / "two.tif")])
    measure = CliRunner().invoke(main, ["measure", str(tmp_path / "two.tif")])
    assert fit.exit_code == 1 and "(--band N chooses one)" in fit.output and "all" not in fit.output
    assert "--band all measures each" in measure.output

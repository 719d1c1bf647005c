"""The split between the library and the command line: a library message says
what is wrong with the data, the CLI adds the option that answers it from the
reason code."""
import ast
import importlib.util
import pathlib
import pkgutil
import re

import pytest

import imgmtf
from imgmtf.cli.hints import CHIP, HINTS, SCAN, option_hints, refusal_hint, rejection_hint

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
    answers = option_hints(CHIP, reason)
    # one answer per refusal, per command ("--band all" only where --band takes it)
    assert option in refusal_hint(reason, "a message") and option in answers[0]
    assert len(answers) == len({h.only for h in HINTS if h.command == CHIP and h.reason == reason})


def test_a_reason_no_option_answers_gets_no_option():
    assert refusal_hint("unreadable", "cannot read") == ""


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
    assert {h.command for h in HINTS} == {CHIP, SCAN}
    assert all(FLAG.search(h.text) for h in HINTS)
    assert len({(h.command, h.reason, h.words, h.only) for h in HINTS}) == len(HINTS)   # one answer per refusal

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
from imgmtf.cli.errors import OPTION_HINTS, refusal_hint

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
    assert option in refusal_hint(reason, "a message") and option in OPTION_HINTS[reason]


def test_a_reason_no_option_answers_gets_no_option():
    assert refusal_hint("unreadable", "cannot read") == ""

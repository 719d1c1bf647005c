"""The package's docstring examples, module by module, as doctests (the
documents' examples run in tests/test_docs.py)."""
import doctest
import importlib
import pkgutil

import pytest

import imgmtf

DOCTEST_FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
MODULES = sorted(m.name for m in pkgutil.walk_packages(imgmtf.__path__, "imgmtf."))


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                       # examples may write files
    module = importlib.import_module(name)
    runner = doctest.DocTestRunner(optionflags=DOCTEST_FLAGS)
    report: list[str] = []
    for test in doctest.DocTestFinder().find(module, name):
        runner.run(test, out=report.append)
    assert not runner.failures, "".join(report)

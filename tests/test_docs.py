"""Every example a user reads runs, so that none can drift from the code.

* README.md and docs/*.md: each document's fenced blocks run in order in a
  fresh folder holding the sample ``data/`` (the README's Python examples as
  ``python -m doctest README.md`` runs them): ``console`` blocks through the
  CLI (each ``$ imgmtf ...`` line, its exit status 0 unless the line ends
  with a ``# exit status N`` comment, and the output shown beneath it, where
  ``...`` stands for any text, as in a doctest; a command shown without
  output prints nothing; ``> FILE`` sends what it prints to FILE),
  ``python`` blocks as doctests sharing the document's names, ``toml``
  blocks read as sensor files.
* No other block shows a command (``$ imgmtf ...``) but the few that
  :data:`RECORDED` names with why the suite cannot run them.
* (The package's docstring examples: tests/test_docstring_examples.py, a
  file of its own so that a parallel run spreads the two.)

When a change moves what a command prints, ``python tests/test_docs.py
--update`` rewrites the console outputs the documents show (lines with
``...`` kept where they still match); read the diff before committing it.
"""
import doctest
import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

import imgmtf
from imgmtf.cli import main

from conftest import real_scene

ROOT = Path(__file__).parent.parent
# pages whose examples their own authors keep (the accuracy study, the
# method), and the generated reproduction report
OTHERS = {"accuracy.md", "method.md"}
# pages whose examples read the shared real scenes (never copied into the repository): linked into
# the folder the examples run in (under the name the page gives it; a shapefile's parts in their
# folder), the page skipped where they are absent (conftest.real_scene)
REAL_SCENES_READ = {"docs/scan.md": {"baotou_l0r_checkerboard.tif": "baotou_l0r_checkerboard.tif"},
                    "docs/restore.md": {"baotou.tif": "baotou_l0r_checkerboard.tif"},
                    "docs/regions.md": {name: name for name in (
                        "sentinel2_b04_bagnolo.tif",
                        *(f"bagnolo_roi/mtf_al_bagnolo.{e}" for e in ("shp", "shx", "dbf", "prj")))}}
# blocks that show commands the suite does not run, each (document, its first command) with why
RECORDED: dict[tuple[str, str], str] = {}
DOCUMENTS = ["README.md", *(f"docs/{p.name}" for p in sorted((ROOT / "docs").glob("*.md"))
                            if p.name not in OTHERS)]
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.MULTILINE | re.DOTALL)
EXIT_STATUS = re.compile(r"#\s*exit status (\d+)")
DOCTEST_FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def fenced_blocks(text: str):
    """(language, body, line number) of every fenced block."""
    for match in FENCE.finditer(text):
        yield match[1], match[2], text.count("\n", 0, match.start()) + 1


def fence_name(text: str, line: int) -> str | None:
    """The file name a fence gives after its language (```toml prelaunch.toml), if any."""
    words = text.splitlines()[line - 1].split()
    return words[1] if len(words) > 1 else None


def console_steps(body: str):
    """(command line, expected output lines) of a console block."""
    steps: list[tuple[str, list[str]]] = []
    for line in body.splitlines():
        if line.startswith("$ "):
            steps.append((line[2:], []))
        elif steps:
            steps[-1][1].append(line)
        elif line.strip():
            raise AssertionError(f"output before any command: {line!r}")
    return steps


def run_command(command: str, where: str) -> list[str]:
    """Run one ``$ imgmtf ...`` line, check its exit status, return its
    output lines (stdout and stderr as a terminal shows them; with
    ``> FILE``, stderr's, stdout written to FILE)."""
    args = shlex.split(command, comments=True)
    assert args[0] == "imgmtf", f"{where}: console blocks run imgmtf only, got {command!r}"
    redirect = None
    if len(args) > 2 and args[-2] == ">":
        args, redirect = args[:-2], args[-1]
    status = EXIT_STATUS.search(command)
    result = CliRunner().invoke(main, args[1:])
    assert result.exit_code == int(status[1] if status else 0), (
        f"{where}: `{command}` exited {result.exit_code}:\n{result.output}")
    shown = result.output
    if redirect is not None:
        Path(redirect).write_text(result.stdout)
        shown = result.stderr
    return [line.rstrip() for line in shown.strip("\n").splitlines()]


def run_console(body: str, where: str) -> None:
    checker = doctest.OutputChecker()
    for command, expected in console_steps(body):
        got = run_command(command, where)
        if any(line.strip() for line in expected):
            want = "\n".join(line.rstrip() for line in expected).strip("\n") + "\n"
            assert checker.check_output(want, "\n".join(got) + "\n", doctest.ELLIPSIS), (
                f"{where}: `{command}` printed\n" + "\n".join(got) + f"\nthe document shows\n{want}"
                + "(python tests/test_docs.py --update rewrites what the documents show)")
        else:       # shown without output: it prints none (a reader would not expect a table)
            assert not got, (f"{where}: `{command}` printed\n" + "\n".join(got) + "\nthe document shows "
                             "nothing (python tests/test_docs.py --update writes it; ... stands for lines left out)")


def run_python(body: str, globs: dict, where: str) -> None:
    if ">>>" not in body:
        exec(compile(body, where, "exec"), globs)
        return
    test = doctest.DocTestParser().get_doctest(body, globs, where, where, 0)
    report: list[str] = []
    runner = doctest.DocTestRunner(optionflags=DOCTEST_FLAGS)
    runner.run(test, out=report.append, clear_globs=False)
    globs.update(test.globs)                          # the next block sees this one's names
    assert not runner.failures, "".join(report)


@pytest.fixture
def sample_folder(tmp_path, monkeypatch):
    """A fresh working folder with the repository's sample data in data/."""
    (tmp_path / "data").symlink_to(ROOT / "data", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("document", DOCUMENTS)
def test_every_example_of_the_document_runs(document, sample_folder):
    link_real_scenes(document, sample_folder)
    text = (ROOT / document).read_text()
    globs: dict = {"__name__": "__docs__"}
    ran = 0
    for language, body, line in fenced_blocks(text):
        where = f"{document}:{line}"
        if language == "console":
            run_console(body, where)
        elif language == "python" and document != "README.md":     # README: python -m doctest, below
            run_python(body, globs, where)
        elif language == "toml":         # a fence of ```toml NAME writes NAME, which later commands read
            path = sample_folder / (fence_name(text, line) or f"block{line}.toml")
            path.write_text(body)
            imgmtf.Sensor.from_toml(path)
        else:
            continue
        ran += 1
    assert ran or document != "README.md"
    assert_ignored(sample_folder)


def link_real_scenes(document: str, folder: Path) -> None:
    for link, name in REAL_SCENES_READ.get(document, {}).items():
        (folder / link).parent.mkdir(exist_ok=True)         # a shapefile's parts, in their folder
        (folder / link).symlink_to(real_scene(name))


def test_every_block_that_shows_a_command_runs_or_says_why_not():
    shown = {}
    for document in DOCUMENTS:
        for language, body, line in fenced_blocks((ROOT / document).read_text()):
            commands = [c for c, _ in console_steps(body)] if body.lstrip().startswith("$ ") else []
            if commands and language != "console":
                shown[(document, commands[0])] = line
    assert sorted(set(shown) - set(RECORDED)) == [] and sorted(set(RECORDED) - set(shown)) == []


def assert_ignored(folder: Path) -> None:
    """Every file or folder the examples wrote, run from the repository's
    root as a newcomer runs them, is one .gitignore covers."""
    import shutil
    import subprocess
    linked = {name.split("/")[0] for names in REAL_SCENES_READ.values() for name in names}
    written = [p.name + "/" * p.is_dir() for p in folder.iterdir()
               if p.name != "data" and not p.name.startswith("block") and p.name not in linked]
    if not written or not shutil.which("git") or not (ROOT / ".git").exists():
        return
    ignored = subprocess.run(["git", "-C", str(ROOT), "check-ignore", "--no-index", *written],
                             capture_output=True, text=True).stdout.split()
    missing = sorted(set(written) - set(ignored))
    assert not missing, f"examples write files .gitignore does not cover: {', '.join(missing)}"


def test_python_m_doctest_passes_on_the_readme(sample_folder):
    """The README's Python examples as `python -m doctest README.md` runs
    them: the whole file one docstring, no option flags (a fence right under
    an output line becomes part of the expected output there)."""
    failures, tried = doctest.testfile(str(ROOT / "README.md"), module_relative=False, verbose=False,
                                       report=True, optionflags=0)
    assert tried and not failures
    assert_ignored(sample_folder)


def test_every_page_reading_real_scenes_says_how_to_link_them():
    """A newcomer runs a page's commands in a folder of their own: each real
    scene (or shapefile folder) it reads is one the page says how to link
    from ../shared/data beside the clone."""
    for document, links in REAL_SCENES_READ.items():
        text = " ".join((ROOT / document).read_text().split())     # a command may wrap
        for link, name in links.items():
            top, source = link.split("/")[0], name.split("/")[0]
            target = f"ln -s ../shared/data/real-scenes/{source}"
            assert target in text and (top == source or f"{target} {top}" in text), (document, link)


def test_the_readme_says_early_what_the_tests_take_and_need():
    first_screen = "\n".join((ROOT / "README.md").read_text().splitlines()[:40])
    assert "under a minute" not in first_screen and "minutes on 2 cores" in first_screen
    assert "IMGMTF_SHARED_DATA" in first_screen and "skip" in first_screen


def test_the_readme_tells_how_to_install_and_test_and_ci_runs_that():
    readme = (ROOT / "README.md").read_text()
    first_screen = "\n".join(readme.splitlines()[:40])
    for command in ("python3 -m venv .venv && . .venv/bin/activate", "pip install . && imgmtf selftest",
                    "pip install '.[test]' && pytest"):
        assert command in first_screen
    ci = (ROOT / ".ci" / "run").read_text()
    assert '".[$extras]"' in ci and "make_env .venv-ci test" in ci and "\n    pytest" in ci
    assert "\nrun_tests .venv-ci\n" in ci and "\nrun_tests .venv-ci-lowest\n" in ci     # both environments tested


def update_console_outputs(document: str) -> None:
    """Rewrite the outputs a document's console blocks show with what the
    commands print now, in a fresh folder as the test runs them; a shown
    line that still matches (``...`` included) is kept as written."""
    import os
    import tempfile
    text = (ROOT / document).read_text()
    checker = doctest.OutputChecker()
    with tempfile.TemporaryDirectory() as folder:
        here = os.getcwd()
        os.chdir(folder)
        os.symlink(ROOT / "data", "data", target_is_directory=True)
        link_real_scenes(document, Path(folder))
        globs: dict = {"__name__": "__docs__"}
        try:
            for language, body, line in list(fenced_blocks(text)):
                if language == "toml" and fence_name(text, line):
                    Path(fence_name(text, line)).write_text(body)
                if language == "python" and document != "README.md":    # what the commands after it read
                    try:                                                  # (camera.md's chart.png)
                        run_python(body, globs, f"{document}:{line}")
                    except AssertionError as exc:                         # its output is the test's to judge
                        print(f"{document}:{line}: a Python example's output differs:\n{exc}")
                if language != "console":
                    continue
                lines = []
                for command, expected in console_steps(body):
                    got = run_command(command, f"{document}:{line}")
                    shown = [e.rstrip() for e in expected]
                    if any(shown) and len(shown) == len(got):
                        got = [e if checker.check_output(e + "\n", g + "\n", doctest.ELLIPSIS) else g
                               for e, g in zip(shown, got)]
                    elif any(shown) and checker.check_output("\n".join(shown) + "\n", "\n".join(got) + "\n",
                                                             doctest.ELLIPSIS):
                        got = shown                 # an abbreviated output ("...") that still matches
                    lines += [f"$ {command}", *got]
                text = text.replace(body, "\n".join(lines) + "\n", 1)
        finally:
            os.chdir(here)
    (ROOT / document).write_text(text)


if __name__ == "__main__":
    import sys
    if sys.argv[1:] != ["--update"]:
        raise SystemExit("usage: python tests/test_docs.py --update  (rewrites the console outputs the docs show)")
    for name in DOCUMENTS:
        update_console_outputs(name)
        print(f"updated {name}")


def test_the_readme_explains_every_reason_the_gate_gives():
    from imgmtf.estimate.gate import FORCIBLE
    table = [line for line in (ROOT / "README.md").read_text().splitlines() if line.startswith("| `")]
    listed = {code for line in table for code in re.findall(r"`([a-z-]+)`", line.split("|")[1])}
    assert sorted(FORCIBLE - listed) == []

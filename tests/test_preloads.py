"""The fork server preloads the command line only where its workers import it."""
import os
import subprocess
import sys

import pytest

PROBE = '''
import multiprocessing
from imgmtf.preloads import CLI_MODULES, main_run_again
from rerun_probe import rerun

if __name__ == "__main__":
    with multiprocessing.get_context("forkserver").Pool(1) as pool:
        print(main_run_again(), pool.apply(rerun), CLI_MODULES)
'''


@pytest.mark.parametrize("how, again", [(["probe.py"], True), (["-m", "package"], False), (["-m", "probe"], True)])
def test_the_main_module_is_said_run_again_where_a_worker_runs_it_again(tmp_path, how, again):
    """A script (the ``imgmtf`` command's) and a module run by ``-m`` are run
    again in each worker as ``__mp_main__``; a package's ``__main__``
    (``python -m imgmtf``) is not, and its fork server need not import the
    command line for them."""
    if "forkserver" not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip("no fork server on this platform")
    (tmp_path / "rerun_probe.py").write_text(
        "import sys\n\ndef rerun():\n    return sys.modules['__main__'].__name__ == '__mp_main__'\n")
    (tmp_path / "probe.py").write_text(PROBE)
    (tmp_path / "package").mkdir()
    (tmp_path / "package" / "__init__.py").write_text("")
    (tmp_path / "package" / "__main__.py").write_text(PROBE)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, *how], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().split(maxsplit=2) == [str(again), str(again), str(("imgmtf.cli",) if again else ())]

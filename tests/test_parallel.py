"""Parallel runs give the serial results, in input order, on local
processes and on a Dask distributed cluster."""
import json
import math
import os
import signal
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from imgmtf.cli import main
from imgmtf.errors import ParameterError
from imgmtf.parallel import run_tasks, signals_deferred

DATA = Path(__file__).parent.parent / "data"


def test_processes_keep_input_order():
    assert list(run_tasks(math.sqrt, [16, 9, 4, 1, 0], workers=2)) == [4, 3, 2, 1, 0]


def test_a_generators_items_are_taken_as_they_are_submitted():
    # a sequence is taken whole; a generator a few items ahead of the workers (the pool's first
    # submissions, IN_FLIGHT_PER_WORKER a worker), and a failed task's error names its own item
    from imgmtf.parallel import IN_FLIGHT_PER_WORKER
    taken = []

    def items():
        for x in [16, 9, -1, 4, 1, 0, 25, 36]:
            taken.append(x)
            yield x
    results = run_tasks(math.sqrt, items(), workers=2, ordered=False, on_error=lambda item, exc: f"{item}?")
    first = next(results)
    assert taken == [16, 9, -1, 4][:IN_FLIGHT_PER_WORKER * 2] and first in {(0, 4), (1, 3), (2, "-1?"), (3, 2)}
    assert sorted([first, *results]) == [(0, 4), (1, 3), (2, "-1?"), (3, 2), (4, 1), (5, 0), (6, 5), (7, 6)]
    taken.clear()
    here = run_tasks(math.sqrt, items(), workers=1)
    assert (next(here), taken) == (4, [16])


def test_a_worker_that_dies_fails_its_tasks_and_the_rest_still_report():
    # os._exit kills the worker running it: the pool breaks, and every task,
    # those running and those not yet submitted, gets one result each
    results = list(run_tasks(os._exit, [3] * 7, workers=2, on_error=lambda item, exc: str(exc)))
    assert len(results) == 7 and all("its worker process died" in r for r in results)
    from concurrent.futures.process import BrokenProcessPool
    with pytest.raises(BrokenProcessPool):
        list(run_tasks(os._exit, [3] * 3, workers=2))


def test_bad_worker_count_and_unreachable_scheduler(monkeypatch):
    with pytest.raises(ParameterError):
        list(run_tasks(math.sqrt, [1, 4], workers=0))
    pytest.importorskip("distributed")
    import imgmtf.parallel
    monkeypatch.setattr(imgmtf.parallel, "SCHEDULER_TIMEOUT_S", 1)
    with pytest.raises(ParameterError, match="cannot reach the Dask scheduler"):
        list(run_tasks(math.sqrt, [1, 4], scheduler="tcp://127.0.0.1:9"))


def test_measure_and_scan_on_a_local_dask_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    files = [str(DATA / "edge_16bit.tif"), str(DATA / "edge_8bit_noisy.tif"), str(tmp_path / "missing.tif")]
    serial = CliRunner().invoke(main, ["measure", "--format", "json", *files])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        on_dask = CliRunner().invoke(main, ["measure", "--format", "json", "--scheduler",
                                            cluster.scheduler_address, *files])
        scan = CliRunner().invoke(main, ["scan", "--format", "json", "--scheduler",
                                         cluster.scheduler_address, str(DATA / "scene.tif")])
    assert on_dask.exit_code == serial.exit_code == 1          # the missing file
    def rows(result):                  # each run has its own start time
        return [{k: v for k, v in json.loads(line).items() if k != "run_utc"}
                for line in result.stdout.splitlines()]
    assert rows(on_dask) == rows(serial)
    assert [json.loads(line)["path"] for line in on_dask.stdout.splitlines()] == files
    assert scan.exit_code == 0
    accepted = [r for r in map(json.loads, scan.stdout.splitlines()) if r["status"] == "accepted"]
    assert len(accepted) == 2


def test_prestarted_workers_are_used_once_and_never_left_behind(monkeypatch):
    # where there is no fork server: a pool of workers started ahead
    import multiprocessing

    from imgmtf import parallel
    monkeypatch.setattr(multiprocessing, "get_all_start_methods", lambda: ["spawn"])
    parallel.prestart_workers(2, ["json"])
    assert parallel._prestarted
    assert list(run_tasks(math.sqrt, [9, 4, 1], workers=2)) == [3, 2, 1]
    assert not parallel._prestarted
    parallel.prestart_workers(2, ["json"])
    assert list(run_tasks(math.sqrt, [9], workers=2)) == [3]     # one task runs here: the pool goes
    assert not parallel._prestarted


def test_workers_forked_from_a_fork_server_start_with_its_modules_and_one_thread(tmp_path):
    """prestart_workers starts the fork server importing the modules once
    (before the workers' fork), with one numerical-library thread (what the
    probe saw when the server imported it); the caller's environment is left
    as it was, and ``preloaded`` says the server has them.  A fork server
    already running is left alone: prestarted workers then import the
    modules themselves, and none is preloaded.  (In processes of their
    own: a process has one fork server.)"""
    import subprocess
    import sys
    if "forkserver" not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip("no fork server on this platform")
    (tmp_path / "probe.py").write_text(
        "import os, sys\n"
        "THREADS_AT_IMPORT, PID_AT_IMPORT = os.environ.get('OPENBLAS_NUM_THREADS'), os.getpid()\n"
        "def state(name):\n"
        "    return name in sys.modules, PID_AT_IMPORT != os.getpid(), THREADS_AT_IMPORT\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]),
           "OPENBLAS_NUM_THREADS": "7"}

    def run(before=""):
        code = ("import os, math; from imgmtf.parallel import preloaded, prestart_workers, run_tasks; " + before +
                "prestart_workers(2, ['probe', 'colorsys']); import probe; "
                "print(list(run_tasks(probe.state, ['colorsys', 'wave'], workers=2)), "
                "os.environ.get('OPENBLAS_NUM_THREADS'), preloaded(['probe']), preloaded(['probe', 'wave']))")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
        assert out.returncode == 0, out.stderr
        return out.stdout.strip()
    assert run() == "[(True, True, '1'), (False, True, '1')] 7 True False"
    # a fork server started before (by another pool): the workers import
    assert run("list(run_tasks(math.sqrt, [1, 4], workers=2)); ") == \
        "[(True, False, '1'), (False, False, '1')] 7 False False"


def test_a_signal_inside_a_deferred_block_is_handled_after_it(ctrl_c_raises):
    steps = []
    with pytest.raises(KeyboardInterrupt):
        with signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            steps.append("after the signal")        # the block is not cut short
    assert steps == ["after the signal"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_the_fork_server_preloads_what_every_worker_set_up_imports(monkeypatch):
    """Workers forked from the server start with the modules their set-up imports (threadpoolctl) loaded,
    beside those asked for, rather than each importing them as it starts."""
    from multiprocessing import forkserver

    from imgmtf import parallel
    preloaded = []
    monkeypatch.setattr(parallel, "_preloaded", set())
    monkeypatch.setattr(forkserver, "set_forkserver_preload", preloaded.extend)
    monkeypatch.setattr(forkserver, "ensure_running", lambda: None)
    parallel._start_fork_server(("imgmtf.batch",))
    assert preloaded == [*parallel.SERVER_PRELUDE, "imgmtf.batch", *parallel.WORKER_MODULES]
    assert "threadpoolctl" in preloaded


def test_the_fork_server_defers_numpys_unused_submodules():
    """In workers forked from the server, NumPy's f2py and testing are registered but not loaded (SciPy's
    first import would load them, 0.2-0.25 s), and load on first use; a process that merely imports the
    module keeps them as NumPy has them."""
    import subprocess
    import sys
    if "forkserver" not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip("no fork server on this platform")
    probe = ("(type(__import__('sys').modules['numpy.f2py']).__name__, "
             "'scipy.special' in __import__('sys').modules, "
             "__import__('numpy').testing.assert_allclose.__name__)")
    code = ("from imgmtf.parallel import prestart_workers, run_tasks\n"
            "if __name__ == '__main__':\n"
            "    prestart_workers(2, ['scipy.special'])\n"
            f"    print(list(run_tasks(eval, [{probe!r}], workers=2)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "[('_LazyModule', True, 'assert_allclose')]", out.stderr
    code = "import sys, imgmtf._server_numpy, numpy; print('numpy.f2py' in sys.modules, hasattr(numpy, 'f2py'))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.split() == ["False", "True"], out.stderr


def test_only_the_fork_server_skips_its_teardown(tmp_path):
    """The fork server, once its command has ended, exits without the interpreter's teardown (0.3 s with
    SciPy loaded, its inherited output pipes open meanwhile: a slow exit handler stands for it here); a
    process that merely imports the module keeps its exit status and exit handlers."""
    import subprocess
    import sys
    import time
    if "forkserver" not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip("no fork server on this platform")
    (tmp_path / "slow_exit.py").write_text("import atexit, time\natexit.register(time.sleep, 5)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    code = ("from imgmtf.parallel import prestart_workers, run_tasks; prestart_workers(2, ['slow_exit']); "
            "print(list(run_tasks(abs, [-1, -2], workers=2)))")
    t = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "[1, 2]", out.stderr
    assert time.perf_counter() - t < 4
    code = ("import atexit, sys, multiprocessing.forkserver, imgmtf._server_exit, imgmtf._fork_server as server; "
            "print(server.in_fork_server()); atexit.register(print, 'handled'); sys.exit(3)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 3 and out.stdout.split() == ["False", "handled"], out.stderr


def test_a_lone_task_goes_to_the_prestarted_fork_server(tmp_path):
    """A lone task goes to a worker of the server this process prestarted (its modules loaded there, not
    here); without a prestarted server it runs here."""
    import subprocess
    import sys
    if "forkserver" not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip("no fork server on this platform")
    (tmp_path / "lone_task.py").write_text("import os\ndef where(x):\n    return x, os.getpid()\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    code = ("import os, sys; from imgmtf.parallel import prestart_workers, run_tasks; "
            "started = sys.argv[1] == 'prestart'; started and prestart_workers(2, ['lone_task']); "
            "import lone_task; "
            "print(list(run_tasks(lone_task.where, [7], workers=2))[0][1] != os.getpid())")
    for asked, away in (("prestart", "True"), ("none", "False")):
        out = subprocess.run([sys.executable, "-c", code, asked], capture_output=True, text=True, env=env, timeout=60)
        assert out.returncode == 0 and out.stdout.split() == [away], out.stderr


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_a_worker_stopped_while_it_sends_its_result_does_not_hold_up_the_exit(tmp_path):
    """A worker terminated part-way through sending its result (a large one takes a while through the
    pipe) leaves part of a message in the pool's result pipe: an interrupted run still ends at once and
    without a traceback (the pool's manager thread waited for the rest of the message for ever, and the
    interpreter's exit for that thread)."""
    import subprocess
    import time
    (tmp_path / "half_sent.py").write_text(
        "import os, struct, sys, time\n"
        "def send_half(marker):\n"
        "    results = sys._getframe(1).f_locals['result_queue']   # the worker loop's, that calls the task\n"
        "    os.write(results._writer.fileno(), struct.pack('!i', 1 << 20) + bytes(16))   # 16 of 1 MiB\n"
        "    open(marker, 'w').close()\n"
        "    time.sleep(60)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    markers = [tmp_path / f"sent{i}" for i in range(6)]      # two running, the rest waiting (cancelled)
    code = ("import sys, half_sent; from imgmtf.parallel import run_tasks, terminate_raises\n"
            "try:\n"
            "    with terminate_raises():\n"
            "        list(run_tasks(half_sent.send_half, sys.argv[1:], workers=2))\n"
            "except KeyboardInterrupt:\n"
            "    from concurrent.futures.process import _ExecutorManagerThread\n"
            "    import threading\n"
            "    print(sum(isinstance(t, _ExecutorManagerThread) for t in threading.enumerate()))\n"
            "    sys.exit(143)\n")
    process = subprocess.Popen([sys.executable, "-c", code, *map(str, markers)], env=env, text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        end = time.monotonic() + 60
        while not all(m.exists() for m in markers[:2]) and time.monotonic() < end and process.poll() is None:
            time.sleep(0.05)
        assert all(m.exists() for m in markers[:2]), process.communicate()[1]
        process.send_signal(signal.SIGTERM)
        stdout, stderr = process.communicate(timeout=20)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == 143 and "Traceback" not in stderr and "Exception" not in stderr, stderr
    # the pool's manager thread has ended before the exit, which would otherwise race it (a traceback)
    assert stdout.split() == ["0"]


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_a_worker_that_dies_while_it_sends_its_result_breaks_the_pool_rather_than_hang_it(tmp_path):
    """A worker killed part-way through sending its result (by the system: out of memory) leaves part of a
    message in the pool's result pipe, and the pool never sees the death; the run still ends, every task
    with a result, the dead worker's a failure."""
    import subprocess
    (tmp_path / "dies_sending.py").write_text(
        "import os, struct, sys\n"
        "def send_half_and_die(x):\n"
        "    if x == 0:\n"
        "        results = sys._getframe(1).f_locals['result_queue']   # the worker loop's, that calls the task\n"
        "        os.write(results._writer.fileno(), struct.pack('!i', 1 << 20) + bytes(16))   # 16 of 1 MiB\n"
        "        os._exit(9)\n"
        "    return x\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    code = ("import json, dies_sending; from imgmtf import parallel; from imgmtf.parallel import run_tasks\n"
            "parallel.STUCK_S = 0.3     # the test's wait, not the user's\n"
            "rows = run_tasks(dies_sending.send_half_and_die, [0, 1, 2, 3, 4], workers=2,\n"
            "                 on_error=lambda item, exc: 'died' if 'worker process died' in str(exc) else exc)\n"
            "print(json.dumps(list(rows)))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60)
    assert out.returncode == 0 and "Traceback" not in out.stderr, out.stderr
    rows = json.loads(out.stdout)
    assert len(rows) == 5 and rows[0] == "died" and all(r in ("died", i) for i, r in enumerate(rows))

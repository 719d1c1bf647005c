"""Interrupts and streaming outputs: Ctrl-C or SIGTERM stops `imgmtf measure`
at once, its workers end with it, and the CSV keeps every row measured;
rows reach the CSV as files complete, not after the last one."""
import csv
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from imgmtf.io import write_geotiff

from conftest import ctrl_c_as_at_a_terminal, exact_edge_chip, gaussian_pixel_transfer

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


@pytest.fixture(scope="module")
def chips(tmp_path_factory):
    folder = tmp_path_factory.mktemp("chips")
    transfer = gaussian_pixel_transfer(0.5, 6.0)
    chip = exact_edge_chip(transfer, 6.0, (64, 64))
    rng = np.random.default_rng(0)
    for i in range(200):
        noisy = np.clip(chip + rng.normal(0, 2, chip.shape), 0, 65535).astype(np.uint16)
        write_geotiff(folder / f"c{i:03d}.tif", noisy)
    return folder


def start_measure(chips, csv_path, workers=2):
    return subprocess.Popen([sys.executable, "-m", "imgmtf.cli", "measure", str(chips), "--workers",
                             str(workers), "--csv", str(csv_path), "--format", "json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=ctrl_c_as_at_a_terminal)


def csv_rows(path):
    """Rows in the CSV, complete or in progress (its temporary file)."""
    partial = [p for p in os.listdir(path.parent) if p.startswith(f".{path.name}.")]
    source = path if path.exists() else (path.parent / partial[0] if partial else None)
    return list(csv.DictReader(source.open())) if source else []


def wait_for_rows(path, n, process, timeout=30.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end and process.poll() is None:
        if len(csv_rows(path)) >= n:
            return
        time.sleep(0.05)
    raise AssertionError(f"fewer than {n} rows streamed to {path} in {timeout} s")


def descendants(pid):
    """Live processes below ``pid`` (workers, the fork server...), from /proc."""
    parents = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[0] != "Z":
                parents[int(entry)] = int(fields[1])
    found, frontier = [], [pid]
    while frontier:
        below = [p for p, parent in parents.items() if parent in frontier]
        found += below
        frontier = below
    return found


def still_alive(pids, timeout=5.0):
    """Those of ``pids`` alive after waiting up to ``timeout`` s for them all
    to end (a fork server with the estimators loaded takes a moment to exit
    after its parent; more on a loaded machine)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end and any(alive(p) for p in pids):
        time.sleep(0.05)
    return [p for p in pids if alive(p)]


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads /proc")
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_stops_at_once_and_keeps_rows(chips, tmp_path, signum, code):
    out = tmp_path / "out.csv"
    process = start_measure(chips, out)
    wait_for_rows(out, 3, process)
    workers = descendants(process.pid)
    assert len(workers) >= 2
    process.send_signal(signum)
    stdout, stderr = process.communicate(timeout=10)
    assert process.returncode == code
    assert stderr.strip().splitlines()[-1].startswith(f"imgmtf: interrupted ({signal.Signals(signum).name})")
    assert "Traceback" not in stderr
    rows = list(csv.DictReader(out.open()))
    assert 3 <= len(rows) < 200 and all(r["status"] == "ok" for r in rows)
    assert len(stdout.splitlines()) == len(rows)            # the same rows on stdout
    assert not [p for p in os.listdir(tmp_path) if "partial" in p]
    assert not still_alive(workers)


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads /proc")
def test_workers_end_when_their_parent_is_killed(chips, tmp_path):
    out = tmp_path / "out.csv"
    process = start_measure(chips, out)
    wait_for_rows(out, 1, process)
    workers = descendants(process.pid)
    assert len(workers) >= 2
    process.kill()
    process.wait(timeout=5)
    assert not still_alive(workers)

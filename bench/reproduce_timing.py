"""Wall time of `imgmtf reproduce`, quick and full, on this machine.

usage: python bench/reproduce_timing.py [--workers N] [--skip-full]
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time

from imgmtf.reproduce import run_study


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    p.add_argument("--skip-full", action="store_true")
    a = p.parse_args()
    for quick in (True, False) if not a.skip_full else (True,):
        with tempfile.TemporaryDirectory() as out:
            t = time.perf_counter()
            result = run_study(out, quick=quick, workers=a.workers)
            wall = time.perf_counter() - t
        print(f"{'quick' if quick else 'full '} run, {a.workers} workers: {wall:6.1f} s wall; "
              f"thresholds {result['thresholds']}")


if __name__ == "__main__":
    main()

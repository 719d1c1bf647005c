"""``imgmtf reproduce``: rerun the paper's study."""
from __future__ import annotations

import math
import os
from pathlib import Path

import click

from .errors import reported_errors
from .options import MAX_WORKERS


@click.command(short_help="Rerun the paper's study and find each method's SNR threshold.")
@click.option("--out", required=True, type=click.Path(file_okay=False), help="output folder")
@click.option("--quick", is_flag=True,
              help="few chips (8 per SNR level): a check that the study runs, too few for its thresholds")
@click.option("--workers", type=click.IntRange(1, MAX_WORKERS), default=os.cpu_count() or 1,
              show_default="all cores", help="worker processes")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="random seed of the study's chips and noise (an integer >= 0)")
@click.option("--progress/--no-progress", default=None, help="progress bars on stderr (default: on a terminal)")
def reproduce(out, quick, workers, seed, progress):
    """Rerun the paper's study: its Tables 1-2 and Figures 2-3, 9-10 and
    12-14; find the lowest SNR at which each method is trustworthy; write
    OUT/report.md with the figures and CSV data."""
    from ..reproduce import THRESHOLD_SNRS, run_study
    with reported_errors():
        result = run_study(out, quick=quick, workers=workers, seed=seed, progress=progress)
    if quick:       # a threshold from a handful of chips per level would be noise printed as a finding
        click.echo(f"thresholds: n/a (a quick run: {result['chips_per_level']} chips per SNR level are too few "
                   "for one; run without --quick)")
    else:
        for method, snr in result["thresholds"].items():
            found = (f"trustworthy from SNR {snr:g}" if math.isfinite(snr)
                     else f"not trustworthy up to SNR {max(THRESHOLD_SNRS)}")
            click.echo(f"{method:8s} {found}")
    click.echo(f"wrote {Path(out) / 'report.md'} ({result['seconds']:.0f} s)")

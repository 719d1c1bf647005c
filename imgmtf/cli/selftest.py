"""``imgmtf selftest``: render chips of known MTF, measure, compare."""
from __future__ import annotations

import sys

import click

from .errors import reported_errors
from .options import MethodOption


@click.command(short_help="Render chips of known MTF, measure them, compare (exit 1 if off).")
@click.option("--method", cls=MethodOption)
def selftest(method):
    """Render generic-sensor chips with known MTF, measure them, and compare
    measured with true; exit 1 if any estimate is out of tolerance."""
    with reported_errors():
        from ..selftest import CASES, POINT_CASE, POINT_CHIP_PX, run_selftest
        from ..sensor.model import DIRECTIONS, Sensor
        from ..version import __version__
        sensor = Sensor()
        click.echo(f"imgmtf {__version__} self-test: generic sensor (Choi & Helder), GSD {sensor.gsd_m:g} m")
        for d in DIRECTIONS:
            click.echo(f"  model {d:>6}-track: FWHM {sensor.fwhm_m(d):.4f} m, "
                       f"MTF at Nyquist {sensor.mtf_nyquist(d):.4f}")
        own = [(case.name, case.size_px) for case in CASES if case.size_px] + [(POINT_CASE[0], POINT_CHIP_PX)]
        click.echo(f"measuring 100 x 100 px 16-bit chips ({'; '.join(f'{name}: {n} x {n} px' for name, n in own)}) "
                   f"with method {method!r} (! marks a figure out of tolerance):")
        width = max(*(len(case.name) for case in CASES), len(POINT_CASE[0]) + len(" across-track"))
        click.echo(f"{'case':<{width}} {'':>4} {'MTF@Nyq':>8} {'MTF50':>8} {'FWHM':>8}")
        click.echo(f"{'':<{width}} {'':>4} {'':>8} {'cy/px':>8} {'px':>8}")
        rows = run_selftest(sensor, method=method)
        for row in rows:
            click.echo(f"{row.name:<{width}} {'true':>4} {row.true['mtf_nyquist']:8.4f} "
                       f"{row.true['mtf50']:8.4f} {row.true['fwhm']:8.4f}")
            marks = {k: ("" if v else "!") for k, v in row.passed.items()}
            click.echo(f"{'':<{width}} {'got':>4} {row.measured['mtf_nyquist']:8.4f}{marks['mtf_nyquist']:1}"
                       f"{row.measured['mtf50']:8.4f}{marks['mtf50']:1}{row.measured['fwhm']:8.4f}{marks['fwhm']:1}"
                       f"  {'PASS' if row.ok else 'FAIL'}  (SNR {row.snr:.0f})")
        failed = [r.name for r in rows if not r.ok]
        if failed:
            click.echo(f"FAILED: {len(failed)} of {len(rows)} cases out of tolerance (marked !)", err=True)
            sys.exit(1)
        click.echo(f"all {len(rows)} cases within tolerance")

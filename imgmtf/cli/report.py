"""``imgmtf report``: trends and the HTML report of a campaign store."""
from __future__ import annotations

import click

from .errors import reported_errors
from .options import FiniteFloat, RequirementType


@click.command(short_help="Trend a campaign store's results and write its HTML report.")
@click.argument("store", type=click.Path(dir_okay=False))
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False),
              help="folder for trend.csv and report.html (created if missing)")
@click.option("--requirement", type=RequirementType(), metavar="MTF|DIR=MTF,...",
              help="the lowest acceptable MTF at Nyquist, for every direction (0.1) or per direction "
                   "(across=0.12,along=0.10; a plain value covers the directions not named): drawn as a line "
                   "on its figures, and each trend's latest acquisition judged pass, fail or undecided "
                   "(its interval straddles it)")
@click.option("--baseline", type=click.Path(dir_okay=False), metavar="SENSOR.toml",
              help="sensor TOML whose across- and along-track MTF at Nyquist are the pre-launch values")
@click.option("--confidence", type=FiniteFloat(0, 1, min_open=True, max_open=True), default=0.95,
              show_default=True, help="confidence of the drift intervals")
def report(store, out_dir, requirement, baseline, confidence):
    """Fit the drift per year of every sensor, band, direction and
    method of the campaign STORE (a GeoPackage written by scan, measure
    or fit with --campaign), and write OUT/trend.csv, OUT/report.html and
    its figures (OUT/figures): one self-contained page (figures embedded,
    each a link to its full-resolution file; nothing fetched) with, per
    direction, the recommended rows' drift (misfit rows listed, never
    trended), the MTF at Nyquist, MTF50, FWHM and RER against time, the
    requirement and the pre-launch value, and every acquisition.  Two
    sensors are never trended together: a file naming no platform is
    keyed by its camera tags or its image's size, type and GSD."""
    with reported_errors():
        from ..campaign.report import write_report
        written = write_report(store, out_dir, requirement=requirement, baseline=baseline,
                               confidence=confidence)
    for warning in written.warnings:
        click.echo(f"warning: {warning}", err=True)
    drifting = [t for t in written.trends if t.drift and t.figure == "mtf_nyquist" and t.recommended]
    for t in drifting:
        click.echo(f"drift: {_named(t.sensor, t.band_name)}, {t.direction}, {t.scope}, "
                   f"{t.method}: MTF at Nyquist {t.slope_per_year:+.4f}/year "
                   f"[{t.slope_ci_low:+.4f}, {t.slope_ci_high:+.4f}]")
    directions: dict[tuple, list] = {}
    for t in written.trends:
        if t.figure == "mtf_nyquist":
            directions.setdefault((t.sensor, t.band_name, t.direction), []).append(t)
    for (sensor, band, direction), found in directions.items():
        if all(t.misfit for t in found):
            click.echo(f"note: {_named(sensor, band)}, {direction}: only misfit rows, nothing to quote or trend")
    click.echo(f"wrote {written.trend_csv}")
    click.echo(f"wrote {written.report_html}")


def _named(sensor: str, band: str | None) -> str:
    """A sensor and its band as a line names them (no band when none is known)."""
    return f"{sensor}, band {band}" if band else sensor

"""``imgmtf scan``: find, measure and combine every edge or bar in a scene."""
from __future__ import annotations

import sys
from pathlib import Path

import click

from .errors import interrupt_code, option_errors, reported_errors, signal_name
from .options import (
    FiniteFloat,
    MethodName,
    interval_options,
    interval_settings,
    length_option,
    parallel_options,
    parse_pair,
)
from .tables import print_scan


@click.command(short_help="Find, measure and combine every edge or bar in a scene.")
@click.argument("scene", type=click.Path())
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--min-length", type=FiniteFloat(16), default=40.0, show_default=True,
              help="shortest straight line worth measuring, px (a checkerboard's inner line counts whole, "
                   "both halves)")
@click.option("--max-length", type=FiniteFloat(16, 2048), default=300.0, show_default=True,
              help="longer targets are measured over their central part, px")
@click.option("--margin", type=click.IntRange(6, 1000), default=12, show_default=True,
              help="ROI extent either side of the target, px")
@click.option("--pulse-width", callback=length_option("px"),
              help="bar width (0.2 to 10 px; px or m) for every bar; estimated per bar when omitted")
@click.option("--method", type=MethodName(), default="msg", show_default=True)
@click.option("--band", type=click.IntRange(min=1),
              help="1-based band (default: the only band, or the luminance of RGB)")
@click.option("--saturation", callback=parse_pair, metavar="LO,HI",
              help="DN range the sensor records (default: an integer file's type range)")
@click.option("--track-azimuth", "track_azimuth", type=FiniteFloat(-360, 360), metavar="DEG",
              help="the ground track's direction in the image, degrees clockwise from up (default: "
                   "rows along track for a scene in sensor geometry; unknown for a map-projected one)")
@click.option("--out", "out_dir", type=click.Path(file_okay=False),
              help="write targets.csv, targets.geojson and overview.png here")
@click.option("--edge-figures", is_flag=True,
              help="with --out: also one measurement figure per accepted half-edge (locations, profile, LSF, "
                   "MTF), DIR/edges/edge<id>.png")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True)
@click.option("--progress/--no-progress", default=None, help="progress bar on stderr (default: on a terminal)")
@interval_options
@parallel_options
def scan(scene, kind, min_length, max_length, margin, pulse_width, method, band, saturation, track_azimuth,
         out_dir, edge_figures, fmt, progress, interval_method, replicates, confidence, workers, scheduler):
    """Find every straight edge (or bar) in SCENE, split at junctions into
    half-edges (checkerboards, four-quadrant and cross targets), measure
    each on its own ROI, say why the others were rejected, and combine the
    accepted half-edges of each target and of the scene into one result
    per direction.  Exit status 1 when none is usable; on Ctrl-C or SIGTERM
    the candidates measured so far are reported and written (130 or 143)."""
    if pulse_width and kind != "pulse":
        raise click.UsageError("--pulse-width applies to --target pulse only")
    if max_length < min_length:
        raise click.UsageError(f"--max-length ({max_length:g} px) is below --min-length ({min_length:g} px)")
    if edge_figures and not out_dir:
        raise click.UsageError("--edge-figures writes into the --out folder: give --out DIR")
    interrupted = None
    with reported_errors():
        from ..parallel import prestart_workers
        if scheduler is None:
            prestart_workers(workers, ["imgmtf.scene.measure"])     # their imports overlap detection
        from ..atomic import ensure_folder
        from ..io import raster_info
        from ..scene.combine import summarise_scan
        from ..scene.export import write_outputs
        from ..scene.measure import scan_scene
        from ..scene.settings import ScanSettings
        with option_errors():
            settings = ScanSettings(kind, min_length, max_length, margin, method=method, band=band,
                                    pulse_width=pulse_width, saturation=saturation,
                                    track_azimuth_deg=track_azimuth,
                                    intervals=interval_settings(interval_method, replicates, confidence))
        if out_dir:
            ensure_folder(out_dir)
        info = raster_info(scene)
        try:
            records = scan_scene(scene, settings, workers=workers, scheduler=scheduler, progress=progress,
                                 figures_dir=str(Path(out_dir) / "edges") if edge_figures else None)
        except KeyboardInterrupt as exc:
            records, interrupted = getattr(exc, "records", None), exc
            if records is None:
                raise
        summaries = summarise_scan(records)
        written = write_outputs(records, info, out_dir, band, summaries) if out_dir else []
        print_scan(scene, info, kind, records, summaries, written, fmt)
    if interrupted is not None:
        measured = sum(r.reason != "interrupted" for r in records)
        click.echo(f"imgmtf: interrupted ({signal_name(interrupted)}): {measured} of {len(records)} "
                   "candidates screened or measured, the rest marked interrupted"
                   + (f"; written to {out_dir}" if out_dir else ""), err=True)
        sys.exit(interrupt_code(interrupted))
    if not any(r.ok for r in records):
        click.echo(f"imgmtf: error: {scene}: no usable {kind} found "
                   f"({len(records)} candidates, all rejected)", err=True)
        sys.exit(1)

"""``imgmtf measure``: the MTF of the edge or bar in each file."""
from __future__ import annotations

import sys
from contextlib import ExitStack
from dataclasses import asdict

import click

from ..errors import ParameterError
from ..kinds import get_kind, kind_names
from ..preloads import MEASURING_MODULES
from .campaign import CampaignWriter, campaign_options
from .errors import closing, interrupt_code, option_errors, reported_errors, signal_name
from .files import check_figure_file, check_output_file
from .options import (
    FiniteFloat,
    MethodOption,
    interval_options,
    interval_settings,
    length_option,
    optical_centre_option,
    parallel_options,
    parse_band,
    parse_roi,
    read_roi_file,
    reading_options,
    roi_file_option,
    width_refusal,
)
from .tables import TextRows


@click.command(short_help="Measure the MTF of the edge or bar in image files or folders.")
@click.argument("paths", nargs=-1, required=True, type=click.Path())
@click.option("--target", "kind", type=click.Choice(kind_names()), default="edge", show_default=True)
@click.option("--pulse-width", callback=length_option("px"),
              help="bar width, 0.2 to 10 px: 1.4px or 1.4 (pixels), 18.3m (metres, needs a GSD); "
                   "estimated from the profile when omitted")
@click.option("--point-size", callback=length_option("px"),
              help="--target points: each target's side when it is a square of known size, 0 to 20 px: 1 or "
                   "1px (pixels), 30m (metres, needs a GSD); its sinc is divided out of the MTF")
@click.option("--gap", callback=length_option("px"),
              help="--target double-bar: the gap between its two bars, edge to edge: 2 or 2px (pixels), 60m "
                   "(metres, needs a GSD); with --pulse-width, each bar's width")
@click.option("--method", cls=MethodOption)
@click.option("--roi", callback=parse_roi,
              help="X,Y,W,H window in pixels (only it is read; needed for images over 16 Mpx)")
@roi_file_option
@optical_centre_option
@click.option("--band", callback=parse_band,
              help="1-based band, or 'all' for one result per band "
                   "(default: the only band, or the luminance of RGB)")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True)
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False),
              help="also write a CSV summary (each row as its file completes)")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False),
              help="figure for a single input (PNG); several figures (--roi-file's features, --band all's "
                   "bands) take _f<id> and _b<band> before the suffix: FILE_f0.png, FILE_b2.png")
@click.option("--plot-dir", type=click.Path(file_okay=False), help="one figure per input in this folder")
@click.option("--recursive", is_flag=True, help="also look for images in sub-folders of folders given")
@click.option("--force", is_flag=True,
              help="measure even where a quality check fails (fill, saturation, a second target, "
                   "non-uniform sides...): every failed check becomes a warning")
@reading_options
@click.option("--track-azimuth", "track_azimuth", type=FiniteFloat(-360, 360), metavar="DEG",
              help="the ground track's direction in the image, degrees clockwise from up (default: "
                   "rows along track for a file with a pixel size in metres, as L1 products; unknown for "
                   "map-projected files; for an image with no georeference, a photo or an L0 product, its own "
                   "axes: horizontal, vertical; 0 says its rows are along track)")
@click.option("--progress/--no-progress", default=None, help="progress bar on stderr (default: on a terminal)")
@interval_options
@parallel_options
@campaign_options
def measure(paths, kind, pulse_width, point_size, gap, method, roi, roi_file, optical_centre, band, fmt, csv_path,
            plot_path, plot_dir, recursive, force, saturation, track_azimuth, transfer, progress, interval_method,
            replicates, confidence, workers, scheduler, campaign, acquired, platform, instrument, band_name):
    """Measure the MTF of the edge (or bar) in each image file, or in every
    image of a folder; with --target points, the 2-D PSF and MTF of the
    point targets on it, one row across and one along track.  With --format json, one JSON object per line (JSON
    Lines) per file and band; a file that cannot be measured gives an error
    line and the rest go on (exit status 1 if any failed).  Rows are printed
    and written to the CSV as each file completes; on Ctrl-C or SIGTERM the
    rows measured so far are kept (exit status 130 or 143).  With
    --campaign, each file (and band) measured is an acquisition added to
    the store with its chip's row as it completes."""
    if plot_path and plot_dir:
        raise click.UsageError("give --plot or --plot-dir, not both")
    if roi and roi_file:
        raise click.UsageError("give --roi or --roi-file, not both")
    if pulse_width and not get_kind(kind).has_width:
        raise click.UsageError(width_refusal())
    if point_size and get_kind(kind).size_keyword is None:
        raise click.UsageError(f"--point-size applies to --target points only, not to a {kind}")
    if gap and get_kind(kind).gap_keyword is None:
        raise click.UsageError(f"--gap applies to --target double-bar only, not to a {kind}")
    if get_kind(kind).gap_keyword is not None and not (gap and pulse_width):
        raise click.UsageError(f"--target {kind} needs --pulse-width (each bar's width) and --gap (the gap "
                               "between them): neither can be read off two bars' profile")
    facts = {"acquired": acquired, "platform": platform, "instrument": instrument, "band_name": band_name}
    if not campaign and any(v is not None for v in facts.values()):      # as scan refuses them: not ignored
        flag = next(f"--{k.replace('_', '-')}" for k, v in facts.items() if v is not None)
        raise click.UsageError(f"{flag} describes the acquisitions of a campaign store: give --campaign STORE.gpkg")
    with reported_errors():
        from ..parallel import InputOrder, prestart_workers, signals_deferred
        if scheduler is None and not plot_path:
            prestart_workers(workers, MEASURING_MODULES)     # their imports overlap ours
        from ..batch import expand_inputs, measure_files, once_each
        from ..measure_settings import MeasureSettings
        from ..records import CsvWriter, JsonLinesWriter, utc_now
        rois = read_roi_file(roi_file) or roi       # once, before any image: its errors are an input's (exit 1)
        with option_errors():
            settings = MeasureSettings(kind, method, band, rois, pulse_width,
                                       interval_settings(interval_method, replicates, confidence), force=force,
                                       saturation=saturation, track_azimuth_deg=track_azimuth, transfer=transfer,
                                       point_size=point_size, gap=gap, optical_centre=optical_centre)
        files, repeated = once_each(expand_inputs(paths, recursive))
        if not files:
            raise ParameterError(f"no image files in {', '.join(paths)}")
        for name, times in repeated.items():
            click.echo(f"imgmtf: {name} is named {times} times: measured once", err=True)
        if plot_path and len(files) > 1:
            raise click.UsageError(f"--plot takes a single input, got {len(files)} files; "
                                   "use --plot-dir for several")
        if plot_path:
            check_figure_file(plot_path)
        if csv_path:
            check_output_file(csv_path)
        run_utc = utc_now()
        store = CampaignWriter.opened(campaign, acquired=acquired, platform=platform, instrument=instrument,
                                      band_name=band_name, run_utc=run_utc)
        if store:
            from ..records import json_safe
            campaign_settings = {"command": "measure", **json_safe(asdict(settings)),
                                 "roi": settings.params()["roi"]}     # a vector file by its name
        if plot_path:
            from ..batch import measure_file
            completed = iter([(0, measure_file(files[0], settings, plot_path, run_utc=run_utc))])
        else:
            completed = measure_files(files, settings, workers=workers, scheduler=scheduler,
                                      plot_dir=plot_dir, progress=progress, run_utc=run_utc,
                                      ordered=False)
        stdout = (JsonLinesWriter(sys.stdout) if fmt == "json"
                  else TextRows(kind, files, bands=band is not None))
        order, counts, interrupted = InputOrder(), {"ok": 0, "error": 0}, None
        # a measurement is a file's band (or vector feature): a star's or a point array's
        # directions are rows of one, and the closing count is of measurements, not rows
        measured: dict[tuple, bool] = {}
        figures: dict[str, list] = {}       # each file's figures written, in the order they come
        with ExitStack() as outputs:
            writers = [stdout]
            if csv_path:
                writers.append(outputs.enter_context(CsvWriter(csv_path)))
            if fmt == "text":
                stdout.header(confidence)

            def emit(batches):
                for batch in batches:
                    for record in batch:
                        with signals_deferred():    # a row reaches every output or none
                            for writer in writers:
                                writer.write(record)
                            counts["ok" if record.ok else "error"] += 1
                            key = (record.path, record.band, record.site.get("feature_id"))
                            measured[key] = measured.get(key, True) and record.ok
                        plots = figures.setdefault(record.path, [])
                        if record.plot and record.plot not in plots:
                            plots.append(record.plot)
                    if store:       # a file's (and band's) chips are one acquisition: its features together
                        for path, band_read in dict.fromkeys((r.path, r.band) for r in batch if r.ok):
                            with signals_deferred():
                                store.add(path, band_read, campaign_settings,
                                          edges=[r for r in batch if r.ok and (r.path, r.band) == (path, band_read)])
            try:
                with closing(completed):
                    for index, batch in completed:
                        emit(order.push(index, batch))
            except KeyboardInterrupt as exc:
                emit(order.pending())            # measured, though after a file still running
                interrupted = exc
    total = counts["ok"] + counts["error"]
    if plot_path or plot_dir:
        say_figures(figures, json=fmt == "json")
    if store:
        store.summary()
    if interrupted is not None:
        kept = f"; rows kept in {csv_path}" if csv_path else ""
        click.echo(f"imgmtf: interrupted ({signal_name(interrupted)}): {total} result(s) of "
                   f"{len(files)} file(s) reported{kept}", err=True)
        sys.exit(interrupt_code(interrupted))
    if len(measured) > 1 and fmt == "text":
        ok = sum(measured.values())
        click.echo(f"{ok} measured, {len(measured) - ok} failed"
                   + (f"; summary in {csv_path}" if csv_path else ""), err=True)
    sys.exit(1 if counts["error"] else 0)


def say_figures(figures: dict[str, list], json: bool = False) -> None:
    """A ``wrote FILE`` line per figure written (on stderr under ``--format
    json``, whose stdout is JSON), and for a file measured with none (every
    chip refused or unreadable) that no figure was written, and why."""
    for path, written in figures.items():
        for plot in written:
            click.echo(f"wrote {plot}", err=json)
        if not written:
            click.echo(f"imgmtf: no figure written for {path}: nothing was measured (its error above "
                       "says why)", err=True)

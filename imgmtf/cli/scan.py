"""``imgmtf scan``: find, measure, combine and fit every edge or bar in one
scene or many, optionally into a campaign store."""
from __future__ import annotations

import sys
from pathlib import Path

import click

from ..errors import ParameterError
from ..kinds import get_kind, kind_names
from ..preloads import FITTING_MODULES, SCANNING_MODULES, WHOLE_SCAN_MODULES
from .errors import closing, interrupt_code, option_errors, reported_errors, signal_name
from .options import (
    DEFAULT_METHOD,
    FiniteFloat,
    MethodName,
    auto_parallel_options,
    interval_options,
    interval_settings,
    length_option,
    optical_centre_option,
    parse_pair,
    read_roi_file,
    roi_file_option,
    width_refusal,
)
from .tables import print_scan

DEFAULT_STAGES = "auto"   # as imgmtf.scene.targetfit's, without importing it for --help


@click.command(short_help="Find, measure and combine every edge, bar or point array in a scene.")
@click.argument("scenes", nargs=-1, required=True, type=click.Path())
@click.option("--target", "kind", type=click.Choice(kind_names()), default="edge", show_default=True)
@click.option("--min-length", type=FiniteFloat(16), default=40.0, show_default=True,
              help="shortest straight line worth measuring, px (a checkerboard's inner line counts whole, "
                   "both halves)")
@click.option("--max-length", type=FiniteFloat(16, 2048), default=300.0, show_default=True,
              help="longer targets are measured over their central part, px")
@click.option("--margin", type=click.IntRange(6, 1000), default=12, show_default=True,
              help="ROI extent either side of the target, px")
@click.option("--pulse-width", callback=length_option("px"),
              help="bar width (0.2 to 10 px; px or m) for every bar; estimated per bar when omitted")
@click.option("--method", type=MethodName(), default=DEFAULT_METHOD, show_default=True)
@click.option("--band", type=click.IntRange(min=1),
              help="1-based band (default: the only band, or the luminance of RGB)")
@click.option("--saturation", callback=parse_pair, metavar="LO,HI",
              help="DN range the sensor records (default: an integer file's type range)")
@click.option("--track-azimuth", "track_azimuth", type=FiniteFloat(-360, 360), metavar="DEG",
              help="the ground track's direction in the image, degrees clockwise from up (default: "
                   "rows along track for a scene in sensor geometry with a pixel size in metres; unknown for a "
                   "map-projected one; for an image with no georeference, a photo or an L0 product, its own "
                   "axes: horizontal, vertical; 0 says its rows are along track)")
@roi_file_option
@optical_centre_option
@click.option("--lens-frequencies", metavar="F1,F2,...", default="0.125,0.25", show_default=True,
              help="with --optical-centre: the frequencies (cy/px) the lens profile reads the MTF at, beside "
                   "MTF50, against the distance from the centre")
@click.option("--fit-stages", default=DEFAULT_STAGES, show_default=True, metavar="STAGES",
              help="the sensor model's stages fitted to each target's half-edges for its across- and "
                   "along-track MTF (imgmtf fit's names, comma-separated); 'auto' for the simplest of "
                   "optics+detector, +diffusion, +lag, +halo that fits; 'none' for no fit")
@click.option("--point-spacing", "point_spacing", type=FiniteFloat(2, 100000), metavar="PX",
              help="--target points: neighbouring points of one array lie within this distance, px (default: "
                   "grouped by their own spacing, each within 1.5 times its nearest neighbour's distance)")
@click.option("--recursive", is_flag=True, help="also look for images in sub-folders of folders given")
@click.option("--out", "out_dir", type=click.Path(file_okay=False),
              help="write targets.csv, targets.geojson and overview.png here (with several scenes, in a "
                   "sub-folder per scene, named after its file)")
@click.option("--edge-figures", is_flag=True,
              help="with --out: also one measurement figure per accepted half-edge (locations, profile, LSF, "
                   "MTF), DIR/edges/edge<id>.png")
@click.option("--campaign", "store", type=click.Path(dir_okay=False), metavar="STORE.gpkg",
              help="add each scene's acquisition, accepted half-edges and summaries to this campaign store "
                   "(a GeoPackage, created when missing) as the scene completes; a scene scanned again "
                   "with the same settings replaces its rows")
@click.option("--acquired", metavar="TIME",
              help="with --campaign: when the scene was taken (ISO 8601, UTC unless an offset is given), "
                   "where neither its metadata nor its product name says; one scene only")
@click.option("--platform", help="with --campaign: the platform (satellite), where the file does not say")
@click.option("--instrument", help="with --campaign: the instrument, where the file does not say")
@click.option("--band-name", help="with --campaign: the band's name, where the file does not say")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True)
@click.option("--verbose", is_flag=True,
              help="list every rejected candidate, not one line per reason (--format json and --out's CSV "
                   "always hold every row)")
@click.option("--progress/--no-progress", default=None, help="progress bar on stderr (default: on a terminal)")
@interval_options
@auto_parallel_options
def scan(scenes, kind, min_length, max_length, margin, pulse_width, method, band, saturation, track_azimuth,
         roi_file, optical_centre, lens_frequencies, fit_stages, point_spacing, recursive, out_dir, edge_figures, store,
         acquired, platform, instrument, band_name, fmt, verbose, progress, interval_method, replicates, confidence,
         workers, scheduler):
    """Find every straight edge (or bar) in each SCENE (files, or folders of
    images), split at junctions into half-edges (checkerboards,
    four-quadrant and cross targets), measure each on its own ROI, say why
    the others were rejected, combine the accepted half-edges of each
    target and of the scene into one result per measured direction,
    invert those directions for the across- and along-track MTF without a
    model (separable, elliptical, or the bracket of both when the data
    cannot tell), fit the sensor model to each target's half-edges for its
    own, and mark the row to quote per direction (*; never a misfit
    fit).  With --campaign, each scene's results go into a
    campaign store as it completes.  Exit status 1 when a scene cannot be
    scanned or has no usable target; on Ctrl-C or SIGTERM the results so
    far are reported and kept (130 or 143): every scene finished is in the
    store.  With --target points, it finds the arrays of compact targets
    (mirrors, lamps, stars) and measures each by the point stack: the
    across- and along-track MTF directly, without a separability
    assumption."""
    if pulse_width and not get_kind(kind).has_width:
        raise click.UsageError(width_refusal())
    if get_kind(kind).gap_keyword is not None:     # a pair is not yet among the lines a scan pairs up
        raise click.UsageError(f"scan does not search for {kind} targets yet: imgmtf measure --target {kind} "
                               "--pulse-width W --gap G --roi X,Y,W,H measures one")
    scanner = get_kind(kind).scanner
    if get_kind(kind).measuring is None and scanner is None:   # a pipeline of its own and no scan of its own
        raise click.UsageError(f"scan searches scenes for lines (edges and bars), not for {kind} targets yet: "
                               f"imgmtf measure --target {kind} SCENE finds and measures every one in a scene "
                               "(--roi X,Y,W,H for one array)")
    if point_spacing is not None and scanner is None:
        raise click.UsageError("--point-spacing groups point targets into arrays: give --target points")
    if edge_figures and scanner is not None:
        raise click.UsageError(f"--edge-figures draws half-edges; a {kind} scan draws its arrays in --out's "
                               "overview.png (imgmtf measure --target points --roi X,Y,W,H --plot for one array)")
    if max_length < min_length:
        raise click.UsageError(f"--max-length ({max_length:g} px) is below --min-length ({min_length:g} px)")
    if edge_figures and not out_dir:
        raise click.UsageError("--edge-figures writes into the --out folder: give --out DIR")
    facts = {"acquired": acquired, "platform": platform, "instrument": instrument, "band_name": band_name}
    if not store and any(v is not None for v in facts.values()):
        flag = next(f"--{k.replace('_', '-')}" for k, v in facts.items() if v is not None)
        raise click.UsageError(f"{flag} describes the acquisitions of a campaign store: give --campaign STORE.gpkg")
    interrupted, outcomes = None, []
    with reported_errors():
        from ..file_lists import expand_inputs
        if scheduler is None:
            _prestart(scenes, recursive, kind, fit_stages, workers)
        from ..scene.series import outputs_folder, scan_scenes
        from ..scene.settings import ScanSettings
        rois = read_roi_file(roi_file)      # once, before any scene: its errors are an input's (exit 1)
        with option_errors():           # a malformed option: exit 2, before any work
            stages = _stages(fit_stages)
            settings = ScanSettings(kind, min_length, max_length, margin, method=method, band=band,
                                    pulse_width=pulse_width, saturation=saturation,
                                    track_azimuth_deg=track_azimuth, roi=rois, optical_centre=optical_centre,
                                    point_spacing_px=point_spacing,
                                    intervals=interval_settings(interval_method, replicates, confidence))
            frequencies = _frequencies(lens_frequencies) if optical_centre is not None else None
            if acquired is not None:
                from ..campaign.acquisitions import parse_time
                parse_time(acquired, "--acquired")
        paths = expand_inputs(scenes, recursive)
        if not paths:
            raise ParameterError(f"no image files in {', '.join(scenes)}")
        if acquired is not None and len(paths) > 1:
            raise click.UsageError(f"--acquired gives one time, for one scene; {len(paths)} scenes were given: "
                                   "scan them one at a time, or let their metadata or product names say when")
        folders: dict[str, str] = {}
        if out_dir:
            from ..atomic import ensure_folder
            ensure_folder(out_dir)
            taken: set[str] = set()
            folders = {p: out_dir if len(paths) == 1 else outputs_folder(out_dir, p, taken) for p in paths}
        completed = scan_scenes(paths, settings, stages=stages, store=store,
                                facts=facts if store else None, workers=workers, scheduler=scheduler,
                                progress=progress,
                                figures_dirs={p: str(Path(f) / "edges") for p, f in folders.items()}
                                if edge_figures else None,
                                overviews={p: str(Path(f) / "overview.png") for p, f in folders.items()})
        try:
            with closing(completed):
                for outcome in completed:
                    outcomes.append(outcome)
                    # (scan_scenes yields each outcome with Ctrl-C held back until it is reported)
                    _report(outcome, kind, band, folders.get(outcome.path), fmt, verbose)
                    if frequencies and fmt == "text" and not outcome.error:
                        _lens_profile(outcome, frequencies, folders.get(outcome.path))
        except KeyboardInterrupt as exc:
            interrupted = exc
    _closing_notes(outcomes, paths, store, kind, fmt)
    if interrupted is not None:
        cut = next((o for o in outcomes if o.interrupted), None)
        if cut is not None:
            measured = sum(r.reason != "interrupted" for r in cut.records)
            what = (f"{measured} of {len(cut.records)} candidates screened or measured, the rest marked "
                    "interrupted; the scene was not stored" if store else
                    f"{measured} of {len(cut.records)} candidates screened or measured, the rest marked interrupted")
        else:
            what = f"{len(outcomes)} of {len(paths)} scenes scanned"
            what += f", each in {store}" if store else ""
        click.echo(f"imgmtf: interrupted ({signal_name(interrupted)}): {what}"
                   + (f"; written to {out_dir}" if out_dir else ""), err=True)
        sys.exit(interrupt_code(interrupted))
    sys.exit(0 if all(o.ok for o in outcomes) else 1)


def _prestart(scenes, recursive: bool, kind: str, fit_stages: str, workers: int | None) -> None:
    """Start the workers' fork server (parallel.prestart_workers) as the scan starts, before this process
    loads anything numerical, so that its imports overlap this process's own: for the workers asked for,
    or chosen for several scenes; for one scene's fits, workers chosen automatically, one per core: they
    go to workers forked from a server that imports SciPy's special functions (0.2-0.4 s) on another core while
    this process detects and measures (scene.afterscan.fit_workers).  Workers chosen automatically for one
    scene's tiles and candidates wait for them to be counted.  The scenes are listed again where their
    errors are reported, after the options' (the list is not checked here)."""
    from ..errors import ImgmtfError
    from ..file_lists import expand_inputs
    from ..parallel import available_cores, can_preload, prestart_workers
    try:
        paths = expand_inputs(scenes, recursive)
    except ImgmtfError:
        return
    if not paths:
        return
    fitted = fit_stages.strip() != "none" and get_kind(kind).fits_sensor      # as scan_one decides
    if workers is not None:
        count = workers
    elif len(paths) > 1:
        from ..scene.series import scenes_workers
        count = scenes_workers(len(paths))
    else:
        count = available_cores() if fitted and can_preload() else 1
    prestart_workers(count, SCANNING_MODULES + (FITTING_MODULES if fitted else ())
                     + (WHOLE_SCAN_MODULES if len(paths) > 1 else ()))


def _stages(text: str) -> str | None:
    """The stages to fit, checked now (None: no fit)."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if names == ["none"]:
        return None
    if names == ["auto"]:
        return "auto"
    from ..sensor.stages import STAGES
    unknown = [n for n in names if n not in STAGES]
    if unknown or not names:
        raise ParameterError(f"--fit-stages: unknown stage {unknown[0] if unknown else text!r}; known: "
                             f"{', '.join(STAGES)}, or auto, or none")
    return ",".join(names)


def _frequencies(text: str) -> tuple[float, ...]:
    """--lens-frequencies: cy/px, each in (0, 1]."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise ParameterError(f"--lens-frequencies: expected numbers F1,F2,... (cy/px), got {text!r}") from None
    if not values or not all(0.0 < v <= 1.0 for v in values):
        raise ParameterError(f"--lens-frequencies: each frequency must lie in (0, 1] cy/px, got {text!r}")
    return values


def _lens_profile(outcome, frequencies, folder) -> None:
    """The scene's lens profile printed (and with --out, its table and figure written)."""
    from ..scene.lens_profile import lens_profile, write_lens_profile
    from .tables import print_lens_profile
    try:
        profile = lens_profile(outcome.records, frequencies)
    except ParameterError as exc:
        click.echo(f"imgmtf: note: {outcome.path}: no lens profile: {exc}", err=True)
        return
    written = []
    if folder:
        from ..plot import plot_lens_profile
        from .files import save_figure
        written.append(write_lens_profile(profile, str(Path(folder) / "lens_profile.csv")))
        save_figure(plot_lens_profile(profile, title=Path(outcome.path).name), str(Path(folder) / "lens_profile.png"))
        written.append(str(Path(folder) / "lens_profile.png"))
    print_lens_profile(profile)
    for path in written:
        click.echo(f"wrote {path}")


def _report(outcome, kind, band, folder, fmt, verbose) -> None:
    """One scene's tables (or JSON rows), and its outputs written."""
    if outcome.error:
        click.echo(f"imgmtf: error: {outcome.error}", err=True)
        return
    from ..io import raster_info
    from ..scene.export import write_outputs
    info = raster_info(outcome.path)
    written = write_outputs(outcome.records, info, folder, band, outcome.summaries) if folder else []
    if get_kind(kind).scanner is not None:      # arrays, not lines: a table of their own
        from .point_tables import print_point_scan
        print_point_scan(outcome.path, info, outcome.records, outcome.summaries, written, fmt)
    else:
        print_scan(outcome.path, info, kind, outcome.records, outcome.summaries, written, fmt, verbose)
    if not any(r.ok for r in outcome.records) and not outcome.interrupted:
        n = len(outcome.records)
        click.echo(f"imgmtf: error: {outcome.path}: no usable {kind} found "
                   f"({n} candidate{'s, all' if n != 1 else ','} rejected)", err=True)


def _closing_notes(outcomes, paths, store, kind, fmt) -> None:
    """Once for the run: the scenes stored without a time, and a count."""
    untimed = [o.path for o in outcomes if o.acquisition is not None and not o.acquisition.acquired_utc
               and o.ok and not o.interrupted]
    if untimed:
        shown = ", ".join(untimed[:3]) + (f" and {len(untimed) - 3} more" if len(untimed) > 3 else "")
        click.echo(f"imgmtf: note: no acquisition time for {len(untimed)} scene(s) ({shown}): neither an "
                   "ACQUISITION_DATETIME metadata item nor a product name with a date says when it was "
                   f"taken; stored in {store} without one, so a trend leaves it out: give --acquired TIME",
                   err=True)
    written = sum(o.acquisition is not None and o.ok for o in outcomes)
    if len(paths) > 1:
        usable = sum(o.ok for o in outcomes)
        stored = f"; {written} stored in {store}" if store else ""
        target = get_kind(kind).noun + (" array" if get_kind(kind).scanner is not None else "")
        click.echo(f"{len(outcomes)} of {len(paths)} scenes scanned: {usable} with a usable {target}, "
                   f"{len(outcomes) - usable} without or failed{stored}", err=True)
    elif store and outcomes and not outcomes[0].interrupted:      # as measure --campaign says it
        click.echo(f"{written} acquisition(s) written to {store}", err=True)

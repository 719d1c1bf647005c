"""``imgmtf fit``: fit the sensor model's stages to edges, bars or double bars."""
from __future__ import annotations

import json

import click

from ..errors import ParameterError
from ..kinds import KINDS, get_kind
from .campaign import CampaignWriter, campaign_options
from .errors import option_errors, reported_errors
from .files import check_figure_file, check_output_file, save_figure
from .options import FiniteFloat, length_option, parse_rois, read_roi_file, reading_options, roi_file_option
from .tables import print_fit, warning_text

#: the kinds fit takes: those of the 1-D pipeline (points have their own)
FIT_KINDS = tuple(name for name, kind in KINDS.items() if kind.measuring is not None)
#: what fit does with edges only, and why not with bars
EDGE_ONLY = {
    "plot_path": ("--plot", "its figure is the edges' fit's (each edge's measured MTF against the model's); "
                            "imgmtf measure --plot draws a double bar's profile and MTF with the model's"),
    "campaign": ("--campaign", "a campaign's acquisition holds the model's across- and along-track rows "
                               "with each edge's misfit test, which the bars' fit does not make"),
}


@click.command(short_help="Fit the sensor model to edges or bars: its MTF in every direction.")
@click.argument("paths", nargs=-1, required=True, type=click.Path())
@click.option("--target", "kind", type=click.Choice(FIT_KINDS), default="edge", show_default=True,
              help="what each file holds: an edge, a bar (pulse) or a double bar (Storey's two spans)")
@click.option("--pulse-width", callback=length_option("px"),
              help="--target pulse or double-bar: each bar's width, 1.4 or 1.4px (pixels), 18.3m (metres)")
@click.option("--gap", callback=length_option("px"),
              help="--target double-bar: the gap between its two bars, edge to edge, px or m")
@click.option("--stages", metavar="NAMES",
              help="comma-separated stages to fit: optics, detector, motion, electronics, diffraction, "
                   "defocus, olpf, jitter, diffusion, halo, lag; or auto: the simplest of optics+detector, "
                   "+diffusion, +lag, +halo that fits (default: those of --sensor, else the paper's four)")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False),
              help="sensor TOML giving starting (and held) values, e.g. a known detector or wavelength")
@click.option("--hold", metavar="PARAMS",
              help="comma-separated parameters held at their starting values: a stage (detector) or "
                   "stage.parameter (detector.width_x_m)")
@click.option("--gsd", type=FiniteFloat(0, min_open=True),
              help="GSD in metres (default: the files', else 1: parameters in px)")
@click.option("--band", type=click.IntRange(min=1), help="1-based band of multi-band files")
@click.option("--roi", multiple=True, callback=parse_rois, metavar="X,Y,W,H",
              help="X,Y,W,H window in pixels: once for every file, or once per file in their order (a file "
                   "named again with another window gives another edge; default: the whole image)")
@roi_file_option
@click.option("--recursive", is_flag=True, help="also look for images in sub-folders of folders given")
@click.option("--force", is_flag=True,
              help="measure an edge even where a quality check fails (fill, saturation, non-uniform "
                   "sides...): every failed check becomes a warning")
@reading_options
@click.option("--confidence", type=FiniteFloat(0, 1, min_open=True, max_open=True), default=0.95,
              show_default=True, help="confidence of the intervals")
@click.option("--out", "out_path", type=click.Path(dir_okay=False), help="write the fitted sensor as TOML")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True,
              help="json: one object with the parameters, directions and a record per edge")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False),
              help="figure of measured against model MTF per edge, residuals and the fitted PSF (PNG)")
@campaign_options
def fit(paths, kind, pulse_width, gap, stages, sensor_path, hold, gsd, band, roi, roi_file, recursive, force,
        saturation, transfer, confidence, out_path, fmt, plot_path, campaign, acquired, platform, instrument,
        band_name):
    """Fit the sensor's stages to the edges of one or more images (one edge
    each; across- and along-track edges together constrain both axes), and
    read the MTF in every direction off the fitted model.  With
    --campaign, the files are the chips of one acquisition: it is added to
    the store with the model's across- and along-track rows (those some
    edge constrains).  Each file is read and its edge measured as
    imgmtf measure does (--roi, --band, --transfer, --force; nodata and
    fill as measure treats them); a file named twice with the same window
    is measured once.  --out writes the sensor with a [fit] table saying
    whether the model fits (imgmtf restore refuses one that does not).
    With --target pulse or double-bar, the stages (default optics and
    detector) are fitted to the bars' profiles (Storey's method: a pair's
    transfer may hide a frequency the model carries across), each file's
    bar measured as imgmtf measure does; --pulse-width and --gap as for
    measure."""
    if get_kind(kind).has_width:
        if roi_file:
            raise click.UsageError("--roi-file gives the windows of edges: fit bars with --roi X,Y,W,H")
        _fit_bars(paths, kind, pulse_width, gap, stages, sensor_path, hold, gsd, band, roi, force, saturation,
                  transfer, confidence, out_path, fmt, given={"plot_path": plot_path, "campaign": campaign})
        return
    if pulse_width or gap:
        raise click.UsageError("--pulse-width and --gap describe bars: give --target pulse or double-bar")
    from ..estimate.fit import check_names
    from ..file_lists import expand_inputs
    from ..sensor.model import Sensor
    from ..sensor_fit import edge_sources, fit_sensor
    with reported_errors():
        start = Sensor.from_toml(sensor_path) if sensor_path else None
        with option_errors():
            check_names(stages, hold or (), start)
            from ..transfer import parse_transfer
            parse_transfer(transfer)
        files = expand_inputs(paths, recursive)
        if not files:
            raise ParameterError(f"no image files in {', '.join(paths)}")
        if len(roi) > 1 and len(roi) != len(files):            # options that contradict the inputs: exit 2
            raise click.UsageError(f"--roi given {len(roi)} times for {len(files)} file(s): give it once for "
                                   "every file, or once per file")
        rois = roi[0] if len(roi) == 1 else (list(roi) if roi else None)
        features: dict[str, dict] = {}
        if roi_file:            # every file's edge in each feature's window, its attributes in its record
            if roi:
                raise click.UsageError("give --roi or --roi-file, not both")
            from ..sensor_fit import feature_edges
            files, rois, fields = feature_edges(files, read_roi_file(roi_file), band)
            features = dict(zip(edge_sources(files, rois), fields))
        if plot_path:
            check_figure_file(plot_path)
        if out_path:
            check_output_file(out_path)
        store = CampaignWriter.opened(campaign, acquired=acquired, platform=platform, instrument=instrument,
                                      band_name=band_name)
        if store:
            store.check_one_acquisition(files, band)
        result = fit_sensor(files, stages=stages, start=start, hold=hold or (), gsd_m=gsd, band=band,
                            roi=rois, confidence=confidence, force=force, transfer=transfer, saturation=saturation)
        written = []
        if out_path:
            from ..version import __version__
            sources = [e.source for e in result.edges]
            result.to_toml(out_path, comment=f"fitted by imgmtf {__version__} to {len(sources)} edge(s): "
                                             f"{', '.join(sources)}", sources=sources)
            written.append(out_path)
        if plot_path:
            from ..batch import file_truth
            from ..plot import plot_fit
            # the truth of each chip imgmtf simulated (its GeoTIFF says how), drawn beside the model
            per_file = rois if isinstance(rois, list) else [rois] * len(files)
            where = dict(zip(edge_sources(files, rois), zip(files, per_file)))
            truths = [file_truth(where[e.source][0], band, where[e.source][1]) for e in result.edges]
            save_figure(plot_fit(result, truths=truths), plot_path)
            written.append(plot_path)
        if store:
            settings = {"command": "fit", "stages": stages, "sensor": sensor_path, "hold": hold, "gsd_m": gsd,
                        "band": band, "roi": roi_file or rois, "confidence": confidence, "force": force,
                        "transfer": transfer, "saturation": saturation}
            store.add_fit(files, result, settings, band=band, plot=plot_path)
            store.summary()
    if fmt == "json":
        from ..records import json_safe
        # NaN as null, no -0.0: as measure's and scan's JSON
        out = result.to_dict()
        out["edges"] = [{**edge, **features.get(edge["path"], {})} for edge in out["edges"]]
        click.echo(json.dumps(json_safe({**out, "written": written})))
        return
    print_fit(result)
    for path in written:
        click.echo(f"wrote {path}")


def _fit_bars(paths, kind, pulse_width, gap, stages, sensor_path, hold, gsd, band, roi, force, saturation,
              transfer, confidence, out_path, fmt, given):
    """``fit --target pulse|double-bar``: the stages fitted to the bars'
    profiles; --sensor, --hold and --out as for edges."""
    clash = [name for name in EDGE_ONLY if given.get(name)]
    if clash:
        flag, why = EDGE_ONLY[clash[0]]
        raise click.UsageError(f"{flag} is the edges' fit's, not with --target {kind}: {why}")
    if len(roi) > 1:
        raise click.UsageError("--target pulse or double-bar takes one --roi for every file")
    from ..bar_fit import fit_bar_files
    from ..estimate.fit import check_names
    from ..file_lists import expand_inputs
    from ..sensor.model import Sensor
    with reported_errors():
        start = Sensor.from_toml(sensor_path) if sensor_path else None
        with option_errors():
            if stages is not None and stages.strip() == "auto":
                raise ParameterError("--stages auto is the edges' fit's: name the bars' stages (optics,detector)")
            check_names(stages or (None if start else "optics,detector"), hold or (), start)
            from ..measure_settings import MeasureSettings
            MeasureSettings(kind, pulse_width=pulse_width, gap=gap)
        files = expand_inputs(paths, False)
        if not files:
            raise ParameterError(f"no image files in {', '.join(paths)}")
        if out_path:
            check_output_file(out_path)
        result = fit_bar_files(files, target=kind, pulse_width=pulse_width, gap=gap,
                               stages=stages or (None if start else "optics,detector"), band=band,
                               roi=roi[0] if roi else None, gsd_m=gsd, confidence=confidence, force=force,
                               transfer=transfer, saturation=saturation, start=start, hold=hold or ())
        written = []
        if out_path:
            from ..version import __version__
            result.to_toml(out_path, comment=f"fitted by imgmtf {__version__} to {len(result.sources)} "
                                             f"{get_kind(kind).noun}(s): {', '.join(result.sources)}")
            written.append(out_path)
    if fmt == "json":
        from ..records import json_safe
        click.echo(json.dumps(json_safe({**result.to_dict(), "written": written})))
        return
    click.echo(f"stages: {result.stages}   reduced chi-square {result.reduced_chi_square:.2f}")
    for p in result.parameters:
        error = f" +- {p.standard_error:.4g}" if p.status == "fitted" else ""
        note = f": {p.note}" if p.note else ""
        click.echo(f"  {p.stage}.{p.name} = {p.value:.4g}{error} {p.unit}  ({p.status}{note})")
    confidence_pct = f"{100 * result.confidence:g} %"
    for source, angle, m, ci, f50 in zip(result.sources, result.normal_angles_deg, result.mtf_nyquist,
                                         result.mtf_nyquist_ci, result.mtf50_cy_px):
        click.echo(f"{source}: normal {angle:.2f} deg, model MTF at Nyquist {m:.4f} "
                   f"[{ci.low:.4f}, {ci.high:.4f}] ({confidence_pct}), MTF50 {f50:.4f} cy/px")
    for warning in result.warnings:
        click.echo(warning_text("  ", warning, hint=False))
    for path in written:
        click.echo(f"wrote {path}")

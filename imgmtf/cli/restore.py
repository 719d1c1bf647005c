"""``imgmtf restore``: MTF compensation of images with a filter designed
from a fitted sensor, and what it costs in noise."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import click

from ..errors import ParameterError
from .errors import one_line, reported_errors
from .files import check_figure_file, check_output_file, load_sensor, save_figure
from .options import FiniteFloat, parallel_options, parse_pair

RASTER_SUFFIXES = (".tif", ".tiff")
KERNEL_SUFFIXES = (".npy", ".txt")


def _odd_kernel(ctx, param, value):
    if value is not None and value % 2 == 0:
        raise click.BadParameter(f"the kernel is centred on a pixel: its side must be odd, got {value}")
    return value


@click.command(short_help="Restore images to a target MTF (MTF compensation).")
@click.argument("paths", nargs=-1, required=True, type=click.Path())
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False),
              help="the sensor to compensate: a TOML file (imgmtf fit --out)")
@click.option("--measured", "measured_path", type=click.Path(dir_okay=False),
              help="instead of --sensor: the 2-D MTF measured without a model, the across- and along-track "
                   "rows of imgmtf scan --format json saved to this file (the assumption the scan chose)")
@click.option("--target-nyquist", required=True, type=FiniteFloat(0, 1, min_open=True), metavar="V",
              help="restored MTF at Nyquist in both axes, by a smooth (Gaussian) target transfer never above 1")
@click.option("--max-noise-gain", type=FiniteFloat(1), metavar="G",
              help="limit of the filter's white-noise gain (restored / input noise std); wins over the target. "
                   "Without it a design whose gain exceeds 4 (the result more noise than detail) is refused")
@click.option("--allow-misfit", is_flag=True,
              help="restore with a sensor whose fit says its model does not fit its edges ([fit] misfit = true "
                   "in the TOML imgmtf fit --out writes), which is otherwise refused; the report says so")
@click.option("--kernel-size", type=click.IntRange(3, 63), callback=_odd_kernel, metavar="N",
              help="an N x N spatial kernel (odd), as operational MTFC applies; default: the FFT form, taps as "
                   "far as they reach")
@click.option("--noise-std", type=FiniteFloat(0), metavar="DN",
              help="the images' noise std (default: measured on each image's central 1024 px)")
@click.option("--signal-std", type=FiniteFloat(0, min_open=True), metavar="DN",
              help="the scene's std, the signal the noise is weighed against (default: measured likewise)")
@click.option("--gsd", type=FiniteFloat(0, min_open=True),
              help="the images' pixel in metres (default: the file's, else the sensor's)")
@click.option("--out", "out_path", required=True, type=click.Path(),
              help="the restored GeoTIFF (.tif) for one image, or a folder: FOLDER/<name>_restored.tif")
@click.option("--kernel", "kernel_path", type=click.Path(dir_okay=False),
              help="also write the filter's taps: .npy (NumPy) or .txt (text), for one image")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False),
              help="figure of the MTF per axis (sensor, filter, restored, target) and the restored edge "
                   "response, for one image (PNG)")
@click.option("--saturation", callback=parse_pair, metavar="LO,HI",
              help="DN the sensor records (default: an integer file's type range); pixels at or beyond "
                   "are kept as they were")
@click.option("--tile", "tile_px", type=click.IntRange(64, 2048), default=1024, show_default=True,
              help="tile side, px: memory holds a few tiles")
@click.option("--recursive", is_flag=True, help="also look for images in sub-folders of folders given")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True,
              help="json: one object per image (JSON Lines)")
@click.option("--progress/--no-progress", default=None, help="progress bar on stderr (default: on a terminal)")
@parallel_options
def restore(paths, sensor_path, measured_path, target_nyquist, max_noise_gain, allow_misfit, kernel_size, noise_std,
            signal_std, gsd, out_path, kernel_path, plot_path, saturation, tile_px, recursive, fmt, progress, workers,
            scheduler):
    """Design a regularised inverse (Wiener) filter from the sensor's 2-D
    transfer and each image's noise so that the restored MTF follows a target,
    apply it tile by tile (georeference, data type, nodata and tags kept),
    and report the designed and achieved MTF at Nyquist, the RER before and
    after, the noise gain and the ringing.  A sensor whose fit says its
    model does not fit is refused (--allow-misfit overrides), and so is a
    filter whose noise would dominate the result (--max-noise-gain sets
    the noise budget).  An image that cannot be restored gives an error
    line and the rest go on (exit status 1 if any failed).  With
    --measured the filter is designed from the MTF a scan measured without
    a model, the rows to quote where the model misfits."""
    if (sensor_path is None) == (measured_path is None):
        raise click.UsageError("give the system to compensate: --sensor FILE (a fitted sensor) or --measured FILE "
                               "(imgmtf scan --format json's rows), one of them")
    with reported_errors():
        from ..file_lists import expand_inputs
        files = expand_inputs(paths, recursive)
        if not files:
            raise ParameterError(f"no image files in {', '.join(paths)}")
        if (kernel_path or plot_path) and len(files) > 1:       # options that contradict: exit 2
            raise click.UsageError(f"--kernel and --plot take a single image, got {len(files)}")
        if kernel_path:
            if Path(kernel_path).suffix.lower() not in KERNEL_SUFFIXES:     # a malformed option: exit 2
                raise click.BadParameter(f"{kernel_path}: a kernel is written as .npy (NumPy) or .txt (text)",
                                         param_hint="'--kernel'")
            check_output_file(kernel_path)
        if plot_path:
            check_figure_file(plot_path)
        if measured_path is not None:
            from ..restore.measured import measured_sensor, read_scan_rows
            sensor, fit = measured_sensor(read_scan_rows(measured_path), measured_path), None
        else:
            sensor = load_sensor(sensor_path)
            from ..estimate.fit.record import read_fit_record
            from ..restore.restoration import check_model_fits
            fit = read_fit_record(sensor_path)
            check_model_fits(fit, sensor_path, allow_misfit=allow_misfit)       # before any output is made
        outputs = _output_paths(files, out_path)
    from ..records import utc_now
    from ..restore.restoration import restore_image
    from ..version import __version__
    run_utc, failed = utc_now(), 0
    options = dict(target_nyquist=target_nyquist, noise_std_dn=noise_std, signal_std_dn=signal_std,
                   max_noise_gain=max_noise_gain, kernel_size=kernel_size, gsd_m=gsd, tile_px=tile_px,
                   saturation=saturation, workers=workers, scheduler=scheduler, progress=progress, run_utc=run_utc,
                   fit=fit, allow_misfit=allow_misfit)
    with reported_errors():
        for path, out in zip(files, outputs):
            try:
                done = restore_image(path, sensor, out, **options)
            except Exception as exc:
                if len(files) == 1:
                    raise                       # one image: its error is the command's
                failed += 1                     # a batch reports it and goes on
                _print_failure(path, exc, fmt)
                continue
            written = [out]
            if kernel_path:
                done.filter.save(kernel_path)
                written.append(kernel_path)
            if plot_path:
                from ..plot.restore import plot_restoration
                save_figure(plot_restoration(done.filter), plot_path)
                written.append(plot_path)
            if fmt == "json":
                click.echo(json.dumps({**done.to_dict(), "status": "ok", "sensor_file": sensor_path or measured_path,
                                       "written": written, "imgmtf_version": __version__, "run_utc": run_utc}))
            else:
                _print_text(done, written)
    if failed:
        click.echo(f"{len(files) - failed} restored, {failed} failed", err=True)
        sys.exit(1)


def _output_paths(files: list[str], out_path: str) -> list[str]:
    """The GeoTIFF each image is restored to: ``out_path`` itself for one
    image given a .tif name, else FOLDER/<name>_restored.tif (the folder
    created); refused before any work when two would collide or one would
    overwrite its input."""
    from ..atomic import ensure_folder
    if Path(out_path).suffix.lower() in RASTER_SUFFIXES and not Path(out_path).is_dir():
        if len(files) > 1:
            raise click.UsageError(f"{out_path}: {len(files)} images need a folder for --out, not one file")
        outputs = [out_path]
        check_output_file(out_path)
    else:
        folder = ensure_folder(out_path)
        outputs = [str(folder / f"{Path(f).stem}_restored.tif") for f in files]
        for out in outputs:
            check_output_file(out)
    if len(set(outputs)) < len(outputs):
        raise ParameterError("two images have the same name: restore them into different folders")
    for path, out in zip(files, outputs):
        if Path(path).exists() and Path(out).exists() and Path(path).resolve() == Path(out).resolve():
            raise ParameterError(f"{out}: would overwrite its own input; give another --out")
    return outputs


def _print_failure(path: str, exc: BaseException, fmt: str) -> None:
    from ..errors import ImgmtfError
    reason = exc.reason if isinstance(exc, ImgmtfError) else "internal"
    message = one_line(exc)
    if fmt == "json":
        click.echo(json.dumps({"input": path, "status": "error", "reason": reason, "error": message}))
    else:
        from .hints import refusal_hint
        click.echo(f"imgmtf: error: {message}{refusal_hint(reason, message, path)}", err=True)


def _print_text(done, written: list[str]) -> None:
    f, d = done.file, done.filter
    click.echo(f"{f.path}: {f.width} x {f.height} px, {f.dtype}, {len(f.bands)} band(s) in {f.tiles} tile(s) each")
    form = f"FFT form, {d.taps.shape[0]} x {d.taps.shape[0]} taps" if d.kernel_size is None else \
        f"{d.kernel_size} x {d.kernel_size} kernel"
    click.echo(f"filter: {form}; noise {d.noise_std_dn:.3g} DN, signal {d.signal_std_dn:.4g} DN ({done.noise_source}): "
               f"regulariser {d.regulariser:.3g}; noise gain {d.noise_gain:.3f}"
               + (f" (limited to {d.max_noise_gain:g})" if d.limited else ""))
    if done.fit is not None:
        click.echo(f"sensor: {done.fit.summary()}")
    click.echo(f"{'axis':<7} {'MTF@Nyq':>7} {'target':>7} {'restored':>8} {'peak':>5} {'RER':>6} {'RER':>6} "
               f"{'over':>5} {'under':>5} {'ring':>5}")
    click.echo(f"{'':<7} {'sensor':>7} {'':>7} {'':>8} {'':>5} {'before':>6} {'after':>6} "
               f"{'%':>5} {'%':>5} {'%':>5}")
    for name, a in done.report.axes.items():
        click.echo(f"{name:<7} {a.system_mtf_nyquist:7.4f} {a.designed_mtf_nyquist:7.4f} "
                   f"{a.achieved_mtf_nyquist:8.4f} {a.peak_mtf_below_nyquist:5.3f} {a.rer_before:6.3f} "
                   f"{a.rer_after:6.3f} {a.overshoot_pct:5.2f} {a.undershoot_pct:5.2f} {a.ringing_pct:5.2f}")
    click.echo(f"clipped {100 * f.clipped_fraction:.3g} %, saturated (kept) {100 * f.saturated_fraction:.3g} %, "
               f"fill (kept) {100 * f.fill_fraction:.3g} %, nodata {100 * f.nodata_fraction:.3g} % of the pixels")
    for warning in done.warnings:
        click.echo(f"warning: {warning}")
    for path in written:
        click.echo(f"wrote {path}")

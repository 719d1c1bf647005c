"""Command-line interface: a thin shell over the public API.

Exit codes: 0 success; 1 a problem with the input (one line on stderr, or
an error record per file: ``error`` and ``reason`` in JSON and CSV); 2 a
usage error (a bad option); 130 interrupted by Ctrl-C and 143 by SIGTERM
(what was measured is kept: CSV rows are written as each file completes).

Start-up stays cheap: this module imports only click; each command imports
the libraries it needs when it runs, so ``imgmtf --help`` loads no
numerical library.  Set ``IMGMTF_DEBUG=1`` to see the traceback of an
internal error instead of its one-line report.
"""
from __future__ import annotations

import json
import math
import os
import sys
from contextlib import ExitStack, contextmanager
from pathlib import Path

import click

from .errors import FileWriteError, ImgmtfError, ParameterError

# Bounds of the size-like options (see docs): what a run may allocate.
MAX_WORKERS = 64                    # as imgmtf.parallel.MAX_WORKERS, without importing it for --help
DEFAULT_LEVELS_DN = {16: (200.0, 1200.0), 8: (30.0, 210.0)}    # simulate's dark and bright sides
MAX_CHIP_PX = 4096                  # simulate --size: the renderer's 16 Mpx
MAX_OVERSAMPLING = 100              # simulate --oversampling
# what a process measuring files loads, NumPy's lazily loaded parts included:
# imported once by the workers' fork server rather than by each worker's first
# file (batch imports the estimators only where it measures, so that a batch's
# parent, which collects records, stays light)
MEASURING_MODULES = ("imgmtf.batch", "imgmtf.estimate.edge", "imgmtf.estimate.pulse", "numpy.fft", "numpy.ma",
                     "numpy.polynomial")


@contextmanager
def _reported_errors():
    """Turn a deliberate imgmtf error into one line on stderr and exit 1; an
    interrupt into one line and exit 130 (Ctrl-C) or 143 (SIGTERM); any
    other exception into a one-line internal error and exit 1 (its
    traceback with IMGMTF_DEBUG=1)."""
    try:
        yield
    except ImgmtfError as exc:
        click.echo(f"imgmtf: error: {_one_line(exc)}{_force_hint(exc.reason)}", err=True)
        sys.exit(1)
    except KeyboardInterrupt as exc:
        click.echo("imgmtf: interrupted", err=True)
        sys.exit(_interrupt_code(exc))
    except (BrokenPipeError, click.ClickException):
        raise                     # click exits quietly when stdout's reader has gone (| head), or with 2
    except Exception as exc:
        if os.environ.get("IMGMTF_DEBUG"):
            raise
        click.echo(f"imgmtf: internal error: {type(exc).__name__}: {_one_line(exc)} "
                   "(please report it; IMGMTF_DEBUG=1 shows where)", err=True)
        sys.exit(1)


def _force_hint(reason) -> str:
    """What the CLI adds to a quality-gate refusal: the flag that overrules it."""
    from .estimate.gate import FORCIBLE
    return " (--force measures it anyway)" if reason in FORCIBLE else ""


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def _interrupt_code(exc: BaseException) -> int:
    return getattr(exc, "exit_code", 130)


def _load_sensor(path: str | None):
    from .sensor.model import Sensor
    if not path:
        return Sensor()
    try:
        return Sensor.from_toml(path)
    except ImgmtfError:
        raise
    except (UnicodeDecodeError, ValueError, TypeError) as exc:  # what a model check may miss
        from .errors import ConfigError
        raise ConfigError(f"{path}: not a readable sensor TOML file ({type(exc).__name__}: "
                          f"{_one_line(exc)})") from None


def _save_figure(fig, path: str | Path) -> None:
    from .batch import save_figure
    save_figure(lambda: fig, str(path))


def check_output_file(path: str) -> None:
    """Refuse an output path that cannot be written, before any work: its
    folder missing, not a folder or not writable, or the path a folder."""
    target = Path(path)
    folder = target.parent
    if target.is_dir():
        raise FileWriteError(f"{path}: is a folder; give a file name")
    if not folder.is_dir():
        what = "does not exist" if not folder.exists() else "is not a folder"
        raise FileWriteError(f"{path}: cannot write: {folder} {what}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise FileWriteError(f"{path}: cannot write: permission denied in {folder}")


#: the formats matplotlib writes (with Pillow, one of its dependencies)
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".svgz", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff", ".webp")


def check_figure_file(path: str) -> None:
    """As :func:`check_output_file`, and the suffix one of the figure
    formats, so a wrong one is refused before any work, not after it."""
    check_output_file(path)
    suffix = Path(path).suffix.lower()
    if suffix not in FIGURE_SUFFIXES:
        raise ParameterError(f"{path}: a figure is written as {', '.join(s[1:] for s in FIGURE_SUFFIXES)} "
                             f"(by its suffix); got {suffix or 'no suffix'}")


class FiniteFloat(click.FloatRange):
    """A float option that refuses NaN and infinities (FloatRange lets NaN
    through every bound)."""

    name = "number"

    def _describe_range(self) -> str:
        """The bounds for the help ("finite" when there are none, rather
        than click's "x<=None")."""
        return "finite" if self.min is None and self.max is None else super()._describe_range()

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number


class MethodName(click.ParamType):
    """A resampling method name, checked against the method registry when
    the option is used (the registry imports SciPy: ``imgmtf --help`` does
    not pay for it)."""

    name = "method"

    @staticmethod
    def names() -> list[str]:
        from .estimate.resampling import METHODS
        return list(METHODS)

    def get_metavar(self, param, ctx=None) -> str:
        return "[" + "|".join(self.names()) + "]"

    def convert(self, value, param, ctx):
        if value in self.names():
            return value
        self.fail(f"{value!r} is not one of {', '.join(map(repr, self.names()))}", param, ctx)

    def shell_complete(self, ctx, param, incomplete):
        from click.shell_completion import CompletionItem
        return [CompletionItem(n) for n in self.names() if n.startswith(incomplete)]


class MethodOption(click.Option):
    """``--method``: its help lists what each registered method does, read
    from the registry when the help is shown (not at start-up)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("type", MethodName())
        kwargs.setdefault("default", "msg")
        kwargs.setdefault("show_default", True)
        super().__init__(*args, **kwargs)

    def get_help_record(self, ctx):
        from .estimate.resampling import METHODS
        self.help = ("how the profile's samples are smoothed and resampled before the MTF (each "
                     "method's own blur is divided out): "
                     + "; ".join(f"{m.name}: {m.description}" for m in METHODS.values()))
        return super().get_help_record(ctx)


def _length_option(default_unit: str):
    """Click callback: "1.4", "1.4px" or "18.3m" -> (value, unit), the value
    finite and > 0."""
    def parse(ctx, param, value):
        if value is None:
            return None
        text = value.strip().lower()
        unit = next((u for u in ("px", "m") if text.endswith(u)), None)
        number = text[: -len(unit)] if unit else text
        try:
            length = float(number)
        except ValueError:
            raise click.BadParameter(f"expected a number with an optional px or m suffix, got {value!r}") from None
        if not math.isfinite(length):
            raise click.BadParameter(f"expected a finite width, got {value!r}")
        return length, unit or default_unit
    return parse


def _parse_pair(ctx, param, value):
    """Click callback: "LO,HI" -> (lo, hi), two finite numbers, lo < hi."""
    if value is None:
        return None
    try:
        low, high = (float(v) for v in value.split(","))
    except ValueError:
        raise click.BadParameter(f"expected LO,HI (two numbers), got {value!r}") from None
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise click.BadParameter(f"expected finite LO < HI, got {value!r}")
    return low, high


def _parse_roi(ctx, param, value):
    if value is None:
        return None
    try:
        parts = tuple(int(p) for p in value.split(","))
    except ValueError:
        parts = ()
    if len(parts) != 4:
        raise click.BadParameter(f"expected X,Y,W,H (four integers), got {value!r}")
    from .inputs import MIN_SIZE_PX
    if parts[2] < MIN_SIZE_PX or parts[3] < MIN_SIZE_PX or parts[0] < 0 or parts[1] < 0:
        raise click.BadParameter(f"expected X, Y >= 0 and W, H >= {MIN_SIZE_PX} px (the smallest chip "
                                 f"measured), got {value!r}")
    return parts


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="imgmtf", prog_name="imgmtf")   # read only when asked
@click.pass_context
def main(ctx):
    """Measure the MTF of imaging sensors from edge and pulse targets, and
    render exact synthetic chips with the generic pushbroom sensor."""
    from .parallel import terminate_raises
    ctx.with_resource(terminate_raises())


# -- simulate -----------------------------------------------------------------
@main.command(short_help="Render an edge or bar chip through the sensor (GeoTIFF, PNG).")
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--angle", type=FiniteFloat(-90, 90, min_open=True), default=6.0, show_default=True,
              help="angle of the edge's normal from the x (column) axis, degrees in (-90, 90], which "
                   "is the edge's tilt from vertical: near 0 across track, near 90 along track "
                   "(measure reports it as normal_angle_deg)")
@click.option("--low", type=FiniteFloat(), show_default="200 at 16 bits, 30 at 8",
              help="DN on the dark side (outside a pulse)")
@click.option("--high", type=FiniteFloat(), show_default="1200 at 16 bits, 210 at 8",
              help="DN on the bright side (inside a pulse)")
@click.option("--pulse-width", callback=_length_option("px"),
              help="bar width of a pulse target: 1.5 or 1.5px (pixels), 1.5m (metres on the ground)")
@click.option("--offset", type=FiniteFloat(), default=0.0, show_default=True,
              help="sub-pixel position of the edge along its normal from the chip centre, px")
@click.option("--size", type=click.IntRange(2, MAX_CHIP_PX), default=50, show_default=True,
              help="chip side, pixels")
@click.option("--gsd", type=FiniteFloat(0, min_open=True), help="output GSD in metres (default: the sensor's)")
@click.option("--bits", type=click.Choice(["8", "16"]), default="16", show_default=True)
@click.option("--noise-std", type=FiniteFloat(0), default=0.0, show_default=True, help="system noise std, DN")
@click.option("--ground-noise", is_flag=True, help="add the paper's 20-layer ground noise (2000 DN^2)")
@click.option("--oversampling", type=click.IntRange(1, MAX_OVERSAMPLING), default=20, show_default=True,
              help="sub-pixels per pixel")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False), help="sensor TOML file")
@click.option("--seed", type=click.IntRange(min=0), help="random seed for the noise (an integer >= 0)")
@click.option("--out", required=True, type=click.Path(dir_okay=False),
              help="output file: .tif (a GeoTIFF that records the GSD and how the chip was made) "
                   "or .png (pixels only)")
def simulate(kind, angle, low, high, pulse_width, offset, size, gsd, bits, noise_std,
             ground_noise, oversampling, sensor_path, seed, out):
    """Render an edge or pulse chip through the generic sensor to a GeoTIFF
    (or a PNG)."""
    with _reported_errors():
        default_low, default_high = DEFAULT_LEVELS_DN[int(bits)]     # a step that fits the bit depth
        low = default_low if low is None else low
        high = default_high if high is None else high
        from .io import write_geotiff, write_png
        from .sensor.noise import GroundNoise
        from .sensor.rendering import render
        from .sensor.targets import Target
        suffix = Path(out).suffix.lower()
        if suffix not in (".tif", ".tiff", ".png"):
            raise ParameterError(f"{out}: simulate writes a GeoTIFF (.tif, .tiff), which records the GSD "
                                 "and how the chip was made, or a PNG (.png, pixels only); "
                                 f"got {suffix or 'no suffix'}")
        check_output_file(out)
        sensor = _load_sensor(sensor_path)
        gsd_m = sensor.gsd_m if gsd is None else gsd
        if kind == "pulse" and pulse_width is None:
            raise ParameterError("a pulse target needs --pulse-width (1.5 or 1.5px: pixels; 1.5m: metres)")
        if kind == "edge" and pulse_width is not None:
            raise ParameterError("--pulse-width applies to --target pulse only")
        width_px = 0.0
        if kind == "pulse":
            value, unit = pulse_width
            width_px = value if unit == "px" else value / gsd_m
            from .inputs import MIN_BAR_WIDTH_PX
            if not width_px >= MIN_BAR_WIDTH_PX:
                raise ParameterError(f"a {width_px:g} px wide pulse is narrower than the {MIN_BAR_WIDTH_PX} px "
                                     "imgmtf can measure (is the unit right?)")
            if width_px > size:
                raise ParameterError(f"the pulse width must be at most the chip ({size} px), "
                                     f"got {width_px:g} px")
        target = Target(kind, angle, low, high, offset, width_px)
        chip = render(sensor, target, size, gsd_m=gsd_m, oversampling=oversampling, bits=int(bits),
                      noise_std_dn=noise_std, ground_noise=GroundNoise() if ground_noise else None,
                      seed=seed)
        if suffix == ".png":
            write_png(out, chip.image)
        else:
            write_geotiff(out, chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
        clipped = f", {100 * chip.clipped_fraction:.1f} % of pixels clipped" if chip.clipped_fraction else ""
        width = f" {width_px:g} px wide" if kind == "pulse" else ""
        click.echo(f"wrote {out}: {size} x {size} px, {bits}-bit, {kind}{width} at {angle:g} deg, "
                   f"GSD {chip.gsd_m:g} m; true MTF at Nyquist along the normal "
                   f"{float(chip.true_mtf(0.5)):.4f}{clipped}")
        if suffix == ".png":
            click.echo(f"note: a PNG keeps the pixels only; the GSD and how the chip was made (which "
                       f"`measure` uses to draw the true MTF) are kept in a GeoTIFF: --out "
                       f"{Path(out).with_suffix('.tif')}")


# -- sensor -------------------------------------------------------------------
@main.command("sensor", short_help="Print (and plot) the sensor model's stages, FWHM and MTF.")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False), help="sensor TOML file")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False),
              help="save the PSF, LSFs and each stage's MTF beside the system's (PNG)")
@click.option("--save", "save_path", type=click.Path(dir_okay=False), help="write the sensor as TOML")
def sensor_command(sensor_path, plot_path, save_path):
    """Print the sensor's stages, and each stage's and the system's FWHM and
    MTF at Nyquist across and along track."""
    with _reported_errors():
        from .sensor.model import DIRECTIONS, Sensor
        if plot_path:
            check_figure_file(plot_path)
        if save_path:
            check_output_file(save_path)
        sensor = _load_sensor(sensor_path)
        click.echo(f"sensor, GSD {sensor.gsd_m:g} m "
                   f"({'the paper' + chr(39) + 's generic sensor' if sensor == Sensor() else sensor_path})")
        for stage in sensor.stages:
            units = stage.units()
            values = ", ".join(f"{k} {v:.6g}{(' ' + units[k]) if units[k] else ''}"
                               for k, v in stage.to_dict(include_name=False).items())
            click.echo(f"  {stage.name:<12} {stage.title}: {values}")
        click.echo(f"{'stage':<12} {'FWHM across (m)':>16} {'FWHM along (m)':>15} "
                   f"{'MTF@Nyq across':>15} {'MTF@Nyq along':>14}")
        parts = {**sensor.components(), "system": sensor}
        for name, part in parts.items():
            has_width = part is sensor or part.stages[0].has_width
            fw = [part.fwhm_m(d) if has_width and part.mtf_nyquist(d) < 1 - 1e-12 else None
                  for d in DIRECTIONS]
            cells = [f"{v:16.4f}" if v is not None else f"{'-':>16}" for v in fw]
            click.echo(f"{name:<12} {cells[0]} {cells[1][1:]} "
                       f"{part.mtf_nyquist('across'):15.4f} {part.mtf_nyquist('along'):14.4f}")
        if save_path:
            sensor.to_toml(save_path)
            click.echo(f"wrote {save_path}")
        if plot_path:
            from .plot import plot_sensor
            _save_figure(plot_sensor(sensor), plot_path)
            click.echo(f"wrote {plot_path}")


# -- fit ----------------------------------------------------------------------
@main.command(short_help="Fit the sensor model to edges: its MTF in every direction.")
@click.argument("paths", nargs=-1, required=True, type=click.Path())
@click.option("--stages", metavar="NAMES",
              help="comma-separated stages to fit: optics, detector, motion, electronics, diffraction, "
                   "defocus, olpf, jitter (default: those of --sensor, else the paper's four)")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False),
              help="sensor TOML giving starting (and held) values, e.g. a known detector or wavelength")
@click.option("--hold", metavar="PARAMS",
              help="comma-separated parameters held at their starting values: a stage (detector) or "
                   "stage.parameter (detector.width_x_m)")
@click.option("--gsd", type=FiniteFloat(0, min_open=True),
              help="GSD in metres (default: the files', else 1: parameters in px)")
@click.option("--band", type=click.IntRange(min=1), help="1-based band of multi-band files")
@click.option("--roi", callback=_parse_roi,
              help="X,Y,W,H window in pixels read from every file (default: the whole image)")
@click.option("--recursive", is_flag=True, help="also look for images in sub-folders of folders given")
@click.option("--confidence", type=click.FloatRange(0, 1, min_open=True, max_open=True), default=0.95,
              show_default=True, help="confidence of the intervals")
@click.option("--out", "out_path", type=click.Path(dir_okay=False), help="write the fitted sensor as TOML")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True,
              help="json: one object with the parameters, directions and a record per edge")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False),
              help="figure of measured against model MTF per edge, residuals and the fitted PSF (PNG)")
def fit(paths, stages, sensor_path, hold, gsd, band, roi, recursive, confidence, out_path, fmt, plot_path):
    """Fit the sensor's stages to the edges of one or more images (one edge
    each; across- and along-track edges together constrain both axes), and
    read the MTF in every direction off the fitted model."""
    from .batch import expand_inputs
    from .estimate.fit import fit_sensor
    from .sensor.model import Sensor
    with _reported_errors():
        files = expand_inputs(paths, recursive)
        if not files:
            raise ParameterError(f"no image files in {', '.join(paths)}")
        if plot_path:
            check_figure_file(plot_path)
        if out_path:
            check_output_file(out_path)
        start = Sensor.from_toml(sensor_path) if sensor_path else None
        result = fit_sensor(files, stages=stages, start=start, hold=hold or (), gsd_m=gsd, band=band,
                            roi=roi, confidence=confidence)
        written = []
        if out_path:
            from .version import __version__
            result.sensor.to_toml(out_path, comment=f"fitted by imgmtf {__version__} to {len(files)} edge(s): "
                                                     f"{', '.join(e.source for e in result.edges)}")
            written.append(out_path)
        if plot_path:
            from .plot import plot_fit
            _save_figure(plot_fit(result), plot_path)
            written.append(plot_path)
    if fmt == "json":
        click.echo(json.dumps({**result.to_dict(), "written": written}))
        return
    _fit_report(result)
    for path in written:
        click.echo(f"wrote {path}")


def _fit_report(result) -> None:
    edges = result.edges
    click.echo(f"fit of {', '.join(s.name for s in result.sensor.stages)} to {len(edges)} edge(s), "
               f"GSD {result.sensor.gsd_m:g} m; reduced chi-square {result.reduced_chi_square:.3g}")
    click.echo(f"{'parameter':<28} {'value':>11} {'std err':>10} {'unit':<5} status")
    for p in result.parameters:
        se = f"{p.standard_error:10.4g}" if p.status == "fitted" else f"{'-':>10}"
        click.echo(f"{p.key:<28} {p.value:11.5g} {se} {p.unit:<5} {p.status}{': ' + p.note if p.note else ''}")
    for a, b, r in result.correlations:
        click.echo(f"correlated: {a} and {b} (r = {r:+.3f}): the data constrain a combination of them "
                   "better than each")
    pct = f"{100 * result.confidence:g}%"
    click.echo(f"{'edge':<32} {'normal':>6} {'dir':>7} {'axis':>6} {'MTF@Nyq':>7} {pct + ' interval':>17} "
               f"{'measured':>8} {'chi2':>6} {'misfit':>7}")
    for e in edges:
        lo, hi = e.mtf_nyquist_ci
        click.echo(f"{e.source:<32} {e.normal_angle_deg:6.2f} {_DIRECTIONS.get(e.direction, e.direction):>7} "
                   f"{e.constrains:>6} {e.mtf_nyquist:7.4f} "
                   f"{f'[{lo:.4f},{hi:.4f}]':>17} {e.measured_mtf_nyquist:8.4f} {e.reduced_chi_square:6.3g} "
                   f"{100 * e.misfit_fraction:6.2f}%")
    click.echo(f"{'direction':<10} {'MTF@Nyq':>7} {pct + ' interval':>17} {'MTF50 cy/px':>11}")
    for name, d in result.directions.items():
        lo, hi = d["mtf_nyquist_ci"]
        click.echo(f"{name:<10} {d['mtf_nyquist']:7.4f} {f'[{lo:.4f},{hi:.4f}]':>17} "
                   f"{_num(d['mtf50_cy_px'], 11, 4)}{'' if d['constrained'] else '  (no edge: extrapolated)'}")
    for warning in result.warnings:
        click.echo(f"warning: {warning}")


# -- measure ------------------------------------------------------------------
def _parse_band(ctx, param, value):
    if value is None or value.lower() == "all":
        return value and "all"
    try:
        band = int(value)
    except ValueError:
        raise click.BadParameter(f"expected a 1-based band number or 'all', got {value!r}") from None
    if band < 1:
        raise click.BadParameter(f"bands are numbered from 1, got {value!r}")
    return band


def _parallel_options(command):
    """--workers and --scheduler, shared by the batch commands."""
    command = click.option("--scheduler", metavar="ADDRESS",
                           help="run on a Dask distributed cluster (tcp://host:8786), or 'local' "
                                "for a local Dask cluster of --workers processes; needs imgmtf[dask]")(command)
    return click.option("--workers", type=click.IntRange(1, MAX_WORKERS), default=1, show_default=True,
                        help="parallel worker processes, each on one thread")(command)


def _interval_options(command):
    """--intervals, --bootstrap and --confidence, shared by measure and scan."""
    command = click.option("--confidence", type=FiniteFloat(0, 1, min_open=True, max_open=True),
                           default=0.95, show_default=True, help="confidence of the intervals")(command)
    command = click.option("--bootstrap", "replicates", type=click.IntRange(min=0), metavar="N",
                           help="intervals from a bootstrap of N row resamplings (20 to 5000; slower); "
                                "0: no intervals")(command)
    return click.option("--intervals", "interval_method", type=click.Choice(["influence", "bootstrap", "none"]),
                        show_default="influence",
                        help="confidence intervals: linearised row influence (about the cost of one fit), "
                             "a bootstrap over rows, or none")(command)


def _intervals(method: str | None, replicates: int | None, confidence: float):
    """The interval settings the options ask for: --bootstrap N means a
    bootstrap of N replicates (0: none); an --intervals that says otherwise
    is a usage error, not silently overruled."""
    from .estimate.intervals import Intervals
    if replicates is not None:
        implied = "bootstrap" if replicates else "none"
        if method not in (None, implied):
            raise click.UsageError(f"--bootstrap {replicates} asks for {implied} intervals, "
                                   f"--intervals {method} for others: give one")
        method = implied
    return Intervals(method or "influence", confidence, **({"replicates": replicates} if replicates else {}))


@main.command(short_help="Measure the MTF of the edge or bar in image files or folders.")
@click.argument("paths", nargs=-1, required=True, type=click.Path())
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--pulse-width", callback=_length_option("px"),
              help="bar width: 1.4px or 1.4 (pixels), 18.3m (metres, needs a GSD); "
                   "estimated from the profile when omitted")
@click.option("--method", cls=MethodOption)
@click.option("--roi", callback=_parse_roi,
              help="X,Y,W,H window in pixels (only it is read; needed for images over 16 Mpx)")
@click.option("--band", callback=_parse_band,
              help="1-based band, or 'all' for one result per band "
                   "(default: the only band, or the luminance of RGB)")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True)
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False),
              help="also write a CSV summary (each row as its file completes)")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), help="figure for a single input (PNG)")
@click.option("--plot-dir", type=click.Path(file_okay=False), help="one figure per input in this folder")
@click.option("--recursive", is_flag=True, help="also look for images in sub-folders of folders given")
@click.option("--force", is_flag=True,
              help="measure even where a quality check fails (fill, saturation, a second target, "
                   "non-uniform sides...): every failed check becomes a warning")
@click.option("--saturation", callback=_parse_pair, metavar="LO,HI",
              help="DN range the sensor records (default: an integer file's type range); "
                   "sides at or beyond it are saturated")
@click.option("--track-azimuth", "track_azimuth", type=FiniteFloat(-360, 360), metavar="DEG",
              help="the ground track's direction in the image, degrees clockwise from up (default: "
                   "rows along track, as in L0/L1 products; unknown for map-projected files)")
@click.option("--progress/--no-progress", default=None, help="progress bar on stderr (default: on a terminal)")
@_interval_options
@_parallel_options
def measure(paths, kind, pulse_width, method, roi, band, fmt, csv_path, plot_path, plot_dir, recursive,
            force, saturation, track_azimuth, progress, interval_method, replicates, confidence, workers,
            scheduler):
    """Measure the MTF of the edge (or bar) in each image file, or in every
    image of a folder.  With --format json, one JSON object per line (JSON
    Lines) per file and band; a file that cannot be measured gives an error
    line and the rest go on (exit status 1 if any failed).  Rows are printed
    and written to the CSV as each file completes; on Ctrl-C or SIGTERM the
    rows measured so far are kept (exit status 130 or 143)."""
    if plot_path and plot_dir:
        raise click.UsageError("give --plot or --plot-dir, not both")
    if pulse_width and kind != "pulse":
        raise click.UsageError("--pulse-width applies to --target pulse only")
    with _reported_errors():
        from .parallel import InputOrder, prestart_workers, signals_deferred
        if scheduler is None and not plot_path:
            prestart_workers(workers, MEASURING_MODULES)     # their imports overlap ours
        from .batch import MeasureSettings, expand_inputs, measure_files
        from .records import CsvWriter, JsonLinesWriter, utc_now
        settings = MeasureSettings(kind, method, band, roi, pulse_width,
                                   _intervals(interval_method, replicates, confidence), force=force,
                                   saturation=saturation, track_azimuth_deg=track_azimuth)
        files = expand_inputs(paths, recursive)
        if not files:
            raise ParameterError(f"no image files in {', '.join(paths)}")
        if plot_path and len(files) > 1:
            raise ParameterError("--plot takes a single input; use --plot-dir for several")
        if plot_path:
            check_figure_file(plot_path)
        if csv_path:
            check_output_file(csv_path)
        run_utc = utc_now()
        if plot_path:
            from .batch import measure_file
            completed = iter([(0, measure_file(files[0], settings, plot_path, run_utc=run_utc))])
        else:
            completed = measure_files(files, settings, workers=workers, scheduler=scheduler,
                                      plot_dir=plot_dir, progress=progress, run_utc=run_utc,
                                      ordered=False)
        stdout = (JsonLinesWriter(sys.stdout) if fmt == "json"
                  else _TextRows(kind, path_width=max(map(len, files)), bands=band is not None))
        order, counts, interrupted = InputOrder(), {"ok": 0, "error": 0}, None
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
            try:
                with _closing(completed):
                    for index, batch in completed:
                        emit(order.push(index, batch))
            except KeyboardInterrupt as exc:
                emit(order.pending())            # measured, though after a file still running
                interrupted = exc
    total = counts["ok"] + counts["error"]
    if interrupted is not None:
        kept = f"; rows kept in {csv_path}" if csv_path else ""
        click.echo(f"imgmtf: interrupted ({_signal_name(interrupted)}): {total} result(s) of "
                   f"{len(files)} file(s) reported{kept}", err=True)
        sys.exit(_interrupt_code(interrupted))
    if total > 1 and fmt == "text":
        click.echo(f"{counts['ok']} measured, {counts['error']} failed"
                   + (f"; summary in {csv_path}" if csv_path else ""), err=True)
    sys.exit(1 if counts["error"] else 0)


@contextmanager
def _closing(generator):
    """Close a task generator when its loop ends, however: an interrupt
    then stops the workers at once rather than when they are collected."""
    try:
        yield generator
    finally:
        close = getattr(generator, "close", None)
        if close:
            close()


def _signal_name(exc: BaseException) -> str:
    return str(exc) if getattr(exc, "signum", None) else "SIGINT"


class _TextRows:
    """The text table of ``measure``, one row per record as it comes: the
    path column as wide as the longest input, the band column when bands
    were asked for."""

    def __init__(self, kind: str, path_width: int = 32, bands: bool = False):
        self.kind, self.bands = kind, bands
        self.path_width = max(path_width, 4)

    def header(self, confidence: float) -> None:
        last = "RER" if self.kind == "edge" else "W"
        first = f"{'path':<{self.path_width}}" + (f" {'band':>4}" if self.bands else "")
        blank = " " * len(first)
        click.echo(f"{first} {'normal':>7} {'tilt':>5} {'dir':>7} {'SNR':>5} {'MTF@Nyq':>7} "
                   f"{f'{100 * confidence:g}% interval':>17} {'MTF50':>7} {'FWHM':>6} {last:>6}")
        click.echo(f"{blank} {'deg':>7} {'deg':>5} {'':>7} {'':>5} {'':>7} {'':>17} "
                   f"{'cy/px':>7} {'px':>6} {'' if self.kind == 'edge' else 'px':>6}")

    def write(self, record) -> None:
        click.echo(_text_row(record.to_dict(), self.kind, self.path_width, self.bands))


def _text_row(record: dict, kind: str, path_width: int = 32, bands: bool = False) -> str:
    """One record as rows of the text table: figures in px units, a
    ground line in metres when the GSD is known, then its warnings."""
    first = f"{record['path']:<{path_width}}"
    if bands:
        band = record["band"]
        first += f" {'lum' if band == 'luminance' else '' if band is None else band:>4}"
    indent = " " * len(first)
    if record["status"] == "error":
        return f"{first} error: {record['error']}{_force_hint(record.get('reason'))}"
    last = record.get("rer") if kind == "edge" else record.get("pulse_width_px")
    lo, hi = record.get("mtf_nyquist_ci") or (None, None)
    interval = f"[{lo:.4f},{hi:.4f}]" if lo is not None and hi is not None else "-"
    direction = record.get("direction") or "-"
    direction = _DIRECTIONS.get(direction, direction)
    cells = [f"{first} {_num(record.get('normal_angle_deg'), 7, 2)} "
             f"{_num(record.get('tilt_deg'), 5, 1)} {direction:>7} "
             f"{_snr(record.get('snr'))} {_num(record.get('mtf_nyquist'), 7, 4)} {interval:>17} "
             f"{_num(record.get('mtf50_cy_px'), 7, 4)} {_num(record.get('fwhm_px'), 6, 3)} {_num(last, 6, 3)}"]
    if record.get("gsd_m"):
        cells.append(f"{indent} on the ground (GSD {record['gsd_m']:g} m): MTF50 "
                     f"{_ground(record.get('mtf50_cy_m'))} cy/m, FWHM {_ground(record.get('fwhm_m'))} m")
    cells += [f"{indent} warning: {w}" for w in record.get("warnings") or []]
    return "\n".join(cells)


def _ground(value) -> str:
    """A figure in metres to 4 significant digits; '-' where it is not
    defined (a bar's MTF50 behind its sinc's zero)."""
    return "-" if value is None else f"{value:.4g}"


def _snr(value) -> str:
    """The SNR in the table's 5 characters: to the unit up to 99999, then
    in thousands (a noise-free chip's can reach millions)."""
    if value is None:
        return f"{'-':>5}"
    return f"{value:5.0f}" if value < 99999.5 else f"{value / 1000:4.0f}k"


def _num(value, width: int, decimals: int) -> str:
    return f"{value:{width}.{decimals}f}" if value is not None else f"{'-':>{width}}"


# -- scan ---------------------------------------------------------------------
@main.command(short_help="Find, measure and combine every edge or bar in a scene.")
@click.argument("scene", type=click.Path())
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--min-length", type=FiniteFloat(16), default=40.0, show_default=True,
              help="shortest straight line worth measuring, px (a checkerboard's inner line counts whole, "
                   "both halves)")
@click.option("--max-length", type=FiniteFloat(16, 2048), default=300.0, show_default=True,
              help="longer targets are measured over their central part, px")
@click.option("--margin", type=click.IntRange(6, 1000), default=12, show_default=True,
              help="ROI extent either side of the target, px")
@click.option("--pulse-width", callback=_length_option("px"),
              help="bar width (px or m) for every bar; estimated per bar when omitted")
@click.option("--method", type=MethodName(), default="msg", show_default=True)
@click.option("--band", type=click.IntRange(min=1),
              help="1-based band (default: the only band, or the luminance of RGB)")
@click.option("--saturation", callback=_parse_pair, metavar="LO,HI",
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
@_interval_options
@_parallel_options
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
    with _reported_errors():
        from .parallel import prestart_workers
        if scheduler is None:
            prestart_workers(workers, ["imgmtf.scene.measure"])     # their imports overlap detection
        from .atomic import ensure_folder
        from .io import raster_info
        from .scene.combine import summarise_scan
        from .scene.export import write_outputs
        from .scene.measure import scan_scene
        from .scene.settings import ScanSettings
        settings = ScanSettings(kind, min_length, max_length, margin, method=method, band=band,
                                pulse_width=pulse_width, saturation=saturation, track_azimuth_deg=track_azimuth,
                                intervals=_intervals(interval_method, replicates, confidence))
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
        _print_scan(scene, info, kind, records, summaries, written, fmt)
    if interrupted is not None:
        measured = sum(r.reason != "interrupted" for r in records)
        click.echo(f"imgmtf: interrupted ({_signal_name(interrupted)}): {measured} of {len(records)} "
                   "candidates screened or measured, the rest marked interrupted"
                   + (f"; written to {out_dir}" if out_dir else ""), err=True)
        sys.exit(_interrupt_code(interrupted))
    if not any(r.ok for r in records):
        click.echo(f"imgmtf: error: {scene}: no usable {kind} found "
                   f"({len(records)} candidates, all rejected)", err=True)
        sys.exit(1)


def _print_scan(scene, info, kind, records, summaries, written, fmt) -> None:
    if fmt == "json":
        from .records import to_json
        for r in (*records, *summaries):
            click.echo(to_json(r))
        return
    accepted = sum(r.ok for r in records)
    click.echo(f"{scene}: {info.width} x {info.height} px, {len(records)} candidate "
               f"{kind}s, {accepted} accepted")
    click.echo(f"{'id':>4} {'rank':>4} {'tgt':>3} {'dir':>7} {'normal':>7} {'len':>5} {'SNR':>5} {'MTF@Nyq':>7} "
               f"{'interval':>15} {'MTF50':>7}  ROI x,y,w,h / reason")
    click.echo(f"{'':>4} {'':>4} {'':>3} {'':>7} {'deg':>7} {'px':>5} {'':>5} {'':>7} {'':>15} {'cy/px':>7}")
    for record in records:
        r = record.to_dict()
        head = (f"{r['id']:>4} {r.get('rank') or '':>4} {r.get('target_id') or '':>3} "
                f"{_DIRECTIONS.get(r.get('direction'), r.get('direction') or '-'):>7} "
                f"{_num(r.get('normal_angle_deg'), 7, 2)} {r['length_px']:5.0f}")
        if record.ok:
            roi = ",".join(str(v) for v in r["roi"])
            click.echo(f"{head} {_num(r.get('snr'), 5, 0)} {_num(r.get('mtf_nyquist'), 7, 4)} "
                       f"{_interval(r.get('mtf_nyquist_ci')):>15} {_num(r.get('mtf50_cy_px'), 7, 4)}  {roi}")
            for warning in r.get("warnings") or []:
                click.echo(f"{'':>{len(head)}} warning: {warning}")
        else:       # the scene's name heads the table: the message need not repeat it
            click.echo(f"{head} {'rejected':>37}  {r['reason']}: {r['error'].removeprefix(r['path'] + ': ')}")
    if summaries:
        click.echo("combined per target and per direction, weighted by precision (consistency over 1: "
                   "the half-edges disagree beyond their intervals):")
        click.echo(f"{'scope':>6} {'tgt':>3} {'dir':>7} {'normal':>7} {'edges':>5} {'MTF@Nyq':>7} "
                   f"{'interval':>15} {'MTF50':>7} {'interval':>15} {'FWHM':>6} {'consist.':>8}")
        for summary in summaries:
            r = summary.to_dict()
            click.echo(f"{r['scope']:>6} {r.get('target_id') or '':>3} "
                       f"{_DIRECTIONS.get(r['direction'], r['direction']):>7} {_num(r['normal_angle_deg'], 7, 2)} "
                       f"{r['n_edges']:>5} {_num(r['mtf_nyquist'], 7, 4)} {_interval(r['mtf_nyquist_ci']):>15} "
                       f"{_num(r.get('mtf50_cy_px'), 7, 4)} {_interval(r.get('mtf50_ci_cy_px')):>15} "
                       f"{_num(r.get('fwhm_px'), 6, 3)} {_num(r.get('consistency'), 8, 2)}")
    for path in written:
        click.echo(f"wrote {path}")


_DIRECTIONS = {"across-track": "across", "along-track": "along"}


def _interval(pair) -> str:
    lo, hi = pair or (None, None)
    return f"[{lo:.4f},{hi:.4f}]" if lo is not None and hi is not None else "-"


# -- reproduce ----------------------------------------------------------------
@main.command(short_help="Rerun the paper's study and find each method's SNR threshold.")
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
    from .reproduce import THRESHOLD_SNRS, run_study
    with _reported_errors():
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


# -- selftest -----------------------------------------------------------------
@main.command(short_help="Render chips of known MTF, measure them, compare (exit 1 if off).")
@click.option("--method", cls=MethodOption)
def selftest(method):
    """Render generic-sensor chips with known MTF, measure them, and compare
    measured with true; exit 1 if any estimate is out of tolerance."""
    with _reported_errors():
        from .selftest import CASES, run_selftest
        from .sensor.model import DIRECTIONS, Sensor
        from .version import __version__
        sensor = Sensor()
        click.echo(f"imgmtf {__version__} self-test: generic sensor (Choi & Helder), GSD {sensor.gsd_m:g} m")
        for d in DIRECTIONS:
            click.echo(f"  model {d:>6}-track: FWHM {sensor.fwhm_m(d):.4f} m, "
                       f"MTF at Nyquist {sensor.mtf_nyquist(d):.4f}")
        click.echo(f"measuring 100 x 100 px 16-bit chips with method {method!r} "
                   "(! marks a figure out of tolerance):")
        width = max(len(case.name) for case in CASES)
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


if __name__ == "__main__":
    main()

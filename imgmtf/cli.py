"""Command-line interface: a thin shell over the public API.

Exit codes: 0 success, 1 a problem with the input (one line on stderr, or
an ``error`` field per file in JSON), 2 a usage error.
"""
from __future__ import annotations

import json
import os
import sys
from contextlib import contextmanager
from pathlib import Path

import click

from . import __version__
from .edge import EdgeEstimator
from .errors import FileWriteError, ImgmtfError, ParameterError
from .inputs import saturation_levels
from .io import read_raster, write_geotiff
from .noise import GroundNoise
from .pulse import PulseEstimator, check_width
from .rendering import render
from .resampling import METHODS
from .selftest import run_selftest
from .sensor import DIRECTIONS, Sensor
from .targets import Target


@contextmanager
def _reported_errors():
    """Turn a deliberate imgmtf error into one line on stderr and exit 1."""
    try:
        yield
    except ImgmtfError as exc:
        click.echo(f"imgmtf: error: {exc}", err=True)
        sys.exit(1)


def _load_sensor(path: str | None) -> Sensor:
    return Sensor.from_toml(path) if path else Sensor()


def _save_figure(fig, path: str | Path) -> None:
    try:
        fig.savefig(path, dpi=110)
    except OSError as exc:
        raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None


def _length_option(default_unit: str):
    """Click callback: "1.4", "1.4px" or "18.3m" -> (value, unit)."""
    def parse(ctx, param, value):
        if value is None:
            return None
        text = value.strip().lower()
        unit = next((u for u in ("px", "m") if text.endswith(u)), None)
        number = text[: -len(unit)] if unit else text
        try:
            return float(number), unit or default_unit
        except ValueError:
            raise click.BadParameter(f"expected a number with an optional px or m suffix, got {value!r}")
    return parse


def _parse_roi(ctx, param, value):
    if value is None:
        return None
    try:
        parts = tuple(int(p) for p in value.split(","))
    except ValueError:
        parts = ()
    if len(parts) != 4:
        raise click.BadParameter(f"expected X,Y,W,H (four integers), got {value!r}")
    return parts


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="imgmtf")
def main():
    """Measure the MTF of imaging sensors from edge and pulse targets, and
    render exact synthetic chips with the generic pushbroom sensor."""


# -- simulate -----------------------------------------------------------------
@main.command()
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--angle", type=float, default=6.0, show_default=True,
              help="tilt of the edge from the column axis, degrees in (-90, 90]; near 90 for along track")
@click.option("--low", type=float, default=200.0, show_default=True, help="DN on the dark side (outside a pulse)")
@click.option("--high", type=float, default=1200.0, show_default=True, help="DN on the bright side (inside a pulse)")
@click.option("--pulse-width", callback=_length_option("m"),
              help="pulse width: 18.3 or 18.3m (metres), 1.4px (pixels); pulse targets")
@click.option("--offset", type=float, default=0.0, show_default=True,
              help="sub-pixel position of the edge along its normal from the chip centre, px")
@click.option("--size", type=int, default=50, show_default=True, help="chip side, pixels")
@click.option("--gsd", type=float, help="output GSD in metres (default: the sensor's)")
@click.option("--bits", type=click.Choice(["8", "16"]), default="16", show_default=True)
@click.option("--noise-std", type=float, default=0.0, show_default=True, help="system noise std, DN")
@click.option("--ground-noise", is_flag=True, help="add the paper's 20-layer ground noise (2000 DN^2)")
@click.option("--oversampling", type=int, default=20, show_default=True, help="sub-pixels per pixel")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False), help="sensor TOML file")
@click.option("--seed", type=int, help="random seed for the noise")
@click.option("--out", required=True, type=click.Path(dir_okay=False), help="output GeoTIFF")
def simulate(kind, angle, low, high, pulse_width, offset, size, gsd, bits, noise_std,
             ground_noise, oversampling, sensor_path, seed, out):
    """Render an edge or pulse chip through the generic sensor to a GeoTIFF."""
    with _reported_errors():
        sensor = _load_sensor(sensor_path)
        gsd_m = sensor.gsd_m if gsd is None else gsd
        if gsd_m <= 0:
            raise ImgmtfError(f"--gsd must be > 0 m, got {gsd_m}")
        if kind == "pulse" and pulse_width is None:
            raise ImgmtfError("a pulse target needs --pulse-width (metres)")
        if kind == "edge" and pulse_width is not None:
            raise ImgmtfError("--pulse-width applies to --target pulse only")
        width_px = 0.0
        if kind == "pulse":
            value, unit = pulse_width
            width_px = value if unit == "px" else value / gsd_m
        target = Target(kind, angle, low, high, offset, width_px)
        chip = render(sensor, target, size, gsd_m=gsd_m, oversampling=oversampling, bits=int(bits),
                      noise_std_dn=noise_std, ground_noise=GroundNoise() if ground_noise else None,
                      seed=seed)
        write_geotiff(out, chip.image, gsd_m=chip.gsd_m, provenance=chip.provenance())
    clipped = f", {100 * chip.clipped_fraction:.1f} % of pixels clipped" if chip.clipped_fraction else ""
    click.echo(f"wrote {out}: {size} x {size} px, {bits}-bit, {kind} at {angle:g} deg, "
               f"GSD {chip.gsd_m:g} m; true MTF at Nyquist along the normal "
               f"{float(chip.true_mtf(0.5)):.4f}{clipped}")


# -- sensor -------------------------------------------------------------------
@main.command("sensor")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False), help="sensor TOML file")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), help="save PSF/LSF/MTF figure (PNG)")
@click.option("--save", "save_path", type=click.Path(dir_okay=False), help="write the sensor as TOML")
def sensor_command(sensor_path, plot_path, save_path):
    """Print the sensor's component and system FWHM and MTF at Nyquist."""
    with _reported_errors():
        sensor = _load_sensor(sensor_path)
        click.echo(f"generic sensor, GSD {sensor.gsd_m:g} m "
                   f"({'paper defaults' if sensor == Sensor() else sensor_path})")
        click.echo(f"{'stage':<12} {'FWHM across (m)':>16} {'FWHM along (m)':>15} "
                   f"{'MTF@Nyq across':>15} {'MTF@Nyq along':>14}")
        stages = {**sensor.components(), "system": sensor}
        for name, stage in stages.items():
            fw = [stage.fwhm_m(d) if stage.mtf_nyquist(d) < 1 - 1e-12 else None for d in DIRECTIONS]
            cells = [f"{v:16.4f}" if v is not None else f"{'-':>16}" for v in fw]
            click.echo(f"{name:<12} {cells[0]} {cells[1][1:]} "
                       f"{stage.mtf_nyquist('across'):15.4f} {stage.mtf_nyquist('along'):14.4f}")
        if save_path:
            sensor.to_toml(save_path)
            click.echo(f"wrote {save_path}")
        if plot_path:
            from .plot import plot_sensor
            _save_figure(plot_sensor(sensor), plot_path)
            click.echo(f"wrote {plot_path}")


# -- measure ------------------------------------------------------------------
@main.command()
@click.argument("paths", nargs=-1, required=True, type=click.Path())
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--pulse-width", callback=_length_option("px"),
              help="bar width: 1.4px or 1.4 (pixels), 18.3m (metres, needs a GSD); "
                   "estimated from the profile when omitted")
@click.option("--method", type=click.Choice(list(METHODS)), default="msg", show_default=True,
              help="profile smoothing/resampling method")
@click.option("--roi", callback=_parse_roi, help="X,Y,W,H crop in pixels")
@click.option("--band", type=int, help="1-based band (default: the only band, or RGB luminance)")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text", show_default=True)
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False), help="figure for a single input (PNG)")
@click.option("--plot-dir", type=click.Path(file_okay=False), help="one figure per input in this folder")
def measure(paths, kind, pulse_width, method, roi, band, fmt, plot_path, plot_dir):
    """Measure the MTF of the edge (or bar) in each image.  With --format
    json, one JSON object per input per line (JSON Lines)."""
    if plot_path and len(paths) > 1:
        raise click.UsageError("--plot takes a single input; use --plot-dir for several")
    if pulse_width and kind != "pulse":
        raise click.UsageError("--pulse-width applies to --target pulse only")
    with _reported_errors():
        if pulse_width and pulse_width[1] == "px":
            check_width(pulse_width[0])
        estimator = EdgeEstimator(method) if kind == "edge" else PulseEstimator(method)
    if plot_dir:
        Path(plot_dir).mkdir(parents=True, exist_ok=True)
    failures = 0
    if fmt == "text":
        last = "RER" if kind == "edge" else "W px"
        click.echo(f"{'path':<32} {'angle':>7} {'dir':>6} {'SNR':>7} {'MTF@Nyq':>8} "
                   f"{'MTF50':>7} {'FWHM':>6} {last:>6}")
    for path in paths:
        try:
            raster = read_raster(path, band)
            if kind == "edge":
                result = estimator(raster.data, roi=roi, gsd_m=raster.gsd_m,
                                   saturation=saturation_levels(raster.dtype))
            else:
                result = estimator(raster.data, width_px=_width_px(pulse_width, raster), roi=roi,
                                   gsd_m=raster.gsd_m)
            figure_path = plot_path or (Path(plot_dir) / f"{Path(path).stem}_mtf.png" if plot_dir else None)
            if figure_path:
                from .plot import plot_measurement
                _save_figure(plot_measurement(result), figure_path)
        except ImgmtfError as exc:
            failures += 1
            if fmt == "json":
                click.echo(json.dumps({"path": path, "error": str(exc)}))
            else:
                click.echo(f"{path:<32} error: {exc}")
            continue
        if fmt == "json":
            click.echo(json.dumps({"path": path, "band": raster.band, **result.to_dict()}))
        else:
            last = result.rer if kind == "edge" else result.pulse_width_px
            click.echo(f"{path:<32} {result.angle_deg:7.2f} {result.direction.split('-')[0]:>6} "
                       f"{result.snr:7.0f} {result.mtf_nyquist:8.4f} {result.mtf50_cy_px:7.4f} "
                       f"{result.fwhm_px:6.3f} {last:6.3f}")
            for warning in result.warnings:
                click.echo(f"{'':<32} warning: {warning}")
    sys.exit(1 if failures else 0)


def _width_px(width, raster) -> float | None:
    """A --pulse-width in pixels for this raster (metres need its GSD)."""
    if width is None:
        return None
    value, unit = width
    if unit == "px":
        return value
    if raster.gsd_m is None:
        raise ParameterError(f"{raster.path}: a width in metres needs a georeferenced image "
                             "(its GSD is unknown); give the width in px")
    check_width(value / raster.gsd_m)
    return value / raster.gsd_m


# -- reproduce ----------------------------------------------------------------
@main.command()
@click.option("--out", required=True, type=click.Path(file_okay=False), help="output folder")
@click.option("--quick", is_flag=True, help="few realisations (under a minute)")
@click.option("--workers", type=click.IntRange(min=1), default=os.cpu_count() or 1,
              show_default="all cores", help="worker processes")
@click.option("--seed", type=int, default=0, show_default=True)
def reproduce(out, quick, workers, seed):
    """Rerun the paper's study (Tables 1-2, Figs. 2-3 and 12-14) and find the
    lowest SNR at which each method is trustworthy; writes OUT/report.md."""
    from .reproduce import run_study
    with _reported_errors():
        result = run_study(out, quick=quick, workers=workers, seed=seed)
    for method, snr in result["thresholds"].items():
        click.echo(f"{method:8s} trustworthy from SNR {snr:g}")
    click.echo(f"wrote {Path(out) / 'report.md'} ({result['seconds']:.0f} s)")


# -- selftest -----------------------------------------------------------------
@main.command()
@click.option("--method", type=click.Choice(list(METHODS)), default="msg", show_default=True)
def selftest(method):
    """Render generic-sensor chips with known MTF, measure them, and compare
    measured with true; exit 1 if any estimate is out of tolerance."""
    sensor = Sensor()
    click.echo(f"imgmtf {__version__} self-test: generic sensor (Choi & Helder), GSD {sensor.gsd_m:g} m")
    for d in DIRECTIONS:
        click.echo(f"  model {d:>6}-track: FWHM {sensor.fwhm_m(d):.4f} m, "
                   f"MTF at Nyquist {sensor.mtf_nyquist(d):.4f}")
    click.echo(f"measuring 100 x 100 px 16-bit chips with method {method!r} "
               "(! marks a figure out of tolerance):")
    click.echo(f"{'case':<28} {'':>5} {'MTF@Nyq':>8} {'MTF50':>8} {'FWHM px':>8}")
    rows = run_selftest(sensor, method=method)
    for row in rows:
        click.echo(f"{row.name:<28} {'true':>5} {row.true['mtf_nyquist']:8.4f} "
                   f"{row.true['mtf50']:8.4f} {row.true['fwhm']:8.4f}")
        marks = {k: ("" if v else "!") for k, v in row.passed.items()}
        click.echo(f"{'':<28} {'got':>5} {row.measured['mtf_nyquist']:8.4f}{marks['mtf_nyquist']:1}"
                   f"{row.measured['mtf50']:8.4f}{marks['mtf50']:1}{row.measured['fwhm']:8.4f}{marks['fwhm']:1}"
                   f"  {'PASS' if row.ok else 'FAIL'}  (SNR {row.snr:.0f})")
    failed = [r.name for r in rows if not r.ok]
    if failed:
        click.echo(f"FAILED: {len(failed)} of {len(rows)} cases out of tolerance (marked !)", err=True)
        sys.exit(1)
    click.echo(f"all {len(rows)} cases within tolerance")


if __name__ == "__main__":
    main()

"""``imgmtf simulate``: render an edge or bar chip through the sensor."""
from __future__ import annotations

from pathlib import Path

import click

from ..errors import ParameterError
from .errors import option_errors, reported_errors
from .files import check_output_file, load_sensor
from .options import FiniteFloat, length_option

# Bounds of the size-like options (see docs): what a run may allocate.
DEFAULT_LEVELS_DN = {16: (200.0, 1200.0), 8: (30.0, 210.0)}    # simulate's dark and bright sides
MAX_CHIP_PX = 4096                  # simulate --size: the renderer's 16 Mpx
MAX_OVERSAMPLING = 100              # simulate --oversampling


@click.command(short_help="Render an edge or bar chip through the sensor (GeoTIFF, PNG).")
@click.option("--target", "kind", type=click.Choice(["edge", "pulse"]), default="edge", show_default=True)
@click.option("--angle", type=FiniteFloat(-90, 90, min_open=True), default=6.0, show_default=True,
              help="angle of the edge's normal from the x (column) axis, degrees in (-90, 90], which "
                   "is the edge's tilt from vertical: near 0 across track, near 90 along track "
                   "(measure reports it as normal_angle_deg)")
@click.option("--low", type=FiniteFloat(), show_default="200 at 16 bits, 30 at 8",
              help="DN on the dark side (outside a pulse)")
@click.option("--high", type=FiniteFloat(), show_default="1200 at 16 bits, 210 at 8",
              help="DN on the bright side (inside a pulse)")
@click.option("--pulse-width", callback=length_option("px"),
              help="bar width of a pulse target, at least 0.2 px and at most --size: 1.5 or 1.5px (pixels), "
                   "1.5m (metres on the ground)")
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
    with reported_errors():
        default_low, default_high = DEFAULT_LEVELS_DN[int(bits)]     # a step that fits the bit depth
        low = default_low if low is None else low
        high = default_high if high is None else high
        from ..io import write_geotiff, write_png
        from ..sensor.noise import GroundNoise
        from ..sensor.rendering import render
        from ..sensor.targets import Target
        suffix = Path(out).suffix.lower()
        if suffix not in (".tif", ".tiff", ".png"):
            raise click.BadParameter(f"{out}: simulate writes a GeoTIFF (.tif, .tiff), which records the GSD and "
                                     "how the chip was made, or a PNG (.png, pixels only); "
                                     f"got {suffix or 'no suffix'}", param_hint="'--out'")
        if kind == "pulse" and pulse_width is None:
            raise click.UsageError("a pulse target needs --pulse-width (1.5 or 1.5px: pixels; 1.5m: metres)")
        if kind == "edge" and pulse_width is not None:
            raise click.UsageError("--pulse-width applies to --target pulse only")
        check_output_file(out)
        sensor = load_sensor(sensor_path)
        gsd_m = sensor.gsd_m if gsd is None else gsd
        # simulate reads no input: a value the renderer refuses is a bad option (exit 2)
        with option_errors():
            width_px = 0.0
            if kind == "pulse":
                value, unit = pulse_width
                width_px = value if unit == "px" else value / gsd_m
                from ..inputs import MIN_BAR_WIDTH_PX
                if not width_px >= MIN_BAR_WIDTH_PX:
                    raise ParameterError(f"--pulse-width: a {width_px:g} px wide pulse is narrower than the "
                                         f"{MIN_BAR_WIDTH_PX} px imgmtf can measure (is the unit right?)")
                if width_px > size:
                    raise ParameterError(f"--pulse-width ({width_px:g} px) is wider than the chip "
                                         f"(--size {size} px)")
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

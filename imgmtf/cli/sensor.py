"""``imgmtf sensor``: the sensor model's stages, FWHM and MTF."""
from __future__ import annotations

import click

from .errors import reported_errors
from .files import check_figure_file, check_output_file, load_sensor, save_figure


@click.command("sensor", short_help="Print (and plot) the sensor model's stages, FWHM and MTF.")
@click.option("--sensor", "sensor_path", type=click.Path(dir_okay=False), help="sensor TOML file")
@click.option("--plot", "plot_path", type=click.Path(dir_okay=False),
              help="save the PSF, LSFs and each stage's MTF beside the system's (PNG)")
@click.option("--save", "save_path", type=click.Path(dir_okay=False), help="write the sensor as TOML")
def sensor_command(sensor_path, plot_path, save_path):
    """Print the sensor's stages, and each stage's and the system's FWHM and
    MTF at Nyquist across and along track."""
    with reported_errors():
        from ..sensor.model import DIRECTIONS, Sensor
        if plot_path:
            check_figure_file(plot_path)
        if save_path:
            check_output_file(save_path)
        sensor = load_sensor(sensor_path)
        click.echo(f"sensor, GSD {sensor.gsd_m:g} m "
                   f"({'the paper' + chr(39) + 's generic sensor' if sensor == Sensor() else sensor_path})")
        for stage in sensor.stages:
            units = stage.units()
            values = ", ".join(f"{k} {_shown(v)}{(' ' + units[k]) if units[k] else ''}"
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
            from ..plot import plot_sensor
            save_figure(plot_sensor(sensor), plot_path)
            click.echo(f"wrote {plot_path}")


def _shown(value) -> str:
    """A stage parameter in the listing: a number, a word (a measured MTF's
    combination) or a tabulated curve, by its length and ends."""
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple)):
        return f"[{len(value)} values, {value[0]:.4g} to {value[-1]:.4g}]"
    return f"{value:.6g}"

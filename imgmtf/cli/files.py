"""Output paths checked before any work, figures saved, sensors loaded."""
from __future__ import annotations

import os
from pathlib import Path

import click

from ..errors import FileWriteError, ImgmtfError
from .errors import one_line


def load_sensor(path: str | None):
    from ..sensor.model import Sensor
    if not path:
        return Sensor()
    try:
        return Sensor.from_toml(path)
    except ImgmtfError:
        raise
    except (UnicodeDecodeError, ValueError, TypeError) as exc:  # what a model check may miss
        from ..errors import ConfigError
        raise ConfigError(f"{path}: not a readable sensor TOML file ({type(exc).__name__}: "
                          f"{one_line(exc)})") from None


def save_figure(fig, path: str | Path) -> None:
    from ..figures import save_figure
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
    formats, so a wrong one is refused (a usage error) before any work, not
    after it."""
    suffix = Path(path).suffix.lower()
    if suffix not in FIGURE_SUFFIXES:           # a malformed option: exit 2, as click's own checks
        raise click.BadParameter(f"{path}: a figure is written as {', '.join(s[1:] for s in FIGURE_SUFFIXES)} "
                                 f"(by its suffix); got {suffix or 'no suffix'}", param_hint="'--plot'")
    check_output_file(path)

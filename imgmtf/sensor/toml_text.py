"""A sensor as TOML text: its lines (``gsd_m`` and a table per stage), the
values in them, and the file written; what :meth:`imgmtf.Sensor.to_toml`
and a fitted sensor's file (:mod:`imgmtf.estimate.fit.record`) share."""
from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from pathlib import Path

from ..errors import FileWriteError
from .stages import Stage


def sensor_toml_lines(gsd_m: float, stages: Sequence[Stage], table: str = "") -> list[str]:
    """A sensor as lines of TOML: ``gsd_m`` and a ``[[stages]]``
    table per stage; within ``table`` when given (``[table]``,
    ``[[table.stages]]``), as a fitted sensor's file keeps it beside its
    ``[fit]`` record.

    Parameters
    ----------
    gsd_m : float
        Its ground sample distance, m.
    stages : sequence of Stage
        Its stages.
    table : str, optional
        The table holding the sensor (default none: the top level).

    Returns
    -------
    list of str
        The lines.

    Examples
    --------
    >>> from imgmtf.sensor.stages import Detector
    >>> sensor_toml_lines(1.0, [Detector()], "sensor")[:4]
    ['[sensor]', 'gsd_m = 1.0', '', '[[sensor.stages]]']
    """
    lines = [f"[{table}]"] if table else []
    lines.append(f"gsd_m = {toml_value(gsd_m)}")
    for stage in stages:
        lines += ["", f"[[{table + '.' if table else ''}stages]]", f"stage = {toml_value(stage.name)}"]
        lines += [f"{k} = {toml_value(v)}" for k, v in stage.to_dict(include_name=False).items()]
    return lines


def toml_value(value: float | str | Sequence[float | str]) -> str:
    """A value in TOML: a number (``nan``, ``inf`` and ``-inf`` included),
    a string (JSON's escapes are TOML's basic string's, non-ASCII as
    \\uXXXX) or an array of them (a measured MTF's curves, a fit's
    sources).

    Examples
    --------
    >>> toml_value(0.5), toml_value(float("-inf")), toml_value("B4"), toml_value([1, 2.5])
    ('0.5', '-inf', '"B4"', '[1.0, 2.5]')
    """
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    number = float(value)  # type: ignore[arg-type]
    return "nan" if math.isnan(number) else "inf" if number == math.inf else "-inf" if number == -math.inf \
        else repr(number)


def write_toml_lines(path: str | os.PathLike, lines: list[str]) -> None:
    """Write ``lines`` of TOML to ``path`` (replaced if it exists).

    Raises
    ------
    FileWriteError
        The file cannot be written.
    """
    try:
        Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
    except OSError as exc:
        raise FileWriteError(f"{path}: cannot write sensor file: {exc.strerror or exc}") from None

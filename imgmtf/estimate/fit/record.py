"""A fitted sensor's file: the sensor and whether its model fits.

``imgmtf fit --out`` writes the sensor in a ``[sensor]`` table, which
:meth:`imgmtf.Sensor.from_toml` reads (it takes the ``[sensor]`` table and
ignores the rest), beside a ``[fit]`` table that says how well the model
fitted the edges it was fitted to (:class:`FitRecord`): whether it misfits,
its reduced chi-square, the smallest misfit p-value and the largest misfit
fraction over its edges, its stages and its source files.  A reader that
needs to know whether the model is to be trusted (``imgmtf restore``) reads
the table with :func:`read_fit_record`; a sensor file without one (written
by hand, by ``imgmtf sensor --save``) makes no claim either way.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import ConfigError
from ...sensor.toml_text import sensor_toml_lines, toml_value, write_toml_lines

#: the keys of the ``[fit]`` table and the type each holds
_FIELDS = {"misfit": bool, "reduced_chi_square": float, "misfit_p": float, "misfit_fraction": float,
           "stages": list, "sources": list, "imgmtf_version": str}


@dataclass(frozen=True)
class FitRecord:
    """How well a fitted sensor's model fitted its edges (the ``[fit]`` table).

    Attributes
    ----------
    misfit : bool
        True when the model does not fit (:attr:`imgmtf.SensorFit.misfit`):
        an edge's residuals are structured, or a parameter sits at a bound.
    reduced_chi_square : float
        Of the samples' residuals (1 for a model that fits to the noise).
    misfit_p : float
        The smallest p-value of structure in an edge's residuals (small:
        structure the noise does not explain); NaN where the test could run
        on no edge.
    misfit_fraction : float
        The largest RMS of that structure, fraction of the edge's step
        (over the edges tested).
    stages : tuple of str
        The fitted sensor's stages.
    sources : tuple of str
        The edges it was fitted to (files, with their ROI when one was given).
    imgmtf_version : str
        The version that fitted it.

    Examples
    --------
    >>> import imgmtf
    >>> from imgmtf.estimate.fit.record import read_fit_record
    >>> fit = imgmtf.fit_sensor([imgmtf.render(imgmtf.Sensor(), imgmtf.Target("edge", 6.0), 60).image])
    >>> fit.to_toml("fitted.toml")
    >>> record = read_fit_record("fitted.toml")
    >>> record.misfit, record.sources, imgmtf.Sensor.from_toml("fitted.toml").gsd_m
    (False, ('array 1',), 1.0)
    """

    misfit: bool
    reduced_chi_square: float
    misfit_p: float
    misfit_fraction: float
    stages: tuple[str, ...]
    sources: tuple[str, ...]
    imgmtf_version: str = ""

    @classmethod
    def of(cls, fit: Any, sources: list[str] | None = None) -> FitRecord:
        """The record of a fit.

        Parameters
        ----------
        fit : SensorFit
            The fit (:func:`imgmtf.fit_sensor`; untyped here: this module
            sits below :mod:`.results`, which writes with it).
        sources : list of str, optional
            What the edges were (default the fit's edge names).

        Returns
        -------
        FitRecord
            Its verdict and figures.
        """
        from ...version import __version__
        edges = fit.edges
        tested = [e for e in edges if math.isfinite(e.misfit_p)]       # an untested edge is no pass
        return cls(bool(fit.misfit), float(fit.reduced_chi_square),
                   min((float(e.misfit_p) for e in tested), default=math.nan),
                   max((float(e.misfit_fraction) for e in tested), default=math.nan),
                   tuple(s.name for s in fit.sensor.stages),
                   tuple(sources) if sources is not None else tuple(e.source for e in edges), __version__)

    def summary(self) -> str:
        """One line: the verdict and its figures."""
        verdict = ("does not fit" if self.misfit else "fits" if math.isfinite(self.misfit_p)
                   else "could not be tested on")
        return (f"the model ({', '.join(self.stages)}) {verdict} the {len(self.sources)} edge(s) it was fitted to "
                f"(reduced chi-square {self.reduced_chi_square:.3g}, misfit p {self.misfit_p:.2g}, "
                f"structure {100 * self.misfit_fraction:.2f} % of the step)")

    def to_dict(self) -> dict:
        return {"misfit": self.misfit, "reduced_chi_square": _json(self.reduced_chi_square),
                "misfit_p": _json(self.misfit_p), "misfit_fraction": _json(self.misfit_fraction),
                "stages": list(self.stages), "sources": list(self.sources), "imgmtf_version": self.imgmtf_version}

    def toml_lines(self) -> list[str]:
        """The ``[fit]`` table, as lines of TOML."""
        return ["[fit]", f"misfit = {'true' if self.misfit else 'false'}",
                f"reduced_chi_square = {toml_value(self.reduced_chi_square)}",
                f"misfit_p = {toml_value(self.misfit_p)}",
                f"misfit_fraction = {toml_value(self.misfit_fraction)}",
                f"stages = {toml_value([str(s) for s in self.stages])}",
                f"sources = {toml_value([str(s) for s in self.sources])}",
                f"imgmtf_version = {toml_value(self.imgmtf_version)}"]


def write_fitted_sensor(path: str | os.PathLike, fit: Any, *, comment: str = "",
                        sources: list[str] | None = None, record: FitRecord | None = None) -> None:
    """Write ``fit``'s sensor as TOML with its ``[fit]`` record: the
    sensor in a ``[sensor]`` table (``gsd_m`` and ``[[sensor.stages]]``),
    which :meth:`imgmtf.Sensor.from_toml` reads as it reads
    :meth:`imgmtf.Sensor.to_toml`'s form.

    Parameters
    ----------
    path : str or pathlib.Path
        The file (replaced if it exists).
    fit : SensorFit
        The fit (:func:`imgmtf.fit_sensor`).
    comment : str, optional
        Lines written as TOML comments on top.
    sources : list of str, optional
        What the edges were (default the fit's edge names).
    record : FitRecord, optional
        The ``[fit]`` record, for a fit of other targets than edges (bars:
        :meth:`imgmtf.estimate.fit.bars.BarFit.to_toml`); default
        :meth:`FitRecord.of` ``fit``.

    Raises
    ------
    FileWriteError
        The file cannot be written.
    """
    record = record if record is not None else FitRecord.of(fit, sources)
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += ["# imgmtf fitted sensor: metres on the ground, cycles/metre for frequencies",
              "# [fit] says whether the model fits the edges it was fitted to (imgmtf restore refuses a misfit)",
              *record.toml_lines(), "", *sensor_toml_lines(fit.sensor.gsd_m, fit.sensor.stages, "sensor")]
    write_toml_lines(path, lines)


def read_fit_record(path: str | Path) -> FitRecord | None:
    """The ``[fit]`` record of a sensor file.

    Parameters
    ----------
    path : str or pathlib.Path
        The sensor TOML.

    Returns
    -------
    FitRecord or None
        Its record; None when it has none (a sensor written by hand or by
        ``imgmtf sensor --save`` makes no claim).

    Raises
    ------
    ConfigError
        The file cannot be read as TOML, or its ``[fit]`` table is malformed.

    Examples
    --------
    >>> import imgmtf
    >>> imgmtf.Sensor().to_toml("plain.toml")
    >>> print(imgmtf.read_fit_record("plain.toml"))
    None
    """
    try:
        with open(path, "rb") as fh:
            doc = tomllib.loads(fh.read().decode("utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read sensor file: {exc.strerror or exc}") from None
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{path}: not a readable sensor TOML file ({type(exc).__name__})") from None
    table = doc.get("fit")
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ConfigError(f"{path}: [fit] must be a table")
    values: dict[str, Any] = {}
    for key, kind in _FIELDS.items():
        if key not in table:
            if key == "imgmtf_version":
                continue
            raise ConfigError(f"{path}: [fit] has no {key}")
        value: Any = table[key]
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        strings = isinstance(value, list) and all(isinstance(v, str) for v in value)
        if not (strings if kind is list else isinstance(value, kind)):
            raise ConfigError(f"{path}: [fit] {key} must be {_KIND_NAMES[kind]}, got {value!r}")
        values[key] = tuple(value) if strings else value
    return FitRecord(**values)


_KIND_NAMES = {bool: "true or false", float: "a number", list: "an array of strings", str: "a string"}


def _json(value: float) -> float | None:
    return value if math.isfinite(value) else None

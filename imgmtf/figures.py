"""Saving figures: atomically, and without ever costing a measurement its
record (a figure that fails becomes a warning on the record)."""
from __future__ import annotations

from pathlib import Path

from .atomic import atomic_output
from .errors import FileWriteError, ImgmtfError
from .records import Record


def with_figure(record: Record, make_figure, path: str) -> Record:
    """``record`` with the figure ``make_figure()`` builds saved to
    ``path`` (its ``plot``), or, when that fails, a warning saying why: a
    figure never costs a measurement its record."""
    try:
        save_figure(make_figure, path)
    except Exception as exc:
        message = str(exc) if isinstance(exc, ImgmtfError) else (
            f"{path}: the figure failed: {type(exc).__name__}: {exc}")
        return record.with_(figures={"warnings": [*record.figures.get("warnings", []), message]})
    return record.with_(plot=path)


def save_figure(make_figure, path: str, dpi: int = 110) -> None:
    """Save the matplotlib figure ``make_figure()`` builds to ``path``
    (atomically; the format from the extension, Agg backend)."""
    with atomic_output(path) as partial:
        try:
            make_figure().savefig(partial, dpi=dpi, format=Path(path).suffix.lstrip(".") or "png")
        except ImgmtfError:
            raise                 # says what is wrong already (a FileWriteError is an OSError too)
        except OSError as exc:
            raise FileWriteError(f"{path}: cannot write the figure: {exc.strerror or exc}") from None

"""Output files that appear whole or not at all.

Every file imgmtf writes (CSV, JSON Lines, GeoJSON, figures, GeoTIFF chips)
is written under a temporary name in its own folder and renamed into place
when it is complete, so a reader never sees half a file and an existing
file is replaced in one step.  A writer may also *keep* what it has so far
when it is interrupted (a CSV of the rows measured before Ctrl-C): see
:func:`atomic_output`'s ``keep_partial``.
"""
from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import FileWriteError


def ensure_folder(folder: str | Path) -> Path:
    """``folder`` created with its parents; FileWriteError naming it when
    it cannot be (a file in the way, no permission...)."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise FileWriteError(f"{folder}: cannot create the folder: {exc.strerror or exc}") from None
    return folder


@contextmanager
def atomic_output(path: str | Path, *, keep_partial: bool = False) -> Iterator[str]:
    """A temporary path beside ``path`` (same folder, same suffix, so that
    writers choosing a format by extension still do), renamed to ``path``
    when the block ends.

    If the block raises, the temporary file is removed, unless
    ``keep_partial`` is set and the exception is an interrupt
    (KeyboardInterrupt or a subclass): then what was written is renamed into
    place, so rows already measured survive Ctrl-C or SIGTERM.

    Raises
    ------
    FileWriteError
        The folder does not exist or is not writable, or the rename fails.

    Examples
    --------
    >>> with atomic_output("summary.csv") as partial:   # doctest: +SKIP
    ...     Path(partial).write_text("a,b\\n1,2\\n")
    """
    path = Path(path)
    if path.is_dir():
        raise FileWriteError(f"{path}: is a folder; give a file name")
    folder = path.parent
    try:
        handle, partial = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".partial{path.suffix}",
                                           dir=folder)
    except OSError as exc:
        raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None
    os.close(handle)
    try:
        yield partial
    except KeyboardInterrupt:
        if keep_partial:
            _replace(partial, path)
        else:
            _remove(partial)
        raise
    except BaseException:
        _remove(partial)
        raise
    _replace(partial, path)


def _replace(partial: str, path: Path) -> None:
    try:
        os.chmod(partial, 0o666 & ~_umask())
        os.replace(partial, path)
    except OSError as exc:
        _remove(partial)
        raise FileWriteError(f"{path}: cannot write: {exc.strerror or exc}") from None


def _remove(partial: str) -> None:
    try:
        os.unlink(partial)
    except OSError:
        pass


def _umask() -> int:
    """The process umask (read by setting it, then restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask

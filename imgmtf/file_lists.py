"""Which files a command is given: the image files named and those in
folders named, each once.  Light (the standard library alone): a command
reads its list before it loads anything numerical or starts its workers."""
from __future__ import annotations

import os
from pathlib import Path

from .errors import ImageReadError

__all__ = ["IMAGE_SUFFIXES", "expand_inputs", "once_each"]

IMAGE_SUFFIXES = frozenset({".tif", ".tiff", ".png", ".jpg", ".jpeg", ".jp2", ".j2k", ".ntf", ".nitf",
                            ".img", ".bmp", ".gif", ".vrt", ".hdr", ".webp"})


def expand_inputs(paths, recursive: bool = False) -> list[str]:
    """Files named, plus the image files (by suffix) in folders named,
    sorted; with ``recursive`` also in their sub-folders.  Paths that do not
    exist are kept, to be reported as errors."""
    out = []
    for raw in map(str, paths):
        path = Path(raw)
        if raw and path.is_dir():          # Path("") is the current folder: "" is no file
            try:
                found = list(path.rglob("*") if recursive else path.iterdir())
            except OSError as exc:
                raise ImageReadError(f"{raw}: cannot list the folder: {exc.strerror or exc}") from None
            # not only regular files: a FIFO named x.tif is reported, not skipped
            out.extend(sorted(str(p) for p in found
                              if p.suffix.lower() in IMAGE_SUFFIXES and not p.is_dir()))
        else:
            out.append(raw)
    return out


def once_each(files: list[str]) -> tuple[list[str], dict[str, int]]:
    """The files in their order with each file once (the same file named
    twice, or by two paths, as ``a.tif ./a.tif``, or inside a folder also
    named), and how many times each repeated one was named (by its first
    name): a batch measures a file once and says so.

    Examples
    --------
    >>> once_each(["a.tif", "b.tif", "./a.tif", "a.tif"])
    (['a.tif', 'b.tif'], {'a.tif': 3})
    """
    first: dict[str, str] = {}
    counts: dict[str, int] = {}
    kept = []
    for name in files:
        key = os.path.normcase(os.path.realpath(name)) if name else name
        if key in first:
            counts[first[key]] = counts.get(first[key], 1) + 1
            continue
        first[key] = name
        kept.append(name)
    return kept, counts

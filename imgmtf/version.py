"""The installed package's version, read once from its metadata (the one
place it is defined is ``pyproject.toml``).

Every command that writes a record reads it, and ``importlib.metadata``
costs 20-30 ms to import (its e-mail parser, zip and CSV readers): a
tenth of a one-chip ``imgmtf measure``'s CPU.  So the version is read from
the ``METADATA`` file of the package's ``.dist-info`` folder, found where
``importlib.metadata`` finds it (the first folder of ``sys.path`` that
holds one); any other layout (a zip or egg on the path, a finder that
provides distributions of its own, two candidates in one folder) is left
to ``importlib.metadata`` itself.
"""
from __future__ import annotations

import os
import re
import sys

DISTRIBUTION = "imgmtf"


def _normalised(name: str) -> str:
    """A distribution's name as ``importlib.metadata`` compares them."""
    return re.sub(r"[-_.]+", "-", name).lower().replace("-", "_")


def dist_info_version(name: str = DISTRIBUTION) -> str | None:
    """The ``Version`` of distribution ``name`` read from its
    ``.dist-info/METADATA`` where ``importlib.metadata`` would read that
    file, else None (not found, or a layout this does not follow: then ask
    ``importlib.metadata``).

    Examples
    --------
    >>> import importlib.metadata
    >>> dist_info_version() in (None, importlib.metadata.version("imgmtf"))
    True
    """
    from importlib.machinery import PathFinder
    if any(hasattr(finder, "find_distributions") and finder is not PathFinder for finder in sys.meta_path):
        return None         # a finder that may provide the distribution before sys.path is searched
    wanted = _normalised(name)
    for entry in sys.path:
        root = entry or "."
        if not isinstance(entry, str) or root.lower().endswith(".egg"):
            return None
        try:
            children = os.listdir(root)
        except OSError:
            if os.path.isfile(root):    # a zip: importlib.metadata looks inside
                return None
            continue
        found = [child for child in children if child.lower().endswith((".dist-info", ".egg-info"))
                 and _normalised(child.lower().rpartition(".")[0].partition("-")[0]) == wanted]
        if not found:
            continue
        if len(found) > 1 or not found[0].lower().endswith(".dist-info"):
            return None
        return _header_version(os.path.join(root, found[0], "METADATA"))
    return None


def _header_version(path: str) -> str | None:
    """The ``Version:`` header of a core-metadata file, None without one."""
    try:
        with open(path, encoding="utf-8") as file:
            for line in file:
                if not line.strip():
                    break           # the headers end at the first blank line
                key, colon, value = line.partition(":")
                if colon and key.lower() == "version":
                    return value.strip() or None
    except (OSError, UnicodeDecodeError):
        pass
    return None


def _version() -> str:
    found = dist_info_version()
    if found is not None:
        return found
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version(DISTRIBUTION)
    except PackageNotFoundError:      # run from a source tree that was never installed
        return "0+unknown"


__version__ = _version()

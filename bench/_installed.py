"""What the benches' new processes import, as an installed imgmtf has it.

``pip install .`` compiles a package's modules once, at install time; an
editable install (a developer's, or this project's CI) compiles them in each
new process unless Python may write its bytecode cache, and
``PYTHONDONTWRITEBYTECODE`` (set on some machines) forbids that: about
0.07-0.1 s of every ``imgmtf`` command's start-up on 2 cores, which no user
of an installed imgmtf pays.  The benches that time commands compile the
package first, so their start-up is the installed one's.
"""
from __future__ import annotations

import compileall
from pathlib import Path

import imgmtf


def compile_package() -> None:
    """Write the bytecode of every imgmtf module (``__pycache__``, ignored
    by git), as ``pip install`` does, whatever ``PYTHONDONTWRITEBYTECODE``
    says: a new process then reads it instead of compiling."""
    compileall.compile_dir(Path(imgmtf.__file__).parent, quiet=1)

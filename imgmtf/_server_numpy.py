"""Imported by the workers' fork server alone, first of what it preloads
(:func:`imgmtf.parallel._start_fork_server`): NumPy's ``f2py`` and ``testing``
are registered as lazily loaded modules (:class:`importlib.util.LazyLoader`:
loaded in full at their first attribute's use).  SciPy's vendored
``array_api_compat`` copies every public attribute of NumPy as ``scipy.special``
first loads it, which imports each of NumPy's lazily loaded submodules: these two
are 0.2-0.25 s of the server's imports (the Fortran wrapper generator and the
test helpers), which no scan uses and every worker waits for, serially, before
its first task.  Imported anywhere else (not while
``multiprocessing.forkserver.main`` preloads it), it does nothing.
"""
from __future__ import annotations

import importlib.util
import sys

from ._fork_server import in_fork_server

UNUSED_SUBMODULES = ("f2py", "testing")


def _defer(package, name: str) -> None:
    """``package.name`` in ``sys.modules`` and on ``package``, its code run at its first attribute's use."""
    spec = importlib.util.find_spec(f"{package.__name__}.{name}")
    if spec is None or spec.loader is None:
        return
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    setattr(package, name, module)      # (NumPy's __getattr__ would import it again, and recurse)


if in_fork_server():
    import numpy

    for _name in UNUSED_SUBMODULES:
        if f"numpy.{_name}" not in sys.modules:
            _defer(numpy, _name)

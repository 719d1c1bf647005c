"""Imported by the workers' fork server alone (:func:`imgmtf.parallel._start_fork_server`
preloads it): at its exit the server skips the interpreter's teardown, which with SciPy
loaded takes 0.3 s while the command's output pipes, which the server inherited, stay
open, and whoever reads them (a shell's pipe, ``subprocess.run``) waits.  The server holds
imports and no state; the workers it forks end by ``os._exit`` already.  Imported anywhere
else (not while ``multiprocessing.forkserver.main`` preloads it), it does nothing."""
from __future__ import annotations

import atexit
import os

from ._fork_server import in_fork_server

if in_fork_server():
    atexit.register(os._exit, 0)

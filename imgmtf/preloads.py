"""What each kind of worker process imports before its first task: the
lists a command hands :func:`imgmtf.parallel.prestart_workers`, so that
the workers' fork server imports them once, as the command starts, rather
than every worker of every pool as its first task arrives (NumPy's lazily
loaded parts included).  One place for them, importing nothing but sys: the
command line reads them before it loads anything numerical.
"""
from __future__ import annotations

import sys


def main_run_again() -> bool:
    """Whether a worker process runs this process's main module again (as
    ``__mp_main__``), as multiprocessing does for a script (the ``imgmtf``
    command) and for a module run by ``python -m`` but a package's
    ``__main__`` (``python -m imgmtf``, ``python -m imgmtf.cli``), which it
    leaves alone."""
    main = sys.modules.get("__main__")
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if name is not None:
        return name != "__main__" and not name.endswith(".__main__")
    return getattr(main, "__file__", None) is not None


# NumPy's parts loaded on first use, which every estimate uses
NUMPY_LAZY = ("numpy.fft", "numpy.ma", "numpy.polynomial")
# a worker started by the fork server runs the ``imgmtf`` script again as ``__mp_main__`` (CPython does
# not hand the script to the fork server, which would run it once), and the script imports the command
# line: 30-40 ms a worker, once in the fork server when preloaded; under ``python -m imgmtf`` no worker
# imports it, and the server's import of it (50-70 ms of CPU) would only delay the first task
CLI_MODULES = ("imgmtf.cli",) if main_run_again() else ()
# a scan's own tasks: the tiles' detection, the candidates' measurement
SCAN_TASK_MODULES = ("imgmtf.scene.detect", "imgmtf.scene.candidates", "imgmtf.estimate.edge",
                     "imgmtf.estimate.pulse", *NUMPY_LAZY)
# what a scan's workers run besides, the targets' sections and the 2-D MTF (fits below: SciPy's special
# functions, only when targets are fitted)
SCANNING_MODULES = (*SCAN_TASK_MODULES, "imgmtf.scene.targetfit", "imgmtf.scene.sections", "imgmtf.estimate.mtf2d",
                    *CLI_MODULES)
# (not SciPy's optimizer, 0.15-0.2 s more, the solver's fallback: a worker loads it if it falls back)
FITTING_MODULES = ("imgmtf.estimate.fit", "scipy.special")
# with several scenes each worker runs whole scans, the segment graph included
WHOLE_SCAN_MODULES = ("imgmtf.scene.series", "imgmtf.scene.measure", "imgmtf.scene.combine")
# a batch of files measured (imgmtf measure): the estimators and the files' reading and records
MEASURING_MODULES = ("imgmtf.batch", "imgmtf.estimate.edge", "imgmtf.estimate.pulse", *NUMPY_LAZY, *CLI_MODULES)

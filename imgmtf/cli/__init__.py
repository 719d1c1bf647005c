"""Command-line interface: a thin shell over the public API, one module per
command (rasterio's ``rio`` layout), the group and its registrations in
:mod:`imgmtf.cli.main`.

Exit codes: 0 success; 1 a problem with the input (one line on stderr, or
an error record per file: ``error`` and ``reason`` in JSON and CSV); 2 a
usage error (a bad option); 130 interrupted by Ctrl-C and 143 by SIGTERM
(what was measured is kept: CSV rows are written as each file completes).

Start-up stays cheap: this module imports only click; each command imports
the libraries it needs when it runs, so ``imgmtf --help`` loads no
numerical library.  Set ``IMGMTF_DEBUG=1`` to see the traceback of an
internal error instead of its one-line report.
"""
from .main import main

__all__ = ["main"]

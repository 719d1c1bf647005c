"""How the CLI reports: a malformed option (out of range, or contradicting
another) as exit 2, a deliberate imgmtf error as one line and exit 1,
an interrupt as exit 130 or 143, an internal error as one line (its
traceback with ``IMGMTF_DEBUG=1``); the hint it adds to a refusal."""
from __future__ import annotations

import os
import sys
from contextlib import contextmanager

import click

from ..errors import ImgmtfError


@contextmanager
def reported_errors():
    """Turn a deliberate imgmtf error into one line on stderr and exit 1; an
    interrupt into one line and exit 130 (Ctrl-C) or 143 (SIGTERM); any
    other exception into a one-line internal error and exit 1 (its
    traceback with IMGMTF_DEBUG=1)."""
    try:
        yield
    except ImgmtfError as exc:
        click.echo(f"imgmtf: error: {one_line(exc)}{refusal_hint(exc.reason, str(exc))}", err=True)
        sys.exit(1)
    except KeyboardInterrupt as exc:
        click.echo("imgmtf: interrupted", err=True)
        sys.exit(interrupt_code(exc))
    except (BrokenPipeError, click.ClickException):
        raise                     # click exits quietly when stdout's reader has gone (| head), or with 2
    except Exception as exc:
        if os.environ.get("IMGMTF_DEBUG"):
            raise
        click.echo(f"imgmtf: internal error: {type(exc).__name__}: {one_line(exc)} "
                   "(please report it; IMGMTF_DEBUG=1 shows where)", err=True)
        sys.exit(1)


@contextmanager
def option_errors():
    """A ParameterError raised while the options alone are turned into
    settings (before any input is read) as click's usage error: exit status 2,
    as for a value outside the range --help prints or options that
    contradict each other; a problem found in an input stays exit 1."""
    from ..errors import ParameterError
    try:
        yield
    except ParameterError as exc:
        raise click.UsageError(one_line(exc)) from None


# refusals a scan of the whole file resolves: it finds each edge and bar
# and measures them one by one, away from fill and from each other
SCAN_SOLVES = frozenset({"fill", "two-targets"})
# the option that answers a refusal, by its reason code: the library's message
# says what is wrong with the data, the command line what to do about it
OPTION_HINTS = {"two-targets": "--roi X,Y,W,H crops it to one target", "not-an-edge": "--target pulse measures a bar",
                "not-a-bar": "--target edge measures an edge", "too-large": "--roi X,Y,W,H measures a window",
                "bands": "--band N chooses one, --band all measures each", "bar-width": "--pulse-width gives it",
                "fit": "--stages fits fewer, --hold holds some", "no-signal": "--signal-std gives it"}


def refusal_hint(reason, message: str = "", path: str | None = None) -> str:
    """What the CLI adds to a refusal: the option that answers its reason,
    ``imgmtf scan`` where the chip holds fill, several edges or a
    checkerboard's corner, and the flag that overrules the gate."""
    from ..estimate.gate import FORCIBLE
    hints = [OPTION_HINTS[reason]] if reason in OPTION_HINTS else []
    if reason in SCAN_SOLVES or (reason == "not-straight" and "meet inside the chip" in message):
        hints.append(f"imgmtf scan {path or 'FILE'} finds and measures each edge in it")
    if reason in FORCIBLE:
        hints.append("--force measures it anyway")
    return f" ({'; '.join(hints)})" if hints else ""


def one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def interrupt_code(exc: BaseException) -> int:
    return getattr(exc, "exit_code", 130)


@contextmanager
def closing(generator):
    """Close a task generator when its loop ends, however: an interrupt
    then stops the workers at once rather than when they are collected."""
    try:
        yield generator
    finally:
        close = getattr(generator, "close", None)
        if close:
            close()


def signal_name(exc: BaseException) -> str:
    return str(exc) if getattr(exc, "signum", None) else "SIGINT"

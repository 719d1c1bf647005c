"""How the CLI reports: a malformed option (out of range, or contradicting
another) as exit 2, a deliberate imgmtf error as one line and exit 1,
an interrupt as exit 130 or 143, an internal error as one line (its
traceback with ``IMGMTF_DEBUG=1``), a refusal with the hint
:mod:`imgmtf.cli.hints` gives."""
from __future__ import annotations

import os
import sys
from contextlib import contextmanager

import click

from ..errors import ImgmtfError
from .hints import refusal_hint


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

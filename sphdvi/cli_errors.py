"""How every ``sphdvi`` command reports failures: a message on stderr and an exit code, no traceback."""
from __future__ import annotations

import contextlib
import functools
import os
import signal
import sys

import click


class Interrupted(BaseException):
    """SIGTERM or SIGHUP during a command without its own clean stop (gencase, measure, export),
    raised where the command is, as SIGINT raises KeyboardInterrupt."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _raise_interrupted(signum, frame):
    raise Interrupted(signum)


@contextlib.contextmanager
def _signals_interrupt():
    """SIGTERM and SIGHUP (unless ignored, as under nohup) raise :class:`Interrupted` for the
    command's life; the handlers before are put back after.  ``sphdvi run`` installs its own
    clean stop inside (a run ends at the next step, resumable)."""
    old = {}
    for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None)):
        if sig is None or signal.getsignal(sig) == signal.SIG_IGN:
            continue
        try:
            old[sig] = signal.signal(sig, _raise_interrupted)
        except ValueError:          # not in the main thread
            pass
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)


def report_errors(fn):
    """Turn sphdvi's own errors into ``error: ...`` on stderr and their exit code
    (2 bad input, 3 diverged, 1 other); click's usage errors pass through; any
    other exception is an internal error (traceback with SPHDVI_DEBUG=1).  An interrupted
    command (SIGINT, SIGTERM, SIGHUP) prints ``interrupted by SIG...`` and exits 1, as an
    interrupted ``sphdvi run`` (README: "1 runtime failure or interruption"; a shell's 130/143
    would be one more code for sweeps to tell apart); files are written atomically, so
    none is left half-written."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        from .errors import EXIT_FAILURE, SphdviError
        try:
            with _signals_interrupt():
                return fn(*args, **kwargs)
        except click.ClickException:
            raise
        except SphdviError as exc:
            click.echo(f"error: {exc}", err=True)
            sys.exit(exc.exit_code)
        except (KeyboardInterrupt, Interrupted) as exc:
            signum = getattr(exc, "signum", signal.SIGINT)
            click.echo(f"interrupted by {signal.Signals(signum).name}", err=True)
            sys.exit(EXIT_FAILURE)
        except MemoryError:
            click.echo("error: out of memory (the case is too large for this machine)", err=True)
            sys.exit(1)
        except OSError as exc:
            if exc.filename:
                click.echo(f"error: {exc.strerror or exc}: {exc.filename}", err=True)
            else:
                click.echo(f"error: {exc}", err=True)
            sys.exit(1)
        except Exception as exc:  # an internal error: short message, full trace on demand
            if os.environ.get("SPHDVI_DEBUG"):
                raise
            click.echo(f"internal error: {type(exc).__name__}: {exc} "
                       "(set SPHDVI_DEBUG=1 to see the traceback, and please report it)", err=True)
            sys.exit(1)
    return wrapper


class FiniteFloat(click.ParamType):
    """An option's number: finite (no nan, inf) and at least ``min`` (above it when
    ``min_open``); anything else is a usage error (exit 2) naming the option."""

    name = "float"

    def __init__(self, min: float | None = None, min_open: bool = False):
        self.min, self.min_open = min, min_open

    def expected(self) -> str:
        if self.min is None:
            return "a finite number"
        return f"a finite number {'>' if self.min_open else '>='} {self.min:g}"

    def convert(self, value, param, ctx):
        import math
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number; expected {self.expected()}", param, ctx)
        if not math.isfinite(number) or (self.min is not None and (
                number <= self.min if self.min_open else number < self.min)):
            self.fail(f"{value!r}: expected {self.expected()}", param, ctx)
        return number

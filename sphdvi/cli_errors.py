"""How every ``sphdvi`` command reports failures: a message on stderr and an exit code, no traceback."""
from __future__ import annotations

import functools
import os
import sys

import click


def report_errors(fn):
    """Turn sphdvi's own errors into ``error: ...`` on stderr and their exit code
    (2 bad input, 3 diverged, 1 other); click's usage errors pass through; any
    other exception is an internal error (traceback with SPHDVI_DEBUG=1)."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        from .errors import SphdviError
        try:
            return fn(*args, **kwargs)
        except click.ClickException:
            raise
        except SphdviError as exc:
            click.echo(f"error: {exc}", err=True)
            sys.exit(exc.exit_code)
        except KeyboardInterrupt:
            click.echo("interrupted", err=True)
            sys.exit(130)
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

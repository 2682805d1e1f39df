"""The ``sphdvi`` command line: a thin click layer over the library.

Nothing heavy is imported at start-up (``sphdvi --help`` must not import numba);
each command imports what it needs. User errors print ``file:line: element:
message`` and exit 2 without a traceback; a diverged run exits 3.
"""
from __future__ import annotations

import functools
import os
import sys

import click

from ._version import __version__

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


def report_errors(fn):
    """Turn sphdvi's own errors into a message on stderr and their exit code."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        from .errors import SphdviError
        try:
            return fn(*args, **kwargs)
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
            click.echo(f"error: {exc.strerror or exc}: {exc.filename or ''}", err=True)
            sys.exit(1)
        except Exception as exc:  # an internal error: short message, full trace on demand
            if os.environ.get("SPHDVI_DEBUG"):
                raise
            click.echo(f"internal error: {type(exc).__name__}: {exc} "
                       "(set SPHDVI_DEBUG=1 to see the traceback, and please report it)", err=True)
            sys.exit(1)
    return wrapper


def print_warnings(warnings) -> None:
    for w in warnings:
        click.echo(w, err=True)


@click.group(context_settings=CONTEXT)
@click.version_option(__version__, "--version", prog_name="sphdvi")
def main():
    """sphdvi: DualSPHysics-style SPH coupled to a Chrono-style DVI multibody solver.

    \b
    Typical use:
      sphdvi gencase cases/dambreak2d/CaseDambreakVal2D_Def.xml -o out/dambreak2d
      sphdvi run out/dambreak2d --tmax 0.5
      sphdvi measure points out/dambreak2d --points "0.5,0,0.1" --vars vel,press
    """


@main.command(context_settings=CONTEXT)
@click.argument("case_xml", type=click.Path(dir_okay=False))
@click.option("-o", "--out", "outdir", type=click.Path(file_okay=False), default=None,
              help="Output folder (default: ./<casename>_out).")
@click.option("--max-nodes", type=click.IntRange(min=1), default=200_000_000, show_default=True,
              help="Refuse drawing domains with more lattice nodes than this.")
@click.option("-q", "--quiet", is_flag=True, help="Print only warnings and errors.")
@report_errors
def gencase(case_xml, outdir, max_nodes, quiet):
    """Turn a DualSPHysics case file into particles, like GenCase.

    Writes OUT/<casename>.h5 (particles, constants, parameters, bodies, links,
    motions, materials, gauges and the source XML) and OUT/<casename>_All.vtp
    (for ParaView), and prints a GenCase-like summary.
    """
    from .case.gencase import build_case, summary, write_outputs
    from .case.reader import case_name_from_path
    from .errors import CaseError
    if not os.path.isfile(case_xml):
        raise CaseError("case file not found", file=case_xml, expected="an existing XML case file")
    if outdir is None:
        outdir = f"{case_name_from_path(case_xml)}_out"
    result = build_case(case_xml, outdir, max_nodes=max_nodes)
    files = write_outputs(result, outdir)
    print_warnings(result.warnings)
    if not quiet:
        click.echo(summary(result))
        click.echo("Files: " + ", ".join(files))


if __name__ == "__main__":  # pragma: no cover
    main()

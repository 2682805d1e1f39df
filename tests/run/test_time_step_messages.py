"""How a run ends and what it says about its time step, as DualSPHysics: MinFluidStop a normal end,
"N DTs adjusted to DtMin" warnings, a density window that excludes the initial fluid (hunt6/c
findings 4, 8, 10)."""
import json
import warnings

import pytest
from click.testing import CliRunner

from pathlib import Path

from sphdvi.cli import main
from sphdvi.simulation import min_fluid

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def drawn(tmp_path_factory):
    """The dam break at dp 0.04 (1,250 fluid particles), drawn once."""
    tmp = tmp_path_factory.mktemp("db")
    case = tmp / "CaseDB_Def.xml"
    case.write_text(DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"'))
    r = invoke(["gencase", case, "-o", tmp / "g"])
    assert r.exit_code == 0, r.output
    return tmp / "g"


def run(drawn, out, *sets, tmax="0.05", quiet=True):
    args = ["run", drawn, "-o", out, "--tmax", tmax, "--tout", "0.01", "--threads", "1"]
    args += ["-q"] if quiet else []
    for s in sets:
        args += ["--set", s]
    return invoke(args)


def test_min_fluid_threshold_as_dualsphysics():
    """NpfMinimum = unsigned(MinFluidStop*CaseNfluid), a float product: 1125 of 1250 for 0.9 (sphdvi's
    int((1 - 0.9)*1250) = 124 excluded stopped one particle early)."""
    assert min_fluid({"MinFluidStop": 0.9}, 1250) == 1125
    assert min_fluid({"MinFluidStop": 0.0}, 1250) == 0 and min_fluid({}, 1250) == 0
    assert min_fluid({"MinFluidStop": 0.5}, 7) == 3


def test_min_fluid_stop_is_a_normal_end(drawn, tmp_path):
    """JSphCpuSingle::Run: fewer fluid particles than NpfMinimum -> warning "The minimum number of
    fluid particles (N) was reached.", the data of that instant saved, TimeMax = TimeStep, a normal
    end.  sphdvi ended "diverged", exit 3, without that output."""
    out = tmp_path / "o"
    with pytest.warns(UserWarning, match="fluid particles were excluded"):
        # the surface's densities fall below 999.7 as the column collapses (an initial density
        # outside the window is an input error)
        r = run(drawn, out, "RhopOutMin=999.7", "MinFluidStop=0.9")
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "completed"
    assert meta["message"].startswith("The minimum number of fluid particles (1125) was reached")
    rows = (out / "run.csv").read_text().splitlines()[1:]
    last = rows[-1].split(",")
    assert float(last[1]) == pytest.approx(meta["physical_time"], rel=1e-9) and meta["physical_time"] < 0.01
    assert int(last[3]) < 251 + 1125
    log = (out / "run.log").read_text()
    assert "WARNING: The minimum number of fluid particles (1125) was reached" in log
    from sphdvi.io.vtkhdf import step_times
    assert step_times(str(out / "particles.vtkhdf"))[-1] == pytest.approx(meta["physical_time"], rel=1e-9)


def test_dtmin_adjustments_are_warned_and_named(drawn, tmp_path):
    """JSphCpu::DtVariable: "N DTs adjusted to DtMin (t:..., nstep:...)" at 1, 10, 100, ... (run.log,
    stderr unless -q); a run that then diverges names DtMin as the cause."""
    out = tmp_path / "o"
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        r = run(drawn, out, "DtMin=2e-4", tmax="0.1", quiet=False)
    assert r.exit_code == 3, r.output
    said = [str(w.message) for w in rec if "DTs adjusted" in str(w.message)]
    assert [s.split(" DTs")[0] for s in said] == ["1", "10", "100"]
    assert said[0].startswith("1 DTs adjusted to DtMin (t:0, nstep:0)")
    log = (out / "run.log").read_text()
    for n in (1, 10, 100):
        assert f"WARNING: {n} DTs adjusted to DtMin (t:" in log
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "diverged" and "DtMin (0.0002 s)" in meta["message"]
    # quiet: run.log only
    out2 = tmp_path / "q"
    with warnings.catch_warnings(record=True) as rec2:
        warnings.simplefilter("always")
        run(drawn, out2, "DtMin=2e-4", tmax="0.003")
    assert not [w for w in rec2 if "DTs adjusted" in str(w.message)]
    assert "WARNING: 10 DTs adjusted to DtMin" in (out2 / "run.log").read_text()


def test_a_density_window_that_excludes_the_initial_fluid(drawn, tmp_path):
    """RhopOutMin above part of the still water's hydrostatic density: an input error (exit 2) before
    any step, with the count, the densities' span and the window, as DualSPHysics's
    JSph::CheckRhoLimits ("Initial fluid density is out of limits ... modify the value of 'RhopOutMin'
    and 'RhopOutMax'"); sphdvi warned, ran, and excluded them in its first steps."""
    out = tmp_path / "o"
    r = run(drawn, out, "RhopOutMin=1001.5")
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert ("750 of 1250 fluid particles start with a density outside RhopOutMin/RhopOutMax [1001.5, 1300] "
            "(the initial fluid densities span [1000, 1002.48] kg/m3)") in text
    assert "Initial fluid density is out of limits" in text and "RhopOutMin and RhopOutMax" in text
    assert "Traceback" not in r.output and not (out / "particles.vtkhdf").exists()


def test_a_startup_warning_of_the_solver_heads_run_log(drawn, tmp_path):
    """A warning of the run's start-up (here the solver's DtFixed below DtMin) is in run.log too, at its
    head (it went to stderr only)."""
    out = tmp_path / "o"
    with pytest.warns(UserWarning, match=r"DtFixed \(1e-05 s\) is below DtMin"):
        r = run(drawn, out, "DtFixed=1e-5", tmax="0.0002")
    assert r.exit_code == 0, r.output
    first = (out / "run.log").read_text().splitlines()[0]
    assert first.startswith("WARNING: DtFixed (1e-05 s) is below DtMin")


def test_startup_warnings_are_logged_once_and_again_on_resume(drawn, tmp_path):
    """A --set warning of the start-up heads run.log; a resume keeps it and logs its own start-up's."""
    out = tmp_path / "o"
    said = "WARNING: --set FtSaveAce: parameter 'FtSaveAce' has no effect in sphdvi"
    with pytest.warns(UserWarning, match="FtSaveAce"):
        r = run(drawn, out, "FtSaveAce=1", tmax="0.02")
    assert r.exit_code == 0, r.output
    log = (out / "run.log").read_text().splitlines()
    assert log[0].startswith(said) and sum(x.startswith(said) for x in log) == 1
    with pytest.warns(UserWarning, match="FtSaveAce"):
        r = invoke(["run", out, "--resume", "--tmax", "0.04", "-q"])
    assert r.exit_code == 0, r.output
    log = (out / "run.log").read_text().splitlines()
    assert log[0].startswith(said) and sum(x.startswith(said) for x in log) == 2
    resumed = next(i for i, x in enumerate(log) if x.startswith("resumed from part"))
    assert log[resumed - 1].startswith(said)


def test_movement_is_a_reason_of_excluded_csv(drawn, tmp_path):
    """A DtFixed far above the CFL one throws particles more than MovLimit in a step: excluded.csv says
    "movement" (DualSPHysics's CODE_OUTMOV)."""
    out = tmp_path / "o"
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        r = run(drawn, out, "DtFixed=2e-3", tmax="0.02")
    assert r.exit_code in (0, 3)
    assert any("excluded" in str(w.message) for w in rec)
    rows = (out / "excluded.csv").read_text().splitlines()
    assert any(row.endswith(",movement") for row in rows[1:])
    assert "movement" in json.loads((out / "run.json").read_text())["excluded"]

"""sphdvi run: outputs, resume (bitwise on 1 thread), divergence, body-only runs."""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import warnings

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
from sphdvi.cli import main
from sphdvi.simulation import POINT_ARRAYS

DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def small_case(tmp_path, dp="0.04", extra_params=""):
    text = DAMBREAK.read_text().replace('dp="0.01"', f'dp="{dp}"')
    if extra_params:
        text = text.replace("<parameters>", "<parameters>" + extra_params)
    path = tmp_path / "CaseDB_Def.xml"
    path.write_text(text)
    return path


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_gencase_error(case, outdir, message):
    """gencase of ``case`` fails with exit code 2 and a message naming the case file and line, without a
    traceback."""
    r = invoke(["gencase", case, "-o", outdir])
    assert r.exit_code == 2, r.output
    assert message in r.output and f"{os.path.basename(str(case))}:" in r.output and "Traceback" not in r.output


def final_state(outdir):
    with h5py.File(os.path.join(outdir, "restart.h5"), "r") as f:
        idp = f["state/idp"][...]
        o = np.argsort(idp)
        return {k: f["state"][k][...][o] for k in ("pos", "vel", "rhop")}, dict(f["scalars"].attrs)


def test_run_outputs(tmp_path):
    case = small_case(tmp_path)
    out = tmp_path / "out"
    r = invoke(["run", case, "-o", out, "--tmax", "0.02", "--tout", "0.005", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "completed" and meta["steps"] > 0 and meta["physical_time"] >= 0.02
    assert meta["threads"] == 1 and meta["runtime_s"] > 0 and meta["startup_s"] > 0
    assert meta["parameters"]["TimeMax"] == 0.02
    rows = (out / "run.csv").read_text().splitlines()
    assert rows[0] == "part,time,steps,particles,excluded,dtmin,dtmax,walltime" and len(rows) == 1 + 5
    assert len((out / "run.log").read_text().splitlines()) >= 5
    from sphdvi.io.vtkhdf import read_step, step_times
    times = step_times(str(out / "particles.vtkhdf"))
    assert len(times) == 5 and times[0] == 0.0
    s = read_step(str(out / "particles.vtkhdf"), -1)
    assert set(s) >= {"Idp", "Vel", "Rhop", "Press", "Type", "Mk"}
    assert set(np.unique(s["Type"])) == {0, 3}
    vtk = pytest.importorskip("vtkmodules.vtkIOHDF")
    reader = vtk.vtkHDFReader()
    reader.SetFileName(str(out / "particles.vtkhdf"))
    reader.UpdateInformation()
    assert reader.GetNumberOfSteps() == 5
    r = invoke(["export", out])
    assert r.exit_code == 0 and (out / "vtp" / "particles.pvd").is_file()
    assert len(list((out / "vtp").glob("Part_*.vtp"))) == 5
    # the file is about its data: 5 steps of 1,501 particles, 53 bytes each (0.4 MB), take under
    # 1 MB (14.3 MB for one step before, the chunks of 2^16 rows of every per-step array)
    data = 5 * 1501 * sum(np.dtype(d).itemsize * n for d, n in POINT_ARRAYS.values()) + 5 * 1501 * 24
    assert (out / "particles.vtkhdf").stat().st_size < max(1 << 20, 2 * data)


def test_run_restores_the_callers_thread_count(tmp_path):
    """An in-process run sets numba's thread count for itself and puts the
    caller's back (a test session would otherwise run on --threads 1 after it)."""
    import numba
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread")
    previous = numba.get_num_threads()
    numba.set_num_threads(2)
    try:
        r = invoke(["run", small_case(tmp_path), "-o", tmp_path / "out", "--tmax", "0.004", "--tout", "0.002",
                    "--threads", "1", "-q"])
        assert r.exit_code == 0, r.output
        assert json.loads((tmp_path / "out" / "run.json").read_text())["threads"] == 1
        assert numba.get_num_threads() == 2
        # --threads 2: threaded from 1,500 particles; a smaller scene runs serially, and says so
        (tmp_path / "small").mkdir()
        for source, out, used in ((tmp_path / "out", tmp_path / "big", 2),
                                  (small_case(tmp_path / "small", dp="0.08"), tmp_path / "small_out", 1)):
            r = invoke(["run", source, "-o", out, "--tmax", "0.002", "--tout", "0.002", "--threads", "2", "-q"])
            assert r.exit_code == 0, r.output
            meta = json.loads((out / "run.json").read_text())
            assert meta["threads"] == 2 and meta["threads_used"] == used, (meta["particles"], meta["threads_used"])
    finally:
        numba.set_num_threads(previous)


def test_set_overrides_and_bad_set(tmp_path):
    case = small_case(tmp_path)
    r = invoke(["run", case, "-o", tmp_path / "o", "--tmax", "0.002", "--set", "Visco=0.05",
                "--set", "StepAlgorithm=2", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    meta = json.loads((tmp_path / "o" / "run.json").read_text())
    assert meta["parameters"]["Visco"] == 0.05 and meta["parameters"]["StepAlgorithm"] == 2
    r = invoke(["run", tmp_path / "o", "--set", "Visc=1"])
    assert r.exit_code == 2 and "did you mean 'Visco'" in r.output
    r = invoke(["run", tmp_path / "o", "--set", "Kernel=7"])
    assert r.exit_code == 2


@pytest.mark.parametrize("algo", [1, 2])
def test_resume_is_bitwise(tmp_path, algo):
    """Stop at an output, resume, and end in the bitwise same state as an uninterrupted run."""
    case = small_case(tmp_path)
    common = ["--tout", "0.004", "--threads", "1", "-q", "--set", f"StepAlgorithm={algo}"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.012"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.008"] + common).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.012"] + common)
    assert r.exit_code == 0, r.output
    sa, ka = final_state(a)
    sb, kb = final_state(b)
    assert ka["nstep"] == kb["nstep"] and ka["time"] == kb["time"]
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k
    assert (a / "run.csv").read_text().count("\n") == (b / "run.csv").read_text().count("\n")


def test_sigkill_then_resume(tmp_path):
    """A run killed with SIGKILL resumes from its last output, bitwise equal on 1 thread."""
    case = small_case(tmp_path)
    args = ["--tmax", "0.03", "--tout", "0.003", "--threads", "1", "-q"]
    full = tmp_path / "full"
    assert invoke(["run", case, "-o", full] + args).exit_code == 0
    killed = tmp_path / "killed"
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    proc = subprocess.Popen([sys.executable, "-m", "sphdvi", "run", str(case), "-o", str(killed)] + args, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    csv = killed / "run.csv"
    deadline = time.time() + 120
    while time.time() < deadline:
        if csv.exists() and csv.read_text().count("\n") >= 4:
            break
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    killed_early = proc.poll() is None
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert killed_early, "the run finished before it could be killed"
    meta = json.loads((killed / "run.json").read_text())
    assert meta["status"] == "running"
    for name in ("run.csv", "run.log"):          # as if killed in the middle of an append
        with open(killed / name, "a") as fh:
            fh.write("99,0.0")
    r = invoke(["run", killed, "--resume"] + args)
    assert r.exit_code == 0, r.output
    s1, k1 = final_state(full)
    s2, k2 = final_state(killed)
    assert k1["nstep"] == k2["nstep"]
    for k in s1:
        assert np.array_equal(s1[k], s2[k]), k
    from sphdvi.io.vtkhdf import step_times
    assert np.array_equal(step_times(str(full / "particles.vtkhdf")), step_times(str(killed / "particles.vtkhdf")))
    # run.csv: the same rows as the uninterrupted run (but the wall time), the torn line cut
    rows = [[r.rsplit(",", 1)[0] for r in (d / "run.csv").read_text().splitlines()] for d in (full, killed)]
    assert rows[0] == rows[1]
    assert "99,0.0" not in (killed / "run.log").read_text()


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP"])
def test_sigterm_stops_cleanly(tmp_path, sig):
    """SIGTERM, and SIGHUP (a closed terminal: exit 129 and run.json left 'running' before), end
    the run as interrupted, resumable."""
    if sig == "SIGHUP" and signal.getsignal(signal.SIGHUP) == signal.SIG_IGN:
        pytest.skip("SIGHUP is ignored here (run under nohup): the run keeps it ignored, as it should")
    case = small_case(tmp_path)
    out = tmp_path / "o"
    proc = subprocess.Popen([sys.executable, "-m", "sphdvi", "run", str(case), "-o", str(out), "--tmax", "5",
                             "--tout", "0.002", "--threads", "1", "-q"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while time.time() < deadline and not ((out / "run.csv").exists()
                                          and (out / "run.csv").read_text().count("\n") >= 3):
        time.sleep(0.05)
    proc.send_signal(getattr(signal, sig))
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1 and "Traceback" not in err
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "interrupted" and "--resume" in meta["message"]


def test_an_ignored_sighup_stays_ignored():
    """Under nohup SIGHUP is ignored: the run's signal handling keeps it so."""
    from sphdvi.simulation import _Stop
    old = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with _Stop():
            assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
            assert signal.getsignal(signal.SIGTERM) not in (signal.SIG_IGN, signal.SIG_DFL)
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
        with _Stop():
            assert signal.getsignal(signal.SIGHUP) not in (signal.SIG_IGN, signal.SIG_DFL)
    finally:
        signal.signal(signal.SIGHUP, old)


def test_a_full_disk_stops_the_run_cleanly_and_it_resumes(tmp_path, monkeypatch):
    """Before each output the run checks that its device holds it (a write failing inside HDF5
    crashed the interpreter at exit, exit 139, run.json left 'running'): with too little space
    it stops with exit 1 and a message saying so and how to go on, run.json 'failed', the outputs
    before intact; once there is room, --resume ends bitwise as an uninterrupted run."""
    import os as _os
    from collections import namedtuple
    case = small_case(tmp_path)
    opts = ["--tmax", "0.02", "--tout", "0.005", "--threads", "1", "-q"]
    ref, out = tmp_path / "ref", tmp_path / "out"
    assert invoke(["run", case, "-o", ref] + opts).exit_code == 0
    real, calls = _os.statvfs, []
    Vfs = namedtuple("Vfs", "f_bavail f_frsize")

    def statvfs(path):                     # room for three outputs
        calls.append(path)
        return Vfs(10 if len(calls) > 3 else real(path).f_bavail, 4096)
    monkeypatch.setattr(_os, "statvfs", statvfs)
    r = invoke(["run", case, "-o", out] + opts)
    assert r.exit_code == 1, r.output
    assert "too little space left on the device" in r.output and "outputs up to part 2 are intact" in r.output
    assert f"'sphdvi run {out} --resume'" in r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "failed" and meta["message"].startswith("too little space")
    assert len((out / "run.csv").read_text().splitlines()) == 1 + 3
    monkeypatch.setattr(_os, "statvfs", real)
    assert invoke(["run", out, "--resume", "--threads", "1", "-q"]).exit_code == 0
    from sphdvi.io.vtkhdf import read_step
    a, b = read_step(str(ref / "particles.vtkhdf"), -1), read_step(str(out / "particles.vtkhdf"), -1)
    assert all(np.array_equal(a[k], b[k]) for k in a)


def test_divergence_exit_3(tmp_path):
    """A time step far above the CFL limit blows up: exit 3 naming time, step, particle and cause."""
    case = small_case(tmp_path)
    out = tmp_path / "o"
    proc = subprocess.run([sys.executable, "-m", "sphdvi", "run", str(case), "-o", str(out), "--tmax", "0.5",
                           "--tout", "0.01", "--threads", "1", "-q", "--set", "DtFixed=0.004"],
                          capture_output=True, text=True)
    assert proc.returncode == 3, proc.stderr
    assert "Traceback" not in proc.stderr
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "diverged"
    assert "t=" in meta["message"] and "step" in meta["message"] and "particle" in meta["message"]
    from sphdvi.io.vtkhdf import step_times
    assert len(step_times(str(out / "particles.vtkhdf"))) >= 1


def test_resume_bitwise_with_floating_body(tmp_path):
    """SPH + a floating body (multibody engine): a resumed run ends bitwise equal, bodies.csv included."""
    case = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"
    common = ["--dp", "0.02", "--tout", "0.01", "--threads", "1", "-q", "--set", "FtPause=0"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.04"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.04", "--tout", "0.01", "--threads", "1", "-q",
                "--set", "FtPause=0"])
    assert r.exit_code == 0, r.output
    sa, _ = final_state(a)
    sb, _ = final_state(b)
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k
    assert (a / "bodies.csv").read_text() == (b / "bodies.csv").read_text()
    rows = (a / "bodies.csv").read_text().splitlines()
    assert len(rows) == 1 + 5 and float(rows[-1].split(",")[4]) != float(rows[1].split(",")[4])


def resumed_equals_uninterrupted(case, tmp_path, common) -> Path:
    """Run ``case`` to 0.04 s, and to 0.02 s then --resume to 0.04 s (``common``: the options,
    --dp first); assert the two end in the bitwise same particle state and bodies.csv; return the
    uninterrupted run's folder."""
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.04"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.04"] + common[2:])
    assert r.exit_code == 0, r.output
    sa, _ = final_state(a)
    sb, _ = final_state(b)
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k
    assert (a / "bodies.csv").read_text() == (b / "bodies.csv").read_text()
    return a


@pytest.mark.parametrize("slip", [1, 2])
def test_resume_bitwise_with_mdbc_on_a_floating_body(tmp_path, slip):
    """mDBC on the S12 box (normals, extrapolated densities, the wall acceleration of SlipMode 2,
    the body's state): a resumed run ends bitwise equal to an uninterrupted one (DualSPHysics
    users report that an mDBC restart needs data its restart files do not keep)."""
    case = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"
    common = ["--dp", "0.02", "--tout", "0.01", "--threads", "1", "-q", "--set", "FtPause=0",
              "--set", "Boundary=2", "--set", "MdbcMkbound=5", "--set", f"SlipMode={slip}"]
    a = resumed_equals_uninterrupted(case, tmp_path, common)
    with h5py.File(a / "restart.h5") as f:
        ptype, rhop = f["state/ptype"][...], f["state/rhop"][...]
    assert rhop[ptype == 2].max() > 1000.2            # the box's particles carry mDBC densities


def test_resume_bitwise_with_the_cases_own_normals(tmp_path):
    """The same with the box's normals from its outline (norgeometry; case.h5 /normals; the file named
    with [CASENAME], matched in any case): a resumed run ends bitwise equal to an uninterrupted one."""
    case = _floating_box_with_normals(
        tmp_path, '<norgeometry><geometryfile file="[CASENAME]_hdp_Actual.vtk"/><distanceh v="2.0"/></norgeometry>')
    case.write_text(case.read_text().replace("<mainlist>", normals_geometry(BOX_OUTLINE), 1))
    common = ["--dp", "0.02", "--tout", "0.01", "--threads", "1", "-q", "--set", "FtPause=0", "--set", "Boundary=2"]
    a = resumed_equals_uninterrupted(case, tmp_path, common)
    with h5py.File(a / "restart.h5") as f:
        normals, ptype = f["aux/normals"][...], f["state/ptype"][...]
    assert np.all(normals[ptype == 0] == 0) and np.any(normals[ptype == 2] != 0)   # the box only


@pytest.mark.parametrize("slip", [1, 2, 3])
def test_mdbc_from_case(tmp_path, slip):
    """Boundary=2 (mDBC) with each SlipMode: normals are computed from the particles; with
    three wall layers the dam break runs without losing particles through the walls."""
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"').replace(
        "<boxfill>bottom | left | right | front | back</boxfill>",
        '<boxfill>bottom | left | right | front | back</boxfill><layers vdp="0,1,2" />')
    case = tmp_path / "CaseMdbc_Def.xml"
    case.write_text(text)
    out = tmp_path / "o"
    r = invoke(["run", case, "-o", out, "--tmax", "0.5", "--tout", "0.1", "--threads", "1", "-q",
                "--set", "Boundary=2", "--set", f"SlipMode={slip}"])
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "completed" and sum(meta["excluded"].values()) == 0
    with h5py.File(out / "restart.h5") as f:
        normals = f["aux/normals"][...]
        ptype = f["state/ptype"][...]
    lengths = np.linalg.norm(normals[ptype == 0], axis=1)
    layered = np.isin(np.round(lengths / 0.04, 6), (0.5, 1.5, 2.5))
    assert layered.mean() > 0.9 and np.isclose(lengths.min(), 0.02)   # walls; corners and tops differ


def test_mdbc_on_the_floating_box_only(tmp_path):
    """``--set MdbcMkbound=5`` with Boundary=2: the S12 box (mkbound 5) gets mDBC normals and
    its particles the extrapolated density, the tank's single-layer walls (mkbound 0) none,
    so they stay DBC; a bad list is an input error (exit 2), an absent mkbound a warning."""
    case = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"
    out = tmp_path / "o"
    with pytest.warns(UserWarning, match="MdbcMkbound '5,7': no boundary particles of mkbound 7"):
        r = invoke(["run", case, "-o", out, "--tmax", "0.02", "--tout", "0.01", "--threads", "1", "-q",
                    "--set", "Boundary=2", "--set", "MdbcMkbound=5,7"])
    assert r.exit_code == 0, r.output
    with h5py.File(out / "restart.h5") as f:
        normals = f["aux/normals"][...]
        ptype = f["state/ptype"][...]
        rhop = f["state/rhop"][...]
    lengths = np.linalg.norm(normals, axis=1)
    assert np.all(lengths[ptype == 0] == 0) and np.all(lengths[ptype == 1] == 0)
    assert np.all(lengths[ptype == 2] > 0)
    # the box's wet particles: the water's pressure extrapolated, not DBC's rho0 start
    assert rhop[ptype == 2].max() > 1000.5
    # the fluid sees the box's particles with the lattice's mass rho0 dp^2, not the body's share
    # (rhopbody 500: half of it); `sphdvi measure` takes the same masses
    with h5py.File(out / "restart.h5") as f:
        mass = f["state/mass"][...]
        idp = f["state/idp"][...]
    assert np.allclose(mass[ptype == 2], 1000 * 0.01 ** 2)
    from sphdvi.measure.post import RunOutput
    assert np.allclose(RunOutput(str(out)).mass_by_idp[idp[ptype == 2]], 1000 * 0.01 ** 2)
    bad = invoke(["run", case, "-o", tmp_path / "b", "--tmax", "0.01", "-q",
                  "--set", "Boundary=2", "--set", "MdbcMkbound=five"])
    assert bad.exit_code == 2 and "MdbcMkbound 'five'" in bad.output and "Traceback" not in bad.output


def _floating_box_with_normals(tmp_path, normals: str):
    tmp_path.mkdir(exist_ok=True)
    case = tmp_path / "CaseBoxNormals_Def.xml"
    text = (REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml").read_text()
    assert text.count("</casedef>") == 1
    case.write_text(text.replace("</casedef>", f"<normals>{normals}</normals></casedef>"))
    return case


TANK_OUTLINE = """<setmkbound mk="0"/><setnormalinvert invert="true"/>
<drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0"/><size x="1" y="2" z="0.6"/>
<layers vdp="-0.5"/></drawbox>"""
BOX_OUTLINE = """<setmkbound mk="5"/><setnormalinvert invert="false"/>
<drawbox><boxfill>all</boxfill><point x="0.4" y="-1" z="0.25"/><size x="0.2" y="2" z="0.1"/>
<layers vdp="0.5"/></drawbox>"""


def normals_geometry(*outlines):
    """A GeometryForNormals list of the given outlines (shapes only), run first in <mainlist>."""
    return ('<list name="GeometryForNormals"><setactive drawpoints="0" drawshapes="1"/>'
            '<setshapemode>actual | bound</setshapemode>' + "".join(outlines)
            + '<shapeout file="hdp"/><resetdraw/></list><mainlist><runlist name="GeometryForNormals"/>')


NORMALS_GEOMETRY = normals_geometry(TANK_OUTLINE, BOX_OUTLINE)


@pytest.mark.parametrize("vdp, count", [("-0.5", 60 + 52), ("0", 0)])
def test_normals_surface_behind_or_through_the_face_layer_is_warned(tmp_path, vdp, count):
    """The box's normals outline drawn dp/2 inside it (<layers vdp="-0.5">), behind its face
    layer: the face layer's normals point back into the box and the next ring's ghost nodes
    fall on it; the run names the mkbound and both rings (60 + 52 particles of the 21 x 11
    box), and does not take the box for a thin wall. The outline on the face layer itself
    (vdp 0, DesignSPHysics's mdbc_dist_vdp 0): gencase names the 60 particles it passes
    through, which get no normal (they keep DBC)."""
    case = _floating_box_with_normals(
        tmp_path, '<norgeometry><geometryfile file="[CaseName]_hdp_Actual.vtk"/><distanceh v="2.0"/></norgeometry>')
    outline = BOX_OUTLINE.replace('<layers vdp="0.5"/>', f'<layers vdp="{vdp}"/>')
    assert outline != BOX_OUTLINE
    case.write_text(case.read_text().replace("<mainlist>", normals_geometry(TANK_OUTLINE, outline), 1))
    out = tmp_path / "out"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", case, "-o", out, "--tmax", "0.001", "--threads", "1", "-q", "--set", "Boundary=2"])
    assert r.exit_code == 0, r.output
    said = [str(w.message) for w in caught]
    inward = [m for m in said if "ghost node" in m]
    through = [m for m in r.output.splitlines() if "passes through" in m]     # gencase's, on stderr
    if count:
        assert len(inward) == 1 and inward[0].startswith(f"mDBC on mkbound 5: {count} of its particles")
        assert "dp/2 = 0.005 m in front of it" in inward[0] and not through
    else:
        assert not inward and len(through) == 1 and "(mkbound 5: 60)" in through[0]
        with h5py.File(out / "CaseBoxNormals.h5") as f:
            normals, ptype, pos = f["normals"][...], f["particles/type"][...], f["particles/pos"][...]
        x, z = pos[:, 0], pos[:, 2]
        box = ptype == 2
        face = box & (np.isclose(x, 0.4) | np.isclose(x, 0.6) | np.isclose(z, 0.25) | np.isclose(z, 0.35))
        assert face.sum() == 60 and np.all(normals[face] == 0.0)
        ring = box & ~face & (np.isclose(x, 0.41) | np.isclose(x, 0.59) | np.isclose(z, 0.26) | np.isclose(z, 0.34))
        assert ring.sum() == 52 and np.allclose(np.abs(normals[ring]).max(axis=1), 0.01)
    assert not any("mkbound 5" in m and "thick" in m for m in said)


def test_case_normals_from_geometry_reach_the_run(tmp_path):
    """DualSPHysics's mDBC set-up: the walls and the S12 box drawn dp/2 in front of their particles
    (GeometryForNormals), ``<normals><norgeometry>`` over that shape file. gencase stores the
    vectors to those outlines (case.h5 /normals, Normal in _All.vtp): dp/2 up from the floor, dp/2
    down from the box's bottom row, none deeper in the box than distanceh h; the run starts from
    them (restart.h5 aux/normals after 0.01 s); the fluid takes the corrected floating particles'
    mass as rho0 dp^2, the others' (DBC) as their share of the body's, and so does measure."""
    case = _floating_box_with_normals(
        tmp_path, '<norgeometry><geometryfile file="[CaseName]_hdp_Actual.vtk"/><distanceh v="2.0"/></norgeometry>')
    text = case.read_text().replace("<mainlist>", NORMALS_GEOMETRY, 1)
    case.write_text(text)
    out = tmp_path / "out"
    with pytest.warns(UserWarning, match="mDBC on mkbound 0: a wall one particle thick"):   # the S12 tank's
        r = invoke(["run", case, "-o", out, "--tmax", "0.01", "--tout", "0.01", "--threads", "1", "-q",
                    "--set", "Boundary=2"])
    assert r.exit_code == 0, r.output
    with h5py.File(out / "CaseBoxNormals.h5") as f:
        normals = f["normals"][...]
        pos, ptype = f["particles/pos"][...], f["particles/type"][...]
        h = f["constants"].attrs["h"]
    dp = 0.01
    floor = (ptype == 0) & np.isclose(pos[:, 2], 0) & (pos[:, 0] > 0.05) & (pos[:, 0] < 0.95)
    assert floor.sum() > 80 and np.allclose(normals[floor], [0, 0, dp / 2])
    box = ptype == 2
    bottom = box & np.isclose(pos[:, 2], 0.25) & (pos[:, 0] > 0.42) & (pos[:, 0] < 0.58)
    assert bottom.sum() > 10 and np.allclose(normals[bottom], [0, 0, -dp / 2])
    depth = np.minimum.reduce([pos[:, 0] - 0.395, 0.605 - pos[:, 0], pos[:, 2] - 0.245, 0.355 - pos[:, 2]])
    assert np.all(np.linalg.norm(normals[box], axis=1)[depth[box] > 2 * h + 1e-9] == 0)
    assert np.allclose(np.linalg.norm(normals[box], axis=1)[depth[box] <= 2 * h - 1e-9],
                       depth[box][depth[box] <= 2 * h - 1e-9])
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(out / "CaseBoxNormals_All.vtp"))
    reader.Update()
    shown = vtk_to_numpy(reader.GetOutput().GetPointData().GetArray("Normal"))
    assert np.allclose(shown, normals, atol=1e-7)
    reader = vtk.vtkXMLPolyDataReader()                     # the glyph file: particles with a normal
    reader.SetFileName(str(out / "CaseBoxNormals_Normals.vtp"))
    reader.Update()
    data = reader.GetOutput().GetPointData()
    has = np.linalg.norm(normals, axis=1) > 0
    assert reader.GetOutput().GetNumberOfPoints() == has.sum()
    size = vtk_to_numpy(data.GetArray("NormalSize"))
    assert np.allclose(size, np.linalg.norm(normals[has], axis=1), rtol=1e-6)
    assert np.allclose(vtk_to_numpy(data.GetArray("Normal")) * size[:, None], normals[has], atol=1e-7)
    with h5py.File(out / "restart.h5") as f:
        run_normals, idp, mass = f["aux/normals"][...], f["state/idp"][...], f["state/mass"][...]
        run_type = f["state/ptype"][...]
    assert np.allclose(run_normals, normals[idp], atol=1e-6)
    corrected = (run_type == 2) & np.any(run_normals != 0, axis=1)
    assert corrected.any() and np.allclose(mass[corrected], 1000 * dp ** 2)
    inner = (run_type == 2) & ~corrected            # out of the outline's reach: DBC, the body's share
    assert inner.any() and np.allclose(mass[inner], 500 * dp ** 2)
    from sphdvi.measure.post import RunOutput
    assert np.array_equal(RunOutput(str(out)).mass_by_idp[idp], mass)   # measure takes the run's masses


def test_initialize_boundnormals_and_fluidvelocity(tmp_path):
    """The solver's ``<special><initialize>``: boundnormal_plane over the floor (auto point: limitdist
    1 dp above it), boundnormal_set on the box, applied after ``<normals>`` (an earlier norset of the
    floor is overridden); fluidvelocity sets a linear profile, extrapolated above its top
    height as DualSPHysics does."""
    case = _floating_box_with_normals(tmp_path, '<norset mkbound="0"><normal x="1" y="0" z="0"/></norset>')
    init = ('<initialize><boundnormal_plane mkbound="0"><point auto="true"/><normal x="0" y="0" z="1"/>'
            '<limitdist vdp="1"/><onlypos><posmax z="0.001"/></onlypos></boundnormal_plane>'
            '<boundnormal_set mkbound="5"><normal x="0" y="0" z="-0.005"/></boundnormal_set>'
            '<fluidvelocity mkfluid="0"><direction x="1" y="0" z="0"/><velocity2 v="0" v2="0.1" z="0" z2="0.1"/>'
            '</fluidvelocity></initialize>')
    text = case.read_text()
    assert "<special>" not in text
    case.write_text(text.replace("<execution>", f"<execution><special>{init}</special>", 1))
    out = tmp_path / "out"
    r = invoke(["gencase", case, "-o", out])
    assert r.exit_code == 0, r.output
    with h5py.File(out / "CaseBoxNormals.h5") as f:
        normals, pos, ptype = f["normals"][...], f["particles/pos"][...], f["particles/type"][...]
        vel = f["particles/vel"][...]
    nb = int(np.count_nonzero(ptype != 3))
    assert f"mDBC normals (the case's): {nb} of {nb} boundary particles (mkbound 0, 5)" in r.output
    floor = (ptype == 0) & np.isclose(pos[:, 2], 0)
    side = (ptype == 0) & (pos[:, 2] > 0.001)
    assert np.allclose(normals[floor], [0, 0, 0.01]) and np.allclose(normals[side], [1, 0, 0])
    assert np.allclose(normals[ptype == 2], [0, 0, -0.005])
    fluid = ptype == 3
    assert np.allclose(vel[fluid, 0], pos[fluid, 2]) and np.all(vel[fluid, 1:] == 0)
    assert vel[fluid, 0].max() > 0.25          # z up to 0.3: beyond z2, extrapolated


def test_case_normals_from_a_mesh_file(tmp_path):
    """norgeometry over an STL file beside the case (no mk per triangle: every particle sees all of
    it) gives the box the same normals as the same outline drawn with <shapeout>; the tank, out of
    its reach, gets none."""
    lo, hi = np.array([0.395, -1, 0.245]), np.array([0.605, 1, 0.355])
    corners = np.array([[lo[0] if i & 1 == 0 else hi[0], lo[1] if i & 2 == 0 else hi[1],
                         lo[2] if i & 4 == 0 else hi[2]] for i in range(8)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    facets = "".join(f"facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {' '.join(repr(float(v)) for v in corners[k])}\n"
                                                                     for k in tri) + "endloop\nendfacet\n"
                     for q in quads for tri in ((q[0], q[1], q[2]), (q[0], q[2], q[3])))
    (tmp_path / "BoxOutline.stl").write_text("solid box\n" + facets + "endsolid box\n")
    results = {}
    for name, normals, lists in (("stl", '<norgeometry><geometryfile file="BoxOutline.stl"/></norgeometry>', None),
                                 ("shape", '<norgeometry><geometryfile file="[CaseName]_hdp_Actual.vtk"/></norgeometry>',
                                  normals_geometry(BOX_OUTLINE))):
        case = _floating_box_with_normals(tmp_path / name, normals)
        if lists:
            case.write_text(case.read_text().replace("<mainlist>", lists, 1))
        shutil.copy(tmp_path / "BoxOutline.stl", tmp_path / name)
        r = invoke(["gencase", case, "-o", tmp_path / name / "o"])
        assert r.exit_code == 0, r.output
        with h5py.File(tmp_path / name / "o" / "CaseBoxNormals.h5") as f:
            results[name] = (f["normals"][...], f["particles/type"][...], f["particles/pos"][...])
    (stl, ptype, pos), (shape, _, _) = results["stl"], results["shape"]
    assert np.any(stl[ptype == 2] != 0) and np.all(stl[ptype == 0] == 0)
    # vtk reads STL in single precision; a particle as far from two faces picks either
    assert np.allclose(np.linalg.norm(stl, axis=1), np.linalg.norm(shape, axis=1), atol=1e-7)
    same = np.all(np.abs(stl - shape) <= 1e-7, axis=1)
    foot = pos[~same] + stl[~same]
    on_face = np.isclose(foot[:, [0, 0, 2, 2]], [0.395, 0.605, 0.245, 0.355], atol=1e-7).any(axis=1)
    assert same.mean() > 0.9 and np.all(on_face)


@pytest.mark.parametrize("normals,fragment", [
    ('<norplane><point x="0" y="0" z="0"/><normal x="0" y="0" z="1"/></norplane>', "missing attribute 'mkbound'"),
    ('<norplane mkbound="five"><point x="0" y="0" z="0"/><normal x="0" y="0" z="1"/></norplane>', "mkbound='five'"),
    ('<norsphere><center x="0" y="0" z="0"/><radius v="-1"/><inside v="true"/></norsphere>', "is not positive"),
    ('<norplane mkbound="0"><point x="0" y="0" z="0"/><normal x="0" y="0" z="0"/></norplane>', "zero vector"),
    ('<norgeometry><geometryfile file="[CaseName]_nothere_Actual.vtk"/></norgeometry>', "no <shapeout file=\"nothere\">"),
    ('<norset mkbound="0"><normal x="0" y="0" z="1"/><clear v="true"/></norset>', "unknown element <clear>"),
    ('<norgeometry><geometryfile file="../outside.stl"/></norgeometry>', "lies outside the case folder"),
    ('<norgeometry><geometryfile file="notamesh.stl"/></norgeometry>', "geometryfile 'notamesh.stl'"),
    ('<norcylinder><center1 x="0" y="0" z="0"/><center2 x="0" y="0" z="0"/><radius v="1"/><inside v="true"/>'
     '</norcylinder>', "center2 is center1"),
])
def test_case_normals_errors_name_the_line(tmp_path, normals, fragment):
    case = _floating_box_with_normals(tmp_path, normals)
    (tmp_path / "notamesh.stl").write_text("this is not an STL file\n")
    r = invoke(["gencase", case, "-o", tmp_path / "o"])
    lines = case.read_text().splitlines()
    line = lines.index(next(x for x in lines if "<normals>" in x)) + 1
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert f"{case.name}:{line}:" in r.output and fragment in r.output, r.output


def test_case_normals_that_reach_nothing(tmp_path):
    """Normals that reach no boundary particle: gencase warns (and of an operation that selects
    none), a run with mDBC stops with exit 2 saying so, a DBC run is unaffected."""
    case = _floating_box_with_normals(
        tmp_path, '<norplane mkbound="5"><point x="0" y="0" z="0"/><normal x="0" y="0" z="1"/></norplane>'
                  '<norset mkbound="7"><normal x="0" y="0" z="1"/></norset>')
    r = invoke(["gencase", case, "-o", tmp_path / "o"])
    assert r.exit_code == 0
    assert "<norset> selects no boundary particle (mkbound '7')" in r.output
    assert "the case's normals reach no boundary particle" in r.output
    r = invoke(["run", tmp_path / "o", "--tmax", "0.002", "-q", "--threads", "1", "--set", "Boundary=2"])
    assert r.exit_code == 2 and "reach no boundary particle" in r.output and "Traceback" not in r.output
    r = invoke(["run", tmp_path / "o", "--tmax", "0.002", "-q", "--threads", "1"])
    assert r.exit_code == 0, r.output


def test_mdbc_run_writes_its_normals(tmp_path):
    """A run with mDBC writes normals.vtp at its start: the boundary particles with a normal, its
    direction and length (as restart.h5 holds them); a DBC run writes none; --overwrite removes it."""
    case = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
    args = ["--dp", "0.1", "--tmax", "0.002", "-q", "--threads", "1"]
    out = tmp_path / "o"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")             # one wall layer: warned, tested below
        assert invoke(["run", case, "-o", out, *args, "--set", "Boundary=2"]).exit_code == 0
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(out / "normals.vtp"))
    reader.Update()
    data = reader.GetOutput().GetPointData()
    with h5py.File(out / "restart.h5") as f:
        normals, ptype = f["aux/normals"][...], f["state/ptype"][...]
    has = (ptype != 3) & np.any(normals != 0, axis=1)
    assert reader.GetOutput().GetNumberOfPoints() == has.sum() > 0
    size = vtk_to_numpy(data.GetArray("NormalSize"))
    assert np.allclose(np.sort(size), np.sort(np.linalg.norm(normals[has], axis=1)), rtol=1e-6)
    assert np.allclose(np.linalg.norm(vtk_to_numpy(data.GetArray("Normal")), axis=1), 1, atol=1e-6)
    assert invoke(["run", case, "-o", out, *args, "--overwrite"]).exit_code == 0
    assert not (out / "normals.vtp").exists()


def test_mdbc_on_one_layer_walls_is_warned(tmp_path):
    """mDBC on a wall one particle thick leaks (README): the run warns, naming the mkbound and the
    layers to draw; with three layers it does not."""
    case = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
    args = ["--dp", "0.1", "--tmax", "0.002", "-q", "--threads", "1", "--set", "Boundary=2"]
    with pytest.warns(UserWarning, match=r'mDBC on mkbound 0: a wall one particle thick.*<layers vdp="0,1">'):
        r = invoke(["run", case, "-o", tmp_path / "one", *args])
    assert r.exit_code == 0
    thick = tmp_path / "CaseThick_Def.xml"
    text = case.read_text()
    wall = '<size x="4" y="2" z="3" />'
    assert text.count(wall) == 1
    thick.write_text(text.replace(wall, wall + '<layers vdp="0,1,2" />'))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", thick, "-o", tmp_path / "three", *args])
    assert r.exit_code == 0 and not any("particle thick" in str(w.message) or "particles thick" in str(w.message)
                                        for w in caught)
    # a wall thicker than one layer but thinner than the kernel's reach (2 layers where it reaches 3)
    from sphdvi.run_checks import warn_thin_mdbc_walls
    with pytest.warns(UserWarning, match=r"mDBC on mkbound 4: the wall is 2 particles thick behind 120 of its face "
                                         r'particles, where the kernel reaches 3 layers.*<layers vdp="0,1,2">'):
        warn_thin_mdbc_walls({4: (2, 120)}, 3, 3 ** 0.5)


def test_undamped_mdbc_mode_is_warned():
    """mDBC SlipMode 1 with DensityDT 2 where most of the fluid is within 2h of mDBC walls (a 3D
    tank 10 dp across grew an acoustic mode across it to wall forces of the water's weight) is
    warned about, naming the share and the remedies; DensityDT 3, SlipMode 2, or a wide tank not."""
    from sphdvi.run_checks import warn_undamped_mdbc
    from sphdvi.sph.cells import share_within
    dp, h = 0.02, 0.02 * 2 ** 0.5
    xs = (np.arange(10) + 0.5) * dp
    fluid = np.array([[x, 0.0, z] for x in xs for z in xs])              # 10 x 10, in 2D
    walls = np.array([[x, 0.0, -0.5 * dp - k * dp] for x in xs for k in range(3)] +
                     [[-0.5 * dp - k * dp, 0.0, z] for z in xs for k in range(3)] +
                     [[10 * dp + 0.5 * dp + k * dp, 0.0, z] for z in xs for k in range(3)])
    p = {"pos": np.r_[walls, fluid], "type": np.r_[np.zeros(len(walls), int), np.full(len(fluid), 3)]}
    normals = np.r_[np.full((len(walls), 3), 0.01), np.zeros((len(fluid), 3))]
    c = {"h": h, "is2d": True}
    # within 2h = 2.83 dp of a wall particle: the two rows over the floor and the two columns by
    # each side wall (their nearest wall particles dp and 2 dp away); 8 x 6 of the 100 are not
    assert share_within(fluid, walls, 2 * h, True) == pytest.approx(0.52)
    for params, warned in (({"SlipMode": 1, "DensityDT": 2}, True), ({"SlipMode": 1, "DensityDT": 3}, False),
                           ({"SlipMode": 2, "DensityDT": 2}, False)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            warn_undamped_mdbc(params, p, normals, c)
        msgs = [str(w.message) for w in caught]
        assert bool(msgs) == warned, msgs
        if warned:
            assert "52 % of the fluid lies within 2h of mDBC walls" in msgs[0] and "DensityDT 3" in msgs[0]
    with warnings.catch_warnings(record=True) as caught:     # DBC walls (no normal): not counted
        warnings.simplefilter("always")
        warn_undamped_mdbc({"SlipMode": 1, "DensityDT": 2}, p, np.zeros_like(normals), c)
    assert not caught


def test_mdbc_floating_mask():
    """The floating particles mDBC corrects, whose mass the fluid takes as rho0 dp^d: Boundary 2
    with any SlipMode, of the MdbcMkbound list when there is one."""
    from sphdvi.case.normals import mdbc_floating_mask
    ptype = np.array([0, 2, 2, 3])
    mkbound = np.array([0, 5, 7, 0])
    assert not mdbc_floating_mask(ptype, mkbound, {}).any()
    assert mdbc_floating_mask(ptype, mkbound, {"Boundary": 2, "SlipMode": 2}).tolist() == [False, True, True, False]
    assert mdbc_floating_mask(ptype, mkbound, {"Boundary": "2"}).tolist() == [False, True, True, False]
    assert mdbc_floating_mask(ptype, mkbound, {"Boundary": 2, "MdbcMkbound": "7"}).tolist() == [False, False, True, False]


def test_dtfixedfile_from_case(tmp_path):
    """DtFixedFile: a (time [s], dt [ms]) file next to the case sets every dt; a
    missing or malformed file is a case error (exit 2) naming the file."""
    (tmp_path / "dt.csv").write_text("# time;dt\n0;0.1\n0.01;0.2\n")
    case = small_case(tmp_path, extra_params='<parameter key="DtFixedFile" value="dt.csv" />')
    out = tmp_path / "o"
    r = invoke(["run", case, "-o", out, "--tmax", "0.02", "--tout", "0.01", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    rows = [l.split(",") for l in (out / "run.csv").read_text().splitlines()[1:]]
    head = "part,time,steps,particles,excluded,dtmin,dtmax,walltime".split(",")
    last = dict(zip(head, rows[-1]))
    assert float(last["dtmin"]) == pytest.approx(2e-4) and float(last["dtmax"]) == pytest.approx(2e-4)
    first = dict(zip(head, rows[1]))
    assert 1e-4 <= float(first["dtmin"]) < float(first["dtmax"]) <= 2e-4
    meta = json.loads((out / "run.json").read_text())
    assert "dtfixedfile_max_excess_s" in meta
    (tmp_path / "dt.csv").write_text("0;0.1\n")
    r = invoke(["gencase", case, "-o", tmp_path / "g"])
    assert r.exit_code == 2 and "DtFixedFile" in r.output and "two" in r.output
    assert "Traceback" not in r.output
    case2 = small_case(tmp_path, extra_params='<parameter key="DtFixedFile" value="nofile.csv" />')
    r = invoke(["gencase", case2, "-o", tmp_path / "g2"])
    assert r.exit_code == 2 and "nofile.csv" in r.output


def test_viscotime_from_case(tmp_path):
    """ViscoTime: a (time [s], Visco) file next to the case; a run with a constant table
    ends bitwise as one with that Visco; a malformed file is a case error naming it."""
    (tmp_path / "visco.txt").write_text("time visco\n0 0.05\n1 0.05\n")
    case = small_case(tmp_path, extra_params='<parameter key="ViscoTime" value="visco.txt" />')
    text = case.read_text().replace('<parameter key="Visco" value="0.02" />', '<parameter key="Visco" value="0.05" />')
    text = text.replace('<parameter key="ViscoTime" value="visco.txt" />', "")
    assert 'value="0.05"' in text
    ref = tmp_path / "Ref_Def.xml"
    ref.write_text(text)
    common = ["--tmax", "0.01", "--tout", "0.01", "--threads", "1", "-q"]
    assert invoke(["run", case, "-o", tmp_path / "a"] + common).exit_code == 0
    assert invoke(["run", ref, "-o", tmp_path / "b"] + common).exit_code == 0
    sa, _ = final_state(tmp_path / "a")
    sb, _ = final_state(tmp_path / "b")
    assert all(np.array_equal(sa[k], sb[k]) for k in sa)
    (tmp_path / "visco.txt").write_text("0 0.05\n0.5 x\n")
    r = invoke(["gencase", case, "-o", tmp_path / "g"])
    assert r.exit_code == 2 and "ViscoTime" in r.output and "visco.txt" in r.output and "line 2" in r.output


def test_set_viscotime_file_is_kept_absolute_for_resume(tmp_path, monkeypatch):
    """``--set ViscoTime=FILE``: FILE relative to the current directory (as any path on the
    command line), stored absolute in run.json, so that ``--resume`` from another directory
    finds it (run.json kept 'visco.txt', and the resume failed to read it)."""
    data, elsewhere = tmp_path / "data", tmp_path / "elsewhere"
    data.mkdir()
    elsewhere.mkdir()
    (data / "visco.txt").write_text("0 0.05\n1 0.03\n")
    case = small_case(tmp_path)
    out = tmp_path / "b"
    common = ["--tout", "0.004", "--threads", "1", "-q"]
    monkeypatch.chdir(data)
    r = invoke(["run", case, "-o", out, "--tmax", "0.004", "--set", "ViscoTime=visco.txt"] + common)
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["overrides"]["set"] == [f"ViscoTime={data / 'visco.txt'}"]
    assert meta["parameters"]["ViscoTime"] == str(data / "visco.txt")
    monkeypatch.chdir(elsewhere)
    r = invoke(["run", out, "--resume", "--tmax", "0.008"] + common)
    assert r.exit_code == 0, r.output
    assert json.loads((out / "run.json").read_text())["status"] == "completed"
    # the same --set given again on resume, from elsewhere, names another file: refused as a change
    (elsewhere / "visco.txt").write_text("0 0.05\n1 0.03\n")
    r = invoke(["run", out, "--resume", "--tmax", "0.012", "--set", "ViscoTime=visco.txt"] + common)
    assert r.exit_code == 2 and "ViscoTime" in r.output and str(elsewhere / "visco.txt") in r.output, r.output


def test_exclusion_warnings_as_dualsphysics(tmp_path):
    """WrnPartsOut: a warning (terminal and run.log) when the particles excluded since the
    previous output reach 1 % of the fluid, then 2, 5, 10, 20 ... %, and when all excluded
    reach 10, 20 ... % of the particles; WrnPartsOut=0 silences them."""
    from sphdvi.simulation import ExclusionWarnings
    w = ExclusionWarnings(True, 1000, 1200)
    assert w.check(9, 1000, 9, 0.1, 10) == []
    assert [x.split(" of")[0] for x in w.check(10, 990, 19, 0.2, 20)] == ["more than 1%"]
    assert w.check(10, 980, 29, 0.3, 30) == []                     # the next level is 2 %
    lines = w.check(100, 880, 129, 0.4, 40)                         # 10 % of the fluid, 10.75 % of all
    assert [x.split(" of")[0] for x in lines] == ["more than 2%", "more than 10%"]
    assert "particles were excluded (t=0.4 s, step 40)" in lines[1]
    assert ExclusionWarnings(False, 1000, 1200).check(500, 500, 500, 0.1, 1) == []
    # from a run: densities above RhopOutMax exclude some of the column's deepest particles (the
    # initial densities reach 1002.48: a window that excludes them is an input error)
    case = small_case(tmp_path)
    for flag, expect in (("1", True), ("0", False)):
        out = tmp_path / f"o{flag}"
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = invoke(["run", case, "-o", out, "--tmax", "0.04", "--tout", "0.02", "--threads", "1", "-q",
                        "--set", "RhopOutMax=1002.6", "--set", f"WrnPartsOut={flag}"])
        assert r.exit_code == 0, r.output
        log = (out / "run.log").read_text()
        assert ("WARNING: more than 1% of the fluid particles were excluded" in log) == expect
        assert any("more than 1%" in str(c.message) for c in caught) == expect
    # the levels warned about travel in restart.h5, so that a resumed run does not warn again
    # at a level it has passed (they started again at 1 % and 10 % before)
    out = tmp_path / "levels"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", case, "-o", out, "--tmax", "0.02", "--tout", "0.01", "--threads", "1", "-q",
                    "--set", "RhopOutMin=999.7"])
    assert r.exit_code == 0, r.output
    assert any("more than 10% of the particles were excluded" in str(w.message) for w in caught)
    with h5py.File(out / "restart.h5", "r") as f:
        levels = int(f["scalars"].attrs["excl_part_pct"]), int(f["scalars"].attrs["excl_total_pct"])
    # 229 of 1,501 particles excluded by 0.01 s (1 % and 10 % warned), 369 by 0.02 s (2 % and 20 %)
    assert levels == (5, 30)
    with h5py.File(out / "restart.h5", "r+") as f:        # as if the next levels had been passed
        f["scalars"].attrs["excl_part_pct"], f["scalars"].attrs["excl_total_pct"] = 200, 200
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert invoke(["run", out, "--resume", "--tmax", "0.03", "--threads", "1", "-q"]).exit_code == 0
    assert not [w for w in caught if "were excluded" in str(w.message)]
    with h5py.File(out / "restart.h5", "r") as f:
        assert int(f["scalars"].attrs["excl_part_pct"]) == 200


def test_excluded_particles_file_and_resume(tmp_path):
    """excluded.csv (DualSPHysics's PartOut): a row per excluded fluid particle, its time, id,
    position, velocity, density and reason, as many as run.json counts, none of them left in
    the run; a run stopped at an output and resumed writes the same file, bitwise; a run that
    excludes nothing writes none."""
    case = small_case(tmp_path)
    common = ["--tout", "0.01", "--threads", "1", "-q", "--set", "RhopOutMax=1002.6"]
    a, b, c = tmp_path / "a", tmp_path / "b", tmp_path / "c"
    with pytest.warns(UserWarning, match="fluid particles were excluded since the previous output"):
        assert invoke(["run", case, "-o", a, "--tmax", "0.04"] + common).exit_code == 0
        assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    with open(b / "excluded.csv", "a") as fh:          # a row after the restart output, as a killed run leaves
        fh.write("0.03,1,0,0,0,0,0,0,1003,rhop\n")
    assert invoke(["run", b, "--resume", "--tmax", "0.04"] + common).exit_code == 0
    text = (a / "excluded.csv").read_text()
    assert text == (b / "excluded.csv").read_text()
    lines = text.splitlines()
    assert lines[0] == "time,idp,x,y,z,vx,vy,vz,rhop,reason"
    rows = [line.split(",") for line in lines[1:]]
    meta = json.loads((a / "run.json").read_text())
    assert len(rows) == meta["excluded"]["rhop"] == sum(meta["excluded"].values()) > 10
    assert {r[-1] for r in rows} == {"rhop"}
    assert all(float(r[8]) > 1002.3 for r in rows)                # the density that excluded it
    assert all(0 < float(r[0]) <= meta["physical_time"] for r in rows)
    assert all(float(r[4]) < 0.3 for r in rows)                   # the foot of the 2 m column
    ids = [int(r[1]) for r in rows]
    with h5py.File(a / "restart.h5", "r") as f:
        left = set(f["state/idp"][...].tolist())
    assert len(set(ids)) == len(ids) and not set(ids) & left and len(left) == meta["particles"] - len(ids)
    assert invoke(["run", case, "-o", c, "--tmax", "0.01", "--tout", "0.01", "--threads", "1", "-q"]).exit_code == 0
    assert not (c / "excluded.csv").exists()


def test_timeoutextra_floating_rows_between_outputs_and_resume(tmp_path):
    """TimeOutExtra: bodies.csv gets a row per body at every multiple of TimeOutExtra
    between the TimeOut outputs (the first step at or after it); a killed-and-resumed run
    writes the same file."""
    case = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"
    common = ["--dp", "0.02", "--tout", "0.02", "--threads", "1", "-q", "--set", "FtPause=0",
              "--set", "TimeOutExtra=0.005"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.04"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.04"] + common[2:])
    assert r.exit_code == 0, r.output
    rows = (a / "bodies.csv").read_text().splitlines()
    nbody = sum(1 for x in rows[1:] if float(x.split(",")[0]) == 0.0)
    times = np.unique([float(x.split(",")[0]) for x in rows[1:]])
    assert len(rows) == 1 + nbody * 9 and times.size == 9          # t = 0, 0.005, ..., 0.04
    assert np.all(times - np.arange(9) * 0.005 >= -1e-12) and np.all(times - np.arange(9) * 0.005 < 2e-4)
    assert (a / "bodies.csv").read_text() == (b / "bodies.csv").read_text()


@pytest.mark.parametrize("quiet", [False, True])
def test_a_slow_start_says_that_it_compiles(tmp_path, monkeypatch, quiet):
    """A first run with a case's options compiles its kernels before any output (10-30 s): past
    COMPILE_NOTICE_AFTER_S a line says so and another when they are ready; ``-q`` says nothing.
    Here the threshold is 0 and the warm-up made 0.3 s slower, so the notice must come."""
    import sphdvi.simulation as simulation
    warm_up = simulation._warm_up

    def slow_warm_up(sph):
        time.sleep(0.3)
        return warm_up(sph)

    monkeypatch.setattr(simulation, "COMPILE_NOTICE_AFTER_S", 0.0)
    monkeypatch.setattr(simulation, "_warm_up", slow_warm_up)
    args = ["run", small_case(tmp_path), "-o", tmp_path / "out", "--tmax", "0.01", "--threads", "1"]
    r = invoke(args + (["-q"] if quiet else []))
    assert r.exit_code == 0, r.output
    said = "compiling the kernels for this case's options" in r.stderr
    ready = re.search(r"kernels ready after (\d+\.\d) s", r.stderr)
    if quiet:
        assert not said and ready is None and r.stderr == ""
    else:
        assert said and ready is not None and float(ready.group(1)) >= 0.3
        # the notice comes before the first progress line
        assert r.stderr.index("kernels ready") < r.stderr.index("progress:")


def test_warm_up_steps_a_copy_of_the_coupled_run(tmp_path, monkeypatch):
    """The start-up's two warm-up steps run on a copy of the whole run, whose end-of-step hook
    steps the copy's floating bodies (so that the multibody kernels compile before the loop's
    clock): the copy's bodies take exactly those two steps, the run's own take every step of the
    run from t = 0, and the run's state is that of a run without the warm-up."""
    import sphdvi.coupling as coupling
    import sphdvi.simulation as simulation
    calls = []
    step = coupling.FloatingBodies.step

    def spy(self, solver, dt):
        calls.append((id(self), float(solver.time)))
        return step(self, solver, dt)

    monkeypatch.setattr(coupling.FloatingBodies, "step", spy)
    case = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"
    common = ["--dp", "0.02", "--tmax", "0.01", "--tout", "0.01", "--threads", "1", "-q", "--set", "FtPause=0"]
    assert invoke(["run", case, "-o", tmp_path / "a"] + common).exit_code == 0
    owners = list(dict.fromkeys(i for i, _ in calls))
    assert len(owners) == 2
    copy_calls = [t for i, t in calls if i == owners[0]]
    run_calls = [t for i, t in calls if i == owners[1]]
    assert len(copy_calls) == 2 and len(run_calls) > 2 and run_calls[0] == copy_calls[0]
    state = final_state(tmp_path / "a")[0]
    monkeypatch.setattr(simulation, "_warm_up", lambda sph: 0.0)
    assert invoke(["run", case, "-o", tmp_path / "b"] + common).exit_code == 0
    for k, v in final_state(tmp_path / "b")[0].items():
        assert np.array_equal(state[k], v), k
    assert (tmp_path / "a" / "bodies.csv").read_text() == (tmp_path / "b" / "bodies.csv").read_text()

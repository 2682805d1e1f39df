"""sphdvi run / export on bad input: option values, --set checks shared with the case reader,
checkpoints of another case, corrupt HDF5 files, DtFixed against the run, --threads, --dp.
Each ends with exit code 2 (or 3 for a run that blows up) and a message naming what is wrong,
without a traceback.  Tiny cases (dp 0.1, a few steps)."""
import json
import warnings
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.errors import InputError

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
PENDULUM = REPO / "cases" / "pendulum" / "CasePendulum_Def.xml"
CASE_H5 = "CaseDambreakVal2D.h5"


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_input_error(r, *fragments):
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and "internal error" not in r.output, r.output
    for text in fragments:
        assert text in r.output, (text, r.output)


def case_xml(tmp_path, params="", name="CaseDambreakVal2D_Def.xml"):
    text = DAMBREAK.read_text()
    if params:
        text = text.replace("<parameters>", "<parameters>" + params)
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def done(tmp_path_factory):
    """A finished tiny run (dp 0.1, outputs at 0, 0.002, 0.004); tests copy it."""
    base = tmp_path_factory.mktemp("done")
    out = base / "out"
    r = invoke(["run", case_xml(base), "-o", out, "--dp", "0.1", "--tmax", "0.004", "--tout", "0.002",
                "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    return out


def copy_run(src, dest):
    import shutil
    shutil.copytree(src, dest)
    return dest


def redraw_case_in(out, tmp_path, dp):
    """Replace the case files of a run folder by the case drawn at another dp, as a user
    copying files around would (gencase itself refuses a folder holding a run's results)."""
    import shutil
    fresh = tmp_path / f"redrawn_{dp}"
    assert invoke(["gencase", case_xml(tmp_path), "-o", fresh, "--dp", str(dp), "-q"]).exit_code == 0
    for f in fresh.iterdir():
        shutil.copy(f, out / f.name)


# -- option values ---------------------------------------------------------------------
@pytest.mark.parametrize("option,value", [("--tmax", "-1"), ("--tmax", "nan"), ("--tmax", "inf"),
                                          ("--tout", "-1"), ("--tout", "nan"), ("--tout", "0"),
                                          ("--dp", "-0.1"), ("--dp", "nan")])
def test_bad_time_options_are_usage_errors(tmp_path, option, value):
    r = invoke(["run", tmp_path, option, value])
    assert_input_error(r, f"Invalid value for '{option}'", "expected a finite number")


def test_timeout_zero_is_a_case_error_at_gencase(tmp_path):
    r = invoke(["gencase", case_xml(tmp_path, '<parameter key="TimeOut" value="0" />'), "-o", tmp_path / "g",
                "--dp", "0.1"])
    assert_input_error(r, "CaseDambreakVal2D_Def.xml:", "parameter TimeOut: 0.0 is not > 0")


# -- --set: the reader's checks and warnings ---------------------------------------------
def test_set_applies_the_cross_parameter_checks(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    r = invoke(["run", out, "--set", "RhopOutMin=1400", "--tmax", "0.002"])
    assert_input_error(r, "RhopOutMin (1400.0) >= RhopOutMax (1300.0)")
    r = invoke(["run", out, "--set", "RhopOutMax=600", "--tmax", "0.002"])
    assert_input_error(r, "RhopOutMin (700.0) >= RhopOutMax (600.0)")


def test_set_warnings_as_the_case_reader():
    from sphdvi.run_options import apply_overrides
    base = {"TimeOut": 0.1, "DensityDT": 0}
    for item, text in (("DeltaSPH=0.05", "'DeltaSPH' is deprecated"),
                       ("FtSaveAce=1", "'FtSaveAce' has no effect"),
                       ("SavePosDouble=2", "'SavePosDouble' has no effect"),
                       ("BoundaryMethod=2", "DualSPHysics reads 'Boundary'")):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            apply_overrides(base, [item])
        assert any(text in str(w.message) for w in caught), (item, [str(w.message) for w in caught])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        apply_overrides(base, ["FtSaveAce=0", "Visco=0.05"])
    assert not caught


def test_set_of_a_constant_and_of_dem():
    from sphdvi.run_options import apply_overrides
    with pytest.raises(InputError, match=r"'Gamma' is a constant of the case.*<gamma value=.*<constantsdef>"):
        apply_overrides({"TimeOut": 0.1}, ["Gamma=5"])
    assert apply_overrides({"TimeOut": 0.1}, ["CFLnumber=5"])["CFLnumber"] == 5.0   # read by the time step only
    assert apply_overrides({"TimeOut": 0.1}, ["RigidAlgorithm=2"])["RigidAlgorithm"] == 2      # DEM
    with pytest.raises(InputError, match=r"RigidAlgorithm: 4 is not one of 0, 1, 2, 3"):
        apply_overrides({"TimeOut": 0.1}, ["RigidAlgorithm=4"])
    with pytest.raises(InputError, match="unknown parameter 'Visc'; did you mean 'Visco'"):
        apply_overrides({"TimeOut": 0.1}, ["Visc=1"])


def test_set_rigid_algorithm_3_needs_a_chrono_section(done, tmp_path):
    """gencase refuses RigidAlgorithm=3 without a <chrono> section; --set RigidAlgorithm=3 on
    such a case is refused as well (it was recorded and run before), nothing written."""
    out = copy_run(done, tmp_path / "o")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    r = invoke(["run", out, "--overwrite", "--set", "RigidAlgorithm=3", "--tmax", "0.002", "--threads", "1"])
    assert_input_error(r, "--set RigidAlgorithm=3", "<execution><special><chrono>", "expected RigidAlgorithm 0 or 1")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_dualsphysics_keys_in_a_case_file(tmp_path):
    """SavePosDouble=2 (DualSPHysics reads != 0) and BoundaryMethod (not a DualSPHysics key,
    ignored by it) are accepted with a warning naming the line; RigidAlgorithm=2 (DEM) without floating
    bodies is warned (DualSPHysics switches DEM off)."""
    case = case_xml(tmp_path, '<parameter key="SavePosDouble" value="2" />'
                              '<parameter key="BoundaryMethod" value="2" />')
    r = invoke(["gencase", case, "-o", tmp_path / "g", "--dp", "0.1", "-q"])
    assert r.exit_code == 0, r.output
    assert "warning: <parameter>: parameter 'SavePosDouble' has no effect" in r.output
    assert "'BoundaryMethod' has no effect in sphdvi (it is not a DualSPHysics key" in r.output
    dem = case_xml(tmp_path, "", "b_Def.xml")
    dem.write_text(dem.read_text().replace('key="RigidAlgorithm" value="1"', 'key="RigidAlgorithm" value="2"'))
    r = invoke(["gencase", dem, "-o", tmp_path / "g2", "--dp", "0.1"])
    assert r.exit_code == 0, r.output
    assert "RigidAlgorithm 2 (DEM) without floating bodies: no DEM contacts" in r.output


# -- --resume: a checkpoint of another case ---------------------------------------------------
def test_resume_refuses_the_checkpoint_of_another_case(done, tmp_path):
    """Re-gencasing OUT at another dp and resuming: refused (exit 2), naming the particle
    counts and dp; the outputs stay as they were."""
    out = copy_run(done, tmp_path / "o")
    before = (out / "run.csv").read_text()
    redraw_case_in(out, tmp_path, 0.05)
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
    assert_input_error(r, "restart.h5 was written by a run of another case", "particles 301 in the checkpoint, "
                       "1001 in the case", "dp 0.1 in the checkpoint, 0.05 in the case")
    assert (out / "run.csv").read_text() == before


def test_resume_of_an_older_checkpoint_without_the_case_identity(done, tmp_path):
    """A checkpoint of an older sphdvi (no case_* scalars) still resumes its own case, and is
    refused for a re-drawn one (its particles are not the case's)."""
    out = copy_run(done, tmp_path / "o")
    with h5py.File(out / "restart.h5", "a") as f:
        for key in ("case_np", "case_dp", "case_h", "case_hash"):
            del f["scalars"].attrs[key]
    other = copy_run(out, tmp_path / "other")
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    with h5py.File(out / "restart.h5") as f:
        assert "case_hash" in f["scalars"].attrs          # written again, with it
    redraw_case_in(other, tmp_path, 0.05)
    r = invoke(["run", other, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
    assert_input_error(r, "written by a run of another case")


def test_body_only_checkpoint_given_to_an_sph_run(done, tmp_path):
    from sphdvi.io.checkpoint import BODIES_RESTART_FORMAT
    out = copy_run(done, tmp_path / "o")
    with h5py.File(out / "restart.h5", "w") as f:
        f.attrs["format"] = BODIES_RESTART_FORMAT
        f.attrs["extra"] = json.dumps({"part": 1, "step": 1, "runtime_s": 0.0, "names": ["b"]})
        f.create_group("bodies")
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "-q"])
    assert_input_error(r, "restart.h5 is the checkpoint of a body-only run")


def test_sph_checkpoint_given_to_a_body_only_run(done, tmp_path):
    out = tmp_path / "p"
    r = invoke(["run", PENDULUM, "-o", out, "--tmax", "0.02", "--tout", "0.01", "-q"])
    assert r.exit_code == 0, r.output
    with h5py.File(out / "restart.h5") as f:
        assert json.loads(f.attrs["extra"])["case_hash"]
    import shutil
    shutil.copy(done / "restart.h5", out / "restart.h5")
    r = invoke(["run", out, "--resume", "--tmax", "0.04", "-q"])
    assert_input_error(r, "restart.h5 is the checkpoint of an SPH run")


# -- corrupt HDF5 files ---------------------------------------------------------------------
def _truncate(path, size=1000):
    data = Path(path).read_bytes()[:size]
    Path(path).write_bytes(data)


def test_corrupt_checkpoint(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    good = (out / "restart.h5").read_bytes()
    _truncate(out / "restart.h5")
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "-q"])
    assert_input_error(r, f"{out / 'restart.h5'} is not a readable checkpoint (truncated file")
    (out / "restart.h5").write_text("garbage\n")
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "-q"])
    assert_input_error(r, f"{out / 'restart.h5'} is not a readable checkpoint (file signature not found")
    (out / "restart.h5").write_bytes(good)
    with h5py.File(out / "restart.h5", "a") as f:
        del f["state/rhop"]
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "-q"])
    assert_input_error(r, "restart.h5 is not a readable checkpoint (no state/rhop")


def test_corrupt_particle_file(done, tmp_path):
    """A truncated particles.vtkhdf: --resume, export and measure name it (exit 2)."""
    out = copy_run(done, tmp_path / "o")
    _truncate(out / "particles.vtkhdf", 3000)
    name = str(out / "particles.vtkhdf")
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "-q"])
    assert_input_error(r, f"{name} is not a readable particle file (truncated file")
    assert_input_error(invoke(["export", out]), f"{name} is not a readable particle file")
    assert_input_error(invoke(["measure", "points", out, "--points", "0.5,0,0.1"]),
                       f"{name} is not a readable particle file")
    with h5py.File(out / "particles.vtkhdf", "w") as f:      # HDF5, but not a particle file
        f.create_group("other")
    assert_input_error(invoke(["export", out]), f"{name} is not a particle file of sphdvi run: no VTKHDF/Points")


def test_corrupt_case_file(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    good = (out / CASE_H5).read_bytes()
    _truncate(out / CASE_H5, 2000)
    r = invoke(["run", out, "--tmax", "0.002", "-q"])
    assert_input_error(r, f"{out / CASE_H5} (truncated file", "cannot be read as HDF5")
    assert_input_error(invoke(["measure", "points", out, "--points", "0.5,0,0.1"]), f"{out / CASE_H5}")
    (out / CASE_H5).write_bytes(good)
    with h5py.File(out / CASE_H5, "a") as f:
        del f["particles/mass"]
    r = invoke(["run", out, "--tmax", "0.002", "-q"])
    assert_input_error(r, f"{out / CASE_H5} is not a readable sphdvi case file")


# -- DtFixed against TimeMax and TimeOut ---------------------------------------------------------
def test_dtfixed_longer_than_the_run(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    r = invoke(["run", out, "--set", "DtFixed=1", "--tmax", "0.002", "-q"])
    assert_input_error(r, "DtFixed (1 s) is longer than the whole run (TimeMax 0.002 s)")
    r = invoke(["run", PENDULUM, "-o", tmp_path / "p", "--set", "DtFixed=10", "--tmax", "0.01", "-q"])
    assert_input_error(r, "DtFixed (10 s) is longer than the whole run (TimeMax 0.01 s)")


def test_dtfixed_that_throws_the_fluid_out_stops_the_run(done, tmp_path):
    """DtFixed = 1 s: warned as longer than TimeOut; its one step excludes 46 % of the fluid,
    under the run's limit (half) but beyond the one-step limit (a quarter): exit 3."""
    out = copy_run(done, tmp_path / "o")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", out, "--set", "DtFixed=1", "--tmax", "1", "--threads", "1", "-q", "--overwrite"])
    assert r.exit_code == 3, r.output
    assert any("DtFixed (1 s) is longer than TimeOut (0.01 s)" in str(w.message) for w in caught)
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "diverged" and "excluded in one step" in meta["message"]
    # the particles of that step are in excluded.csv, though no output followed it
    rows = [line.split(",") for line in (out / "excluded.csv").read_text().splitlines()[1:]]
    n_out = int(meta["message"].split(": ")[1].split(" of")[0])
    assert len(rows) == n_out and {r[-1] for r in rows} <= {"position", "rhop", "movement"} and "position" in {r[-1] for r in rows}


# -- --threads and --dp --------------------------------------------------------------------------
def test_threads_beyond_numba_are_clamped_and_recorded(done, tmp_path):
    import numba
    out = copy_run(done, tmp_path / "o")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", out, "--threads", "99999999999", "--tmax", "0.002", "-q", "--overwrite"])
    assert r.exit_code == 0, r.output
    limit = numba.config.NUMBA_NUM_THREADS
    assert json.loads((out / "run.json").read_text())["threads"] == limit
    assert any(f"--threads 99999999999: numba runs at most {limit} threads" in str(w.message) for w in caught)


def test_dp_where_gencase_does_not_run(done, tmp_path):
    """--dp with a gencase folder or --resume: the case's own dp is accepted, another refused."""
    out = copy_run(done, tmp_path / "o")
    r = invoke(["run", out, "--dp", "0.05", "--tmax", "0.002", "-q"])
    assert_input_error(r, "--dp 0.05: a gencase output folder holds the case", "drawn at dp=0.1")
    xml = case_xml(tmp_path)
    r = invoke(["run", xml, "-o", out, "--resume", "--dp", "0.05", "--tmax", "0.006", "-q"])
    assert_input_error(r, "--dp 0.05: --resume continues the run of the case", "drawn at dp=0.1")
    r = invoke(["run", xml, "-o", out, "--resume", "--dp", "0.1", "--tmax", "0.006", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output


# -- export --dir ------------------------------------------------------------------------------
def test_export_dir_is_used_as_given(done, tmp_path):
    """--dir: relative paths inside OUTDIR (also ../x), absolute ones as given, never changed;
    an existing file is refused."""
    out = copy_run(done, tmp_path / "run" / "o")
    r = invoke(["export", out, "--dir", "../escape"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "run" / "escape" / "particles.pvd").is_file() and not (out / "escape").exists()
    absdir = tmp_path / "abs" / "vtp"
    r = invoke(["export", out, "--dir", absdir])
    assert r.exit_code == 0 and (absdir / "Part_0002.vtp").is_file(), r.output
    assert not (out / "vtp").exists()
    r = invoke(["export", out, "--dir", "run.csv"])
    assert_input_error(r, "run.csv exists and is not a folder")
    isodir = tmp_path / "abs" / "iso"         # --isosurface takes --dir the same way
    r = invoke(["export", out, "--isosurface", "--dir", str(isodir)])
    assert r.exit_code == 0 and (isodir / "isosurface.pvd").is_file(), r.output
    r = invoke(["export", out, "--isosurface", "--dir", "run.csv"])
    assert_input_error(r, "run.csv exists and is not a folder")
    r = invoke(["export", out, "--isosurface", "--iso-spacing", "nan"])
    assert_input_error(r, "Invalid value for '--iso-spacing'")
    r = invoke(["export", out, "--isosurface", "--iso-spacing", "1e-7"])     # out of memory before
    assert_input_error(r, "--iso-spacing 1e-07: ", "grid nodes over the fluid", "expected a spacing >= ")


def test_export_of_a_body_only_run_says_it_has_no_particles(tmp_path):
    out = tmp_path / "pend"
    assert invoke(["run", PENDULUM, "-o", out, "--tmax", "0.01", "-q"]).exit_code == 0
    r = invoke(["export", out])
    assert_input_error(r, "holds a body-only run (no fluid)", "bodies.csv and links.csv")
    assert "run 'sphdvi run' first" not in r.output


def test_a_particle_file_locked_by_its_run_is_named_as_such(done, tmp_path):
    """A program holding particles.vtkhdf open for writing with HDF5's lock (an older sphdvi run; a
    run now writes it without, tests/cli/test_cli_audit9.py) keeps readers out: measure and export say
    so (they called the file 'truncated or corrupt?' before)."""
    import os
    import subprocess
    import sys
    if os.environ.get("HDF5_USE_FILE_LOCKING", "").upper() == "FALSE":
        pytest.skip("HDF5 file locking is off here")
    out = copy_run(done, tmp_path / "o")
    path = out / "particles.vtkhdf"
    holder = subprocess.Popen([sys.executable, "-c", "import h5py, sys, time; f = h5py.File(sys.argv[1], 'a'); "
                               "print('open', flush=True); time.sleep(60)", str(path)],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "open"
        for args in (["export", out], ["measure", "elevation", out, "--at", "0.2"]):
            r = invoke(args)
            assert_input_error(r, "is locked by another program that holds it open for writing", "--resume")
            assert "corrupt" not in r.output
    finally:
        holder.kill()
        holder.wait()


def test_output_folders_that_cannot_be_made_are_bad_input(done, tmp_path):
    """-o / --dir below a file, or a case file's name taken by a folder: exit 2 naming the option
    and the path (exit 1 with a bare 'Not a directory' or a temporary file's name before)."""
    afile = tmp_path / "afile"
    afile.write_text("x")
    xml = case_xml(tmp_path)
    for args in (["gencase", xml, "-o", afile / "sub", "--dp", "0.1", "-q"],
                 ["run", xml, "-o", afile / "sub", "--dp", "0.1", "--tmax", "0.002", "-q"]):
        assert_input_error(invoke(args), f"-o {afile / 'sub'}: the folder cannot be made (Not a directory)")
    assert_input_error(invoke(["export", done, "--dir", afile / "sub"]), "--dir ", "the folder cannot be made")
    taken = tmp_path / "taken"
    (taken / CASE_H5).mkdir(parents=True)
    assert_input_error(invoke(["gencase", xml, "-o", taken, "--dp", "0.1", "-q"]),
                       f"{CASE_H5} is a folder, where a file is to be written")

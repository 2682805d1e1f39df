"""Bad input to `sphdvi measure` and `sphdvi export`: MeasureTool points files (POINTSLIST counts,
POINTSENDLIST), 2-number points in 3D, non-finite --point/--axis, outputs onto the run's own
files, damaged particles.vtkhdf / bodies.csv, and a fluid run whose particle file is missing."""
import json
import os
import shutil

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from _tank import hydrostatic_tank, write_run
from sphdvi.cli import main
from sphdvi.measure.post import MAX_POINTS, parse_points


@pytest.fixture(scope="module")
def run2d(tmp_path_factory):
    return write_run(str(tmp_path_factory.mktemp("t2d")), hydrostatic_tank(1.0, 0.4, 0.05, True, layers=3))


@pytest.fixture(scope="module")
def run3d(tmp_path_factory):
    tank = hydrostatic_tank(0.6, 0.4, 0.05, False, width=0.4, layers=3)
    return write_run(str(tmp_path_factory.mktemp("t3d")), tank)


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def points_file(tmp_path, text):
    path = tmp_path / "p.txt"
    path.write_text(text)
    return str(path)


def assert_exit_2(r, *texts):
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and "internal error" not in r.output, r.output
    for text in texts:
        assert text in r.output, (text, r.output)


# ---------------------------------------------------------------------------------
# points files: POINTSENDLIST read as the range it defines, POINTSLIST counts checked
# ---------------------------------------------------------------------------------
def test_pointsendlist_is_the_range_from_the_first_to_the_last_point(tmp_path):
    """DualSPHysics's doc/help/FilePointsTemplate.txt: POINTSENDLIST rows Begin / Step / End;
    along each axis begin, begin + step, ... up to end, a step of 0 keeps the begin value (the
    three rows were read as three points)."""
    pts = parse_points(points_file(tmp_path, "POINTSENDLIST\n0.0 0.0 0.03\n0.1 0.0 0.0\n4.0 0.0 0.0\n"))
    assert pts.shape == (41, 3)
    np.testing.assert_allclose(pts[:, 0], np.arange(41) * 0.1, atol=1e-12)
    assert (pts[:, 1] == 0).all() and (pts[:, 2] == 0.03).all()
    # a vertical x = 0.2 from z 1 to 3 by 0.5, then the same as a POINTSLIST of 5
    col = parse_points(points_file(tmp_path, "POINTSENDLIST\n0.2 0 1.0\n0 0 0.5\n0.2 0 3.0\n"
                                             "POINTSLIST\n0.2 0 1.0\n0 0 0.5\n1 1 5\n"))
    np.testing.assert_allclose(col[:5], col[5:])
    np.testing.assert_allclose(col[:5, 2], [1.0, 1.5, 2.0, 2.5, 3.0])
    # a negative step towards a smaller end, a 2D mesh (x 2 by 1, z 3 by 1)
    down = parse_points(points_file(tmp_path, "POINTSENDLIST\n4 0 0\n-1 0 0\n0 0 0\n"))
    assert down[:, 0].tolist() == [4, 3, 2, 1, 0]
    assert parse_points(points_file(tmp_path, "POINTSENDLIST\n0 0 0\n1 0 1\n1 0 2\n")).shape == (6, 3)


@pytest.mark.parametrize("text, message", [
    ("POINTSLIST\n0 0 0\n0.1 0 0\n-5 1 1\n", ":4: '-5 1 1': POINTSLIST counts must be whole numbers >= 1"),
    ("POINTSLIST\n0 0 0\n0.1 0 0\n0 1 1\n", ":4: '0 1 1': POINTSLIST counts must be whole numbers >= 1"),
    ("POINTSLIST\n0 0 0\n0.1 0 0\n2.9 1 1\n", ":4: '2.9 1 1': POINTSLIST counts must be whole numbers >= 1"),
    ("POINTSLIST\n0 0 0\n0.1 0 0\nnan 1 1\n", ":4: 'nan 1 1': the POINTSLIST numbers must be finite"),
    ("POINTSLIST\n0 0 0\n0 0 0\n100000000 1 1\n", ":4: the POINTSLIST makes 100,000,000 x 1 x 1 = 100,000,000 points; "
                                                   "at most 1,000,000"),
    ("POINTSLIST\n0 0 0\n0.1 0 0\n", ":3: '0.1 0 0': the POINTSLIST ends after 2 row(s); expected 3 rows"),
    ("POINTSENDLIST\n0 0 0\n-0.1 0 0\n4 0 0\n", ":3: '-0.1 0 0': StepX -0.1 goes away from EndX 4"),
    ("POINTSENDLIST\n0 0 0\n1e-9 0 0\n4 0 0\n", ":4: the POINTSENDLIST makes 4,000,000,001 points along X"),
    ("POINTSENDLIST\n0 0 0\n0.001 0.001 0.001\n1 1 1\n", "makes 1,001 x 1,001 x 1,001 = 1,003,003,001 points"),
    ("POINTSENDLIST\n0 0 0\ninf 0 0\n4 0 0\n", ":3: 'inf 0 0': the POINTSENDLIST numbers must be finite"),
])
def test_bad_list_blocks_are_refused_with_the_file_line(tmp_path, text, message):
    """Counts were forced to >= 1 (-5 -> 1 point), truncated (2.9 -> 2), a NaN one warned from numpy,
    a huge one expanded without limit (a measure of 1e8 points ran out of time)."""
    path = points_file(tmp_path, text)
    with pytest.raises(ValueError) as exc:
        parse_points(path)
    assert str(exc.value).startswith(path) and message in str(exc.value), str(exc.value)


def test_points_file_errors_exit_2(run2d, tmp_path):
    r = invoke("measure", "points", run2d, "--points", points_file(tmp_path, "POINTSLIST\n0 0 0\n0 0 0\n1e8 1 1\n"))
    assert_exit_2(r, "Invalid value for '--points'", f"{MAX_POINTS:,}")
    r = invoke("measure", "points", run2d, "--vars", "press",
               "--points", points_file(tmp_path, "POINTSENDLIST\n0.1 0 0.1\n0.1 0 0\n0.5 0 0\n"))
    assert r.exit_code == 0, r.output
    assert r.stdout.splitlines()[0].count("press_") == 5


# ---------------------------------------------------------------------------------
# 2-number points in a 3D case; non-finite --point / --axis
# ---------------------------------------------------------------------------------
def test_2d_shorthand_points_are_refused_in_3d(run3d, run2d):
    """x,z (and --at x) are 2D shorthands: in a 3D case they were read as y = 0 silently."""
    r = invoke("measure", "points", run3d, "--points", "0.3,0.2", "--vars", "press")
    assert_exit_2(r, "'0.3,0.2': the case is 3D: expected x,y,z")
    r = invoke("measure", "elevation", run3d, "--at", "0.3;0.3,0.2")
    assert_exit_2(r, "'0.3': the case is 3D: expected x,y")
    assert invoke("measure", "points", run3d, "--points", "0.3,0.2,0.2", "--vars", "press").exit_code == 0
    assert invoke("measure", "elevation", run3d, "--at", "0.3,0.2").exit_code == 0
    # 2D keeps them
    r2 = invoke("measure", "points", run2d, "--points", "0.5,0.2", "--vars", "press")
    assert r2.exit_code == 0 and r2.stdout == invoke("measure", "points", run2d, "--points", "0.5,0,0.2",
                                                     "--vars", "press").stdout, r2.output
    assert invoke("measure", "elevation", run2d, "--at", "0.3").exit_code == 0


@pytest.mark.parametrize("option, value", [("--point", "nan,0,0"), ("--point", "0,inf,0"),
                                           ("--axis", "0,0,0,nan,1,0"), ("--axis", "0,0,0,0,-inf,0")])
def test_forces_point_and_axis_must_be_finite(run2d, option, value):
    """--point nan,0,0 was accepted and wrote empty moment columns."""
    r = invoke("measure", "forces", run2d, "--mkbound", "0", option, value)
    assert_exit_2(r, f"Invalid value for '{option}'", "must be finite")


# ---------------------------------------------------------------------------------
# --csv / --plot never overwrite a run's own files
# ---------------------------------------------------------------------------------
@pytest.fixture
def run_copy(run2d, tmp_path):
    out = tmp_path / "r"
    shutil.copytree(run2d, out)
    for name in ("run.json", "run.csv", "run.log", "bodies.csv", "links.csv", "restart.h5", "GaugesVel_g1.csv"):
        (out / name).write_text("x\n")
    return out


def snapshot(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir()}


@pytest.mark.parametrize("name", ["particles.vtkhdf", "Tank.h5", "run.json", "run.csv", "run.log", "bodies.csv",
                                  "links.csv", "restart.h5", "GaugesVel_g1.csv", "excluded.csv", "GaugesSWL_x.csv"])
def test_csv_onto_a_file_of_the_run_is_refused(run_copy, name):
    """`--csv r/particles.vtkhdf` replaced the run's particles with a CSV (then neither measure
    nor --resume could read the run); the same for the case file, run.csv, bodies.csv, ..."""
    before = snapshot(run_copy)
    for command in (["points", "--points", "0.5,0,0.2"], ["bodies"], ["forces", "--mkbound", "0"]):
        r = invoke("measure", command[0], run_copy, *command[1:], "--csv", run_copy / name)
        assert_exit_2(r, "Invalid value for '--csv'", f"{name} is a file of the run or case in",
                      "does not overwrite it")
    assert snapshot(run_copy) == before


def test_plot_and_csv_into_other_places(run_copy, run2d, tmp_path):
    """--plot onto a run's file is refused too, as is a --csv onto another run's files or any
    existing HDF5 file; other names in the run folder, and run.csv elsewhere, are written."""
    before = snapshot(run_copy)
    r = invoke("measure", "elevation", run2d, "--at", "0.3", "--plot", run_copy / "Tank_All.png", "--csv",
               run_copy / "run.csv")
    assert_exit_2(r, "Invalid value for '--csv'", "run.csv is a file of the run or case in")
    r = invoke("measure", "elevation", run_copy, "--at", "0.3", "--plot", run_copy / "particles.vtkhdf")
    assert_exit_2(r, "Invalid value for '--plot'", "is a file of the run or case in")
    (tmp_path / "data.h5").write_bytes(b"x")
    r = invoke("measure", "elevation", run_copy, "--at", "0.3", "--csv", tmp_path / "data.h5")
    assert_exit_2(r, "data.h5 is an HDF5 file")
    assert snapshot(run_copy) == before
    r = invoke("measure", "elevation", run_copy, "--at", "0.3", "--csv", run_copy / "elev.csv", "--plot",
               run_copy / "elev.png")
    assert r.exit_code == 0 and (run_copy / "elev.csv").exists() and (run_copy / "elev.png").exists(), r.output
    r = invoke("measure", "elevation", run_copy, "--at", "0.3", "--csv", tmp_path / "run.csv")
    assert r.exit_code == 0 and (tmp_path / "run.csv").exists(), r.output


# ---------------------------------------------------------------------------------
# damaged run outputs
# ---------------------------------------------------------------------------------
def test_particle_file_without_an_array_is_named(run_copy):
    """Rhop deleted from particles.vtkhdf gave "internal error: IndexError" (exit 1)."""
    with h5py.File(run_copy / "particles.vtkhdf", "r+") as f:
        del f["VTKHDF/PointData/Rhop"]
    r = invoke("measure", "points", run_copy, "--points", "0.5,0,0.2")
    assert_exit_2(r, "particles.vtkhdf lacks VTKHDF/PointData/Rhop (not a particle file of a sphdvi run, or damaged)")
    r = invoke("measure", "elevation", run_copy, "--at", "0.3")
    assert_exit_2(r, "lacks VTKHDF/PointData/Rhop")
    with h5py.File(run_copy / "particles.vtkhdf", "r+") as f:
        del f["VTKHDF/Steps/PointDataOffsets/Vel"]
    r = invoke("measure", "forces", run_copy, "--mkbound", "0")
    assert_exit_2(r, "lacks VTKHDF/Steps/PointDataOffsets/Vel")
    r = invoke("export", run_copy)
    assert_exit_2(r, "lacks VTKHDF/Steps/PointDataOffsets/Vel")


@pytest.mark.parametrize("text, message", [
    ("a,b\n1,x\n", "bodies.csv is not a readable bodies.csv of a sphdvi run (damaged?): no column time, body, x, ..."),
    ("time,body,x,y,z,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,cfx,cfy,cfz,ctx,cty,ctz\n"
     "0,b,1,2,3,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n0.1,b,1,2,x,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n",
     "bodies.csv:3: not a readable bodies.csv row (damaged?): expected numbers"),
    ("time,body,x,y,z,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,cfx,cfy,cfz,ctx,cty,ctz\n0,b,1,2\n",
     "bodies.csv:2: not a readable bodies.csv row"),
])
def test_damaged_bodies_csv_is_an_input_error(run_copy, text, message):
    """A bodies.csv with other columns gave "internal error: KeyError: 'time'" (exit 1)."""
    os.unlink(run_copy / "particles.vtkhdf")          # the logs are the record (a body-only run)
    (run_copy / "bodies.csv").write_text(text)
    (run_copy / "links.csv").write_text("time,link,fx,fy,fz,tx,ty,tz\n")
    assert_exit_2(invoke("measure", "bodies", run_copy), message)


def test_damaged_links_csv_is_an_input_error(run_copy):
    os.unlink(run_copy / "particles.vtkhdf")
    (run_copy / "bodies.csv").write_text("time,body,x,y,z,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,cfx,cfy,cfz,ctx,cty,ctz\n"
                                         "0,b,1,2,3,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n")
    (run_copy / "links.csv").write_text("time,link,fx\n0,l,1\n")
    assert_exit_2(invoke("measure", "bodies", run_copy), "links.csv is not a readable links.csv", "no column fy")
    (run_copy / "links.csv").write_text("time,link,fx,fy,fz,tx,ty,tz\n")
    r = invoke("measure", "bodies", run_copy)
    assert r.exit_code == 0 and len(r.stdout.splitlines()) == 2, r.output


# ---------------------------------------------------------------------------------
# export of a run without its particle file
# ---------------------------------------------------------------------------------
def test_export_names_the_missing_particle_file_of_a_fluid_run(run_copy):
    """A fluid run with floating bodies (bodies.csv, run.json) whose particles.vtkhdf is gone was
    said to be "a body-only run (no fluid)"; run.json's fluid_particles tells them apart."""
    os.unlink(run_copy / "particles.vtkhdf")
    (run_copy / "run.json").write_text(json.dumps({"status": "completed", "fluid_particles": 120}))
    r = invoke("export", run_copy)
    assert_exit_2(r, "particles.vtkhdf not found: the run in", "has 120 fluid particles, and its particle file is "
                  "missing")
    assert "body-only" not in r.output
    (run_copy / "run.json").write_text(json.dumps({"status": "completed", "fluid_particles": 0}))
    assert_exit_2(invoke("export", run_copy), "holds a body-only run (no fluid)")
    os.unlink(run_copy / "run.json")
    assert_exit_2(invoke("export", run_copy), "particles.vtkhdf not found: run 'sphdvi run' first")

"""sphdvi measure on analytic snapshots: hydrostatic tank (elevation, forces), CLI, CSV."""
import os

import numpy as np
import pytest
from click.testing import CliRunner

from _tank import hydrostatic_tank, write_run
from sphdvi.cli import main
from sphdvi.measure.post import RunOutput, measure_elevation, measure_forces, measure_points
from sphdvi.measure.tables import Table, read_table, table_text, write_table

DEPTH = 0.4


@pytest.fixture(scope="module")
def tank2d(tmp_path_factory):
    tank = hydrostatic_tank(1.0, DEPTH, 0.02, True, layers=3)
    return tank, write_run(str(tmp_path_factory.mktemp("t2d")), tank, times=(0.0, 0.1))


@pytest.fixture(scope="module")
def tank3d(tmp_path_factory):
    tank = hydrostatic_tank(0.6, DEPTH, 0.04, False, width=0.4, layers=3)
    return tank, write_run(str(tmp_path_factory.mktemp("t3d")), tank)


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.mark.parametrize("which", ["tank2d", "tank3d"])
def test_elevation_equals_depth(which, request):
    """Still tank: elevation and depth equal the water depth within dp/2
    (measured: 2D +0.0036 m with dp 0.02, 3D -0.0008 m with dp 0.04)."""
    tank, out = request.getfixturevalue(which)
    dp = tank["constants"]["dp"]
    xy = [[0.3, 0.2, 0.0], [0.11, 0.13, 0.0]]
    t = measure_elevation(RunOutput(out), xy)
    assert t.names == ["elevation_0", "depth_0", "elevation_1", "depth_1"]
    assert np.all(np.abs(t.data - DEPTH) < dp / 2), t.data
    if tank["constants"]["is2d"]:
        # at the face of a side wall the depth is still the water's (the wall's particles reaching
        # up to the surface were taken for the bottom: a few mm, then negative); in 3D the kernel
        # sum at a wall face stays under its threshold of 0.5 (no surface found)
        t = measure_elevation(RunOutput(out), [[0.0, 0.0, 0.0]])
        assert np.all(np.abs(t.data[:, 1] - DEPTH) < dp), t.data


@pytest.mark.parametrize("which", ["tank2d", "tank3d"])
def test_force_on_bottom_equals_weight(which, request):
    """Force of the fluid on the bottom of a hydrostatic tank = weight of the water
    within 1 % (measured: 2D Wendland h=sqrt(2)dp: 0.78 % low; 3D h=sqrt(3)dp: 0.25 % low)."""
    tank, out = request.getfixturevalue(which)
    run = RunOutput(out)
    t = measure_forces(run, [0], mkbound=True)
    assert t.names == ["fx", "fy", "fz", "mx", "my", "mz"]
    fz = t.column("fz")
    assert np.all(np.abs(-fz / tank["weight"] - 1.0) < 0.01), fz / tank["weight"]
    assert np.all(np.abs(t.data[:, :2]) < 1e-9 * tank["weight"])
    # the whole tank (bottom + walls, by global mk) carries the weight too
    t_all = measure_forces(run, [2, 3])
    assert np.all(np.abs(-t_all.column("fz") / tank["weight"] - 1.0) < 0.01)
    # moment of a symmetric load about the tank centre line is ~0; about x=0 it is F * L/2
    L = 1.0 if tank["constants"]["is2d"] else 0.6
    t0 = measure_forces(run, [0], mkbound=True, point=[L / 2, 0.2, 0.0])
    assert abs(t0.column("my")[0]) < 1e-9 * tank["weight"]
    ta = measure_forces(run, [0], mkbound=True, axis=([0, 0, 0], [0, 1, 0]))
    np.testing.assert_allclose(ta.column("my")[0], -L / 2 * t0.column("fz")[0], rtol=2e-3)
    assert ta.column("mx")[0] == 0 and ta.column("mz")[0] == 0


def test_points_values_and_wall_flag(tank2d):
    tank, out = tank2d
    c = tank["constants"]
    run = RunOutput(out)
    pts = np.array([[0.5, 0.0, 0.2], [0.01, 0.0, 0.2], [0.5, 0.0, 0.8]])
    t, near = measure_points(run, pts, ["press", "rhop", "vel"])
    assert t.time.tolist() == [0.0, 0.1] and t.part.tolist() == [0, 1]
    p_expected = c["rhop0"] * 9.81 * (DEPTH - 0.2)
    assert abs(t.column("press_0")[0] / p_expected - 1) < 0.01
    assert np.isnan(t.column("press_2")).all() and np.isnan(t.column("velx_2")).all()
    assert [i for i, _, _ in near] == [1]
    r = invoke("measure", "points", out, "--points", "0.5,0,0.2;0.01,0,0.2", "--vars", "press")
    assert r.exit_code == 0, r.output
    assert "point 1 (0.01, 0, 0.2)" in r.stderr and "1.5h" in r.stderr


def test_cli_outputs_and_exit_codes(tank2d, tmp_path):
    tank, out = tank2d
    r = invoke("measure", "points", out, "--points", "0.5,0,0.1")
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    assert lines[0].startswith("time [s],velx_0 [m/s],vely_0 [m/s],velz_0 [m/s],rhop_0 [kg/m^3],press_0 [Pa]")
    assert len(lines) == 3
    pts = tmp_path / "pts.txt"
    pts.write_text("POINTS\n0.5 0 0.1\n# comment\n0.6 0 0.1\n")
    r = invoke("measure", "points", out, "--points", pts, "--vars", "press", "--csv", tmp_path / "p.csv", "--sep", ";")
    assert r.exit_code == 0, r.output
    text = (tmp_path / "p.csv").read_text().splitlines()
    assert text[0] == " ;PosX [m]:;0.5;0.6" and text[3] == "Part;Time [s];press_0 [Pa];press_1 [Pa]"
    # bad input: exit 2, clear message, no traceback
    for bad in ("1,2,3,4", "a,b,c", ";", str(tmp_path / "missing.txt")):
        r = invoke("measure", "points", out, "--points", bad)
        assert r.exit_code == 2, (bad, r.output)
        assert "Invalid value for '--points'" in r.output and "Traceback" not in r.output
    r = invoke("measure", "points", out, "--points", "0,0,0", "--vars", "vel,foo")
    assert r.exit_code == 2 and "foo" in r.output
    r = invoke("measure", "forces", out, "--mk", "77")
    assert r.exit_code == 2 and "no boundary or floating particles with mk 77" in r.output
    r = invoke("measure", "forces", out)
    assert r.exit_code == 2
    r = invoke("measure", "forces", out, "--mk", "2", "--axis", "1,2")
    assert r.exit_code == 2 and "--axis" in r.output
    r = invoke("measure", "elevation", str(tmp_path), "--at", "0.5")
    assert r.exit_code == 2 and "no gencase output" in r.output
    r = invoke("measure", "forces", out, "--mkbound", "0", "--csv", tmp_path / "f.csv")
    assert r.exit_code == 0, r.output
    t = read_table(str(tmp_path / "f.csv"))
    assert t.names == ["fx", "fy", "fz", "mx", "my", "mz"] and t.units[:3] == ["N/m"] * 3


def test_cli_bad_options_exit_2_before_any_output(tank2d, tmp_path):
    """Option values are checked before the table is computed or printed: --plot needs an image
    name, --csv and --plot an existing folder (never created), --kclimit/--threshold finite and
    in range, --first an existing output, --at no z; a missing points file is named."""
    tank, out = tank2d
    (tmp_path / "afile").write_text("x")
    cases = [
        (["points", "--points", "0.5,0,0.1", "--plot", tmp_path / "x.txt"], "expected an image file name"),
        (["points", "--points", "0.5,0,0.1", "--csv", tmp_path / "no" / "dir" / "x.csv"], "does not exist"),
        (["points", "--points", "0.5,0,0.1", "--kclimit", "nan"], "Invalid value for '--kclimit'"),
        (["points", "--points", "0.5,0,0.1", "--kclimit", "-1"], "Invalid value for '--kclimit'"),
        (["elevation", "--at", "0.3", "--threshold", "-5"], "Invalid value for '--threshold'"),
        (["elevation", "--at", "0.3", "--dz", "inf"], "Invalid value for '--dz'"),
        (["elevation", "--at", "0.3", "--first", "10"], "--first 10: "),
        (["elevation", "--at", "0.3", "--first", "1", "--last", "0"], "--last 0 is before --first 1"),
        (["elevation", "--at", "0.2,0,1"], "expected x or x,y"),
        # a step that would sample beyond memory (it ran ~70 s, then exit 1 "out of memory")
        (["elevation", "--at", "0.3", "--dz", "1e-9"], "samples along each vertical"),
        (["points", "--points", "nonexist.txt"], "nonexist.txt: file not found"),
        # what was wrong, not Python's words ("invalid literal for int()", "file not found" for a folder)
        (["forces", "--mkbound", "abc"], "'abc' is not an mk; expected mk numbers or ranges"),
        (["points", "--points", "0.5,0,0.1", "--trackmk", "1,x"], "'x' is not an mk"),
        (["points", "--points", str(tmp_path)], "is a folder; expected a points file"),
        (["points", "--points", "0.5,0,0.1", "--csv", tmp_path / "afile" / "x.csv"], "afile is a file, not a folder"),
        (["points", "--points", str(tmp_path / "nope.csv")], "nope.csv: file not found"),
    ]
    for args, text in cases:
        r = invoke("measure", args[0], out, *args[1:])
        assert r.exit_code == 2, (args, r.output)
        assert text in r.output and "Traceback" not in r.output, (args, r.output)
        assert r.stdout == "" or "time [s]" not in r.stdout, (args, r.stdout)     # no table printed
    assert not (tmp_path / "no").exists()
    r = invoke("measure", "elevation", out, "--at", "0.3", "--first", "10")
    assert "has 2 output times, numbered 0 to 1" in r.output
    r = invoke("measure", "elevation", out, "--at", "0.3", "--first", "1")
    assert r.exit_code == 0 and len(r.stdout.splitlines()) == 2, r.output


def test_cli_2d_points_off_the_plane_are_warned(tank2d):
    """In 2D the kernel uses x and z: a y off the case's plane is ignored, with a warning."""
    tank, out = tank2d
    r = invoke("measure", "points", out, "--points", "0.5,0.3,0.2", "--vars", "press")
    assert r.exit_code == 0, r.output
    assert "the case is 2D" in r.stderr and "y = 0.3" in r.stderr
    same = invoke("measure", "points", out, "--points", "0.5,0,0.2", "--vars", "press")
    assert "the case is 2D" not in same.stderr and same.stdout == r.stdout
    r = invoke("measure", "elevation", out, "--at", "0.3,0.2")
    assert r.exit_code == 0 and "the case is 2D" in r.stderr, r.output


def test_cli_points_outside_the_domain_are_warned_and_variables_counted_once(tank2d):
    """A point or vertical outside the case's domain reads nothing: warned (empty columns came
    silently); a variable named twice gives its columns once."""
    tank, out = tank2d
    r = invoke("measure", "points", out, "--points", "0.5,0,0.2;100,0,100", "--vars", "vel,press,vel")
    assert r.exit_code == 0, r.output
    assert "--points: 1 point(s) outside the simulation domain" in r.stderr and "point 1" in r.stderr
    header = r.stdout.splitlines()[0]
    assert header.count("velx_0") == 1 and header.count("press_1") == 1
    r = invoke("measure", "elevation", out, "--at", "0.3;50")
    assert r.exit_code == 0 and "--at: 1 point(s) outside the simulation domain" in r.stderr, r.output
    r = invoke("measure", "elevation", out, "--at", "0.3")
    assert "outside" not in r.stderr
    r = invoke("measure", "elevation", out, "--at", "0.3", "--threshold", "5")     # never crossed
    assert r.exit_code == 0 and "--threshold 5: the kernel sum inside the water is about 1" in r.stderr


def test_csv_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    data = rng.normal(size=(4, 3)) * 1e3
    data[1, 2] = np.nan
    t = Table(np.array([0.0, 0.01, 0.02, 0.03]), ["velx_0", "press_0", "press_1"], ["m/s", "Pa", "Pa"], data,
              np.arange(4), np.array([[0.1, 0, 0.2], [0.1, 0, 0.2], [0.3, 0, 0.4]]))
    for sep in (",", ";"):
        path = tmp_path / f"t{sep == ';'}.csv"
        write_table(t, str(path), sep=sep)
        back = read_table(str(path))
        assert back.names == t.names and back.units == t.units
        np.testing.assert_array_equal(back.time, t.time)
        np.testing.assert_allclose(back.data, t.data, rtol=5e-9, equal_nan=True)   # 9 digits
        assert np.isnan(back.data[1, 2])
        assert table_text(back, sep) == path.read_text()          # text round trip is exact
        if sep == ";":
            np.testing.assert_array_equal(back.positions, t.positions)
            np.testing.assert_array_equal(back.part, t.part)


def test_plot(tank2d, tmp_path):
    pytest.importorskip("matplotlib")
    tank, out = tank2d
    r = invoke("measure", "elevation", out, "--at", "0.3;0.6", "--plot", tmp_path / "e.png", "--csv",
               tmp_path / "e.csv")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "e.png").stat().st_size > 1000


@pytest.mark.parametrize("which", ["tank2d", "tank3d"])
def test_isosurface_export(which, request):
    """Free surface of the still tank within dp/2 of the depth (3D triangles, 2D lines in x-z)."""
    pytest.importorskip("vtkmodules")
    tank, out = request.getfixturevalue(which)
    is2d = tank["constants"]["is2d"]
    r = invoke("export", out, "--isosurface")
    assert r.exit_code == 0, r.output
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    rd = vtkXMLPolyDataReader()
    rd.SetFileName(os.path.join(out, "iso", "Iso_0000.vtp"))
    rd.Update()
    poly = rd.GetOutput()
    assert (poly.GetNumberOfLines() if is2d else poly.GetNumberOfPolys()) > 20
    p = vtk_to_numpy(poly.GetPoints().GetData())
    mid = (np.abs(p[:, 0] - 0.3) < 0.1) & (p[:, 2] > DEPTH / 2)
    if not is2d:
        mid &= np.abs(p[:, 1] - 0.2) < 0.1
    assert mid.sum() > 2            # the free surface, away from the sheet along the walls
    assert np.abs(p[mid, 2] - DEPTH).max() < tank["constants"]["dp"] / 2
    assert os.path.exists(os.path.join(out, "iso", "isosurface.pvd"))
    assert len(os.listdir(os.path.join(out, "iso"))) == len(RunOutput(out).times()) + 1


def test_measure_help_imports_nothing_heavy():
    import subprocess
    import sys
    code = ("import sys\nfrom click.testing import CliRunner\nfrom sphdvi.cli import main\n"
            "for c in ([], ['points'], ['elevation'], ['forces'], ['bodies']):\n"
            "    r = CliRunner().invoke(main, ['measure'] + c + ['--help'])\n"
            "    assert r.exit_code == 0 and 'Usage' in r.output, r.output\n"
            "heavy = [m for m in ('numba', 'h5py', 'numpy', 'matplotlib') if m in sys.modules]\n"
            "assert not heavy, heavy\n")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)


def test_viscotime_viscosity_of_the_force_at_the_snapshot_time():
    """ViscoTime cases: the viscous force term uses Visco x ViscoBoundFactor at the
    snapshot's time (linear in the table, end values outside)."""
    from sphdvi.measure.core import KernelSpec
    spec = KernelSpec(kind=2, h=0.014, dp=0.01, is2d=True, visco_bound=0.01,
                      visco_table=((0.0, 0.02), (1.0, 0.04)))
    assert spec.visco_bound_at(None) == 0.01
    assert spec.visco_bound_at(0.25) == pytest.approx(0.025)
    assert spec.visco_bound_at(-1.0) == 0.02 and spec.visco_bound_at(5.0) == 0.04
    assert KernelSpec(kind=2, h=0.014, dp=0.01, is2d=True, visco_bound=0.01).visco_bound_at(0.5) == 0.01


def test_bodies_of_a_body_only_run_honour_first_last_every(tmp_path):
    """measure bodies on a body-only run (from bodies.csv): --first/--last/--every select the
    output rows (surge/sway/heave still from t = 0); --first past the end is an error."""
    from pathlib import Path
    case = Path(__file__).resolve().parents[2] / "cases" / "pendulum" / "CasePendulum_Def.xml"
    out = tmp_path / "p"
    r = invoke("run", case, "-o", out, "--tmax", "0.03", "--tout", "0.01", "-q")
    assert r.exit_code == 0, r.output
    full = invoke("measure", "bodies", out, "--csv", tmp_path / "all.csv")
    part = invoke("measure", "bodies", out, "--first", "1", "--last", "2", "--csv", tmp_path / "part.csv")
    assert full.exit_code == 0 and part.exit_code == 0, (full.output, part.output)
    a, b = read_table(str(tmp_path / "all.csv")), read_table(str(tmp_path / "part.csv"))
    assert a.time.size == 4 and b.time.tolist() == a.time[1:3].tolist()
    np.testing.assert_array_equal(b.data, a.data[1:3])
    r = invoke("measure", "bodies", out, "--first", "10")
    assert r.exit_code == 2 and "--first 10: " in r.output and "4 output times" in r.output


def _rotated_tank_run(tmp_path, is2d):
    """The still-water tank turned and shifted as one rigid block: at time t by θ = 10 t degrees
    about y (2D) or about a tilted axis (3D), and moved by (0.1 t, 0, 0.05 t)."""
    from sphdvi.motion import _rotation
    tank = (hydrostatic_tank(1.0, DEPTH, 0.02, True, layers=3) if is2d
            else hydrostatic_tank(0.6, DEPTH, 0.04, False, width=0.4, layers=3))
    axis = np.array([0.0, 1.0, 0.0]) if is2d else np.array([0.3, 1.0, 0.5]) / np.linalg.norm([0.3, 1.0, 0.5])
    centre = np.array([0.3, 0.0, 0.1])

    def moves(t, tk):
        R = _rotation(axis, np.radians(10.0 * t))
        pos = (tk["pos"] - centre) @ R.T + centre + np.array([0.1, 0.0, 0.05]) * t
        return pos, tk["vel"], tk["rhop"]
    return tank, write_run(str(tmp_path / ("r2" if is2d else "r3")), tank, times=(0.0, 1.0, 2.0), moves=moves)


@pytest.mark.parametrize("is2d", [True, False])
def test_points_tracking_the_walls_move_with_the_tank(tmp_path, is2d):
    """--trackmk: a point given at the start rides with the walls (MeasureTool -trackmk), so in a
    tank moved as one rigid block it reads what it read at the start; a fixed point does not."""
    tank, out = _rotated_tank_run(tmp_path, is2d)
    run = RunOutput(out)
    pts = np.array([[0.3, 0.0 if is2d else 0.2, 0.15]])
    walls = [int(m) for m in np.unique(tank["mk"][tank["type"] == 0])]
    moving, _ = measure_points(run, pts, ["press"], track=(walls, False))
    fixed, _ = measure_points(run, pts, ["press"])
    p = moving.column("press_0")
    assert np.allclose(p, p[0], rtol=1e-5) and abs(p[0] / (1000 * 9.81 * (DEPTH - 0.15)) - 1) < 0.02
    assert not abs(fixed.column("press_0")[2] / p[0] - 1) < 0.05     # another value, or none (NaN)
    by_mkbound, _ = measure_points(run, pts, ["press"], track=([0, 1], True))
    assert np.array_equal(by_mkbound.column("press_0"), p)
    r = invoke("measure", "points", out, "--points", "0.3,0,0.15" if is2d else "0.3,0.2,0.15", "--vars", "press",
               "--trackmkbound", "0,1")
    assert r.exit_code == 0, r.output
    assert np.allclose(read_table_text(r.stdout)[:, -1], p, rtol=1e-6)


def read_table_text(text):
    rows = [ln.split(",") for ln in text.splitlines() if ln and ln[0].isdigit()]
    return np.array([[float(v) for v in r] for r in rows])


def test_trackmk_errors(tank2d):
    _, out = tank2d
    r = invoke("measure", "points", out, "--points", "0.5,0,0.2", "--trackmk", "77")
    assert r.exit_code == 2 and "--trackmk 77" in r.output and "Traceback" not in r.output
    r = invoke("measure", "points", out, "--points", "0.5,0,0.2", "--trackmk", "2", "--trackmkbound", "0")
    assert r.exit_code == 2 and "at most one of --trackmk and --trackmkbound" in r.output


def test_kcorr_is_the_kernel_sum_and_2d_units_are_per_metre(tank2d):
    """kcorr (MeasureTool's): ~1 inside the still water, ~0.5 at its surface, 0 in the air, never
    blanked by --kclimit; mass and vol of a 2D case are per metre of depth (kg/m, m^2)."""
    tank, out = tank2d
    pts = [[0.5, 0.0, 0.2], [0.5, 0.0, DEPTH], [0.5, 0.0, DEPTH + 0.2]]
    t, _ = measure_points(RunOutput(out), pts, ["kcorr", "mass", "vol"])
    assert t.names[:3] == ["kcorr_0", "kcorr_1", "kcorr_2"]
    k = t.data[0, :3]
    assert abs(k[0] - 1.0) < 0.02 and 0.35 < k[1] < 0.65 and k[2] == 0.0, k
    assert t.units[3:6] == ["kg/m"] * 3 and t.units[6:] == ["m^2"] * 3

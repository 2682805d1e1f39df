"""Mooring lines in a run (``<special><moorings>``, cases/mooredbox2d): the output files with
DualSPHysics's names and columns, a resumed run that ends bitwise as an uninterrupted one (the
lines' nodes are in restart.h5), and (slow) C4: the box held down by its taut lines sinks by
what they pull, and the lines at rest are their elastic catenaries."""
import re
from pathlib import Path

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "mooredbox2d" / "CaseMooredBox2D_Def.xml"


def run(out, *extra, case=CASE):
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "-q", *extra])
    assert r.exit_code == 0, r.output
    return out


def final_state(outdir):
    with h5py.File(outdir / "restart.h5", "r") as f:
        o = np.argsort(f["state/idp"][...])
        state = {k: f["state"][k][...][o] for k in ("pos", "vel", "rhop")}
        state.update({f"line_{k}": f["arrays/moorings"][k][()] for k in ("pos", "vel", "F")})
        state.update({f"body_{k}": f["bodies"][k][...] for k in ("pos", "vel")})
        return state, dict(f["scalars"].attrs)


def test_the_mooring_files_have_dualsphysics_names_and_columns(tmp_path):
    """MoorDynPlus_tension.csv / _force.csv (the case's <savedata>: every 0.01 s from 0) and one
    FtForcePoints file per fairlead (every output): their headers, a row per time, and the
    fairlead's force in both (the lines start taut: stretched 2.85 %, 80 N)."""
    case = tmp_path / "CaseMooredBox2D_Def.xml"
    case.write_text(CASE.read_text().replace('<savecsv_points value="true" />',
                                             '<savecsv_points value="true" /><savevtk_points value="true" />'))
    out = run(tmp_path / "a", "--tmax", "0.05", "--set", "FtPause=0", case=case)
    data = out / "moordynplus_data"
    head = (data / "MoorDynPlus_tension.csv").read_text().splitlines()
    assert head[0] == "time [s];dt [s];Anchor_L0 [N];Fairlead_L0 [N];Anchor_L1 [N];Fairlead_L1 [N]"
    rows = np.loadtxt(data / "MoorDynPlus_tension.csv", delimiter=";", skiprows=1)
    assert rows.shape[1] == 6 and rows[0, 0] == 0.0 and rows.shape[0] == 6           # t = 0, 0.01 ... 0.05
    assert rows[0, 3] == pytest.approx(2.9e3 * (0.32 ** 0.5 / 0.55 - 1), rel=0.02)
    force = (data / "MoorDynPlus_force.csv").read_text().splitlines()[0].split(";")
    assert force[2:5] == ["Anchor.x_L0 [N]", "Anchor.y_L0 [N]", "Anchor.z_L0 [N]"] and len(force) == 14
    forces = np.loadtxt(data / "MoorDynPlus_force.csv", delimiter=";", skiprows=1)
    pts = sorted(out.glob("FtForcePoints_ft*_pt*.csv"))
    assert [p.name for p in pts] == ["FtForcePoints_ft0000_pt00.csv", "FtForcePoints_ft0000_pt01.csv"]
    assert pts[0].read_text().splitlines()[0] == ("Part;Time [s];PosX [m];PosY [m];PosZ [m];ForceX [N];ForceY [N];"
                                                  "ForceZ [N];VelX [m/s];VelY [m/s];VelZ [m/s]")
    a = np.loadtxt(pts[0], delimiter=";", skiprows=1)
    assert a[:, 0].tolist() == [0, 1]                       # TimeOut 0.05: parts 0 and 1
    # the left line pulls its fairlead (x 1.35) down and to the left, towards its anchor (x 0.95)
    assert a[0, 5] < 0 and a[0, 7] < 0 and a[0, 2] == pytest.approx(1.35)
    # the same fairlead force in both files at the output of t = 0.05 (the step that reached it; no ramp)
    assert forces[-1, 0] == a[1, 1] and a[1, 1] == pytest.approx(0.05, abs=2e-4)
    assert forces[-1, 5:8] == pytest.approx(a[1, 5:8], rel=1e-8)
    # <savevtk_lines> and <savevtk_moorings> (on by default), <savevtk_points> (set here): at each output,
    # a polyline per line with a vertex / a sphere at each node (cell array Line), and the fairleads
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOLegacy import vtkPolyDataReader

    def read(name):
        reader = vtkPolyDataReader()
        reader.SetFileName(str(out / "MooringsVtk" / name))
        reader.Update()
        return reader.GetOutput()
    names = sorted(p.name for p in (out / "MooringsVtk").iterdir())
    assert names == ["FtForcesPoints_0000.vtk", "FtForcesPoints_0001.vtk", "MooringsLines_0000.vtk",
                     "MooringsLines_0001.vtk", "Moorings_0000.vtk", "Moorings_0001.vtk"]
    poly = read("MooringsLines_0001.vtk")
    assert (poly.GetNumberOfPoints(), poly.GetNumberOfVerts(), poly.GetNumberOfLines()) == (42, 42, 2)
    assert vtk_to_numpy(poly.GetCellData().GetArray("Line")).tolist() == [0] * 21 + [1] * 21 + [0, 1]
    nodes = vtk_to_numpy(poly.GetPoints().GetData())
    assert nodes[[0, 21], 0] == pytest.approx([0.95, 2.05]) and nodes[[0, 21], 2] == pytest.approx([0.0, 0.0])
    balls = read("Moorings_0001.vtk")
    assert balls.GetNumberOfLines() == 2 and balls.GetNumberOfPolys() % 42 == 0
    pts = vtk_to_numpy(balls.GetPoints().GetData())
    assert np.array_equal(pts[:42], nodes)
    per = (len(pts) - 42) // 42                             # each node's sphere: a tenth of its first segment
    r = np.linalg.norm(pts[42:42 + per] - nodes[0], axis=1)
    assert r == pytest.approx(np.linalg.norm(nodes[1] - nodes[0]) / 10, abs=3e-7)      # float32 at ~1 m
    fair = read("FtForcesPoints_0001.vtk")
    assert fair.GetNumberOfVerts() == 2
    arrays = {k: vtk_to_numpy(fair.GetPointData().GetArray(k)) for k in ("FtId", "Vel", "Force")}
    assert arrays["FtId"].tolist() == [0, 0]
    assert arrays["Force"][0] == pytest.approx(a[1, 5:8], rel=1e-6)
    assert vtk_to_numpy(fair.GetPoints().GetData())[0] == pytest.approx(a[1, 2:5], rel=1e-6)


def test_a_resumed_run_ends_bitwise_as_an_uninterrupted_one(tmp_path):
    """1 thread, FtPause 0 so the box moves: the fluid, the body and the lines' nodes and loads."""
    a = run(tmp_path / "a", "--tmax", "0.1", "--tout", "0.05", "--set", "FtPause=0")
    b = run(tmp_path / "b", "--tmax", "0.05", "--tout", "0.05", "--set", "FtPause=0")
    r = CliRunner().invoke(main, ["run", str(b), "--resume", "--tmax", "0.1", "--tout", "0.05", "--threads", "1",
                                  "-q", "--set", "FtPause=0"])
    assert r.exit_code == 0, r.output
    (sa, ka), (sb, kb) = final_state(a), final_state(b)
    assert ka["nstep"] == kb["nstep"]
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k
    for name in ("moordynplus_data/MoorDynPlus_tension.csv", "FtForcePoints_ft0000_pt01.csv"):
        assert (a / name).read_text() == (b / name).read_text(), name


def connect_case(tmp_path):
    """C4's case with the left line split at a sinker (a connect of 50 g, 2e-5 m³) half way: anchor ->
    sinker (10 segments) and sinker -> box (10 segments)."""
    text = CASE.read_text()
    left = """<line comment="left line">
                            <vesselconnection bodyref="50" x="1.35" y="0" z="0.4" />
                            <fixconnection x="0.95" y="0" z="0" />
                        </line>"""
    assert left in text
    split = """<line><connect conref="7" /><fixconnection x="0.95" y="0" z="0" />
                            <length value="0.275" /><segments value="10" /></line>
                        <line><vesselconnection bodyref="50" x="1.35" y="0" z="0.4" /><connect conref="7" />
                            <length value="0.275" /><segments value="10" /></line>"""
    text = text.replace(left, split).replace("<lines>", """<connects><connect conref="7" x="1.15" y="0" z="0.2" M="0.05"
                            V="2e-5"><coeffini cda="0.002" ca="1" /></connect></connects>
                    <lines>""")
    case = tmp_path / "CaseSinker_Def.xml"
    case.write_text(text)
    return case


def test_a_line_with_a_sinker_runs_and_resumes_bitwise(tmp_path):
    """A connect in a run: the lines' files have a column pair per line (three lines), the sinker
    moves under its lines and weight, and a resumed run ends bitwise as an uninterrupted one (the
    connect's position and velocity are in restart.h5)."""
    case = connect_case(tmp_path)
    a = run(tmp_path / "a", "--tmax", "0.1", "--tout", "0.05", "--set", "FtPause=0", case=case)
    b = run(tmp_path / "b", "--tmax", "0.05", "--tout", "0.05", "--set", "FtPause=0", case=case)
    r = CliRunner().invoke(main, ["run", str(b), "--resume", "--tmax", "0.1", "--tout", "0.05", "--threads", "1",
                                  "-q", "--set", "FtPause=0"])
    assert r.exit_code == 0, r.output
    head = (a / "moordynplus_data" / "MoorDynPlus_tension.csv").read_text().splitlines()[0]
    assert head.endswith("Anchor_L2 [N];Fairlead_L2 [N]")
    with h5py.File(a / "restart.h5", "r") as f:
        cpos, cvel = f["arrays/moorings"]["cpos"][()], f["arrays/moorings"]["cvel"][()]
        nodes = f["arrays/moorings"]["pos"][()]
    assert cpos.shape == (1, 3) and np.abs(cvel).max() > 0
    assert np.array_equal(nodes[10], cpos[0]) and np.array_equal(nodes[11], cpos[0])    # both lines' ends
    (sa, ka), (sb, kb) = final_state(a), final_state(b)
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k
    with h5py.File(b / "restart.h5", "r") as f:
        assert np.array_equal(f["arrays/moorings"]["cpos"][()], cpos)


@pytest.mark.slow
def test_c4_the_moored_box_sinks_by_what_its_lines_pull(tmp_path):
    """C4 (sphdvi.validation.mooredbox): the box (0.3 x 0.2 m, half as dense as water) on two lines
    0.55 m long between its bottom corners and anchors 0.4 m to each side (0.566 m apart: taut),
    4 s at dp 0.02 (about 50 s per run on 1 thread), against the same box free. Over the last
    second it floats δ deeper: within 0.5 dp of the lines' pull over ρ g b (less the tank's level
    rise; S12's mark for a draft; measured δ 16.5 mm against 19.1 mm, −0.13 dp: the boundary's gap
    makes SPH's box buoyancy grow 16 % faster with depth at this dp, 11 % at dp 0.01), and the
    fluid's extra lift on it balances the lines' pull within 2 % (measured +0.4 %); each line's mean
    force is its elastic catenary's at its fairlead's mean position within 2 % (measured 0.03 %).
    Figures in README (C4)."""
    from sphdvi.validation.mooredbox import equilibrium_errors
    free_case = tmp_path / "CaseFreeBox2D_Def.xml"
    free_case.write_text(re.sub(r"\n\s*<moorings>.*</moorings>", "", CASE.read_text(), flags=re.S))
    moored = run(tmp_path / "moored", "--tmax", "4")
    free = run(tmp_path / "free", "--tmax", "4", case=free_case)
    e = equilibrium_errors(str(moored), str(free))
    print({k: round(v, 5) for k, v in e.items()})
    assert e["sink"] > 0.5 * e["dp"]            # the lines do hold it down, by more than half a particle
    assert abs(e["sink_dp"]) <= 0.5
    assert abs(e["lift_error"]) <= 0.02
    assert e["catenary_error"] <= 0.02
    assert abs(e["drift"]) < 0.1 * e["dp"]


def test_moorings_in_a_body_only_run_are_refused(tmp_path):
    """Without fluid the case runs on the multibody engine alone, which does not carry the lines:
    exit 2 naming <moorings> rather than a run that leaves them out."""
    text = CASE.read_text()
    text = re.sub(r"<setmkfluid mk=\"0\" />\s*<drawbox>.*?</drawbox>", "", text, count=1, flags=re.S)
    case = tmp_path / "CaseDry_Def.xml"
    case.write_text(text)
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(tmp_path / "o"), "-q", "--tmax", "0.01"])
    assert r.exit_code == 2, r.output
    assert "<special><moorings>: mooring lines in a body-only run" in r.output and "Traceback" not in r.output


def test_moorings_with_periodic_boundaries_are_refused(tmp_path):
    """A moored body crossing a periodic end would drag its lines across the domain: exit 2."""
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(tmp_path / "o"), "-q", "--tmax", "0.01",
                                  "--set", "XPeriodicIncZ=1e-12"])     # a written increment: periodic in x
    assert r.exit_code == 2, r.output
    assert "<special><moorings> with periodic boundaries is not supported" in r.output

"""Run-time gauges of <special><gauges> against the post-processing of the same run."""
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.vtkhdf import step_times
from sphdvi.measure.post import RunOutput, measure_forces, measure_points
from sphdvi.measure.tables import read_table

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
GAUGES = """<gauges>
    <default><output value="true" /></default>
    <velocity name="V1"><point x="0.5" y="0" z="0.5" /></velocity>
    <velocity name="V2"><point x="0.9" y="0" z="1.8" /><computedt value="0" /><outputdt value="0" /></velocity>
    <swl name="S1"><point0 x="0.5" y="0" z="-0.05" /><point2 x="0.5" y="0" z="2.5" /></swl>
    <maxz name="M1"><point0 x="0.5" y="0" z="0" /><height value="3" /></maxz>
    <force name="F1"><target mkbound="0" /></force>
    <mesh name="G1"><point x="0.2" y="0" z="0.2" /><vec1 x="1" y="0" z="0" /><vec2 x="0" y="1" z="0" />
      <vec3 x="0" y="0" z="1" /><size1 value="0.4" /><size3 value="2.5" />
      <outputdata value="vel,veldir,rhop,zsurf" /><dirdat x="1" y="0" z="0" /></mesh>
    <velocity name="Off"><point x="0.5" y="0" z="0.5" /><output value="false" /></velocity>
  </gauges>"""


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def run_out(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("gauges")
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"')
    text = re.sub(r"<gauges>.*?</gauges>", GAUGES, text, flags=re.S)
    case = tmp / "CaseG_Def.xml"
    case.write_text(text)
    out = tmp / "out"
    r = invoke("run", case, "-o", out, "--tmax", "0.02", "--tout", "0.005", "--threads", "1", "-q")
    assert r.exit_code == 0, r.output
    return out


def test_gauge_files(run_out):
    names = sorted(p.name for p in run_out.glob("Gauges*.csv"))
    assert names == ["GaugesForce_F1.csv", "GaugesMaxZ_M1.csv", "GaugesMesh_G1_Rhop.csv", "GaugesMesh_G1_Vel.csv",
                     "GaugesMesh_G1_VelDir.csv", "GaugesMesh_G1_Zsurf.csv", "GaugesSWL_S1.csv",
                     "GaugesVel_V1.csv", "GaugesVel_V2.csv"]          # not 'Off' (<output value="false"/>)
    head = (run_out / "GaugesVel_V1.csv").read_text().splitlines()[0]
    assert head == "time [s];velx [m/s];vely [m/s];velz [m/s];posx [m];posy [m];posz [m]"
    meta = __import__("json").loads((run_out / "run.json").read_text())
    v2 = read_table(str(run_out / "GaugesVel_V2.csv"))
    assert v2.time.shape[0] == meta["steps"] + 1          # computedt 0: every step (and t=0)
    m1 = read_table(str(run_out / "GaugesMaxZ_M1.csv"))
    assert m1.data[0, 0] == pytest.approx(2.0)            # top particle of the 2 m column at t=0
    np.testing.assert_allclose(m1.data[:, 1:], [[0.5, 0.0, 0.0]] * m1.time.shape[0])   # posx..posz: point0
    s1 = read_table(str(run_out / "GaugesSWL_S1.csv"))
    assert abs(s1.data[0, 2] - 2.0 - 0.02) < 0.02          # surface of the column within dp/2
    nodes = 11 * 63                                        # 0.4/dp+1 along vec1, 2.5/dp+1 along vec3
    tables = {k: read_table(str(run_out / f"GaugesMesh_G1_{k}.csv")) for k in ("Vel", "VelDir", "Rhop", "Zsurf")}
    assert [len(tables[k].names) for k in ("Vel", "VelDir", "Rhop", "Zsurf")] == [3 * nodes, nodes, nodes, 11]
    head = (run_out / "GaugesMesh_G1_Vel.csv").read_text().splitlines()[0].split(";")
    assert head[:4] == ["time [s]", "v(0:0:0).x [m/s]", "v(0:0:0).y [m/s]", "v(0:0:0).z [m/s]"]
    assert head[-1] == "v(10:0:62).z [m/s]"                # DualSPHysics's order: i fastest
    zs = tables["Zsurf"].data[0]
    assert np.all(np.abs(zs - 2.02) < 0.02)
    rhop = tables["Rhop"].data[0]
    # i fastest: the first rows of nodes are in the water; the top ones, in the air, read kcdummy (0)
    assert np.all(np.abs(rhop[:33] - 1000) < 30) and np.all(rhop[-11:] == 0.0)


def test_velocity_gauge_matches_measure_points(run_out):
    """The gauge (float64 solver state) and `measure points` (float32 snapshot fields) at the
    same output times: equal to float32 round-off (measured max relative diff ~1e-8)."""
    times = step_times(str(run_out / "particles.vtkhdf"))
    g = read_table(str(run_out / "GaugesVel_V1.csv"))
    np.testing.assert_allclose(g.time, times, rtol=1e-9)    # computed at the output steps
    post, _ = measure_points(RunOutput(str(run_out)), [[0.5, 0.0, 0.5]], ["vel"])
    np.testing.assert_allclose(g.data[:, :3], post.data, rtol=1e-6, atol=1e-9)
    assert np.abs(g.data[1:, 0]).max() > 1e-3                # the flow has started: not all zeros
    r = invoke("measure", "points", run_out, "--points", "0.5,0,0.5", "--vars", "vel", "--sep", ";")
    assert r.exit_code == 0, r.output


def test_force_gauge_matches_measure_forces(run_out):
    g = read_table(str(run_out / "GaugesForce_F1.csv"))
    post = measure_forces(RunOutput(str(run_out)), [0], mkbound=True)
    scale = np.abs(post.data[:, :3]).max()
    np.testing.assert_allclose(g.data[:, 1:4], post.data[:, :3], rtol=0, atol=1e-5 * scale)
    np.testing.assert_allclose(g.data[:, 0], np.linalg.norm(g.data[:, 1:4], axis=1), rtol=1e-8)


def test_resume_keeps_rows_and_appends(run_out, tmp_path):
    import shutil
    out = tmp_path / "copy"
    shutil.copytree(run_out, out)
    before = read_table(str(out / "GaugesVel_V1.csv"))
    with open(out / "GaugesVel_V1.csv", "a") as fh:        # a row after the restart time, then a torn one
        fh.write("0.5;1;2;3;0;0;0\n0.6;1;2")
    r = invoke("run", out, "--resume", "--tmax", "0.03", "--tout", "0.005", "--threads", "1", "-q")
    assert r.exit_code == 0, r.output
    after = read_table(str(out / "GaugesVel_V1.csv"))
    n = before.time.shape[0]
    np.testing.assert_array_equal(after.data[:n], before.data)
    assert after.time.shape[0] == n + 2 and np.all(np.diff(after.time) > 0)
    np.testing.assert_allclose(after.time, step_times(str(out / "particles.vtkhdf")), rtol=1e-9)

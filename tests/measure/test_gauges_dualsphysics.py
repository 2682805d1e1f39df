"""The run-time gauges as DualSPHysics's JGaugeSystem / JGaugeItem define them: the mesh
gauge's ``<sizeK length distpt>``, ``kclimit`` / ``kcdummy``, one file per variable; dry
gauges' values; ``<output>`` off by default with ``outputdt`` TimeOut; periodic copies."""
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from case.casetext import case_xml
from sphdvi.case.gauge_spec import mesh_axis
from sphdvi.cli import main
from sphdvi.measure.gauges import kernel_corrected
from sphdvi.measure.tables import read_table

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def run_case(tmp_path, gauges, tmax="0.02", tout="0.01", extra=()):
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"')
    text = re.sub(r"<gauges>.*?</gauges>", lambda m: f"<gauges>\n{gauges}\n</gauges>", text, flags=re.S)
    case = tmp_path / "CaseG_Def.xml"
    case.write_text(text)
    out = tmp_path / "out"
    r = invoke("run", case, "-o", out, "--tmax", tmax, "--tout", tout, "--threads", "1", *extra)
    assert r.exit_code == 0, r.output
    return out, r.output


def test_mesh_axis_counts_as_jmeshdata():
    """JMeshData::MakeMeshPt: floor((L + 0.01 d)/d) + 1 nodes d apart when L >= d, else one."""
    assert mesh_axis({"length": 0.4, "distpt": 0.1}, 0.04) == (5.0, 0.1)
    assert mesh_axis({"length": 0.389, "distpt": 0.1}, 0.04) == (4.0, 0.1)     # 3.89 + 0.01 -> 3 steps
    assert mesh_axis({"length": 0.05, "distpt": 0.1}, 0.04) == (1.0, 0.1)
    assert mesh_axis({"length": 0.0, "distpt": 0.1}, 0.04) == (1.0, 0.1)
    assert mesh_axis(0.4, 0.04) == (11.0, 0.04)                                # sphdvi's value form: dp apart


def test_kernel_correction_as_jgaugemesh():
    vals = np.array([[2.0], [2.0], [2.0]])                # Shepard-normalised
    ksum = np.array([1.0, 0.3, 0.0])
    np.testing.assert_allclose(kernel_corrected(vals, ksum, 0.5, 0.0)[:, 0], [2.0, 0.0, 0.0])
    np.testing.assert_allclose(kernel_corrected(vals, ksum, 0.5, 1000.0)[:, 0], [2.0, 1000.0, 1000.0])
    np.testing.assert_allclose(kernel_corrected(vals, ksum, 0.5, None)[:, 0], [2.0, 0.6, 0.0])   # raw below
    np.testing.assert_allclose(kernel_corrected(vals, ksum, None, 0.0)[:, 0], [2.0, 0.6, 0.0])   # raw everywhere


MESH = """<default><output value="true" /></default>
<mesh name="G">
  <point x="0.2" y="0" z="1.8" />
  <vec1 x="1" y="0" z="0" /><vec3 x="0" y="0" z="1" />
  <size1 length="0.2" distpt="0.1" /><size3 length="0.4" distpt="0.05" />
  <outputdata value="rhop,zsurf" />{extra}
</mesh>"""


def test_mesh_gauge_in_dualsphysics_syntax(tmp_path):
    """<sizeK length distpt>: 3 x 9 nodes 0.1 and 0.05 m apart across the column's top (z = 2.0);
    the nodes above it read kcdummy (0 by default), zsurf is found from the column's nodes."""
    out, _ = run_case(tmp_path, MESH.format(extra=""))
    rhop = read_table(str(out / "GaugesMesh_G_Rhop.csv"))
    head = (out / "GaugesMesh_G_Rhop.csv").read_text().splitlines()[0].split(";")
    assert head[1] == "v(0:0:0) [kg/m^3]" and head[-1] == "v(2:0:8) [kg/m^3]" and len(head) == 1 + 27
    r0 = rhop.data[0].reshape(9, 3)                      # (k, i): i fastest
    assert np.all(r0[0] > 990) and np.all(r0[-1] == 0.0)  # z = 1.8 in the water, z = 2.2 in the air: kcdummy
    zs = read_table(str(out / "GaugesMesh_G_Zsurf.csv"))
    assert zs.data.shape[1] == 3 and np.all(np.abs(zs.data[0] - 2.0) < 0.04)


def test_mesh_gauge_kcdummy_and_kclimit_none(tmp_path):
    out, _ = run_case(tmp_path, MESH.format(extra='<kcdummy value="1000" />'))
    r0 = read_table(str(out / "GaugesMesh_G_Rhop.csv")).data[0].reshape(9, 3)
    assert np.all(r0[-1] == 1000.0)
    (tmp_path / "none").mkdir()
    out, _ = run_case(tmp_path / "none", MESH.format(extra='<kclimit value="none" />'))
    r0 = read_table(str(out / "GaugesMesh_G_Rhop.csv")).data[0].reshape(9, 3)
    assert np.all(r0[0] > 900) and np.all(r0[-1] == 0.0)          # raw sums: 0 in the air
    surface = r0[4]                                                 # z = 2.0: about half the support
    assert np.all((surface > 200) & (surface < 800)), surface


def test_mesh_size_needs_length_and_distpt(tmp_path):
    bad = MESH.format(extra="").replace('<size1 length="0.2" distpt="0.1" />', '<size1 length="0.2" />')
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"')
    case = tmp_path / "CaseG_Def.xml"
    case.write_text(re.sub(r"<gauges>.*?</gauges>", lambda m: f"<gauges>\n{bad}\n</gauges>", text, flags=re.S))
    r = invoke("gencase", case, "-o", tmp_path / "g")
    assert r.exit_code == 2 and "<size1>: missing attribute 'distpt'" in r.output, r.output


DRY = """<default><output value="true" /></default>
<swl name="S"><point0 x="2.5" y="0" z="0.0" /><point2 x="2.5" y="0" z="1.0" /></swl>
<maxz name="M"><point0 x="2.5" y="0" z="0.1" /><height value="2" /></maxz>
<velocity name="V"><point x="2.5" y="0" z="0.5" /></velocity>"""


def test_dry_gauges_write_numbers(tmp_path):
    """No empty cells: a dry swl line reads point0 (JGaugeSwl), a dry maxz point0's z (posz is point0's
    z), a dry velocity point 0."""
    out, _ = run_case(tmp_path, DRY)
    s = read_table(str(out / "GaugesSWL_S.csv"))
    np.testing.assert_allclose(s.data[:, :3], [[2.5, 0.0, 0.0]] * s.time.shape[0])
    m = read_table(str(out / "GaugesMaxZ_M.csv"))
    np.testing.assert_allclose(m.data, [[0.1, 2.5, 0.0, 0.1]] * m.time.shape[0])
    v = read_table(str(out / "GaugesVel_V.csv"))
    np.testing.assert_array_equal(v.data[:, :3], 0.0)
    assert ";;" not in (out / "GaugesSWL_S.csv").read_text()


def test_output_off_by_default_and_rows_every_timeout(tmp_path):
    """JGaugeSystem: <output> false unless asked (gencase says so, no file); outputdt defaults to
    TimeOut however often the gauge is computed."""
    gauges = ('<velocity name="quiet"><point x="0.5" y="0" z="0.5" /></velocity>\n'
              '<velocity name="V"><point x="0.5" y="0" z="0.5" /><computedt value="0.001" />'
              '<output value="true" /></velocity>')
    out, output = run_case(tmp_path, gauges, tmax="0.02", tout="0.01")
    assert "gauge 'quiet' writes no file" in output
    assert not (out / "GaugesVel_quiet.csv").exists()
    v = read_table(str(out / "GaugesVel_V.csv"))
    np.testing.assert_allclose(v.time, [0.0, 0.01, 0.02], atol=2e-4)


def test_gauges_see_across_a_periodic_end(tmp_path):
    """Still water 0.2 m deep in a channel periodic in x: the gauges at the periodic end read what
    the ones mid-channel read (before: 0.117 m against 0.214 m, and an empty velocity)."""
    case = tmp_path / "Per_Def.xml"
    case.write_text(PERIODIC_CASE)
    out = tmp_path / "out"
    r = invoke("run", case, "-o", out, "--threads", "1", "-q")
    assert r.exit_code == 0, r.output
    edge, mid = (read_table(str(out / f"GaugesSWL_{n}.csv")).data[:, 2] for n in ("edge", "mid"))
    np.testing.assert_allclose(edge, mid, atol=0.004)
    v = read_table(str(out / "GaugesVel_vedge.csv"))
    assert np.isfinite(v.data[:, :3]).all() and np.abs(v.data[:, :3]).max() < 0.05
    # `sphdvi measure` after the run likewise: the pressure 0.1 m down at the end as mid-channel
    from sphdvi.measure.post import RunOutput, measure_points
    res, _ = measure_points(RunOutput(str(out)), [[0.0, 0.0, 0.1], [0.3, 0.0, 0.1]], ["press"])
    assert np.isfinite(res.data).all()
    np.testing.assert_allclose(res.data[:, 0], res.data[:, 1], rtol=0.05)


PERIODIC_CASE = case_xml(
    pointmin=("-0.06", "0", "-0.06"), pointmax=("0.7", "0", "0.4"),
    commands="""
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0.02" /><size x="0.58" y="2" z="0.18" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="-0.04" /><size x="0.58" y="2" z="0.04" /></drawbox>""",
    special="""
            <gauges>
                <default><computedt value="0.01" /><output value="true" /></default>
                <swl name="edge"><point0 x="0.0" y="0" z="0.0" /><point2 x="0.0" y="0" z="0.35" /></swl>
                <swl name="mid"><point0 x="0.3" y="0" z="0.0" /><point2 x="0.3" y="0" z="0.35" /></swl>
                <velocity name="vedge"><point x="0.0" y="0" z="0.1" /></velocity>
                <velocity name="vmid"><point x="0.3" y="0" z="0.1" /></velocity>
            </gauges>""",
    parameters="""
            <parameter key="XPeriodicIncZ" value="0" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="DensityDT" value="1" />
            <parameter key="TimeMax" value="0.02" />
            <parameter key="TimeOut" value="0.01" />""")

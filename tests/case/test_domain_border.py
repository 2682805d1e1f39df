"""The default simulation domain as DualSPHysics builds it (JSph::LoadCaseParticles): the
particles' bounding box widened by BORDER_MAP*h = 0.05 h each side (dp/2 along a periodic
axis, JPartsLoad4::CalculeLimits), then <simulationdomain> applied to that widened box
(JSph::ResizeMapLimits)."""
import json

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from casetext import case_xml, write_case
from sphdvi.case.gencase import build_case
from sphdvi.cli import main


def build(tmp_path, **kw):
    tmp_path.mkdir(parents=True, exist_ok=True)
    return build_case(write_case(tmp_path, case_xml(**kw)), str(tmp_path / "out"))


def test_default_domain_is_widened_by_border_map(tmp_path):
    """The 2D tank of casetext (particles from (0, 0) to (4, 3), h = 0.0282843 m): x and z
    reach 0.05 h beyond the particles (y stays the 2D plane)."""
    r = build(tmp_path)
    pos, h = r.particles["pos"], r.constants.h
    lo, hi = np.asarray(r.domain["posmin"]), np.asarray(r.domain["posmax"])
    for i in (0, 2):
        assert lo[i] == pytest.approx(pos[:, i].min() - 0.05 * h, abs=1e-12)
        assert hi[i] == pytest.approx(pos[:, i].max() + 0.05 * h, abs=1e-12)
    assert lo[1] == hi[1] == r.constants.posy2d


def test_domain_rules_apply_to_the_widened_box(tmp_path):
    """"default" is the widened limit and "default + x%" is x % of the widened extent; a
    number is that number."""
    r = build(tmp_path, parameters='<simulationdomain><posmin x="default - 10%" z="-0.5"/>'
                                   '<posmax x="default" z="default + 50%"/></simulationdomain>')
    b = 0.05 * r.constants.h
    pos = r.particles["pos"]
    xlo, xhi = pos[:, 0].min() - b, pos[:, 0].max() + b
    zlo, zhi = pos[:, 2].min() - b, pos[:, 2].max() + b
    assert r.domain["posmin"][0] == pytest.approx(xlo - 0.1 * (xhi - xlo), abs=1e-12)
    assert r.domain["posmax"][0] == pytest.approx(xhi, abs=1e-12)
    assert r.domain["posmin"][2] == -0.5
    assert r.domain["posmax"][2] == pytest.approx(zhi + 0.5 * (zhi - zlo), abs=1e-12)


def test_periodic_axis_takes_half_dp_and_ignores_the_rules(tmp_path):
    """Along a periodic axis DualSPHysics widens by dp/2 and ResizeMapLimits leaves the axis
    alone; a rule written for it is warned about."""
    r = build(tmp_path, parameters='<parameter key="XPeriodicIncZ" value="0"/>'
                                   '<simulationdomain><posmax x="default + 50%" z="default + 50%"/></simulationdomain>')
    pos, dp = r.particles["pos"], r.constants.dp
    assert r.domain["posmin"][0] == pytest.approx(pos[:, 0].min() - dp / 2, abs=1e-12)
    assert r.domain["posmax"][0] == pytest.approx(pos[:, 0].max() + dp / 2, abs=1e-12)
    assert r.domain["posmax"][2] > pos[:, 2].max() + 1.0         # z is not periodic: its rule applies
    assert any("periodic axis x are ignored" in w for w in r.warnings)


STILL_LAYER = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><coefsound value="20" />
            <coefh value="0.866025" /><cflnumber value="0.2" /></constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.02"><pointmin x="-0.1" y="-0.1" z="-0.1" /><pointmax x="0.3" y="0.3" z="0.4" /></definition>
            <commands><mainlist>
                <setmkfluid mk="0" />
                <drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0.06" /><size x="0.12" y="0.12" z="0.14" /></drawbox>
                <setmkbound mk="0" />
                <drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0.0" /><size x="0.12" y="0.12" z="0.04" /></drawbox>
            </mainlist></commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.05" />
            <parameter key="DensityDT" value="2" />
            <parameter key="XYPeriodic" value="1" />
            <parameter key="TimeMax" value="0.06" />
            <parameter key="TimeOut" value="0.03" />
        </parameters>
    </execution>
</case>
"""


def test_still_layer_keeps_its_top_layer(tmp_path):
    """A still XY-periodic water layer whose free surface is the highest thing in the case (the
    auditor's peri3d): its top layer rises by micrometres while it settles; with the 0.05 h
    margin it stays in (the particles' bounding box as domain excluded the whole top layer at
    t = 0.029 s), and gencase prints and writes the widened domain."""
    case = tmp_path / "Still_Def.xml"
    case.write_text(STILL_LAYER)
    g = tmp_path / "g"
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(g)])
    assert r.exit_code == 0, r.output
    h = 0.866025 * np.sqrt(3.0) * 0.02
    top = 0.2 + 0.05 * h
    assert f"{top:.6g})" in r.output
    with h5py.File(g / "Still.h5") as f:
        assert f["domain"].attrs["posmax"][2] == pytest.approx(top, abs=1e-12)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(g), "-o", str(out), "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "completed" and meta["excluded"]["position"] == 0


def test_case_file_with_the_old_domain_still_runs(tmp_path):
    """A case file written before the margin (domain = the particles' bounding box) loads and
    runs as it did."""
    case = tmp_path / "Still_Def.xml"
    case.write_text(STILL_LAYER.replace('value="0.06"', 'value="0.002"'))
    g = tmp_path / "g"
    assert CliRunner().invoke(main, ["gencase", str(case), "-o", str(g)]).exit_code == 0
    with h5py.File(g / "Still.h5", "r+") as f:
        pos = f["particles/pos"][...]
        f["domain"].attrs["posmin"] = pos.min(axis=0)
        f["domain"].attrs["posmax"] = pos.max(axis=0)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(g), "-o", str(out), "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert json.loads((out / "run.json").read_text())["status"] == "completed"

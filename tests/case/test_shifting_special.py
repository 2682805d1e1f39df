"""``<special><shifting>`` as DualSPHysics reads it (JSphShifting::ReadXml, JSph::LoadCaseConfig):
mode 0-3 only, no second definition in <parameters>, and the zones, which a run honours."""
import numpy as np
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.io.vtkhdf import read_step, step_times
from sphdvi.simulation import shift_zones


def _case(tmp_path, special, params="", name="CaseShift"):
    """A 2D dam 0.2 x 0.3 m in a tank 0.6 m wide with ``special`` in <special> and ``params`` first
    in <parameters>."""
    text = case_xml(pointmin=("-0.06", "0", "-0.06"), pointmax=("0.6", "0", "0.4"), mkconfig="", commands="""
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.2" y="2" z="0.3" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="-0.02" y="-1" z="-0.02" />
                        <size x="0.6" y="2" z="0.4" /></drawbox>""",
                    special=special, parameters=params + '<parameter key="StepAlgorithm" value="2" />'
                    '<parameter key="DensityDT" value="1" /><parameter key="TimeMax" value="0.03" />'
                    '<parameter key="TimeOut" value="0.03" />')
    return write_case(tmp_path, text, f"{name}_Def.xml")


def _gencase(tmp_path, special, params=""):
    case = _case(tmp_path, special, params)
    return CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "g")])


def test_mode_4_is_refused_in_special(tmp_path):
    r = _gencase(tmp_path, '<shifting><mode value="4" /></shifting>')
    assert r.exit_code == 2, r.output
    assert "shifting mode 4 is not valid" in r.output and "<mode>" in r.output


def test_shifting_defined_twice_is_refused(tmp_path):
    r = _gencase(tmp_path, '<shifting><mode value="1" /></shifting>', '<parameter key="Shifting" value="0" />')
    assert r.exit_code == 2, r.output
    assert "Shifting is defined several times" in r.output


def test_missing_mode_is_refused(tmp_path):
    r = _gencase(tmp_path, '<shifting><coefficient value="-2" /></shifting>')
    assert r.exit_code == 2, r.output
    assert "no <mode>" in r.output


def test_zones_are_read_as_posref_and_edges(tmp_path):
    r = _gencase(tmp_path, """<shifting><mode value="3" />
        <shiftingzone><posref x="0" y="-1" z="0" /><size x="0.1" y="2" z="0.2" /></shiftingzone>
        <shiftingzone><posref x="0" y="-1" z="0" /><size x="0.1" y="2" z="0.2" />
            <rotateaxis angle="90" anglesunits="degrees"><point1 x="0" y="0" z="0" /><point2 x="0" y="1" z="0" />
            </rotateaxis></shiftingzone>
        <shiftingzone><posref x="0" y="-1" z="0" /><vecx x="0.1" y="0" z="0.1" /><vecy x="0" y="2" z="0" />
            <vecz x="-0.1" y="0" z="0.1" /></shiftingzone></shifting>""")
    assert r.exit_code == 0, r.output
    data = read_case_h5(str(tmp_path / "g" / "CaseShift.h5"))
    z = shift_zones(data)
    assert len(z) == 3
    np.testing.assert_allclose(z[0]["vecs"], np.diag([0.1, 2, 0.2]))
    # JMatrix4d::MatrixRot's sense (as <initials><rotateaxis>): +90 degrees about y takes x to +z
    np.testing.assert_allclose(z[1]["vecs"], [[0, 0, 0.1], [0, 2, 0], [-0.2, 0, 0]], atol=1e-12)
    np.testing.assert_allclose(z[2]["vecs"], [[0.1, 0, 0.1], [0, 2, 0], [-0.1, 0, 0.1]])


def test_flat_oblique_zone_is_refused(tmp_path):
    r = _gencase(tmp_path, """<shifting><mode value="3" />
        <shiftingzone><posref x="0" y="-1" z="0" /><vecx x="0.1" y="0" z="0.1" /><vecy x="0" y="2" z="0" />
            <vecz x="0.2" y="0" z="0.2" /></shiftingzone></shifting>""")
    assert r.exit_code == 2, r.output
    assert "span no volume" in r.output


def _final_positions(tmp_path, name, special):
    case = _case(tmp_path, special, name=name)
    out = tmp_path / f"out_{name}"
    r = CliRunner().invoke(main, ["run", case, "-o", str(out), "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    path = str(out / "particles.vtkhdf")
    last = read_step(path, len(step_times(path)) - 1)
    return last["points"][np.argsort(last["Idp"])]


def test_a_zone_away_from_the_fluid_shifts_nothing(tmp_path):
    """DualSPHysics: particles outside every zone get no shift, so a far zone is no shifting."""
    none = _final_positions(tmp_path, "none", '<shifting><mode value="0" /></shifting>')
    far = _final_positions(tmp_path, "far", """<shifting><mode value="3" /><shiftingzone><posref x="5" y="-1" z="5" />
        <size x="0.1" y="2" z="0.1" /></shiftingzone></shifting>""")
    full = _final_positions(tmp_path, "full", '<shifting><mode value="3" /></shifting>')
    assert np.array_equal(far, none)
    assert np.abs(full - none).max() > 1e-7

"""``<special><inout>`` read as DualSPHysics v5 reads it (sphdvi.case.inout_xml): what it accepts,
and each refusal an error naming the line and what was expected (exit 2)."""
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.simulation import find_case_file

SLAB = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.2" /></drawbox>
                    <setmkfluid mk="1" />
                    <drawbox><boxfill>left</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.2" /></drawbox>"""

GOOD = """<inoutzone>
                    <refilling value="1" /><inputtreatment value="2" /><layers value="4" />
                    <zone2d><particles mkfluid="1" direction="right" /></zone2d>
                    <imposevelocity mode="0"><velocity v="0.5" /></imposevelocity>
                    <imposerhop mode="1" />
                    <imposezsurf mode="0"><zsurf value="0.15" /><remove value="true" /></imposezsurf>
                </inoutzone>"""


def _gencase(tmp_path, zones, head="", commands=SLAB):
    text = case_xml(dp="0.02", pointmin=("-0.2", "0", "-0.1"), pointmax=("0.8", "0", "0.3"), commands=commands,
                    special=f"<inout>{head}{zones}</inout>",
                    parameters='<parameter key="TimeMax" value="0.1" /><parameter key="TimeOut" value="0.1" />')
    case = write_case(tmp_path, text, "CaseIO_Def.xml")
    out = tmp_path / "g"
    return CliRunner().invoke(main, ["gencase", case, "-o", str(out)]), out


def test_a_v5_zone_is_read(tmp_path):
    r, out = _gencase(tmp_path, GOOD, '<memoryresize size0="2" size="4" /><determlimit value="1e-3" />'
                                      '<extrapolatemode value="3" /><useboxlimit value="false" />')
    assert r.exit_code == 0, r.output
    spec = read_case_h5(find_case_file(str(out)))["json"]["special"]["inout"]
    assert spec["determlimit"] == 1e-3 and spec["useboxlimit"] is False
    z = spec["zones"][0]
    assert (z["refilling"], z["inputtreatment"], z["layers"]) == (1, 2, 4)
    assert z["shape"] == {"kind": "particles", "line": z["shape"]["line"], "mkfluid": 1, "direction": [1.0, 0.0, 0.0]}
    assert z["velocity"] == {"mode": 0, "profile": "uniform", "rows": [[0.0, 0.5]]}
    assert z["rhop"] == {"mode": 1} and z["zsurf"]["rows"] == [[0.0, 0.15]] and z["zsurf"]["remove"] is True


def test_line_zone_and_variable_tables(tmp_path):
    zone = """<inoutzone><refilling value="0" /><inputtreatment value="2" /><layers value="3" />
        <zone2d><line><point x="-0.01" z="0" /><point2 x="-0.01" z="0.2" /><rotate angle="10" /></line></zone2d>
        <imposevelocity mode="1"><velocitytimes2><timevalue time="0" v="0" v2="1" z="0" z2="0.2" />
            <timevalue time="1" v="1" v2="2" z="0" z2="0.2" /></velocitytimes2></imposevelocity>
        <imposerhop mode="2" />
        <imposezsurf mode="1"><zsurftimes><timevalue time="0" zsurf="0.1" /><timevalue time="1" zsurf="0.2" />
            </zsurftimes></imposezsurf></inoutzone>"""
    r, out = _gencase(tmp_path, zone)
    assert r.exit_code == 0, r.output
    z = read_case_h5(find_case_file(str(out)))["json"]["special"]["inout"]["zones"][0]
    # DualSPHysics's default direction of a line: (-vz, 0, vx), v = point2 - point (turned at the run)
    assert z["shape"]["kind"] == "line" and z["shape"]["direction"] == pytest.approx([-1.0, 0.0, 0.0])
    assert z["velocity"]["profile"] == "linear" and len(z["velocity"]["rows"]) == 2
    assert z["zsurf"]["rows"] == [[0.0, 0.1], [1.0, 0.2]]


@pytest.mark.parametrize("zones, message", [
    (GOOD.replace('<layers value="4" />', ''), "missing child element <layers>"),
    (GOOD.replace('<layers value="4" />', '<layers value="0" />'), "below 1"),
    (GOOD.replace('<refilling value="1" />', '<refilling value="3" />'), "above 2"),
    (GOOD.replace('<imposevelocity mode="0"><velocity v="0.5" /></imposevelocity>',
                  '<imposevelocity mode="3"><gridveldata file="g.csv" /></imposevelocity>'), "mode=\"3\""),
    (GOOD.replace('<velocity v="0.5" />', '<jetcircle v="1" distance="1" radius="1" />'), "<jetcircle>"),
    (GOOD.replace('<velocity v="0.5" />', '<velocity v="0.5" /><flowvelocity active="true" />'), "flowvelocity"),
    (GOOD.replace('<imposezsurf mode="0"><zsurf value="0.15" /><remove value="true" /></imposezsurf>', ''),
     "needs a free-surface level"),
    (GOOD.replace('<refilling value="1" />', '<userefilling value="true" />'), "<userefilling>"),
    (GOOD.replace('<imposerhop mode="1" />', '<imposerhop mode="1"><zsurf value="1" /></imposerhop>'),
     "<zsurf> in <imposerhop>"),
    (GOOD.replace('<velocity v="0.5" />', '<velocity v="-0.5" />'), "invalid for an outflow"),
    (GOOD.replace('<zone2d><particles mkfluid="1" direction="right" /></zone2d>',
                  '<zone2d><particles mkfluid="3" direction="right" /></zone2d>'), "which has no particles"),
    (GOOD.replace('<zone2d><particles mkfluid="1" direction="right" /></zone2d>',
                  '<zone3d><box><point x="0" y="0" z="0" /><size x="0" y="1" z="1" /><direction x="1" y="0" z="0" />'
                  '</box></zone3d>'), "<zone3d> in a 2D case"),
    (GOOD.replace('direction="right"', 'direction="back"'), "along y"),
    (GOOD.replace('<imposevelocity mode="0"><velocity v="0.5" /></imposevelocity>',
                  '<imposevelocity mode="1"><velocityfile file="missing.csv" /></imposevelocity>'), "not found"),
])
def test_refusals_name_the_element(tmp_path, zones, message):
    r, _ = _gencase(tmp_path, zones)
    assert r.exit_code == 2, r.output
    assert message in r.output and "CaseIO_Def.xml:" in r.output and "Traceback" not in r.output


def test_a_velocity_file_error_names_its_line(tmp_path):
    (tmp_path / "vel.csv").write_text("time;v\n0;1\n0.5;x\n")
    zones = GOOD.replace('<imposevelocity mode="0"><velocity v="0.5" /></imposevelocity>',
                         '<imposevelocity mode="1"><velocityfile file="vel.csv" /></imposevelocity>')
    r, _ = _gencase(tmp_path, zones)
    assert r.exit_code == 2 and "vel.csv:3" in r.output, r.output


def test_a_buffer_outside_the_domain_stops_the_run(tmp_path):
    """The buffer's layers behind the plane must lie in the simulation domain (DualSPHysics:
    "Point for inlet conditions ... is outside the domain"): exit 2 naming the zone and the point."""
    text = case_xml(dp="0.02", pointmin=("-0.05", "0", "-0.1"), pointmax=("0.8", "0", "0.3"), commands=SLAB,
                    special=f"<inout>{GOOD}</inout>",
                    parameters='<parameter key="TimeMax" value="0.01" /><parameter key="TimeOut" value="0.01" />')
    case = write_case(tmp_path, text, "CaseIO_Def.xml")
    r = CliRunner().invoke(main, ["run", case, "-o", str(tmp_path / "o"), "--quiet"])
    assert r.exit_code == 2, r.output
    assert "inout zone 0" in r.output and "outside the simulation domain" in r.output


WALLS = SLAB + """
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.1" y="-1" z="-0.05" /><size x="0.8" y="2" z="0.04" />
                    </drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.1" y="-1" z="0.25" /><size x="0.8" y="2" z="0.04" />
                    </drawbox>"""


def _gencase_bc(tmp_path, boundcorr):
    text = case_xml(dp="0.02", pointmin=("-0.2", "0", "-0.1"), pointmax=("0.8", "0", "0.4"), commands=WALLS,
                    special=f"<inout>{GOOD}</inout>{boundcorr}",
                    parameters='<parameter key="TimeMax" value="0.1" /><parameter key="TimeOut" value="0.1" />')
    case = write_case(tmp_path, text, "CaseIO_Def.xml")
    out = tmp_path / "g"
    return CliRunner().invoke(main, ["gencase", case, "-o", str(out)]), out


def test_boundcorr_is_read(tmp_path):
    r, out = _gencase_bc(tmp_path, """<boundcorr><determlimit value="1e-3" /><extrapolatemode value="2" />
        <mkzone mkbound="0"><autoconfig direction="top" /></mkzone>
        <mkzone mkbound="1"><autolimitpoint dpfactor="0.5" /><direction x="0" y="0" z="-1" /></mkzone>
        </boundcorr>""")
    assert r.exit_code == 0, r.output
    bc = read_case_h5(find_case_file(str(out)))["json"]["special"]["boundcorr"]
    assert bc["determlimit"] == 1e-3
    assert bc["zones"][0]["mkbound"] == [0] and bc["zones"][0]["auto"] == "top"
    assert bc["zones"][0]["direction"] == [0.0, 0.0, 1.0]
    assert bc["zones"][1]["dpfactor"] == 0.5 and bc["zones"][1]["direction"] == [0.0, 0.0, -1.0]


@pytest.mark.parametrize("boundcorr, message", [
    ('<boundcorr><mkzone mkbound="0"><autoconfig direction="up" /></mkzone></boundcorr>', "is not recognised"),
    ('<boundcorr><mkzone mkbound="0,0-1"><autoconfig direction="top" /></mkzone>'
     '<mkzone mkbound="1"><autoconfig direction="top" /></mkzone></boundcorr>', "in two <mkzone>"),
    ('<boundcorr><mkzone mkbound="7"><autoconfig direction="top" /></mkzone></boundcorr>', "has no particles"),
    ('<boundcorr><mkzone mkbound="0"><direction x="0" y="0" z="1" /></mkzone></boundcorr>',
     "missing child element <limitpoint>"),
    ('<boundcorr><determlimit value="1e-3" /></boundcorr>', "has no <mkzone>"),
])
def test_boundcorr_refusals(tmp_path, boundcorr, message):
    r, _ = _gencase_bc(tmp_path, boundcorr)
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output

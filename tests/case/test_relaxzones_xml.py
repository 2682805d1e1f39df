"""``<special><relaxationzones>`` read as DualSPHysics reads it (sphdvi.case.relaxzones_xml): its
defaults, and each refusal an error naming the line and what was expected (exit 2)."""
import re

import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.simulation import find_case_file

REGULAR = """<rzwaves_regular>
                    <waveheight value="0.03" /><waveperiod value="1.2" /><depth value="0.3" /><swl value="0.3" />
                    <center x="0" y="0" z="0" /><width value="1" />
                </rzwaves_regular>"""

SPECTRUM = """<rzwaves_spectrum>
                    <spectrum value="jonswap" /><waveheight value="0.04" /><waveperiod value="1.4" /><waves value="20" />
                    <randomseed value="3" /><depth value="0.3" /><swl value="0.3" /><center x="0" y="0" z="0" />
                    <width value="1" /><ramptime value="2" />
                    <saveserie timemin="0" timemax="10" timedt="0.1" xpos="1" />
                </rzwaves_spectrum>"""

UNIFORM = """<rzwaves_uniform>
                    <start value="0.5" /><duration value="2" />
                    <domainbox><point x="0.3" y="-0.05" z="0" /><size x="0.4" y="0.1" z="0.2" />
                        <direction x="-1" y="0" z="0" />
                        <rotateaxis angle="-45" anglesunits="degrees"><point1 x="0.3" y="0" z="0" />
                            <point2 x="0.3" y="1" z="0" /></rotateaxis></domainbox>
                    <velocitytimes><timevalue time="0" v="0" /><timevalue time="2" v="0.5" /></velocitytimes>
                    <coefdt value="0" /><function psi="0.8" beta="2" />
                </rzwaves_uniform>"""


def _gencase(tmp_path, zones):
    text = case_xml(special=f"<relaxationzones>{zones}</relaxationzones>",
                    parameters='<parameter key="TimeMax" value="0.1" /><parameter key="TimeOut" value="0.1" />')
    case = write_case(tmp_path, text, "CaseRZ_Def.xml")
    out = tmp_path / "g"
    return CliRunner().invoke(main, ["gencase", case, "-o", str(out)]), out


def _zones(out):
    return read_case_h5(find_case_file(str(out)))["json"]["special"]["relaxationzones"]


def test_a_regular_zone_takes_dualsphysics_defaults(tmp_path):
    r, out = _gencase(tmp_path, REGULAR)
    assert r.exit_code == 0, r.output
    z = _zones(out)[0]
    assert z["type"] == "rzwaves_regular"
    assert (z["start"], z["duration"], z["waveorder"], z["phase"], z["ramp"]) == (0.0, 0.0, 1, 0.0, 0.0)
    assert (z["coefdt"], z["psi"], z["beta"], z["driftcorrection"]) == (1000.0, 0.9, 1.0, 0.0)
    assert z["coefdir"] == [1.0, 0.0, 0.0] and z["center"] == [0.0, 0.0, 0.0] and z["width"] == 1.0


def test_a_spectrum_zone_reads_the_sea_state_and_its_outputs(tmp_path):
    r, out = _gencase(tmp_path, SPECTRUM.replace('<waves value="20" />', '<waves value="20" /><waveorder value="2" />'))
    assert r.exit_code == 0, r.output
    # DualSPHysics's relaxation kernels sum linear waves: a second order is warned about and not made
    assert "generates first-order waves" in r.output
    z = _zones(out)[0]
    assert (z["spectrum"], z["discretization"], z["peakcoef"], z["waves"], z["randomseed"]) == \
        ("jonswap", "stretched", 3.3, 20, 3)
    assert z["waveorder"] == 1 and z["ramptime"] == 2.0 and z["serieini"] == 0.0
    assert z["saveserie"] == {"timemin": 0.0, "timemax": 10.0, "timedt": 0.1, "xpos": 1.0}


def test_a_uniform_zone_reads_its_box_and_velocity_table(tmp_path):
    r, out = _gencase(tmp_path, UNIFORM)
    assert r.exit_code == 0, r.output
    z = _zones(out)[0]
    box = z["domainbox"]
    assert box["point"] == [0.3, -0.05, 0.0] and box["size"] == [0.4, 0.1, 0.2]
    assert box["direction"] == [-1.0, 0.0, 0.0]
    assert box["rotation"]["angle"] == pytest.approx(-0.7853981633974483)
    assert z["velocitytimes"] == [[0.0, 0.0], [2.0, 0.5]]
    assert (z["start"], z["duration"], z["coefdt"], z["psi"], z["beta"]) == (0.5, 2.0, 0.0, 0.8, 2.0)


def test_several_zones_are_kept_in_order(tmp_path):
    r, out = _gencase(tmp_path, REGULAR + UNIFORM)
    assert r.exit_code == 0, r.output
    assert [z["type"] for z in _zones(out)] == ["rzwaves_regular", "rzwaves_uniform"]


@pytest.mark.parametrize("zones, message", [
    ("<rzwaves_external_1d><filesvel value=\"a\" /></rzwaves_external_1d>", "<rzwaves_external_1d> is not supported"),
    ("<rzwaves_solitary />", "unknown relaxation zone <rzwaves_solitary>"),
    (REGULAR.replace('<width value="1" />', ''), "missing <width>"),
    (REGULAR.replace('<width value="1" />', '<width value="0" />'), "<width> must be positive"),
    (REGULAR.replace('<swl value="0.3" />', ''), "missing <swl>"),
    (REGULAR.replace('<width value="1" />', '<width value="1" /><waveorder value="3" />'), "waveorder 3"),
    (REGULAR.replace('<width value="1" />', '<width value="1" /><coefdt value="-1" />'), "<coefdt> value=-1"),
    (REGULAR.replace('<width value="1" />', '<width value="1" /><driftcorrection value="2" />'), "driftcorrection"),
    (REGULAR.replace('<width value="1" />', '<width value="1" /><coefdir x="2" y="0" z="0" />'), "<coefdir>"),
    (REGULAR.replace('<width value="1" />', '<width value="1" /><function psi="0" beta="1" />'), "psi > 0"),
    (REGULAR.replace('<width value="1" />', '<width value="1" /><wavedir x="1" />'), "unknown element <wavedir>"),
    (SPECTRUM.replace('<spectrum value="jonswap" />', ''), "missing <spectrum>"),
    (UNIFORM.replace('<size x="0.4" y="0.1" z="0.2" />', '<size x="0.4" y="0" z="0.2" />'), "three sizes > 0"),
    (UNIFORM.replace('<direction x="-1" y="0" z="0" />', '<direction x="0" y="0" z="0" />'), "zero vector"),
    (UNIFORM.replace('<velocitytimes><timevalue time="0" v="0" /><timevalue time="2" v="0.5" /></velocitytimes>', ''),
     "missing <velocity> or <velocitytimes>"),
])
def test_bad_zones_are_case_errors(tmp_path, zones, message):
    r, _ = _gencase(tmp_path, zones)
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output
    assert re.search(r"CaseRZ_Def\.xml:\d+: <", r.output)         # file, line, element

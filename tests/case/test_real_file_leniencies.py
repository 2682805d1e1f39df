"""What real DualSPHysics case files hold that sphdvi refused or warned about (an audit of 35
files: DualSPHysics v5.4's examples, DesignSPHysics's templates, a user's project):

* DesignSPHysics writes ``<!-- Case name: ... -->`` on the line before ``<?xml ...?>``; TinyXML
  (GenCase's reader) takes a declaration anywhere, XML only first;
* ``<!---wall boundaries--->``: TinyXML ends a comment at its first ``-->`` and reads nothing in it;
* label attributes DualSPHysics does not read: ``cmt`` (examples' ``<drawbox cmt="piston">``),
  ``objname`` (DesignSPHysics, on every object), ``name`` on ``<setmkfluid>``/``<setmkbound>``
  (examples/main/04_ExternalForces), ``<chrono datadir=".">`` (examples/chrono/06_ZipLine);
* a ``<floating>`` range naming mk blocks the geometry did not draw (examples/chrono/07
  DamBreak1Cube: "51-53" with one cube): GenCase applies it to the blocks that exist;
* a gauge whose ``<output value="false"/>`` the case gives on purpose (examples/others/GaugeSystem);
* the keys of DualSPHysics's separate non-Newtonian build: named as such, not "did you mean";
* a GenCase output file (``Case_out/Case.xml``) given as the case: its ``<execution>`` holds
  ``<uservars>`` (the exported variables DualSPHysics evaluates the execution section with) and
  ``<vtkout>`` (GenCase's list of shape files)."""
from __future__ import annotations

import numpy as np
import pytest
from casetext import case_xml, write_case          # tests/case (on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.gencase import build_case
from sphdvi.cli import main
from sphdvi.errors import CaseError

DESIGNSPHYSICS_HEAD = '<!-- Case name: MyCase -->\n'


def _gencase(tmp_path, text, name="Case_Def.xml"):
    path = write_case(tmp_path, text, name)
    r = CliRunner().invoke(main, ["gencase", path, "-o", str(tmp_path / "out"), "--overwrite"])
    return r.exit_code, r.output


def test_comment_before_the_xml_declaration(tmp_path):
    code, out = _gencase(tmp_path, DESIGNSPHYSICS_HEAD + case_xml())
    assert code == 0, out
    # the lines keep their numbers: an error further down names its own line
    text = DESIGNSPHYSICS_HEAD + case_xml(parameters='<parameter key="X" value="1"/>')
    line = next(k for k, s in enumerate(text.splitlines(), 1) if 'key="X"' in s)
    code, out = _gencase(tmp_path, text)
    assert code == 2 and "malformed XML" not in out
    assert f"Case_Def.xml:{line}: <parameter>: unknown parameter key 'X'" in out


def test_a_malformed_file_still_names_its_line(tmp_path):
    code, out = _gencase(tmp_path, DESIGNSPHYSICS_HEAD + case_xml().replace("</mkconfig>", "").replace(
        '<mkconfig boundcount="240" fluidcount="9" />', '<mkconfig boundcount="240" fluidcount="9">'))
    assert code == 2 and "malformed XML" in out and "Traceback" not in out


def test_comments_with_double_hyphens(tmp_path):
    text = case_xml(commands="""
                    <!---fluid--->
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="2" /></drawbox>
                    <!-- walls -- three of them - -->
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>""")
    code, out = _gencase(tmp_path, text)
    assert code == 0, out


def test_label_attributes_are_not_warned(tmp_path):
    text = case_xml(commands="""
                    <setmkfluid mk="0" name="FluidLeft" />
                    <drawbox cmt="water" objname="Fluid"><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="2" /></drawbox>
                    <setmkbound mk="0" name="Container" />
                    <drawbox objname="Tank"><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>""")
    code, out = _gencase(tmp_path, text)
    assert code == 0, out
    assert "unknown attribute" not in out
    # an attribute that is not a label is still named
    code, out = _gencase(tmp_path, text.replace('cmt="water"', 'colour="blue"'))
    assert code == 0 and "unknown attribute 'colour' ignored" in out


def test_casedef_requiredversion_is_not_warned(tmp_path):
    """GenCase_CaseTemplate.xml (v5.0.295): ``<casedef requiredversion="v5.0.295">``."""
    code, out = _gencase(tmp_path, case_xml().replace("<casedef>", '<casedef requiredversion="v5.0.295">'))
    assert code == 0 and "unknown attribute" not in out, out
    code, out = _gencase(tmp_path, case_xml().replace("<casedef>", '<casedef requiredversio="v5.0.295">'))
    assert code == 0 and "unknown attribute 'requiredversio' ignored" in out


FLOATING_COMMANDS = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="1" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>
                    <setmkbound mk="51" />
                    <drawbox><boxfill>solid</boxfill><point x="2" y="-1" z="0.5" /><size x="0.2" y="2" z="0.2" /></drawbox>"""


def test_floating_range_with_undrawn_blocks(tmp_path):
    """<floating mkbound="51-53"> with mk 51 alone drawn: one body (51); a warning names 52-53.
    A <floating> none of whose blocks were drawn is warned beside one that made a body (DualSPHysics's
    14_DEM CaseManyFloatings has such a <floating mkbound="2001-42000">), and an error when no
    <floating> made one."""
    floatings = '<floatings><floating mkbound="{}"><massbody value="10" /></floating></floatings>'
    code, out = _gencase(tmp_path, case_xml(commands=FLOATING_COMMANDS, casedef_extra=floatings.format("51-53")))
    assert code == 0, out
    assert "mkbound 52-53 of this <floating> drew no particles: it applies to mkbound 51" in out
    assert "Floating mkbound 51 (mk 61): 121 particles, mass 10 kg/m" in out
    assert "Floating mkbound 52" not in out and "Floating mkbound 53" not in out
    code, out = _gencase(tmp_path, case_xml(commands=FLOATING_COMMANDS, casedef_extra=floatings.format("60-62")))
    assert code == 2 and "floating mkbound 60-62 has no particles" in out
    both = floatings.format("51").replace("</floatings>", '<floating mkbound="60-40000" relativeweight="0.3" />'
                                                          '</floatings>')
    code, out = _gencase(tmp_path, case_xml(commands=FLOATING_COMMANDS, casedef_extra=both))
    assert code == 0, out
    assert "floating mkbound 60-40000 drew no particles: this <floating> makes no body (the others do)" in out
    assert "Floating mkbound 51 (mk 61): 121 particles" in out


def _gauge_case(output):
    special = ('<gauges><velocity name="G"><point x="0.5" y="0" z="0.5" />'
               f'{output}</velocity></gauges>')
    return case_xml(special=special)


def test_explicit_gauge_output_false_is_not_warned(tmp_path):
    code, out = _gencase(tmp_path, _gauge_case('<output value="false" />'))
    assert code == 0 and "writes no file" not in out
    code, out = _gencase(tmp_path, _gauge_case(""))
    assert code == 0 and "gauge 'G' writes no file" in out
    code, out = _gencase(tmp_path, _gauge_case('<output value="false" /><savevtkpart value="true" />'))
    assert code == 0 and "<savevtkpart> has no effect" in out and "computes nothing for it" in out
    code, out = _gencase(tmp_path, _gauge_case('<output value="true" /><savevtkpart value="true" />'))
    assert code == 0 and "<savevtkpart> has no effect" in out and "computes nothing" not in out


def test_non_newtonian_keys_are_named_as_such(tmp_path):
    code, out = _gencase(tmp_path, case_xml(parameters='<parameter key="RheologyTreatment" value="2" />'))
    assert code == 2 and "non-Newtonian build" in out and "ViscoTreatment" not in out
    code, out = _gencase(tmp_path, case_xml(special='<nnphases><phase mkfluid="0"><rhop value="1000" /></phase>'
                                                    '</nnphases>'))
    assert code == 2 and "<special><nnphases> belongs to DualSPHysics's separate multiphase non-Newtonian" in out


def test_dtfixed_given_a_file_points_to_dtfixedfile(tmp_path):
    """examples/others/ExternalDtFile (before v5) gave DtFixed a file; v5.4 refuses it as sphdvi does,
    and the message now says where a file goes."""
    code, out = _gencase(tmp_path, case_xml(parameters='<parameter key="DtFixed" value="DtData.txt" />'))
    assert code == 2 and "goes in DtFixedFile" in out and "Traceback" not in out
    code, out = _gencase(tmp_path, case_xml(parameters='<parameter key="DtFixed" value="0.0001" />'))
    assert code == 0, out


def _execution_extra(text, extra):
    return text.replace("</execution>", extra + "</execution>")


GENCASE_OUTPUT_EXTRA = """
        <uservars>
            <varstr name="Label" value="tank" />
            <varnum name="Tend" value="0.75" />
        </uservars>
        <vtkout mkboundfirst="11" mkfluidfirst="1">
            <vtkfile name="Case_Tank.vtk" mk="11" mkbound="0" />
        </vtkout>"""


def test_gencase_output_uservars_and_vtkout(tmp_path):
    """JCaseUserVars writes ``<varnum|varstr name value>``; JSph::LoadConfigVars defines them before
    the execution parameters are read, so ``#Tend`` works there."""
    text = _execution_extra(case_xml(parameters='<parameter key="TimeMax" value="#Tend*2" />'), GENCASE_OUTPUT_EXTRA)
    code, out = _gencase(tmp_path, text)
    assert code == 0 and "warning" not in out.lower(), out
    r = build_case(write_case(tmp_path, text), str(tmp_path / "out2"))
    assert r.case.parameters["TimeMax"] == 1.5


def test_uservars_disagreeing_with_the_case_keep_the_case_value(tmp_path):
    text = _execution_extra(
        case_xml(predefinition='<newvar Tend="0.5" />', parameters='<parameter key="TimeMax" value="#Tend*2" />'),
        GENCASE_OUTPUT_EXTRA)
    code, out = _gencase(tmp_path, text)
    assert code == 0 and "uservars: Tend=0.75 differs from the case's own Tend=0.5" in out, out
    r = build_case(write_case(tmp_path, text), str(tmp_path / "out2"))
    assert r.case.parameters["TimeMax"] == 1.0


def test_uservars_bad_entries(tmp_path):
    code, out = _gencase(tmp_path, _execution_extra(case_xml(), '<uservars><var name="A" value="1"/></uservars>'))
    assert code == 2 and "unknown element <var> in <uservars>" in out and "Traceback" not in out
    code, out = _gencase(tmp_path, _execution_extra(case_xml(), '<uservars><varnum name="1A" value="1"/></uservars>'))
    assert code == 2 and "'1A' is not a valid variable name" in out
    code, out = _gencase(tmp_path, _execution_extra(case_xml(), '<uservars><varnum name="A" value="x"/></uservars>'))
    assert code == 2 and "<varnum>" in out and "Traceback" not in out


def test_a_gencase_output_file_reads_as_its_case(tmp_path):
    """GenCase v5.0.222's output for DualSPHysics's examples/main/01_DamBreak (CaseDambreak_out/
    CaseDambreak.xml in yzhao469/DualSPHysicsAgent_v1, a copy of the v5.4 package with its outputs):
    its <execution> carries <particles>, <constants>, <motion/> and <vtkout>; sphdvi draws the same
    particles per mk and the same h and B as that record."""
    from gencase_output_cases import CASEDAMBREAK_OUT      # tests/case (on the path: conftest)
    path = write_case(tmp_path, CASEDAMBREAK_OUT, "CaseDambreak.xml")
    r = build_case(path, str(tmp_path / "out"))
    counts = {int(m): int((r.particles["mk"] == m).sum()) for m in np.unique(r.particles["mk"])}
    assert counts == {10: 39993, 11: 2383, 20: 810, 1: 128310}
    assert r.constants.h == pytest.approx(0.014722431864, rel=1e-10)
    assert r.constants.b == pytest.approx(162005.14286, rel=1e-9)
    assert not [w for w in r.warnings if "unknown" in w]


def test_bare_v5_normals_with_svshapes_read_silently(tmp_path):
    """DualSPHysics v5.0's bare <normals> (<distanceh>, <geometryfile>, <svshapes> directly
    inside; mdbc/04 CaseDamBreak3D): <svshapes value> got an unknown-attribute warning."""
    from casetext import TANK_2D
    hdp = ('<setactive drawpoints="0" drawshapes="1"/><setmkbound mk="0"/><drawbox>'
           '<boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0"/><size x="4" y="2" z="3"/>'
           '<layers vdp="-0.5"/></drawbox><shapeout file="hdp"/><resetdraw/>')
    normals = ('<normals><distanceh value="2.0"/><geometryfile file="[CaseName]_hdp_Actual.vtk"/>'
               '<svshapes value="1"/></normals>')
    text = case_xml(commands=hdp + TANK_2D, casedef_extra=normals, dp="0.05")
    r = build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    assert not [w for w in r.warnings if "svshapes" in w]
    assert r.normals is not None and np.any(r.normals != 0)


def test_temperature_special_is_a_named_refusal(tmp_path):
    """DualSPHysics's examples/main/99_Temperature has <special><temperature> (heat transfer):
    "unknown special section" before, now refused by name."""
    text = case_xml(special='<temperature><tempdef value="20"/></temperature>')
    with pytest.raises(CaseError, match=r"<special><temperature> is not supported by sphdvi"):
        build_case(write_case(tmp_path, text), str(tmp_path / "out"))


def test_boundextrap_is_named_as_boundcorrs_obsolete_name(tmp_path):
    """DualSPHysics refuses <special><boundextrap> ("The XML section 'boundextrap' is obsolete."): it is
    <boundcorr>'s earlier name, which the error says."""
    text = case_xml(special='<boundextrap><determlimit value="1e+3"/></boundextrap>')
    with pytest.raises(CaseError, match=r"<boundextrap> is the obsolete name of <boundcorr>") as e:
        build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    assert e.value.element == "boundextrap" and "<boundcorr> with the same content" in str(e.value)

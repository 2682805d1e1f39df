"""``<special><flexstrucs>`` read as DualSPHysics v5.4 reads it (sphdvi.case.flexstruc_xml): the body
dicts the run reads from the gencase output, each refusal of the reader and of gencase an error naming
the file, line and element (exit 2 from ``sphdvi gencase``, no traceback), the warnings, and
:func:`flexstruc_parameter_problem`'s refusals of the parameters."""
import re

import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.flexstruc_xml import flexstruc_parameter_problem, read_flexstrucs
from sphdvi.case.xmldoc import CaseReader, load_xml, strip_disabled
from sphdvi.cli import main
from sphdvi.errors import CaseError, Warnings
from sphdvi.io.casefile import read_case_h5
from sphdvi.simulation import find_case_file

# DualSPHysics's examples/flexstruc/02_TurekHron/CaseTurekHronCSM3 (no fluid; g = 2 m/s²)
CONSTANTS = """
        <constantsdef>
            <gravity x="0" y="0" z="-2.0" /><rhop0 value="1000" /><hswl value="0.0" auto="false" />
            <gamma value="7" /><speedsystem value="5" auto="false" /><coefsound value="10" />
            <speedsound value="0" auto="true" /><coefh value="1.0" /><cflnumber value="0.1" />
        </constantsdef>"""
# the clamp: a circle, mk 0; the beam: a box, mk 1, drawn after it; mk 2: another box (fixed, moving or
# floating, as the test needs), clear of the beam
COMMANDS = """
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <drawsphere radius="0.05"><point x="0.2" y="0.0" z="0.2" /></drawsphere>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.2" y="-0.01" z="0.19" />
                        <size x="0.4" y="0.02" z="0.02" /></drawbox>
                    <setmkbound mk="2" />
                    <drawbox><boxfill>solid</boxfill><point x="0.3" y="-0.01" z="0.0" />
                        <size x="0.1" y="0.02" z="0.02" /></drawbox>"""
MVNULL = """<objreal ref="{mk}"><begin mov="1" start="0" /><mvnull id="1" /></objreal>"""
MOTION = "\n        <motion>" + MVNULL.format(mk=1) + "</motion>"
SYMPLECTIC = '<parameter key="StepAlgorithm" value="2" />'
TIMES = '<parameter key="TimeMax" value="0.1" /><parameter key="TimeOut" value="0.05" />'
MATERIAL = """<density value="1000.0" /><youngmod value="1.4e6" /><poissratio value="0.4" />
                    <constitmodel value="1" /><hgfactor value="0.0" />"""


def body(mkbound="1", mkclamp="0", material=MATERIAL, attrs=""):
    """One <flexstrucbody> (mkbound/mkclamp None: the attribute left out)."""
    head = "".join(f' {k}="{v}"' for k, v in (("mkbound", mkbound), ("mkclamp", mkclamp)) if v is not None)
    return f"""
                <flexstrucbody{head}{attrs}>
                    {material}
                </flexstrucbody>"""


def flexstrucs(*bodies):
    return "\n            <flexstrucs>" + "".join(bodies if bodies else (body(),)) + "\n            </flexstrucs>"


def _case(tmp_path, special, *, motion=MOTION, floatings="", parameters=SYMPLECTIC, is2d=True):
    """The CSM3 case (2D) or a 3D slab of it, with ``special`` in <special>."""
    text = case_xml(dp="0.005" if is2d else "0.01", constants=CONSTANTS, commands=COMMANDS,
                    pointmin=("-0.1", "0" if is2d else "-0.02", "-0.1"),
                    pointmax=("0.7", "0" if is2d else "0.02", "0.3"),
                    casedef_extra=floatings + motion, special=special, parameters=parameters + TIMES)
    return write_case(tmp_path, text, "CaseFlex_Def.xml")


def _read(tmp_path, special, **kw):
    """The reader's list (and the warnings) for a case whose <special> is ``special``."""
    path = _case(tmp_path, special, **kw)
    root, _ = load_xml(path)
    strip_disabled(root, path)
    warnings = Warnings()
    reader = CaseReader(path, warnings=warnings)
    reader.root = root
    return read_flexstrucs(reader, root.find("execution/special/flexstrucs")), list(warnings)


def _gencase(tmp_path, special, **kw):
    path = _case(tmp_path, special, **kw)
    out = tmp_path / "g"
    return CliRunner().invoke(main, ["gencase", path, "-o", str(out), "-q"]), out


def _line_of(path, text: str) -> int:
    """The 1-based line of the first line of file ``path`` that holds ``text``."""
    lines = open(path).read().splitlines()
    return next(i for i, ln in enumerate(lines, 1) if text in ln)


def test_the_turek_hron_csm3_body_reaches_the_gencase_output(tmp_path):
    r, out = _gencase(tmp_path, flexstrucs())
    assert r.exit_code == 0, r.output
    assert "warning" not in r.output
    line = _line_of(tmp_path / "CaseFlex_Def.xml", "<flexstrucbody")
    special = read_case_h5(find_case_file(str(out)))["json"]["special"]
    assert special["flexstrucs"] == [{"mkbound": 1, "mkclamp": [0], "density": 1000.0, "youngmod": 1.4e6,
                                      "poissratio": 0.4, "constitmodel": 1, "hgfactor": 0.0, "line": line}]


def test_defaults_lists_order_and_inactive_bodies(tmp_path):
    no_hg = MATERIAL.replace('<hgfactor value="0.0" />', "").replace('value="1"', 'value="2"')
    bodies, warnings = _read(tmp_path, flexstrucs(body("1", "0,3-4", no_hg), body("2", "9", attrs=' active="false"'),
                                                  body("5", " 0 ", MATERIAL.replace('"0.0"', '"0.1"'))))
    assert not warnings
    assert [(b["mkbound"], b["mkclamp"], b["constitmodel"], b["hgfactor"]) for b in bodies] == \
        [(1, [0, 3, 4], 2, 0.0), (5, [0], 1, 0.1)]
    assert bodies[0]["line"] < bodies[1]["line"]
    assert all(set(b) == {"mkbound", "mkclamp", "density", "youngmod", "poissratio", "constitmodel", "hgfactor",
                          "line"} for b in bodies)


def test_an_empty_section_is_accepted_with_a_warning(tmp_path):
    for special in ("\n            <flexstrucs />", flexstrucs(body(attrs=' active="false"'))):
        r, out = _gencase(tmp_path, special)
        assert r.exit_code == 0, r.output
        assert "<flexstrucs>: <flexstrucs> holds no active <flexstrucbody>: it does nothing" in r.output
        assert read_case_h5(find_case_file(str(out)))["json"]["special"]["flexstrucs"] == []


def test_an_inactive_section_is_left_out(tmp_path):
    r, out = _gencase(tmp_path, flexstrucs().replace("<flexstrucs>", '<flexstrucs active="false">'))
    assert r.exit_code == 0, r.output
    assert "flexstrucs" not in read_case_h5(find_case_file(str(out)))["json"]["special"]


def test_a_3d_case_takes_st_venant_kirchhoff_only(tmp_path):
    svk = MATERIAL.replace('<constitmodel value="1" />', '<constitmodel value="3" />')
    bodies, _ = _read(tmp_path, flexstrucs(body(material=svk)), is2d=False)
    assert bodies[0]["constitmodel"] == 3
    with pytest.raises(CaseError, match=r"constitmodel value=1 \(plane strain\) in a 3D case .*\"Constitutive model "
                                        r"for body 0 is not valid for 3D simulations\.\""):
        _read(tmp_path, flexstrucs(), is2d=False)


SEVENTEEN = flexstrucs(*(body(str(mk), "0") for mk in range(1, 18)))
READER_ERRORS = [
    (flexstrucs().replace("</flexstrucs>", "<body /></flexstrucs>"), "body",
     "unknown element <body> inside <flexstrucs>"),
    (flexstrucs(body(material=MATERIAL + "<youngsmod value=\"1\" />")), "youngsmod",
     "unknown element <youngsmod> inside <flexstrucbody>"),
    (flexstrucs(body(mkbound=None)), "flexstrucbody", "missing attribute 'mkbound'"),
    (flexstrucs(body(mkclamp=None)), "flexstrucbody", "missing attribute 'mkclamp'"),
    (flexstrucs(body(material=MATERIAL.replace('<density value="1000.0" />', ""))), "flexstrucbody",
     "missing <density>"),
    (flexstrucs(body(material=MATERIAL.replace('<youngmod value="1.4e6" />', ""))), "flexstrucbody",
     "missing <youngmod>"),
    (flexstrucs(body(material=MATERIAL.replace('<poissratio value="0.4" />', ""))), "flexstrucbody",
     "missing <poissratio>"),
    (flexstrucs(body(material=MATERIAL.replace('<constitmodel value="1" />', ""))), "flexstrucbody",
     "missing <constitmodel>"),
    (flexstrucs(body(material=MATERIAL + '<density value="2" />')), "density", "a second <density> inside"),
    (flexstrucs(body(mkclamp="0;2")), "flexstrucbody", "mkclamp: '0;2' in mk list"),
    (flexstrucs(body(mkclamp="0,2-9")), "flexstrucbody", 'mkclamp="0,2-9" names 9 mks; expected at most 8'),
    (flexstrucs(body(mkbound="-1")), "flexstrucbody", "mkbound='-1' is below 0"),
    (SEVENTEEN, "flexstrucbody", "a 17th <flexstrucbody> (DualSPHysics: \"Maximum number of flexible structure "
                                 "bodies has been reached.\")"),
    (flexstrucs(body(), body("1", "2")), "flexstrucbody", "flexible structure mkbound=1 is already configured"),
    (flexstrucs(body(), body("2", "1")), "flexstrucbody", "mkclamp 1 is a flexible structure (DualSPHysics: "
                                                          "\"MkClamp for mkbound=2 cannot be a flexible structure.\")"),
    (flexstrucs(body("1", "0,1")), "flexstrucbody", "mkclamp 1 is a flexible structure"),
    (flexstrucs(body(material=MATERIAL.replace('<constitmodel value="1" />', '<constitmodel value="4" />'))),
     "constitmodel", "\"Constitutive model for body 0 is not valid.\""),
    (flexstrucs(body(material=MATERIAL.replace('<constitmodel value="1" />', '<constitmodel value="1.5" />'))),
     "constitmodel", "value='1.5' is not an integer"),
    (flexstrucs(body(), body("2", "0", MATERIAL.replace('<constitmodel value="1" />', '<constitmodel value="3" />'))),
     "constitmodel", "constitmodel value=3 (St Venant-Kirchhoff) in a 2D case (DualSPHysics: \"Constitutive model "
                     "for body 1 is not valid for 2D simulations.\"); expected 1 (plane strain) or 2"),
    (flexstrucs(body(material=MATERIAL.replace('"1000.0"', '"0"'))), "density", "density value=0 is out of range"),
    (flexstrucs(body(material=MATERIAL.replace('"1.4e6"', '"-1e6"'))), "youngmod", "youngmod value=-1e+06 is out"),
    (flexstrucs(body(material=MATERIAL.replace('"0.4"', '"0.5"'))), "poissratio", "poissratio value=0.5 is out of "
                                                                                  "range; expected a Poisson's ratio"),
    (flexstrucs(body(material=MATERIAL.replace('"0.4"', '"-1"'))), "poissratio", "poissratio value=-1 is out"),
    (flexstrucs(body(material=MATERIAL.replace('<hgfactor value="0.0" />', '<hgfactor value="-0.1" />'))),
     "hgfactor", "hgfactor value=-0.1 is out of range"),
]


@pytest.mark.parametrize("special, element, message", READER_ERRORS)
def test_bad_sections_are_case_errors(tmp_path, special, element, message):
    with pytest.raises(CaseError) as exc:
        _read(tmp_path, special)
    assert message in str(exc.value)
    assert exc.value.element == element and exc.value.line and exc.value.file.endswith("CaseFlex_Def.xml")


@pytest.mark.parametrize("special, element, message", READER_ERRORS[::4])
def test_gencase_exits_2_without_a_traceback(tmp_path, special, element, message):
    r, _ = _gencase(tmp_path, special)
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output
    assert re.search(rf"CaseFlex_Def\.xml:\d+: <{element}>: ", r.output)


FLOATING = '\n        <floatings><floating mkbound="2" relativeweight="0.5" /></floatings>'
GENCASE_ERRORS = [
    (flexstrucs(body("2", "0")), {}, "flexstrucbody", "flexible structure mkbound 2 is a fixed boundary (it has no "
                                                      "<motion>) (DualSPHysics: \"MkBound value for mkbound=2 is not a "
                                                      "valid Mk moving boundary.\")"),
    (flexstrucs(body("7", "0")), {}, "flexstrucbody", "flexible structure mkbound 7 has no particles"),
    (flexstrucs(body("2", "0")), {"floatings": FLOATING}, "flexstrucbody",
     "flexible structure mkbound 2 is a floating body"),
    (flexstrucs(body("1", "0,7")), {}, "flexstrucbody", "mkclamp 7 of flexible structure mkbound 1 has no boundary "
                                                        "particles (DualSPHysics: \"MkClamp value for mkbound=1 is "
                                                        "not a valid Mk boundary.\")"),
    (flexstrucs(), {"parameters": SYMPLECTIC + '<parameter key="XPeriodicIncZ" value="0" />'}, "flexstrucs",
     "DualSPHysics: \"Flexible structures are not allowed with periodic conditions.\""),
    (flexstrucs(), {"parameters": SYMPLECTIC + '<parameter key="Boundary" value="2" />'}, "flexstrucs",
     "DualSPHysics: \"Flexible structures are not allowed with original mDBC (SlipMode=1).\""),
    (flexstrucs(), {"parameters": '<parameter key="Boundary" value="2" /><parameter key="SlipMode" value="2" />'},
     "flexstrucs", "DualSPHysics: \"Flexible structures with mDBC are not allowed with Verlet.\""),
]


@pytest.mark.parametrize("special, kw, element, message", GENCASE_ERRORS)
def test_gencase_refuses_what_needs_the_particles_and_parameters(tmp_path, special, kw, element, message):
    r, _ = _gencase(tmp_path, special, **kw)
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output
    m = re.search(rf"CaseFlex_Def\.xml:(\d+): <{element}>: ", r.output)
    assert m and int(m.group(1)) == _line_of(tmp_path / "CaseFlex_Def.xml", f"<{element}")


def test_a_moving_clamp_and_mdbc_with_symplectic_are_accepted(tmp_path):
    motion = "\n        <motion>" + MVNULL.format(mk=1) + MVNULL.format(mk=2) + "</motion>"
    mdbc = SYMPLECTIC + '<parameter key="Boundary" value="2" /><parameter key="SlipMode" value="2" />'
    r, out = _gencase(tmp_path, flexstrucs(body("1", "0,2")), motion=motion, parameters=mdbc)
    assert r.exit_code == 0, r.output
    assert read_case_h5(find_case_file(str(out)))["json"]["special"]["flexstrucs"][0]["mkclamp"] == [0, 2]


def test_an_ignored_motion_and_a_floating_clamp_are_warned_about(tmp_path):
    motion = """
        <motion><objreal ref="1"><begin mov="1" start="0" />
            <mvrect id="1" duration="1"><vel x="0.1" y="0" z="0" /></mvrect></objreal></motion>"""
    r, _ = _gencase(tmp_path, flexstrucs(body("1", "0,2")), motion=motion, floatings=FLOATING)
    assert r.exit_code == 0, r.output
    objreal = _line_of(tmp_path / "CaseFlex_Def.xml", "<objreal")
    assert (f"CaseFlex_Def.xml:{objreal}: warning: <objreal>: the motion of flexible structure mkbound 1 (mvrect) is "
            "ignored") in r.output
    assert "<flexstrucbody>: mkclamp 2 of flexible structure mkbound 1 is a floating body: it clamps nothing" \
        in r.output


@pytest.mark.parametrize("params, periodic, expected", [
    ({"Boundary": 1, "SlipMode": 1, "StepAlgorithm": 1}, False, None),
    ({"Boundary": 2, "SlipMode": 2, "StepAlgorithm": 2}, False, None),
    ({"Boundary": 2, "SlipMode": 3, "StepAlgorithm": 2}, False, None),
    ({}, False, None),
    ({"Boundary": 1, "SlipMode": 1, "StepAlgorithm": 2}, True,
     "Flexible structures are not allowed with periodic conditions."),
    ({"Boundary": 2, "SlipMode": 1, "StepAlgorithm": 2}, False,
     "Flexible structures are not allowed with original mDBC (SlipMode=1)."),
    ({"Boundary": 2, "StepAlgorithm": 2}, False,
     "Flexible structures are not allowed with original mDBC (SlipMode=1)."),
    ({"Boundary": 2, "SlipMode": 2, "StepAlgorithm": 1}, False,
     "Flexible structures with mDBC are not allowed with Verlet."),
    ({"Boundary": 2, "SlipMode": 3}, False, "Flexible structures with mDBC are not allowed with Verlet."),
])
def test_the_parameter_problems(params, periodic, expected):
    assert flexstruc_parameter_problem(params, periodic) == expected

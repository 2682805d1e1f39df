"""The <chrono> section at gencase, against DualSPHysics v5.4's JChronoObjects::ReadXml,
ReadCoeffs/JLinearValue::LoadFile, CheckParams and JChronoData (audit hunt8/c findings 1, 4, 6-10):
stiffness/damping tables read as JReadDatafile reads them, one body per mkbound, contact materials
required when bodies collide, <collision activate> mandatory, DualSPHysics's link names, and a
warning for each option read but not applied."""
import re

import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

from sphdvi.case.gencase import build_case
from sphdvi.errors import CaseError

# a floor (mkbound 0) and two boxes (mkbounds 1 and 2) in the air, no fluid: gencase only
BODIES = """
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.6" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.1" y="-1" z="0.3" /><size x="0.1" y="2" z="0.06" /></drawbox>
                    <setmkbound mk="2" />
                    <drawbox><boxfill>solid</boxfill><point x="0.4" y="-1" z="0.3" /><size x="0.1" y="2" z="0.06" /></drawbox>"""
FLOATINGS = '<floatings><floating mkbound="1" rhopbody="500" /><floating mkbound="2" rhopbody="500" /></floatings>'
STEEL = '<property name="steel" Kfric="0.3" Restitution_Coefficient="0.5" Young_Modulus="2e11" PoissonRatio="0.3"/>'


def build(tmp_path, chrono, props="", files=None):
    """gencase of BODIES with ``chrono`` inside <chrono>; ``files``: {name: text} beside the case."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    for name, text in (files or {}).items():
        (tmp_path / name).write_text(text)
    extra = FLOATINGS + (f"<properties>{props}</properties>" if props else "")
    text = case_xml(pointmin=("-0.1", "0", "-0.1"), pointmax=("0.7", "0", "0.8"), commands=BODIES,
                    casedef_extra=extra, special=f"<chrono>{chrono}</chrono>",
                    parameters='<parameter key="RigidAlgorithm" value="3" />')
    return build_case(write_case(tmp_path, text), str(tmp_path / "out"))


def chrono_warnings(r):
    return [w for w in r.warnings if "no fluid" not in w and "fluid particles" not in w]


HINGE = ('<link_hinge idbody1="A"><rotpoint x="0.15" y="0" z="0.5"/><rotvector x="0" y="1" z="0"/>'
         '<stiffness file="k.txt"/></link_hinge>')


@pytest.mark.parametrize("text", ["0;10\n1;20\n", "time;k\n0;10\n1;20\n", "0\t10\n1\t20\n", "0 10\n1  20\n",
                                  "0,10\n1,20\n", "# k table\n0 10 # start\n1 20\n"])
def test_stiffness_file_separators(tmp_path, text):
    """A <stiffness file> as JReadDatafile reads it: ';', ',', spaces or tabs, a header, '#' comments
    (before, anything but ';' crashed at run start with an AxisError); read at gencase."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/>' + HINGE, files={"k.txt": text})
    (link,) = r.case.special["chrono"]["links"]
    assert link["stiffness"]["times"] == [0.0, 1.0] and link["stiffness"]["values"] == [10.0, 20.0]


@pytest.mark.parametrize("text, message", [
    ("0 10\n", r"k\.txt: one data row \(line 1\)"), ("# nothing\n", r"k\.txt: no data rows"),
    ("0 10\n1 x\n", r"k\.txt:2: .*'1 x' is not numeric"), ("0 10\n1 -5\n", r"k\.txt:2: stiffness -5 at time 1")])
def test_stiffness_file_errors(tmp_path, text, message):
    """Fewer than two rows ("Cannot be less than two values." in DualSPHysics), a bad value: a
    CaseError at gencase naming the file (and its line)."""
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <stiffness>: .*" + message):
        build(tmp_path, '<bodyfloating id="A" mkbound="1"/>' + HINGE, files={"k.txt": text})


@pytest.mark.parametrize("bodies", [
    '<bodyfloating id="B" mkbound="1"/><bodyfloating id="C" mkbound="1"/>',
    '<bodyfloating id="B" mkbound="1"/><bodyfixed id="C" mkbound="1"/>',
    '<bodyfloating id="B" mkbound="1-2"/><bodyfloating id="C" mkbound="2"/>'])
def test_mkbound_in_two_bodies(tmp_path, bodies):
    """One mkbound in two <chrono> bodies (any kinds, after range expansion) is refused, as
    JChronoData::CheckAddBodyError ("MkBound %u is already in use for other body"); before, one
    body free-fell as a phantom while the other got the particles' loads."""
    with pytest.raises(CaseError, match=r"<body\w+>: mkbound [12] is already in use for the body 'B2?' \(line \d+\)"):
        build(tmp_path, bodies)


COLLIDE = ('<collision activate="true"><contactmethod value="{cm}"/></collision>'
           '<bodyfixed id="floor" mkbound="0" modelfile="AutoActual"/>'
           '<bodyfloating id="A" mkbound="1" modelfile="AutoActual"/>')


@pytest.mark.parametrize("cm, props, missing", [
    (0, "", "it has no property"),
    (0, '<property name="p" Kfric="0.3"/><links><link mkbound="0-2" property="p"/></links>',
     "its property 'p' has no Restitution_Coefficient"),
    (1, '<property name="p" Kfric="0.3" Restitution_Coefficient="0"/><links><link mkbound="0-2" property="p"/></links>',
     "its property 'p' has no Young_Modulus or PoissonRatio")])
def test_collision_bodies_need_a_material(tmp_path, cm, props, missing):
    """A colliding body (modelfile, collisions on) without Kfric / Restitution_Coefficient (and
    Young_Modulus / PoissonRatio under SMC) is refused as JChronoObjects::CheckParams does; it got
    sphdvi's default material silently before."""
    with pytest.raises(CaseError, match=r"<bodyfixed>: chrono body 'floor' \(mkbound 0\) collides .*" + re.escape(missing)):
        build(tmp_path, COLLIDE.format(cm=cm), props)


def test_collision_materials_given(tmp_path):
    """Each colliding body's material by a <link> (a combined 'a + b' one too); a body without
    modelfile needs none."""
    props = (STEEL + '<property name="soft" Kfric_User="0.1"/><links><link mkbound="0" property="steel"/>'
             '<link mkbound="1" property="steel + soft"/></links>')
    r = build(tmp_path, COLLIDE.format(cm=1) + '<bodyfloating id="B" mkbound="2"/>', props)
    assert [b["id"] for b in r.case.special["chrono"]["bodies"]] == ["floor", "A", "B"]


def test_collision_activate_is_required(tmp_path):
    """<collision> without activate is refused (mandatory in DualSPHysics); activate="false"
    reads no children (DualSPHysics does not look at them)."""
    with pytest.raises(CaseError, match=r"<collision>: missing attribute 'activate'"):
        build(tmp_path / "a", '<collision><distancedp value="0.5"/></collision><bodyfloating id="A" mkbound="1"/>')
    r = build(tmp_path / "b", '<collision activate="false"><contactmethod value="7"/><whatever/></collision>'
                              '<bodyfloating id="A" mkbound="1" modelfile="AutoActual"/>')
    assert r.case.special["chrono"]["collision"]["activate"] is False


def spheric(name="", body2=""):
    return (f'<link_spheric idbody1="A"{f" idbody2={chr(34)}{body2}{chr(34)}" if body2 else ""}'
            f'{f" name={chr(34)}{name}{chr(34)}" if name else ""}><rotpoint x="0.15" y="0" z="0.5"/></link_spheric>')


def test_default_link_names(tmp_path):
    """DualSPHysics's names: Link_<id1>_<id2>, Link_<id1> to the ground, _2, _3 for repeats (an
    explicit name taking the default one pushes it on too)."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2"/>'
              + spheric() + spheric() + spheric(name="Link_A_3") + spheric() + spheric(body2="B") + spheric(body2="B"))
    names = [ln["name"] for ln in r.case.special["chrono"]["links"]]
    assert names == ["Link_A", "Link_A_2", "Link_A_3", "Link_A_4", "Link_A_B", "Link_A_B_2"]


def test_explicit_link_name_twice(tmp_path):
    """An explicit name used twice (or a default name used again) is refused
    (JChronoData::AddLink*: "Name='..' is already in use for other Link.")."""
    for links in (spheric(name="j") + spheric(name="j"), spheric() + spheric(name="Link_A")):
        with pytest.raises(CaseError, match=r"<link_spheric>: link name '(j|Link_A)' is already in use \(line \d+\)"):
            build(tmp_path, '<bodyfloating id="A" mkbound="1"/>' + links)


def test_options_not_applied_are_warned(tmp_path):
    """<timestepper value="1"> (HHT), imposefric and <savedata>: one warning each; timestepper 0
    (what sphdvi does) and savedata -1 (nothing written) none."""
    r = build(tmp_path / "a", '<savedata value="0.01"/><timestepper value="1" alpha="-0.3"/>'
              + COLLIDE.format(cm=0).replace('modelfile="AutoActual"/>', 'modelfile="AutoActual" imposefric="true"/>'),
              STEEL + '<links><link mkbound="0-2" property="steel"/></links>')
    w = chrono_warnings(r)
    assert len(w) == 4, w
    assert any("<timestepper>: HHT (timestepper 1, alpha -0.3) is not supported by sphdvi: the Euler implicit" in x
               for x in w)
    assert sum("imposefric is not supported by sphdvi" in x for x in w) == 2       # floor and box
    assert any("<savedata>: <savedata> (DualSPHysics's ChronoExchange_mkbound_XX.csv" in x and "bodies.csv" in x
               for x in w)
    r = build(tmp_path / "b", '<savedata value="-1"/><timestepper value="0"/><bodyfloating id="A" mkbound="1"/>')
    assert chrono_warnings(r) == []
    with pytest.raises(CaseError, match=r"<timestepper>: timestepper value 2; expected 0 .* or 1"):
        build(tmp_path / "c", '<timestepper value="2"/><bodyfloating id="A" mkbound="1"/>')


def test_coulombdamping_needs_rest_length(tmp_path):
    """<rest_length> is mandatory in a link_coulombdamping (DualSPHysics reads it without a default)."""
    link = ('<link_coulombdamping idbody1="A" idbody2="B"><point_fb1 x="0.15" y="0" z="0.33"/>'
            '<point_fb2 x="0.45" y="0" z="0.33"/><damping value="5"/></link_coulombdamping>')
    with pytest.raises(CaseError, match=r"<link_coulombdamping>: missing <rest_length>"):
        build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2"/>' + link)


def test_pulley_without_hinge_and_empty_section_warned(tmp_path):
    """A link_pulley whose first body is in no link_hinge: DualSPHysics's warning; a <chrono> with
    no body (DualSPHysics refuses it): a warning that every floating is a free body."""
    pulley = ('<link_pulley idbody1="A" idbody2="B"><rotpoint x="0.15" y="0" z="0.33"/>'
              '<rotvector x="0" y="1" z="0"/><radius value="0.1"/><radius2 value="0.05"/></link_pulley>')
    r = build(tmp_path / "a", '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2"/>' + pulley)
    (w,) = chrono_warnings(r)
    assert "<link_pulley>: the body 'A' also should belong to a link_hinge" in w
    hinge = '<link_hinge idbody1="A"><rotpoint x="0.15" y="0" z="0.33"/><rotvector x="0" y="1" z="0"/></link_hinge>'
    r = build(tmp_path / "b", '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2"/>' + hinge + pulley)
    assert chrono_warnings(r) == []
    r = build(tmp_path / "c", '<savedata value="-1"/>')
    (w,) = chrono_warnings(r)
    assert "<chrono>: <chrono> defines no body: DualSPHysics refuses it" in w and "every <floating> a free body" in w


def test_scaleforce_mkbounds(tmp_path):
    """<scaleforce><body mkbound="range" x y z/>: ranges as DualSPHysics; an mkbound of no chrono
    body is refused (DualSPHysics's GetBodyByMk throws), with no body listed a floating's passes."""
    r = build(tmp_path / "a", '<bodyfloating id="A" mkbound="1-2"/>'
              '<scaleforce><body mkbound="1-2" x="0.5" y="1" z="2"/></scaleforce>')
    (item,) = r.case.special["chrono"]["scaleforce"]
    assert item["mkbound"] == [1, 2] and item["scale"] == [0.5, 1.0, 2.0]
    with pytest.raises(CaseError, match=r"<body>: mkbound 2 is not a <chrono> body; expected .* \(1\)"):
        build(tmp_path / "b", '<bodyfloating id="A" mkbound="1"/><scaleforce><body mkbound="2" x="0" y="0" z="0"/>'
                              '</scaleforce>')
    with pytest.raises(CaseError, match=r"<body>: <scaleforce> mkbound 0 is not a floating body"):
        build(tmp_path / "c", '<scaleforce><body mkbound="0" x="0" y="0" z="0"/></scaleforce>')
    with pytest.raises(CaseError, match=r"missing attribute"):
        build(tmp_path / "d", '<bodyfloating id="A" mkbound="1"/><scaleforce><body mkbound="1" x="0"/></scaleforce>')


def test_chrono_gravity_is_said_once(tmp_path):
    """<chrono><gravity x y z> (older templates; not read by v5.4): one warning naming the gravity
    that applies, not three "unknown attribute" ones."""
    r = build(tmp_path, '<gravity x="0" y="0" z="-9.81"/><bodyfloating id="A" mkbound="1"/>')
    w = chrono_warnings(r)
    assert len(w) == 1 and "<chrono><gravity> is not read" in w[0], w

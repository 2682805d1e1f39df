"""Several <properties><links><link> reaching one mk, and links that name no property, as
DualSPHysics v5.4's JCaseProperties (src/source/JCaseProperties.cpp) reads them (audit hunt11/p
findings 1 and 2):

* JCasePropLinks::GetProps joins the properties of every link naming the mk ("a" in one link and
  "b" in another are "a+b" in one), GetPropsSort sorts the names and drops repeats, and
  JSph::LoadDemData takes each value from the first property of the sorted list that gives it (a
  ``*_User`` value first); sphdvi took the last link alone (and its collision check the first);
* JCasePropLinks::AddLink keeps a link only when its mk list and its property are non-empty once
  the blanks are dropped: a link with property="" is dropped (warned here), where sphdvi stopped
  with "property '' is not defined"."""
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.gencase import build_case
from sphdvi.cli import main
from sphdvi.errors import CaseError
from sphdvi.io.casefile import read_case_h5
from sphdvi.mechanism import _material_for, mechanism_from_case

# a floor (mkbound 0) and two boxes (mkbounds 1 and 2) above it, no fluid: gencase only
BODIES = """
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.6" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.1" y="-1" z="0.3" /><size x="0.1" y="2" z="0.1" /></drawbox>
                    <setmkbound mk="2" />
                    <drawbox><boxfill>solid</boxfill><point x="0.4" y="-1" z="0.3" /><size x="0.1" y="2" z="0.1" /></drawbox>"""
FLOATINGS = '<floatings><floating mkbound="1" rhopbody="500" /><floating mkbound="2" rhopbody="500" /></floatings>'
COLLIDE = ('<collision activate="true"><contactmethod value="0"/></collision>'
           '<bodyfixed id="floor" mkbound="0" modelfile="AutoActual"/>'
           '<bodyfloating id="A" mkbound="1" modelfile="AutoActual"/>'
           '<bodyfloating id="B" mkbound="2" modelfile="AutoActual"/>')
# three properties: a and b give different keys, b and c the same one
PROPS = ('<property name="a"><Kfric value="0.2"/></property>'
         '<property name="b"><Restitution_Coefficient value="0.6"/><Kfric value="0.4"/></property>'
         '<property name="c" Restitution_Coefficient="0.9" Kfric="0.7"/>')


def case_text(links, chrono=COLLIDE):
    extra = FLOATINGS + f"<properties>{PROPS}<links>{links}</links></properties>"
    return case_xml(pointmin=("-0.1", "0", "-0.1"), pointmax=("0.7", "0", "0.8"), commands=BODIES, dp="0.05",
                    casedef_extra=extra, special=f"<chrono>{chrono}</chrono>",
                    parameters='<parameter key="RigidAlgorithm" value="3" />')


def build(tmp_path, links, chrono=COLLIDE):
    tmp_path.mkdir(parents=True, exist_ok=True)
    return build_case(write_case(tmp_path, case_text(links, chrono)), str(tmp_path / "out"))


def materials(r, mkbound):
    """(name, spec) of an mkbound from the reader's output, as the run resolves it."""
    js = {"materials": {k: vars(v) for k, v in r.case.materials.items()}, "material_links": r.case.material_links}
    return _material_for(mkbound, js)


def link_warnings(r):
    return [w for w in r.warnings if "<link>" in w]


def test_two_links_with_different_keys_combine(tmp_path):
    """mkbound 1 linked to a (Kfric) and to b (Restitution_Coefficient, Kfric): both, Kfric from a,
    the first of the sorted pair; before, the last link (b) alone: Kfric 0.4."""
    r = build(tmp_path, '<link mkbound="1" property="b"/><link mkbound="1" property="a"/>'
                        '<link mkbound="0,2" property="c"/>')
    name, spec = materials(r, 1)
    assert name == "a + b" and (spec["friction"], spec["restitution"]) == (0.2, 0.6)


def test_two_links_equal_one_combined_link(tmp_path):
    """property="a+b" in one link and two links "a" and "b" (either order) are the same."""
    one = materials(build(tmp_path / "one", '<link mkbound="0-2" property="b + a"/>'), 1)
    for k, links in enumerate(['<link mkbound="0-2" property="a"/><link mkbound="0-2" property="b"/>',
                               '<link mkbound="0-2" property="b"/><link mkbound="0-2" property="a"/>']):
        assert materials(build(tmp_path / f"two{k}", links), 1) == one


def test_same_key_first_sorted_property_wins(tmp_path):
    """b and c both give Kfric and Restitution_Coefficient: c linked first, b second, b (sorted
    first) gives both, whatever the order of the links; a property named twice counts once."""
    r = build(tmp_path, '<link mkbound="0-2" property="c"/><link mkbound="0-2" property="b"/>'
                        '<link mkbound="2" property="c + c"/>')
    for mkb in (0, 1, 2):
        name, spec = materials(r, mkb)
        assert name == "b + c" and (spec["friction"], spec["restitution"]) == (0.4, 0.6)


def test_range_link_and_a_link_to_one_body(tmp_path):
    """A range covering the three bodies plus a link to one of them: that one has both
    properties, the others the range's only."""
    r = build(tmp_path, '<link mkbound="0-2" property="c"/><link mkbound="2" property="a"/>')
    assert materials(r, 0) == materials(r, 1) == ("c", {"name": "c", "friction": 0.7, "restitution": 0.9})
    name, spec = materials(r, 2)
    assert name == "a + c" and (spec["friction"], spec["restitution"]) == (0.2, 0.9)


def test_user_value_of_any_linked_property_wins(tmp_path):
    """A *_User value of a property from a second link wins over the first property's plain value."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    text = case_text('<link mkbound="0-2" property="c"/><link mkbound="1" property="z"/>').replace(
        "</properties>", '<property name="z" Kfric_User="0.05"/></properties>')
    r = build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    name, spec = materials(r, 1)
    assert name == "c + z" and (spec["friction"], spec["restitution"]) == (0.05, 0.9)


def test_collision_check_sees_every_link(tmp_path):
    """The gencase check of a colliding body's material reads all its links: a Kfric from one and a
    Restitution_Coefficient from another pass (before: the first link only, "its property 'a' has
    no Restitution_Coefficient"); a body with neither still stops."""
    build(tmp_path / "ok", '<link mkbound="0-2" property="a"/><link mkbound="0-2" property="b"/>')
    with pytest.raises(CaseError, match=r"chrono body 'A' \(mkbound 1\) collides .*its property 'a' has no "
                                        r"Restitution_Coefficient"):
        build(tmp_path / "bad", '<link mkbound="0-2" property="a"/><link mkbound="0,2" property="b"/>')


def test_the_run_gets_the_combined_materials(tmp_path):
    """gencase + mechanism_from_case on a body-only case: each body's contact material is the
    combination of its links."""
    case = write_case(tmp_path, case_text('<link mkbound="0-2" property="c"/><link mkbound="1" property="b"/>'
                                          '<link mkbound="1" property="a"/>'))
    res = CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    mech = mechanism_from_case(read_case_h5(str(next((tmp_path / "out").glob("*.h5")))))
    by_name = {m["name"]: m for m in mech["materials"]}
    used = [b["shapes"][0]["material"] for b in mech["bodies"]]
    assert used == ["c", "a + b + c", "c"]
    assert (by_name["a + b + c"]["friction"], by_name["a + b + c"]["restitution"]) == (0.2, 0.6)
    assert (by_name["c"]["friction"], by_name["c"]["restitution"]) == (0.7, 0.9)


@pytest.mark.parametrize("written", ["", "   ", "+", " + "])
def test_link_without_property_is_dropped_with_a_warning(tmp_path, written):
    """property="" (or blanks): JCasePropLinks::AddLink drops the link; sphdvi drops it too, with a
    warning naming the file and line (before: "property '' is not defined", exit 2)."""
    r = build(tmp_path, f'<link mkbound="0-2" property="c"/><link mkbound="1" property="{written}"/>')
    assert [ln["property"] for ln in r.case.material_links] == ["c"]
    (w,) = link_warnings(r)
    assert "Case_Def.xml:" in w and f"property={written!r} names no property: the link is dropped" in w
    assert materials(r, 1)[0] == "c"


def test_link_without_property_reads_no_mk_list(tmp_path):
    """The dropped link's mk list is not read (DualSPHysics never parses it), nor warned as unknown."""
    r = build(tmp_path, '<link mkbound="0-2" property="c"/><link mkbound="x" property=""/>')
    (w,) = link_warnings(r)
    assert "names no property" in w and "unknown attribute" not in w


def test_trailing_plus_names_one_property(tmp_path):
    """property="a+" is "a" (GetPropsSort skips the empty name; it was "property '' is not defined")."""
    r = build(tmp_path, '<link mkbound="0-2" property="c+"/>')
    assert r.case.material_links[0]["property"] == "c" and link_warnings(r) == []

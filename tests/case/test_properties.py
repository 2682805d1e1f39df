"""<properties>: property names and <link> particles read as DualSPHysics's JCaseProperties
(src/source/JCaseProperties.cpp): names without spaces, found whatever the case of their letters;
a <link> by mkbound, else mkfluid, else the global mk."""
import pytest
from casetext import TANK_2D, case_xml, write_case

from sphdvi.case.gencase import build_case
from sphdvi.errors import CaseError

STEEL = ('<property name="steel"><Young_Modulus value="2.1e11"/><PoissonRatio value="0.3"/>'
         '<Restitution_Coefficient value="0.8"/><Kfric value="0.45"/></property>')
FLOATING_BOX = """
    <setmkbound mk="50" />
    <drawbox><boxfill>solid</boxfill><point x="2" y="-1" z="0.5" /><size x="0.2" y="2" z="0.2" /></drawbox>"""


def build(tmp_path, props, commands=TANK_2D, floatings=""):
    tmp_path.mkdir(parents=True, exist_ok=True)
    xml = case_xml(commands=commands, casedef_extra=floatings + f"<properties>{props}</properties>")
    return build_case(write_case(tmp_path, xml), str(tmp_path / "out"))


def test_link_by_global_mk(tmp_path):
    """<link mk=..>: the global mk (JCasePropLinks::ReadXml's LINK_Mk): with fluidcount 9, mk 10
    is mkbound 0 and mk 1 is mkfluid 0 (it was refused: "missing mkbound or mkfluid")."""
    r = build(tmp_path, STEEL + '<links><link mk="1,10" property="steel"/></links>')
    assert r.case.material_links == [{"property": "steel", "line": r.case.material_links[0]["line"],
                                      "mkbound": [0], "mkfluid": [0]}]
    assert not any("<link>" in w for w in r.warnings)


def test_link_mkbound_first_as_dualsphysics(tmp_path):
    """mkbound wins over mkfluid and mk (ReadXml reads the first of them only): the others are
    warned about, not read."""
    r = build(tmp_path, STEEL + '<links><link mkbound="0" mk="1" property="steel"/></links>')
    assert r.case.material_links[0]["mkbound"] == [0] and "mkfluid" not in r.case.material_links[0]
    assert any("mkbound and mk given: DualSPHysics reads mkbound only" in w for w in r.warnings)
    assert not any("unknown attribute" in w for w in r.warnings)
    with pytest.raises(CaseError, match="missing mkbound, mkfluid or mk"):
        build(tmp_path / "b", STEEL + '<links><link property="steel"/></links>')


def test_link_mk_zero_links_nothing(tmp_path):
    r = build(tmp_path, STEEL + '<links><link mk="0-1" property="steel"/></links>')
    assert r.case.material_links[0]["mkfluid"] == [0] and "mkbound" not in r.case.material_links[0]
    assert any("mk 0 is no particle's mk" in w for w in r.warnings)


@pytest.mark.parametrize("written", ["Steel", "STEEL", " st eel "])
def test_property_name_case_and_spaces(tmp_path, written):
    """property="Steel" finds <property name="steel"> (GetIndexProperty lower-cases both; names
    are kept without spaces): the link holds the name as defined."""
    r = build(tmp_path, STEEL + f'<links><link mkbound="0" property="{written}"/></links>')
    assert r.case.material_links[0]["property"] == "steel"


def test_combined_property_names_and_floating(tmp_path):
    """A combination and a floating's property name are matched the same way; a property
    defined with spaces and capitals is stored without the spaces."""
    props = (STEEL + '<property name="User Def01" Restitution_Coefficient_User="0.65"/>'
             '<links><link mkbound="0" property="STEEL + userdef01"/></links>')
    floatings = '<floatings><floating mkbound="50" rhopbody="500" property="USERDEF01"/></floatings>'
    r = build(tmp_path, props, commands=TANK_2D + FLOATING_BOX, floatings=floatings)
    assert set(r.case.materials) == {"steel", "UserDef01"}
    assert r.case.material_links[0]["property"] == "steel+UserDef01"
    assert r.case.floatings[0].property == "UserDef01"
    from sphdvi.mechanism import _material_for
    case_json = {"materials": {k: vars(v) for k, v in r.case.materials.items()},
                 "material_links": r.case.material_links}
    name, spec = _material_for(0, case_json)      # sorted, as GetPropsSort
    assert name == "UserDef01 + steel" and spec["restitution"] == 0.65 and spec["friction"] == 0.45


def test_undefined_property_still_refused(tmp_path):
    with pytest.raises(CaseError, match=r"property 'wood' is not defined; expected .*\(defined: steel\)"):
        build(tmp_path, STEEL + '<links><link mkbound="0" property="Steel + wood"/></links>')


def test_property_of_the_same_name_adds_its_values(tmp_path):
    """A second <property> of a name (whatever the case of its letters) adds its values to the
    first, as JCaseProperties::ReadXmlProperty (AddProperty finds the first; sphdvi replaced it,
    losing the first's values), and a value both give is refused, as its "Value already exists"."""
    r = build(tmp_path / "a", STEEL + '<property name="STEEL" Sfric="0.2"><Kfric_User value="0.1"/></property>'
                                      '<links><link mkbound="0" property="steel"/></links>')
    assert set(r.case.materials) == {"steel"}
    m = r.case.materials["steel"]
    assert (m.kfric, m.sfric, m.young, m.restitution, m.user) == (0.1, 0.2, 2.1e11, 0.8, ["kfric"])
    assert r.case.material_links[0]["property"] == "steel"
    with pytest.raises(CaseError, match=r"property 'steel' gives 'Kfric' a second time \(first at line \d+\)"):
        build(tmp_path / "b", STEEL + '<property name="STEEL"><Kfric value="0.1"/></property>'
                                      '<links><link mkbound="0" property="steel"/></links>')


def test_property_file_merges_with_the_case(tmp_path):
    """<propertyfile> items join the case's properties the same way (one store, as DualSPHysics)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "props.xml").write_text('<data><materials><property name="steel" Sfric="0.25"/>'
                                        '<property name="wood"><Kfric value="0.6"/></property></materials></data>')
    r = build(tmp_path, STEEL + '<propertyfile file="props.xml" path="data.materials"/>'
                                '<links><link mkbound="0" property="steel + wood"/></links>')
    assert set(r.case.materials) == {"steel", "wood"}
    assert (r.case.materials["steel"].kfric, r.case.materials["steel"].sfric) == (0.45, 0.25)


def test_value_names_are_matched_exactly(tmp_path):
    """Value names are not case-insensitive where DualSPHysics reads them (JCaseProperties::
    GetValuePtr compares the name as written): <young_modulus> is not Young_Modulus, warned."""
    props = ('<property name="steel"><young_modulus value="1e9"/><Kfric value="0.45"/></property>'
             '<links><link mkbound="0" property="steel"/></links>')
    r = build(tmp_path, props)
    assert r.case.materials["steel"].young is None
    assert any("'young_modulus' is not read (did you mean 'Young_Modulus'?)" in w for w in r.warnings)


def test_combined_properties_take_values_as_dualsphysics():
    """JCaseProperties::GetPropsSort + JSph::LoadDemData: the names sorted, each value from the
    first property that gives it, a *_User value of any of them first (sphdvi merged in document
    order, the later replacing the earlier)."""
    from sphdvi.mechanism import _material_for
    mats = {"steel": {"kfric": 0.35, "restitution": 0.8, "user": []},
            "userdef01": {"kfric": 0.1, "restitution": 0.2, "young": 2e9, "user": []},
            "SetKfric": {"kfric": 0.5, "user": ["kfric"]}}
    js = {"materials": mats}
    name, spec = _material_for(0, js, "userdef01 + steel")
    assert name == "steel + userdef01"
    assert (spec["friction"], spec["restitution"], spec["young"]) == (0.35, 0.8, 2e9)
    _, spec = _material_for(0, js, "steel+SetKfric")
    assert spec["friction"] == 0.5 and spec["restitution"] == 0.8
    _, spec = _material_for(0, {"materials": {"a": {"kfric": 0.2}, "b": {"kfric": 0.4}}}, "b+a")
    assert spec["friction"] == 0.2          # an older case file (no "user" list) reads too

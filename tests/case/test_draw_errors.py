"""GenCase drawing: every user error is a CaseError with file:line and element, never a crash."""
from __future__ import annotations

import pytest
from lxml import etree

from sphdvi.case.draw import UNSUPPORTED, run_geometry
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError

from test_draw import box, draw


def raw(tmp_path, xml, max_nodes=200_000_000):
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return run_geometry(reader, etree.fromstring(xml), casename="c", outdir=None,
                        max_nodes=max_nodes)


def test_unknown_command_lists_known(tmp_path):
    with pytest.raises(CaseError) as e:
        draw(tmp_path, '<setmkfluid mk="0"/>\n<drawdonut radius="1"/>')
    msg = str(e.value)
    assert "unknown command <drawdonut>" in msg and "drawbox" in msg and "drawsphere" in msg
    assert e.value.line == 2 and e.value.element == "drawdonut"
    assert msg.startswith(str(tmp_path / "case.xml") + ":2:")


@pytest.mark.parametrize("tag", sorted(UNSUPPORTED))
def test_unsupported_commands(tmp_path, tag):
    with pytest.raises(CaseError, match="not supported by sphdvi") as e:
        draw(tmp_path, f"<{tag}/>")
    assert e.value.element == tag


def test_layers_errors(tmp_path):
    with pytest.raises(CaseError, match="not supported"):
        draw(tmp_path, '<setmkbound mk="0"/><drawellipsoid><point x="5"/><radius x="1" y="1" z="1"/>'
                       '<layers vdp="1"/></drawellipsoid>')
    with pytest.raises(CaseError, match="vdp"):
        draw(tmp_path, '<setmkbound mk="0"/>' + box((0, 0, 0), (1, 1, 1), extra='<layers vdp="1,x"/>'))
    with pytest.raises(CaseError, match="missing attribute 'vdp'"):
        draw(tmp_path, '<setmkbound mk="0"/>' + box((0, 0, 0), (1, 1, 1), extra='<layers/>'))


@pytest.mark.parametrize("dp,pmax,match", [
    ("1e-9", (10, 10, 10), "lattice nodes"),
    ("1e-300", (1e300, 1e300, 1e300), "lattice nodes|not finite"),
    ("0", (1, 1, 1), "not positive"),
    ("-1", (1, 1, 1), "not positive"),
    ("nan", (1, 1, 1), "not"),
    ("inf", (1, 1, 1), "not finite"),
    ("abc", (1, 1, 1), "not a number"),
    ("1", (-1, 1, 1), "below pointmin"),
])
def test_bad_definition(tmp_path, dp, pmax, match):
    with pytest.raises(CaseError, match=match):
        draw(tmp_path, "", dp=dp, pmax=pmax)


def test_absurd_size_gives_clear_error(tmp_path):
    with pytest.raises(CaseError, match=r"domain has .* lattice nodes.*at most 1000"):
        draw(tmp_path, "", dp=0.1, pmax=(10, 10, 10), max_nodes=1000)


def test_missing_definition_parts(tmp_path):
    with pytest.raises(CaseError, match="definition"):
        raw(tmp_path, "<geometry><commands><mainlist/></commands></geometry>")
    with pytest.raises(CaseError, match="pointmax"):
        raw(tmp_path, '<geometry><definition dp="1"><pointmin x="0" y="0" z="0"/></definition>'
                      "</geometry>")
    with pytest.raises(CaseError, match="unknown child element <bogus>"):
        raw(tmp_path, '<geometry><bogus/></geometry>')


def test_drawing_without_mk(tmp_path):
    with pytest.raises(CaseError, match="no mk selected"):
        draw(tmp_path, box((0, 0, 0), (1, 1, 1)))


@pytest.mark.parametrize("body,match", [
    ('<setmkfluid mk="-1"/>', "below 0"),
    ('<setmkfluid mk="1.5"/>', "not an integer"),
    ('<setmkfluid/>', "missing attribute 'mk'"),
    ('<setdrawmode mode="fancy"/>', "not recognised"),
    ('<setmkbound mk="0"/>' + box((0, 0, 0), (1, 1, 1), fill="solid | roof"), "invalid boxfill"),
    ('<setmkbound mk="0"/><drawbox><point x="0" y="0" z="0"/></drawbox>', "size"),
    ('<setmkbound mk="0"/><drawbox><point x="0" y="0" z="0"/><size x="1"/><endpoint x="1"/>'
     '</drawbox>', "exactly one"),
    ('<setmkbound mk="0"/><drawbox><size x="1"/></drawbox>', "<point>"),
    # a missing component is an error, as DualSPHysics's reader (it was 0: the box drew nothing)
    ('<setmkbound mk="0"/><drawbox><point x="0" y="0" z="0"/><size x="1" y="2"/></drawbox>',
     r"<size>: missing attribute 'z'; expected a number"),
    ('<setmkbound mk="0"/><drawsphere radius="-1"><point x="1" y="0" z="0"/></drawsphere>', "not positive"),
    ('<setmkbound mk="0"/><drawsphere radius="1"/>', "exactly 1"),
    ('<setmkbound mk="0"/><drawcylinder radius="1"><point x="1" y="0" z="0"/><point x="1" y="0" z="0"/></drawcylinder>',
     "coincide"),
    ('<setmkbound mk="0"/><drawcylinder radius="1" mask="top"><point x="1" y="0" z="0"/><point x="2" y="0" z="0"/>'
     '</drawcylinder>', "mask"),
    ('<setmkbound mk="0"/><drawellipsoid radius="0.5"><point x="0" y="0" z="0"/><point x="3" y="0" z="0"/>'
     '</drawellipsoid>', "radius"),
    ('<setmkbound mk="0"/><drawprism><point x="0" y="0" z="0"/><point x="1" y="0" z="0"/>'
     '<point x="0" y="1" z="0"/><point x="0" y="0" z="1"/>'
     '<point x="1" y="0" z="1"/><point x="0" y="1" z="1"/><point x="0" y="0" z="3"/></drawprism>', "at least 6|even"),
    ('<setmkbound mk="0"/><drawpolygon><point x="0" y="0" z="0"/><point x="1" y="0" z="0"/>'
     '<point x="2" y="0" z="0"/></drawpolygon>',
     "no area"),
    ('<setmkbound mk="0"/><drawtriangles><points><point x="0" y="0" z="0"/><point x="1" y="0" z="0"/>'
     '<point x="0" y="1" z="0"/>'
     '</points><triangles><triangle x="0" y="1" z="5"/></triangles></drawtriangles>', "above 2"),
    ('<setmkbound mk="0"/><drawline><point x="0" y="0" z="0"/></drawline>', "exactly 2"),
    ('<setmkbound mk="0"/><drawlineto x="1"/>', "no line start"),
    ('<setmkbound mk="0"/><drawpoint x="#nosuchvar"/>', "unknown variable"),
    ('<scale x="0" y="1" z="1"/>', "scale factor is 0"),
    ('<scale/>', "missing scale"),
    ('<rotate ang="10" x="0" y="0" z="0"/>', "axis"),
    ('<rotateline ang="10"><point x="1" y="0" z="0"/><point x="1" y="0" z="0"/></rotateline>', "coincide"),
    ('<matrixload/>', "no matrix saved"),
    ('<stateload/>', "no state saved"),
    ('<mkload/>', "no mk saved"),
    ('<varsload/>', "no variables saved"),
    ('<setvar nosuch="1"/>', "does not exist"),
    ('<newvarcte K="1"/><setvar K="2"/>', "constant"),
    ('<newvar Dp="3"/>', "constant"),
    ('<newvar v="1/0"/>', "division by zero"),
    ('<newvar v="sqrt(-1)"/>', "cannot evaluate"),
    ('<newvar v="__import__(1)"/>', "unknown function"),
    ('<runlist name="nolist"/>', "no <list"),
    ('<setmkfluid mk="0"/><fillpoint x="1" y="1" z="1"><modefill>water</modefill></fillpoint>',
     "invalid modefill"),
    ('<setmkfluid mk="0"/><rotate ang="30" x="0" y="0" z="1"/><scale x="1" y="2" z="1"/>'
     '<fillbox x="1" y="1" z="1"><point x="0" y="0" z="0"/><size x="2" y="2" z="2"/></fillbox>',
     "non-uniform scale"),
    ('<shapeout file="a b"/>', "file name"),
    ('<shapeout file="a" format="obj"/>', "not recognised"),
])
def test_command_errors(tmp_path, body, match):
    with pytest.raises(CaseError, match=match):
        draw(tmp_path, body)


def test_predefinition_only_variables(tmp_path):
    with pytest.raises(CaseError, match="not allowed in <predefinition>"):
        draw(tmp_path, "", predef='<predefinition><setmkfluid mk="0"/></predefinition>')
    with pytest.raises(CaseError, match="unknown variable 'Dp'"):
        draw(tmp_path, "", predef='<predefinition><newvar a="Dp*2"/></predefinition>')


def test_runlist_recursion_and_limits(tmp_path):
    lists = '<list name="a"><runlist name="b"/></list><list name="b"><runlist name="a"/></list>'
    with pytest.raises(CaseError, match="recursive runlist"):
        draw(tmp_path, '<runlist name="a"/>', lists=lists)
    lists = '<list name="a"><newvar x="1"/><newvar y="1"/></list>'
    with pytest.raises(CaseError, match="commands executed"):
        draw(tmp_path, '<runlist name="a" times="1000000"/>', lists=lists)
    with pytest.raises(CaseError, match="defined twice"):
        draw(tmp_path, "", lists='<list name="a"/><list name="a"/>')
    with pytest.raises(CaseError, match="below 0"):
        draw(tmp_path, '<runlist name="a" times="-1"/>', lists='<list name="a"/>')


def test_fill_seed_outside_warns(tmp_path):
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    from test_draw import geometry_xml
    xml = geometry_xml('<setmkfluid mk="0"/><fillvoidpoint x="50" y="1" z="1"/>')
    d = run_geometry(reader, etree.fromstring(xml), casename="c", outdir=None)
    assert len(d.pos) == 0
    assert any("outside" in w for w in reader.warnings)


@pytest.mark.parametrize("attr", ['x="1e308"', 'x="-1e308"', 'radius="1e308"'])
def test_huge_coordinates_no_crash(tmp_path, attr):
    body = ('<setmkbound mk="0"/><drawsphere radius="1"><point x="1" y="0" z="0"/></drawsphere>'
            .replace('radius="1"', attr if "radius" in attr else 'radius="1"')
            .replace('<point x="1" y="0" z="0"/>', f'<point {attr} y="0" z="0"/>' if "radius" not in attr
                     else '<point x="1" y="0" z="0"/>'))
    try:
        draw(tmp_path, body)
    except CaseError:
        pass


def test_huge_boxes_and_lines_are_clipped(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((-1e300, -1e300, -1e300), (2e300, 2e300, 2e300),
                                                   fill="all"))
    assert len(d.pos) == 0
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((-1e300, -1e300, -1e300), (2e300, 2e300, 2e300)))
    assert len(d.pos) == 10 ** 3

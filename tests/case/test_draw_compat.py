"""GenCase compatibility of the drawing commands found in the DualSPHysics v5.4 examples:
``mask`` lists the faces left out (an open shape has no inside in full mode), ``<resetdraw>``,
``<setboxlimitmode>``, GenCase's own ``<case app date>`` attributes and the no-fluid warning."""
from __future__ import annotations

import numpy as np
import pytest
from casetext import case_xml, write_case
from test_draw import CYL, PRISM, draw, nodes

from sphdvi.case.gencase import build_case
from sphdvi.errors import CaseError


def warnings_of(tmp_path, body, **kw):
    from lxml import etree

    from sphdvi.case.draw import run_geometry
    from sphdvi.case.xmldoc import CaseReader
    from test_draw import geometry_xml
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    d = run_geometry(reader, etree.fromstring(geometry_xml(body, **kw)), casename="case",
                     outdir=None)
    return d, list(reader.warnings)


# ---------------------------------------------------------------- mask = faces left out
# CaseFloatingWavesVal (v5.4 example 08) scaled to dp = 1: a flume drawn as a prism whose
# faces are 1 = polygon at y=-1, 2 = polygon at y=1, 3 = P1P2 (end wall x=-5), 4 = P2P3
# (bottom z=0), 5 = P3P4 (beach slope), 6 = P4P1 (lid z=6). mask="1|2|3|6" keeps the bottom
# and the slope; the fillbox seed lies inside the prism and must find void.
FLUME = """<setdrawmode mode="{mode}"/><setmkbound mk="0"/>
<drawprism mask="{mask}">
<point x="-5" y="-1" z="6"/><point x="-5" y="-1" z="0"/><point x="4" y="-1" z="0"/>
<point x="10" y="-1" z="6"/>
<point x="-5" y="1" z="6"/><point x="-5" y="1" z="0"/><point x="4" y="1" z="0"/>
<point x="10" y="1" z="6"/></drawprism>
<setmkfluid mk="0"/><fillbox x="1" y="0" z="1"><modefill>void</modefill>
<point x="-2" y="-1" z="-0.5"/><size x="25" y="2" z="4.5"/></fillbox>"""
FLUME_KW = dict(pmin=(-6, 0, -1), pmax=(12, 0, 8))


@pytest.mark.parametrize("mode", ["full", "face"])
def test_prism_mask_lists_hidden_faces(tmp_path, mode):
    d = draw(tmp_path, FLUME.format(mode=mode, mask="1|2|3|6"), **FLUME_KW)
    bound = nodes(d, fluid=False)
    # bottom z=0 from x=-5 to 4 and the slope z = x - 4 up to (10, 6), in 2D as thick as a
    # 4-connected line (its staircase nodes z = x - 3): nothing else
    assert bound == ({(x, 0, 0) for x in range(-5, 5)} | {(x, 0, x - 4) for x in range(5, 11)}
                     | {(x, 0, x - 3) for x in range(4, 10)})
    assert not any(z == 6 and x < 9 for x, _, z in bound)           # no lid (face 6)
    assert not any(x == -5 and z > 0 for x, _, z in bound)          # no end wall (face 3)
    # the fluid fills the flume above the bottom, left of the slope, up to the fillbox top, the
    # nodes at least dp/2 inside the fill box (x=-2 and z=4 lie on its faces; GenCase fills the nodes at least dp/2 inside a <fillbox> (see test_draw_gencase_counts.py))
    assert nodes(d, fluid=True) == {(x, 0, z) for z in range(1, 4) for x in range(-1, z + 3)}
    assert d.count_fluid == 18
    assert d.primitives[0]["params"]["mask"] == [1, 2, 3, 6] and not d.primitives[0]["solid"]


def test_prism_mask_is_not_a_bit_set(tmp_path):
    # as bits, 1|2|3|6 = 7 would hide the first three faces (1, 2, 3) and draw the lid
    d = draw(tmp_path, FLUME.format(mode="full", mask="1|2|3"), **FLUME_KW)
    bound = nodes(d, fluid=False)
    assert (0, 0, 6) in bound and (-5, 0, 3) not in bound and d.count_fluid == 18
    d = draw(tmp_path, FLUME.format(mode="full", mask="1|2|6"), **FLUME_KW)
    assert (0, 0, 6) not in nodes(d, fluid=False) and (-5, 0, 3) in nodes(d, fluid=False)
    d = draw(tmp_path, FLUME.format(mode="full", mask="0"), **FLUME_KW)
    assert d.count_fluid == 0          # closed: the inside is boundary, the seed finds no void


def test_wavemaker_pattern_keeps_fluid_drawn_before(tmp_path):
    # CaseWavemaker: fluid prism (mask 0), then the same prism as boundary with faces left out
    # in full mode; GenCase leaves the fluid inside (the face-mode variant gives the same)
    pts = ('<point x="5" y="{y}" z="1.5"/><point x="5" y="{y}" z="1.1"/><point x="1" y="{y}" z="0"/>'
           '<point x="0" y="{y}" z="0"/><point x="0" y="{y}" z="1.5"/>')
    prism = "<drawprism mask=\"{m}\">" + pts.format(y=0) + pts.format(y=2) + "</drawprism>"
    body = ('<setdrawmode mode="full"/><setmkfluid mk="0"/>' + prism.format(m="0")
            + '<setmkvoid/><drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0.75"/>'
            '<size x="5" y="2" z="1"/></drawbox>'
            + '<setdrawmode mode="{mode}"/><setmkbound mk="0"/>' + prism.format(m="1 | 2 | 6 | 7"))
    kw = dict(dp=0.1, pmin=(-0.1, -0.05, -0.05), pmax=(5.1, 2.1, 2))
    full = draw(tmp_path, body.replace("{mode}", "full"), **kw)
    face = draw(tmp_path, body.replace("{mode}", "face"), **kw)
    assert full.count_fluid == face.count_fluid > 1500
    assert np.array_equal(full.pos, face.pos) and np.array_equal(full.is_fluid, face.is_fluid)
    b = full.pos[~full.is_fluid]
    assert not np.any((b[:, 0] < 0.05) & (b[:, 2] > 0.05))   # no face 6 (x = 0, the piston)
    assert not np.any(np.isclose(b[:, 2], 1.5) & (b[:, 0] < 4.9))   # no face 7 (the top)
    fluid_y = full.pos[full.is_fluid, 1]
    assert fluid_y.min() < 0.1 and fluid_y.max() > 1.9     # no y caps (faces 1, 2) over it


def test_mask_numbers_beyond_the_faces_are_ignored_and_warned(tmp_path):
    # a 5-face prism with mask="7" is closed; a mask none of whose faces exists is warned about
    # (mask="96" passed silently before)
    for mask in ("7", "96"):
        d, w = warnings_of(tmp_path, PRISM.format(mode="face", mask=mask))
        assert any(f"mask names face {mask} but this <drawprism> has faces 1 to 5 only"
                   in m for m in w), w
    d, w = warnings_of(tmp_path, PRISM.format(mode="full", mask="7"))
    assert len(d.pos) == 45
    d, w = warnings_of(tmp_path, CYL.format(mode="full", mask="4 | 5"))
    assert len(d.pos) == 13 * 5 and any("mask names faces 4, 5 but this <drawcylinder> has faces 1 to 3"
                                    in m for m in w)
    d, w = warnings_of(tmp_path, PRISM.format(mode="full", mask="1 | 2"))
    assert w == []


@pytest.mark.parametrize("mask", ["1 | 96", "1 | 2 | 6 | 7"])
def test_mask_number_beyond_the_faces_beside_valid_ones_is_silent(tmp_path, mask):
    # audit finding 7: CaseFlapBeach_REG and CasePointAbsorber (v5.4) write mask="1 | 2 | 6 | 7"
    # on 4-point prisms (faces 1 to 6); GenCase is silent, the drawing uses the faces that exist
    d, w = warnings_of(tmp_path, FLUME.format(mode="full", mask=mask), **FLUME_KW)
    assert w == []
    ref = draw(tmp_path, FLUME.format(mode="full", mask=mask.rsplit("|", 1)[0]), **FLUME_KW)
    assert np.array_equal(d.pos, ref.pos) and np.array_equal(d.mk, ref.mk)
    assert d.primitives[0]["params"]["mask"] == sorted(int(v) for v in mask.split("|"))


@pytest.mark.parametrize("mode,mask,count", [
    ("face", "1 | 2", 5 * 8), ("face", "3", 9 + 9), ("face", "1 | 3", 9), ("face", "2", 9 + 4 * 8),
    ("full", "2", 9 + 4 * 8), ("full", "3", 9 + 9), ("full", "0", 13 * 5), ("full", "1|2|3", 0)])
def test_cylinder_mask_faces(tmp_path, mode, mask, count):
    # faces 1 = cover at the first point (z=2), 2 = cover at the second point (z=6), 3 = tube
    d = draw(tmp_path, CYL.format(mode=mode, mask=mask))
    assert len(d.pos) == count


def test_open_cylinder_in_full_mode_is_a_cup(tmp_path):
    body = CYL.format(mode="full", mask="2") + (
        '<setmkfluid mk="0"/><fillbox x="5" y="5" z="4"><modefill>void</modefill>'
        '<point x="0" y="0" z="0"/><size x="10" y="10" z="6"/></fillbox>')
    d = draw(tmp_path, body)
    # up to z=5: z=6 lies on the fill box's top (GenCase fills the nodes at least dp/2 inside a <fillbox> (see test_draw_gencase_counts.py))
    assert nodes(d, fluid=True) == {(5, 5, z) for z in (3, 4, 5)}
    assert (5, 5, 2) in nodes(d, fluid=False) and d.count_bound == 41


def test_pyramid_mask_faces(tmp_path):
    # faces 1 = base, 2, 3, 4 = sides apex-P1P2, apex-P2P3, apex-P3P1
    body = ('<setdrawmode mode="{mode}"/><setmkbound mk="0"/><drawpyramid mask="{mask}">'
            '<point x="0" y="0" z="3"/><point x="0" y="0" z="0"/><point x="3" y="0" z="0"/>'
            '<point x="0" y="3" z="0"/></drawpyramid>')
    closed = nodes(draw(tmp_path, body.format(mode="face", mask="0")))
    no_y0 = nodes(draw(tmp_path, body.format(mode="face", mask="2")))
    assert {(1, 0, 1), (2, 0, 0)} <= closed and (1, 0, 1) not in no_y0 and (1, 1, 0) in no_y0
    # the template's mask="1 | 3 | 5" (5 does not exist) opens the shape: faces only in full mode
    assert nodes(draw(tmp_path, body.format(mode="full", mask="1 | 3 | 5"))) == \
        nodes(draw(tmp_path, body.format(mode="face", mask="1 | 3")))


@pytest.mark.parametrize("shape,mask", [(PRISM, "2"), (CYL, "3"), (CYL, "1")])
def test_masked_shape_in_solid_mode_draws_its_volume(tmp_path, shape, mask):
    """solid mode draws no surface, so the mask changes nothing: the closed shape's volume
    (GenCase v4.0.053's record of DualSPHysics's motion/Motion08: three short cylinders with
    mask="1" in solid mode are whole disks, 110, 311 and 312 particles; sphdvi said "an open
    shape has no inside" and drew nothing, so their motion found no particles)."""
    d, w = warnings_of(tmp_path, shape.format(mode="solid", mask=mask))
    ref = draw(tmp_path, shape.format(mode="solid", mask="0"))
    assert nodes(d) == nodes(ref) and len(ref.pos) > 0 and not w


def test_short_masked_cylinder_in_solid_mode_is_a_disk(tmp_path):
    """Motion08's mkbound 151 at dp 1: a cylinder of radius 10 and length 1/2 along y, mask="1",
    in solid mode: the disk of nodes within the radius in the x-z plane (GenCase: 311-312;
    here 317, the 12 nodes at exactly the radius included)."""
    body = ('<setdrawmode mode="solid"/><setmkbound mk="0"/><drawcylinder radius="10" mask="1">'
            '<point x="15" y="5.5" z="15"/><point x="15" y="5" z="15"/></drawcylinder>')
    got = nodes(draw(tmp_path, body, pmax=(30, 10, 30)))
    disk = {(x, 5, z) for x in range(31) for z in range(31) if (x - 15) ** 2 + (z - 15) ** 2 <= 100}
    assert got == disk and len(disk) == 317


@pytest.mark.parametrize("mask", ["top", "-1", "1.5", "1 | x"])
def test_bad_mask(tmp_path, mask):
    with pytest.raises(CaseError, match="mask") as e:
        draw(tmp_path, PRISM.format(mode="full", mask=mask))
    assert e.value.element == "drawprism" and e.value.line


# ---------------------------------------------------------------- resetdraw
NORMALS_LIST = """<list name="GeometryForNormals">
<setactive drawpoints="0" drawshapes="1"/><setshapemode>actual | bound</setshapemode>
<setnormalinvert invert="true"/><setdrawmode mode="face"/><move x="3" y="0" z="0"/>
<setmkbound mk="0"/>
<drawbox><boxfill>all</boxfill><point x="1" y="1" z="1"/><size x="4" y="4" z="4"/>
<layers vdp="-0.5"/></drawbox>
<shapeout file="hdp"/><resetdraw/></list>"""


def test_resetdraw_after_normals_geometry(tmp_path):
    # the v5.x mDBC pattern: shapes only, then <resetdraw/> re-enables drawing points
    body = ('<runlist name="GeometryForNormals"/><setmkfluid mk="0"/>'
            '<drawbox><boxfill>solid</boxfill><point x="1" y="1" z="1"/><size x="2" y="2" z="2"/>'
            '</drawbox>')
    d, w = warnings_of(tmp_path, body, lists=NORMALS_LIST)
    assert w == []
    # full mode and identity matrix again: the solid 3x3x3 box at 1..3, not moved by x=3
    assert nodes(d, fluid=True) == {(x, y, z) for x in (1, 2, 3) for y in (1, 2, 3)
                                    for z in (1, 2, 3)}


def test_resetdraw_clears_the_pen(tmp_path):
    body = ('<runlist name="GeometryForNormals"/>'
            '<drawbox><boxfill>solid</boxfill><point x="1" y="1" z="1"/><size x="2" y="2" z="2"/>'
            '</drawbox>')
    with pytest.raises(CaseError, match="no mk selected") as e:
        draw(tmp_path, body, lists=NORMALS_LIST)
    assert e.value.element == "drawbox"


def test_resetdraw_keeps_what_was_drawn(tmp_path):
    # a plain state command (GenCase_CaseTemplate.xml): no warning for what was drawn before
    body = ('<setmkbound mk="2"/><drawpoint x="1" y="1" z="1"/><matrixsave/><resetdraw/>'
            '<matrixload/><setmkfluid mk="0"/><drawpoint x="2" y="2" z="2"/>')
    d, w = warnings_of(tmp_path, body)
    assert nodes(d) == {(1, 1, 1), (2, 2, 2)}
    assert w == []


# ---------------------------------------------------------------- commands that draw nothing
WALL_2D = ('<setmkfluid mk="0"/><drawbox><boxfill>solid</boxfill><point x="0.1" y="-1" z="0.1"/>'
           '<size x="0.2" y="2" z="0.2"/></drawbox><setmkbound mk="3"/>')
KW_2D = dict(dp=0.1, pmax=(1, 0, 1))


def test_2d_shape_off_the_plane_is_warned(tmp_path):
    """A 2D wall box from y=0.2 to 0.7 (posy 0) or a point at y=0.3 creates no particle: warned
    with the command's line, mk and y range (it vanished silently, and the fluid with it)."""
    body = (WALL_2D + '<drawbox><boxfill>solid</boxfill><point x="0" y="0.2" z="0"/>'
            '<size x="1" y="0.5" z="0.2"/></drawbox><drawpoint x="0.5" y="0.3" z="0.5"/>')
    d, w = warnings_of(tmp_path, body, **KW_2D)
    assert d.count_bound == 0 and d.count_fluid == 9
    assert len(w) == 2
    assert "<drawbox>: this <drawbox> (mkbound 3) creates no particles: it spans y = 0.2..0.7 and misses " \
           "the 2D plane y = 0" in w[0] and w[0].startswith(str(tmp_path / "case.xml") + ":1:")
    assert "<drawpoint> (mkbound 3) creates no particles: it spans y = 0.3..0.3" in w[1]


def test_shape_outside_the_domain_is_warned(tmp_path):
    d, w = warnings_of(tmp_path, '<setmkfluid mk="1"/><drawsphere radius="1"><point x="20" y="5" z="5"/>'
                                 '</drawsphere>')
    assert len(d.pos) == 0 and len(w) == 1
    assert "(mkfluid 1) creates no particles: it lies outside the domain pointmin" in w[0]


def test_commands_that_may_draw_nothing_are_not_warned(tmp_path):
    """Void drawing, fills into a filled region (already warned by the fill itself) and hidden
    points (setactive) are not warned twice."""
    body = (WALL_2D + '<setmkvoid/><drawpoint x="0.5" y="0.3" z="0.5"/><setmkbound mk="3"/>'
            '<setactive drawpoints="false"/><drawpoint x="0.5" y="0.3" z="0.5"/>'
            '<setactive drawpoints="true"/><setmkfluid mk="0"/><fillbox x="0.2" y="0" z="0.2">'
            '<modefill>void</modefill><point x="0" y="0" z="0"/><size x="1" y="0" z="1"/></fillbox>')
    d, w = warnings_of(tmp_path, body, **KW_2D)
    assert len(w) == 1 and "<fillbox>: the seed node is not of a kind listed in <modefill>" in w[0]


def test_false_printf_and_abort_read_their_text(tmp_path):
    """<printf>/<abort> whose if= is false: no "unknown attribute 'text'" warning."""
    from lxml import etree

    from sphdvi.case.draw import run_geometry
    from sphdvi.case.xmldoc import CaseReader
    from test_draw import geometry_xml
    el = etree.fromstring(geometry_xml('<printf if="Dp&gt;2" text="never"/><abort if="Dp&gt;2" text="no"/>'
                                       '<setmkfluid mk="0"/><drawpoint x="1" y="1" z="1"/>'))
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    run_geometry(reader, el, casename="case", outdir=None)
    reader.warn_unread_attributes(el)
    assert list(reader.warnings) == []


# ---------------------------------------------------------------- setboxlimitmode
FILL_TANK = ('<setmkbound mk="0"/><drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="0" '
             'z="0"/><size x="6" y="0" z="8"/></drawbox>')
FILL = ('<setmkfluid mk="0"/><fillbox x="3" y="0" z="1"><modefill>void</modefill><point x="0" y="0" '
        'z="0"/><size x="6" y="0" z="3.5"/></fillbox>')


def test_setboxlimitmode_sets_the_fill_limits(tmp_path):
    """A fillbox fills the nodes at least dp/2 inside its box (GenCase's default, ``inner``); after
    <setboxlimitmode mode="full"> every node from the one nearest its min corner to the one nearest
    its max corner, a top at 3.5 dp filling the row at 4 (GenCase v5.4's CaseSloshingHR record:
    fill top at 46.5 dp, fluid to the row at 47). A drawbox is not affected."""
    kw = dict(pmin=(-1, 0, -1), pmax=(8, 0, 10))
    inner = draw(tmp_path, FILL_TANK + FILL, **kw)
    assert inner.count_fluid == 5 * 3 and inner.pos[inner.is_fluid, 2].max() == 3
    explicit = draw(tmp_path, FILL_TANK + '<setboxlimitmode mode="inner"/>' + FILL, **kw)
    assert np.array_equal(explicit.pos, inner.pos)
    full = draw(tmp_path, FILL_TANK + '<setboxlimitmode mode="full"/>' + FILL, **kw)
    assert full.count_fluid == 5 * 4 and full.pos[full.is_fluid, 2].max() == 4
    box = ('<setmkfluid mk="0"/><drawbox><boxfill>solid</boxfill><point x="0.5" y="0.5" '
           'z="0.5"/><size x="2.2" y="2" z="2.5"/></drawbox>')
    plain = draw(tmp_path, box)
    for mode in ("full", "inner"):
        other = draw(tmp_path, f'<setboxlimitmode mode="{mode}"/>' + box)
        assert np.array_equal(plain.pos, other.pos) and len(other.pos) > 0


def test_setboxlimitmode_unknown_mode_refused(tmp_path):
    with pytest.raises(CaseError, match="not recognised") as e:
        draw(tmp_path, '<setboxlimitmode mode="half"/>')
    assert e.value.element == "setboxlimitmode" and e.value.line


# ---------------------------------------------------------------- whole cases
def test_gencase_app_and_date_attributes_are_accepted(tmp_path):
    text = case_xml().replace("<case>", '<case app="GenCase v5.4.354.01 (12-11-2024)" '
                                         'date="12-11-2024 10:00:00">')
    res = build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    assert not [w for w in res.warnings if "unknown attribute" in w]
    text = case_xml().replace("<case>", '<case app="x" colour="red">')
    res = build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    assert [w for w in res.warnings if "unknown attribute 'colour'" in w]


BODY_ONLY = """
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill>
                        <point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>"""


def test_no_fluid_created_is_warned(tmp_path):
    # the seed lies in the wall: the fill finds no void and the case ends without fluid
    commands = BODY_ONLY + """
                    <setmkfluid mk="0" />
                    <fillbox x="0" y="0" z="1"><modefill>void</modefill>
                        <point x="0" y="-1" z="0" /><size x="4" y="2" z="2" /></fillbox>"""
    res = build_case(write_case(tmp_path, case_xml(commands=commands)), str(tmp_path / "out"))
    msgs = [w for w in res.warnings if "no fluid particles were created" in w]
    assert len(msgs) == 1 and "the case has no fluid" in msgs[0] and "fill" in msgs[0]
    assert "Case_Def.xml:" in msgs[0]


def test_fluid_replaced_later_is_warned(tmp_path):
    commands = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="1" y="-1" z="1" /><size x="1" y="2" z="1" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>"""
    res = build_case(write_case(tmp_path, case_xml(commands=commands)), str(tmp_path / "out"))
    assert [w for w in res.warnings if "later drawing commands replaced all of them" in w]


def test_body_only_case_is_silent(tmp_path):
    res = build_case(write_case(tmp_path, case_xml(commands=BODY_ONLY)), str(tmp_path / "out"))
    assert not [w for w in res.warnings if "fluid" in w]
    assert res.particles["pos"].shape[0] > 0


def test_setmknextbound_numbers_the_blocks_of_a_list(tmp_path):
    """DualSPHysics's chrono/03 CaseFlexibleGate: a list draws a gate segment, moves up and ends
    with <setmknextbound next="true"/>; run five times from <setmkbound mk="1"/> it draws the
    segments mkbound 1 to 5 (its <floating mkbound="1-5">). The same for fluid."""
    lists = ('<list name="Block"><drawbox><boxfill>solid</boxfill><point x="1" y="1" z="0"/>'
             '<size x="1" y="1" z="1"/></drawbox><move x="0" y="0" z="2"/>'
             '<setmknextbound next="true"/></list>')
    d = draw(tmp_path, '<setmkbound mk="1"/><runlist name="Block" times="5"/>', lists=lists)
    zs = {int(m): sorted({int(round(p[2])) for p, k in zip(d.pos, d.mk) if k == m}) for m in set(d.mk)}
    assert sorted(zs) == [1, 2, 3, 4, 5]
    assert [zs[m] for m in sorted(zs)] == [[2 * i, 2 * i + 1] for i in range(5)]
    f = draw(tmp_path, '<setmkfluid mk="3"/><drawpoint x="1" y="1" z="1"/><setmknextfluid/>'
             '<drawpoint x="2" y="2" z="2"/>')
    assert sorted(f.mk.tolist()) == [3, 4] and f.is_fluid.all()


@pytest.mark.parametrize("body,expected", [
    ('<setmknextbound next="true"/>', "no mkbound set before it"),
    ('<setmkfluid mk="0"/><setmknextbound/>', "no mkbound set before it"),
    ('<setmkbound mk="2"/><setmknextbound next="false"/>', 'next="false" is not supported'),
    ('<setmkbound mk="65535"/><setmknextbound/>', "has no next"),
])
def test_setmknext_errors(tmp_path, body, expected):
    with pytest.raises(CaseError) as e:
        draw(tmp_path, body)
    assert expected in str(e.value)


# ---------------------------------------------------------------- <setfrdrawmode>
def test_free_draw_mode_draws_on_the_lattice_and_warns(tmp_path):
    """DualSPHysics's TurekHron FSI2 cases wrap their cylinder in <setfrdrawmode auto="true"> ...
    auto="false">: GenCase's free drawing (its rule is not published) is drawn on the lattice, as
    without it, with a warning; auto="false" alone says nothing."""
    cyl = CYL.format(mode="full", mask="0")
    plain, w0 = warnings_of(tmp_path, cyl)
    free, w1 = warnings_of(tmp_path, '<setfrdrawmode auto="true" />' + cyl + '<setfrdrawmode auto="false" />')
    assert np.array_equal(plain.pos, free.pos) and np.array_equal(plain.mk, free.mk)
    assert not w0 and len(w1) == 1 and "free drawing" in w1[0] and "on the lattice" in w1[0]
    _, w2 = warnings_of(tmp_path, '<setfrdrawmode auto="false" />' + cyl)
    assert not w2

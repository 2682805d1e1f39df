"""GenCase drawing (sphdvi.case.draw): counts and positions on small hand-computed lattices."""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from lxml import etree

from sphdvi.case.draw import run_geometry
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError


def geometry_xml(body, dp=1.0, pmin=(0, 0, 0), pmax=(10, 10, 10), pointref=None, predef="",
                 lists=""):
    ref = "" if pointref is None else '<pointref x="{}" y="{}" z="{}"/>'.format(*pointref)
    return (f"<geometry>{predef}<definition dp=\"{dp}\">{ref}"
            '<pointmin x="{}" y="{}" z="{}"/>'.format(*pmin)
            + '<pointmax x="{}" y="{}" z="{}"/>'.format(*pmax)
            + f"</definition><commands>{lists}<mainlist>{body}</mainlist></commands></geometry>")


def draw(tmp_path, body, outdir=None, max_nodes=200_000_000, **kw):
    el = etree.fromstring(geometry_xml(body, **kw))
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return run_geometry(reader, el, casename="case", outdir=outdir, max_nodes=max_nodes)


def nodes(d, fluid=None):
    """Set of integer (x, y, z) node tuples (dp = 1 lattices starting at 0)."""
    sel = np.ones(len(d.pos), bool) if fluid is None else (d.is_fluid == fluid)
    return {tuple(int(round(v)) for v in p) for p in d.pos[sel]}


def box(point, size=None, endpoint=None, fill="solid", extra=""):
    s = f'<size x="{size[0]}" y="{size[1]}" z="{size[2]}"/>' if size is not None else \
        f'<endpoint x="{endpoint[0]}" y="{endpoint[1]}" z="{endpoint[2]}"/>'
    return (f"<drawbox><boxfill>{fill}</boxfill>"
            f'<point x="{point[0]}" y="{point[1]}" z="{point[2]}"/>{s}{extra}</drawbox>')


def lattice_box(lo, hi):
    return set(itertools.product(*[range(a, b + 1) for a, b in zip(lo, hi)]))


DAMBREAK = """<setdrawmode mode="full" />
<setmkfluid mk="0" />
<drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="2" /></drawbox>
<setmkbound mk="0" />
<drawbox><boxfill>bottom | left | right | front | back</boxfill>
<point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>"""


# ---------------------------------------------------------------- acceptance: 2D dam break
@pytest.mark.parametrize("dp,nfluid,nbound", [(0.02, 5000, 501), (0.01, 20000, 1001)])
def test_dambreak_2d_counts(tmp_path, dp, nfluid, nbound):
    d = draw(tmp_path, DAMBREAK, dp=dp, pmin=(-1, 0, -1), pmax=(4.5, 0, 3.5))
    assert d.is2d and d.posy2d == 0.0
    assert (d.count_fluid, d.count_bound) == (nfluid, nbound)
    assert np.all(d.pos[:, 1] == 0.0)
    assert d.mk.dtype == np.int32 and set(d.mk.tolist()) == {0}
    f = np.round(d.pos[d.is_fluid] / dp).astype(int)
    assert f[:, 0].min() == 1 and f[:, 0].max() == round(1 / dp)
    assert f[:, 2].min() == 1 and f[:, 2].max() == round(2 / dp)
    b = np.round(d.pos[~d.is_fluid] / dp).astype(int)
    assert set(b[:, 0].tolist()) == set(range(0, round(4 / dp) + 1))
    assert b[:, 2].max() == round(3 / dp)
    assert len({tuple(p) for p in np.round(d.pos / dp).astype(int).tolist()}) == len(d.pos)


def test_dambreak_primitives(tmp_path):
    d = draw(tmp_path, DAMBREAK, dp=0.02, pmin=(-1, 0, -1), pmax=(4.5, 0, 3.5))
    assert [p["shape"] for p in d.primitives] == ["box", "box"]
    assert d.primitives[0]["fluid"] and d.primitives[0]["solid"]
    assert not d.primitives[1]["fluid"] and not d.primitives[1]["solid"]
    assert d.primitives[0]["params"]["min"] == [0, -1, 0]
    assert d.primitives[0]["params"]["max"] == [1, 1, 2]


# ---------------------------------------------------------------- parity with GenCase outputs
def mk_counts(d):
    out = {}
    for f, m in zip(d.is_fluid.tolist(), d.mk.tolist()):
        key = ("fluid" if f else "bound", m)
        out[key] = out.get(key, 0) + 1
    return out


def test_gencase_parity_off_lattice_3d(tmp_path):
    """DualSPHysics examples/others/SaveDt/Case5aSvdt_8k.xml: GenCase wrote
    bound mk0 3965, bound mk1 281, fluid 3795 (dp 0.0272, off-lattice boxes)."""
    body = ('<setdrawmode mode="full"/><setmkfluid mk="0"/>'
            + box((0, 0, 0), (0.4, 0.67, 0.3))
            + '<setmkbound mk="0"/>'
            + box((0, 0, 0), (1.6, 0.67, 0.4), fill="bottom | left | right | front | back")
            + '<setmkvoid/>' + box((0.9, 0.24, 0), (0.12, 0.12, 0.45))
            + '<setmkbound mk="1"/>'
            + box((0.9, 0.24, 0), (0.12, 0.12, 0.45), fill="top | left | right | front | back")
            + '<shapeout file=""/>')
    d = draw(tmp_path, body, dp=0.0272, pmin=(-0.05, -0.05, -0.05), pmax=(2, 1, 1))
    assert mk_counts(d) == {("bound", 0): 3965, ("bound", 1): 281, ("fluid", 0): 3795}


def test_gencase_parity_rotated_box_case(tmp_path):
    """DualSPHysics examples/others/RotatedBox/RotatedBox.xml: GenCase wrote bound mk0 12630,
    mk1 16261, mk2 960 (rotated 40 degrees), mk3 832, fluid 99000. sphdvi matches all but
    the rotated walls (840: one node layer per planar face; GenCase's rule gives 960; 832 while
    the band was searched only 0.5 beyond a triangle's box, see test_raster_band_range.py)."""
    body = ('<setshapemode>real | bound</setshapemode><setdrawmode mode="full"/>'
            '<setmkfluid mk="0"/>' + box((0, 0, 0), (0.25, 0.5, 0.1))
            + '<setmkbound mk="2"/><rotateline ang="40"><point x="0.45" y="0.145" z="0"/>'
              '<point x="0.45" y="0.145" z="1"/></rotateline>'
            + box((0.45, 0.04, 0), (0.05, 0.21, 0.04), fill="all ^ top ^ bottom")
            + '<matrixreset/><setmkbound mk="3"/>'
            + box((0.45, 0.25, 0), (0.05, 0.21, 0.04), fill="all ^ top ^ bottom")
            + '<setmkbound mk="0"/>' + box((0, 0, 0), (0.8, 0.5, 0.15), fill="left | front | back")
            + '<setmkbound mk="1"/>' + box((0, 0, 0), (0.8, 0.5, 0.15), fill="bottom"))
    d = draw(tmp_path, body, dp=0.005, pmin=(-0.2, -0.2, -0.2), pmax=(3, 0.7, 0.3))
    assert mk_counts(d) == {("bound", 0): 12630, ("bound", 1): 16261, ("bound", 2): 840,
                            ("bound", 3): 832, ("fluid", 0): 99000}


# ---------------------------------------------------------------- boxes
def test_box_solid_3d(tmp_path):
    d = draw(tmp_path, '<setmkfluid mk="2"/>' + box((1, 2, 3), (2, 1, 3)))
    assert nodes(d) == lattice_box((1, 2, 3), (3, 3, 6))
    assert d.is_fluid.all() and set(d.mk.tolist()) == {2}


def test_box_endpoint_and_negative_size(tmp_path):
    a = draw(tmp_path, '<setmkbound mk="1"/>' + box((1, 1, 1), endpoint=(3, 4, 2)))
    b = draw(tmp_path, '<setmkbound mk="1"/>' + box((3, 4, 2), (-2, -3, -1)))
    assert nodes(a) == nodes(b) == lattice_box((1, 1, 1), (3, 4, 2))
    assert not a.is_fluid.any()


def test_box_all_faces(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((1, 1, 1), (4, 4, 4), fill="all"))
    assert len(d.pos) == 5 ** 3 - 3 ** 3
    assert nodes(d) == lattice_box((1, 1, 1), (5, 5, 5)) - lattice_box((2, 2, 2), (4, 4, 4))


@pytest.mark.parametrize("face,axis,value", [("bottom", 2, 1), ("top", 2, 5), ("left", 0, 1),
                                             ("right", 0, 5), ("front", 1, 1), ("back", 1, 5)])
def test_box_single_face(tmp_path, face, axis, value):
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((1, 1, 1), (4, 4, 4), fill=face))
    assert len(d.pos) == 25
    assert np.all(d.pos[:, axis] == value)


def test_box_face_combination(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((1, 1, 1), (4, 4, 4), fill="bottom | left"))
    assert len(d.pos) == 25 + 25 - 5
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((1, 1, 1), (4, 4, 4), fill="solid | top"))
    assert len(d.pos) == 125


def test_box_off_lattice(tmp_path):
    # 0.3..2.3: GenCase fills from the node nearest the min corner (0) to the one nearest
    # the max corner (2); faces at the nearest layers 0 and 2, extent 0..2
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0.3, 0.3, 0.3), (2, 2, 2)))
    assert nodes(d) == lattice_box((0, 0, 0), (2, 2, 2))
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0.6, 0.5, 0.4), (1.8, 2, 2.2)))
    # x 0.6..2.4 -> 1..2, y 0.5..2.5 -> 1..3 (halves round up), z 0.4..2.6 -> 0..3
    assert nodes(d) == lattice_box((1, 1, 0), (2, 3, 3))
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((0.3, 0.3, 0.3), (2, 2, 2), fill="all"))
    assert nodes(d) == lattice_box((0, 0, 0), (2, 2, 2)) - {(1, 1, 1)}


def test_box_thin_plate_face(tmp_path):
    # a zero-thickness plate off the lattice still gets its nearest layer
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((0, 0, 2.4), (3, 3, 0), fill="bottom"))
    assert nodes(d) == lattice_box((0, 0, 2), (3, 3, 2))


def test_box_drawmode_without_boxfill(tmp_path):
    body = '<setmkbound mk="0"/><setdrawmode mode="{}"/><drawbox><point x="1" y="1" z="1"/>' \
           '<size x="4" y="4" z="4"/></drawbox>'
    assert len(draw(tmp_path, body.format("full")).pos) == 125
    assert len(draw(tmp_path, body.format("solid")).pos) == 125
    assert len(draw(tmp_path, body.format("face")).pos) == 98
    # wire: 8 corners + 12 edges x 3 inner nodes
    assert len(draw(tmp_path, body.format("wire")).pos) == 8 + 12 * 3


def test_box_faces_add_and_remove(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((1, 1, 1), (4, 4, 4), fill="all ^ top ^ bottom"))
    assert len(d.pos) == 16 * 5
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((1, 1, 1), (4, 4, 4), fill="top | left ^ top"))
    assert np.all(d.pos[:, 0] == 1) and len(d.pos) == 25


def test_box_params_world_frame(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/><move x="1" y="1" z="1"/><scale x="2" y="1" z="1"/>'
             '<rotate ang="90" x="0" y="0" z="1"/>' + box((0, 0, 0), (1, 2, 3)))
    p = d.primitives[0]["params"]
    assert np.allclose(p["size"], [1, 4, 3]) and p["local_size"] == [1, 2, 3]
    assert np.allclose(np.abs(p["axes"]), [[0, 1, 0], [1, 0, 0], [0, 0, 1]])
    # <rotate> turns DualSPHysics's way (clockwise seen from +z): [0,1]x[0,2] -> [0,2]x[-1,0]
    assert np.allclose(p["min"], [1, 0, 1]) and np.allclose(p["max"], [5, 1, 4])


def test_box_rotated_by_angles(tmp_path):
    # 2x1x1 box rotated 90 degrees about z around its point (5,5,5): x in [4,5], y in [5,7]
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((5, 5, 5), (2, 1, 1),
                                                   extra='<angles x="0" y="0" z="90"/>'))
    assert nodes(d) == lattice_box((4, 5, 5), (5, 7, 6))


def test_box_rotated_faces(tmp_path):
    # a 45-degree rotated square plate (bottom face only) in 3D
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((5, 5, 3), (2, 2, 1), fill="bottom",
                                                    extra='<angles x="0" y="0" z="45"/>'))
    assert len(d.pos) > 0 and np.all(d.pos[:, 2] == 3)
    solid = draw(tmp_path, '<setmkbound mk="0"/>' + box((5, 5, 3), (2, 2, 0), fill="solid",
                                                        extra='<angles x="0" y="0" z="45"/>'))
    # the plate covers the solid (in-plane) nodes of the rotated square
    assert nodes(solid) <= nodes(d)


def test_box_clipped_to_domain(tmp_path):
    # GenCase's domain: floor((pointmax - pointmin)/dp) nodes per axis, none on pointmax
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((-5, -5, -5), (8, 8, 8)), pmax=(2, 2, 2))
    assert nodes(d) == lattice_box((0, 0, 0), (1, 1, 1))
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((-5, -5, -5), (8, 8, 8)), pmax=(2.5, 2.99, 3))
    assert nodes(d) == lattice_box((0, 0, 0), (1, 1, 2))
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((20, 20, 20), (8, 8, 8)), pmax=(2, 2, 2))
    assert len(d.pos) == 0


def test_overwrite_order_and_void(tmp_path):
    body = ('<setmkfluid mk="1"/>' + box((0, 0, 0), (4, 4, 4))
            + '<setmkbound mk="3"/>' + box((0, 0, 0), (4, 4, 0))
            + '<setmkvoid/>' + box((0, 0, 4), (4, 4, 0)))
    d = draw(tmp_path, body)
    assert len(d.pos) == 125 - 25
    assert nodes(d, fluid=False) == lattice_box((0, 0, 0), (4, 4, 0))
    assert nodes(d, fluid=True) == lattice_box((0, 0, 1), (4, 4, 3))
    assert set(d.mk[~d.is_fluid].tolist()) == {3} and set(d.mk[d.is_fluid].tolist()) == {1}


def test_order_of_particles_x_fastest(tmp_path):
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0, 0, 0), (1, 1, 1)))
    assert d.pos.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0],
                              [0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1]]


def test_pointref_alignment(tmp_path):
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0, 0, 0), (2, 2, 2)), dp=0.5,
             pmin=(0.25, 0.25, 0.25), pmax=(2, 2, 2), pointref=(0, 0, 0))
    assert d.origin.tolist() == [0.5, 0.5, 0.5]
    assert d.pos.min(axis=0).tolist() == [0.5, 0.5, 0.5]
    assert len(d.pos) == 3 ** 3 and d.pos.max(axis=0).tolist() == [1.5, 1.5, 1.5]
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0, 0, 0), (2, 2, 2)), dp=0.5,
             pmin=(0.25, 0.25, 0.25), pmax=(2, 2, 2))
    assert d.pos.min(axis=0).tolist() == [0.25, 0.25, 0.25]
    assert len(d.pos) == 3 ** 3 and d.pos.max(axis=0).tolist() == [1.25, 1.25, 1.25]


def test_2d_layer_only(tmp_path):
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0, -1, 0), (3, 2, 2)),
             pmin=(0, 0.5, 0), pmax=(5, 0.5, 5))
    assert d.is2d and d.posy2d == 0.5
    assert len(d.pos) == 4 * 3 and np.all(d.pos[:, 1] == 0.5)
    # a box that does not reach the 2D plane draws nothing
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0, 1, 0), (3, 2, 2)),
             pmin=(0, 0.5, 0), pmax=(5, 0.5, 5))
    assert len(d.pos) == 0


def test_floating_point_noise_never_loses_nodes(tmp_path):
    # 0.1 steps accumulate noise; every node of 0..3 (31 per axis) must be there
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0.3, 0, 0.3), (2.7, 0, 2.7)), dp=0.1,
             pmin=(0, 0, 0), pmax=(3.1000000001, 0, 3.1))
    assert len(d.pos) == 28 * 28


# ---------------------------------------------------------------- curved shapes
def brute(fn, lo=-6, hi=6):
    return {p for p in itertools.product(range(lo, hi + 1), repeat=3) if fn(*p)}


def shell_of(inside, is2d=False):
    dirs = [(1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)] + ([] if is2d else [(0, 1, 0), (0, -1, 0)])
    return {p for p in inside if any((p[0] + a, p[1] + b, p[2] + c) not in inside
                                     for a, b, c in dirs)}


SPHERE = '<setdrawmode mode="{mode}"/><setmkbound mk="0"/><drawsphere radius="{r}">' \
         '<point x="{c}" y="{c}" z="{c}"/></drawsphere>'


def test_sphere_solid_and_shell(tmp_path):
    ball = brute(lambda x, y, z: x * x + y * y + z * z <= 4)
    assert len(ball) == 33
    d = draw(tmp_path, SPHERE.format(mode="solid", r=2, c=5))
    assert nodes(d) == {(x + 5, y + 5, z + 5) for x, y, z in ball}
    # full mode fills CURVED_FULL_REACH = 0.6 dp beyond the surface (GenCase's records)
    d = draw(tmp_path, SPHERE.format(mode="full", r=2, c=5))
    assert nodes(d) == {(x + 5, y + 5, z + 5) for x, y, z in
                        brute(lambda x, y, z: x * x + y * y + z * z <= 2.6 ** 2)}
    d = draw(tmp_path, SPHERE.format(mode="face", r=2, c=5))
    shell = shell_of(ball)
    assert nodes(d) == {(x + 5, y + 5, z + 5) for x, y, z in shell}
    assert len(shell) == 26  # the centre and its 6 neighbours have all neighbours inside


def test_sphere_shell_is_closed(tmp_path):
    d = draw(tmp_path, SPHERE.format(mode="face", r=3.7, c=5))
    s = nodes(d)
    inside = brute(lambda x, y, z: (x - 5) ** 2 + (y - 5) ** 2 + (z - 5) ** 2 <= 3.7 ** 2, 0, 10)
    # flood from the centre through non-shell nodes never escapes the sphere
    seen, todo = set(), [(5, 5, 5)]
    while todo:
        p = todo.pop()
        if p in seen or p in s or not all(0 <= v <= 10 for v in p):
            continue
        seen.add(p)
        todo += [(p[0] + a, p[1] + b, p[2] + c) for a, b, c in
                 [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]]
    assert seen <= inside and seen


def test_circle_2d(tmp_path):
    d = draw(tmp_path, SPHERE.format(mode="solid", r=2, c=5), pmin=(0, 5, 0), pmax=(10, 5, 10))
    assert len(d.pos) == 13
    d = draw(tmp_path, SPHERE.format(mode="full", r=2, c=5), pmin=(0, 5, 0), pmax=(10, 5, 10))
    assert len(d.pos) == 21     # within 2.6: the 13 and (+-2, +-1), (+-1, +-2)
    d = draw(tmp_path, SPHERE.format(mode="face", r=2, c=5), pmin=(0, 5, 0), pmax=(10, 5, 10))
    assert len(d.pos) == 8  # the 2D ring: all but the centre and its 4 neighbours


def test_sphere_params_after_transform(tmp_path):
    d = draw(tmp_path, '<move x="1" y="0" z="0"/><scale x="2" y="2" z="2"/>'
             + SPHERE.format(mode="solid", r=1, c=2))
    p = d.primitives[0]["params"]
    assert p["center"] == [5, 4, 4] and p["radius"] == 2
    assert len(d.pos) == 33


CYL = '<setdrawmode mode="{mode}"/><setmkbound mk="0"/><drawcylinder radius="1.5" mask="{mask}">' \
      '<point x="5" y="5" z="2"/><point x="5" y="5" z="6"/></drawcylinder>'


@pytest.mark.parametrize("mode,mask,count", [("full", "0", 13 * 5), ("solid", "0", 45),
                                             ("face", "0", 9 + 9 + 3 * 8),
                                             ("face", "1 | 2", 5 * 8), ("face", "3", 9 + 9),
                                             ("face", "1", 9 + 4 * 8)])
def test_cylinder(tmp_path, mode, mask, count):
    d = draw(tmp_path, CYL.format(mode=mode, mask=mask))
    assert len(d.pos) == count
    assert d.pos[:, 2].min() >= 2 and d.pos[:, 2].max() <= 6


def test_cylinder_mask_hides_first_cover(tmp_path):
    d = draw(tmp_path, CYL.format(mode="face", mask="1"))
    layer2 = d.pos[d.pos[:, 2] == 2]
    assert len(layer2) == 8 and [5, 5, 2] not in layer2.tolist()
    assert len(d.pos[d.pos[:, 2] == 6]) == 9


def test_cylinder_oblique_matches_brute_force(tmp_path):
    p1, p2 = np.array([2, 3, 1.0]), np.array([8, 6, 7.0])
    u = (p2 - p1) / np.linalg.norm(p2 - p1)
    for mode, reach in (("solid", 0.0), ("full", 0.6)):
        body = (f'<setdrawmode mode="{mode}"/><setmkfluid mk="0"/><drawcylinder radius="2">'
                '<point x="2" y="3" z="1"/><point x="8" y="6" z="7"/></drawcylinder>')
        d = draw(tmp_path, body)

        def inside(x, y, z):
            v = np.array([x, y, z]) - p1
            t = v @ u
            return (-reach - 1e-9 <= t <= np.linalg.norm(p2 - p1) + reach + 1e-9
                    and v @ v - t * t <= (2 + reach) ** 2 + 1e-9)
        assert nodes(d) == brute(inside, 0, 9)      # the domain's nodes: 0..9


def test_ellipsoid_axes_and_foci(tmp_path):
    body = ('<setdrawmode mode="solid"/><setmkfluid mk="0"/><drawellipsoid><point x="5" y="5" z="5"/>'
            '<radius x="3" y="2" z="1"/></drawellipsoid>')
    d = draw(tmp_path, body)
    exp = brute(lambda x, y, z: x * x / 9 + y * y / 4 + z * z <= 1)
    assert nodes(d) == {(x + 5, y + 5, z + 5) for x, y, z in exp}
    # full mode: each semi-axis 0.6 dp longer
    d = draw(tmp_path, body.replace("solid", "full"))
    exp = brute(lambda x, y, z: x * x / 3.6 ** 2 + y * y / 2.6 ** 2 + z * z / 1.6 ** 2 <= 1)
    assert nodes(d) == {(x + 5, y + 5, z + 5) for x, y, z in exp}
    body = ('<setdrawmode mode="solid"/><setmkfluid mk="0"/><drawellipsoid radius="2"><point x="4" y="5" z="5"/>'
            '<point x="6" y="5" z="5"/></drawellipsoid>')
    d = draw(tmp_path, body)
    exp = brute(lambda x, y, z: np.hypot(np.hypot(x + 1, y), z) + np.hypot(np.hypot(x - 1, y), z)
                <= 4 + 1e-9)
    assert nodes(d) == {(x + 5, y + 5, z + 5) for x, y, z in exp}
    assert d.primitives[0]["params"]["radii"][0] == 2


# ---------------------------------------------------------------- polyhedra
PRISM = ('<setdrawmode mode="{mode}"/><setmkbound mk="0"/><drawprism mask="{mask}">'
         '<point x="0" y="0" z="0"/><point x="4" y="0" z="0"/><point x="0" y="4" z="0"/>'
         '<point x="0" y="0" z="2"/><point x="4" y="0" z="2"/><point x="0" y="4" z="2"/>'
         '</drawprism>')


@pytest.mark.parametrize("mode,mask,count", [("solid", "0", 45), ("full", "0", 45),
                                             ("face", "0", 15 + 15 + 12),
                                             ("face", "1 | 2", 3 * 12), ("wire", "0", 27)])
def test_prism(tmp_path, mode, mask, count):
    d = draw(tmp_path, PRISM.format(mode=mode, mask=mask))
    assert len(d.pos) == count
    assert np.all(d.pos[:, 0] + d.pos[:, 1] <= 4)


def test_pyramid_tetrahedron(tmp_path):
    body = ('<setdrawmode mode="solid"/><setmkfluid mk="0"/><drawpyramid>'
            '<point x="0" y="0" z="3"/><point x="0" y="0" z="0"/><point x="3" y="0" z="0"/>'
            '<point x="0" y="3" z="0"/></drawpyramid>')
    d = draw(tmp_path, body)
    assert nodes(d) == brute(lambda x, y, z: min(x, y, z) >= 0 and x + y + z <= 3, 0, 4)
    assert len(d.pos) == 20
    d = draw(tmp_path, body.replace('"solid"', '"face"').replace("<drawpyramid>",
                                                                  '<drawpyramid mask="1">'))
    # base hidden: no node of z=0 except those on the three side faces
    assert nodes(d) == brute(lambda x, y, z: min(x, y, z) >= 0 and x + y + z <= 3
                             and (x == 0 or y == 0 or x + y + z == 3), 0, 4)


# ---------------------------------------------------------------- planar shapes, lines, points
def test_polygon_2d_nonconvex(tmp_path):
    body = ('<setmkfluid mk="0"/><drawpolygon>'
            '<point x="0" y="0" z="0"/><point x="4" y="0" z="0"/><point x="4" y="0" z="2"/>'
            '<point x="2" y="0" z="2"/><point x="2" y="0" z="4"/><point x="0" y="0" z="4"/>'
            '</drawpolygon>')
    d = draw(tmp_path, body, pmin=(-2, 0, -2), pmax=(8, 0, 8))
    exp = {(x, 0, z) for x in range(5) for z in range(5) if x <= 2 or z <= 2}
    assert nodes(d) == exp


def test_triangle_quadri_strip_fan(tmp_path):
    q = ('<point x="1" y="1" z="3"/><point x="4" y="1" z="3"/><point x="4" y="4" z="3"/>'
         '<point x="1" y="4" z="3"/>')
    d = draw(tmp_path, f'<setmkbound mk="0"/><drawquadri>{q}</drawquadri>')
    assert nodes(d) == lattice_box((1, 1, 3), (4, 4, 3))
    d = draw(tmp_path, '<setmkbound mk="0"/><drawtriangle><point x="0" y="0" z="1"/>'
             '<point x="3" y="0" z="1"/><point x="0" y="3" z="1"/></drawtriangle>')
    assert nodes(d) == {(x, y, 1) for x in range(4) for y in range(4) if x + y <= 3}
    strip = ('<point x="0" y="0" z="2"/><point x="0" y="2" z="2"/><point x="2" y="0" z="2"/>'
             '<point x="2" y="2" z="2"/>')
    d = draw(tmp_path, f'<setmkbound mk="0"/><drawtrianglesstrip>{strip}</drawtrianglesstrip>')
    assert nodes(d) == lattice_box((0, 0, 2), (2, 2, 2))
    fan = ('<point x="1" y="1" z="2"/><point x="0" y="0" z="2"/><point x="2" y="0" z="2"/>'
           '<point x="2" y="2" z="2"/><point x="0" y="2" z="2"/>')
    d = draw(tmp_path, f'<setmkbound mk="0"/><drawtrianglesfan>{fan}</drawtrianglesfan>')
    assert nodes(d) == lattice_box((0, 0, 2), (2, 2, 2)) - {(0, 1, 2)}


def cube_triangles(lo=1, hi=5):
    v = [[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (lo, hi)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, e in faces:
        tris += [(a, b, c), (a, c, e)]
    return v, tris


def test_drawtriangles_closed_cube(tmp_path):
    v, tris = cube_triangles()
    pts = "".join(f'<point x="{x}" y="{y}" z="{z}"/>' for x, y, z in v)
    tri = "".join(f'<triangle x="{a}" y="{b}" z="{c}"/>' for a, b, c in tris)
    d = draw(tmp_path, f'<setmkbound mk="0"/><drawtriangles><points>{pts}</points>'
             f'<triangles>{tri}</triangles></drawtriangles>')
    assert nodes(d) == lattice_box((1, 1, 1), (5, 5, 5)) - lattice_box((2, 2, 2), (4, 4, 4))


def test_lines_and_points(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/><drawline><point x="0" y="1" z="1"/>'
             '<point x="4" y="1" z="1"/></drawline>')
    assert nodes(d) == {(x, 1, 1) for x in range(5)}
    d = draw(tmp_path, '<setmkbound mk="0"/><drawline><point x="0" y="0" z="0"/>'
             '<point x="4" y="4" z="4"/></drawline>')
    assert nodes(d) == {(i, i, i) for i in range(5)}
    d = draw(tmp_path, '<setmkbound mk="0"/><drawlines><point x="0" y="0" z="0"/>'
             '<point x="2" y="0" z="0"/><point x="2" y="0" z="2"/></drawlines>')
    assert nodes(d) == {(0, 0, 0), (1, 0, 0), (2, 0, 0), (2, 0, 1), (2, 0, 2)}
    d = draw(tmp_path, '<setmkbound mk="0"/><setlinebegin x="0" y="0" z="0"/>'
             '<drawlineto x="0" y="2" z="0"/><drawlineto x="2" y="2" z="0"/>')
    assert nodes(d) == {(0, 0, 0), (0, 1, 0), (0, 2, 0), (1, 2, 0), (2, 2, 0)}
    d = draw(tmp_path, '<setmkfluid mk="4"/><drawpoint x="1.4" y="2.6" z="3.5"/>'
             '<drawpoints><point x="0" y="0" z="0"/><point x="-3" y="0" z="0"/></drawpoints>')
    assert nodes(d) == {(1, 3, 4), (0, 0, 0)}


def test_long_line_clipped(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/><drawline><point x="-1e12" y="1" z="1"/>'
             '<point x="1e12" y="1" z="1"/></drawline>')
    assert nodes(d) == {(x, 1, 1) for x in range(10)}


# ---------------------------------------------------------------- transforms
def test_move_rotate_order(tmp_path):
    # rotate first (90 deg about z, DualSPHysics's sense: clockwise seen from +z), then move:
    # box [0,2]x[0,1]x[0,1] -> x in [0,1], y in [-2,0] -> +5
    d = draw(tmp_path, '<setmkfluid mk="0"/><move x="5" y="5" z="5"/><rotate ang="90" x="0" '
             'y="0" z="1"/>' + box((0, 0, 0), (2, 1, 1)))
    assert nodes(d) == lattice_box((5, 3, 5), (6, 5, 6))


def test_rotateline_scale_and_matrix_stack(tmp_path):
    body = ('<setmkfluid mk="0"/><rotateline ang="180"><point x="5" y="0" z="0"/>'
            '<point x="5" y="1" z="0"/></rotateline>' + box((1, 1, 0), (1, 1, 1)))
    d = draw(tmp_path, body, pmin=(-10, -10, -10))
    # 180 deg about the line x=5, z=0 (along y): x -> 10-x, z -> -z
    assert nodes(d) == lattice_box((8, 1, -1), (9, 2, 0))
    body = ('<setmkfluid mk="0"/><matrixsave/><scale x="2" y="1" z="1"/>' + box((1, 1, 1), (1, 0, 0))
            + '<matrixload/>' + box((0, 5, 0), (0, 0, 0)))
    d = draw(tmp_path, body)
    assert nodes(d) == {(2, 1, 1), (3, 1, 1), (4, 1, 1), (0, 5, 0)}
    body = ('<setmkfluid mk="0"/><move x="3" y="0" z="0"/><matrixreset/>' + box((0, 0, 0), (0, 0, 0)))
    assert nodes(draw(tmp_path, body)) == {(0, 0, 0)}


def test_statesave_stateload(tmp_path):
    body = ('<setmkfluid mk="1"/><statesave/><setmkbound mk="7"/><move x="2" y="0" z="0"/>'
            '<stateload/>' + box((0, 0, 0), (0, 0, 0)))
    d = draw(tmp_path, body)
    assert nodes(d) == {(0, 0, 0)} and d.is_fluid.all() and d.mk.tolist() == [1]
    body = '<setmkfluid mk="1"/><mksave/><setmkbound mk="7"/><mkload/>' + box((0, 0, 0), (0, 0, 0))
    d = draw(tmp_path, body)
    assert d.is_fluid.all() and d.mk.tolist() == [1]


# ---------------------------------------------------------------- fills
TANK = '<setmkbound mk="0"/>' + box((0, 0, 0), (6, 6, 6), fill="all")


def test_fillpoint_void_inside_tank(tmp_path):
    d = draw(tmp_path, TANK + '<setmkfluid mk="2"/><fillpoint x="3" y="3" z="3">'
             '<modefill>void</modefill></fillpoint>')
    assert nodes(d, fluid=True) == lattice_box((1, 1, 1), (5, 5, 5))
    assert len(d.pos) == 7 ** 3
    d = draw(tmp_path, TANK + '<setmkfluid mk="2"/><fillvoidpoint x="3" y="3" z="3"/>')
    assert d.count_fluid == 125


def test_fillbox_limits(tmp_path):
    d = draw(tmp_path, TANK + '<setmkfluid mk="2"/><fillbox x="3" y="3" z="2">'
             '<modefill>void</modefill><point x="0" y="0" z="0"/><size x="6" y="6" z="3"/>'
             '</fillbox>')
    # the top z=3 is a node on the box's face: not filled (GenCase fills the nodes at least dp/2 inside a <fillbox> (see test_draw_gencase_counts.py))
    assert nodes(d, fluid=True) == lattice_box((1, 1, 1), (5, 5, 2))


def test_fill_modes_fluid_bound_and_filters(tmp_path):
    pre = TANK + '<setmkfluid mk="2"/><fillvoidpoint x="3" y="3" z="3"/>'
    # void erases the fluid (modefill fluid), walls stay
    d = draw(tmp_path, pre + '<setmkvoid/><fillpoint x="3" y="3" z="3"><modefill>fluid</modefill>'
             '</fillpoint>')
    assert d.count_fluid == 0 and d.count_bound == 7 ** 3 - 5 ** 3
    # through fluid and bound: the whole tank becomes mk 9 fluid
    d = draw(tmp_path, pre + '<setmkfluid mk="9"/><fillpoint x="3" y="3" z="3">'
             '<modefill>fluid | bound</modefill></fillpoint>')
    assert d.count_fluid == 7 ** 3 and set(d.mk.tolist()) == {9}
    # mkfluid filter: only fluid of mk 5 is fillable -> nothing happens
    d = draw(tmp_path, pre + '<setmkfluid mk="9"/><fillpoint x="3" y="3" z="3" mkfluid="5">'
             '<modefill>fluid</modefill></fillpoint>')
    assert set(d.mk[d.is_fluid].tolist()) == {2}
    # border alone acts as void: seed on a fluid node fills nothing
    d = draw(tmp_path, pre + '<setmkfluid mk="9"/><fillpoint x="3" y="3" z="3">'
             '<modefill>border</modefill></fillpoint>')
    assert set(d.mk[d.is_fluid].tolist()) == {2}


def test_fill_leaks_through_open_top(tmp_path):
    body = ('<setmkbound mk="0"/>' + box((0, 0, 0), (6, 6, 6), fill="bottom | left | right | front | back")
            + '<setmkfluid mk="0"/><fillbox x="3" y="3" z="3"><modefill>void</modefill>'
            '<point x="-1.5" y="-1.5" z="-1.5"/><size x="9" y="9" z="9"/></fillbox>')
    d = draw(tmp_path, body, pmin=(-2, -2, -2), pmax=(8, 8, 8))
    # nodes -1 ... 7 lie at least dp/2 inside the fill box (GenCase fills the nodes at least dp/2 inside a <fillbox> (see test_draw_gencase_counts.py))
    # the fill escapes over the walls (top z=6) and fills the whole fill box but the walls
    walls = 7 * 7 + 24 * 6
    assert d.count_bound == walls
    assert d.count_fluid == 9 ** 3 - walls


def test_fill_2d(tmp_path):
    body = ('<setmkbound mk="0"/>' + box((0, -1, 0), (6, 2, 6), fill="all")
            + '<setmkfluid mk="1"/><fillvoidpoint x="2" y="0" z="2"/>')
    d = draw(tmp_path, body, pmin=(-1, 0, -1), pmax=(8, 0, 8))
    assert d.count_fluid == 25 and d.count_bound == 24


# ---------------------------------------------------------------- variables and lists
def test_variables_predefinition_and_builtins(tmp_path):
    predef = '<predefinition><newvarcte L="2"/><newvar H="L+1"/></predefinition>'
    body = ('<setmkfluid mk="0"/><newvar half="Dp/2" top="PosMax_z-1"/>'
            '<drawbox><point x="0" y="0" z="#top-H"/><size x="#L" y="0" z="#H"/></drawbox>')
    d = draw(tmp_path, body, predef=predef)
    assert nodes(d) == lattice_box((0, 0, 6), (2, 0, 9))


def test_runlist_loop_with_counter(tmp_path):
    lists = '<list name="step"><drawpoint x="#i" y="0" z="0"/><setvar i="i+1"/></list>'
    body = '<setmkbound mk="0"/><newvar i="0"/><runlist name="step" times="5"/>'
    d = draw(tmp_path, body, lists=lists)
    assert nodes(d) == {(i, 0, 0) for i in range(5)}


def test_strings_printf_delvar(tmp_path, capsys):
    body = ('<newvarstr T="ab"/><newvarstr U="[T]_[Dp*100]"/><printf text="U=[U]\\nok"/>'
            '<printf if="Dp&gt;2" text="never"/><newvar x1="1" x2="2"/><delvar vars="x*"/>'
            '<printf text="[Data2D]"/>')
    d = draw(tmp_path, body)
    assert d.messages == ["U=ab_100\nok", "0"]
    assert "U=ab_100" in capsys.readouterr().out


def test_abort(tmp_path):
    with pytest.raises(CaseError, match="too small"):
        draw(tmp_path, '<abort if="Dp&lt;2" text="Dp [Dp] too small"/>')
    draw(tmp_path, '<abort if="Dp&gt;2" text="no"/>')


def test_setactive_drawpoints(tmp_path):
    d = draw(tmp_path, '<setmkfluid mk="0"/><setactive drawpoints="false"/>' + box((0, 0, 0), (1, 1, 1))
             + '<setactive drawpoints="true"/>' + box((5, 5, 5), (0, 0, 0)))
    assert nodes(d) == {(5, 5, 5)}


def test_no_effect_commands_accepted(tmp_path):
    d = draw(tmp_path, '<setdpctes cteline="0.1"/><setshapemode>actual | dp</setshapemode>'
             '<debugout/><setmkfluid mk="0"/>' + box((0, 0, 0), (0, 0, 0)))
    assert len(d.pos) == 1


def test_triangle_raster_matches_its_definition():
    """The compiled triangle rasteriser marks exactly the nodes its rule describes."""
    from sphdvi.case.draw import kernels
    rng = np.random.default_rng(7)
    g = np.stack(np.meshgrid(*[np.arange(-2, 13)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    for _ in range(40):
        tri = rng.uniform(0, 10, (1, 3, 3))
        out = np.zeros((15, 15, 15), dtype=bool)
        kernels.raster_triangles(tri, np.array([-2, -2, -2]), out, -0.5 + 1e-6, 0.5 + 1e-6, 0.5 + 1e-6)
        a, b, c = tri[0]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        w = (g - a) @ n
        q = g - w[:, None] * n
        # distance of q to the triangle (inside -> 0), by dense sampling of the closed triangle
        uv = np.array([(u, v) for u in np.linspace(0, 1, 121) for v in np.linspace(0, 1, 121)
                       if u + v <= 1])
        samples = a + uv[:, :1] * (b - a) + uv[:, 1:] * (c - a)
        band = (w > -0.5 + 1e-6) & (w <= 0.5 + 1e-6)
        exp = np.zeros(len(g), bool)
        idx = np.nonzero(band)[0]
        if idx.size:
            d = np.sqrt(((q[idx, None, :] - samples[None]) ** 2).sum(-1)).min(axis=1)
            exp[idx] = d <= 0.5 + 1e-6
            unsure = np.abs(d - 0.5) < 0.02  # sampling error near the edge tolerance
        got = out.reshape(-1)
        if idx.size:
            keep = np.ones(len(g), bool)
            keep[idx[unsure]] = False
            assert np.array_equal(got[keep], exp[keep])
        else:
            assert not got.any()


def test_box_faces_follow_a_quarter_turn(tmp_path):
    # after <rotate ang="90"> about z (DualSPHysics's sense: (x, y) -> (y, -x)), local x runs
    # along world -y: the "left" face (local x min, x = 1) becomes the world y-max face y = -1,
    # "front" (local y min, y = -5) the world x-min face x = -5
    body = '<setmkbound mk="0"/><rotate ang="90" x="0" y="0" z="1"/>'
    d = draw(tmp_path, body + box((1, -5, 1), (2, 2, 2), fill="left"), pmin=(-10, -10, -10))
    assert np.all(d.pos[:, 1] == -1) and len(d.pos) == 9
    d = draw(tmp_path, body + box((1, -5, 1), (2, 2, 2), fill="front"), pmin=(-10, -10, -10))
    assert np.all(d.pos[:, 0] == -5) and len(d.pos) == 9


def test_curved_modes_solid_and_wire(tmp_path):
    full = draw(tmp_path, SPHERE.format(mode="full", r=2.5, c=5))
    solid = draw(tmp_path, SPHERE.format(mode="solid", r=2.5, c=5))
    face = draw(tmp_path, SPHERE.format(mode="face", r=2.5, c=5))
    wire = draw(tmp_path, SPHERE.format(mode="wire", r=2.5, c=5))
    assert nodes(solid) < nodes(full)          # full reaches 0.6 dp beyond the surface
    assert nodes(face) == nodes(wire) and nodes(face) < nodes(solid)


def test_void_sphere_carves_a_box(tmp_path):
    d = draw(tmp_path, '<setmkfluid mk="0"/>' + box((0, 0, 0), (10, 10, 10))
             + '<setmkvoid/>' + SPHERE.format(mode="solid", r=2, c=5).replace('<setmkbound mk="0"/>', ""))
    assert len(d.pos) == 10 ** 3 - 33
    assert (5, 5, 5) not in nodes(d)


def test_printf_in_predefinition_and_list_calls(tmp_path):
    predef = '<predefinition><newvar n="3"/><printf text="n=[n]"/></predefinition>'
    lists = '<list name="inner"><setvar n="n+1"/></list><list name="outer"><runlist name="inner" times="2"/></list>'
    d = draw(tmp_path, '<runlist name="outer" times="3"/><printf text="[n]"/>', predef=predef, lists=lists)
    assert d.messages == ["n=3", "9"]


def test_box_layers(tmp_path):
    """A face's layers move it along its normal, widened towards its drawn neighbours only (GenCase
    v5: a 3 m x 3 m floor with <layers vdp="0,1,2"> at dp 0.0064 wrote 3 x 470^2 particles; GenCase
    v5.4: the 4 layers of a boxfill-all 2D tank closed rings of 1410 + 8k particles, an all^top 3D
    tank 361,104 with its walls ending at their layer-0 top)."""
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="bottom",
                                                   extra='<layers vdp="0,1*,2"/>'))
    assert len(d.pos) == 3 * 25
    assert sorted(set(d.pos[:, 2].tolist())) == [1, 2, 3]
    assert set(d.pos[:, 0].tolist()) == {3, 4, 5, 6, 7}
    assert [p["params"]["layer"] for p in d.primitives] == [0, 1, 2]
    # a tank with 3-layer walls keeps its fluid inside; its layers are closed shells, edges and
    # corners included (cubes of 5, 7 and 9 nodes a side)
    body = ('<setmkfluid mk="0"/>' + box((3, 3, 3), (4, 4, 4))
            + '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="all",
                                           extra='<layers vdp="0,1,2"/>'))
    d = draw(tmp_path, body)
    assert d.count_fluid == 27 and d.count_bound == 9 ** 3 - 27
    # an open tank (no top): the walls' layers do not rise above the layer-0 top (z = 7), its
    # floor and walls widen towards each other
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="bottom | left | right | front | back",
                                                   extra='<layers vdp="0,1"/>'))
    assert len(d.pos) == (5 ** 3 - 3 ** 2 * 4) + (7 * 7 * 6 - 5 * 5 * 5) and d.pos[:, 2].max() == 7
    # front and back only: moved along y, not widened (no drawn neighbour)
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="front | back",
                                                   extra='<layers vdp="0,1"/>'))
    assert len(d.pos) == 4 * 25 and set(d.pos[:, 1].tolist()) == {2, 3, 7, 8}
    # a solid box's layers still widen it on every side
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="solid",
                                                   extra='<layers vdp="0,1"/>'))
    assert len(d.pos) == 7 ** 3
    # an inward layer that shrinks the box away is skipped with a warning
    d = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (2, 2, 2), fill="all",
                                                   extra='<layers vdp="0,-2"/>'))
    assert len(d.pos) == 26


def test_empty_layers_list_draws_the_shape_once(tmp_path):
    # <layers vdp=""/>: GenCase v5.4 drew the shape once (yupengxiang/DualSPHysics F2_SLOT_TRANSFER:
    # its counts with the attribute and without it are the same)
    plain = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="all"))
    empty = draw(tmp_path, '<setmkbound mk="0"/>' + box((3, 3, 3), (4, 4, 4), fill="all", extra='<layers vdp=""/>'))
    assert np.array_equal(plain.pos, empty.pos) and len(empty.pos) == 98


def test_sphere_and_cylinder_layers(tmp_path):
    one = draw(tmp_path, SPHERE.format(mode="face", r=2, c=5))
    two = draw(tmp_path, SPHERE.format(mode="face", r=2, c=5).replace(
        "</drawsphere>", '<layers vdp="0,1"/></drawsphere>'))
    big = draw(tmp_path, SPHERE.format(mode="face", r=3, c=5))
    assert nodes(two) == nodes(one) | nodes(big)
    d = draw(tmp_path, CYL.format(mode="face", mask="0").replace(
        "</drawcylinder>", '<layers vdp="1"/></drawcylinder>'))
    # radius 2.5, covers at z=1 and z=7: 21 nodes per cover, 12 side nodes per layer
    assert len(d.pos) == 21 + 21 + 5 * 12


# ---------------------------------------------------------------- fillbox under a rotation
def _turned_box_nodes(lat_max, ang, point, size, margin, is2d=False):
    """Nodes (dp 1 lattice 0..lat_max) whose coordinates, turned back by ``ang`` degrees about
    y through the origin, lie in [point - margin, point + size + margin] (margin < 0 shrinks)."""
    from sphdvi.case.draw import transform as tf     # <rotate>'s sense: test_rotation_sense.py
    back = tf.inverse(tf.rotation_line(ang, np.zeros(3), (0, 1, 0)))
    out = set()
    ys = [0] if is2d else range(lat_max + 1)
    for x in range(lat_max + 1):
        for y in ys:
            for z in range(lat_max + 1):
                q = tf.apply(back, np.array([[x, y, z]], dtype=float))[0]
                m = np.array([margin, 0.0 if is2d else margin, margin])
                if np.all(q >= np.array(point) - m - 1e-9) and np.all(q <= np.array(point) + size + m + 1e-9):
                    out.add((x, y, z))
    return out


@pytest.mark.parametrize("is2d", [False, True])
def test_fillbox_under_a_rotation_fills_the_turned_box(tmp_path, is2d):
    """A void lattice filled from a seed inside a box turned 30 degrees: the nodes at least dp/2
    inside it along its own axes (inner), or those of a solid <drawbox> under the same rotation
    (setboxlimitmode full)."""
    kw = dict(pmin=(0, 0, 0), pmax=(12, 0, 12)) if is2d else dict(pmin=(0, 0, 0), pmax=(12, 12, 12))
    turn = '<rotate ang="30" x="0" y="1" z="0"/>'
    y0, ysize = (-1, 2) if is2d else (2, 6.5)       # a 2D case: the plane y = 0 inside the box
    box = f'<point x="4" y="{y0}" z="0.5"/><size x="6" y="{ysize}" z="5"/>'
    fill = f'<setmkfluid mk="0"/>{turn}<fillbox x="7" y="{0 if is2d else 5}" z="3">{box}</fillbox>'
    d = draw(tmp_path, fill, **kw)
    expect = _turned_box_nodes(11, 30, (4, y0, 0.5), np.array([6, ysize, 5]), -0.5, is2d)
    assert nodes(d) == expect and len(expect) > (15 if is2d else 100)
    full = draw(tmp_path, '<setboxlimitmode mode="full"/>' + fill, **kw)
    solid = draw(tmp_path, f'<setmkfluid mk="0"/>{turn}<drawbox><boxfill>solid</boxfill>{box}</drawbox>', **kw)
    assert nodes(full) == nodes(solid) and nodes(full) > nodes(d)


def test_fillbox_under_a_rotation_stops_at_walls(tmp_path):
    """A tank turned 20 degrees and filled under the same rotation: the water stays inside."""
    turn = '<rotate ang="20" x="0" y="1" z="0"/>'
    body = (f'<setmkbound mk="0"/>{turn}<drawbox><boxfill>bottom | left | right</boxfill>'
            '<point x="4" y="-1" z="1"/><size x="12" y="2" z="8"/></drawbox>'
            '<setmkfluid mk="0"/><fillbox x="8" y="0" z="3"><modefill>void</modefill>'
            '<point x="4" y="-1" z="1"/><size x="12" y="2" z="6"/></fillbox>')
    d = draw(tmp_path, body, pmin=(0, 0, 0), pmax=(22, 0, 22))
    water = nodes(d, fluid=True)
    expect = _turned_box_nodes(21, 20, (4, 0, 1), np.array([12, 0, 6]), -0.5, True) - nodes(d, fluid=False)
    assert water == expect and len(water) > 40

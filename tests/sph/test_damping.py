"""Damping zones (``<special><damping>``, DualSPHysics's JDsDamping): the per-component
multiplier max(0, 1 − dt·redumax·f²·factor) of v5.x, the plane zone with its lateral
``<domain>``, ``<dampingbox>`` and ``<dampingcylinder>``, against transcriptions of
JDsDampingOp_*::ComputeDampingCpu; and how the case reader reads them."""
import math
import re
from types import SimpleNamespace

import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

from sphdvi.case.gencase import build_case
from sphdvi.errors import CaseError
from sphdvi.sph.damping import DampingBox, DampingCylinder, DampingZone, damping_zones
from sphdvi.sph.state import FLUID

V0 = np.array([1.0, 0.5, -2.0])


def state(points, ptype=FLUID):
    pos = np.asarray(points, float).reshape(-1, 3)
    return SimpleNamespace(pos=pos, vel=np.tile(V0, (pos.shape[0], 1)), ptype=np.full(pos.shape[0], ptype))


def multiplier(f, dt, redumax, factor):
    """One particle's multiplier as DualSPHysics v5.x writes it: per component, then floored at 0."""
    m = [1.0 - dt * f * f * redumax * k for k in factor]
    return np.array([x if x >= 0 else 0.0 for x in m])


PLANE = {"limitmin": [1.0, 0, 0], "limitmax": [2.0, 0, 0], "overlimit": 0.5}


@pytest.mark.parametrize("redumax, dt, factor", [(10, 1e-4, (1, 1, 0.5)), (2e4, 1e-4, (0.5, 0.5, 0.5)),
                                                 (1e4, 1e-4, (3, 1, 1))])
def test_plane_zone_multiplier_is_floored_per_component(redumax, dt, factor):
    """A factor above 1 with a large reduction stopped nothing and reversed the velocity
    (v *= 1 − min(1, dt·redumax·f²)·factor = −2 for factor 3); DualSPHysics floors each
    component's multiplier at 0."""
    zone = DampingZone(dict(PLANE, redumax=redumax, factorxyz=list(factor)))
    xs = [0.5, 1.0, 1.25, 1.5, 2.0, 2.4, 2.5, 2.6]
    s = state([[x, 0, 0] for x in xs])
    zone.apply(s, dt)
    for x, v in zip(xs, s.vel):
        d = x - 1.0
        if 0 < d <= 1.5:
            expect = V0 * multiplier(1.0 if d >= 1.0 else d, dt, redumax, factor)
        else:
            expect = V0
        np.testing.assert_allclose(v, expect, rtol=0, atol=1e-15, err_msg=f"x={x}")
    assert np.all(s.vel * V0 >= 0)          # never reversed


def test_only_fluid_is_damped():
    s = state([[1.5, 0, 0]], ptype=0)
    DampingZone(PLANE).apply(s, 1e-3)
    assert np.array_equal(s.vel[0], V0)


def test_plane_zone_domain_limits_it_laterally():
    """<domain zmin zmax><point1..4 x y>: only particles inside the quadrilateral (any order
    of its corners, as ComputeDomPlanes sorts them) and the z range."""
    for corners in ([[1, -1], [3, -1], [3, 1], [1, 1]], [[1, -1], [3, 1], [1, 1], [3, -1]]):
        zone = DampingZone(dict(PLANE, domain={"zmin": 0.0, "zmax": 1.0, "points": corners}))
        pts = [[1.5, 0, 0.5], [1.5, 0.9, 0.5], [1.5, 1.1, 0.5], [1.5, 0, 1.2], [1.5, 0, -0.1], [2.5, -0.5, 0.0]]
        s = state(pts)
        zone.apply(s, 1e-3)
        damped = [not np.array_equal(v, V0) for v in s.vel]
        assert damped == [True, True, False, False, False, True], corners


def box_reference(ps, min1, min2, max1, max2, over, dirs):
    """fdis of JDsDampingOp_Box::ComputeDampingCpu (None: not damped), its set-up included."""
    min1, min2, max1, max2 = (np.array(v, float) for v in (min1, min2, max1, max2))
    o1, o2 = max1 - over, max2 + over
    for name, hi, ax in (("top", 1, 2), ("back", 1, 1), ("right", 1, 0), ("bottom", 0, 2), ("front", 0, 1),
                         ("left", 0, 0)):
        if name not in dirs:
            if hi:
                max2[ax] = o2[ax] = min2[ax]
            else:
                max1[ax] = o1[ax] = min1[ax]
    s1, s2 = np.maximum(min1 - max1, 0), np.maximum(max2 - min2, 0)
    ps = np.asarray(ps, float)
    if not (np.all(o1 <= ps) and np.all(ps <= o2)) or (np.all(min1 <= ps) and np.all(ps <= min2)):
        return None
    f = 1.0
    if np.all(max1 <= ps) and np.all(ps <= max2):
        f = 0.0
        for ax in (2, 1, 0):
            if s2[ax]:
                f = max(f, (ps[ax] - min2[ax]) / s2[ax])
        for ax in (2, 1, 0):
            if s1[ax]:
                f = max(f, (min1[ax] - ps[ax]) / s1[ax])
    return f


@pytest.mark.parametrize("dirs", [("left", "right", "front", "back", "top", "bottom"), ("right", "top")])
def test_box_zone_as_dualsphysics(dirs):
    spec = {"type": "box", "limitmin": [[0, 0, 0], [1, 1, 1]], "limitmax": [[-0.5, -0.5, -0.5], [2, 2, 1.5]],
            "overlimit": 0.25, "redumax": 50.0, "factorxyz": [1, 1, 1], "directions": list(dirs)}
    (zone,) = damping_zones([spec])
    assert isinstance(zone, DampingBox)
    rng = np.random.default_rng(3)
    pts = rng.uniform(-1.0, 2.5, size=(400, 3))
    s = state(pts)
    zone.apply(s, 1e-3)
    for p, v in zip(pts, s.vel):
        f = box_reference(p, *spec["limitmin"], *spec["limitmax"], 0.25, dirs)
        expect = V0 if f is None else V0 * multiplier(f, 1e-3, 50.0, (1, 1, 1))
        np.testing.assert_allclose(v, expect, rtol=0, atol=1e-14, err_msg=str(p))


@pytest.mark.parametrize("p2", [[0, 0, 1], [1, 0, 1]])
def test_cylinder_zone_as_dualsphysics(p2):
    zone = DampingCylinder({"point1": [0, 0, 0], "point2": p2, "limitmin": 1.0, "limitmax": 2.0,
                            "overlimit": 0.5, "redumax": 100.0})
    rng = np.random.default_rng(5)
    pts = rng.uniform(-3, 3, size=(400, 3))
    s = state(pts)
    zone.apply(s, 1e-3)
    a = np.asarray(p2, float)
    for p, v in zip(pts, s.vel):
        if p2[:2] == [0, 0]:
            r = math.hypot(p[0], p[1])
        else:   # twice the triangle's area over the base (fgeo::LinePointDist)
            r = np.linalg.norm(np.cross(p, a)) / np.linalg.norm(a)
        vdis = r - 1.0
        expect = V0 * multiplier(min(vdis / 1.0, 1.0), 1e-3, 100.0, (1, 1, 1)) if 0 < vdis <= 1.5 else V0
        np.testing.assert_allclose(v, expect, rtol=0, atol=1e-14)


# -- the case reader -------------------------------------------------------------------
def build(tmp_path, damping):
    return build_case(write_case(tmp_path, case_xml(dp="0.05", special=f"<damping>{damping}</damping>")),
                      str(tmp_path / "out"))


ZONE = '<limitmin x="3" y="0" z="0"/><limitmax x="3.9" y="0" z="0"/>'


def test_factorxyz_components_default_to_one(tmp_path):
    """DualSPHysics reads x, y and z of <factorxyz> each with default 1 (sphdvi required all three)."""
    r = build(tmp_path, f'<dampingzone>{ZONE}<factorxyz z="0.5"/></dampingzone>'
                        f'<dampingzone>{ZONE}<factorxyz/></dampingzone>')
    assert [z["factorxyz"] for z in r.case.special["damping"]] == [[1.0, 1.0, 0.5], [1.0, 1.0, 1.0]]


def test_domain_box_and_cylinder_are_read(tmp_path):
    r = build(tmp_path,
              f'<dampingzone>{ZONE}<overlimit value="0.1"/><domain zmin="0" zmax="2"><point1 x="3" y="-1"/>'
              '<point2 x="5" y="-1"/><point3 x="5" y="1"/><point4 x="3" y="1"/></domain></dampingzone>'
              '<dampingbox><directions value="all, -top"/><limitmin><pointini x="0" y="-1" z="0"/>'
              '<pointend x="1" y="1" z="1"/></limitmin><limitmax><pointini x="-1" y="-1" z="-1"/>'
              '<pointend x="2" y="1" z="2"/></limitmax><factorxyz x="0.5"/></dampingbox>'
              '<dampingcylinder><point1 x="0" y="0" z="0"/><point2 x="0" y="0" z="1"/><limitmin radius="1"/>'
              '<limitmax radius="2"/><redumax value="20"/></dampingcylinder>')
    plane, box, cyl = r.case.special["damping"]
    assert plane["domain"] == {"zmin": 0.0, "zmax": 2.0, "points": [[3, -1], [5, -1], [5, 1], [3, 1]]}
    assert box["type"] == "box" and box["directions"] == ["left", "front", "bottom", "right", "back"]
    assert box["limitmin"] == [[0, -1, 0], [1, 1, 1]] and box["factorxyz"] == [0.5, 1, 1]
    assert cyl["type"] == "cylinder" and (cyl["limitmin"], cyl["limitmax"], cyl["redumax"]) == (1, 2, 20)
    assert [type(z).__name__ for z in damping_zones(r.case.special["damping"])] == \
        ["DampingZone", "DampingBox", "DampingCylinder"]


BOX = ('<limitmin><pointini x="0" y="-1" z="0"/><pointend x="1" y="1" z="1"/></limitmin>'
       '<limitmax><pointini x="-1" y="-1" z="-1"/><pointend x="2" y="1" z="2"/></limitmax>')


@pytest.mark.parametrize("damping, message", [
    (f'<dampingbox><directions value="up"/>{BOX}</dampingbox>', "direction 'up' is not valid"),
    (f'<dampingbox><directions value="-top"/>{BOX}</dampingbox>', "no direction is active"),
    ('<dampingbox><limitmin><pointini x="0" y="-1" z="0"/><pointend x="1" y="1" z="1"/></limitmin>'
     '<limitmax><pointini x="0.5" y="-1" z="-1"/><pointend x="2" y="1" z="2"/></limitmax></dampingbox>',
     "the <limitmin> box is not inside the <limitmax> box"),
    ('<dampingcylinder><point1 x="0" y="0" z="0"/><point2 x="0" y="0" z="1"/><limitmin radius="2"/>'
     '<limitmax radius="1"/></dampingcylinder>', "limitmin radius 2 is above limitmax radius 1"),
    (f'<dampingzone>{ZONE}<domain zmin="0" zmax="1"><point1 x="0" y="0"/></domain></dampingzone>',
     "missing child element <point2>"),
    (f'<dampingzone>{ZONE}<factorxyz x="-1"/></dampingzone>', "factors >= 0"),
    ('<dampingring/>', "unknown damping zone <dampingring>"),
])
def test_bad_damping_is_a_case_error(tmp_path, damping, message):
    with pytest.raises(CaseError, match=r"Case_Def.xml:\d+: .*" + re.escape(message)):
        build(tmp_path, damping)


ZONES = [PLANE, {**PLANE, "limitmin": [1.0, 0.2, -0.3], "limitmax": [2.0, 0.7, 0.4], "factorxyz": [1, 0.5, 2],
                 "domain": {"zmin": -1.0, "zmax": 0.8, "points": [[0, -1], [3, -1], [3, 1.5], [0, 1.2]]}},
         {"type": "box", "limitmin": [[0, 0, 0], [1, 1, 1]], "limitmax": [[-0.5, -0.5, -0.5], [2, 2, 1.5]],
          "overlimit": 0.25, "redumax": 50.0, "directions": ["right", "top", "front"]},
         {"type": "cylinder", "point1": [0.1, 0.2, 0], "point2": [0.1, 0.2, 1], "limitmin": 0.5, "limitmax": 1.5,
          "overlimit": 0.5, "redumax": 100.0},
         {"type": "cylinder", "point1": [0, 0, 0], "point2": [1, 0.3, 1], "limitmin": 0.5, "limitmax": 1.5,
          "overlimit": 0.5, "redumax": 100.0}]


@pytest.mark.parametrize("spec", ZONES, ids=["plane", "plane-domain", "box", "cylinder-vertical", "cylinder"])
def test_compiled_loop_matches_the_zone_selection(spec):
    """apply() is one compiled loop (ComputeDampingCpu); it damps exactly the fluid particles that
    the zone's numpy definition (select) holds, by the same multiplier (to the last bit, but for
    the oblique plane's distance, a dot product numpy's BLAS sums in another order: to round-off),
    and leaves the others (outside, or not fluid) untouched."""
    import numba
    from sphdvi.sph import damping as D
    (zone,) = damping_zones([spec])
    rng = np.random.default_rng(11)
    pts = rng.uniform(-1.0, 3.0, size=(2000, 3))
    s = state(pts)
    s.ptype = np.where(rng.random(pts.shape[0]) < 0.2, 0, FLUID).astype(np.int8)
    s.vel = rng.normal(size=pts.shape)
    expect = s.vel.copy()
    fluid = np.flatnonzero(s.ptype == FLUID)
    inside, f = zone.select(pts[fluid])
    rows = fluid[inside]
    expect[rows] *= D.reduction(1e-3 * zone.redumax * f * f, zone.factor)
    assert 50 < rows.size < fluid.size
    zone.apply(s, 1e-3)
    assert isinstance(zone._kernel, numba.core.registry.CPUDispatcher)
    others = np.setdiff1d(np.arange(pts.shape[0]), rows)
    np.testing.assert_array_equal(s.vel[others], expect[others])
    if spec.get("domain"):
        np.testing.assert_allclose(s.vel[rows], expect[rows], rtol=1e-14, atol=1e-16)
    else:
        np.testing.assert_array_equal(s.vel[rows], expect[rows])

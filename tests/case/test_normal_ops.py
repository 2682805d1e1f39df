"""The mDBC normals a case defines (GenCase's <normals>, the solver's <special><initialize>):
each operation's vectors against the surface it describes, worked out by hand."""
import numpy as np
import pytest

from sphdvi.case.normal_ops import _nearest_on_triangle, apply_normal_ops, plane_cuts
from sphdvi.case.normals import boundary_normals

from test_normals import tank

DP = 0.05
H = 1.0 * np.sqrt(2) * DP


def run_ops(ops, pos, ptype, mkbound, is2d=True, geometry=None, start=None):
    normals = np.zeros_like(pos) if start is None else start.copy()
    if is2d:
        normals[:, 1] = 0.0
    empty = apply_normal_ops(normals, ops, pos, ptype, mkbound, dp=DP, h=H, is2d=is2d, posy2d=0.0,
                             geometry=geometry, computed=lambda: boundary_normals(pos, ptype, DP, is2d))
    return normals, empty


def op(kind, **kw):
    base = {"kind": kind, "tag": kind, "line": 1, "mkbound": "", "onlypos": None}
    if kind in ("plane", "sphere", "cylinder", "parts"):
        base["maxdisth"] = 2.0
    if kind in ("plane", "sphere", "cylinder"):
        base["clear"] = True
    base.update(kw)
    return base


def box_triangles(point, size, skip=()):
    """The 12 triangles of the box point .. point + size (faces named x0, x1, y0, y1, z0, z1)."""
    lo, hi = np.asarray(point, float), np.asarray(point, float) + np.asarray(size, float)
    tris = []
    for axis in range(3):
        for side, name in ((lo, f"{'xyz'[axis]}0"), (hi, f"{'xyz'[axis]}1")):
            if name in skip:
                continue
            u, v = [k for k in range(3) if k != axis]
            quad = []
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                q = np.empty(3)
                q[axis] = side[axis]
                q[u] = (lo, hi)[a][u]
                q[v] = (lo, hi)[b][v]
                quad.append(q)
            tris += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    return np.array(tris)


def floor_rows(rows=4):
    """Boundary rows z = 0, -dp, ... under x in [0, 1] (mkbound 0), and a row of mkbound 1 at z = 1."""
    xs = np.arange(0, 1 + DP / 2, DP)
    pos = [[x, 0, -k * DP] for k in range(rows) for x in xs] + [[x, 0, 1.0] for x in xs]
    mk = [0] * (rows * len(xs)) + [1] * len(xs)
    return np.array(pos, float), np.zeros(len(pos), int), np.array(mk)


def test_plane_foot_of_perpendicular_within_maxdisth_and_clear():
    pos, ptype, mk = floor_rows()
    plane = op("plane", mkbound="0", point=[0, 0, DP / 2], normal=[0, 0, 2], limitdist=0.5)
    n, empty = run_ops([plane], pos, ptype, mk, start=np.full_like(pos, 7.0))
    assert empty == []
    depth = DP / 2 - pos[:, 2]
    reach = depth < 2 * H                       # 2h = 0.141: rows 0, 1, 2 (0.025, 0.075, 0.125)
    sel = mk == 0
    assert np.allclose(n[sel & reach], np.column_stack([0 * depth, 0 * depth, depth])[sel & reach])
    assert np.all(n[sel & ~reach] == 0)          # clear: out of reach loses the earlier value
    assert np.all(n[mk == 1] == [7, 0, 7])       # another mkbound is left alone
    assert (sel & reach).sum() == 3 * 21 and (sel & ~reach).sum() == 21
    kept, _ = run_ops([dict(plane, clear=False)], pos, ptype, mk, start=np.full_like(pos, 7.0))
    assert np.all(kept[sel & ~reach] == [7, 0, 7])


def test_plane_auto_point_lies_limitdist_in_front_of_the_mk():
    pos, ptype, mk = floor_rows(2)
    auto = op("plane", mkbound="0,1", point=None, normal=[0, 0, 1], limitdist=0.5)
    n, _ = run_ops([auto], pos, ptype, mk)
    # mk 0: top row at z = 0, so the plane is at dp/2; mk 1 (one row at z = 1): at 1 + dp/2
    assert np.allclose(n[(mk == 0) & (pos[:, 2] == 0)], [0, 0, DP / 2])
    assert np.allclose(n[(mk == 0) & (pos[:, 2] < 0)], [0, 0, 1.5 * DP])
    assert np.allclose(n[mk == 1], [0, 0, DP / 2])
    # an oblique normal: in front of the farthest particle along it
    tilt = np.array([1.0, 0, 1.0]) / np.sqrt(2)
    n, _ = run_ops([op("plane", mkbound="0", point=None, normal=tilt.tolist(), limitdist=0.5, maxdisth=0)],
                   pos, ptype, mk)
    ahead = (pos[mk == 0] + n[mk == 0]) @ tilt
    assert np.allclose(ahead, ahead[0]) and ahead[0] == pytest.approx((pos[mk == 0] @ tilt).max() + DP / 2)


def test_sphere_inside_and_outside():
    rng = np.random.default_rng(3)
    pos = rng.uniform(-1, 1, (400, 3))
    ptype = np.zeros(400, int)
    mk = np.zeros(400, int)
    c, radius = np.array([0.1, -0.2, 0.05]), 0.6
    dist = np.linalg.norm(pos - c, axis=1)
    for inside in (True, False):
        n, _ = run_ops([op("sphere", center=c.tolist(), radius=radius, inside=inside, maxdisth=2.0)],
                       pos, ptype, mk, is2d=False)
        gap = radius - dist
        hit = ((gap > 0) if inside else (gap < 0)) & (np.abs(gap) <= 2 * H)
        assert hit.sum() > 20
        assert np.allclose(np.linalg.norm(n[hit], axis=1), np.abs(gap[hit]))
        assert np.allclose(np.linalg.norm(pos[hit] + n[hit] - c, axis=1), radius)
        assert np.all(n[~hit] == 0)


def test_cylinder_inside_side_caps_and_rim():
    """A capped cylinder along z from 0 to 1, radius 0.3: a particle near the side goes to the
    side, near a cap to the cap, as near to both to the rim; an open end (limit2 false) has no cap."""
    cyl = op("cylinder", center1=[0, 0, 0], center2=[0, 0, 1], radius=0.3, inside=True, limit1=True,
             limit2=True, maxdisth=2.0)
    pos = np.array([[0.25, 0, 0.5],      # side, 0.05 in
                    [0.0, 0.1, 0.04],    # bottom cap, 0.04 in
                    [0.0, 0.27, 0.97],   # top: 0.03 from both: the rim
                    [0.0, 0.0, 0.5],     # the axis: out of reach
                    [0.5, 0.0, 0.5]])    # outside: not inside
    ptype, mk = np.zeros(5, int), np.zeros(5, int)
    n, _ = run_ops([cyl], pos, ptype, mk, is2d=False)
    assert n[0] == pytest.approx([0.05, 0, 0])
    assert n[1] == pytest.approx([0, 0, -0.04])
    assert n[2] == pytest.approx([0, 0.03, 0.03])
    assert np.all(n[3] == 0) and np.all(n[4] == 0)
    open_top, _ = run_ops([dict(cyl, limit2=False)], pos, ptype, mk, is2d=False)
    assert open_top[2] == pytest.approx([0, 0.03, 0])
    out = op("cylinder", center1=[0, 0, 0], center2=[0, 0, 1], radius=0.3, inside=False, limit1=True,
             limit2=True, maxdisth=2.0)
    pos = np.array([[0.35, 0, 0.5], [0.0, 0.1, -0.05], [0.34, 0.0, 1.03], [0.1, 0, 0.5]])
    n, _ = run_ops([out], pos, np.zeros(4, int), np.zeros(4, int), is2d=False)
    assert n[0] == pytest.approx([-0.05, 0, 0])
    assert n[1] == pytest.approx([0, 0, 0.05])
    assert n[2] == pytest.approx([-0.04, 0, -0.03])
    assert np.all(n[3] == 0)


def test_set_onlypos_and_order():
    pos, ptype, mk = floor_rows(1)
    ops = [op("set", normal=[0, 0, 1]), op("set", normal=[1, 0, 0], onlypos={"posmin": [0.5, None, None], "posmax": [None, None, None]})]
    n, _ = run_ops(ops, pos, ptype, mk)
    right = pos[:, 0] >= 0.5
    assert np.all(n[right] == [1, 0, 0]) and np.all(n[~right] == [0, 0, 1])
    _, empty = run_ops([op("set", normal=[0, 0, 1], mkbound="9")], pos, ptype, mk)
    assert [e["mkbound"] for e in empty] == ["9"]


def test_nearest_point_on_triangle_against_sampling():
    rng = np.random.default_rng(7)
    tri = rng.normal(size=(3, 3))
    uv = rng.random((200_000, 2))
    uv = uv[uv.sum(axis=1) <= 1]
    samples = tri[0] + uv[:, :1] * (tri[1] - tri[0]) + uv[:, 1:] * (tri[2] - tri[0])
    for p in rng.normal(scale=2, size=(50, 3)):
        q = _nearest_on_triangle(p, tri[0], tri[1], tri[2])
        best = np.linalg.norm(samples - p, axis=1).min()
        assert np.linalg.norm(q - p) <= best + 1e-12
        assert np.linalg.norm(q - p) >= best - 0.02


def test_plane_cuts_of_a_box_in_2d():
    """The 2D plane y = 0 cuts a box's side faces in segments; its front and back faces (parallel)
    give none; a wall drawn with no depth (zero-area triangles in the plane) is its own cut."""
    tris = box_triangles(np.array([0.0, -1, 0]), np.array([2.0, 2, 1]))
    segs, src = plane_cuts(tris, 0.0, 1e-12)
    ends = {tuple(np.round(np.sort([s[0, 0], s[1, 0]]), 9)) + tuple(np.round(np.sort([s[0, 2], s[1, 2]]), 9))
            for s in segs}
    assert np.all(segs[:, :, 1] == 0)
    covered = set()
    for x0, x1, z0, z1 in ends:
        covered.add("bottom" if z0 == z1 == 0 else "top" if z0 == z1 == 1 else
                    "left" if x0 == x1 == 0 else "right" if x0 == x1 == 2 else "?")
    assert covered == {"bottom", "top", "left", "right"}
    flat = np.array([[[0, 0, 0], [1, 0, 0], [1, 0, 0]]], float)
    segs, _ = plane_cuts(flat, 0.0, 1e-12)
    assert len(segs) == 1 and sorted([segs[0, 0, 0], segs[0, 1, 0]]) == [0, 1]
    face = np.array([[[0, 0, 0], [1, 0, 0], [0, 0, 1]]], float)
    assert len(plane_cuts(face, 0.0, 1e-12)[0]) == 0


@pytest.mark.parametrize("layers", [1, 3])
def test_geometry_normals_match_the_ones_from_the_particles(layers):
    """Two independent routes to the same normals: the nearest point of the tank's outline drawn
    dp/2 inside the walls (GenCase's GeometryForNormals with layers vdp=-0.5) and sphdvi's
    normals from the particle arrangement agree on every wall particle but the walls' free top
    ends, for one and for three wall layers, the corners included: the particles under a corner
    point to the outline's corner, and the floor particle beside it straight up."""
    pos, ptype = tank(DP, layers)
    mk = np.zeros(len(pos), int)
    tris = box_triangles(np.array([DP / 2, -1, DP / 2]), np.array([1 - DP, 2, 1.0]), skip=("z1",))
    geo = op("geometry", file="hdp", distanceh=(layers + 1) * DP / H)
    n, _ = run_ops([geo], pos, ptype, mk, geometry=lambda o: (tris, None))
    ref = boundary_normals(pos, ptype, DP, True)
    b = ptype == 0
    x, z = pos[:, 0], pos[:, 2]
    top_end = b & (z > 0.45)
    assert np.all(n[ptype == 3] == 0)
    assert np.all(np.linalg.norm(n[b], axis=1) > 0)
    agree = b & ~top_end
    assert agree.sum() >= 35 * layers
    assert np.allclose(n[agree], ref[agree], atol=1e-12)
    under = b & ((x < DP / 2) | (x > 1 - DP / 2)) & (z < DP / 2)
    foot = pos[under] + n[under]
    assert np.allclose(np.abs(foot[:, 0] - 0.5), 0.5 - DP / 2) and np.allclose(foot[:, 2], DP / 2)
    beside = b & np.isclose(z, 0) & (np.isclose(x, DP) | np.isclose(x, 1 - DP))
    assert np.allclose(n[beside], [0, 0, DP / 2])


def test_geometry_normals_keep_to_their_own_mk():
    """A shape file that carries the mk of each triangle: a particle whose mkbound drew part of
    the surface sees that part only (a body by the floor keeps its own normals); a mkbound that
    drew none sees all of it."""
    xs = np.arange(0, 1 + DP / 2, DP)
    floor = np.array([[x, 0, 0] for x in xs])
    body = np.array([[0.5, 0, 2 * DP], [0.5, 0, 3 * DP]])
    other = np.array([[0.2, 0, -DP]])
    pos = np.vstack([floor, body, other])
    mk = np.array([0] * len(xs) + [1, 1] + [2])
    ptype = np.zeros(len(pos), int)
    floor_tris = box_triangles(np.array([-1.0, -1, -1]), np.array([3.0, 2, 1 + DP / 2]))
    body_tris = box_triangles(np.array([0.45, -1, 1.5 * DP]), np.array([0.1, 2, 2 * DP]))
    tris = np.concatenate([floor_tris, body_tris])
    tri_mk = np.array([0] * len(floor_tris) + [1] * len(body_tris))
    geo = op("geometry", file="hdp", distanceh=3 * DP / H)
    n, _ = run_ops([geo], pos, ptype, mk, geometry=lambda o: (tris, tri_mk))
    assert np.allclose(n[mk == 0], [0, 0, DP / 2])
    assert np.allclose(n[mk == 1], [[0, 0, -DP / 2], [0, 0, DP / 2]])
    assert np.allclose(n[mk == 2], [0, 0, 1.5 * DP])


def _tank_walls_3d():
    """The walls of a 0.4 x 0.3 m tank 0.2 m high, two layers thick (the inner at x, y, z = 0),
    and the arange of its y nodes."""
    xs = np.arange(-DP, 0.4 + 1.5 * DP, DP)
    ys = np.arange(-DP, 0.3 + 1.5 * DP, DP)
    zs = np.arange(-DP, 0.2 + DP / 2, DP)
    g = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    wall = (g[:, 0] < DP / 2) | (g[:, 0] > 0.4 - DP / 2) | (g[:, 1] < DP / 2) | (g[:, 1] > 0.3 - DP / 2) \
        | (g[:, 2] < DP / 2)
    return g[wall], ys


def test_geometry_normals_3d_tank_against_the_clamped_point():
    """3D: a tank of two wall layers (floor and four walls, 0.4 x 0.3 m, 0.2 m high) and its inner
    outline dp/2 in front of them, open at the top (0.5 m, above the walls): every wall particle
    lies outside the outline's box, so the nearest point of the outline is the particle clamped
    into that box (faces, edges and corners alike); N within distanceh h = 2 dp, none beyond
    (the outer layer's edges and corners, 2.1 and 2.6 dp away)."""
    pos, _ = _tank_walls_3d()
    ptype = np.zeros(len(pos), int)
    lo, hi = np.array([DP / 2, DP / 2, DP / 2]), np.array([0.4 - DP / 2, 0.3 - DP / 2, 0.5])
    tris = box_triangles(lo, hi - lo, skip=("z1",))
    reach = 2 * DP
    geo = op("geometry", file="hdp", distanceh=reach / H)
    n, _ = run_ops([geo], pos, ptype, np.zeros(len(pos), int), is2d=False, geometry=lambda o: (tris, None))
    want = np.clip(pos, lo, hi) - pos
    near = np.linalg.norm(want, axis=1) <= reach
    assert near.sum() > 350 and (~near).sum() > 40
    assert np.allclose(n[near], want[near], atol=1e-12)
    assert np.all(n[~near] == 0)


def test_geometry_normals_maxsizeh_limits_their_length():
    """<norgeometry><maxsizeh v=".."> (GenCase v5.4's template: "Maximum allowed normal size
    (H*value) (disabled=0, default=0)"): a particle whose normal would be longer has none; 0 is no
    limit."""
    pos, ptype = tank(DP, 3)
    mk = np.zeros(len(pos), int)
    tris = box_triangles(np.array([DP / 2, -1, DP / 2]), np.array([1 - DP, 2, 1.0]), skip=("z1",))
    full, _ = run_ops([op("geometry", file="hdp", distanceh=4 * DP / H, maxsizeh=0.0)], pos, ptype, mk,
                      geometry=lambda o: (tris, None))
    cut, _ = run_ops([op("geometry", file="hdp", distanceh=4 * DP / H, maxsizeh=1.6 * DP / H)], pos, ptype, mk,
                     geometry=lambda o: (tris, None))
    length = np.linalg.norm(full, axis=1)
    assert np.any(length > 1.6 * DP)
    keep = length <= 1.6 * DP
    assert np.array_equal(cut[keep], full[keep]) and np.all(cut[~keep] == 0)


def test_geometry_through_the_particles_gives_them_no_normal():
    """A normals geometry drawn through the face layer (DesignSPHysics's mdbc_dist_vdp 0, a
    solid box as its own geometry) leaves each particle on it without a normal, whose direction
    is undefined, though rounding makes its vector 6e-17 m rather than 0 (arange's 0.30000000000000004
    against the surface's 0.3 here): a normal that short gave mDBC a ghost node on the particle itself.
    The particles on the surface are counted by mkbound, and the layer behind keeps N = dp
    towards the surface."""
    pos, ys = _tank_walls_3d()
    ptype = np.zeros(len(pos), int)
    mk = np.where(pos[:, 2] < DP / 2, 3, 0)          # the floor mkbound 3, the walls 0
    tris = box_triangles(np.zeros(3), np.array([0.4, 0.3, 0.5]), skip=("z1",))
    inner = np.all((pos > -DP / 2) & (pos < np.array([0.4, 0.3, 0.5]) + DP / 2), axis=1)     # the face layer
    assert ys[7] != 0.3 and ys[7] == pytest.approx(0.3, abs=1e-15)
    normals, through = np.zeros_like(pos), []
    apply_normal_ops(normals, [op("geometry", file="hdp", distanceh=1.5 * DP / H)], pos, ptype, mk, dp=DP, h=H,
                     is2d=False, geometry=lambda o: (tris, None), on_surface=through)
    assert np.all(normals[inner] == 0.0)
    assert len(through) == 1
    assert through[0][1] == {0: int((inner & (mk == 0)).sum()), 3: int((inner & (mk == 3)).sum())}
    behind = ~inner & (np.linalg.norm(np.clip(pos, 0, [0.4, 0.3, 0.5]) - pos, axis=1) < 1.01 * DP)
    assert behind.sum() > 100
    assert np.allclose(np.linalg.norm(normals[behind], axis=1), DP)


def test_plane_reach_is_the_same_for_mirror_walls():
    """Two mirror walls on a 0.1 lattice (z = k 0.1), planes at z = 0.3 (normal +z, rows 0 to 3
    under it) and z = 0.7 (normal -z, rows 7 to 10 over it), reach exactly 0.3: both take their
    4 rows. With a strict < on the float depth (DualSPHysics's mdbc/02 CasePoiseuilleLR: 2 rows
    against 3) the first lost its far row (0.3 - 0.0 = 0.3) and the second kept it
    (1.0 - 0.7000000000000001)."""
    xs = np.arange(0, 1 + DP / 2, DP)
    rows = [k * 0.1 for k in (0, 1, 2, 3, 7, 8, 9, 10)]
    pos = np.array([[x, 0, z] for z in rows for x in xs], float)
    mk = np.repeat([0, 0, 0, 0, 1, 1, 1, 1], len(xs))
    ptype = np.zeros(len(pos), int)
    maxdisth = 0.3 / H
    ops = [op("plane", mkbound="0", point=[0, 0, 3 * 0.1], normal=[0, 0, 1], limitdist=0.5, maxdisth=maxdisth),
           op("plane", mkbound="1", point=[0, 0, 7 * 0.1], normal=[0, 0, -1], limitdist=0.5, maxdisth=maxdisth)]
    start = np.full_like(pos, 7.0)
    start[:, 1] = 0.0
    n, _ = run_ops(ops, pos, ptype, mk, start=start)
    reached = ~np.all(n == [7, 0, 7], axis=1)           # clear: a row out of reach keeps no value
    cleared = np.all(n == 0, axis=1) & ~np.isclose(pos[:, 2], 0.3) & ~np.isclose(pos[:, 2], 0.7)
    assert not cleared.any()
    assert reached[mk == 0].sum() == reached[mk == 1].sum() == 4 * len(xs)
    far = np.isclose(pos[:, 2], 0.0) | np.isclose(pos[:, 2], 1.0)
    assert np.allclose(np.abs(n[far, 2]), 0.3)

"""mDBC normals from the particles: wall, floor and corner normals point to the fluid, to the surface
dp/2 in front of the walls."""
import numpy as np
import pytest

from sphdvi.case.normals import boundary_normals


def tank(dp=0.05, layers=1, is2d=True):
    pts, types = [], []
    for k in range(layers):
        off = k * dp
        xs = np.arange(-off, 1.0 + off + dp / 2, dp)
        zw = np.arange(-off + dp, 0.6, dp)
        pts += [[x, 0, -off] for x in xs] + [[-off, 0, z] for z in zw] + [[1.0 + off, 0, z] for z in zw]
    types += [0] * len(pts)
    fx, fz = np.meshgrid(np.arange(dp, 1.0 - dp / 2, dp), np.arange(dp, 0.3, dp))
    fl = np.column_stack([fx.ravel(), 0 * fx.ravel(), fz.ravel()])
    pos = np.vstack([np.array(pts), fl])
    ptype = np.array(types + [3] * len(fl))
    return pos, ptype


@pytest.mark.parametrize("layers", [1, 3])
def test_tank_normals(layers):
    dp = 0.05
    pos, ptype = tank(dp, layers)
    n = boundary_normals(pos, ptype, dp, True)
    assert np.all(n[ptype == 3] == 0)
    b = ptype == 0

    def at(x, z):
        i = np.flatnonzero(b & np.isclose(pos[:, 0], x) & np.isclose(pos[:, 2], z))[0]
        return n[i]

    assert at(0.5, 0.0) == pytest.approx([0, 0, dp / 2])
    assert at(0.0, 0.3) == pytest.approx([dp / 2, 0, 0])
    assert at(1.0, 0.3) == pytest.approx([-dp / 2, 0, 0])
    # the corner particles point to the corner of the surface dp/2 in front of the walls, the
    # floor beside them straight up (GenCase's normals from the tank's outline)
    for k in range(layers):
        c = -k * dp
        assert at(c, c) == pytest.approx([dp / 2 - c, 0, dp / 2 - c])
        assert at(1.0 - c, c) == pytest.approx([-(dp / 2 - c), 0, dp / 2 - c])
        assert at(dp, c) == pytest.approx([0, 0, dp / 2 - c])
        assert at(c, dp) == pytest.approx([dp / 2 - c, 0, 0])
    if layers == 1:
        corner = b & (np.isclose(pos[:, 0], 0) | np.isclose(pos[:, 0], 1)) & np.isclose(pos[:, 2], 0)
        assert np.allclose(np.linalg.norm(n[b & ~corner], axis=1), dp / 2)


def _square_body_in_water(dp, water_top):
    """A solid 9 x 9 square of floating particles centred at z = 1 (side 0.4 m at dp 0.05)
    in water from z = 0.5 up to ``water_top``: positions, types, the lattice of the body's
    rows and the water's positions."""
    g = np.arange(-0.2, 0.2 + dp / 2, dp)
    X, Z = np.meshgrid(g, g)
    body = np.column_stack([X.ravel(), 0 * X.ravel(), Z.ravel() + 1.0])
    fx, fz = np.meshgrid(np.arange(-0.6, 0.6, dp), np.arange(0.5, water_top, dp))
    fl = np.column_stack([fx.ravel(), 0 * fx.ravel(), fz.ravel()])
    fl = fl[np.max(np.abs(fl - [0, 0, 1.0]), axis=1) > 0.2 + dp / 2]
    pos = np.vstack([body, fl])
    return pos, np.array([2] * len(body) + [3] * len(fl)), g, fl


def _at(pos, n, x, z):
    return n[np.flatnonzero(np.isclose(pos[:, 0], x) & np.isclose(pos[:, 2], z))[0]]


def test_solid_body_normals_point_outwards():
    dp = 0.05
    pos, ptype, _, _ = _square_body_in_water(dp, 1.5)
    n = boundary_normals(pos, ptype, dp, True)
    assert _at(pos, n, 0.0, 1.2) == pytest.approx([0, 0, dp / 2])
    assert _at(pos, n, -0.2, 1.0) == pytest.approx([-dp / 2, 0, 0])


def test_floating_body_normals_point_out_of_it_where_it_is_dry():
    """A floating box half out of the water: its dry top row points up, dp/2 to its top
    surface, as GenCase's normals from the outline (facing the nearest water it pointed
    down through the box, 4.5 dp, its ghost nodes in the water under it); the second row
    1.5 dp up; the wet bottom down. The same block as a fixed solid keeps the
    face-the-fluid rule that the back layers of thick walls need: its top row points to the
    water beside it."""
    dp = 0.05
    pos, ptype, g, fl = _square_body_in_water(dp, 1.0)
    n = boundary_normals(pos, ptype, dp, True)
    assert _at(pos, n, 0.0, 1.2) == pytest.approx([0, 0, dp / 2])
    assert _at(pos, n, 0.0, 1.15) == pytest.approx([0, 0, 1.5 * dp])
    assert _at(pos, n, 0.0, 0.8) == pytest.approx([0, 0, -dp / 2])
    assert _at(pos, n, -0.2, 1.1) == pytest.approx([-dp / 2, 0, 0])
    fixed = boundary_normals(pos, np.where(ptype == 2, 0, ptype), dp, True)
    assert _at(pos, fixed, 0.0, 1.2) == pytest.approx([-4.5 * dp, 0, 0])   # to the water beside it
    # a one-layer floating plate on the water: no side is nearer, so it faces the fluid
    pos = np.vstack([np.column_stack([g, 0 * g, 0 * g + 1.0 + dp]), fl])
    n = boundary_normals(pos, np.array([2] * len(g) + [3] * len(fl)), dp, True)
    assert _at(pos, n, 0.0, 1.0 + dp) == pytest.approx([0, 0, -dp / 2])


def test_thick_wall_distances():
    """Three wall layers: |N| = 0.5, 1.5, 2.5 dp from the fluid side outwards."""
    dp = 0.05
    pos, ptype = tank(dp, layers=3)
    n = boundary_normals(pos, ptype, dp, True)
    for k, z in enumerate((0.0, -dp, -2 * dp)):
        i = np.flatnonzero((ptype == 0) & np.isclose(pos[:, 0], 0.5) & np.isclose(pos[:, 2], z))[0]
        assert n[i] == pytest.approx([0, 0, (k + 0.5) * dp])


@pytest.mark.parametrize("is2d", [True, False])
def test_periodic_channel_walls_keep_plane_normals(is2d):
    """A channel periodic in x (and y in 3D): the walls run through the periodic ends, so with
    the periodic images every wall particle, the end columns included, has the plate normal
    (0, 0, (k + 1/2) dp) for layer k."""
    from sphdvi.sph.periodic import Periodicity
    dp, n, cols, layers = 0.1, 6, 8, 3
    ys = [0.0] if is2d else np.arange(cols) * dp
    X, Y, Z = np.meshgrid(np.arange(cols) * dp, ys, (np.arange(n) + 0.5) * dp, indexing="ij")
    fluid = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    wz = np.r_[-(np.arange(layers) + 0.5) * dp, n * dp + (np.arange(layers) + 0.5) * dp]
    X, Y, Z = np.meshgrid(np.arange(cols) * dp, ys, wz, indexing="ij")
    wall = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    pos = np.vstack([wall, fluid])
    ptype = np.r_[np.zeros(len(wall), int), np.full(len(fluid), 3)]
    axes = ["x"] if is2d else ["x", "y"]
    nrm = boundary_normals(pos, ptype, dp, is2d, Periodicity(axes, pos, dp, {}))[: len(wall)]
    z = wall[:, 2]
    depth = np.where(z < 0, -z, z - n * dp)                     # (k + 1/2) dp
    expected = np.column_stack([0 * z, 0 * z, np.where(z < 0, depth, -depth)])
    np.testing.assert_allclose(nrm, expected, atol=1e-12)
    # without the images too: the lattice surface stops at the particles' bounding box
    np.testing.assert_allclose(boundary_normals(pos, ptype, dp, is2d)[: len(wall)], expected, atol=1e-12)


def test_solid_body_normals_reach_its_outline():
    """Every particle of a solid square body in water points to the nearest point of the body's
    outline dp/2 outside its particles (corners and deep particles alike), as GenCase's normals
    from the body's geometry."""
    dp = 0.05
    pos, ptype, g, _ = _square_body_in_water(dp, 1.5)
    n = boundary_normals(pos, ptype, dp, True)
    body = ptype == 2
    half = g[-1] + dp / 2
    rel = pos[body] - [0, 0, 1.0]
    to_side = half - np.abs(rel[:, [0, 2]])                 # distance to the nearer side in x and z
    np.testing.assert_allclose(np.linalg.norm(n[body], axis=1), to_side.min(axis=1), atol=1e-12)
    foot = np.abs(rel + n[body])[:, [0, 2]]
    assert np.all(np.isclose(foot, half).any(axis=1))       # on the outline


def test_3d_tank_normals_are_the_nearest_point_of_its_inner_outline():
    """3D: a tank of two wall layers (0.4 x 0.3 m, 0.2 m high) with water 0.1 m deep: every wall
    particle below the walls' top ends points to the nearest point of the inner outline dp/2 in
    front of the walls, the particle clamped into that box: faces, edges and corners (there
    the vector to the outline's corner, dp sqrt(3)/2 long on the first layer)."""
    dp = 0.02
    xs, ys, zs = np.arange(-dp, 0.4 + 1.5 * dp, dp), np.arange(-dp, 0.3 + 1.5 * dp, dp), np.arange(-dp, 0.2, dp)
    g = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    wall = ((g[:, 0] < dp / 2) | (g[:, 0] > 0.4 - dp / 2) | (g[:, 1] < dp / 2) | (g[:, 1] > 0.3 - dp / 2)
            | (g[:, 2] < dp / 2))
    water = ~wall & (g[:, 2] < 0.1)
    pos = np.vstack([g[wall], g[water]])
    ptype = np.r_[np.zeros(wall.sum(), int), np.full(water.sum(), 3)]
    n = boundary_normals(pos, ptype, dp, False)
    lo, hi = np.array([dp / 2] * 3), np.array([0.4 - dp / 2, 0.3 - dp / 2, 1.0])
    below = (ptype == 0) & (pos[:, 2] < 0.2 - 3 * dp)
    assert below.sum() > 1500
    np.testing.assert_allclose(n[below], np.clip(pos[below], lo, hi) - pos[below], atol=1e-12)
    corner = np.all(np.isclose(pos, 0), axis=1)
    assert n[corner][0] == pytest.approx([dp / 2] * 3)


@pytest.mark.parametrize("layers, inner_mean, inner_max", [(1, 17.0, 48.0), (3, 10.0, 24.0)])
def test_curved_wall_normals(layers, inner_mean, inner_max):
    """A round wall drawn on the lattice (radius 15 dp, water inside): its lattice surface is a
    staircase, so where the steps are short (more than about 20 degrees from an axis) the normals
    come from the neighbours. Measured against the radius on the wet layer (mean / max): one
    layer 16.4 / 47.5 degrees, three layers 9.5 / 23.2 (the particle route alone gave 23.0 / 52.1
    and 5.6 / 15.0; the lattice route alone 19.6 / 74.1 and 26.5 / 74.1); GenCase's norcylinder
    gives a round wall its exact normals."""
    dp, radius = 0.02, 0.3
    xx, zz = np.meshgrid(np.arange(-0.4, 0.4001, dp), np.arange(-0.4, 0.4001, dp))
    grid = np.column_stack([xx.ravel(), 0 * xx.ravel(), zz.ravel()])
    r = np.linalg.norm(grid[:, [0, 2]], axis=1)
    ring = (r >= radius - dp / 2) & (r < radius + (layers - 0.5) * dp)
    water = r < radius - dp / 2
    pos = np.vstack([grid[ring], grid[water]])
    ptype = np.r_[np.zeros(ring.sum(), int), np.full(water.sum(), 3)]
    n = boundary_normals(pos, ptype, dp, True)[: ring.sum()]
    inward = -grid[ring] / r[ring][:, None]
    angle = np.degrees(np.arccos(np.clip((n * inward).sum(axis=1) / np.linalg.norm(n, axis=1), -1, 1)))
    wet = r[ring] < radius + dp / 2
    assert angle[wet].mean() < inner_mean and angle[wet].max() < inner_max
    assert np.all((n * inward).sum(axis=1) > 0)                 # every one towards the water


def _tank_3d(dp, layers):
    """A 3D tank 10 dp wide with walls ``layers`` thick and water 4 dp deep, and its mkbounds
    (0 the walls, none for the water)."""
    k = np.arange(-(layers - 1), 9 + layers)
    g = np.stack(np.meshgrid(k, k, np.arange(-(layers - 1), 8), indexing="ij"), axis=-1).reshape(-1, 3)
    wall = (g[:, 0] <= 0) | (g[:, 0] >= 9) | (g[:, 1] <= 0) | (g[:, 1] >= 9) | (g[:, 2] <= 0)
    water = ~wall & (g[:, 2] < 5)
    pos = np.vstack([g[wall], g[water]]) * dp
    ptype = np.r_[np.zeros(wall.sum(), int), np.full(water.sum(), 3)]
    return pos, ptype, np.zeros(len(pos), int)


@pytest.mark.parametrize("layers, thin", [(1, {0: 1}), (2, {0: 2}), (3, {})])
def test_thin_walls_are_found_in_3d(layers, thin):
    """A 3D tank whose walls are thinner than the kernel's reach (3 layers at coefh 1: 2h =
    3.46 dp) is found, with the fewest layers behind a face particle, though its corner
    particles' normals are longer than dp; with three layers it is not."""
    from sphdvi.case.normals import layers_needed, thin_wall_mkbounds
    dp = 0.05
    h = dp * np.sqrt(3)
    pos, ptype, _ = _tank_3d(dp, layers)
    n = boundary_normals(pos, ptype, dp, False)
    assert np.linalg.norm(n[ptype == 0], axis=1).max() == pytest.approx(dp * (layers - 0.5) * np.sqrt(3))
    found = thin_wall_mkbounds(pos, n, ptype, np.zeros(len(pos), int), dp, h)
    assert {mk: fewest for mk, (fewest, _) in found.items()} == thin
    assert layers_needed(h, dp) == 3 and layers_needed(dp * np.sqrt(2), dp) == 2      # 3D and 2D, coefh 1


def test_normals_into_their_own_wall_are_found_and_not_read_as_a_thin_wall():
    """Normals from a surface behind the face layer (a solid box whose faces fall half-way
    between nodes given as its own normals geometry: GenCase's DualSPHysicsGPT Case_Def.xml
    variant) point back into the wall, dp/2 long, and their ghost nodes r + 2N fall on the next
    layer: :func:`ghosts_in_own_wall` finds exactly those, and the thin-wall count, which read
    them as a wall one particle thick (counted along -N it met the water), leaves them out.
    The normals derived from the particles have none."""
    from sphdvi.case.normals import ghosts_in_own_wall, inward_normal_mkbounds, thin_wall_mkbounds
    dp = 0.05
    h = dp * np.sqrt(3)
    pos, ptype, mk = _tank_3d(dp, 3)
    n = boundary_normals(pos, ptype, dp, False)
    assert not ghosts_in_own_wall(pos, n, ptype, mk, dp, h).any()
    assert thin_wall_mkbounds(pos, n, ptype, mk, dp, h) == {}
    length = np.linalg.norm(n, axis=1)
    face = (ptype == 0) & np.isclose(length, dp / 2) & (np.count_nonzero(np.abs(n) > 1e-12, axis=1) == 1)
    assert face.sum() == 8 * 8 + 4 * 8 * 7          # the floor and the four walls below the top (z 1 .. 7)
    bad = n.copy()
    bad[face] *= -1.0
    found = ghosts_in_own_wall(pos, bad, ptype, mk, dp, h)
    assert np.array_equal(found, face)
    assert inward_normal_mkbounds(pos, bad, ptype, mk, dp, h) == {0: int(face.sum())}
    assert thin_wall_mkbounds(pos, bad, ptype, mk, dp, h) == {}
    # another body's ghost nodes may fall on this wall: only a particle's own wall counts
    other = mk.copy()
    other[face] = 7
    assert not ghosts_in_own_wall(pos, bad, ptype, other, dp, h).any()


@pytest.mark.parametrize("h_dp, need", [(np.sqrt(2), 2), (np.sqrt(3), 3), (1.2 * np.sqrt(3), 4), (2.0, 3),
                                        (2.0000001, 4), (1.5, 2), (0.5, 1)])
def test_layers_needed_counts_the_layers_closer_than_2h(h_dp, need):
    """A fluid particle at rest lies dp from the first layer; layer k (k dp off) carries kernel
    weight if k dp < 2h.  At h = 2 dp (hdp 2, DualSPHysics's examples/mdbc/04_Dambreak, drawn with
    three layers) the fourth lies at 2h, where the kernel is 0."""
    from sphdvi.case.normals import layers_needed
    assert layers_needed(h_dp * 0.01, 0.01) == need


def _dambreak_box(dp=0.02, mirrored=False):
    """GenCase's particles of CaseDambreakMdbc2D's tank scaled to 0.4 x 0.3 m (3 layers drawn
    outwards, each one dp higher than the one inside it) with a 0.2 x 0.2 m water column in its
    left corner; ``mirrored``: the same scene mirrored about x = 0.2."""
    pts = []
    for k in range(3):
        xs = np.arange(-k * dp, 0.4 + k * dp + dp / 2, dp)
        zs = np.arange(-k * dp + dp, 0.3 + k * dp + dp / 2, dp)
        pts += [[x, 0, -k * dp] for x in xs] + [[-k * dp, 0, z] for z in zs] + [[0.4 + k * dp, 0, z] for z in zs]
    g = np.arange(dp, 0.2 + dp / 2, dp)
    fx, fz = np.meshgrid(g, g)
    pos = np.vstack([np.round(pts, 12), np.column_stack([fx.ravel(), 0 * fx.ravel(), fz.ravel()])])
    ptype = np.array([0] * len(pts) + [3] * fx.size)
    if mirrored:
        pos[:, 0] = 0.4 - pos[:, 0]
    return pos, ptype


def test_wall_tops_get_mirror_normals_into_the_tank():
    """The tops of a tank's walls (a staircase: each layer one dp above the one inside it) get
    mirror-image normals on the two sides whatever the water's place (here in the left half),
    each towards the tank: the ghost node r + 2N inside the tank, in no boundary particle's cell
    (the right wall's second layer got N = (1.4, -4.3) dp, out of the tank; the left wall's
    (-0.2, -0.4) dp, into the wall)."""
    dp = 0.02
    pos, ptype = _dambreak_box(dp)
    n = boundary_normals(pos, ptype, dp, True)
    b = ptype == 0
    cells = {tuple(np.rint(p[[0, 2]] / dp).astype(int)) for p in pos[b]}
    top = np.flatnonzero(b & (pos[:, 2] > 0.25) & (pos[:, 0] < 0.2))
    assert len(top) == 12
    for i in top:
        j = np.flatnonzero(b & np.isclose(pos[:, 0], 0.4 - pos[i, 0]) & np.isclose(pos[:, 2], pos[i, 2]))[0]
        assert n[j] == pytest.approx(n[i] * [-1, 1, 1], abs=1e-9 * dp)
        for k in (i, j):
            g = pos[k] + 2 * n[k]
            assert 0.0 < g[0] < 0.4 and 0.0 < g[2] <= 0.3 + 1e-9, (pos[k], n[k] / dp)
            assert tuple(np.rint(g[[0, 2]] / dp).astype(int)) not in cells, (pos[k], n[k] / dp)


def test_normals_follow_the_scene_under_mirroring_and_reordering():
    """The normals do not depend on the particles' order, and the mirror image of a scene
    (water included) gets the mirror image of its normals."""
    dp = 0.02
    pos, ptype = _dambreak_box(dp)
    n = boundary_normals(pos, ptype, dp, True)
    pm, _ = _dambreak_box(dp, mirrored=True)
    nm = boundary_normals(pm, ptype, dp, True)
    np.testing.assert_allclose(nm * [-1, 1, 1], n, atol=1e-9 * dp)
    perm = np.random.default_rng(1).permutation(len(pos))
    npm = np.empty_like(n)
    npm[perm] = boundary_normals(pos[perm], ptype[perm], dp, True)
    np.testing.assert_allclose(npm, n, atol=1e-9 * dp)

"""mDBC normals from the particles: wall, floor and corner normals point to the fluid, |N| = dp/2."""
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
    c = at(0.0, 0.0)
    assert c[0] > 0 and c[2] > 0 and np.linalg.norm(c) == pytest.approx(dp / 2)
    if layers == 1:
        assert np.allclose(np.linalg.norm(n[b], axis=1), dp / 2)


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
    face-the-fluid rule that the back layers of thick walls need."""
    dp = 0.05
    pos, ptype, g, fl = _square_body_in_water(dp, 1.0)
    n = boundary_normals(pos, ptype, dp, True)
    assert _at(pos, n, 0.0, 1.2) == pytest.approx([0, 0, dp / 2])
    assert _at(pos, n, 0.0, 1.15) == pytest.approx([0, 0, 1.5 * dp])
    assert _at(pos, n, 0.0, 0.8) == pytest.approx([0, 0, -dp / 2])
    assert _at(pos, n, -0.2, 1.1) == pytest.approx([-dp / 2, 0, 0])
    fixed = boundary_normals(pos, np.where(ptype == 2, 0, ptype), dp, True)
    assert _at(pos, fixed, 0.0, 1.2)[2] < 0
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
    (0, 0, (k + 1/2) dp) for layer k. Without them the end columns get corner normals."""
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
    plain = boundary_normals(pos, ptype, dp, is2d)[: len(wall)]
    ends = np.isclose(wall[:, 0], 0) | np.isclose(wall[:, 0], (cols - 1) * dp)
    assert np.all(np.abs(plain[ends & (np.abs(z) < dp)][:, 0]) > 0.1 * dp)   # corner normals there

"""Particle-cloud contacts as a smooth surface (hunt9/g finding 5).

DualSPHysics's Chrono collides a <chrono> body as a triangle mesh of its surface
(JChronoObjects, modelfile AutoActual): a cube rests face to face on a floor at one
height whatever the particles' lateral alignment, and slides freely with Kfric 0.  A
cloud is collided as the tangent planes of its surface particles (dp/2 in front of them)
on flat faces and as spheres at edges and corners (collision.cloud_surface), so two flat
particle faces touch at a layer distance of exactly dp.  The old union of spheres rested
at 1.0 / 0.866 / 0.707 dp (aligned / staggered in y / in x and y), chattered ±7..25 % and
held a frictionless cube pushed with 0.1 mg in its grooves.

Tolerances: a resting NSC contact keeps its gap at zero to the solver's tolerance (the
largest transient is one step of gravity, g h² = 1e-5 m = 5e-4 dp), so the layer gap is
checked to 1e-3 dp (the old error was 0.13..0.29 dp) and the contact force to 1 % of mg
at every step of the last 0.2 s.  A frictionless slide follows x = F t²/2m up to the
integrator's first-order term ((n+1)/n, 0.2 % at 500 steps): checked to 2 %.
"""
import math

import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.dvi import System
from sphdvi.dvi._math import np_quat_to_mat
from sphdvi.dvi.collision import cloud_surface

G = 9.81
DP = 0.02
C6 = np.arange(6) * DP - 2.5 * DP                     # 6 particles a side, centred: at a body
#                                                       position (dp/2, dp/2) its lattice is the floor's
CUBE = np.array([[x, y, z] for x in C6 for y in C6 for z in C6])
FLOOR = np.array([[x, y, 0.0] for x in np.arange(-15, 16) * DP for y in np.arange(-15, 16) * DP])
REST_Z = DP + C6.max()                                # bottom layer one dp above the floor's


def _qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def _rot(axis, deg):
    h = math.radians(deg) / 2
    v = [0.0, 0.0, 0.0]
    v[axis] = math.sin(h)
    return (math.cos(h), *v)


def _cube_on_floor(pos, mu, force=(0.0, 0.0, 0.0), quat=(1, 0, 0, 0), floor=FLOOR):
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-10, envelope=0.5 * DP)
    m = s.add_material("m", friction=mu, restitution=0.0)
    fl = s.add_body(1.0, kind="fixed", pos=(0, 0, 0))
    s.add_cloud(fl, floor, DP / 2, material=m)
    inertia = (0.1 ** 2 / 6,) * 3
    b = s.add_body(1.0, inertia, pos=pos, quat=quat, force=force)
    s.add_cloud(b, CUBE, DP / 2, material=m)
    return s, b


def _run(s, b, t_end, t_rec):
    fz = []
    while s.time < t_end - 1e-9:
        s.step(1e-3)
        if s.time > t_rec:
            fz.append(s.contact_force[b, 2])
    return np.array(fz)


def test_cloud_surface_classifies_faces_edges_and_sheets():
    """A filled 6³ cube keeps its 152 surface particles: 96 face particles with their face's
    outward axis normal (one-sided), 56 edge and corner features; a one-layer floor is a
    two-sided sheet except its rim, a two-layer one two one-sided faces; a 2-D square
    (plane_normal) gets in-plane normals."""
    pts, nrm, s = cloud_surface(CUBE, DP / 2)
    assert s == pytest.approx(DP)
    assert len(pts) == 152
    flat = nrm[:, 3] == 1
    assert flat.sum() == 96 and (nrm[:, 3] == 0).sum() == 56
    # each face particle's normal is the axis of its face, pointing out of the cube
    k = np.argmax(np.abs(nrm[flat, :3]), axis=1)
    sgn = np.sign(nrm[flat, :3][np.arange(flat.sum()), k])
    np.testing.assert_allclose(np.abs(nrm[flat, :3]).max(axis=1), 1.0, atol=1e-12)
    assert np.all(pts[flat][np.arange(flat.sum()), k] * sgn == pytest.approx(C6.max()))
    pts, nrm, _ = cloud_surface(FLOOR, DP / 2)
    rim = np.abs(pts[:, :2]).max(axis=1) > 14.5 * DP
    assert np.all(nrm[~rim, 3] == 2) and np.all(nrm[rim, 3] == 0)
    np.testing.assert_allclose(np.abs(nrm[~rim, 2]), 1.0)
    # a two-layer plate: each layer's face one-sided, outward (the layer behind is not a neighbour)
    pts, nrm, _ = cloud_surface(np.vstack([FLOOR, FLOOR - [0, 0, DP]]), DP / 2)
    rim = np.abs(pts[:, :2]).max(axis=1) > 14.5 * DP
    assert np.all(nrm[~rim, 3] == 1) and np.all(nrm[rim, 3] == 0)
    np.testing.assert_array_equal(nrm[~rim, 2], np.where(pts[~rim, 2] == 0, 1.0, -1.0))
    sq = np.array([[x, 0.0, z] for x in C6 for z in C6])
    pts, nrm, _ = cloud_surface(sq, DP / 2, plane_normal=(0, 1, 0))
    assert len(pts) == 20 and (nrm[:, 3] == 1).sum() == 16
    assert np.all(nrm[:, 1] == 0)


@pytest.mark.parametrize("offset", [(DP / 2, DP / 2), (DP / 2, 0.0), (0.0, 0.0)],
                         ids=["aligned", "staggered_y", "staggered_xy"])
def test_cube_rests_at_one_height_whatever_the_alignment(offset):
    """Cube cloud on a floor cloud, lattices aligned or staggered by dp/2: the layer gap is
    dp and the contact force is mg at every step (the old sphere union: 0.707..1 dp, ±25 %)."""
    s, b = _cube_on_floor((offset[0], offset[1], REST_Z + 0.002), mu=0.5)
    fz = _run(s, b, 0.5, 0.3)
    assert abs((s.pos[b, 2] - C6.max()) / DP - 1.0) < 1e-3
    assert np.abs(fz / G - 1.0).max() < 1e-2
    assert np.abs(s.vel[b]).max() < 1e-6


@pytest.mark.parametrize("offset", [(DP / 2, DP / 2), (0.0, 0.0)], ids=["aligned", "staggered_xy"])
def test_frictionless_cube_slides_freely(offset):
    """Kfric 0, pushed with 0.1 mg: x = F t²/2m (the old clouds interlocked: 1.6e-5 m)."""
    F = 0.1 * G
    s, b = _cube_on_floor((offset[0], offset[1], REST_Z + 0.001), mu=0.0, force=(F, 0, 0))
    _run(s, b, 0.5, 0.5)
    assert (s.pos[b, 0] - offset[0]) / (0.5 * F * 0.5 ** 2) == pytest.approx(1.0, abs=0.02)
    assert abs((s.pos[b, 2] - C6.max()) / DP - 1.0) < 1e-3
    assert np.abs(s.omega_b[b]).max() < 1e-6


def test_friction_holds_a_pushed_cube():
    """Kfric 0.5, pushed with 0.3 mg (below μ m g): the cube stays."""
    s, b = _cube_on_floor((0.0, 0.0, REST_Z), mu=0.5, force=(0.3 * G, 0, 0))
    _run(s, b, 0.5, 0.5)
    assert abs(s.pos[b, 0]) < 1e-6


@pytest.mark.parametrize("quat", [_qmul(_rot(0, 35), _rot(1, 30)), _qmul(_rot(0, 40), _rot(1, 3))],
                         ids=["corner", "edge"])
def test_cube_dropped_on_a_corner_or_edge_settles_on_a_face(quat):
    """Dropped on a corner or on an edge (Kfric 0.5), the cube tumbles onto a face and rests
    there at a layer gap of dp with the weight on the contacts."""
    s, b = _cube_on_floor((0.0, 0.0, 0.15), mu=0.5, quat=quat)
    fz = _run(s, b, 1.5, 1.3)
    R = np_quat_to_mat(s.quat[b])
    assert np.abs(R[2]).max() == pytest.approx(1.0, abs=1e-6)      # a body axis is vertical
    assert abs((s.pos[b, 2] - C6.max()) / DP - 1.0) < 1e-3
    assert np.abs(fz / G - 1.0).max() < 1e-2


@pytest.mark.parametrize("floor", ["sheet", "block"])
def test_cube_over_the_rim_of_a_floor(floor):
    """A frictionless cube resting with a third of it over the floor's rim gets no sideways
    push from the rim (the rim's edge particles against the cube's face plane), and with its
    centre of mass past the rim it tips over and falls."""
    pts = FLOOR if floor == "sheet" else np.vstack([FLOOR, FLOOR - [0, 0, DP], FLOOR - [0, 0, 2 * DP]])
    rim = FLOOR[:, 0].max()
    s, b = _cube_on_floor((rim - 0.017, 0.0, REST_Z + 0.001), mu=0.0, floor=pts)
    _run(s, b, 0.6, 0.6)
    assert abs(s.pos[b, 0] - (rim - 0.017)) < 1e-9 and abs(s.vel[b, 0]) < 1e-9
    assert abs((s.pos[b, 2] - C6.max()) / DP - 1.0) < 1e-3
    s, b = _cube_on_floor((rim + 0.008, 0.0, REST_Z + 0.001), mu=0.5, floor=pts)
    _run(s, b, 0.6, 0.6)
    assert s.pos[b, 2] < 0.0


BALL_R = 0.05
SLAB = np.array([[x, y, z] for x in np.arange(-15, 16) * DP for y in np.arange(-15, 16) * DP
                 for z in (-2 * DP, -DP, 0.0)])                  # a three-layer block, top at z = 0


def _ball_on_slab(xy, vel=(0.0, 0.0, 0.0), mu=0.5):
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-10, envelope=0.5 * DP)
    m = s.add_material("m", friction=mu, restitution=0.0)
    fl = s.add_body(1.0, kind="fixed")
    s.add_cloud(fl, SLAB, DP / 2, material=m)
    b = s.add_body(1.0, (0.4 * BALL_R ** 2,) * 3, pos=(xy[0], xy[1], BALL_R + DP / 2 + 0.001),
                   vel=vel)
    s.add_sphere(b, BALL_R, material=m)
    return s, b


@pytest.mark.parametrize("xy", [(0.0, 0.0), (DP / 2, 0.0), (DP / 2, DP / 2), (0.0037, 0.0061)],
                         ids=["over_a_particle", "between_two", "between_four", "anywhere"])
def test_sphere_rests_on_a_cloud_face_wherever_it_lands(xy):
    """A true sphere on a cloud block's top face rests on the face's tangent plane, R + dp/2
    above the top layer, with one contact holding m g at every step, wherever it lands on the
    lattice (the sphere against each particle's sphere sat 0.8 / 1.7 mm low between two /
    four particles and, off-centre, rocked with the force off by up to 260 %)."""
    s, b = _ball_on_slab(xy)
    fz = _run(s, b, 0.5, 0.3)
    assert abs(s.pos[b, 2] - (BALL_R + DP / 2)) < 1e-6
    np.testing.assert_allclose(s.pos[b, :2], xy, atol=1e-6)
    assert np.abs(fz / G - 1.0).max() < 1e-2
    assert s.n_contacts == 1


def test_sphere_rolls_across_a_cloud_face_at_one_height():
    """Thrown along the face (0.4, 0.1) m/s with Kfric 0.5, the sphere skids, then rolls at
    5/7 of its speed over ~12 lattice cells, its centre at R + dp/2 within 1e-5 m throughout
    (the particle spheres' bumps: 1.7 mm)."""
    s, b = _ball_on_slab((-0.1, 0.013), vel=(0.4, 0.1, 0.0))
    z = []
    while s.time < 0.8 - 1e-9:
        s.step(1e-3)
        if s.time > 0.05:
            z.append(s.pos[b, 2])
    assert np.abs(np.array(z) - (BALL_R + DP / 2)).max() < 1e-5
    assert s.pos[b, 0] > 0.1
    np.testing.assert_allclose(s.vel[b, :2], (0.4 * 5 / 7, 0.1 * 5 / 7), rtol=1e-3)


def test_2d_square_on_a_line():
    """2-D (plane_normal = y, as mechanism gives a 2-D case's clouds): a staggered square
    rests at one dp on a one-row floor and slides freely with Kfric 0."""
    sq = np.array([[x, 0.0, z] for x in C6 for z in C6])
    line = np.array([[x, 0.0, 0.0] for x in np.arange(-20, 21) * DP])
    for mu, F in ((0.5, 0.0), (0.0, 0.1 * G)):
        s = System(gravity=(0, 0, -G), solver="bb", envelope=0.5 * DP)
        m = s.add_material("m", friction=mu, restitution=0.0)
        fl = s.add_body(1.0, kind="fixed")
        s.add_cloud(fl, line, DP / 2, material=m, plane_normal=(0, 1, 0))
        b = s.add_body(1.0, (1e-3,) * 3, pos=(DP / 2, 0, REST_Z + 0.002), translation_dof=(1, 0, 1),
                       rotation_dof=(0, 1, 0), force=(F, 0, 0))
        s.add_cloud(b, sq, DP / 2, material=m, plane_normal=(0, 1, 0))
        fz = _run(s, b, 0.4, 0.3)
        assert abs((s.pos[b, 2] - C6.max()) / DP - 1.0) < 1e-3
        assert np.abs(fz / G - 1.0).max() < 1e-2
        assert (s.pos[b, 0] - DP / 2) == pytest.approx(0.5 * F * 0.4 ** 2, abs=0.02 * 0.5 * 0.1 * G * 0.16)


def test_cli_cube_drop_rests_on_its_face(tmp_path):
    """The auditor's CaseDrop (AutoActual cube of 0.1 m dropped, sliding, on a particle floor,
    lattices staggered): rests at the floor's top layer + dp + 0.05 with a steady contact
    force (old: z 0.06732 = 0.866 dp, cfz 9.30..10.69)."""
    text = case_xml(pointmin=("-0.5", "-0.5", "-0.5"), pointmax=("0.5", "0.5", "1"), commands="""
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.2" y="-0.2" z="-0.04" />
                        <size x="0.4" y="0.4" z="0.04" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.05" y="-0.05" z="0.1" />
                        <size x="0.1" y="0.1" z="0.1" /></drawbox>""",
                    casedef_extra="""
        <properties>
            <property name="mat" Kfric="0.5" Restitution_Coefficient="0.5" Young_Modulus="1e8" PoissonRatio="0.3" />
            <links><link mkbound="0,1" property="mat" /></links>
        </properties>
        <floatings><floating mkbound="1"><massbody value="1" /><linearvelini x="0.5" y="0" z="0" /></floating>
        </floatings>""",
                    special="""<chrono><collision activate="true"><distancedp value="0.5" /></collision>
                <bodyfloating id="cube" mkbound="1" modelfile="AutoActual" />
                <bodyfixed id="floor" mkbound="0" modelfile="AutoActual" /></chrono>""",
                    parameters='<parameter key="RigidAlgorithm" value="3" /><parameter key="DtFixed" value="0.001" />'
                               '<parameter key="TimeMax" value="0.6" /><parameter key="TimeOut" value="0.01" />')
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", write_case(tmp_path, text, "CaseDrop_Def.xml"), "-o", str(out), "-q",
                                  "--threads", "1"])
    assert r.exit_code == 0, r.output
    d = np.genfromtxt(out / "bodies.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    d = d[d["body"] == "cube"]
    late = d["time"] > 0.35
    np.testing.assert_allclose(d["z"][late], 0.0 + DP + 0.05, atol=1e-5)
    assert np.abs(d["cfz"][late] / G - 1.0).max() < 1e-2


# a capsule or a cylinder lying on the cloud block's top face (axis along x, turned by yaw
# about z): its axis samples (capsule) or rim support points (cylinder) against the face's
# tangent plane, the block's edge and corner particles against its exact surface
ROD_R = 0.03
ROD_H = 0.08                                    # half length


def _rod_on_slab(shape, xy, yaw=0.0, vel=(0.0, 0.0, 0.0), mu=0.5):
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-10, envelope=0.5 * DP)
    m = s.add_material("m", friction=mu, restitution=0.0)
    fl = s.add_body(1.0, kind="fixed")
    s.add_cloud(fl, SLAB, DP / 2, material=m)
    q = _qmul(_rot(2, yaw), _rot(1, 90.0))        # local z (the axis) along x, then yaw
    Ia = 0.5 * ROD_R ** 2
    It = (3 * ROD_R ** 2 + (2 * ROD_H) ** 2) / 12
    b = s.add_body(1.0, (It, It, Ia), pos=(xy[0], xy[1], ROD_R + DP / 2 + 0.001), quat=q,
                   vel=vel)
    if shape == "capsule":
        s.add_capsule(b, ROD_R, ROD_H, material=m)
    else:
        s.add_cylinder(b, ROD_R, ROD_H, material=m)
    return s, b


@pytest.mark.parametrize("shape", ["capsule", "cylinder"])
@pytest.mark.parametrize("xy, yaw", [((0.0, 0.0), 0.0), ((DP / 2, DP / 2), 0.0),
                                     ((0.0037, 0.0061), 0.0), ((0.0037, 0.0061), 27.0)],
                         ids=["over_a_row", "between_rows", "anywhere", "anywhere_turned"])
def test_rod_rests_on_a_cloud_face_wherever_it_lands(shape, xy, yaw):
    """A capsule or a cylinder lying on a cloud block's top face rests on the face's tangent
    plane, its axis R + dp/2 above the top layer (to 1e-9 m), level, with the contact force
    m g to 1 % at every step of the last 0.2 s, wherever it lands and however it is turned
    (against each particle's sphere it sank between the particles and rocked)."""
    s, b = _rod_on_slab(shape, xy, yaw)
    fz = _run(s, b, 0.5, 0.3)
    assert abs(s.pos[b, 2] - (ROD_R + DP / 2)) < 1e-9
    np.testing.assert_allclose(s.pos[b, :2], xy, atol=1e-6)
    axis = np_quat_to_mat(s.quat[b])[:, 2]
    assert abs(axis[2]) < 1e-8
    assert np.abs(fz / G - 1.0).max() < 1e-2


@pytest.mark.parametrize("shape", ["capsule", "cylinder"])
def test_rod_rolls_across_a_cloud_face_at_one_height(shape):
    """Thrown across its axis at 0.3 m/s with Kfric 0.5, the rod skids, then rolls over ~8
    lattice cells, its axis at R + dp/2 within 1e-6 m throughout."""
    s, b = _rod_on_slab(shape, (-0.1, 0.0037), yaw=90.0, vel=(0.3, 0.0, 0.0))
    z = []
    while s.time < 0.6 - 1e-9:
        s.step(1e-3)
        if s.time > 0.05:
            z.append(s.pos[b, 2])
    assert np.abs(np.array(z) - (ROD_R + DP / 2)).max() < 1e-6
    assert s.pos[b, 0] > 0.0
    omega = s.omega_world[b]
    # rolling without slip: v = ω × (R + dp/2) about the axis (world y)
    assert abs(s.vel[b, 0] - omega[1] * ROD_R) < 1e-3 * abs(s.vel[b, 0]) + 1e-6

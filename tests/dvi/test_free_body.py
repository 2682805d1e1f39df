"""M1: free body (semi-implicit Euler, exponential-map quaternion update)."""
import numpy as np

from sphdvi.dvi import System


def test_free_fall_and_ballistic():
    h = 1e-3
    s = System(gravity=(0, 0, -9.81))
    s.add_body(2.0, (0.1, 0.2, 0.3), pos=(0, 0, 10), vel=(1.0, -0.5, 2.0))
    n = 1000
    for _ in range(n):
        s.step(h)
    t = n * h
    z_exact = 10 + 2.0 * t - 0.5 * 9.81 * t * t
    assert abs(s.pos[0, 2] - z_exact) <= h * 9.81 * t  # O(h) offset of symplectic Euler
    assert abs(s.pos[0, 0] - 1.0 * t) < 1e-12          # DSPH#74: free flight = v t
    assert abs(s.pos[0, 1] + 0.5 * t) < 1e-12
    assert abs(s.vel[0, 2] - (2.0 - 9.81 * t)) < 1e-12


def test_external_force_per_step():
    s = System(gravity=(0, 0, 0))
    s.add_body(2.0, (1, 1, 1))
    F = np.array([[4.0, 0, 0]])
    for _ in range(100):
        s.step(1e-2, forces=F)
    assert abs(s.vel[0, 0] - 2.0) < 1e-12
    np.testing.assert_allclose(s.total_force[0], [4, 0, 0], atol=1e-12)


def test_torque_free_symmetric_top():
    """Symmetric top I1 = I2 = 1, I3 = 2: the body-frame ω precesses about the
    symmetry axis at Ω = (I3 − I1)/I1 ω3; |L_world| and energy are conserved."""
    I1, I3 = 1.0, 2.0
    w0 = np.array([0.3, 0.0, 2.0])
    s = System(gravity=(0, 0, 0))
    s.add_body(1.0, (I1, I1, I3), omega=w0)
    L0 = s.angular_momentum_world(0)
    E0 = s.kinetic_energy()
    h = 1e-4
    n = 10000
    for _ in range(n):
        s.step(h)
    t = n * h
    Om = (I3 - I1) / I1 * w0[2]
    wb = s.omega_b[0]
    # ω_b(t) = (a cos Ωt, a sin Ωt, ω3) for ω_b(0) = (a, 0, ω3) with Ω as above
    # (rotation sense: dω1/dt = -Ω ω2)
    expected = np.array([0.3 * np.cos(Om * t), 0.3 * np.sin(Om * t), 2.0])
    np.testing.assert_allclose(wb, expected, atol=2e-3)
    L = s.angular_momentum_world(0)
    assert np.linalg.norm(L - L0) / np.linalg.norm(L0) < 1e-3
    assert abs(s.kinetic_energy() - E0) / E0 < 1e-3


def test_dof_restriction_and_imposed_velocity():
    s = System(gravity=(0, 0, -9.81))
    a = s.add_body(1.0, (1, 1, 1), translation_dof=(1, 0, 0), rotation_dof=(0, 0, 0),
                   vel=(1, 1, 1), omega=(1, 1, 1))
    b = s.add_body(1.0, (1, 1, 1), imposed_velocity=(0.5, None, None, None, None, 2.0))
    for _ in range(100):
        s.step(1e-3)
    np.testing.assert_allclose(s.vel[a], [1, 0, 0], atol=1e-14)
    np.testing.assert_allclose(s.omega_world[a], [0, 0, 0], atol=1e-14)
    np.testing.assert_allclose(s.vel[b, 0], 0.5, atol=1e-10)
    np.testing.assert_allclose(s.omega_world[b, 2], 2.0, atol=1e-10)
    np.testing.assert_allclose(s.vel[b, 2], -9.81 * 0.1, atol=1e-10)  # free component


def test_moving_body_follows_motion():
    s = System(gravity=(0, 0, -9.81))
    b = s.add_body(1.0, (1, 1, 1), kind="moving", motion=lambda t: ((np.sin(t), 0, 0), (0, 0, 1.0)))
    for _ in range(1000):
        s.step(1e-3)
    assert abs(s.pos[b, 0] - (1 - np.cos(1.0))) < 1e-3
    assert abs(s.pos[b, 2]) < 1e-15


def test_euler_angles_convention():
    """bodies.csv angles: R = Rz(yaw) Ry(pitch) Rx(roll), degrees."""
    from sphdvi.dvi._math import np_quat_to_mat, quat_to_euler_deg
    rng = np.random.default_rng(3)
    for _ in range(50):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        r, p, y = np.radians(quat_to_euler_deg(q)[0])
        Rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
        Ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
        Rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
        np.testing.assert_allclose(Rz @ Ry @ Rx, np_quat_to_mat(q), atol=1e-10)


def test_only_the_link_types_present_are_built(monkeypatch):
    """A body without links or contacts: System.step calls no row builder, nor prepare_rows nor
    the CCP solver (v = v_free, what the solvers return on zero rows); a system with one spring
    builds its row and no mate's."""
    import pytest
    from sphdvi.dvi import rows as rw
    from sphdvi.dvi import system as system_module

    def free():
        s = System(gravity=(0, 0, -9.81))
        s.add_body(2.0, (1.0, 1.0, 1.0), pos=(0, 0, 1), vel=(1.0, 0.0, 0.5))
        return s

    for name in ("build_mate_rows", "build_spring_rows", "build_coulomb_rows", "build_pulley_rows",
                 "build_imposed_rows"):
        monkeypatch.setattr(rw, name, lambda *a, _n=name: pytest.fail(f"{_n} called"))
    for name in ("prepare_rows", "solve_ccp", "solve_direct"):
        monkeypatch.setattr(system_module, name, lambda *a, _n=name: pytest.fail(f"{_n} called"))
    s = free()
    F = np.array([[0.4, 0.0, 0.0]])
    for _ in range(10):
        s.step(1e-2, forces=F)
    assert s.n_rows == 0 and s.last_iterations == 0
    np.testing.assert_allclose(s.vel[0], [1.0 + 0.2 * 0.1, 0.0, 0.5 - 9.81 * 0.1], rtol=0, atol=1e-12)
    monkeypatch.undo()
    monkeypatch.setattr(rw, "build_mate_rows", lambda *a: pytest.fail("build_mate_rows called"))
    s = free()
    s.add_spring(0, -1, point1=(0, 0, 1), point2=(0, 0, 2), stiffness=50.0, damping=1.0, rest_length=1.0)
    s.step(1e-3)
    assert s.n_rows == 1

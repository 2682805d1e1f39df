"""M2/M4: joints, motors, pulley, closed loops."""
import math

import numpy as np
import pytest

from conftest import agm, crossing_times
from sphdvi.dvi import System
from sphdvi.dvi._math import np_quat_to_mat

G = 9.81


def compound_pendulum(theta0_deg, h=1e-3, solver="bb", periods=2.2):
    """Uniform-ish body (m = 1, I_c = 0.01) on a hinge at distance d = 1 (axis y)."""
    d = 1.0
    Ic = 0.01
    th = math.radians(theta0_deg)
    s = System(gravity=(0, 0, -G), solver=solver, max_iter=100, tol=1e-10)
    # body below the pivot at angle θ0 from the vertical, in the x-z plane
    b = s.add_body(1.0, (Ic, Ic, Ic), pos=(d * math.sin(th), 0, -d * math.cos(th)))
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 1, 0))
    Ip = Ic + d * d
    T0 = 2 * math.pi * math.sqrt(Ip / (G * d))
    T = T0 / agm(1.0, math.cos(th / 2))
    n = int(periods * T / h)
    t = np.arange(1, n + 1) * h
    x = np.empty(n)
    e = np.empty(n)
    viol = 0.0
    for k in range(n):
        s.step(h)
        x[k] = s.pos[b, 0]
        e[k] = s.kinetic_energy() + s.potential_energy()
        if k % 50 == 0:
            viol = max(viol, s.constraint_violation())
    return t, x, e, T, viol, s


@pytest.mark.parametrize("theta0,expected_ratio", [(30, 1.01741), (90, 1.18034), (150, 1.76220)])
def test_pendulum_large_amplitude_period(theta0, expected_ratio):
    t, x, e, T, viol, s = compound_pendulum(theta0)
    T0 = 2 * math.pi * math.sqrt(1.01 / G)
    assert T / T0 == pytest.approx(expected_ratio, abs=1e-5)  # the reference formula
    tc = crossing_times(t, x, -1)
    Tm = tc[1] - tc[0]
    assert abs(Tm / T - 1) < 5e-3
    assert viol < 1e-4


def test_pendulum_energy_drift_small():
    """Euler implicit linearised damps numerically; over 10 small-amplitude
    periods at h = 1e-3 the drift must stay below 1 % of the swing energy."""
    t, x, e, T, viol, s = compound_pendulum(30, h=1e-3, periods=10)
    swing = 1.0 * G * 1.0 * (1 - math.cos(math.radians(30)))
    assert abs(e[-1] - e[0]) / swing < 1e-2


def test_reaction_of_hinge_at_release():
    """Horizontal compound pendulum at release: joint force = m g (1 − m d²/I_p)
    upwards on the body, zero torque about the hinge axis."""
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=200, tol=1e-12)
    b = s.add_body(1.0, (0.04, 0.1, 0.1), pos=(2, 0, 0))
    lid = s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 1, 0))
    s.step(1e-4)
    Fz = G * (1 - 4.0 / 4.1)
    np.testing.assert_allclose(s.link_force[lid], [0, 0, Fz], atol=2e-3)
    assert abs(s.link_torque[lid][1]) < 1e-9


def _double_pendulum_ode(T):
    """Minimal-coordinate ODE of two uniform rods (m = 1, l = 1), angles from
    +x towards +z, solved to 1e-12 (reference for M7)."""
    from scipy.integrate import solve_ivp

    def rhs(t, y, m=1.0, l=1.0):
        th1, th2, w1, w2 = y
        s1, c1, s2, c2 = math.sin(th1), math.cos(th1), math.sin(th2), math.cos(th2)
        J1 = np.array([[-l / 2 * s1, 0], [l / 2 * c1, 0]])
        J2 = np.array([[-l * s1, -l / 2 * s2], [l * c1, l / 2 * c2]])
        a1 = np.array([-l / 2 * c1 * w1 ** 2, -l / 2 * s1 * w1 ** 2])
        a2 = np.array([-l * c1 * w1 ** 2 - l / 2 * c2 * w2 ** 2, -l * s1 * w1 ** 2 - l / 2 * s2 * w2 ** 2])
        M = m * (J1.T @ J1 + J2.T @ J2) + np.diag([m * l * l / 12] * 2)
        f = -m * G * (J1[1] + J2[1]) - m * (J1.T @ a1 + J2.T @ a2)
        dw = np.linalg.solve(M, f)
        return [w1, w2, dw[0], dw[1]]

    return solve_ivp(rhs, (0, T), [0, 0, 0, 0], rtol=1e-12, atol=1e-12, dense_output=True).sol


def double_pendulum(h, tend, solver="bb", ode=None):
    s = System(gravity=(0, 0, -G), solver=solver, max_iter=200, tol=1e-11)
    I = 1.0 / 12.0
    # two uniform rods of length 1, horizontal at start, hinged about y
    b1 = s.add_body(1.0, (I, I, 1e-4), pos=(0.5, 0, 0), quat=(math.cos(math.pi / 4), 0, math.sin(math.pi / 4), 0))
    b2 = s.add_body(1.0, (I, I, 1e-4), pos=(1.5, 0, 0), quat=(math.cos(math.pi / 4), 0, math.sin(math.pi / 4), 0))
    s.add_link("hinge", b1, -1, point=(0, 0, 0), axis=(0, 1, 0))
    s.add_link("hinge", b2, b1, point=(1, 0, 0), axis=(0, 1, 0))
    e0 = s.kinetic_energy() + s.potential_energy()
    n = int(tend / h)
    emin = emax = e0
    viol = 0.0
    err = 0.0
    for k in range(1, n + 1):
        s.step(h)
        e = s.kinetic_energy() + s.potential_energy()
        emin = min(emin, e)
        emax = max(emax, e)
        if k % 100 == 0:
            viol = max(viol, s.constraint_violation())
            if ode is not None:
                th1, th2 = ode(k * h)[:2]
                x2 = math.cos(th1) + 0.5 * math.cos(th2)
                z2 = math.sin(th1) + 0.5 * math.sin(th2)
                err = max(err, math.hypot(s.pos[b2, 0] - x2, s.pos[b2, 2] - z2))
    return s, e0, emin, emax, viol, err


def test_double_pendulum_energy_and_ode():
    """M7: energy drift < 1 % of m g l and the CoM of rod 2 within 1e-3 m of
    the minimal-coordinate ODE for t < 2 s (first order: error ≈ 2.8 h)."""
    s, e0, emin, emax, viol, err = double_pendulum(2e-4, 2.0, ode=_double_pendulum_ode(2.0))
    scale = 2 * 1.0 * G * 1.0
    assert (e0 - emin) / scale < 1e-2
    assert (emax - e0) / scale < 1e-3  # never gains energy beyond round-off/stabilisation
    assert viol < 1e-5
    assert err < 1e-3


@pytest.mark.slow
def test_double_pendulum_energy_10s():
    s, e0, emin, emax, viol, err = double_pendulum(1e-4, 10.0)
    scale = 2 * 1.0 * G * 1.0
    assert (e0 - emin) / scale < 1e-2
    assert (emax - e0) / scale < 1e-3


def test_slider_crank_closed_form():
    """Crank (r = 0.2) driven at ω = 2π rad/s by a speed motor, rod l = 0.5,
    slider on a prismatic joint along x: x = r cos ωt + √(l² − r² sin² ωt)."""
    r, l, w = 0.2, 0.5, 2 * math.pi
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=300, tol=1e-11)
    crank = s.add_body(1.0, (0.01, 0.01, 0.01), pos=(r / 2, 0, 0))
    rod = s.add_body(1.0, (0.02, 0.02, 0.02), pos=(r + (l - r) / 2 + 0.0, 0, 0))
    # rod from crank tip (r,0,0) to slider (r+l, 0, 0) when θ = 0
    s.pos[rod] = (r + l / 2, 0, 0)
    slider = s.add_body(1.0, (0.01, 0.01, 0.01), pos=(r + l, 0, 0))
    # crank angle θ measured from +x towards +z is a rotation about −y
    s.add_link("hinge", crank, -1, point=(0, 0, 0), axis=(0, -1, 0), motor="speed", motor_target=w)
    s.add_link("hinge", rod, crank, point=(r, 0, 0), axis=(0, 1, 0))
    s.add_link("hinge", slider, rod, point=(r + l, 0, 0), axis=(0, 1, 0))
    s.add_link("slider", slider, -1, point=(r + l, 0, 0), axis=(1, 0, 0))
    h = 1e-3
    err = 0.0
    viol = 0.0
    for k in range(1, 1001):
        s.step(h)
        t = k * h
        xe = r * math.cos(w * t) + math.sqrt(l * l - (r * math.sin(w * t)) ** 2)
        err = max(err, abs(s.pos[slider, 0] - xe))
        if k % 20 == 0:
            viol = max(viol, s.constraint_violation())
    assert err < 1e-3
    assert viol < 1e-4


def test_hinge_angle_motor():
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-12)
    b = s.add_body(1.0, (0.1, 0.1, 0.1), pos=(0.5, 0, 0))
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 0, 1), motor="angle",
               motor_target=lambda t: 0.5 * math.sin(t))
    for _ in range(1000):
        s.step(1e-3)
    ang = math.atan2(s.pos[b, 1], s.pos[b, 0])
    assert abs(ang - 0.5 * math.sin(1.0)) < 1e-6


def test_pulley_ratio():
    """Two wheels on hinges coupled by a belt: r1 ω1 = r2 ω2."""
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=200, tol=1e-13)
    w1 = s.add_body(1.0, (0.1, 0.1, 0.2), pos=(0, 0, 0))
    w2 = s.add_body(2.0, (0.3, 0.3, 0.5), pos=(1, 0, 0))
    s.add_link("hinge", w1, -1, point=(0, 0, 0), axis=(0, 0, 1))
    s.add_link("hinge", w2, -1, point=(1, 0, 0), axis=(0, 0, 1))
    s.add_link("pulley", w1, w2, axis=(0, 0, 1), radius=0.1, radius2=0.3)
    T = np.zeros((2, 3))
    T[0, 2] = 1.0
    for _ in range(500):
        s.step(1e-3, torques=T)
    om = s.omega_world
    assert om[w1, 2] > 1.0
    assert abs(0.1 * om[w1, 2] - 0.3 * om[w2, 2]) < 1e-9
    # dynamics: τ = (I1 + I2 (r1/r2)²) α1
    alpha = 1.0 / (0.2 + 0.5 / 9.0)
    assert om[w1, 2] == pytest.approx(alpha * 0.5, rel=1e-6)


def test_four_bar_drift_and_spherical_pointline():
    """Closed four-bar loop (hinges) under gravity: violation stays small."""
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=200, tol=1e-11)
    a = s.add_body(1.0, (0.01,) * 3, pos=(0, 0, -0.5))
    c = s.add_body(1.0, (0.01,) * 3, pos=(1, 0, -0.5))
    bl = s.add_body(1.0, (0.01,) * 3, pos=(0.5, 0, -1.0))
    s.add_link("hinge", a, -1, point=(0, 0, 0), axis=(0, 1, 0))
    s.add_link("hinge", c, -1, point=(1, 0, 0), axis=(0, 1, 0))
    s.add_link("hinge", bl, a, point=(0, 0, -1), axis=(0, 1, 0))
    s.add_link("hinge", bl, c, point=(1, 0, -1), axis=(0, 1, 0))
    s.set_velocity(bl, vel=(1.0, 0, 0))
    viol = 0.0
    for k in range(2000):
        s.step(1e-3)
        if k % 20 == 0:
            viol = max(viol, s.constraint_violation())
    assert viol < 1e-5
    assert np.all(np.isfinite(s.pos))


def test_pointline_variants():
    """Point-line: the point slides along the line; rotvector locks the other
    rotations, rotvector2 adds a second free rotation."""
    for rot_axis, rot_axis2, free in ((None, None, 3), ((0, 0, 1), None, 1), ((0, 0, 1), (1, 0, 0), 2)):
        s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-12)
        b = s.add_body(1.0, (0.1, 0.1, 0.1), pos=(0, 0, 0), omega=(1.0, 2.0, 3.0))
        s.add_link("pointline", b, -1, point=(0, 0, 0), axis=(0, 0, 1), rot_axis=rot_axis,
                   rot_axis2=rot_axis2)
        for _ in range(200):
            s.step(1e-3)
        assert abs(s.pos[b, 0]) < 1e-9 and abs(s.pos[b, 1]) < 1e-9
        assert s.pos[b, 2] < -0.1  # free fall along the line
        w = s.omega_world[b]
        R = np_quat_to_mat(s.quat[b])
        if free == 3:
            assert np.all(np.abs(w) > 0.5)
        elif free == 1:
            np.testing.assert_allclose(w, [0, 0, 3.0], atol=1e-9)
        else:  # universal-joint-like: body z stays ⟂ to world x (rotvector2)
            assert abs(R[:, 2] @ [1, 0, 0]) < 1e-5
            assert abs(w[0]) > 0.5 and abs(w[2]) > 0.5
        assert s.constraint_violation() < 1e-5


def four_bar(projection, tend):
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-12,
               position_projection=projection)
    a = s.add_body(1.0, (0.01,) * 3, pos=(0, 0, -0.5))
    c = s.add_body(1.0, (0.01,) * 3, pos=(1, 0, -0.5))
    bl = s.add_body(1.0, (0.01,) * 3, pos=(0.5, 0, -1.0))
    s.add_link("hinge", a, -1, point=(0, 0, 0), axis=(0, 1, 0))
    s.add_link("hinge", c, -1, point=(1, 0, 0), axis=(0, 1, 0))
    s.add_link("hinge", bl, a, point=(0, 0, -1), axis=(0, 1, 0))
    s.add_link("hinge", bl, c, point=(1, 0, -1), axis=(0, 1, 0))
    s.set_velocity(bl, vel=(2.0, 0, 0))
    viol = 0.0
    e0 = s.kinetic_energy() + s.potential_energy()
    its = []
    for k in range(int(round(tend / 1e-3))):
        s.step(1e-3)
        its.append(s.last_iterations)
        if k % 100 == 0:
            viol = max(viol, s.constraint_violation())
    return viol, s, e0, its


@pytest.mark.parametrize("projection,limit", [(False, 1e-5), (True, 1e-9)])
def test_four_bar_drift(projection, limit):
    """M12: closed four-bar loop; with position projection the violation stays
    < 1e-9 m, without it at the O(h²v²/L) level of velocity stabilisation."""
    viol, s, e0, its = four_bar(projection, 5.0)
    assert viol < limit


@pytest.mark.slow
def test_four_bar_100s():
    viol, s, e0, its = four_bar(True, 100.0)
    assert viol < 1e-6
    assert np.all(np.isfinite(s.pos))


def test_slider_pendulum_vs_ode():
    """M8 (Chrono utest_CH_slider_pend): slider on a prismatic joint with a
    horizontal spring, uniform rod hinged on it.  Minimal coordinates (x, φ);
    positions within 1e-3 m, constraint drift < 1e-6 (position projection)."""
    from scipy.integrate import solve_ivp
    m1, m2, l, k = 1.0, 0.5, 0.8, 20.0
    I2 = m2 * l * l / 12

    def rhs(t, y):
        x, ph, vx, w = y
        J2 = np.array([[1.0, 0.5 * l * math.cos(ph)], [0.0, 0.5 * l * math.sin(ph)]])
        a2 = np.array([-0.5 * l * math.sin(ph) * w * w, 0.5 * l * math.cos(ph) * w * w])
        M = np.diag([m1, I2]) + m2 * J2.T @ J2
        f = np.array([-k * x, 0.0]) - m2 * G * J2[1] - m2 * J2.T @ a2
        acc = np.linalg.solve(M, f)
        return [vx, w, acc[0], acc[1]]

    x0, ph0 = 0.1, math.radians(30)
    T = 2.0
    ode = solve_ivp(rhs, (0, T), [x0, ph0, 0, 0], rtol=1e-12, atol=1e-12, dense_output=True).sol
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=200, tol=1e-12, position_projection=True)
    sl = s.add_body(m1, (0.01, 0.01, 0.01), pos=(x0, 0, 0))
    # φ measured from −z towards +x: a rotation by −φ about +y
    q = (math.cos(-ph0 / 2), 0, math.sin(-ph0 / 2), 0)
    pe = s.add_body(m2, (I2, I2, I2), pos=(x0 + 0.5 * l * math.sin(ph0), 0, -0.5 * l * math.cos(ph0)), quat=q)
    s.add_link("prismatic", sl, -1, point=(x0, 0, 0), axis=(1, 0, 0))
    s.add_spring(sl, -1, point1=(x0, 0, 0), point2=(-1.0, 0, 0), stiffness=k, rest_length=1.0)
    s.add_link("hinge", pe, sl, point=(x0, 0, 0), axis=(0, 1, 0))
    h = 1e-4
    err = 0.0
    viol = 0.0
    for n in range(1, int(T / h) + 1):
        s.step(h)
        if n % 200 == 0:
            x, ph = ode(n * h)[:2]
            err = max(err, abs(s.pos[sl, 0] - x),
                      abs(s.pos[pe, 0] - (x + 0.5 * l * math.sin(ph))),
                      abs(s.pos[pe, 2] + 0.5 * l * math.cos(ph)))
            viol = max(viol, s.constraint_violation())
    assert err < 1e-3
    assert viol < 1e-6

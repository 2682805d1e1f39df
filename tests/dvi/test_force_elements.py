"""M4: springs, dampers, joint stiffness (implicit compliance rows or explicit
impulses), stiff cases."""
import math

import numpy as np
import pytest

from conftest import crossing_times
from sphdvi.dvi import System

G = 9.81


@pytest.mark.parametrize("k,c", [(10.0, 0.5), (100.0, 5.0)])
def test_spring_mass_damper(k, c):
    """TSDA between ground and a 1 kg mass (no gravity), Chrono utest_JOINT_tsda
    parameters: x(t) = e^(−ζω t)(A cos ω_d t + B sin ω_d t)."""
    m = 1.0
    h = 2e-5 if k > 50 else 1e-4
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=50, tol=1e-13)
    b = s.add_body(m, (0.1, 0.1, 0.1), pos=(1.2, 0, 0))
    s.add_spring(b, -1, point1=(1.2, 0, 0), point2=(0, 0, 0), stiffness=k, damping=c, rest_length=1.0)
    wn = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta ** 2)
    x0 = 0.2
    n = int(2.0 / h)
    t = np.arange(1, n + 1) * h
    x = np.empty(n)
    for i in range(n):
        s.step(h)
        x[i] = s.pos[b, 0] - 1.0
    exact = np.exp(-zeta * wn * t) * x0 * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    assert np.abs(x - exact).max() < 1e-3 * x0
    tc = crossing_times(t, x, -1)
    if len(tc) >= 2:
        assert abs((tc[1] - tc[0]) / (2 * math.pi / wd) - 1) < 5e-3
    # spring reaction on body 1 (link force) = −k x − c v along x
    assert abs(s.link_force[0][0] - (-k * x[-1] - c * s.vel[b, 0])) < 1e-3 * k * x0


def test_coulomb_damper_linear_decay():
    """Mass-spring with a Coulomb damper F: amplitude falls by 4F/k per cycle
    and the motion stops inside |x| ≤ F/k."""
    m, k, F = 1.0, 100.0, 1.0
    h = 1e-4
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=100, tol=1e-13)
    b = s.add_body(m, (0.1, 0.1, 0.1), pos=(1.3, 0, 0))
    s.add_spring(b, -1, point1=(1.3, 0, 0), point2=(0, 0, 0), stiffness=k, rest_length=1.0)
    s.add_coulomb_damper(b, -1, point1=(1.3, 0, 0), point2=(-1.0, 0, 0), force=F)
    n = int(3.0 / h)
    x = np.empty(n)
    for i in range(n):
        s.step(h)
        x[i] = s.pos[b, 0] - 1.0
    peaks = [x[i] for i in range(1, n - 1) if x[i] > x[i - 1] and x[i] >= x[i + 1] and x[i] > 0.02]
    drops = -np.diff(peaks)
    # 4F/k = 0.04 per cycle, the analytic decrement of a Coulomb-damped oscillator (Den Hartog
    # 1930): measured within 3.3e-7 of it at h = 1e-4 (the peaks are step samples), so a damper
    # force off by more than ~0.01 % fails
    assert len(drops) >= 2
    np.testing.assert_allclose(drops, 4 * F / k, rtol=1e-4)
    # x0 = 0.3 -> peaks 0.26, 0.22, ...; stops within |x| <= F/k
    for _ in range(int(6.0 / h)):
        s.step(h)
    assert abs(s.pos[b, 0] - 1.0) <= F / k + 1e-6
    assert abs(s.vel[b, 0]) < 1e-8


@pytest.mark.parametrize("scheme", ["implicit", "explicit", "auto"])
def test_torsional_spring_frequency_and_table(scheme):
    """Hinge with rotational stiffness k: ω = √(k/I), implicit or explicit
    (auto picks explicit here: ω h = 1e-3)."""
    I, k = 0.5, 50.0
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=50, tol=1e-13,
               spring_integration=scheme)
    b = s.add_body(1.0, (0.1, 0.1, I), omega=(0, 0, 1.0))
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 0, 1), stiffness=k)
    h = 1e-4
    n = int(2.0 / h)
    th = np.empty(n)
    for i in range(n):
        s.step(h)
        th[i] = s.m_angle[0, 2]
    t = np.arange(1, n + 1) * h
    tc = crossing_times(t, th, -1)
    w = math.sqrt(k / I)
    assert abs((tc[1] - tc[0]) / (2 * math.pi / w) - 1) < 2e-3
    assert abs(th.max() - 1.0 / w) / (1.0 / w) < 1e-2
    # reaction torque about the axis on body 1: −k θ at the end of the step
    # (implicit) or at its start (explicit)
    th_end = th[-1] + h * s.omega_world[b, 2]
    th_force = th_end if scheme == "implicit" else th[-1]
    assert abs(s.link_torque[0][2] + k * th_force) < 1e-6 * k
    # time-dependent stiffness table: zero stiffness -> free rotation
    s2 = System(gravity=(0, 0, 0), solver="bb", max_iter=50)
    b2 = s2.add_body(1.0, (0.1, 0.1, I), omega=(0, 0, 1.0))
    s2.add_link("hinge", b2, -1, point=(0, 0, 0), axis=(0, 0, 1), stiffness=[[0, 0.0], [10, 0.0]])
    for _ in range(100):
        s2.step(1e-3)
    assert abs(s2.omega_world[b2, 2] - 1.0) < 1e-10


def test_stiff_hinge_1e8_is_stable():
    """Hinge stiffness 1e8 N·m/rad on a 1 m, 1 kg pendulum at h = 1e-3:
    finite, energy bounded, constraint violation < 1e-4."""
    s = System(gravity=(0, 0, -G), solver="bb", max_iter=100, tol=1e-12)
    b = s.add_body(1.0, (0.01, 0.01, 0.01), pos=(1, 0, 0), omega=(0, 1.0, 0))
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 1, 0), stiffness=1e8, damping=0.0)
    e0 = s.kinetic_energy() + s.potential_energy()
    viol = 0.0
    for k in range(2000):
        s.step(1e-3)
        viol = max(viol, s.constraint_violation())
        assert s.kinetic_energy() + s.potential_energy() <= e0 + 1e-6 + 1e-5 * abs(e0)
    assert np.all(np.isfinite(s.pos))
    assert viol < 1e-4
    assert abs(s.pos[b, 2]) < 1e-6  # held horizontal by the stiff spring


def test_spring_scheme_auto_is_explicit_when_soft_and_implicit_when_stiff():
    """A soft spring keeps its amplitude (explicit: no numerical damping); a
    spring with ω h = 10 stays bounded (implicit) where the explicit form,
    asked for on purpose, blows up."""
    def amplitude_after(k, h, steps, scheme):
        s = System(gravity=(0, 0, 0), solver="bb", max_iter=50, tol=1e-13,
                   spring_integration=scheme)
        b = s.add_body(1.0, (0.1, 0.1, 0.1), pos=(1.1, 0, 0))
        s.add_spring(b, -1, point1=(1.1, 0, 0), point2=(0, 0, 0), stiffness=k, rest_length=1.0)
        e = []
        for _ in range(steps):
            s.step(h)
            e.append(0.5 * s.vel[b, 0] ** 2 + 0.5 * k * (s.pos[b, 0] - 1.0) ** 2)
        return math.sqrt(2 * max(e[-steps // 4:]) / k)
    # soft: ω h = 1e-3 over 10 periods
    soft = dict(k=100.0, h=1e-4, steps=int(2 * math.pi * 10 / 10.0 / 1e-4))
    assert abs(amplitude_after(**soft, scheme="auto") - 0.1) < 2e-4
    assert amplitude_after(**soft, scheme="implicit") < 0.1 * (1 - 1e-3)  # damped
    # stiff: ω h = 10
    stiff = dict(k=1e8, h=1e-3, steps=200)
    assert amplitude_after(**stiff, scheme="auto") <= 0.1 + 1e-12
    with np.errstate(all="ignore"):
        a = amplitude_after(**stiff, scheme="explicit")
    assert not (a < 1.0)


@pytest.mark.parametrize("solver,iters", [("direct", 100), ("bb", 2000)])
def test_mass_ratio_chain_1e4(solver, iters):
    """Spherical-joint chain with masses 1, 100, 1e4 (ratio 1e4), released
    horizontal: finite, energy bounded, violation < 1e-4 at h = 1e-3.  The
    matrix-free solvers need many iterations here (BB: 2000; PSOR/APGD with
    300 iterations gain energy), the direct path is exact."""
    s = System(gravity=(0, 0, -G), solver=solver, max_iter=iters, tol=1e-12)
    masses = [1.0, 100.0, 1e4]
    prev = -1
    for i, m in enumerate(masses):
        I = m * 0.01
        b = s.add_body(m, (I, I, I), pos=(0.5 + i, 0, 0))
        s.add_link("spherical", b, prev, point=(float(i), 0, 0))
        prev = b
    e0 = s.kinetic_energy() + s.potential_energy()
    viol = 0.0
    for k in range(1000):
        s.step(1e-3)
        if k % 10 == 0:
            viol = max(viol, s.constraint_violation())
    e1 = s.kinetic_energy() + s.potential_energy()
    scale = sum(m * G * (0.5 + i) for i, m in enumerate(masses))
    assert np.all(np.isfinite(s.pos))
    assert e1 <= e0 + 1e-3 * scale
    assert viol < 1e-4


def test_imposed_velocity_with_spring_stays_attached():
    """DSPH#124: a spring attached to a body with an imposed velocity: the
    imposed component is exact, the free ones follow the spring."""
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=100, tol=1e-13)
    b = s.add_body(1.0, (0.1, 0.1, 0.1), pos=(0, 0, 1.0), imposed_velocity=(0.2, None, None, 0, 0, 0))
    s.add_spring(b, -1, point1=(0, 0, 1.0), point2=(0, 0, 0), stiffness=10.0, rest_length=0.9)
    for _ in range(1000):
        s.step(1e-3)
    assert abs(s.pos[b, 0] - 0.2) < 1e-9
    assert abs(s.pos[b, 2] - 1.0) > 1e-3  # spring acts on the free component
    assert np.linalg.norm(s.link_force[0]) > 0


def test_spherical_joint_rotational_stiffness():
    """Spherical joint with rotational stiffness k on all three axes: small
    torsional oscillations about x at ω = √(k/I_x), the joint point fixed."""
    I, k = 0.2, 20.0
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=50, tol=1e-13)
    b = s.add_body(1.0, (I, 0.5, 0.5), omega=(0.05, 0, 0))
    s.add_link("spherical", b, -1, point=(0, 0, 0), stiffness=k)
    h = 1e-4
    n = int(1.5 / h)
    wx = np.empty(n)
    for i in range(n):
        s.step(h)
        wx[i] = s.omega_world[b, 0]
    t = np.arange(1, n + 1) * h
    tc = crossing_times(t, wx, -1)
    assert abs((tc[1] - tc[0]) / (2 * math.pi / math.sqrt(k / I)) - 1) < 2e-3
    assert np.abs(s.pos[b]).max() < 1e-9


def test_hinged_flap_constant_torque():
    """A flap on a hinge under a constant external torque τ (no gravity):
    θ(t) = ½ (τ/I_axis) t² exactly for the velocity and O(h) for θ."""
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=50, tol=1e-13)
    b = s.add_body(2.0, (0.3, 0.3, 0.3), pos=(0.5, 0, 0))
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 0, 1))
    Iax = 0.3 + 2.0 * 0.25
    T = np.zeros((1, 3))
    T[0, 2] = 0.4
    h = 1e-3
    for _ in range(1000):
        s.step(h, torques=T)
    w_exact = 0.4 / Iax * 1.0
    assert abs(s.omega_world[b, 2] - w_exact) < 1e-6 * w_exact + 1e-4
    th = math.atan2(s.pos[b, 1], s.pos[b, 0])
    assert abs(th - 0.5 * 0.4 / Iax) < h * w_exact

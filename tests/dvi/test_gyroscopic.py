"""The gyroscopic term ω × (J ω) of a free rotation, taken at the step's midpoint (implicit
midpoint rule of Euler's equations in the body frame, hunt8/t finding 2): a torque-free body
keeps its rotational energy and |L| to round-off; the explicit term made both grow at first
order in h (dE/E = +9.8e-4 over 2 s at h = 1e-3 for the body below)."""
import numpy as np

from sphdvi.dvi import System
from sphdvi.dvi._kernels import gyroscopic_midpoint

I_B = (0.01, 0.02, 0.03)
W0 = (1.0, 0.2, 3.0)        # near the unstable middle axis's separatrix: a tumbling body


def spin(h, n, inertia=np.diag(I_B), omega=W0):
    s = System(gravity=(0, 0, 0))
    b = s.add_body(mass=1.0, inertia=inertia, omega=omega)
    L0, E0 = s.angular_momentum_world(b).copy(), s.kinetic_energy()
    for _ in range(n):
        s.step(h)
    return s, b, L0, E0


def test_torque_free_body_keeps_energy_and_angular_momentum_magnitude():
    s, b, L0, E0 = spin(1e-3, 2000)
    L = s.angular_momentum_world(b)
    assert abs(s.kinetic_energy() / E0 - 1.0) < 1e-12
    assert abs(np.linalg.norm(L) / np.linalg.norm(L0) - 1.0) < 1e-12
    # the direction of L still drifts at first order in h (the attitude moves with the
    # step's end ω, as the joint solver needs): 1.1e-4 over 2 s at h = 1e-3
    assert np.linalg.norm(L - L0) / np.linalg.norm(L0) < 2e-4


def test_full_inertia_tensor_keeps_energy():
    """A principal frame rotated 30° about (1, 1, 0): off-diagonal J, same conservation."""
    ax = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    K = np.array([[0, -ax[2], ax[1]], [ax[2], 0, -ax[0]], [-ax[1], ax[0], 0]])
    a = np.radians(30.0)
    Q = np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K
    s, b, L0, E0 = spin(1e-3, 1000, inertia=Q @ np.diag(I_B) @ Q.T)
    assert abs(s.kinetic_energy() / E0 - 1.0) < 1e-12
    assert abs(np.linalg.norm(s.angular_momentum_world(b)) / np.linalg.norm(L0) - 1.0) < 1e-12


def test_midpoint_step_solves_the_implicit_equation():
    """ω₁ = ω₀ + h J⁻¹ (τ − ω_m × J ω_m) with ω_m = (ω₀ + ω₁)/2, to round-off, with a torque."""
    J = np.diag(I_B)
    w0, tb, h = np.array(W0), np.array([0.01, -0.02, 0.005]), 1e-2
    w1 = gyroscopic_midpoint(h, np.linalg.inv(J), J, tb, w0)
    wm = 0.5 * (w0 + w1)
    np.testing.assert_allclose(w1, w0 + h * np.linalg.solve(J, tb - np.cross(wm, J @ wm)), rtol=0, atol=1e-15)


def test_a_step_too_long_for_the_iteration_keeps_the_explicit_step():
    """h|ω| far above 1: the fixed-point iteration diverges; the explicit step is returned
    (finite), not the diverged iterate."""
    J = np.diag(I_B)
    w0, tb, h = np.array([100.0, 20.0, 300.0]), np.zeros(3), 1.0
    w1 = gyroscopic_midpoint(h, np.linalg.inv(J), J, tb, w0)
    np.testing.assert_allclose(w1, w0 - h * np.linalg.solve(J, np.cross(w0, J @ w0)), rtol=1e-15)

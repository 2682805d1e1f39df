"""Order of accuracy of the Verlet and Symplectic integrators.

The integrator kernels are driven with analytic rates instead of SPH forces:
particles in a harmonic potential a = -w^2 (x - x0) (exact solution
x0 + A cos(w t + phi)) and a density relaxing as d(rho)/dt = -k rho (exact
rho0 exp(-k t)).  Integrating one period with dt, dt/2, dt/4 gives the
observed order log2(e(dt)/e(dt/2)):

* Symplectic (predictor-corrector, rho^{n+1} = rho^n (2-eps)/(2+eps)): 2 for
  positions and densities;
* Verlet started from the exact state at -dt and no Euler step (VerletSteps
  larger than the run): 2;
* Verlet as DualSPHysics starts it (v^{-1} = v^0) with an Euler step every
  40 steps: the start and the Euler steps are locally first order, so only
  convergence with order >= 0.8 is asserted (about 2 is observed here: the
  Euler steps damp the start error mode).
"""
import math

import numpy as np

from sphdvi.sph import integrators as I
from sphdvi.sph.specialise import specialised

W = 2.0 * math.pi
K = 0.7
N = 5


def _setup():
    rng = np.random.default_rng(0)
    x0 = rng.uniform(-1, 1, (N, 3))
    amp = rng.uniform(0.1, 0.5, (N, 3))
    phi = rng.uniform(0, 2 * math.pi, (N, 3))
    r0 = rng.uniform(990, 1010, N)
    return x0, amp, phi, r0


def _exact(t, x0, amp, phi, r0):
    return (x0 + amp * np.cos(W * t + phi), -amp * W * np.sin(W * t + phi),
            r0 * np.exp(-K * t))


def _ip(dt):
    ip = np.zeros(17)
    ip[0] = dt
    ip[1] = 1000.0
    ip[2] = 0.0
    ip[3] = 1e9
    return ip


def run_symplectic(nsteps, T=1.0):
    x0, amp, phi, r0 = _setup()
    pos, vel, rho = _exact(0.0, x0, amp, phi, r0)
    pos, vel, rho = pos.copy(), vel.copy(), rho.copy()
    dt = T / nsteps
    ptype = np.full(N, 3, np.int8)
    pre = [np.zeros_like(pos), np.zeros_like(vel), np.zeros_like(rho)]
    ip = _ip(dt)
    out = np.zeros(N, np.int8)
    dummy2, dummy1 = np.zeros((1, 3)), np.zeros(1)
    corr = specialised(I.symplectic_corr_serial,
                       (0, pos, vel, rho, *pre, vel, rho, ptype, dummy2, dummy1, ip, out), (0,))
    for _ in range(nsteps):
        I.symplectic_pre_serial(pos, vel, rho, *pre, -W * W * (pos - x0), -K * rho, ptype, ip, out)
        corr(0, pos, vel, rho, *pre, -W * W * (pos - x0), -K * rho, ptype, dummy2, dummy1, ip, out)
    ex = _exact(T, x0, amp, phi, r0)
    return np.abs(pos - ex[0]).max(), np.abs(rho - ex[2]).max()


def run_verlet(nsteps, exact_start, verlet_steps, T=1.0):
    x0, amp, phi, r0 = _setup()
    dt = T / nsteps
    pos, vel, rho = [a.copy() for a in _exact(0.0, x0, amp, phi, r0)]
    if exact_start:
        _, vm1, rm1 = _exact(-dt, x0, amp, phi, r0)
    else:
        vm1, rm1 = vel.copy(), rho.copy()
    ptype = np.full(N, 3, np.int8)
    ip = _ip(dt)
    out = np.zeros(N, np.int8)
    dummy2, dummy1 = np.zeros((1, 3)), np.zeros(1)
    ace = np.zeros((N, 3))
    ar = np.zeros(N)
    step = specialised(I.verlet_serial, (0, False, pos, vel, rho, vm1, rm1, ace, ar, ptype,
                                         dummy2, dummy1, ip, out), (0,))
    count = 0
    for _ in range(nsteps):
        ace[:] = -W * W * (pos - x0)
        ar[:] = -K * rho
        count += 1                  # as the solver (DualSPHysics's ComputeVerlet)
        euler = count >= verlet_steps
        if euler:
            count = 0
        step(0, euler, pos, vel, rho, vm1, rm1, ace, ar, ptype, dummy2, dummy1, ip, out)
    ex = _exact(T, x0, amp, phi, r0)
    return np.abs(pos - ex[0]).max(), np.abs(rho - ex[2]).max()


def _orders(errs):
    return [math.log2(errs[k] / errs[k + 1]) for k in range(len(errs) - 1)]


def test_symplectic_second_order():
    res = [run_symplectic(n) for n in (100, 200, 400)]
    op = _orders([r[0] for r in res])
    orho = _orders([r[1] for r in res])
    print("Symplectic observed order: position", op, "density", orho)
    assert min(op) > 1.9 and min(orho) > 1.9


def test_verlet_second_order_with_exact_start():
    res = [run_verlet(n, True, 10 ** 9) for n in (100, 200, 400)]
    op = _orders([r[0] for r in res])
    orho = _orders([r[1] for r in res])
    print("Verlet (exact start, no Euler) observed order: position", op, "density", orho)
    assert min(op) > 1.9 and min(orho) > 1.9


def test_verlet_dualsphysics_start_converges():
    res = [run_verlet(n, False, 40) for n in (200, 400, 800)]
    op = _orders([r[0] for r in res])
    orho = _orders([r[1] for r in res])
    print("Verlet (DualSPHysics start, Euler every 40) observed order: position", op,
          "density", orho)
    assert min(op) > 0.8 and min(orho) > 0.8

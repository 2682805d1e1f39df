"""Per-body numba kernels of the time step."""
import math

import numpy as np
from numba import njit

from ._math import cross


@njit(cache=True)
def apply_dof_masks(inv_mass, inv_I_b, dof_mask, Rb):
    """Effective inverse mass (per world axis) and body-frame inverse inertia
    with locked DOFs (world axes): M⁻¹_ang = Rᵀ P R J⁻¹ Rᵀ P R, P = diag(mask)."""
    nb = inv_mass.shape[0]
    invm3 = np.empty((nb, 3))
    invI = np.empty((nb, 3, 3))
    for i in range(nb):
        for k in range(3):
            invm3[i, k] = inv_mass[i] * dof_mask[i, k]
        if dof_mask[i, 3] == 1.0 and dof_mask[i, 4] == 1.0 and dof_mask[i, 5] == 1.0:
            invI[i] = inv_I_b[i]
        else:
            R = Rb[i]
            P = np.diag(dof_mask[i, 3:].copy())
            A = R.T @ P @ R
            invI[i] = A @ inv_I_b[i] @ A
    return invm3, invI


# fixed-point iterations of the implicit midpoint gyroscopic term (each a few flops of a 3x3
# product; it converges to round-off in 3-6 at h|ω| <= 0.1, the cap guards a huge h|ω|)
GYRO_MAX_ITER = 30


@njit(cache=True)
def free_velocity(h, kind, invm3, invI, I_b, Rb, vel6, F, T):
    """v_free = v + h M⁻¹ f with f = [F_world; Rᵀ T_world − ω_m × (J ω_m)], the gyroscopic
    term at the midpoint ω_m = (ω + ω_free)/2 (implicit midpoint rule of Euler's equations in
    the body frame, solved by fixed-point iteration): a torque-free body keeps its kinetic
    energy ½ωᵀJω and |L| = |Jω| to round-off (the explicit ω × (J ω), Chrono's ChBody form,
    made both grow at first order in h; DualSPHysics's own FtCalcForces has no gyroscopic
    term).  :func:`gyroscopic_midpoint`."""
    nb = kind.shape[0]
    out = vel6.copy()
    for i in range(nb):
        if kind[i] != 0:
            continue
        for k in range(3):
            out[i, k] += h * invm3[i, k] * F[i, k]
        R = Rb[i]
        tb = np.empty(3)
        for k in range(3):
            tb[k] = R[0, k] * T[i, 0] + R[1, k] * T[i, 1] + R[2, k] * T[i, 2]      # Rᵀ T
        w1 = gyroscopic_midpoint(h, invI[i], I_b[i], tb, vel6[i, 3:])
        for k in range(3):
            out[i, 3 + k] = w1[k]
    return out


@njit(cache=True)
def gyroscopic_midpoint(h, invI, J, tb, w0):
    """ω₁ = ω₀ + h J⁻¹ (τ_b − ω_m × (J ω_m)), ω_m = (ω₀ + ω₁)/2, by fixed-point iteration from
    the explicit step; when the iteration does not contract (h|ω| of order 1) the explicit
    step is kept."""
    x0, y0, z0 = w0[0], w0[1], w0[2]
    ex, ey, ez = _gyro_step(h, invI, J, tb, x0, y0, z0, x0, y0, z0)
    x1, y1, z1 = ex, ey, ez
    scale = max(1e-300, math.sqrt(x0 * x0 + y0 * y0 + z0 * z0) + math.sqrt(x1 * x1 + y1 * y1 + z1 * z1))
    prev = math.inf
    for _ in range(GYRO_MAX_ITER):
        xn, yn, zn = _gyro_step(h, invI, J, tb, x0, y0, z0, 0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1))
        step = math.sqrt((xn - x1) ** 2 + (yn - y1) ** 2 + (zn - z1) ** 2)
        if not step < prev and step > 1e-10 * scale:     # diverging: keep the explicit step
            x1, y1, z1 = ex, ey, ez
            break
        x1, y1, z1 = xn, yn, zn
        if step <= 4e-16 * scale or not step < prev:     # converged (or stalled at round-off)
            break
        prev = step
    out = np.empty(3)
    out[0], out[1], out[2] = x1, y1, z1
    return out


@njit(cache=True, inline="always")
def _gyro_step(h, invI, J, tb, x0, y0, z0, xm, ym, zm):
    """ω₀ + h J⁻¹ (τ_b − ω_m × (J ω_m)), in scalars (no temporary arrays)."""
    lx = J[0, 0] * xm + J[0, 1] * ym + J[0, 2] * zm
    ly = J[1, 0] * xm + J[1, 1] * ym + J[1, 2] * zm
    lz = J[2, 0] * xm + J[2, 1] * ym + J[2, 2] * zm
    rx = tb[0] - (ym * lz - zm * ly)
    ry = tb[1] - (zm * lx - xm * lz)
    rz = tb[2] - (xm * ly - ym * lx)
    return (x0 + h * (invI[0, 0] * rx + invI[0, 1] * ry + invI[0, 2] * rz),
            y0 + h * (invI[1, 0] * rx + invI[1, 1] * ry + invI[1, 2] * rz),
            z0 + h * (invI[2, 0] * rx + invI[2, 1] * ry + invI[2, 2] * rz))


@njit(cache=True)
def link_point_torques(lf, ltc, P1w, b1, pos):
    """Torque about the link point P1 from the torque about body 1's centre."""
    out = np.empty_like(ltc)
    for l in range(lf.shape[0]):
        x = np.zeros(3)
        if b1[l] >= 0:
            x = pos[b1[l]].copy()
        r = P1w[l] - x
        out[l] = ltc[l] - cross(r, lf[l])
    return out

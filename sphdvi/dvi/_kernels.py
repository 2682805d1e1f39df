"""Per-body numba kernels of the time step."""
import math

import numpy as np
from numba import njit

from ._math import cross, integrate_bodies
from .solvers import prepare_rows


@njit(cache=True)
def apply_dof_masks(inv_mass, inv_I_b, dof_mask, Rb):
    """Effective inverse mass (per world axis) and body-frame inverse inertia
    with locked DOFs (world axes): M⁻¹_ang = Rᵀ P R J⁻¹ Rᵀ P R, P = diag(mask)."""
    nb = inv_mass.shape[0]
    invm3 = np.empty((nb, 3))
    invI = np.empty((nb, 3, 3))
    dof_masks_into(inv_mass, inv_I_b, dof_mask, Rb, invm3, invI)
    return invm3, invI


@njit(cache=True)
def dof_masks_into(inv_mass, inv_I_b, dof_mask, Rb, invm3, invI):
    """:func:`apply_dof_masks` into the arrays ``invm3`` (nb, 3) and ``invI`` (nb, 3, 3)."""
    for i in range(inv_mass.shape[0]):
        for k in range(3):
            invm3[i, k] = inv_mass[i] * dof_mask[i, k]
        if dof_mask[i, 3] == 1.0 and dof_mask[i, 4] == 1.0 and dof_mask[i, 5] == 1.0:
            invI[i] = inv_I_b[i]
        else:
            R = Rb[i]
            P = np.diag(dof_mask[i, 3:].copy())
            A = R.T @ P @ R
            invI[i] = A @ inv_I_b[i] @ A


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
    out = vel6.copy()
    free_velocity_into(h, kind, invm3, invI, I_b, Rb, vel6, F, T, out)
    return out


@njit(cache=True)
def free_velocity_into(h, kind, invm3, invI, I_b, Rb, vel6, F, T, out):
    """:func:`free_velocity` into ``out`` (nb, 6), which must not be ``vel6``."""
    nb = kind.shape[0]
    tb = np.empty(3)
    for i in range(nb):
        for k in range(6):
            out[i, k] = vel6[i, k]
        if kind[i] != 0:
            continue
        for k in range(3):
            out[i, k] += h * invm3[i, k] * F[i, k]
        R = Rb[i]
        for k in range(3):
            tb[k] = R[0, k] * T[i, 0] + R[1, k] * T[i, 1] + R[2, k] * T[i, 2]      # Rᵀ T
        w1 = gyroscopic_midpoint(h, invI[i], I_b[i], tb, vel6[i, 3:])
        for k in range(3):
            out[i, 3 + k] = w1[k]


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


@njit(cache=True)
def step_start(quat, f_ext, t_ext, forces, torques, mass, gravity, kind, R, F, T):
    """Start of System.step into kept arrays: each body's rotation R(q) (as
    :func:`sphdvi.dvi._math.body_rotations`) and its applied loads F = f_ext + forces + m g
    (floating bodies only: ``kind`` 0), T = t_ext + torques (world; ``forces``/``torques`` with
    no rows: none this step)."""
    nb = quat.shape[0]
    has_f = forces.shape[0] == nb
    has_t = torques.shape[0] == nb
    for i in range(nb):
        w, x, y, z = quat[i, 0], quat[i, 1], quat[i, 2], quat[i, 3]
        R[i, 0, 0] = 1.0 - 2.0 * (y * y + z * z)
        R[i, 0, 1] = 2.0 * (x * y - w * z)
        R[i, 0, 2] = 2.0 * (x * z + w * y)
        R[i, 1, 0] = 2.0 * (x * y + w * z)
        R[i, 1, 1] = 1.0 - 2.0 * (x * x + z * z)
        R[i, 1, 2] = 2.0 * (y * z - w * x)
        R[i, 2, 0] = 2.0 * (x * z - w * y)
        R[i, 2, 1] = 2.0 * (y * z + w * x)
        R[i, 2, 2] = 1.0 - 2.0 * (x * x + y * y)
        fl = 1.0 if kind[i] == 0 else 0.0
        for k in range(3):
            f = f_ext[i, k] + forces[i, k] if has_f else f_ext[i, k]
            F[i, k] = f + mass[i] * gravity[k] * fl
            T[i, k] = t_ext[i, k] + torques[i, k] if has_t else t_ext[i, k]


@njit(cache=True)
def step_free(h, kind, inv_mass, inv_I_b, dof_mask, R, I_b, vel, omega_b, F, T, invm3, invI,
              vel6, vfree):
    """The bodies' part of System.step before the rows, into kept arrays: the DOF-masked
    inverse masses (:func:`apply_dof_masks`), the velocities ``vel6`` = (v, ω_body) and the
    free velocities (:func:`free_velocity`)."""
    dof_masks_into(inv_mass, inv_I_b, dof_mask, R, invm3, invI)
    for i in range(kind.shape[0]):
        for k in range(3):
            vel6[i, k] = vel[i, k]
            vel6[i, 3 + k] = omega_b[i, k]
    free_velocity_into(h, kind, invm3, invI, I_b, R, vel6, F, T, vfree)


@njit(cache=True)
def step_end(h, cf, ct, smc_f, smc_t, aF, aT, bf, bt, contact_force, contact_torque,
             total_force, total_torque, lf, ltc, P1w, b1, link_torque, vout, pos, quat, vel,
             omega_b, kind):
    """End of System.step into kept arrays: the contact loads (rows + SMC), the total loads
    (applied + rows), each link's torque about its point on body 1
    (:func:`link_point_torques`, at the pose before the move), then v⁺ and the move
    (:func:`sphdvi.dvi._math.integrate_bodies`).  ``bf``/``bt`` (the rows' loads, which
    :func:`rows.accumulate_row_forces` adds to) are left zeroed for the next step."""
    for i in range(pos.shape[0]):
        for k in range(3):
            contact_force[i, k] = cf[i, k] + smc_f[i, k]
            contact_torque[i, k] = ct[i, k] + smc_t[i, k]
            total_force[i, k] = aF[i, k] + bf[i, k]
            total_torque[i, k] = aT[i, k] + bt[i, k]
            bf[i, k] = 0.0
            bt[i, k] = 0.0
    for l in range(lf.shape[0]):
        x0 = x1 = x2 = 0.0
        if b1[l] >= 0:
            x0, x1, x2 = pos[b1[l], 0], pos[b1[l], 1], pos[b1[l], 2]
        r0 = P1w[l, 0] - x0
        r1 = P1w[l, 1] - x1
        r2 = P1w[l, 2] - x2
        link_torque[l, 0] = ltc[l, 0] - (r1 * lf[l, 2] - r2 * lf[l, 1])
        link_torque[l, 1] = ltc[l, 1] - (r2 * lf[l, 0] - r0 * lf[l, 2])
        link_torque[l, 2] = ltc[l, 2] - (r0 * lf[l, 1] - r1 * lf[l, 0])
    for i in range(pos.shape[0]):
        for k in range(3):
            vel[i, k] = vout[i, k]
            omega_b[i, k] = vout[i, 3 + k]
    integrate_bodies(pos, quat, vel, omega_b, kind, h)


@njit(cache=True)
def prepare_live_rows(nr, ra, rb, J, E, kind, invm3, invI, MiJ, gdiag, bias, g):
    """:func:`sphdvi.dvi.solvers.prepare_rows`, then the rows that cannot act (no dynamic
    body: Jacobi diagonal 1e300) get no bias and no warm start."""
    prepare_rows(nr, ra, rb, J, E, kind, invm3, invI, MiJ, gdiag)
    clear_dead_rows(nr, gdiag, bias, g)


@njit(cache=True)
def clear_dead_rows(nr, r_g, r_bias, g):
    """Rows that cannot act (no dynamic body: Jacobi diagonal 1e300, :func:`prepare_rows`) get
    no bias and no warm start."""
    for k in range(nr):
        if r_g[k] >= 1e300:
            r_bias[k] = 0.0
            g[k] = 0.0


@njit(cache=True)
def copy_state(pos, quat, vel, omega_b, pos2, quat2, vel2, omega_b2):
    """Copy the bodies' poses and velocities into arrays of the same shapes
    (System.get_state/set_state into kept arrays)."""
    for i in range(pos.shape[0]):
        for k in range(3):
            pos2[i, k] = pos[i, k]
            vel2[i, k] = vel[i, k]
            omega_b2[i, k] = omega_b[i, k]
        for k in range(4):
            quat2[i, k] = quat[i, k]


@njit(cache=True)
def scatter_warm(g, c_row, c_mu, g3):
    """Warm start of the contact rows: each contact's (normal, tangent, tangent) impulses from
    ``g3`` into ``g`` at its first row ``c_row`` (the tangents only with friction, ``c_mu`` > 0)."""
    for i in range(c_row.shape[0]):
        r = c_row[i]
        g[r] = g3[i, 0]
        if c_mu[i] > 0:
            g[r + 1] = g3[i, 1]
            g[r + 2] = g3[i, 2]


@njit(cache=True)
def gather_warm(g, c_row, c_mu, g3):
    """The contacts' impulses of the step (the next warm start): the reverse of
    :func:`scatter_warm` into ``g3`` (zero tangents without friction)."""
    for i in range(c_row.shape[0]):
        r = c_row[i]
        g3[i, 0] = g[r]
        if c_mu[i] > 0:
            g3[i, 1] = g[r + 1]
            g3[i, 2] = g[r + 2]
        else:
            g3[i, 1] = 0.0
            g3[i, 2] = 0.0

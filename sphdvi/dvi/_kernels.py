"""Per-body numba kernels of the time step."""
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


@njit(cache=True)
def free_velocity(h, kind, invm3, invI, I_b, Rb, vel6, F, T):
    """v_free = v + h M⁻¹ f with f = [F_world; Rᵀ T_world − ω × (J ω)]
    (explicit gyroscopic term, Chrono's ChBody convention)."""
    nb = kind.shape[0]
    out = vel6.copy()
    for i in range(nb):
        if kind[i] != 0:
            continue
        for k in range(3):
            out[i, k] += h * invm3[i, k] * F[i, k]
        w = vel6[i, 3:].copy()
        tb = Rb[i].T @ T[i] - cross(w, I_b[i] @ w)
        dw = invI[i] @ tb
        for k in range(3):
            out[i, 3 + k] += h * dw[k]
    return out


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

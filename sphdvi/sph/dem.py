"""DualSPHysics's DEM contacts between rigid bodies (``RigidAlgorithm`` 2, "DCDEM": Canelas et al.
2016, Comput. Phys. Commun. 202; JSphCpu::InteractionForcesDEM): a particle-level soft contact
between the particles of a floating body and those of another body or of a wall.

Each particle is a sphere of diameter Dp. For a floating particle i and a non-fluid particle j of
another mk block, with r = |x_i − x_j|, n = (x_i − x_j)/r, v = v_i − v_j, v_n = v·n and the
overlap δ = Dp − r:

    k_n = 4 / (3 (τ_i + τ_j)) √(Dp/4),   τ = (1 − ν²)/E                    Hertz stiffness
    m*  = M_i/2 against a wall, M_i M_j/(M_i + M_j) between bodies (M the bodies' masses)
    g_n = −2 ln ē √(m* k_n) / √(π + ln² ē),   ē = (e_i + e_j)/2               damping
    f_n = k_n δ^1.5 − g_n δ^0.25 v_n                                         normal force (δ > 0)
    f_t = min(μ̄ f_n tanh(8 v_t), (k_n Δt − g_n) v_t / 3.5, 0),  μ̄ = (μ_i + μ_j)/2
          along t = v_t/|v_t|, v_t = v − v_n n                              tangential force

and the particle's acceleration gains (f_n n + f_t t)/m_i (its mass), so that the body's load, the
sum of m_i a_i, is the sum of the contact forces. Δt (DualSPHysics's DemDtForce) is the previous
step's dt under Verlet, dt/2 in the Symplectic predictor and dt in its corrector. The time step sees
8/t_c, t_c = 3.21 (m*/k_n)^0.4 |v_n|^−0.2 (Hertz's contact duration), the largest over the pairs
within 2h of a particle in contact, as a viscous term (DualSPHysics's viscdt).

Deviation: DualSPHysics takes f_t = min(μ̄ f_n tanh(8 v_t), (k_n Δt − g_n) v_t/3.5), which pushes a
sliding particle further along where k_n Δt > g_n (light, stiff, nearly elastic bodies or a long
step); sphdvi caps it at 0, so a tangential force never drives sliding. Where it opposes sliding
(k_n Δt < g_n, every pair of DualSPHysics's examples) the two agree: there it is a viscous force,
and Kfric has no effect.
"""
from __future__ import annotations

import math

import numpy as np

from ._env import CHUNK
from numba import njit, prange

from .cells import stencil_bounds
from .interaction import _dt_maxima


class DemTable:
    """The DEM material of every mk block: ``mat_of_mk[mk]`` its row (−1: fluid, or no block), and
    per row τ = (1 − ν²)/E, the restitution coefficient, Kfric and the body's mass (0 for a wall)."""

    def __init__(self, mat_of_mk, tau, restitution, kfric, body_mass, names=()):
        self.mat_of_mk = np.ascontiguousarray(mat_of_mk, dtype=np.int64)
        self.tau = np.ascontiguousarray(tau, dtype=np.float64)
        self.restitution = np.ascontiguousarray(restitution, dtype=np.float64)
        self.kfric = np.ascontiguousarray(kfric, dtype=np.float64)
        self.body_mass = np.ascontiguousarray(body_mass, dtype=np.float64)
        self.names = tuple(names)


@njit(cache=True, error_model="numpy")
def _dem_range(i0, i1, is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, rs, r2max, mk, mat_of_mk,
               tau, rest, kfric, bmass, dp, dtforce, ace, viscdt):
    """The DEM contacts of the floating rows i0..i1 (module docstring) into their particles' ``ace``
    and ``viscdt`` (rows ``oi``); ``mk``: each packed row's mk (its real particle's for a periodic
    copy), gathered in row order."""
    kn_geo = math.sqrt(dp / 4.0) * 4.0 / 3.0
    for i in range(i0, i1):
        o = oi[i]
        if o < 0 or ptype[i] != 2:
            continue
        mki = mk[i]
        mi = mat_of_mk[mki]
        if is2d:
            xi, yi, zi = nb[i, 0], 0.0, nb[i, 1]
            vxi, vyi, vzi = nb[i, 2], 0.0, nb[i, 3]
            mpi = nb[i, 6]
        else:
            xi, yi, zi = nb[i, 0], nb[i, 1], nb[i, 2]
            vxi, vyi, vzi = nb[i, 3], nb[i, 4], nb[i, 5]
            mpi = nb[i, 8]
        xlo, xhi, ylo, yhi, zlo, zhi = stencil_bounds(cell[i], ncx, ncy, ncz, rs, is2d)
        ax = 0.0
        ay = 0.0
        az = 0.0
        demdt = 0.0
        for z in range(zlo, zhi + 1):
            for y in range(ylo, yhi + 1):
                row = (z * ncy + y) * ncx if not is2d else z * ncx
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    ptj = ptype[j]
                    if ptj == 3:
                        continue
                    mkj = mk[j]
                    if mkj == mki:
                        continue            # the same body (or block)
                    if is2d:
                        dx, dy, dz = xi - nb[j, 0], 0.0, zi - nb[j, 1]
                        dvx, dvy, dvz = vxi - nb[j, 2], 0.0, vzi - nb[j, 3]
                    else:
                        dx, dy, dz = xi - nb[j, 0], yi - nb[j, 1], zi - nb[j, 2]
                        dvx, dvy, dvz = vxi - nb[j, 3], vyi - nb[j, 4], vzi - nb[j, 5]
                    r2 = dx * dx + dy * dy + dz * dz
                    if r2 > r2max or r2 < 1e-18:
                        continue
                    mj = mat_of_mk[mkj]
                    r = math.sqrt(r2)
                    nx, ny, nz = dx / r, dy / r, dz / r
                    vn = dvx * nx + dvy * ny + dvz * nz
                    if ptj < 2:
                        mstar = 0.5 * bmass[mi]
                    else:
                        mstar = bmass[mi] * bmass[mj] / (bmass[mi] + bmass[mj])
                    kn = kn_geo / (tau[mi] + tau[mj])
                    if vn != 0.0:
                        tc = 3.21 * (mstar / kn) ** 0.4 * abs(vn) ** -0.2
                        v = 8.0 / tc
                        if v > demdt:
                            demdt = v
                    over = dp - r
                    if over <= 0.0:
                        continue
                    e = 0.5 * (rest[mi] + rest[mj])
                    mu = 0.5 * (kfric[mi] + kfric[mj])
                    le = math.log(e)
                    gn = -2.0 * le * math.sqrt(mstar * kn) / math.sqrt(math.pi + le * le)
                    fn = kn * over ** 1.5 - gn * over ** 0.25 * vn
                    ax += fn * nx / mpi
                    ay += fn * ny / mpi
                    az += fn * nz / mpi
                    tx, ty, tz = dvx - vn * nx, dvy - vn * ny, dvz - vn * nz
                    vt = math.sqrt(tx * tx + ty * ty + tz * tz)
                    if vt > 0.0:
                        ft = min(mu * fn * math.tanh(8.0 * vt), (kn * dtforce - gn) * vt / 3.5, 0.0)
                        ax += ft * tx / vt / mpi
                        ay += ft * ty / vt / mpi
                        az += ft * tz / vt / mpi
        if ax != 0.0 or ay != 0.0 or az != 0.0:
            ace[o, 0] += ax
            if not is2d:
                ace[o, 1] += ay
            ace[o, 2] += az
            if demdt > viscdt[o]:
                viscdt[o] = demdt


@njit(cache=True, error_model="numpy")
def dem_serial(is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, rs, r2max, mk, mat_of_mk, tau, rest,
               kfric, bmass, dp, dtforce, ace, viscdt, vel_type, dtmax, cst):
    """The DEM contacts of every floating row, then each chunk's time-step maxima again (the
    contacts change the floating particles' ace and viscdt: DualSPHysics's AceMax and ViscDtMax
    see them)."""
    n = nb.shape[0]
    for c in range((n + CHUNK - 1) // CHUNK):
        i0 = c * CHUNK
        i1 = min(n, i0 + CHUNK)
        _dem_range(i0, i1, is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, rs, r2max, mk, mat_of_mk,
                   tau, rest, kfric, bmass, dp, dtforce, ace, viscdt)
        _dt_maxima(i0, i1, is2d, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst)


@njit(cache=True, parallel=True, error_model="numpy")
def dem_parallel(is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, rs, r2max, mk, mat_of_mk, tau, rest,
                 kfric, bmass, dp, dtforce, ace, viscdt, vel_type, dtmax, cst):
    """:func:`dem_serial` over chunks of rows in threads (each row writes its own particle)."""
    n = nb.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        i0 = c * CHUNK
        i1 = min(n, i0 + CHUNK)
        _dem_range(i0, i1, is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, rs, r2max, mk, mat_of_mk,
                   tau, rest, kfric, bmass, dp, dtforce, ace, viscdt)
        _dt_maxima(i0, i1, is2d, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst)

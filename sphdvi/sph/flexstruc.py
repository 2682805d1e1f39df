r"""Flexible structures (DualSPHysics v5.4's ``<special><flexstrucs>``; O'Connor & Rogers 2021,
"A fluid-structure interaction model for free-surface flows and flexible structures using smoothed
particle hydrodynamics on a GPU", J. Fluids Struct. 104, 103312): a total Lagrangian SPH solid.

The particles of a flexible body (a moving mk block) are integrated by this solid; the boundary
particles of its clamp mks within 2h of it (``mkclamp``) hold it with their own (fixed or imposed)
motion. Every quantity refers to the reference configuration X, the positions at t = 0; V = dp^d
is a particle's volume, m_s = ρ_s V its mass, W and ∇_iW(X_ij) = (dW/dr)/r (X_i − X_j) the
kernel of the fluid (its h), the pairs those of one body (its flexible and clamp particles) with
0 < |X_ij| ≤ 2h, fixed for the run:

    L_i  = [Σ_j V (X_j − X_i) ⊗ ∇_iW(X_ij)]⁻¹                      kernel correction (in 2D the
                                                                  y row and column are the identity)
    F_i  = Σ_j V (x_j − x_i) ⊗ ∇_iW(X_ij) · L_i                     deformation gradient (F = I at t = 0)
    E_i  = (F_iᵀF_i − I)/2,   S_i = C : E_i,   P_i = F_i S_i        Green–Lagrange strain, 2nd and 1st
                                                                  Piola–Kirchhoff stresses
    a_i  = (V/ρ_s) Σ_j (P_i L_i + P_j L_j) ∇_iW(X_ij)              elastic acceleration (flexible
                                                                  particles; clamp particles are held)

C in Voigt form with engineering shear strains: plane strain (constitmodel 1) and St Venant–
Kirchhoff (3) S_xx = (λ + 2μ) E_xx + λ (E_yy + E_zz), S_xz = 2μ E_xz, ...; plane stress (2)
S_xx = E/(1 − ν²) (E_xx + ν E_zz), S_xz = E/(1 + ν) E_xz. In 2D (the x–z plane) S_yy is not formed.

Hourglass control (Ganzenmüller 2015, ``hgfactor`` α): with r_ij = x_i − x_j, r = |r_ij|,
R_ij = X_i − X_j, δ_ij = (r_ij − F_i R_ij)·r_ij/r and δ_ji = (r_ij − F_j R_ij)·r_ij/r,

    a_i −= α V E W(|R_ij|) / (ρ_s |R_ij|² r) (δ_ij + δ_ji)/2 r_ij.

The fluid acts on a flexible particle i through its fluid neighbours j as on a wall, with the
reaction of the fluid's own terms (the flexible particle is a moving boundary particle to the fluid:
mass m_b = ρ0 dp^d, pressure from its density by the fluid's EOS; under DBC the density comes from the
boundary continuity, under mDBC from the ghost node, below):

    a_i += (m_b/m_s) Σ_j m_j [−(p_i + p_j)/(ρ_i ρ_j) + Π_ij] ∇_iW(r_ij)        (ViscoTreatment 1)
    a_i += (m_b/m_s) Σ_j m_j 4 ν_b r_ij·∇_iW(r_ij) / ((r² + η²)(ρ_i + ρ_j)) v_ij    (2, 3; no SPS)

with Π_ij Monaghan's term with Visco × ViscoBoundFactor (and the cubic kernel's tensile term), so
that the pair's forces are equal and opposite. Gravity is added in the update: Verlet's step is a
semi-implicit Euler one, v += (a + g) dt, x += v dt; the Symplectic predictor x = x⁰ + v⁰ dt/2,
v = v⁰ + (a + g) dt/2, the corrector v = v⁰ + (a + g) dt, x = x⁰ + (v⁰ + v) dt/2. The time step
gains dt_3 = h / max_i c_i, c_i = c_s √(det F_i) (the P-wave speed √(E(1 − ν)/(ρ(1 + ν)(1 − 2ν)))
at the current density ρ_s/det F_i), and the flexible particles' |a| enter the force condition.

With mDBC (Boundary 2; DualSPHysics v5.4 allows its mDBC2 only, SlipMode 2 or 3 with Symplectic,
and refuses SlipMode 1 and Verlet, as sphdvi does) the structure's particles are mDBC walls whose
normals, ghost density and wall acceleration follow the solid:

* F is found before the mDBC correction of each evaluation (:meth:`FlexStruc.geometry`, at the
  positions of that evaluation: the predictor's and the corrector's in a Symplectic step, as
  DualSPHysics's UpdateFlexStrucGeometry after each cell divide), the forces after the fluid's
  interaction (:meth:`FlexStruc.forces`, from that F).
* Normals: every flexible or clamp particle with a normal n0 at t = 0 (the case's, as any wall's)
  takes n = |n0| F⁻ᵀn0 / |F⁻ᵀn0| (CalcFlexStrucNormals; :func:`turn_normals`), exactly R n0 under a
  rotation R and normal to a stretched face; it overwrites the normals a moving clamp's motion turned.
  A particle whose F is singular keeps its last normal (DualSPHysics would take inf/NaN).
* Density: the flexible particles (not the clamps, which are ordinary walls there) take the Shepard
  density at the ghost node, never the first-order one (InteractionMdbc2CorrectionT2's
  !CODE_IsFlexStrucFlex test; :func:`FlexStruc.flex_of_idp` marks them by id for
  :mod:`sphdvi.sph.mdbc`), before the pressure cloning; their ghost velocity is then the Shepard
  average too (sphdvi's corrected ghost velocity, MdbcGhostVelocity 1, goes with a corrected density).
* Wall acceleration of the pressure cloning: (v^{n+1} − v^n)/dt of the particle's own update
  (:func:`keep_velocity` before it, :func:`structure_wall_ace` at the end of the step), as
  DualSPHysics's CopyMotionVelAce runs over them with the moving walls.
* The fluid's force on the structure takes mDBC's packed density, pressure and mass (zero for a
  particle switched off, whose ghost node is dry: no force, as the fluid feels none from it) and, in
  the viscous term, the particle's tangential velocity ``tvel`` as the fluid sees it (DualSPHysics's
  TangenVel), so the pair forces stay equal and opposite.

The wall acceleration enters the pressure the structure feels: a particle accelerating towards the
water sees a higher pressure, a force proportional to the acceleration of the step before (an
added mass ρ0 2|N| per unit area, explicit). Measured here: a light plate (ρ_s/ρ0 = 0.5, 3 particles
thick, dp 0.01 m) hit by a dam break diverges at the impact, and runs to the end without the
structure's wall acceleration; at ρ_s/ρ0 = 1 and 1.2 it runs; normals that reach deep into the
structure (|N| up to 2.5 dp, the automatic normals of a plate that faces the water with all its
columns) made it diverge at 1.2 and 3 as well. DualSPHysics computes the same term.

Deviations from DualSPHysics v5.4 (documented in the README): the pairs are those of one body
(DualSPHysics pairs every flexible-structure particle within 2h whatever its body, gluing bodies
that start within 2h, and takes the neighbour's stress with the particle's own material); the
hourglass kernel is W at the reference distance (Ganzenmüller's form; DualSPHysics takes W at the
current distance with no cut-off); a particle whose correction matrix cannot be inverted (too few
neighbours) is refused at the start instead of running with inf/NaN.
"""
from __future__ import annotations

import math

import numpy as np

from ._env import CHUNK
from numba import njit, prange

from .cells import stencil_bounds
from .interaction import _tensile
from .kernels import kernel_alpha, kernel_fac, kernel_w

MODEL_NAMES = {1: "Plane Strain", 2: "Plane Stress", 3: "St. Venant Kirchhoff"}
#: below this many structure particles its passes run serially whatever the solver's choice (measured,
#: tools/bench_flexstruc.py, 2 threads: 146 particles took twice as long threaded, 1,383 as long, 5,317 1/1.4)
PARALLEL_MIN = 4000
#: DualSPHysics's reason codes of a failed update (sphdvi's wording)
FAIL_REASONS = {1: "has a non-finite position or velocity", 2: "left the simulation domain"}


def constitutive_coefficients(model: int, youngmod: float, poissratio: float) -> tuple:
    """(diagonal, off-diagonal, shear) entries of the Voigt matrix C of a constitutive model
    (DualSPHysics's JSphFlexStrucBody): plane strain and St Venant–Kirchhoff λ + 2μ, λ, μ;
    plane stress E/(1 − ν²), νE/(1 − ν²), E/(2(1 + ν))."""
    e, nu = float(youngmod), float(poissratio)
    if model in (1, 3):
        k = e / ((1.0 + nu) * (1.0 - 2.0 * nu))
        return k * (1.0 - nu), k * nu, k * (1.0 - 2.0 * nu) / 2.0
    if model == 2:
        k = e / (1.0 - nu * nu)
        return k, k * nu, k * (1.0 - nu) / 2.0
    raise ValueError(f"constitutive model must be 1, 2 or 3, got {model!r}")


def sound_speed(youngmod: float, poissratio: float, density: float) -> float:
    """The structure's P-wave speed √(E(1 − ν)/(ρ(1 + ν)(1 − 2ν))) (DualSPHysics's GetSoundSpeed,
    for every model)."""
    e, nu = float(youngmod), float(poissratio)
    return math.sqrt(e * (1.0 - nu) / (float(density) * (1.0 + nu) * (1.0 - 2.0 * nu)))


# ------------------------------------------------------------------------------------ set-up
@njit(cache=True, error_model="numpy")
def _clamps_near(cand_pos, flex_pos, r2max):
    """Whether each candidate lies within 2h (r² ≤ r2max, r² ≥ 1e-18) of a flexible particle."""
    out = np.zeros(cand_pos.shape[0], np.bool_)
    for c in range(cand_pos.shape[0]):
        for f in range(flex_pos.shape[0]):
            d2 = 0.0
            for m in range(3):
                d = cand_pos[c, m] - flex_pos[f, m]
                d2 += d * d
            if d2 <= r2max and d2 >= 1e-18:
                out[c] = True
                break
    return out


@njit(cache=True, error_model="numpy")
def _reference_pairs(X, group, r2max, count_only, pstart, pj):
    """The pairs of each particle with the others of its group (body) within 2h, in index order:
    counts into pstart[k + 1] (count_only), else the neighbours into pj from pstart."""
    K = X.shape[0]
    for i in range(K):
        p = pstart[i]
        c = 0
        for j in range(K):
            if j == i or group[j] != group[i]:
                continue
            d2 = 0.0
            for m in range(3):
                d = X[i, m] - X[j, m]
                d2 += d * d
            if d2 <= r2max and d2 >= 1e-18:
                if not count_only:
                    pj[p + c] = j
                c += 1
        if count_only:
            pstart[i + 1] = c


@njit(cache=True, error_model="numpy")
def _reference_gradients(X, pstart, pj, kern, inv_h, alpha, alpha_h2, g0, rref, wref):
    """∇_iW(X_ij), X_ij and W(|X_ij|) of every pair."""
    for i in range(X.shape[0]):
        for p in range(pstart[i], pstart[i + 1]):
            j = pj[p]
            r2 = 0.0
            for m in range(3):
                d = X[i, m] - X[j, m]
                rref[p, m] = d
                r2 += d * d
            q = math.sqrt(r2) * inv_h
            fac = kernel_fac(kern, q, alpha_h2)
            for m in range(3):
                g0[p, m] = fac * rref[p, m]
            wref[p] = kernel_w(kern, q, alpha)


@njit(cache=True, error_model="numpy")
def _correction_matrices(X, pstart, pj, g0, vol, is2d, L, det):
    """M_i = Σ_j V (X_j − X_i) ⊗ ∇_iW(X_ij) (2D: the y row and column of the identity) and its
    inverse L_i; det[i] = det M_i (0 where it has no pair)."""
    for i in range(X.shape[0]):
        m = np.zeros((3, 3))
        for p in range(pstart[i], pstart[i + 1]):
            j = pj[p]
            for a in range(3):
                da = vol * (X[j, a] - X[i, a])
                for b in range(3):
                    m[a, b] += da * g0[p, b]
        if is2d:
            m[0, 1] = m[1, 0] = m[1, 2] = m[2, 1] = 0.0
            m[1, 1] = 1.0
        d = np.linalg.det(m)
        det[i] = d
        if d != 0.0 and np.isfinite(d):
            L[i] = np.linalg.inv(m)


# ------------------------------------------------------------------------------- each step
@njit(cache=True, error_model="numpy")
def locate_rows(idp, slot, rows):
    """rows[k] = the row (in ``idp``'s order) of flexible-structure particle k (slot[idp] = k)."""
    ns = slot.shape[0]
    for r in range(idp.shape[0]):
        i = idp[r]
        if i < ns:
            k = slot[i]
            if k >= 0:
                rows[k] = r


@njit(cache=True, error_model="numpy")
def rows_current(idp, kidp, rows):
    """Whether rows[k] still holds particle kidp[k] for every k (no sort or removal since)."""
    n = idp.shape[0]
    for k in range(rows.shape[0]):
        r = rows[k]
        if r < 0 or r >= n or idp[r] != kidp[k]:
            return False
    return True


@njit(cache=True, error_model="numpy")
def _geometry_range(k0, k1, is2d, pos, rows, pstart, pj, g0, L, vol, body, cdiag, coff, cshear, F, PL, J):
    """F, P L and det F of particles k0..k1 (module docstring) from the current positions."""
    fh = np.empty((3, 3))
    S = np.empty((3, 3))
    for i in range(k0, k1):
        ri = rows[i]
        x0, x1, x2 = pos[ri, 0], pos[ri, 1], pos[ri, 2]
        f00 = f01 = f02 = f10 = f11 = f12 = f20 = f21 = f22 = 0.0
        if is2d:            # the x-z plane: F_yy = 1, no y coupling
            for p in range(pstart[i], pstart[i + 1]):
                rj = rows[pj[p]]
                dx = vol * (pos[rj, 0] - x0)
                dz = vol * (pos[rj, 2] - x2)
                gx = g0[p, 0]
                gz = g0[p, 2]
                f00 += dx * gx
                f02 += dx * gz
                f20 += dz * gx
                f22 += dz * gz
            f11 = 1.0
        else:
            for p in range(pstart[i], pstart[i + 1]):
                rj = rows[pj[p]]
                dx = vol * (pos[rj, 0] - x0)
                dy = vol * (pos[rj, 1] - x1)
                dz = vol * (pos[rj, 2] - x2)
                gx = g0[p, 0]
                gy = g0[p, 1]
                gz = g0[p, 2]
                f00 += dx * gx
                f01 += dx * gy
                f02 += dx * gz
                f10 += dy * gx
                f11 += dy * gy
                f12 += dy * gz
                f20 += dz * gx
                f21 += dz * gy
                f22 += dz * gz
        fh[0, 0], fh[0, 1], fh[0, 2] = f00, f01, f02
        fh[1, 0], fh[1, 1], fh[1, 2] = f10, f11, f12
        fh[2, 0], fh[2, 1], fh[2, 2] = f20, f21, f22
        for a in range(3):
            for b in range(3):
                F[i, a, b] = fh[a, 0] * L[i, 0, b] + fh[a, 1] * L[i, 1, b] + fh[a, 2] * L[i, 2, b]
        # Green-Lagrange strain E = (F^T F - I)/2
        e00 = 0.5 * (F[i, 0, 0] ** 2 + F[i, 1, 0] ** 2 + F[i, 2, 0] ** 2 - 1.0)
        e11 = 0.5 * (F[i, 0, 1] ** 2 + F[i, 1, 1] ** 2 + F[i, 2, 1] ** 2 - 1.0)
        e22 = 0.5 * (F[i, 0, 2] ** 2 + F[i, 1, 2] ** 2 + F[i, 2, 2] ** 2 - 1.0)
        e01 = 0.5 * (F[i, 0, 0] * F[i, 0, 1] + F[i, 1, 0] * F[i, 1, 1] + F[i, 2, 0] * F[i, 2, 1])
        e02 = 0.5 * (F[i, 0, 0] * F[i, 0, 2] + F[i, 1, 0] * F[i, 1, 2] + F[i, 2, 0] * F[i, 2, 2])
        e12 = 0.5 * (F[i, 0, 1] * F[i, 0, 2] + F[i, 1, 1] * F[i, 1, 2] + F[i, 2, 1] * F[i, 2, 2])
        b = body[i]
        d, o, s2 = cdiag[b], coff[b], 2.0 * cshear[b]
        if is2d:
            S[0, 0] = d * e00 + o * e22
            S[2, 2] = o * e00 + d * e22
            S[1, 1] = 0.0
            S[0, 2] = S[2, 0] = s2 * e02
            S[0, 1] = S[1, 0] = S[1, 2] = S[2, 1] = 0.0
        else:
            S[0, 0] = d * e00 + o * (e11 + e22)
            S[1, 1] = d * e11 + o * (e00 + e22)
            S[2, 2] = d * e22 + o * (e00 + e11)
            S[0, 1] = S[1, 0] = s2 * e01
            S[0, 2] = S[2, 0] = s2 * e02
            S[1, 2] = S[2, 1] = s2 * e12
        # P = F S, then P L
        for a in range(3):
            for c in range(3):
                fh[a, c] = F[i, a, 0] * S[0, c] + F[i, a, 1] * S[1, c] + F[i, a, 2] * S[2, c]
        for a in range(3):
            for c in range(3):
                PL[i, a, c] = fh[a, 0] * L[i, 0, c] + fh[a, 1] * L[i, 1, c] + fh[a, 2] * L[i, 2, c]
        J[i] = (F[i, 0, 0] * (F[i, 1, 1] * F[i, 2, 2] - F[i, 1, 2] * F[i, 2, 1])
                - F[i, 0, 1] * (F[i, 1, 0] * F[i, 2, 2] - F[i, 1, 2] * F[i, 2, 0])
                + F[i, 0, 2] * (F[i, 1, 0] * F[i, 2, 1] - F[i, 1, 1] * F[i, 2, 0]))


@njit(cache=True, error_model="numpy")
def geometry_serial(is2d, pos, rows, pstart, pj, g0, L, vol, body, cdiag, coff, cshear, F, PL, J):
    """:func:`_geometry_range` over every flexible-structure particle."""
    _geometry_range(0, rows.shape[0], is2d, pos, rows, pstart, pj, g0, L, vol, body, cdiag, coff, cshear,
                    F, PL, J)


@njit(cache=True, parallel=True, error_model="numpy")
def geometry_parallel(is2d, pos, rows, pstart, pj, g0, L, vol, body, cdiag, coff, cshear, F, PL, J):
    """:func:`geometry_serial` in chunks over threads."""
    n = rows.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _geometry_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, pos, rows, pstart, pj, g0, L, vol, body,
                        cdiag, coff, cshear, F, PL, J)


@njit(cache=True, error_model="numpy")
def turn_normals(rows, F, n0, normals):
    """normals[rows[k]] = |n0| F⁻ᵀn0 / |F⁻ᵀn0| for every particle k with a normal n0[k] ≠ 0
    (DualSPHysics's CalcFlexStrucNormals): F⁻ᵀ = cof(F)/det F, so the direction is that of
    cof(F) n0, turned round where det F < 0; a particle whose F is singular keeps its normal."""
    for k in range(rows.shape[0]):
        nx = n0[k, 0]
        ny = n0[k, 1]
        nz = n0[k, 2]
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            continue
        f00, f01, f02 = F[k, 0, 0], F[k, 0, 1], F[k, 0, 2]
        f10, f11, f12 = F[k, 1, 0], F[k, 1, 1], F[k, 1, 2]
        f20, f21, f22 = F[k, 2, 0], F[k, 2, 1], F[k, 2, 2]
        # the cofactor matrix C = det(F) F^-T
        c00 = f11 * f22 - f12 * f21
        c01 = f12 * f20 - f10 * f22
        c02 = f10 * f21 - f11 * f20
        c10 = f02 * f21 - f01 * f22
        c11 = f00 * f22 - f02 * f20
        c12 = f01 * f20 - f00 * f21
        c20 = f01 * f12 - f02 * f11
        c21 = f02 * f10 - f00 * f12
        c22 = f00 * f11 - f01 * f10
        det = f00 * c00 + f01 * c01 + f02 * c02
        mx = c00 * nx + c01 * ny + c02 * nz
        my = c10 * nx + c11 * ny + c12 * nz
        mz = c20 * nx + c21 * ny + c22 * nz
        m = math.sqrt(mx * mx + my * my + mz * mz)
        if not (m > 0.0 and det != 0.0 and math.isfinite(m) and math.isfinite(det)):
            continue
        f = math.sqrt(nx * nx + ny * ny + nz * nz) / m
        if det < 0.0:
            f = -f
        r = rows[k]
        normals[r, 0] = f * mx
        normals[r, 1] = f * my
        normals[r, 2] = f * mz


@njit(cache=True, error_model="numpy")
def keep_velocity(rows, clamp, vel, v0):
    """v0[k] = the velocity of flexible particle k (its row ``rows[k]``): v^n, before its update."""
    for k in range(rows.shape[0]):
        if clamp[k]:
            continue
        r = rows[k]
        for m in range(3):
            v0[k, m] = vel[r, m]


@njit(cache=True, error_model="numpy")
def structure_wall_ace(rows, clamp, vel, v0, dt, wall_ace):
    """wall_ace[rows[k]] = (v^{n+1} − v^n)/dt of the flexible particles, mDBC2's wall acceleration
    (DualSPHysics's CopyMotionVelAce runs over them as over the moving walls)."""
    for k in range(rows.shape[0]):
        if clamp[k]:
            continue
        r = rows[k]
        for m in range(3):
            wall_ace[r, m] = (vel[r, m] - v0[k, m]) / dt


@njit(cache=True, error_model="numpy")
def _elastic_range(k0, k1, is2d, pos, rows, clamp, pstart, pj, g0, rref, wref, vol, body, rho_s, youngmod,
                   hgfactor, csound, F, PL, J, ace, out):
    """Elastic and hourglass accelerations of the flexible particles k0..k1 added to their ``ace``
    rows; out[0] = max |a|² (the whole ace of the row: fluid and elastic), out[1] = max c_i."""
    amax = 0.0
    cmax = 0.0
    for i in range(k0, k1):
        if clamp[i]:
            continue
        ri = rows[i]
        b = body[i]
        vr = vol / rho_s[b]
        hg = hgfactor[b] * vol * youngmod[b] / rho_s[b]
        ax = 0.0
        ay = 0.0
        az = 0.0
        for p in range(pstart[i], pstart[i + 1]):
            j = pj[p]
            gx, gy, gz = g0[p, 0], g0[p, 1], g0[p, 2]
            ax += vr * ((PL[i, 0, 0] + PL[j, 0, 0]) * gx + (PL[i, 0, 1] + PL[j, 0, 1]) * gy
                        + (PL[i, 0, 2] + PL[j, 0, 2]) * gz)
            ay += vr * ((PL[i, 1, 0] + PL[j, 1, 0]) * gx + (PL[i, 1, 1] + PL[j, 1, 1]) * gy
                        + (PL[i, 1, 2] + PL[j, 1, 2]) * gz)
            az += vr * ((PL[i, 2, 0] + PL[j, 2, 0]) * gx + (PL[i, 2, 1] + PL[j, 2, 1]) * gy
                        + (PL[i, 2, 2] + PL[j, 2, 2]) * gz)
            if hg != 0.0:
                rj = rows[j]
                dx = pos[ri, 0] - pos[rj, 0]
                dy = pos[ri, 1] - pos[rj, 1]
                dz = pos[ri, 2] - pos[rj, 2]
                r = math.sqrt(dx * dx + dy * dy + dz * dz)
                if r > 0.0:
                    Rx, Ry, Rz = rref[p, 0], rref[p, 1], rref[p, 2]
                    R2 = Rx * Rx + Ry * Ry + Rz * Rz
                    # r_ij - F_i R_ij and r_ij - F_j R_ij, each along r_ij
                    di = ((dx - (F[i, 0, 0] * Rx + F[i, 0, 1] * Ry + F[i, 0, 2] * Rz)) * dx
                          + (dy - (F[i, 1, 0] * Rx + F[i, 1, 1] * Ry + F[i, 1, 2] * Rz)) * dy
                          + (dz - (F[i, 2, 0] * Rx + F[i, 2, 1] * Ry + F[i, 2, 2] * Rz)) * dz) / r
                    dj = ((dx - (F[j, 0, 0] * Rx + F[j, 0, 1] * Ry + F[j, 0, 2] * Rz)) * dx
                          + (dy - (F[j, 1, 0] * Rx + F[j, 1, 1] * Ry + F[j, 1, 2] * Rz)) * dy
                          + (dz - (F[j, 2, 0] * Rx + F[j, 2, 1] * Ry + F[j, 2, 2] * Rz)) * dz) / r
                    c = hg * wref[p] / (R2 * r) * 0.5 * (di + dj)
                    ax -= c * dx
                    ay -= c * dy
                    az -= c * dz
        ace[ri, 0] += ax
        if not is2d:
            ace[ri, 1] += ay
        ace[ri, 2] += az
        a2 = ace[ri, 0] ** 2 + ace[ri, 1] ** 2 + ace[ri, 2] ** 2
        if a2 > amax:
            amax = a2
        c = csound[b] * math.sqrt(abs(J[i]))
        if c > cmax:
            cmax = c
    out[0] = amax
    out[1] = cmax


@njit(cache=True, error_model="numpy")
def elastic_serial(is2d, pos, rows, clamp, pstart, pj, g0, rref, wref, vol, body, rho_s, youngmod, hgfactor,
                   csound, F, PL, J, ace, out):
    """:func:`_elastic_range` over every particle; out (1, 2): max |a|², max c."""
    _elastic_range(0, rows.shape[0], is2d, pos, rows, clamp, pstart, pj, g0, rref, wref, vol, body, rho_s,
                   youngmod, hgfactor, csound, F, PL, J, ace, out[0])


@njit(cache=True, parallel=True, error_model="numpy")
def elastic_parallel(is2d, pos, rows, clamp, pstart, pj, g0, rref, wref, vol, body, rho_s, youngmod, hgfactor,
                     csound, F, PL, J, ace, out):
    """:func:`elastic_serial` in chunks over threads; out (chunks, 2)."""
    n = rows.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _elastic_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, pos, rows, clamp, pstart, pj, g0, rref, wref,
                       vol, body, rho_s, youngmod, hgfactor, csound, F, PL, J, ace, out[c])


@njit(cache=True, error_model="numpy")
def fluid_on_structure(kern, visco, is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, rs, cst, idp, slot,
                       clamp, body, rho_s, vol, mdbc2, tvel, ace):
    """The fluid's pressure and viscous forces on every flexible particle (module docstring),
    added to its ``ace`` row: the reaction of the terms the fluid's interaction gives its fluid
    neighbours (packed rows ``nb`` in cell order, ``oi`` their particles' rows).  ``mdbc2``
    (SlipMode 2, 3): the viscosity sees the particle's tangential velocity ``tvel`` (per packed
    row, :mod:`sphdvi.sph.mdbc`), as the fluid does; its packed density, pressure and mass are
    mDBC's (zero mass when switched off: no force)."""
    h = cst[0]
    inv_h = 1.0 / h
    r2max = cst[1]
    eta2 = cst[2]
    alpha = cst[3]
    alpha_h2 = cst[4]
    cs0h = cst[5] * h
    vis_b = cst[7]
    od_wdp = cst[15]
    eta2l = cst[21]
    ns = slot.shape[0]
    cm = 6 if is2d else 8       # packed columns: density, pressure, mass, 1/density from here
    for i in range(nb.shape[0]):
        o = oi[i]
        if o < 0 or ptype[i] != 1:
            continue
        pid = idp[o]
        if pid >= ns:
            continue
        k = slot[pid]
        if k < 0 or clamp[k]:
            continue
        if is2d:
            xi, yi, zi = nb[i, 0], 0.0, nb[i, 1]
            vxi, vyi, vzi = nb[i, 2], 0.0, nb[i, 3]
        else:
            xi, yi, zi = nb[i, 0], nb[i, 1], nb[i, 2]
            vxi, vyi, vzi = nb[i, 3], nb[i, 4], nb[i, 5]
        if mdbc2:       # the velocity the fluid's viscosity sees (mDBC2)
            vxi, vyi, vzi = tvel[i, 0], tvel[i, 1], tvel[i, 2]
        rhoi = nb[i, cm - 2]
        pi = nb[i, cm - 1]
        mb = nb[i, cm]
        iri = nb[i, cm + 1]
        tens_i = _tensile(pi, rhoi) if kern == 1 else 0.0
        xlo, xhi, ylo, yhi, zlo, zhi = stencil_bounds(cell[i], ncx, ncy, ncz, rs, is2d)
        ax = 0.0
        ay = 0.0
        az = 0.0
        for z in range(zlo, zhi + 1):
            for y in range(ylo, yhi + 1):
                row = (z * ncy + y) * ncx if not is2d else z * ncx
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    if ptype[j] != 3:
                        continue
                    if is2d:
                        dx, dy, dz = xi - nb[j, 0], 0.0, zi - nb[j, 1]
                        dvx, dvy, dvz = vxi - nb[j, 2], 0.0, vzi - nb[j, 3]
                    else:
                        dx, dy, dz = xi - nb[j, 0], yi - nb[j, 1], zi - nb[j, 2]
                        dvx, dvy, dvz = vxi - nb[j, 3], vyi - nb[j, 4], vzi - nb[j, 5]
                    r2 = dx * dx + dy * dy + dz * dz
                    if r2 >= r2max or r2 < 1e-18:
                        continue
                    q = math.sqrt(r2) * inv_h
                    fac = kernel_fac(kern, q, alpha_h2)
                    rhoj = nb[j, cm - 2]
                    mfac = nb[j, cm] * fac
                    coef = -(pi + nb[j, cm - 1]) * iri * nb[j, cm + 1]
                    if kern == 1:
                        wr = kernel_w(1, q, alpha) * od_wdp
                        wr = wr * wr
                        coef -= (tens_i + _tensile(nb[j, cm - 1], rhoj)) * (wr * wr)
                    if visco == 1:
                        dot = dvx * dx + dvy * dy + dvz * dz
                        coef += vis_b * cs0h * min(dot / (r2 + eta2), 0.0) * 2.0 / (rhoi + rhoj)
                    else:
                        vt = mfac * 4.0 * vis_b * r2 / ((r2 + eta2l) * (rhoi + rhoj))
                        ax += vt * dvx
                        ay += vt * dvy
                        az += vt * dvz
                    ax += coef * mfac * dx
                    ay += coef * mfac * dy
                    az += coef * mfac * dz
        f = mb / (rho_s[body[k]] * vol)
        ace[o, 0] += f * ax
        if not is2d:
            ace[o, 1] += f * ay
        ace[o, 2] += f * az


@njit(cache=True, error_model="numpy")
def _check_row(pos, vel, r, k, usedom, dom, fail):
    """Record (in ``fail``: k, reason) the first particle with a non-finite value or outside the domain."""
    bad = 0
    for m in range(3):
        if not (math.isfinite(pos[r, m]) and math.isfinite(vel[r, m])):
            bad = 1
    if bad == 0 and usedom:
        for m in range(3):
            if pos[r, m] < dom[m] or pos[r, m] > dom[3 + m]:
                bad = 2
    if bad != 0 and fail[0] < 0:
        fail[0] = k
        fail[1] = bad


@njit(cache=True, error_model="numpy")
def update_euler(rows, clamp, pos, vel, ace, g, dt, moved, usedom, dom, fail):
    """Verlet steps of the flexible particles (DualSPHysics's semi-implicit Euler): v += (a + g) dt,
    x += v dt; ``moved``: the fluid's integrator already advanced x by the old v dt."""
    for k in range(rows.shape[0]):
        if clamp[k]:
            continue
        r = rows[k]
        for m in range(3):
            vn = vel[r, m] + (ace[r, m] + g[m]) * dt
            if moved:
                pos[r, m] += (vn - vel[r, m]) * dt
            else:
                pos[r, m] += vn * dt
            vel[r, m] = vn
        _check_row(pos, vel, r, k, usedom, dom, fail)


@njit(cache=True, error_model="numpy")
def update_predictor(rows, clamp, pos, vel, pos_pre, vel_pre, ace, g, dt, usedom, dom, fail):
    """Symplectic predictor of the flexible particles: x = x⁰ + v⁰ dt/2, v = v⁰ + (a + g) dt/2."""
    h = 0.5 * dt
    for k in range(rows.shape[0]):
        if clamp[k]:
            continue
        r = rows[k]
        for m in range(3):
            pos[r, m] = pos_pre[r, m] + vel_pre[r, m] * h
            vel[r, m] = vel_pre[r, m] + (ace[r, m] + g[m]) * h
        _check_row(pos, vel, r, k, usedom, dom, fail)


@njit(cache=True, error_model="numpy")
def update_corrector(rows, clamp, pos, vel, pos_pre, vel_pre, ace, g, dt, usedom, dom, fail):
    """Symplectic corrector of the flexible particles: v = v⁰ + (a + g) dt, x = x⁰ + (v⁰ + v) dt/2."""
    for k in range(rows.shape[0]):
        if clamp[k]:
            continue
        r = rows[k]
        for m in range(3):
            vn = vel_pre[r, m] + (ace[r, m] + g[m]) * dt
            pos[r, m] = pos_pre[r, m] + (vel_pre[r, m] + vn) * 0.5 * dt
            vel[r, m] = vn
        _check_row(pos, vel, r, k, usedom, dom, fail)


class FlexStruc:
    """The flexible bodies of a scene: their particles (flexible and clamp, index k), reference
    pairs, correction matrices and materials, and the work arrays of each evaluation.

    Parameters: ``bodies``, the case's ``<flexstrucs>`` list (dicts with mkbound, mkclamp, density,
    youngmod, poissratio, constitmodel, hgfactor); the particles at t = 0 (``pos``, ``idp``, ``mk``,
    ``ptype``); ``is2d``, ``h``, ``dp`` and ``kernel`` (1 cubic, 2 Wendland) of the case.
    """

    def __init__(self, bodies, pos, idp, mk, ptype, *, is2d, h, dp, kernel):
        pos = np.asarray(pos, float).reshape(-1, 3)
        idp = np.asarray(idp, np.int64)
        mk = np.asarray(mk, np.int64)
        ptype = np.asarray(ptype)
        self.is2d = bool(is2d)
        self.h = float(h)
        self.kernel = int(kernel)
        self.vol = float(dp) ** (2 if self.is2d else 3)
        self.bodies = [dict(b) for b in bodies]
        r2max = 4.0 * self.h * self.h
        kidp, kclamp, kbody, kpos = [], [], [], []
        taken = np.zeros(idp.shape[0], bool)
        self.counts = []
        for b, spec in enumerate(self.bodies):
            flex = np.flatnonzero(mk == int(spec["mkbound"]))
            if flex.size == 0:
                raise ValueError(f"flexible structure mkbound={spec['mkbound']}: no particle has this mk")
            if np.any(ptype[flex] != 1):
                raise ValueError(f"flexible structure mkbound={spec['mkbound']}: its particles must be moving "
                                 "boundary particles (a <motion> object with mvnull)")
            flex = flex[np.argsort(idp[flex], kind="stable")]
            taken[flex] = True
            cand = np.flatnonzero(np.isin(mk, [int(m) for m in spec["mkclamp"]]) & (ptype <= 1) & ~taken)
            near = _clamps_near(np.ascontiguousarray(pos[cand]), np.ascontiguousarray(pos[flex]), r2max)
            clamps = cand[near]
            clamps = clamps[np.argsort(idp[clamps], kind="stable")]
            taken[clamps] = True
            self.counts.append((flex.size, clamps.size))
            for rows, is_clamp in ((flex, False), (clamps, True)):
                kidp.append(idp[rows])
                kclamp.append(np.full(rows.size, is_clamp))
                kbody.append(np.full(rows.size, b, np.int64))
                kpos.append(pos[rows])
        self.idp = np.ascontiguousarray(np.concatenate(kidp))
        self.clamp = np.ascontiguousarray(np.concatenate(kclamp))
        self.body = np.ascontiguousarray(np.concatenate(kbody))
        self.X = np.ascontiguousarray(np.concatenate(kpos))
        K = self.idp.size
        self.slot = np.full(int(idp.max()) + 1 if idp.size else 1, -1, np.int64)
        self.slot[self.idp] = np.arange(K)
        self._pairs(r2max)
        self._materials()
        self.rows = np.full(K, -1, np.int64)
        self.F = np.zeros((K, 3, 3))
        self.PL = np.zeros((K, 3, 3))
        self.J = np.ones(K)
        self.out = np.zeros(((K + CHUNK - 1) // CHUNK + 1, 2))
        self.fail = np.full(2, -1, np.int64)
        self.n0 = np.zeros((K, 3))          # the initial mDBC normals (set_normals0; zero: none)
        self.has_normals = False
        self.v0 = np.zeros((K, 3))          # v^n of the flexible particles (mDBC2's wall acceleration)
        self.amax2 = 0.0
        self.cmax = float(self.csound.max()) if self.csound.size else 0.0

    def _pairs(self, r2max):
        K = self.idp.size
        self.pstart = np.zeros(K + 1, np.int64)
        _reference_pairs(self.X, self.body, r2max, True, self.pstart, np.zeros(0, np.int64))
        self.pstart = np.cumsum(self.pstart)
        self.pj = np.zeros(int(self.pstart[-1]), np.int64)
        _reference_pairs(self.X, self.body, r2max, False, self.pstart, self.pj)
        P = self.pj.size
        alpha = kernel_alpha(self.kernel, self.h, self.is2d)
        self.g0 = np.zeros((P, 3))
        self.rref = np.zeros((P, 3))
        self.wref = np.zeros(P)
        _reference_gradients(self.X, self.pstart, self.pj, self.kernel, 1.0 / self.h, alpha,
                             alpha / (self.h * self.h), self.g0, self.rref, self.wref)
        self.L = np.zeros((K, 3, 3))
        det = np.zeros(K)
        _correction_matrices(self.X, self.pstart, self.pj, self.g0, self.vol, self.is2d, self.L, det)
        # a matrix as good as singular: too few neighbours (a line of particles, a lone particle)
        scale = np.abs(det).max() if K else 0.0
        bad = np.flatnonzero(~np.isfinite(det) | (np.abs(det) <= 1e-6 * scale) | (np.diff(self.pstart) == 0))
        if bad.size:
            k = int(bad[0])
            spec = self.bodies[int(self.body[k])]
            raise ValueError(
                f"flexible structure mkbound={spec['mkbound']}: {bad.size} of its particles have too few "
                f"neighbours within 2h for the kernel correction (the first: particle {int(self.idp[k])} at "
                f"({', '.join(f'{v:g}' for v in self.X[k])}), {int(self.pstart[k + 1] - self.pstart[k])} "
                "neighbours); the structure must be at least two particles thick")

    def _materials(self):
        B = len(self.bodies)
        self.cdiag, self.coff, self.cshear = (np.zeros(B) for _ in range(3))
        self.rho_s, self.youngmod, self.hgfactor, self.csound = (np.zeros(B) for _ in range(4))
        for b, s in enumerate(self.bodies):
            self.cdiag[b], self.coff[b], self.cshear[b] = constitutive_coefficients(
                int(s["constitmodel"]), s["youngmod"], s["poissratio"])
            self.rho_s[b] = float(s["density"])
            self.youngmod[b] = float(s["youngmod"])
            self.hgfactor[b] = float(s.get("hgfactor") or 0.0)
            self.csound[b] = sound_speed(s["youngmod"], s["poissratio"], s["density"])

    # --------------------------------------------------------------------------- each step
    @property
    def size(self) -> int:
        return int(self.idp.size)

    def locate(self, idp):
        """Find the particles' current rows (after a sort, an exclusion or a new inlet particle)."""
        if not rows_current(idp, self.idp, self.rows):
            self.rows[:] = -1
            locate_rows(idp, self.slot, self.rows)
            if np.any(self.rows < 0):
                lost = self.idp[self.rows < 0]
                raise RuntimeError(f"flexible-structure particles lost from the state: {lost[:5].tolist()}")

    def set_normals0(self, normals, idp):
        """The initial mDBC normals n0 of the particles (flexible and clamp) from ``normals``, rows
        in the order of ``idp`` (the particles at t = 0)."""
        self.locate(idp)
        self.n0 = np.ascontiguousarray(np.asarray(normals, float)[self.rows])
        self.has_normals = bool(np.any(self.n0))

    def flex_of_idp(self):
        """int8 by particle id: 1 for the flexible particles (not the clamps), 0 else; mDBC2 gives
        them the Shepard ghost density (:mod:`sphdvi.sph.mdbc`)."""
        out = np.zeros(self.slot.shape[0], np.int8)
        out[self.idp[~self.clamp]] = 1
        return out

    def geometry(self, pos, idp, parallel=False):
        """F, P L and det F of every particle (flexible and clamp) from the current positions; before
        the mDBC correction, which needs F for the normals (:meth:`turn_normals`)."""
        self.locate(idp)
        args = (self.is2d, pos, self.rows, self.pstart, self.pj, self.g0, self.L, self.vol, self.body,
                self.cdiag, self.coff, self.cshear, self.F, self.PL, self.J)
        (geometry_parallel if parallel and self.size >= PARALLEL_MIN else geometry_serial)(*args)

    def turn_normals(self, normals):
        """The normals of the particles with an initial normal (rows as the last :meth:`geometry`'s),
        n = |n0| F⁻ᵀn0 / |F⁻ᵀn0| (DualSPHysics's CalcFlexStrucNormals, clamps included)."""
        if self.has_normals:
            turn_normals(self.rows, self.F, self.n0, normals)

    def forces(self, pos, ace, parallel=False):
        """The elastic and hourglass accelerations of the flexible particles into ``ace``, from the
        last :meth:`geometry` (the same positions); sets ``amax2`` (max |a|² of their whole ace) and
        ``cmax``."""
        out = self.out
        out[:] = 0.0
        eargs = (self.is2d, pos, self.rows, self.clamp, self.pstart, self.pj, self.g0, self.rref, self.wref,
                 self.vol, self.body, self.rho_s, self.youngmod, self.hgfactor, self.csound, self.F, self.PL,
                 self.J, ace, out)
        (elastic_parallel if parallel and self.size >= PARALLEL_MIN else elastic_serial)(*eargs)
        self.amax2 = float(out[:, 0].max())
        self.cmax = float(out[:, 1].max())

    def config_lines(self) -> list:
        """run.log's lines (DualSPHysics's "Flexible Structures configuration")."""
        lines = ["Flexible Structures configuration:"]
        for b, s in enumerate(self.bodies):
            nflex, nclamp = self.counts[b]
            lines += [f"  Flexible Structure {b} (mkbound:{s['mkbound']}):",
                      f"    Clamp mkbound: {','.join(str(m) for m in s['mkclamp'])} ({nclamp} clamp particles, "
                      f"{nflex} flexible)",
                      f"    Particle volume: {self.vol:g}",
                      f"    Particle mass: {self.rho_s[b] * self.vol:g}",
                      f"    Density: {self.rho_s[b]:g}",
                      f"    Young's modulus: {self.youngmod[b]:g}",
                      f"    Poisson ratio: {float(s['poissratio']):g}",
                      f"    Sound speed: {self.csound[b]:g}",
                      f"    Hourglass correction factor: {self.hgfactor[b]:g}",
                      f"    Constitutive model: {MODEL_NAMES[int(s['constitmodel'])]}"]
        return lines

"""Constraint rows, implicit Schur-complement products and the CCP solvers.

The velocity-level cone complementarity problem of one Anitescu–Tasora step is

    find γ ∈ K  with  u = N γ + r ∈ K*,  γ·u = 0,
    N = D M⁻¹ Dᵀ + E,   r = D v_free + b,

which is the optimality condition of ``min_{γ∈K} ½ γᵀNγ + rᵀγ``.  ``N`` is never
formed: ``N x`` scatters ``M⁻¹ Jᵀ x`` into per-body velocity buffers and gathers
``J w`` back (Chrono's ``SchurComplementProduct``).

Row storage (one row per scalar constraint, contacts are 3 consecutive rows):

* ``ra, rb``  int32 body indices, -1 = the world (no velocity).
* ``J``       [nr, 12]: linear (world) and angular (body frame) parts for body a
              then body b.  ``J v`` is the constraint velocity.
* ``MiJ``     [nr, 12]: ``M⁻¹ Jᵀ`` per body (precomputed by :func:`prepare_rows`).
* ``b``, ``E``  stabilisation/bias and compliance (diagonal) terms.
* ``kind``    row kind (constants below); ``mu`` friction on FRIC_N rows;
              ``lo, hi`` bounds of BOXED rows (impulses).

Velocities are stored per body as ``v[nb, 6]`` = (linear world, angular body).

Every solver returns ``(iterations, residual)``; the residual is the largest
component of the natural map  ``D (γ - Π_K(γ - D⁻¹ (Nγ + r)))`` (D the Jacobi
diagonal, averaged on friction triplets), which has units of velocity: on a
bilateral row it is the constraint-velocity error, on a contact it is zero
exactly at a CCP solution.
"""
import math

import numpy as np
from numba import njit

BILATERAL = 0
UNILATERAL = 1
FRIC_N = 2
FRIC_T = 3
BOXED = 4

SOLVER_PSOR = 0
SOLVER_APGD = 1
SOLVER_BB = 2
SOLVER_NAMES = {"psor": SOLVER_PSOR, "apgd": SOLVER_APGD, "bb": SOLVER_BB}
# accepted spellings (DualSPHysics offers BB and MINRES; MINRES only handles
# bilateral problems, which the "direct" path solves exactly)
SOLVER_ALIASES = {"psor": "psor", "pgs": "psor", "sor": "psor", "gs": "psor", "apgd": "apgd",
                  "apgdref": "apgd", "bb": "bb", "barzilaiborwein": "bb", "spg": "bb",
                  "direct": "direct", "minres": "direct"}


# ------------------------------------------------------------------ projection
@njit(cache=True)
def average_friction_triplets(diag, kind, n):
    """Replace the three diagonal values of each friction triplet (normal, u, w) by their mean,
    as Chrono does, so the block-scaled step keeps the cone isotropic (dvi.md §1.3)."""
    i = 0
    while i < n:
        if kind[i] == FRIC_N:
            avg = (diag[i] + diag[i + 1] + diag[i + 2]) / 3.0
            diag[i] = avg
            diag[i + 1] = avg
            diag[i + 2] = avg
            i += 3
        else:
            i += 1


@njit(cache=True)
def project_cone(gn, gu, gw, mu):
    """Exact Euclidean projection onto the Coulomb cone ‖γ_t‖ ≤ μ γ_n.

    Three branches: inside the cone (kept), inside the polar cone (to 0),
    otherwise onto the cone surface: γ_n' = (γ_n + μ t)/(1 + μ²)."""
    if mu <= 0.0:
        return max(gn, 0.0), 0.0, 0.0
    t = math.sqrt(gu * gu + gw * gw)
    if t <= mu * gn:
        return gn, gu, gw
    if mu * t <= -gn:
        return 0.0, 0.0, 0.0
    gn2 = (gn + mu * t) / (1.0 + mu * mu)
    f = mu * gn2 / t
    return gn2, gu * f, gw * f


@njit(cache=True)
def project_all(x, kind, mu, lo, hi, scale):
    """Project a (scaled) impulse vector onto K; ``scale`` multiplies the box
    bounds (cones are invariant under the block-isotropic scaling)."""
    nr = x.shape[0]
    i = 0
    while i < nr:
        k = kind[i]
        if k == FRIC_N:
            a, bb, c = project_cone(x[i], x[i + 1], x[i + 2], mu[i])
            x[i] = a
            x[i + 1] = bb
            x[i + 2] = c
            i += 3
            continue
        if k == UNILATERAL:
            if x[i] < 0.0:
                x[i] = 0.0
        elif k == BOXED:
            l = lo[i] * scale[i]
            hh = hi[i] * scale[i]
            if x[i] < l:
                x[i] = l
            elif x[i] > hh:
                x[i] = hh
        i += 1


# -------------------------------------------------------------- row products
@njit(cache=True)
def prepare_rows(nr, ra, rb, J, E, kind, invm3, invI, MiJ, gdiag):
    """MiJ = M⁻¹ Jᵀ per body and the Jacobi diagonal J M⁻¹ Jᵀ + E (averaged
    over the three rows of a friction triplet, as Chrono does)."""
    for k in range(nr):
        g = E[k]
        for side in range(2):
            body = ra[k] if side == 0 else rb[k]
            o = 6 * side
            if body < 0:
                for c in range(6):
                    MiJ[k, o + c] = 0.0
                continue
            for c in range(3):
                MiJ[k, o + c] = invm3[body, c] * J[k, o + c]
            for r in range(3):
                s = 0.0
                for c in range(3):
                    s += invI[body, r, c] * J[k, o + 3 + c]
                MiJ[k, o + 3 + r] = s
            for c in range(6):
                g += J[k, o + c] * MiJ[k, o + c]
        gdiag[k] = g
    average_friction_triplets(gdiag, kind, nr)
    for k in range(nr):
        if gdiag[k] <= 1e-300:
            # row between non-dynamic bodies (fixed/moving or locked DOFs):
            # it cannot act; a huge diagonal keeps its impulse at zero
            gdiag[k] = 1e300
    return


@njit(cache=True)
def rows_times_v(nr, ra, rb, J, v, out):
    """out_k = J_k · v (constraint velocity)."""
    for k in range(nr):
        s = 0.0
        a = ra[k]
        if a >= 0:
            for c in range(6):
                s += J[k, c] * v[a, c]
        bb = rb[k]
        if bb >= 0:
            for c in range(6):
                s += J[k, 6 + c] * v[bb, c]
        out[k] = s


@njit(cache=True)
def scatter_impulses(nr, ra, rb, MiJ, x, w):
    """w += Σ_k M⁻¹ J_kᵀ x_k  (w is [nb, 6])."""
    for k in range(nr):
        xk = x[k]
        if xk == 0.0:
            continue
        a = ra[k]
        if a >= 0:
            for c in range(6):
                w[a, c] += MiJ[k, c] * xk
        bb = rb[k]
        if bb >= 0:
            for c in range(6):
                w[bb, c] += MiJ[k, 6 + c] * xk


@njit(cache=True)
def schur_product(nr, ra, rb, J, MiJ, E, x, w, out):
    """out = N x = J M⁻¹ Jᵀ x + E x without forming N (w: [nb, 6] scratch)."""
    w[:, :] = 0.0
    scatter_impulses(nr, ra, rb, MiJ, x, w)
    rows_times_v(nr, ra, rb, J, w, out)
    for k in range(nr):
        out[k] += E[k] * x[k]


@njit(cache=True)
def _schur_scaled(nr, ra, rb, J, MiJ, E, s, z, tmp, w, out):
    """out = S⁻¹ N S⁻¹ z with S = diag(s)."""
    for k in range(nr):
        tmp[k] = z[k] / s[k]
    schur_product(nr, ra, rb, J, MiJ, E, tmp, w, out)
    for k in range(nr):
        out[k] /= s[k]


@njit(cache=True)
def _natural_residual(z, g, s, kind, mu, lo, hi, tmp):
    """max_k s_k |z - Π(z - g)|_k in the scaled variables (velocity units)."""
    nr = z.shape[0]
    for k in range(nr):
        tmp[k] = z[k] - g[k]
    project_all(tmp, kind, mu, lo, hi, s)
    res = 0.0
    for k in range(nr):
        d = abs(z[k] - tmp[k]) * s[k]
        if d > res:
            res = d
    return res


# ------------------------------------------------------- sliding correction
@njit(cache=True)
def max_abs_diff(n, a, b):
    """max_k |a_k − b_k| over the first n entries (NaN if any difference is NaN, as numpy's
    ``np.abs(a − b).max()``), without a temporary array."""
    res = 0.0
    for k in range(n):
        d = abs(a[k] - b[k])
        if d != d:
            return d
        if d > res:
            res = d
    return res


@njit(cache=True)
def sliding_speeds(nr, ra, rb, J, kind, mu, gdiag, v, s):
    """De Saxcé's sliding term of each friction triplet, ``s_k = μ_k ‖(J_u v, J_w v)‖`` on its
    normal row k (0 elsewhere and on rows that cannot act), at the velocities ``v``: Chrono::
    Multicore's ChConstraintRigidRigid::Build_s (``fric · sqrt(s_v² + s_w²)`` of ``D_tᵀ v``).
    Added to the normal row's right-hand side it cancels the separation speed ``u_n = μ‖u_t‖``
    that the convexified (associated) Coulomb law of the CCP gives a sliding contact."""
    for k in range(nr):
        s[k] = 0.0
    k = 0
    while k < nr:
        if kind[k] != FRIC_N:
            k += 1
            continue
        if gdiag[k] < 1e300:
            a = ra[k]
            bb = rb[k]
            su = 0.0
            sw = 0.0
            if a >= 0:
                for c in range(6):
                    su += J[k + 1, c] * v[a, c]
                    sw += J[k + 2, c] * v[a, c]
            if bb >= 0:
                for c in range(6):
                    su += J[k + 1, 6 + c] * v[bb, c]
                    sw += J[k + 2, 6 + c] * v[bb, c]
            s[k] = mu[k] * math.sqrt(su * su + sw * sw)
        k += 3


@njit(cache=True)
def row_residuals(nr, ra, rb, J, b, E, kind, mu, lo, hi, gdiag, gamma, v, out):
    """Per-row natural-map residual (velocity units, as the solvers' ``res``) of the impulses
    ``gamma`` with the velocities ``v = v_free + M⁻¹ Dᵀ γ``: ``u = J v + b + E γ``, then
    ``s_k |z − Π(z − u/s)|_k`` with ``z = s γ``, ``s = √diag``."""
    u = np.empty(nr)
    rows_times_v(nr, ra, rb, J, v, u)
    s = np.sqrt(gdiag[:nr])
    z = np.empty(nr)
    tmp = np.empty(nr)
    for k in range(nr):
        z[k] = gamma[k] * s[k]
        tmp[k] = z[k] - (u[k] + b[k] + E[k] * gamma[k]) / s[k]
    project_all(tmp, kind[:nr], mu[:nr], lo[:nr], hi[:nr], s)
    for k in range(nr):
        out[k] = abs(z[k] - tmp[k]) * s[k] if gdiag[k] < 1e300 else 0.0


# ----------------------------------------------------------------------- PSOR
@njit(cache=True)
def solve_psor(nr, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag, gamma, v,
               max_iter, tol, omega):
    """Projected Gauss–Seidel (PSOR) with incremental velocity update.

    ``v`` enters as the free velocity plus M⁻¹ Jᵀ γ of the warm start and leaves
    as v⁺.  A friction triplet is updated jointly and projected on its cone."""
    it = 0
    res = 0.0
    for it in range(1, max_iter + 1):
        res = 0.0
        i = 0
        while i < nr:
            a = ra[i]
            bb = rb[i]
            nrow = 3 if kind[i] == FRIC_N else 1
            # constraint velocities of the block
            u0 = 0.0
            u1 = 0.0
            u2 = 0.0
            for r in range(nrow):
                s = b[i + r] + E[i + r] * gamma[i + r]
                if a >= 0:
                    for c in range(6):
                        s += J[i + r, c] * v[a, c]
                if bb >= 0:
                    for c in range(6):
                        s += J[i + r, 6 + c] * v[bb, c]
                if r == 0:
                    u0 = s
                elif r == 1:
                    u1 = s
                else:
                    u2 = s
            gi = gdiag[i]
            g0 = gamma[i] - omega * u0 / gi
            if nrow == 3:
                g1 = gamma[i + 1] - omega * u1 / gi
                g2 = gamma[i + 2] - omega * u2 / gi
                g0, g1, g2 = project_cone(g0, g1, g2, mu[i])
            else:
                g1 = 0.0
                g2 = 0.0
                kk = kind[i]
                if kk == UNILATERAL:
                    if g0 < 0.0:
                        g0 = 0.0
                elif kk == BOXED:
                    if g0 < lo[i]:
                        g0 = lo[i]
                    elif g0 > hi[i]:
                        g0 = hi[i]
            for r in range(nrow):
                if r == 0:
                    d = g0 - gamma[i]
                    gamma[i] = g0
                elif r == 1:
                    d = g1 - gamma[i + 1]
                    gamma[i + 1] = g1
                else:
                    d = g2 - gamma[i + 2]
                    gamma[i + 2] = g2
                if d != 0.0:
                    if a >= 0:
                        for c in range(6):
                            v[a, c] += MiJ[i + r, c] * d
                    if bb >= 0:
                        for c in range(6):
                            v[bb, c] += MiJ[i + r, 6 + c] * d
                    ad = abs(d) * gdiag[i + r]
                    if ad > res:
                        res = ad
            i += nrow
        if res <= tol:
            break
    return it, res


# ----------------------------------------------------------------------- APGD
@njit(cache=True)
def _quad(z, Nz, r):
    s = 0.0
    for k in range(z.shape[0]):
        s += z[k] * (0.5 * Nz[k] + r[k])
    return s


@njit(cache=True)
def solve_apgd(nr, nb, ra, rb, J, MiJ, r, E, kind, mu, lo, hi, gdiag, gamma,
               max_iter, tol):
    """Accelerated projected gradient (Nesterov/FISTA with adaptive Lipschitz
    backtracking and gradient restart; Mazhar, Heyn, Negrut, Tasora 2015),
    on the Jacobi-scaled problem z = √diag · γ.  Returns the best iterate."""
    s = np.sqrt(gdiag)
    rs = r / s
    w = np.zeros((nb, 6))
    tmp = np.empty(nr)
    z = gamma * s
    project_all(z, kind, mu, lo, hi, s)
    Nz = np.empty(nr)
    _schur_scaled(nr, ra, rb, J, MiJ, E, s, z, tmp, w, Nz)
    # Lipschitz estimate from a perturbation
    pert = z - 1.0
    Np = np.empty(nr)
    _schur_scaled(nr, ra, rb, J, MiJ, E, s, pert, tmp, w, Np)
    dn = 0.0
    nn = 0.0
    for k in range(nr):
        dn += (Nz[k] - Np[k]) ** 2
        nn += 1.0
    L = max(math.sqrt(dn / nn), 1e-3)
    y = z.copy()
    Ny = Nz.copy()
    best = z.copy()
    gtmp = np.empty(nr)
    g = np.empty(nr)
    for k in range(nr):
        g[k] = Nz[k] + rs[k]
    best_res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
    theta = 1.0
    z1 = np.empty(nr)
    Nz1 = np.empty(nr)
    it = 0
    if best_res <= tol:
        gamma[:] = best / s
        return 0, best_res
    for it in range(1, max_iter + 1):
        for k in range(nr):
            g[k] = Ny[k] + rs[k]
        fy = _quad(y, Ny, rs)
        for _bt in range(60):
            for k in range(nr):
                z1[k] = y[k] - g[k] / L
            project_all(z1, kind, mu, lo, hi, s)
            _schur_scaled(nr, ra, rb, J, MiJ, E, s, z1, tmp, w, Nz1)
            f1 = _quad(z1, Nz1, rs)
            lin = 0.0
            dd = 0.0
            for k in range(nr):
                d = z1[k] - y[k]
                lin += g[k] * d
                dd += d * d
            if f1 <= fy + lin + 0.5 * L * dd + 1e-14 * abs(fy):
                break
            L *= 2.0
        theta1 = 0.5 * (-theta * theta + theta * math.sqrt(theta * theta + 4.0))
        beta = theta * (1.0 - theta) / (theta * theta + theta1)
        # residual at z1
        for k in range(nr):
            gtmp[k] = Nz1[k] + rs[k]
        res = _natural_residual(z1, gtmp, s, kind, mu, lo, hi, tmp)
        if res < best_res:
            best_res = res
            best[:] = z1
        restart = 0.0
        for k in range(nr):
            restart += g[k] * (z1[k] - z[k])
        if restart > 0.0:
            theta1 = 1.0
            beta = 0.0
        for k in range(nr):
            y[k] = z1[k] + beta * (z1[k] - z[k])
            Ny[k] = Nz1[k] + beta * (Nz1[k] - Nz[k])
            z[k] = z1[k]
            Nz[k] = Nz1[k]
        theta = theta1
        L *= 0.9
        if best_res <= tol:
            break
    for k in range(nr):
        gamma[k] = best[k] / s[k]
    return it, best_res


# ------------------------------------------------------------------------- BB
@njit(cache=True)
def solve_bb(nr, nb, ra, rb, J, MiJ, r, E, kind, mu, lo, hi, gdiag, gamma,
             max_iter, tol):
    """Spectral projected gradient (Barzilai–Borwein steps alternating BB1/BB2,
    non-monotone Armijo search over the last 10 objective values; Birgin,
    Martínez, Raydan 2000) on the Jacobi-scaled problem.  One N·x per iteration."""
    s = np.sqrt(gdiag)
    rs = r / s
    w = np.zeros((nb, 6))
    tmp = np.empty(nr)
    z = gamma * s
    project_all(z, kind, mu, lo, hi, s)
    Nz = np.empty(nr)
    _schur_scaled(nr, ra, rb, J, MiJ, E, s, z, tmp, w, Nz)
    g = Nz + rs
    f = _quad(z, Nz, rs)
    hist = np.full(10, f)
    best = z.copy()
    best_res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
    alpha = 1.0
    d = np.empty(nr)
    Nd = np.empty(nr)
    it = 0
    if best_res <= tol:
        gamma[:] = best / s
        return 0, best_res
    for it in range(1, max_iter + 1):
        for k in range(nr):
            d[k] = z[k] - alpha * g[k]
        project_all(d, kind, mu, lo, hi, s)
        for k in range(nr):
            d[k] -= z[k]
        _schur_scaled(nr, ra, rb, J, MiJ, E, s, d, tmp, w, Nd)
        gd = 0.0
        dNd = 0.0
        for k in range(nr):
            gd += g[k] * d[k]
            dNd += d[k] * Nd[k]
        if gd >= 0.0:
            # no descent direction left: retry with a unit step once
            if alpha != 1.0:
                alpha = 1.0
                continue
            break
        fmax = hist[0]
        for q in range(1, 10):
            if hist[q] > fmax:
                fmax = hist[q]
        lam = 1.0
        fnew = f + gd + 0.5 * dNd
        for _bt in range(20):
            fnew = f + lam * gd + 0.5 * lam * lam * dNd
            if fnew <= fmax + 1e-4 * lam * gd:
                break
            lq = -gd / dNd if dNd > 0.0 else 0.5 * lam
            lam = min(max(lq, 0.1 * lam), 0.9 * lam)
        sy = 0.0
        ss = 0.0
        yy = 0.0
        for k in range(nr):
            sk = lam * d[k]
            yk = lam * Nd[k]
            z[k] += sk
            g[k] += yk
            sy += sk * yk
            ss += sk * sk
            yy += yk * yk
        f = fnew
        hist[it % 10] = f
        if sy <= 0.0:
            alpha = 1.0
        elif it % 2 == 0:
            alpha = ss / sy
        else:
            alpha = sy / yy
        alpha = min(max(alpha, 1e-13), 1e13)
        res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
        if res < best_res:
            best_res = res
            best[:] = z
        if best_res <= tol:
            break
    for k in range(nr):
        gamma[k] = best[k] / s[k]
    return it, best_res


# ------------------------------------------------------------------ front-end
@njit(cache=True)
def solve_ccp(solver, nr, nb, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag,
              gamma, vfree, vout, max_iter, tol, omega):
    """Solve one CCP; ``gamma`` holds the warm start on entry and the solution
    on exit, ``vout`` receives v⁺ = v_free + M⁻¹ Dᵀ γ."""
    vout[:, :] = vfree
    if nr == 0:
        return 0, 0.0
    ra = ra[:nr]
    rb = rb[:nr]
    J = J[:nr]
    MiJ = MiJ[:nr]
    b = b[:nr]
    E = E[:nr]
    kind = kind[:nr]
    mu = mu[:nr]
    lo = lo[:nr]
    hi = hi[:nr]
    gdiag = gdiag[:nr]
    gamma = gamma[:nr]
    project_all(gamma, kind, mu, lo, hi, np.ones(nr))
    if solver == SOLVER_PSOR:
        scatter_impulses(nr, ra, rb, MiJ, gamma, vout)
        return solve_psor(nr, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag,
                          gamma, vout, max_iter, tol, omega)
    r = np.empty(nr)
    rows_times_v(nr, ra, rb, J, vfree, r)
    for k in range(nr):
        r[k] += b[k]
    if solver == SOLVER_APGD:
        it, res = solve_apgd(nr, nb, ra, rb, J, MiJ, r, E, kind, mu, lo, hi,
                             gdiag, gamma, max_iter, tol)
    else:
        it, res = solve_bb(nr, nb, ra, rb, J, MiJ, r, E, kind, mu, lo, hi,
                           gdiag, gamma, max_iter, tol)
    scatter_impulses(nr, ra, rb, MiJ, gamma, vout)
    return it, res


# PSOR's creep check (solve_iterative): the mean of its residual over this many steps ...
PSOR_CREEP_STEPS = 1000
# ... above this (m/s) is warned about once: sustained over 10 s it moves a resting body by
# 1e-4 m, TOLERANCES M4's drift bound.  A 5-box stack (0.1 m, 1 kg, μ 0.5, h 1e-3 s) either
# converges (≥ 400 iterations: residual 1e-10, ~325 sweeps a step once warm) or stalls
# (≤ 300: mean residual 1e-4–5e-4 m/s, drift 1e-4–6.5e-4 m and ground reaction 3–16 % off
# the weight over 10 s); BB and APGD reach 1e-10 there in 4–6 iterations.
PSOR_CREEP_RESIDUAL = 1e-5


def _psor_creep_check(owner, res):
    """Warn once per ``owner`` (its pending_warnings, for run.log) when PSOR's residual, averaged
    over PSOR_CREEP_STEPS steps (the last solve of each step: the sliding correction solves a
    step more than once), is above PSOR_CREEP_RESIDUAL: projected Gauss–Seidel stalls on stacked
    bodies at too few iterations (Chrono's ChSolverPSOR docs: "convergence might stall"), and
    its unconverged impulses let a resting stack creep and its reactions swing."""
    st = getattr(owner, "_psor_creep", None)
    if st is None:
        st = owner._psor_creep = {"t": None, "res": 0.0, "sum": 0.0, "n": 0, "warned": False}
    if st["warned"]:
        return
    if st["t"] is not None and owner.time != st["t"]:
        st["sum"] += st["res"]
        st["n"] += 1
        if st["n"] >= PSOR_CREEP_STEPS:
            mean = st["sum"] / st["n"]
            st["sum"], st["n"] = 0.0, 0
            if mean > PSOR_CREEP_RESIDUAL:
                st["warned"] = True
                line = (f"PSOR solver at t={owner.time:.6g} s: its residual averaged "
                        f"{mean:.3g} m/s over the last {PSOR_CREEP_STEPS} steps (above "
                        f"{PSOR_CREEP_RESIDUAL:g}) at {owner.max_iter} iterations: projected "
                        "Gauss-Seidel stalls on bodies resting on each other, which then creep "
                        "(a 5-box stack at 100 iterations: 6.5e-4 m and ground reaction 16 % off "
                        "the weight in 10 s); raise maxiter (that stack holds from 400) or use "
                        "BB or APGD")
                owner.say(line)
    st["t"] = owner.time
    st["res"] = res


# ------------------------------------------------------- dense / direct path
@njit(cache=True)
def assemble_dense(nr, ra, rb, J, MiJ, E):
    """Dense N = J M⁻¹ Jᵀ + E (only for small row counts: O(nr²))."""
    N = np.zeros((nr, nr))
    for i in range(nr):
        for j in range(i, nr):
            s = 0.0
            for si in range(2):
                bi = ra[i] if si == 0 else rb[i]
                if bi < 0:
                    continue
                for sj in range(2):
                    bj = ra[j] if sj == 0 else rb[j]
                    if bj != bi:
                        continue
                    for c in range(6):
                        s += J[i, 6 * si + c] * MiJ[j, 6 * sj + c]
            N[i, j] = s
            N[j, i] = s
        N[i, i] += E[i]
    return N


@njit(cache=True)
def dense_jacobi_scaling(N, kind):
    """Diagonal of a dense N (floored at 1e-300), averaged over each friction triplet, and its
    square root: the Jacobi scaling γ = s·γ̃ of the dense solvers (as the matrix-free ones)."""
    n = N.shape[0]
    d0 = np.empty(n)
    for k in range(n):
        d0[k] = max(N[k, k], 1e-300)
    average_friction_triplets(d0, kind, n)
    return d0, np.sqrt(d0)


@njit(cache=True)
def solve_dense_bb(N, r, kind, mu, lo, hi, gamma, max_iter, tol):
    """Spectral projected gradient on an explicit (small) N, Jacobi-scaled."""
    n = r.shape[0]
    d0, s = dense_jacobi_scaling(N, kind)
    Ns = N / np.outer(s, s)
    rs = r / s
    z = gamma * s
    project_all(z, kind, mu, lo, hi, s)
    tmp = np.empty(n)
    g = Ns @ z + rs
    f = 0.5 * (z @ (g - rs)) + rs @ z
    hist = np.full(10, f)
    best = z.copy()
    best_res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
    alpha = 1.0
    it = 0
    for it in range(1, max_iter + 1):
        if best_res <= tol:
            break
        d = z - alpha * g
        project_all(d, kind, mu, lo, hi, s)
        d -= z
        Nd = Ns @ d
        gd = g @ d
        dNd = d @ Nd
        if gd >= 0.0:
            if alpha != 1.0:
                alpha = 1.0
                continue
            break
        fmax = hist.max()
        lam = 1.0
        fnew = f + gd + 0.5 * dNd
        for _bt in range(20):
            fnew = f + lam * gd + 0.5 * lam * lam * dNd
            if fnew <= fmax + 1e-4 * lam * gd:
                break
            lq = -gd / dNd if dNd > 0.0 else 0.5 * lam
            lam = min(max(lq, 0.1 * lam), 0.9 * lam)
        sv = lam * d
        yv = lam * Nd
        z += sv
        g += yv
        f = fnew
        hist[it % 10] = f
        sy = sv @ yv
        if sy <= 0.0:
            alpha = 1.0
        elif it % 2 == 0:
            alpha = (sv @ sv) / sy
        else:
            alpha = sy / (yv @ yv)
        alpha = min(max(alpha, 1e-13), 1e13)
        res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
        if res < best_res:
            best_res = res
            best[:] = z
    gamma[:] = best / s
    return it, best_res


# interior-point (log-barrier) solve of the dense contact CCP
BIG_BOUND = 1e299            # |lo|, |hi| at or above this: no bound (rows use ±1e300)
IPM_PROX = 1e-9             # proximal weight in the Newton matrix (Q has a unit diagonal)
IPM_T0 = 0.01               # the starting t: this times the gradient-balancing value
IPM_CENTRED = 1.0           # Newton decrement² below which t is raised ...
IPM_T_FACTOR = 10.0         # ... by this factor
IPM_MAX_ROWS = 300           # larger contact problems keep the projected gradient only (O(n³) a step)


@njit(cache=True)
def _dense_cholesky(H, n):
    """In-place lower Cholesky factor of the leading n×n block of H; a pivot that rounding
    leaves not positive (a near-singular H) is floored at 1e-15 of its row's diagonal."""
    for j in range(n):
        d = H[j, j]
        floor = max(1e-15 * H[j, j], 1e-300)
        for k in range(j):
            d -= H[j, k] * H[j, k]
        if d < floor:
            d = floor
        d = math.sqrt(d)
        H[j, j] = d
        for i in range(j + 1, n):
            v = H[i, j]
            for k in range(j):
                v -= H[i, k] * H[j, k]
            H[i, j] = v / d


@njit(cache=True)
def _cholesky_solve(L, n, x):
    """Solve L Lᵀ x = x in place."""
    for i in range(n):
        v = x[i]
        for k in range(i):
            v -= L[i, k] * x[k]
        x[i] = v / L[i, i]
    for i in range(n - 1, -1, -1):
        v = x[i]
        for k in range(i + 1, n):
            v -= L[k, i] * x[k]
        x[i] = v / L[i, i]


@njit(cache=True)
def _barrier_feasible(z, typ, mu, lb, ub):
    """z strictly inside K (cones, half-lines, boxes)?"""
    n = z.shape[0]
    for i in range(n):
        t = typ[i]
        if t == 1:
            if not z[i] > lb[i]:
                return False
        elif t == 2:
            if not z[i] < ub[i]:
                return False
        elif t == 3:
            if not (z[i] > lb[i] and z[i] < ub[i]):
                return False
        elif t == 4:
            m = mu[i]
            if not (z[i] > 0.0 and m * m * z[i] * z[i] - z[i + 1] * z[i + 1] - z[i + 2] * z[i + 2] > 0.0):
                return False
    return True


@njit(cache=True)
def _barrier_terms(z, typ, mu, lb, ub, grad, H):
    """Add the log barrier's gradient to ``grad`` and its (block-diagonal) Hessian to ``H``:
    −log(z−l), −log(u−z) and, per friction cone, −log(μ²z_n² − ‖z_t‖²) (self-concordant,
    parameter 2; Nesterov & Nemirovski 1994, Boyd & Vandenberghe 2004 §11.6)."""
    n = z.shape[0]
    for i in range(n):
        t = typ[i]
        if t == 1 or t == 3:
            d = z[i] - lb[i]
            grad[i] -= 1.0 / d
            H[i, i] += 1.0 / (d * d)
        if t == 2 or t == 3:
            d = ub[i] - z[i]
            grad[i] += 1.0 / d
            H[i, i] += 1.0 / (d * d)
        if t == 4:
            m2 = mu[i] * mu[i]
            a0 = 2.0 * m2 * z[i]
            a1 = -2.0 * z[i + 1]
            a2 = -2.0 * z[i + 2]
            D = m2 * z[i] * z[i] - z[i + 1] * z[i + 1] - z[i + 2] * z[i + 2]
            grad[i] -= a0 / D
            grad[i + 1] -= a1 / D
            grad[i + 2] -= a2 / D
            a = (a0, a1, a2)
            dd = (2.0 * m2, -2.0, -2.0)
            for p in range(3):
                for q in range(3):
                    h = a[p] * a[q] / (D * D)
                    if p == q:
                        h -= dd[p] / D
                    H[i + p, i + q] += h


@njit(cache=True)
def _barrier_value(z, typ, mu, lb, ub):
    """The log barrier of K at a strictly feasible z."""
    v = 0.0
    n = z.shape[0]
    for i in range(n):
        t = typ[i]
        if t == 1 or t == 3:
            v -= math.log(z[i] - lb[i])
        if t == 2 or t == 3:
            v -= math.log(ub[i] - z[i])
        if t == 4:
            v -= math.log(mu[i] * mu[i] * z[i] * z[i] - z[i + 1] * z[i + 1] - z[i + 2] * z[i + 2])
    return v


@njit(cache=True)
def _max_step(z, d, typ, mu, lb, ub):
    """Largest α with z + α d still in K (closed; 1e300 when unbounded)."""
    amax = 1e300
    n = z.shape[0]
    for i in range(n):
        t = typ[i]
        if (t == 1 or t == 3) and d[i] < 0.0:
            amax = min(amax, (z[i] - lb[i]) / -d[i])
        if (t == 2 or t == 3) and d[i] > 0.0:
            amax = min(amax, (ub[i] - z[i]) / d[i])
        if t == 4:
            # D(α) = μ²(z_n + α d_n)² − ‖z_t + α d_t‖² = A α² + 2 B α + C, C > 0: first root > 0
            m2 = mu[i] * mu[i]
            A = m2 * d[i] * d[i] - d[i + 1] * d[i + 1] - d[i + 2] * d[i + 2]
            B = m2 * z[i] * d[i] - z[i + 1] * d[i + 1] - z[i + 2] * d[i + 2]
            C = m2 * z[i] * z[i] - z[i + 1] * z[i + 1] - z[i + 2] * z[i + 2]
            root = 1e300
            if A == 0.0:
                if B < 0.0:
                    root = -C / (2.0 * B)
            else:
                disc = B * B - A * C
                if disc >= 0.0:
                    sq = math.sqrt(disc)
                    # roots (−B ± sq)/A, computed stably
                    q = -(B + sq) if B >= 0.0 else -(B - sq)
                    r1 = q / A
                    r2 = C / q if q != 0.0 else 1e300
                    for rt in (r1, r2):
                        if rt > 0.0 and rt < root:
                            root = rt
            # the cone's other nappe (z_n < 0) also has D > 0: stop where z_n crosses 0
            if d[i] < 0.0:
                root = min(root, z[i] / -d[i])
            amax = min(amax, root)
    return amax


@njit(cache=True)
def solve_dense_ipm(N, r, kind, mu, lo, hi, gamma, max_iter, tol):
    """Log-barrier interior-point method (damped Newton on t·f + barrier, t raised 10× once
    centred; Boyd & Vandenberghe 2004 §11.3, self-concordant step 1/(1+λ), §9.6) for the dense
    CCP ``min_{γ∈K} ½γᵀNγ + rᵀγ`` on the Jacobi-scaled problem.  Newton steps invert N, so the
    iteration count does not grow with its condition number (a light body under one 1e7 times
    heavier); a first-order method's does.  Starts from ``gamma`` pushed into K's interior,
    stops at the natural-map residual ``tol`` (as the other solvers), returns the best iterate."""
    n = r.shape[0]
    d0, s = dense_jacobi_scaling(N, kind)
    dmax = d0.max()
    # variable types: 0 free, 1 lower bound, 2 upper bound, 3 both, 4 cone normal (owns the
    # next two rows), 5 cone tangent, 6 fixed at 0 (a row that cannot act, μ = 0 tangents)
    typ = np.zeros(n, np.int64)
    lb = np.zeros(n)
    ub = np.zeros(n)
    fix = np.zeros(n)
    act = np.ones(n, np.bool_)
    i = 0
    while i < n:
        k = kind[i]
        if k == FRIC_N:
            dead = d0[i] <= 1e-300 or d0[i] < 1e-15 * dmax
            if dead:
                typ[i] = 6
                typ[i + 1] = 6
                typ[i + 2] = 6
            elif mu[i] <= 0.0:
                typ[i] = 1
                typ[i + 1] = 6
                typ[i + 2] = 6
            else:
                typ[i] = 4
                typ[i + 1] = 5
                typ[i + 2] = 5
            i += 3
            continue
        if d0[i] <= 1e-300 or d0[i] < 1e-15 * dmax:
            typ[i] = 6
        elif k == UNILATERAL:
            typ[i] = 1
        elif k == BOXED:
            hl = lo[i] > -BIG_BOUND
            hh = hi[i] < BIG_BOUND
            if hl and hh and hi[i] <= lo[i]:
                typ[i] = 6
                fix[i] = lo[i] * s[i]
            elif hl and hh:
                typ[i] = 3
            elif hl:
                typ[i] = 1
            elif hh:
                typ[i] = 2
            lb[i] = lo[i] * s[i] if hl else 0.0
            ub[i] = hi[i] * s[i] if hh else 0.0
        i += 1
    for k in range(n):
        if typ[k] == 6:
            act[k] = False
    Q = np.empty((n, n))
    for a in range(n):
        for b in range(n):
            Q[a, b] = N[a, b] / (s[a] * s[b])
    c = r / s
    # start: the warm start, projected, then strictly inside
    z = gamma * s
    project_all(z, kind, mu, lo, hi, s)
    zmax = 0.0
    for k in range(n):
        if act[k]:
            zmax = max(zmax, abs(z[k]), abs(r[k] / s[k]))
    off = 1e-3 * zmax if zmax > 0.0 else 1.0
    for k in range(n):
        t = typ[k]
        if t == 6:
            z[k] = fix[k]
        elif t == 1:
            z[k] = max(z[k], lb[k]) + off
        elif t == 2:
            z[k] = min(z[k], ub[k]) - off
        elif t == 3:
            w = ub[k] - lb[k]
            z[k] = min(max(z[k], lb[k] + 0.01 * w), ub[k] - 0.01 * w)
        elif t == 4:
            tn = math.sqrt(z[k + 1] * z[k + 1] + z[k + 2] * z[k + 2]) / mu[k]
            z[k] = max(z[k], tn) + off + tn * 0.01
    tmp = np.empty(n)
    g = Q @ z + c
    best = z.copy()
    best_res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
    it = 0
    if best_res <= tol:
        gamma[:] = best / s
        return 0, best_res
    # t: balance the objective's and the barrier's gradients at the start
    gb = np.zeros(n)
    Hb = np.zeros((n, n))
    _barrier_terms(z, typ, mu, lb, ub, gb, Hb)
    num = 0.0
    den = 0.0
    for k in range(n):
        if act[k]:
            num -= g[k] * gb[k]
            den += g[k] * g[k]
    tt = num / den if den > 0.0 and num > 0.0 else 1.0
    tt = min(max(tt * IPM_T0, 1e-12), 1e12)
    H = np.empty((n, n))
    grad = np.empty(n)
    dz = np.empty(n)
    dzf = np.empty(n)
    idx = np.nonzero(act)[0]
    na = idx.shape[0]
    for it in range(1, max_iter + 1):
        # Newton system on the active variables: (t Q + ∇²B) dz = −(t g + ∇B)
        gb[:] = 0.0
        Hb[:, :] = 0.0
        _barrier_terms(z, typ, mu, lb, ub, gb, Hb)
        for a in range(na):
            ia = idx[a]
            grad[a] = tt * g[ia] + gb[ia]
            for b in range(na):
                H[a, b] = tt * Q[ia, idx[b]] + Hb[ia, idx[b]]
            # proximal (Levenberg–Marquardt) term ρ‖z − z_k‖²/2 about the current point: no
            # change of the gradient, but bounded steps along directions where Q vanishes
            # (self-equilibrated impulses of a wedged body: there the barrier has no minimum)
            H[a, a] += tt * IPM_PROX
        for a in range(na):
            dz[a] = -grad[a]
        _dense_cholesky(H, na)
        _cholesky_solve(H, na, dz)
        lam2 = 0.0
        for a in range(na):
            lam2 -= grad[a] * dz[a]
        if not math.isfinite(lam2):
            break
        # largest step to K's boundary, then backtracking (Armijo) on t·f + B; the change of
        # t·f is evaluated as t(α gᵀΔ + ½α² ΔᵀQΔ), free of cancellation at large t
        for k in range(n):
            dzf[k] = 0.0
        for a in range(na):
            dzf[idx[a]] = dz[a]
        Qd = Q @ dzf
        gd = 0.0
        dQd = 0.0
        for k in range(n):
            gd += g[k] * dzf[k]
            dQd += dzf[k] * Qd[k]
        step = min(1.0, 0.99 * _max_step(z, dzf, typ, mu, lb, ub))
        b0 = _barrier_value(z, typ, mu, lb, ub)
        ok = False
        for _bt in range(60):
            for k in range(n):
                tmp[k] = z[k] + step * dzf[k]
            if _barrier_feasible(tmp, typ, mu, lb, ub):
                phi = tt * (step * gd + 0.5 * step * step * dQd) + _barrier_value(tmp, typ, mu, lb, ub) - b0
                if phi <= -0.25 * step * lam2 or step * math.sqrt(max(lam2, 0.0)) < 1e-12:
                    ok = True
                    break
            step *= 0.5
        if not ok:
            break
        z[:] = tmp
        g = Q @ z + c
        res = _natural_residual(z, g, s, kind, mu, lo, hi, tmp)
        if res < best_res:
            best_res = res
            best[:] = z
        if best_res <= tol:
            break
        if lam2 <= IPM_CENTRED:
            tt *= IPM_T_FACTOR
            if tt > 1e30:
                break
    gamma[:] = best / s
    return it, best_res


@njit(cache=True)
def row_islands(nr, nb, ra, rb, MiJ, label):
    """Split the rows into islands, the connected components of the bodies that the rows link
    (Chrono::Multicore's and Bullet's simulation islands): a row links the sides whose
    ``M⁻¹ Jᵀ`` is not zero, so the world, fixed and moving bodies (and locked directions) link
    nothing and ``N = D M⁻¹ Dᵀ + E`` is block-diagonal by island.  ``label[k]`` receives row k's
    island (numbered in the order of their first rows; -1: a row that cannot act, no live side);
    returns the number of islands."""
    parent = np.arange(nb)
    live = np.zeros((nr, 2), np.bool_)
    for k in range(nr):
        for side in range(2):
            body = ra[k] if side == 0 else rb[k]
            if body < 0:
                continue
            for c in range(6):
                if MiJ[k, 6 * side + c] != 0.0:
                    live[k, side] = True
                    break
        if live[k, 0] and live[k, 1]:
            x = ra[k]
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            y = rb[k]
            while parent[y] != y:
                parent[y] = parent[parent[y]]
                y = parent[y]
            if x != y:
                parent[max(x, y)] = min(x, y)
    island_of_root = np.full(nb, -1, np.int64)
    n = 0
    for k in range(nr):
        if not (live[k, 0] or live[k, 1]):
            label[k] = -1
            continue
        x = ra[k] if live[k, 0] else rb[k]
        while parent[x] != x:
            x = parent[x]
        if island_of_root[x] < 0:
            island_of_root[x] = n
            n += 1
        label[k] = island_of_root[x]
    return n


def _solve_direct_island(ra, rb, J, MiJ, b, E, kind, mu, lo, hi, g, vfree, max_iter, tol):
    """solve_direct on the rows of one island (``g`` the warm start in, the impulses out):
    bilateral rows by Cholesky, the reduced contact CCP by the dense BB and, where that has not
    converged, the interior-point method.  Returns (iterations, residual, IPM skipped)."""
    from scipy.linalg import cho_factor, cho_solve
    nr = ra.shape[0]
    N = assemble_dense(nr, ra, rb, J, MiJ, E)
    r = np.empty(nr)
    rows_times_v(nr, ra, rb, J, vfree, r)
    r += b
    bil = kind == BILATERAL
    ib = np.nonzero(bil)[0]
    ic = np.nonzero(~bil)[0]
    it, res, skipped = 0, 0.0, False
    if ib.size:
        Nbb = N[np.ix_(ib, ib)]
        reg = 1e-13 * max(np.trace(Nbb) / ib.size, 1e-300)
        fac = cho_factor(Nbb + reg * np.eye(ib.size))
    if ic.size == 0:
        g[ib] = -cho_solve(fac, r[ib])
    else:
        Ncc = N[np.ix_(ic, ic)]
        rc = r[ic].copy()
        if ib.size:
            Nbc = N[np.ix_(ib, ic)]
            X = cho_solve(fac, Nbc)
            Ncc = Ncc - Nbc.T @ X
            rc = rc - X.T @ r[ib]
        gc = g[ic].copy()
        kc, muc, loc, hic = kind[ic].copy(), mu[ic].copy(), lo[ic].copy(), hi[ic].copy()
        it, res = solve_dense_bb(Ncc, rc, kc, muc, loc, hic, gc, max_iter, tol)
        if res > tol and ic.size <= IPM_MAX_ROWS:
            # not converged (an ill-conditioned N: a heavy body on a light one): Newton steps
            gi = gc.copy()
            it2, res2 = solve_dense_ipm(Ncc, rc, kc, muc, loc, hic, gi, max_iter, tol)
            it += it2
            if res2 < res:
                res = res2
                gc = gi
        elif res > tol:
            skipped = True
        # γ = z/s on a boxed row can leave its bound by an ulp: clip it back
        bx = kc == BOXED
        gc[bx] = np.minimum(np.maximum(gc[bx], loc[bx]), hic[bx])
        g[ic] = gc
        if ib.size:
            g[ib] = -cho_solve(fac, r[ib] + Nbc @ gc)
    return it, res, skipped


def _warn_island_without_ipm(owner, ra, rb, MiJ):
    """Warn once per ``owner`` (a System: its pending_warnings, for run.log) that an island of
    more than IPM_MAX_ROWS contact rows ended its solve without the interior-point finish, when
    the island's floating bodies span a mass ratio beyond what BB resolves (bodychecks.
    CONTACT_RATIO_LIMIT): there a heavy body on a light one may be crushed."""
    from ..bodychecks import CONTACT_RATIO_LIMIT
    if owner is None or getattr(owner, "_ipm_island_warned", False):
        return
    bodies = sorted({int(x) for side, col in ((ra, 0), (rb, 6)) for k, x in enumerate(side)
                     if x >= 0 and MiJ[k, col:col + 6].any()})
    masses = [float(owner.mass[i]) for i in bodies if owner.inv_mass[i] > 0.0]
    if len(masses) < 2 or max(masses) / min(masses) <= CONTACT_RATIO_LIMIT["bb"]:
        return
    owner._ipm_island_warned = True
    names = [owner.names[i] for i in bodies]
    shown = ", ".join(names[:12]) + (f" and {len(names) - 12} more" if len(names) > 12 else "")
    line = (f"direct solver at t={owner.time:.6g} s: an island of {len(names)} bodies in contact "
            f"({shown}) has more than {IPM_MAX_ROWS} contact rows, so its solve ends without the "
            f"interior-point finish, and its mass ratio {max(masses) / min(masses):.3g} is above "
            f"the {CONTACT_RATIO_LIMIT['bb']:g} that the projected gradient resolves: a heavy body "
            "resting on a light one there may be crushed or launched")
    owner.say(line)


def solve_direct(nr, nb, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag, gamma, vfree, vout,
                 max_iter, tol, owner=None):
    """Direct path for small mechanisms, island by island (:func:`row_islands`: N is
    block-diagonal by island, so each island's problem is solved on its own, exactly, at
    O(Σ n_i³) instead of O(n³)): the bilateral (and compliance) rows are
    eliminated exactly with a Cholesky factorisation of their Schur block and
    the remaining contact/boxed rows solve the reduced CCP
    ``N' = N_cc − N_cb N_bb⁻¹ N_bc`` with a dense spectral projected gradient and, where that
    has not reached ``tol`` in ``max_iter`` iterations (an ill-conditioned N': a light body
    under a heavy one), with the interior-point method :func:`solve_dense_ipm` from its best
    iterate (islands of up to IPM_MAX_ROWS contact rows; a larger one that has not converged is
    warned about once, through ``owner``, where its mass ratio is beyond BB's limit).  Robust to
    large mass ratios and stiff compliance (dense: rows per island ≲ 1000).  Returns the largest
    iteration count and residual of the islands."""
    vout[:, :] = vfree
    if nr == 0:
        return 0, 0.0
    sl = slice(0, nr)
    ra, rb, J, MiJ, b, E = ra[sl], rb[sl], J[sl], MiJ[sl], b[sl], E[sl]
    kind, mu, lo, hi, g = kind[sl], mu[sl], lo[sl], hi[sl], gamma[sl]
    label = np.empty(nr, np.int64)
    nisl = row_islands(nr, vfree.shape[0], ra, rb, MiJ, label)
    it, res = 0, 0.0
    if nisl == 1 and label.min() == 0:
        it, res, skipped = _solve_direct_island(ra, rb, J, MiJ, b, E, kind, mu, lo, hi, g, vfree,
                                                max_iter, tol)
        if skipped:
            _warn_island_without_ipm(owner, ra, rb, MiJ)
    else:
        g[label < 0] = 0.0              # rows that cannot act
        order = np.argsort(label, kind="stable")
        bounds = np.searchsorted(label[order], np.arange(nisl + 1))
        for q in range(nisl):
            ix = order[bounds[q]:bounds[q + 1]]
            gq = g[ix]
            itq, resq, skipped = _solve_direct_island(ra[ix], rb[ix], J[ix], MiJ[ix], b[ix], E[ix],
                                                      kind[ix], mu[ix], lo[ix], hi[ix], gq, vfree,
                                                      max_iter, tol)
            g[ix] = gq
            it, res = max(it, itq), max(res, resq)
            if skipped:
                _warn_island_without_ipm(owner, ra[ix], rb[ix], MiJ[ix])
    scatter_impulses(nr, ra, rb, MiJ, g, vout)
    return it, res


# ------------------------------------------- joint-only islands, solved exactly
# The iterative solvers hand every island whose rows are all linear equalities (joints, and the
# compliance rows of springs, dampers and motors; explicit springs' fixed impulses) to a dense
# Cholesky solve: there the CCP is a linear system, and BB, PSOR and APGD converge on the
# out-of-plane rows of a joint chain (Jacobi-scaled condition numbers 1e3–1.6e4 for 2–5 links) too
# slowly to hold it in its plane in 100 iterations.  Islands with contacts or bounded rows stay
# iterative.  (Chrono users get the same by choosing a direct sparse solver for such systems.)
EXACT_JOINT_MAX_ROWS = 600      # larger joint-only islands stay iterative, and so do those whose
EXACT_JOINT_MAX_WORK = 4.5e6    # envelope factor takes more than this (Σ width², ~ flops: dense
                                # 240 rows; a chain of n hinges ~330 n, one hub's 100 hinges 4.3e7)
EXACT_PIVOT_MIN = 1e-11         # a Cholesky pivot below this fraction of its diagonal: redundant
                                # joint rows (a closed loop), the island stays iterative


@njit(cache=True)
def _is_equality_row(kind, lo, hi):
    """A row whose CCP set is a point or the whole line: bilateral (K = R, compliance or not), or
    boxed with lo = hi (an explicit spring's fixed impulse)."""
    return kind == BILATERAL or (kind == BOXED and lo == hi)


@njit(cache=True)
def plan_exact_islands(nr, nb, ra, rb, MiJ, kind, lo, hi, max_rows, label, xorder, xstart):
    """The islands (:func:`row_islands`) whose rows are all equalities (:func:`_is_equality_row`)
    and at most ``max_rows``: ``label[k]`` their number (0 ...) on their rows, -1 on the others
    (the iterative solver's), ``xorder[xstart[q]:xstart[q+1]]`` island q's rows in row order.
    Returns (islands, their rows, the largest island's rows); a scene without equality rows (a
    contacts-only one) returns at once, leaving ``label`` as it is."""
    found = False
    for k in range(nr):
        if _is_equality_row(kind[k], lo[k], hi[k]):
            found = True
            break
    if not found:
        return 0, 0, 0
    n = row_islands(nr, nb, ra, rb, MiJ, label)
    cnt = np.zeros(n, np.int64)
    ok = np.ones(n, np.bool_)
    for k in range(nr):
        q = label[k]
        if q < 0:
            continue
        cnt[q] += 1
        if not _is_equality_row(kind[k], lo[k], hi[k]):
            ok[q] = False
    newid = np.full(n, -1, np.int64)
    nx = 0
    for q in range(n):
        if ok[q] and cnt[q] <= max_rows:
            newid[q] = nx
            nx += 1
    for q in range(nx + 1):
        xstart[q] = 0
    big = 0
    for q in range(n):
        if newid[q] >= 0:
            xstart[newid[q] + 1] = cnt[q]
            big = max(big, cnt[q])
    for q in range(nx):
        xstart[q + 1] += xstart[q]
    fill = xstart[:nx].copy() if nx > 0 else np.zeros(0, np.int64)
    for k in range(nr):
        q = label[k]
        x = newid[q] if q >= 0 else -1
        label[k] = x
        if x >= 0:
            xorder[fill[x]] = k
            fill[x] += 1
    return nx, xstart[nx], big


@njit(cache=True)
def _envelope_cholesky(H, n, first):
    """In-place lower Cholesky factor of H[:n, :n] within its envelope (row i's entries from column
    ``first[i]``, the first non-zero: the fill stays inside it, so a chain's banded N costs
    O(n·band²)).  Returns False where a pivot falls below EXACT_PIVOT_MIN of its diagonal (rows
    that are linearly dependent, up to rounding)."""
    for i in range(n):
        fi = first[i]
        for j in range(fi, i + 1):
            fj = first[j]
            v = H[i, j]
            for k in range(max(fi, fj), j):
                v -= H[i, k] * H[j, k]
            if j < i:
                H[i, j] = v / H[j, j]
            else:
                if not v > EXACT_PIVOT_MIN * H[i, i]:
                    return False
                H[i, i] = math.sqrt(v)
    return True


@njit(cache=True)
def _envelope_solve(L, n, first, x):
    """Solve L Lᵀ x = x in place with the envelope factor of :func:`_envelope_cholesky`."""
    for i in range(n):
        v = x[i]
        for k in range(first[i], i):
            v -= L[i, k] * x[k]
        x[i] = v / L[i, i]
    for i in range(n - 1, -1, -1):
        x[i] /= L[i, i]
        xi = x[i]
        for k in range(first[i], i):
            x[k] -= L[i, k] * xi


@njit(cache=True)
def _live_side(MiJ, k, side):
    """Row k's side moves its body (M⁻¹ Jᵀ not zero there: :func:`row_islands`' link)."""
    for c in range(6):
        if MiJ[k, 6 * side + c] != 0.0:
            return True
    return False


@njit(cache=True)
def _solve_equality_island(rows, ra, rb, J, MiJ, b, E, kind, lo, gamma, vfree, H, vec, iw, loc,
                           bhead, max_work):
    """One joint-only island's impulses: fixed rows (boxed, lo = hi) at lo, the bilateral ones
    from ``(N_bb + εI) γ_b = −(r_b + N_bf γ_f)`` (``r = J v_free + b``, ε as
    :func:`_solve_direct_island`'s, 1e-13 of the mean diagonal) by an envelope Cholesky
    factorisation.  N is assembled from each body's rows (``N_ij = Σ J_i M⁻¹ J_jᵀ`` over the bodies
    rows i and j share, as :func:`assemble_dense`), so a chain costs O(n·band²), not O(n²).
    Work arrays: ``H`` [n, n], ``vec`` [n], ``iw`` (int [5, 2n]: the bilateral rows, their
    envelope, then the bodies' row lists: next, row, side), ``loc`` (per row: its place among the
    bilateral rows, -1 for a fixed one) and ``bhead`` (per body: its list's head; -1 on entry and
    on return).  Returns False (``gamma`` untouched) where the envelope's factor work
    ``Σ (p − first[p] + 1)²`` is above ``max_work`` or the rows are dependent
    (:func:`_envelope_cholesky`)."""
    n = rows.shape[0]
    bil = iw[0]
    first = iw[1]
    bnext = iw[2]
    brow = iw[3]
    bside = iw[4]
    nbil = 0
    ne = 0
    for a in range(n):
        k = rows[a]
        if kind[k] == BILATERAL:
            loc[k] = nbil
            bil[nbil] = k
            nbil += 1
        else:
            loc[k] = -1
        for side in range(2):
            body = ra[k] if side == 0 else rb[k]
            if body >= 0 and _live_side(MiJ, k, side):
                brow[ne] = k
                bside[ne] = side
                bnext[ne] = bhead[body]
                bhead[body] = ne
                ne += 1
    work = 0.0
    for p in range(nbil):
        i = bil[p]
        # the envelope: the first bilateral row that shares a body with row i
        fp = p
        for si in range(2):
            body = ra[i] if si == 0 else rb[i]
            if body < 0 or not _live_side(MiJ, i, si):
                continue
            e = bhead[body]
            while e >= 0:
                q = loc[brow[e]]
                if q >= 0 and q < fp:
                    fp = q
                e = bnext[e]
        first[p] = fp
        work += (p - fp + 1.0) ** 2
    ok = work <= max_work
    if ok and nbil > 0:
        tr = 0.0
        for p in range(nbil):
            i = bil[p]
            fp = first[p]
            for q in range(fp, p + 1):
                H[p, q] = 0.0
            v = b[i]
            for si in range(2):
                body = ra[i] if si == 0 else rb[i]
                if body < 0:
                    continue
                for c in range(6):
                    v += J[i, 6 * si + c] * vfree[body, c]
                if not _live_side(MiJ, i, si):
                    continue
                e = bhead[body]
                while e >= 0:
                    j = brow[e]
                    q = loc[j]
                    if q <= p:
                        o = 6 * bside[e]
                        h = 0.0
                        for c in range(6):
                            h += J[i, 6 * si + c] * MiJ[j, o + c]
                        if q >= 0:
                            H[p, q] += h
                        else:
                            v += h * lo[j]
                    e = bnext[e]
            vec[p] = -v
            H[p, p] += E[i]
            tr += H[p, p]
        reg = 1e-13 * max(tr / nbil, 1e-300)
        for p in range(nbil):
            H[p, p] += reg
        ok = _envelope_cholesky(H, nbil, first)
        if ok:
            _envelope_solve(H, nbil, first, vec)
    for e in range(ne):
        k = brow[e]
        body = ra[k] if bside[e] == 0 else rb[k]
        bhead[body] = -1
    if not ok:
        return False
    for a in range(n):
        k = rows[a]
        if loc[k] < 0:
            gamma[k] = lo[k]
        else:
            gamma[k] = vec[loc[k]]
    return True


@njit(cache=True)
def solve_ccp_exact_islands(solver, nr, nb, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag, gamma,
                            vfree, vout, max_iter, tol, omega, nx, label, xorder, xstart, H, vec,
                            iw, loc, bhead, rest, rJ, rf, rk, max_work):
    """:func:`solve_ccp` with the ``nx`` joint-only islands of :func:`plan_exact_islands` solved
    exactly (:func:`_solve_equality_island`, with its work arrays ``H`` ... ``bhead``; one whose
    rows are dependent or whose factor is above ``max_work`` goes back to the others) and the other rows, gathered into the work arrays
    ``rest`` (int [3, nr]: ra, rb, the row numbers), ``rJ`` ([2, nr, 12]: J, MiJ), ``rf`` ([7, nr]:
    b, E, μ, lo, hi, diag, γ) and ``rk`` (kind), by the iterative ``solver`` as before.  Returns the iterative solver's iterations and
    the larger residual (an exact island's: its largest bilateral constraint velocity)."""
    for q in range(nx):
        rows = xorder[xstart[q]:xstart[q + 1]]
        if not _solve_equality_island(rows, ra, rb, J, MiJ, b, E, kind, lo, gamma, vfree, H, vec,
                                      iw, loc, bhead, max_work):
            for a in range(rows.shape[0]):
                label[rows[a]] = -1
    m = 0
    for k in range(nr):
        if label[k] < 0:
            rest[0, m] = ra[k]
            rest[1, m] = rb[k]
            rest[2, m] = k
            for c in range(12):
                rJ[0, m, c] = J[k, c]
                rJ[1, m, c] = MiJ[k, c]
            rf[0, m] = b[k]
            rf[1, m] = E[k]
            rf[2, m] = mu[k]
            rf[3, m] = lo[k]
            rf[4, m] = hi[k]
            rf[5, m] = gdiag[k]
            rf[6, m] = gamma[k]
            rk[m] = kind[k]
            m += 1
    it = 0
    res = 0.0
    if m > 0:
        it, res = solve_ccp(solver, m, nb, rest[0], rest[1], rJ[0], rJ[1], rf[0], rf[1], rk, rf[2],
                            rf[3], rf[4], rf[5], rf[6], vfree, vout, max_iter, tol, omega)
        for p in range(m):
            gamma[rest[2, p]] = rf[6, p]
    else:
        vout[:, :] = vfree
    # the islands' impulses (their bodies are no other row's), then their residual
    for k in range(nr):
        if label[k] < 0:
            continue
        xk = gamma[k]
        if xk == 0.0:
            continue
        for side in range(2):
            body = ra[k] if side == 0 else rb[k]
            if body >= 0:
                for c in range(6):
                    vout[body, c] += MiJ[k, 6 * side + c] * xk
    for k in range(nr):
        if label[k] < 0 or kind[k] != BILATERAL:
            continue
        u = b[k] + E[k] * gamma[k]
        for side in range(2):
            body = ra[k] if side == 0 else rb[k]
            if body >= 0:
                for c in range(6):
                    u += J[k, 6 * side + c] * vout[body, c]
        if abs(u) > res:
            res = abs(u)
    return it, res


class _ExactWork:
    """Work arrays of :func:`solve_iterative`'s exact islands, kept on their owner (a System) and
    grown when the rows or the largest island outgrow them: a step allocates none of them."""

    def __init__(self):
        self.cap = -1
        self.hcap = -1
        self.bhead = np.zeros(0, np.int64)

    def rows(self, nr):
        if nr > self.cap:
            n = max(nr, 2 * self.cap, 64)
            self.cap = n
            self.label = np.empty(n, np.int64)
            self.xorder = np.empty(n, np.int64)
            self.xstart = np.empty(n + 1, np.int64)
            self.rest = np.empty((3, n), np.int32)
            self.rJ = np.empty((2, n, 12))
            self.rf = np.empty((7, n))
            self.rk = np.empty(n, np.int8)
            self.loc = np.empty(n, np.int64)
        return self

    def bodies(self, nb):
        if nb > self.bhead.shape[0]:
            self.bhead = np.full(nb, -1, np.int64)
        return self

    def dense(self, n):
        if n > self.hcap:
            self.hcap = n
            self.H = np.empty((n, n))
            self.vec = np.empty(n)
            self.iw = np.empty((5, 2 * n), np.int64)
        return self


def solve_iterative(solver, nr, nb, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag, gamma, vfree,
                    vout, max_iter, tol, omega, owner=None, exact_joints=False):
    """:func:`solve_ccp`, then, for PSOR, the creep check of ``owner`` (a System):
    :func:`_psor_creep_check`.  With ``exact_joints`` the islands whose rows are all equalities
    (joints, springs' and motors' compliance rows: a linear system) of at most
    EXACT_JOINT_MAX_ROWS rows (and an envelope factor of at most EXACT_JOINT_MAX_WORK) are solved
    exactly (:func:`solve_ccp_exact_islands`, as ``direct`` solves them) and only the others
    iteratively; a scene without such an island (contacts in
    every island) takes :func:`solve_ccp` as it is."""
    nx = 0
    if exact_joints and nr > 0:
        W = getattr(owner, "_exact_work", None) if owner is not None else None
        if W is None:
            W = _ExactWork()
            if owner is not None:
                owner._exact_work = W
        W.rows(nr).bodies(nb)
        nx, _nxr, big = plan_exact_islands(nr, nb, ra, rb, MiJ, kind, lo, hi, EXACT_JOINT_MAX_ROWS,
                                           W.label, W.xorder, W.xstart)
    if nx:
        W.dense(big)
        it, res = solve_ccp_exact_islands(solver, nr, nb, ra, rb, J, MiJ, b, E, kind, mu, lo, hi,
                                          gdiag, gamma, vfree, vout, max_iter, tol, omega, nx,
                                          W.label, W.xorder, W.xstart, W.H, W.vec, W.iw, W.loc,
                                          W.bhead, W.rest, W.rJ, W.rf, W.rk,
                                          EXACT_JOINT_MAX_WORK)
    else:
        it, res = solve_ccp(solver, nr, nb, ra, rb, J, MiJ, b, E, kind, mu, lo, hi, gdiag, gamma,
                            vfree, vout, max_iter, tol, omega)
    if solver == SOLVER_PSOR and owner is not None:
        _psor_creep_check(owner, res)
    return it, res

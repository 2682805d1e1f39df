"""The lumped-mass mooring line of MoorDyn (Hall & Goupee 2015, Ocean Engineering 104, 590-603) as
DualSPHysics's MoorDynPlus (Domínguez et al. 2019, Coastal Engineering 153) integrates it: numba
kernels over every line of a case at once (structure of arrays; nodes of all lines concatenated).

A line of unstretched length L is N segments of l = L/N between N + 1 nodes; node 0 is its anchor
end and node N its fairlead end. Each segment i (nodes i, i + 1; r = R_{i+1} − R_i, ℓ = |r|)
carries

    T_i  = EA (ℓ/l − 1) r/ℓ   when ℓ > l (no compression)                                     (1)
    Td_i = c (dℓ/dt / l) r/ℓ,  c = BA, or ζ l √(EA m) for BA = −ζ < 0                        (2)

and each node i, with Q_i the unit tangent (R_{i+1} − R_{i−1}; one-sided at the ends), its
relative velocity v = −Ṙ_i (still water) split into v_q = (v·Q)Q and v_p = v − v_q, and F_s the
submergence of an adjacent segment (1 both nodes below the free surface, 0 both above, ½ across):

    W  = −g Σ_s ½ A l (ρ − F_s ρ_w) e_z                        weight and buoyancy
    Dp = ½ ρ_w Cdn D (Σ_s ½ F_s l) |v_p| v_p                   transverse drag
    Dq = ½ ρ_w Cdt π D (Σ_s ½ F_s l) |v_q| v_q                 tangential drag
    B_z = [kBot (z_bed − z) − cBot ż] S,  S = Σ_s ½ D l,  for z < z_bed    seabed
    B_xy = −F_fr u/|u|,  u = (ẋ, ẏ),  F_fr = μ fricDamp |u|, or μ |B_z| once
           that exceeds s_μ μ |B_z| (MoorDynPlus's rule)                seabed friction
    F_i = T_i − T_{i−1} + Td_i − Td_{i−1} + W + Dp + Dq + B                                      (3)

(the sums over the node's one or two segments). Its mass matrix is
M_i = m_i I + ρ_w v_i [Can (I − QQᵀ) + Cat QQᵀ] with m_i = Σ_s ½ ρ A l and v_i = Σ_s ½ F_s A l,
inverted in closed form (Sherman-Morrison: M = a I + b QQᵀ, M⁻¹ = (I − b/(a + b) QQᵀ)/a).

The internal nodes 1..N−1 are integrated by the midpoint rule (RK2), as MoorDynPlus, in
``nsub`` sub-steps of a coupling step; an end node is fixed (an anchor) or follows its body on
the straight path between the body's poses at the step's start and end (a vessel end). The
force a line puts on its body is F of that end node (3): the last segment's tension and damping,
half a segment's wet weight, that node's drag and seabed contact (MoorDynPlus's connection force).
Nothing here allocates inside the sub-step loop or writes files.

Deviations from MoorDynPlus (its 2025 source): the submergence test uses the free surface's z
(MoorDynPlus compares with z = 0 whatever ``freesurface`` says); the end nodes' seabed area is
½ D l (MoorDynPlus leaves D out at node 0 and reads past its segment array at node N); a line's
end tension is that of its end segment, |T + Td| (MoorDynPlus's takes the end node's net force
less a further weight term); the force returned is the one at the step's end, not at the start of
its last sub-step.
"""
from __future__ import annotations

import math

import numpy as np

from ..sph import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit

#: end kinds (``end_kind``)
FIXED, VESSEL, CONNECT = 0, 1, 2
#: per-connect parameters, columns of the ``cprm`` array: mass M, volume V, drag area CdA, added-mass Ca
C_M, C_V, C_CDA, C_CA = range(4)
NCPRM = 4

#: per-line parameters, columns of the ``prm`` array
P_L, P_EA, P_C, P_D, P_A, P_RHO, P_CAN, P_CAT, P_CDN, P_CDT, P_ZBED, P_BREAK = range(12)
NPRM = 12
#: global parameters, entries of ``glob``
G_RHOW, G_G, G_KBOT, G_CBOT, G_MU, G_FRICDAMP, G_STATDYN, G_ZFS, G_CDSCALE = range(9)
NGLOB = 9


@njit(cache=True)
def _submerged(za, zb, zfs):
    """MoorDynPlus's segment submergence: 1 below the free surface, 0 above, ½ across it."""
    if za <= zfs and zb < zfs:
        return 1.0
    if za > zfs and zb > zfs:
        return 0.0
    return 0.5


@njit(cache=True)
def _set_ends(t, t0, first, last, end_kind, end_p0, end_v, end_conn, cpos, cvel, broken, pos, vel):
    """The end nodes of every unbroken line at time t: a fixed end where it was, a vessel end at
    p0 + v (t − t0) with velocity v, a connect end at its connect node (``cpos``, ``cvel``); a
    broken line's nodes stay where it broke."""
    for k in range(first.shape[0]):
        if broken[k]:
            continue
        for e in range(2):
            j = first[k] if e == 0 else last[k]
            if end_kind[k, e] == VESSEL:
                for d in range(3):
                    pos[j, d] = end_p0[k, e, d] + end_v[k, e, d] * (t - t0)
                    vel[j, d] = end_v[k, e, d]
            elif end_kind[k, e] == CONNECT:
                c = end_conn[k, e]
                for d in range(3):
                    pos[j, d] = cpos[c, d]
                    vel[j, d] = cvel[c, d]
            else:
                for d in range(3):
                    vel[j, d] = 0.0


@njit(cache=True)
def connect_accelerations(pos, first, last, end_kind, end_conn, broken, prm, glob, fnet, cvel, cprm, cmat, cfor,
                          cacc):
    """The acceleration of every free connect node (MoorDyn's Connection, as MoorDynPlus's
    IConnection): its force, the eq. (3) forces of the line end nodes it holds (each with its half
    segment's weight, drag and seabed contact) plus its own (V ρ_w − M) g upwards and drag
    −½ ρ_w CdA |v_i| v_i per component (MoorDyn's form), over its mass matrix, (M + ρ_w V Ca) I plus
    each end node's m_i I + ρ_w v_i [Can (I − QQᵀ) + Cat QQᵀ] (Q along the end segment); solved as a
    3 × 3 system (``cmat``, ``cfor``: work arrays). A broken line gives its connects nothing; a
    connect without mass (every line of a massless connect broken) stays at rest.

    Deviations from MoorDynPlus 2025: its (M + ρ_w V Ca) lands on all nine entries of the matrix
    (a scalar added to a matrix: a sideways kick under a clump weight), here on the diagonal as
    MoorDyn and MoorDynPlus 2020; the end forces and matrices are this evaluation's (MoorDynPlus's
    lag one evaluation, and its acceleration is 0 at t = 0 exactly); a broken line's frozen end
    force and mass are not kept."""
    rho_w, g, zfs = glob[G_RHOW], glob[G_G], glob[G_ZFS]
    nc = cacc.shape[0]
    for c in range(nc):
        for d in range(3):
            cfor[c, d] = 0.0
            for d2 in range(3):
                cmat[c, d, d2] = 0.0
    for k in range(first.shape[0]):
        if broken[k]:
            continue
        l, area, rho, can, cat = prm[k, P_L], prm[k, P_A], prm[k, P_RHO], prm[k, P_CAN], prm[k, P_CAT]
        for e in range(2):
            if end_kind[k, e] != CONNECT:
                continue
            c = end_conn[k, e]
            j = first[k] if e == 0 else last[k]
            i = j + 1 if e == 0 else j - 1          # the end segment's other node
            qx, qy, qz = pos[i, 0] - pos[j, 0], pos[i, 1] - pos[j, 1], pos[i, 2] - pos[j, 2]
            qn = math.sqrt(qx * qx + qy * qy + qz * qz)
            q = (qx / qn, qy / qn, qz / qn)
            m = 0.5 * l * rho * area
            vol = 0.5 * _submerged(pos[j, 2], pos[i, 2], zfs) * l * area
            for d in range(3):
                cfor[c, d] += fnet[j, d]
                cmat[c, d, d] += m + rho_w * vol * can
                for d2 in range(3):
                    cmat[c, d, d2] += rho_w * vol * (cat - can) * q[d] * q[d2]
    for c in range(nc):
        mass, vol, cda, ca = cprm[c, C_M], cprm[c, C_V], cprm[c, C_CDA], cprm[c, C_CA]
        for d in range(3):
            cmat[c, d, d] += mass + rho_w * vol * ca
            cfor[c, d] -= 0.5 * rho_w * cda * abs(cvel[c, d]) * cvel[c, d]
        cfor[c, 2] += (vol * rho_w - mass) * g
        a = cmat[c]
        det = (a[0, 0] * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]) - a[0, 1] * (a[1, 0] * a[2, 2] - a[1, 2] * a[2, 0])
               + a[0, 2] * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]))
        if det <= 0.0:
            for d in range(3):
                cacc[c, d] = 0.0
            continue
        f0, f1, f2 = cfor[c, 0], cfor[c, 1], cfor[c, 2]
        # Cramer's rule
        cacc[c, 0] = (f0 * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]) - a[0, 1] * (f1 * a[2, 2] - a[1, 2] * f2)
                      + a[0, 2] * (f1 * a[2, 1] - a[1, 1] * f2)) / det
        cacc[c, 1] = (a[0, 0] * (f1 * a[2, 2] - a[1, 2] * f2) - f0 * (a[1, 0] * a[2, 2] - a[1, 2] * a[2, 0])
                      + a[0, 2] * (a[1, 0] * f2 - f1 * a[2, 0])) / det
        cacc[c, 2] = (a[0, 0] * (a[1, 1] * f2 - f1 * a[2, 1]) - a[0, 1] * (a[1, 0] * f2 - f1 * a[2, 0])
                      + f0 * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0])) / det


@njit(cache=True)
def line_forces(pos, vel, first, last, prm, glob, broken, fnet, acc, seg_t, seg_len):
    """Eq. (3) at every node of every unbroken line into ``fnet`` and the internal nodes'
    accelerations M⁻¹ F into ``acc``; each segment's |T + Td| into ``seg_t`` and stretched length
    into ``seg_len`` (segment i of a line at row first + i)."""
    rho_w, g = glob[G_RHOW], glob[G_G]
    kbot, cbot, mu = glob[G_KBOT], glob[G_CBOT], glob[G_MU]
    fricdamp, statdyn, zfs, cdscale = glob[G_FRICDAMP], glob[G_STATDYN], glob[G_ZFS], glob[G_CDSCALE]
    for k in range(first.shape[0]):
        if broken[k]:
            continue
        l, ea, c, dia, area, rho = prm[k, P_L], prm[k, P_EA], prm[k, P_C], prm[k, P_D], prm[k, P_A], prm[k, P_RHO]
        can, cat = prm[k, P_CAN], prm[k, P_CAT]
        cdn, cdt, zbed = prm[k, P_CDN] * cdscale, prm[k, P_CDT] * cdscale, prm[k, P_ZBED]
        a, b = first[k], last[k]
        for j in range(a, b + 1):
            for d in range(3):
                fnet[j, d] = 0.0
        # segments: tension and damping, onto both nodes
        for j in range(a, b):
            rx = pos[j + 1, 0] - pos[j, 0]
            ry = pos[j + 1, 1] - pos[j, 1]
            rz = pos[j + 1, 2] - pos[j, 2]
            ln = math.sqrt(rx * rx + ry * ry + rz * rz)
            ldot = (rx * (vel[j + 1, 0] - vel[j, 0]) + ry * (vel[j + 1, 1] - vel[j, 1])
                    + rz * (vel[j + 1, 2] - vel[j, 2])) / ln
            f = c * ldot / l
            if ln > l:
                f += ea * (ln / l - 1.0)
            seg_t[j] = abs(f)
            seg_len[j] = ln
            fx, fy, fz = f * rx / ln, f * ry / ln, f * rz / ln
            fnet[j, 0] += fx
            fnet[j, 1] += fy
            fnet[j, 2] += fz
            fnet[j + 1, 0] -= fx
            fnet[j + 1, 1] -= fy
            fnet[j + 1, 2] -= fz
        # nodes: weight and buoyancy, drag, seabed; then the accelerations of the internal ones
        for j in range(a, b + 1):
            lo = j - 1 if j > a else j
            hi = j + 1 if j < b else j
            qx = pos[hi, 0] - pos[lo, 0]
            qy = pos[hi, 1] - pos[lo, 1]
            qz = pos[hi, 2] - pos[lo, 2]
            qn = math.sqrt(qx * qx + qy * qy + qz * qz)
            qx, qy, qz = qx / qn, qy / qn, qz / qn
            wet = 0.0        # Σ ½ A l (ρ − F ρ_w)
            sub = 0.0        # Σ ½ F l
            half = 0.0       # Σ ½ l
            if j > a:
                fs = _submerged(pos[j - 1, 2], pos[j, 2], zfs)
                wet += 0.5 * area * l * (rho - fs * rho_w)
                sub += 0.5 * fs * l
                half += 0.5 * l
            if j < b:
                fs = _submerged(pos[j, 2], pos[j + 1, 2], zfs)
                wet += 0.5 * area * l * (rho - fs * rho_w)
                sub += 0.5 * fs * l
                half += 0.5 * l
            fnet[j, 2] -= g * wet
            vx, vy, vz = -vel[j, 0], -vel[j, 1], -vel[j, 2]
            vq = vx * qx + vy * qy + vz * qz
            vqx, vqy, vqz = vq * qx, vq * qy, vq * qz
            vpx, vpy, vpz = vx - vqx, vy - vqy, vz - vqz
            vp = math.sqrt(vpx * vpx + vpy * vpy + vpz * vpz)
            dp = 0.5 * rho_w * cdn * dia * sub * vp
            dq = 0.5 * rho_w * cdt * math.pi * dia * sub * abs(vq)
            fnet[j, 0] += dp * vpx + dq * vqx
            fnet[j, 1] += dp * vpy + dq * vqy
            fnet[j, 2] += dp * vpz + dq * vqz
            if pos[j, 2] < zbed:
                bz = (kbot * (zbed - pos[j, 2]) - cbot * vel[j, 2]) * dia * half
                fnet[j, 2] += bz
                if mu > 0.0:
                    u = math.sqrt(vel[j, 0] * vel[j, 0] + vel[j, 1] * vel[j, 1])
                    if u > 0.0:
                        ffr = u * mu * fricdamp
                        fmax = abs(bz) * mu
                        if ffr > statdyn * fmax:
                            ffr = fmax
                        fnet[j, 0] -= ffr * vel[j, 0] / u
                        fnet[j, 1] -= ffr * vel[j, 1] / u
            if a < j < b:
                m = half * rho * area
                vol = sub * area
                aa = m + rho_w * vol * can
                bb = rho_w * vol * (cat - can)
                fq = fnet[j, 0] * qx + fnet[j, 1] * qy + fnet[j, 2] * qz
                s = bb / (aa + bb) * fq
                acc[j, 0] = (fnet[j, 0] - s * qx) / aa
                acc[j, 1] = (fnet[j, 1] - s * qy) / aa
                acc[j, 2] = (fnet[j, 2] - s * qz) / aa


@njit(cache=True)
def _check_breaks(first, last, prm, broken, seg_t) -> int:
    """Lines whose end segment's tension reached their break tension (> 0) are marked broken;
    returns how many broke now."""
    n = 0
    for k in range(first.shape[0]):
        bt = prm[k, P_BREAK]
        if broken[k] or bt <= 0.0:
            continue
        if seg_t[first[k]] >= bt or seg_t[last[k] - 1] >= bt:
            broken[k] = True
            n += 1
    return n


@njit(cache=True)
def advance_lines(t0, dt, nsub, pos, vel, first, last, end_kind, end_p0, end_v, prm, glob, broken,
                  fnet, acc, seg_t, seg_len, pos_h, vel_h, end_conn, cpos, cvel, cprm, cwork) -> int:
    """``nsub`` midpoint (RK2) sub-steps of dt/nsub from t0 for the internal nodes of every unbroken
    line and every connect node (``cpos``, ``cvel``; ``cprm``: :data:`C_M`...; ``cwork``: the
    connects' work arrays of :func:`empty_connect_work`), the ends set by :func:`_set_ends`; then
    eq. (3) at the step's end (``fnet``, ``seg_t``, ``seg_len``) and the connects' accelerations.
    ``pos_h``, ``vel_h``: work arrays shaped as ``pos``. Returns the number of lines that broke
    (their nodes stay where they were)."""
    cpos_h, cvel_h, cacc, cmat, cfor = cwork
    h = dt / nsub if nsub > 0 else 0.0
    nbroke = 0
    nc = cpos.shape[0]
    for s in range(nsub):
        t = t0 + s * h
        _set_ends(t, t0, first, last, end_kind, end_p0, end_v, end_conn, cpos, cvel, broken, pos, vel)
        line_forces(pos, vel, first, last, prm, glob, broken, fnet, acc, seg_t, seg_len)
        nbroke += _check_breaks(first, last, prm, broken, seg_t)
        if nc:
            connect_accelerations(pos, first, last, end_kind, end_conn, broken, prm, glob, fnet, cvel, cprm, cmat,
                                  cfor, cacc)
        for k in range(first.shape[0]):
            for j in range(first[k], last[k] + 1):
                for d in range(3):
                    if first[k] < j < last[k] and not broken[k]:
                        pos_h[j, d] = pos[j, d] + 0.5 * h * vel[j, d]
                        vel_h[j, d] = vel[j, d] + 0.5 * h * acc[j, d]
                    else:
                        pos_h[j, d] = pos[j, d]
                        vel_h[j, d] = vel[j, d]
        for c in range(nc):
            for d in range(3):
                cpos_h[c, d] = cpos[c, d] + 0.5 * h * cvel[c, d]
                cvel_h[c, d] = cvel[c, d] + 0.5 * h * cacc[c, d]
        _set_ends(t + 0.5 * h, t0, first, last, end_kind, end_p0, end_v, end_conn, cpos_h, cvel_h, broken, pos_h,
                  vel_h)
        line_forces(pos_h, vel_h, first, last, prm, glob, broken, fnet, acc, seg_t, seg_len)
        nbroke += _check_breaks(first, last, prm, broken, seg_t)
        if nc:
            connect_accelerations(pos_h, first, last, end_kind, end_conn, broken, prm, glob, fnet, cvel_h, cprm,
                                  cmat, cfor, cacc)
        for k in range(first.shape[0]):
            if broken[k]:
                continue
            for j in range(first[k] + 1, last[k]):
                for d in range(3):
                    pos[j, d] += h * vel_h[j, d]
                    vel[j, d] += h * acc[j, d]
        for c in range(nc):
            for d in range(3):
                cpos[c, d] += h * cvel_h[c, d]
                cvel[c, d] += h * cacc[c, d]
    _set_ends(t0 + dt, t0, first, last, end_kind, end_p0, end_v, end_conn, cpos, cvel, broken, pos, vel)
    line_forces(pos, vel, first, last, prm, glob, broken, fnet, acc, seg_t, seg_len)
    nbroke += _check_breaks(first, last, prm, broken, seg_t)
    if nc:
        connect_accelerations(pos, first, last, end_kind, end_conn, broken, prm, glob, fnet, cvel, cprm, cmat, cfor,
                              cacc)
    return nbroke


def auto_time_step(length: float, segments: int, ea: float, rho: float, rho_w: float, area: float) -> float:
    """MoorDynPlus's ``dtM auto``: 2π/(100 ω) with ω = (2N/L) √(EA / (|ρ − ρ_w| A)), a hundredth of
    the period of the line's highest axial mode taken with its wet mass (its mass ρ A for a line as
    dense as the water, where MoorDynPlus's ω is infinite)."""
    mw = abs(rho - rho_w) * area or rho * area
    omega = (2.0 * segments / length) * math.sqrt(ea / mw)
    return 2.0 * math.pi / (100.0 * omega)


def damping_coefficient(ba: float, seg_length: float, ea: float, mass: float) -> float:
    """Eq. (2): BA ≥ 0 is the coefficient (N s); BA = −ζ < 0 gives ζ l √(EA m)."""
    return float(ba) if ba >= 0 else -float(ba) * seg_length * math.sqrt(ea * mass)


def empty_work(nnodes: int) -> dict:
    """The kernels' work arrays for ``nnodes`` nodes in all."""
    return {name: np.zeros((nnodes, 3)) for name in ("fnet", "acc", "pos_h", "vel_h")} | {
        "seg_t": np.zeros(nnodes), "seg_len": np.zeros(nnodes)}


def empty_connect_work(nconnects: int) -> tuple:
    """:func:`advance_lines`'s ``cwork`` for ``nconnects`` connect nodes: (pos_h, vel_h, acc, mass
    matrices, forces)."""
    return (np.zeros((nconnects, 3)), np.zeros((nconnects, 3)), np.zeros((nconnects, 3)),
            np.zeros((nconnects, 3, 3)), np.zeros((nconnects, 3)))


@njit(cache=True)
def vessel_positions(centre, quat, body, local, out):
    """``out[i]`` = centre[b] + R(quat[b]) local[i] of each vessel connection i on body b = body[i]."""
    for i in range(body.shape[0]):
        b = body[i]
        w, x, y, z = quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3]
        u0, u1, u2 = local[i, 0], local[i, 1], local[i, 2]
        t0 = 2.0 * (y * u2 - z * u1)
        t1 = 2.0 * (z * u0 - x * u2)
        t2 = 2.0 * (x * u1 - y * u0)
        out[i, 0] = centre[b, 0] + u0 + w * t0 + (y * t2 - z * t1)
        out[i, 1] = centre[b, 1] + u1 + w * t1 + (z * t0 - x * t2)
        out[i, 2] = centre[b, 2] + u2 + w * t2 + (x * t1 - y * t0)


@njit(cache=True)
def body_loads(pos, fnet, node, body, lift, broken_end, centre, ramp, F, T):
    """F[b], T[b]: the sum over the vessel connections on body b of their node's force ``fnet``
    plus ``lift`` (the connection's (V ρ_w − M) g, upwards), times ``ramp``, and its moment about
    ``centre[b]``; a connection of a broken line gives nothing."""
    F[:] = 0.0
    T[:] = 0.0
    for i in range(node.shape[0]):
        if broken_end[i]:
            continue
        b, j = body[i], node[i]
        fx, fy, fz = ramp * fnet[j, 0], ramp * fnet[j, 1], ramp * (fnet[j, 2] + lift[i])
        rx, ry, rz = pos[j, 0] - centre[b, 0], pos[j, 1] - centre[b, 1], pos[j, 2] - centre[b, 2]
        F[b, 0] += fx
        F[b, 1] += fy
        F[b, 2] += fz
        T[b, 0] += ry * fz - rz * fy
        T[b, 1] += rz * fx - rx * fz
        T[b, 2] += rx * fy - ry * fx

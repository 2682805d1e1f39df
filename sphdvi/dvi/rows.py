"""Row builders: joints (generic mate), force elements as compliance/boxed rows,
imposed velocities and frictional contacts.  All are numba kernels that append
rows to preallocated arrays and return the new row count.

Angular Jacobian blocks are first written in the world frame (``ρ·ω_world``) and
converted to the body frame (``Rᵀρ``) because bodies store ω in their own frame.
"""
import math

import numpy as np
from numba import njit

from ._math import cross, mat_to_rotvec
from ._vec import mat_t_vec, mat_vec, row3, v_cross, v_dot, v_scale, v_sub
from .solvers import BILATERAL, BOXED, FRIC_N, FRIC_T, UNILATERAL

LINK_CONTACT = -1
LINK_IMPOSED = -2


SPRING_AUTO = 0
SPRING_IMPLICIT = 1
SPRING_EXPLICIT = 2

# Explicit (symplectic-Euler) treatment of a spring-damper row is kept where it
# is stable with a wide margin: ω h ≤ 0.2 and c w h ≤ 0.2 (w = J M⁻¹ Jᵀ); the
# explicit limits are ω h < 2 and c w h < 2.
EXPLICIT_OMEGA_H = 0.2
EXPLICIT_DAMP_H = 0.2


@njit(cache=True)
def _row_mobility(k, ra, rb, J, invm3, invI):
    """w = J M⁻¹ Jᵀ of row k (DOF-masked inverse mass, body-frame inertia)."""
    w = 0.0
    for side in range(2):
        i = ra[k] if side == 0 else rb[k]
        if i < 0:
            continue
        o = 6 * side
        for c in range(3):
            w += J[k, o + c] * J[k, o + c] * invm3[i, c]
        for c in range(3):
            s = 0.0
            for m in range(3):
                s += invI[i, c, m] * J[k, o + 3 + m]
            w += J[k, o + 3 + c] * s
    return w


@njit(cache=True)
def _row_speed(k, ra, rb, J, vel6):
    """J v of row k at the velocities vel6 (linear world, angular body frame)."""
    s = 0.0
    for side in range(2):
        i = ra[k] if side == 0 else rb[k]
        if i < 0:
            continue
        o = 6 * side
        for c in range(6):
            s += J[k, o + c] * vel6[i, c]
    return s


@njit(cache=True)
def _soft_row(k, h, kk, cc, err, f0, scheme, vel6, invm3, invI, ra, rb, J, b, E, kind, lo, hi):
    """Spring-damper force ``f = f0 − k·err − c·q̇`` on row k.

    Implicit (backward Euler, unconditionally stable): the compliance row
    ``E = 1/(h(hk + c))``, ``b = (k·err − f0)/(hk + c)``.  Explicit
    (symplectic Euler, as Chrono's ChLinkTSDA without Jacobians): the impulse
    is fixed at ``γ = h f(q_n, q̇_n)`` by a boxed row with ``lo = hi = γ``; it
    has no numerical damping, so a soft spring keeps its amplitude.  ``auto``
    takes the explicit form where it is stable with a wide margin."""
    explicit = scheme == SPRING_EXPLICIT
    if scheme == SPRING_AUTO:
        w = _row_mobility(k, ra, rb, J, invm3, invI)
        explicit = h * h * kk * w <= EXPLICIT_OMEGA_H ** 2 and h * cc * w <= EXPLICIT_DAMP_H
    if explicit:
        g = h * (f0 - kk * err - cc * _row_speed(k, ra, rb, J, vel6))
        kind[k] = BOXED
        lo[k] = g
        hi[k] = g
        return
    den = h * kk + cc
    E[k] = 1.0 / (h * den)
    b[k] = (kk * err - f0) / den

MOTOR_NONE = 0
MOTOR_POSITION = 1
MOTOR_SPEED = 2


@njit(cache=True)
def _body_frame(i, pos, Rb):
    """Pose of body i (world pose for i = -1)."""
    if i < 0:
        return np.zeros(3), np.eye(3)
    return pos[i].copy(), Rb[i].copy()


@njit(cache=True)
def _write_row(k, a, bb, lin_a, angw_a, lin_b, angw_b, Ra, Rb_, ra, rb, J):
    """Store row k; angular parts converted to each body's frame."""
    ra[k] = a
    rb[k] = bb
    for c in range(3):
        J[k, c] = lin_a[c]
        J[k, 6 + c] = lin_b[c]
        sa = 0.0
        sb = 0.0
        for m in range(3):
            sa += Ra[m, c] * angw_a[m]
            sb += Rb_[m, c] * angw_b[m]
        J[k, 3 + c] = sa
        J[k, 9 + c] = sb


@njit(cache=True)
def _clear_row(k, b, E, kind, lo, hi, mu, rlink, Cpos):
    b[k] = 0.0
    E[k] = 0.0
    kind[k] = BILATERAL
    lo[k] = -1e300
    hi[k] = 1e300
    mu[k] = 0.0
    rlink[k] = 0
    Cpos[k] = np.nan  # position error is defined only on rigid rows


@njit(cache=True)
def _wrap_angle(a):
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit(cache=True)
def _locked_rotation(a, nfree_rot, mask, Q1, Q2):
    """(C, world Jacobian axis ρ, ``Ċ = ρ·(ω1 − ω2)``) of the locked rotation about axis a of
    the rotation frame (Q1 on body 1, Q2 on body 2, world columns).

    One free axis f (hinge, cylindrical, hinged slider, point-line with one rotation):
    ``C = s Q1[:, f]·Q2[:, o]`` with o the third axis and s = ±1 so that ρ ≈ +Q2[:, a].  Body 1's
    free axis does not move under the free rotation, so the two rows' axes ``s Q1[:, f]×Q2[:, o]``
    stay two perpendicular axes of frame 2 at every angle about f (the dot-1 pairs ``y1·z2``,
    ``z1·x2`` of a z hinge have the same axis x1 = y2 at ±90°: a singular pair; Chrono's
    ChLinkMateGeneric::Update uses the relative quaternion's vector part, independent too).
    Otherwise (all locked, or one locked) the dot-1 rows ``y1·z2``, ``z1·x2``, ``x1·y2``: they have
    no singular pose on the joint's motion (all locked: axes x, y, z at the locked pose, dependent only
    ~90° away from it; one locked: |ρ| = 1 wherever C = 0)."""
    if nfree_rot == 1:
        f = 0
        for k in range(3):
            if mask[3 + k] == 0:
                f = k
        o = 3 - a - f
        sg = 1.0 if (o - f) % 3 == 1 else -1.0      # e_f × e_o = sg e_a
        al = Q1[:, f].copy()
        be = Q2[:, o].copy()
    else:
        sg = 1.0
        al = Q1[:, (a + 1) % 3].copy()
        be = Q2[:, (a + 2) % 3].copy()
    q = 0.0
    for c in range(3):
        q += al[c] * be[c]
    return sg * q, cross(al, be) * sg


@njit(cache=True)
def build_mate_rows(nr, h, vrec, pos, Rb,
                    m_b1, m_b2, m_p1, m_p2, m_T1, m_T2, m_Q1, m_Q2, m_mask,
                    m_k, m_c, m_rest, m_mmode, m_mval, m_mdval, m_angle, m_lid,
                    m_P1w, scheme, vel6, invm3, invI,
                    ra, rb, J, b, E, kind, lo, hi, mu, rlink, Cpos):
    """Generic mate (Chrono ChLinkMateGeneric semantics, own derivation).

    DOF k = 0..2: translation of marker 1 along axis k of the translation frame
    of body 2, ``C = e_k·(P1 − P2)``.  DOF k = 3..5: rotation about axis k of the
    rotation frame, locked by :func:`_locked_rotation` (with one free rotation f: ``±f1·o2``, o the
    third axis; otherwise the dot-1 rows ``y1·z2``, ``z1·x2``, ``x1·y2``).
    A constrained DOF gives a stabilised bilateral row ``b = clamp(C/h, ±v_rec)``.
    A free DOF gets a motor row (speed: ``b = −ω*(t+h)``; position:
    ``b = clamp((q − q*(t))/h, ±v_rec) − (q*(t+h) − q*(t))/h``) or, with stiffness k and
    damping c, a spring-damper row (:func:`_soft_row`: implicit compliance
    ``E = 1/(h(hk + c))``, ``b = k(q − q0)/(hk + c)``, or explicit)."""
    nm = m_b1.shape[0]
    for m in range(nm):
        i1 = m_b1[m]
        i2 = m_b2[m]
        x1, R1 = _body_frame(i1, pos, Rb)
        x2, R2 = _body_frame(i2, pos, Rb)
        P1 = x1 + R1 @ m_p1[m]
        P2 = x2 + R2 @ m_p2[m]
        for c in range(3):
            m_P1w[m, c] = P1[c]
        T2 = R2 @ m_T2[m]
        Q1 = R1 @ m_Q1[m]
        Q2 = R2 @ m_Q2[m]
        d = P1 - P2
        r1 = P1 - x1
        r12 = P1 - x2
        # relative rotation of frame 1 in frame 2 and its (unwrapped) angles
        Rrel = Q2.T @ Q1
        rv = mat_to_rotvec(Rrel)
        nfree_rot = 0
        for k in range(3):
            if m_mask[m, 3 + k] == 0:
                nfree_rot += 1
        for k in range(3):
            if nfree_rot == 1 and m_mask[m, 3 + k] == 0:
                # single free axis: exact angle with turn counting
                if k == 0:
                    raw = math.atan2(Rrel[2, 1], Rrel[1, 1])
                elif k == 1:
                    raw = math.atan2(Rrel[0, 2], Rrel[2, 2])
                else:
                    raw = math.atan2(Rrel[1, 0], Rrel[0, 0])
                m_angle[m, k] = m_angle[m, k] + _wrap_angle(raw - m_angle[m, k])
            else:
                m_angle[m, k] = rv[k]
        for k in range(6):
            rigid = m_mask[m, k] != 0
            mode = m_mmode[m, k]
            kk = m_k[m, k]
            cc = m_c[m, k]
            if not rigid and mode == MOTOR_NONE and kk <= 0.0 and cc <= 0.0:
                continue
            _clear_row(nr, b, E, kind, lo, hi, mu, rlink, Cpos)
            rlink[nr] = m_lid[m]
            if k < 3:
                e = T2[:, k].copy()
                q = 0.0
                for c in range(3):
                    q += e[c] * d[c]
                angw1 = cross(r1, e)
                angw2 = -cross(r12, e)
                _write_row(nr, i1, i2, e, angw1, -e, angw2, R1, R2, ra, rb, J)
            else:
                a = k - 3
                if rigid:
                    q, ax = _locked_rotation(a, nfree_rot, m_mask[m], Q1, Q2)
                else:
                    ax = Q2[:, a].copy()
                    q = m_angle[m, a]
                z3 = np.zeros(3)
                _write_row(nr, i1, i2, z3, ax, z3, -ax, R1, R2, ra, rb, J)
            if rigid:
                Cpos[nr] = q
                b[nr] = min(max(q / h, -vrec), vrec)
            elif mode == MOTOR_POSITION:
                # ChLinkMateGeneric/ChLinkMotorRotationAngle: the error against the target at
                # the step's start clamped by the recovery speed, plus the target's rate over
                # the step (m_mdval): a motor started away from its target turns to it at
                # v_rec, one on its target follows it exactly
                b[nr] = min(max((q - m_mval[m, k]) / h, -vrec), vrec) - m_mdval[m, k]
            elif mode == MOTOR_SPEED:
                b[nr] = -m_mval[m, k]
            else:
                _soft_row(nr, h, kk, cc, q - m_rest[m, k], 0.0, scheme, vel6, invm3, invI,
                          ra, rb, J, b, E, kind, lo, hi)
            nr += 1
    return nr


@njit(cache=True)
def _distance_row(nr, i1, i2, p1, p2, pos, Rb, ra, rb, J):
    """Row along the line P1−P2 (``J v = d‖P1 − P2‖/dt``); returns (l, P1)."""
    x1, R1 = _body_frame(i1, pos, Rb)
    x2, R2 = _body_frame(i2, pos, Rb)
    P1 = x1 + R1 @ p1
    P2 = x2 + R2 @ p2
    dv = P1 - P2
    l = math.sqrt(dv[0] ** 2 + dv[1] ** 2 + dv[2] ** 2)
    if l < 1e-12:
        n = np.array([0.0, 0.0, 1.0])
    else:
        n = dv / l
    _write_row(nr, i1, i2, n, cross(P1 - x1, n), -n, -cross(P2 - x2, n), R1, R2, ra, rb, J)
    return l, P1


@njit(cache=True)
def build_spring_rows(nr, h, pos, Rb, s_b1, s_b2, s_p1, s_p2, s_k, s_c, s_l0, s_f0,
                      s_lid, s_P1w, s_len, scheme, vel6, invm3, invI,
                      ra, rb, J, b, E, kind, lo, hi, mu, rlink, Cpos):
    """Linear spring-damper (TSDA) F = f0 − k(l − l0) − c l̇ along P1−P2, as a
    spring-damper row (:func:`_soft_row`, implicit or explicit)."""
    for m in range(s_b1.shape[0]):
        kk = s_k[m]
        cc = s_c[m]
        den = h * kk + cc
        _clear_row(nr, b, E, kind, lo, hi, mu, rlink, Cpos)
        l, P1 = _distance_row(nr, s_b1[m], s_b2[m], s_p1[m], s_p2[m], pos, Rb, ra, rb, J)
        s_len[m] = l
        for c in range(3):
            s_P1w[m, c] = P1[c]
        if den <= 0.0:
            continue  # pure preload: applied as an explicit force elsewhere
        rlink[nr] = s_lid[m]
        _soft_row(nr, h, kk, cc, l - s_l0[m], s_f0[m], scheme, vel6, invm3, invI,
                  ra, rb, J, b, E, kind, lo, hi)
        nr += 1
    return nr


@njit(cache=True)
def build_coulomb_rows(nr, h, pos, Rb, d_b1, d_b2, d_p1, d_p2, d_F, d_lid, d_P1w,
                       ra, rb, J, b, E, kind, lo, hi, mu, rlink, Cpos):
    """Coulomb damper: friction force of magnitude ≤ F along P1−P2 as a boxed
    velocity row, γ ∈ [−hF, hF], target relative speed 0."""
    for m in range(d_b1.shape[0]):
        _clear_row(nr, b, E, kind, lo, hi, mu, rlink, Cpos)
        l, P1 = _distance_row(nr, d_b1[m], d_b2[m], d_p1[m], d_p2[m], pos, Rb, ra, rb, J)
        for c in range(3):
            d_P1w[m, c] = P1[c]
        rlink[nr] = d_lid[m]
        kind[nr] = BOXED
        lo[nr] = -h * d_F[m]
        hi[nr] = h * d_F[m]
        nr += 1
    return nr


@njit(cache=True)
def build_pulley_rows(nr, pos, Rb, p_b1, p_b2, p_a1, p_a2, p_r1, p_r2, p_lid, p_P1w,
                      ra, rb, J, b, E, kind, lo, hi, mu, rlink, Cpos):
    """Pulley/belt: r1 ω1·a1 − r2 ω2·a2 = 0 (velocity-level bilateral row)."""
    z3 = np.zeros(3)
    for m in range(p_b1.shape[0]):
        i1 = p_b1[m]
        i2 = p_b2[m]
        x1, R1 = _body_frame(i1, pos, Rb)
        x2, R2 = _body_frame(i2, pos, Rb)
        _clear_row(nr, b, E, kind, lo, hi, mu, rlink, Cpos)
        a1 = R1 @ p_a1[m]
        a2 = R2 @ p_a2[m]
        _write_row(nr, i1, i2, z3, p_r1[m] * a1, z3, -p_r2[m] * a2, R1, R2, ra, rb, J)
        for c in range(3):
            p_P1w[m, c] = x1[c]
        rlink[nr] = p_lid[m]
        nr += 1
    return nr


@njit(cache=True)
def build_imposed_rows(nr, Rb, imposed, ra, rb, J, b, E, kind, lo, hi, mu, rlink, Cpos):
    """Imposed body velocity components (world frame, NaN = free) as rheonomic
    velocity rows ``e_k·v = v*`` / ``e_k·ω_world = ω*``."""
    z3 = np.zeros(3)
    I3 = np.eye(3)
    for i in range(imposed.shape[0]):
        for k in range(6):
            val = imposed[i, k]
            if math.isnan(val):
                continue
            _clear_row(nr, b, E, kind, lo, hi, mu, rlink, Cpos)
            e = np.zeros(3)
            e[k % 3] = 1.0
            if k < 3:
                _write_row(nr, i, -1, e, z3, z3, z3, Rb[i], I3, ra, rb, J)
            else:
                _write_row(nr, i, -1, z3, e, z3, z3, Rb[i], I3, ra, rb, J)
            b[nr] = -val
            rlink[nr] = LINK_IMPOSED
            nr += 1
    return nr


@njit(cache=True)
def tangent_basis(n):
    """Two unit vectors u, w with (n, u, w) right-handed."""
    if abs(n[0]) < 0.6:
        a = np.array([1.0, 0.0, 0.0])
    else:
        a = np.array([0.0, 1.0, 0.0])
    u = a - n * (a[0] * n[0] + a[1] * n[1] + a[2] * n[2])
    u /= math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
    w = cross(n, u)
    return u, w


@njit(cache=True)
def _tangents_t(n):
    if abs(n[0]) < 0.6:
        a = (1.0, 0.0, 0.0)
    else:
        a = (0.0, 1.0, 0.0)
    u = v_sub(a, v_scale(n, v_dot(a, n)))
    u = v_scale(u, 1.0 / math.sqrt(v_dot(u, u)))
    return u, v_cross(n, u)


@njit(cache=True)
def _put_side(J, k, o, lin, angw, R, world):
    """Write one body block of row k (angular part to the body frame)."""
    J[k, o] = lin[0]
    J[k, o + 1] = lin[1]
    J[k, o + 2] = lin[2]
    if world:
        J[k, o + 3] = angw[0]
        J[k, o + 4] = angw[1]
        J[k, o + 5] = angw[2]
    else:
        ab = mat_t_vec(R, angw)
        J[k, o + 3] = ab[0]
        J[k, o + 4] = ab[1]
        J[k, o + 5] = ab[2]


@njit(cache=True)
def build_contact_rows(nr, h, vrec, min_bounce, pos, Rb, vel6, nc, c_a, c_b, c_pt,
                       c_n, c_gap, c_mu, c_e, c_row,
                       ra, rb, J, b, E, kind, lo, hi, mu, rlink, Cpos):
    """Contact rows (normal from body a to body b; J_n v > 0 when separating).

    b_n = max(Φ/h, −v_rec), tangential b = 0 (the System adds the sliding term μ‖u_t‖ to
    b_n afterwards, :meth:`System._solve_rows`).  Newton restitution b_n = e·v_n⁻
    (ChContactNSC::ContIntLoadConstraint_C) when the rebound speed e·|v_n⁻| exceeds the
    minimum bounce speed (Chrono compares the same) and the gap closes within the step at
    the pre-step approach speed, ``Φ + h v_n⁻ < 0``.  Deliberately not Chrono's
    ``Φ + h e v_n⁻ < 0`` (the rebound speed, dvi.md §1.5): Chrono's test skips the bounce
    when the impact falls with Φ in [h e|v_n|, h|v_n|), stops the body at the surface and
    bounces it next step from the much smaller Φ/h, so its rebound depends on the phase of
    the impact within the step (audit g, e = 0.5, drop 1 m, h = 1e-3: rebound ratios
    0.2506 0.2514 0.2599 0.2651 with this rule, 0.2506 0.2514 0.0907 0.2700 with Chrono's;
    first rebound over 41 drop heights 0.50–0.52 m: 0.2490–0.2535 against 0.0701–0.2530;
    e² = 0.25).  μ > 0 gives a FRIC_N/FRIC_T/FRIC_T triplet, μ = 0 a single UNILATERAL
    row.  ``vel6`` = pre-step velocities (linear world, ω body)."""
    I3 = np.eye(3)
    for ci in range(nc):
        a = c_a[ci]
        bb = c_b[ci]
        P = row3(c_pt, ci)
        n = row3(c_n, ci)
        u, w = _tangents_t(n)
        if a >= 0:
            raa = v_sub(P, row3(pos, a))
            Ra = Rb[a]
        else:
            raa = P
            Ra = I3
        if bb >= 0:
            rbb = v_sub(P, row3(pos, bb))
            Rbb = Rb[bb]
        else:
            rbb = P
            Rbb = I3
        c_row[ci] = nr
        nrow = 3 if c_mu[ci] > 0.0 else 1
        for r in range(nrow):
            if r == 0:
                e = n
            elif r == 1:
                e = u
            else:
                e = w
            k = nr + r
            ra[k] = a
            rb[k] = bb
            _put_side(J, k, 0, v_scale(e, -1.0), v_scale(v_cross(raa, e), -1.0), Ra, a < 0)
            _put_side(J, k, 6, e, v_cross(rbb, e), Rbb, bb < 0)
            b[k] = 0.0
            E[k] = 0.0
            kind[k] = FRIC_T
            lo[k] = -1e300
            hi[k] = 1e300
            mu[k] = 0.0
            rlink[k] = -1
            Cpos[k] = np.nan
        # pre-step normal velocity
        vn = 0.0
        if a >= 0:
            for c in range(6):
                vn += J[nr, c] * vel6[a, c]
        if bb >= 0:
            for c in range(6):
                vn += J[nr, 6 + c] * vel6[bb, c]
        gap = c_gap[ci]
        e_rest = c_e[ci]
        if e_rest > 0.0 and e_rest * vn < -min_bounce and gap + h * vn < 0.0:
            b[nr] = e_rest * vn
        else:
            b[nr] = max(gap / h, -vrec)
        Cpos[nr] = gap
        if nrow == 3:
            kind[nr] = FRIC_N
            mu[nr] = c_mu[ci]
        else:
            kind[nr] = UNILATERAL
        nr += nrow
    return nr


@njit(cache=True)
def accumulate_row_forces(nr, ra, rb, J, gamma, inv_h, Rb, rlink, nlinks,
                          c_force, c_torque, l_force, l_torque_c, nb, b_force, b_torque):
    """Forces γ/h of the last step: per body all-row and contact force/torque
    (world, about the centre) and per link the force/torque on body 1 (torque
    about body 1's centre; converted to the link point by the caller)."""
    c_force[:, :] = 0.0
    c_torque[:, :] = 0.0
    l_force[:, :] = 0.0
    l_torque_c[:, :] = 0.0
    for k in range(nr):
        g = gamma[k] * inv_h
        if g == 0.0:
            continue
        lk = rlink[k]
        for side in range(2):
            body = ra[k] if side == 0 else rb[k]
            o = 6 * side
            f = (J[k, o] * g, J[k, o + 1] * g, J[k, o + 2] * g)
            tb = (J[k, o + 3] * g, J[k, o + 4] * g, J[k, o + 5] * g)
            if body >= 0:
                tw = mat_vec(Rb[body], tb)
                for c in range(3):
                    b_force[body, c] += f[c]
                    b_torque[body, c] += tw[c]
                if lk == -1:
                    for c in range(3):
                        c_force[body, c] += f[c]
                        c_torque[body, c] += tw[c]
            else:
                tw = tb
            if lk >= 0 and side == 0:
                for c in range(3):
                    l_force[lk, c] += f[c]
                    l_torque_c[lk, c] += tw[c]

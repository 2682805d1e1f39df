r"""Fused particle interaction in gather form (DualSPHysics formulation).

For each particle ``a`` (one loop iteration per particle, no atomics) the
kernel sums over its neighbours ``b`` found through the cell list:

* momentum (Crespo et al. 2015 eq. 4; Domínguez et al. 2022 eq. 8)
  dv_a/dt = -sum_b m_b (p_a + p_b)/(rho_a rho_b) grad_a W_ab + viscous + g,
  with the cubic-spline tensile correction (Monaghan 2000) when Kernel=1;
* viscosity: ``ViscoTreatment`` 1, artificial (Monaghan 1992)
  Pi_ab = -Visco c0 mu_ab / rho_ab for v_ab.r_ab < 0,
  mu_ab = h v_ab.r_ab / (r_ab^2 + eta^2), eta^2 = 0.01 h^2;
  3, laminar (Lo & Shao 2002)
  sum_b m_b 4 nu (r_ab.grad_a W_ab) / ((rho_a+rho_b)(r_ab^2+eta^2)) v_ab;
  2, laminar + SPS (Dalrymple & Rogers 2006), sum_b m_b (tau_a + tau_b).grad W
  with tau/rho^2 from :func:`sps_tau` (lagged by one evaluation, as DualSPHysics);
  as DualSPHysics, wall neighbours take part with tau_b = 0 and enter the
  velocity gradient of the fluid particle (their velocity: the wall's, or the
  tangential ghost velocity of mDBC slip modes 2 and 3);
  ``ViscoBoundFactor`` multiplies Visco for fluid-boundary pairs;
* continuity (Domínguez et al. 2022 eq. 6)
  drho_a/dt = rho_a sum_b (m_b/rho_b) v_ab . grad_a W_ab + D_a,
* density diffusion D_a (``DensityDT``), as DualSPHysics applies it:
  1 Molteni & Colagrossi (2009) over fluid and floating neighbours, on fluid
  particles with no fixed/moving boundary neighbour (with mDBC walls, cst[22]
  = 1, over the wall particles too, as DualSPHysics) and no neighbour from a
  floating body whose particles are no heavier than 1.2 fluid particles
  (cst[23]; DualSPHysics's DELTA_HEAVYFLOATING; the mass compared is the one
  the fluid sees, rho0 dp^d for an mDBC body); 2 Fourtakas et al.
  (2019) with the hydrostatic correction, over fluid-fluid pairs, on fluid
  particles with no fixed/moving boundary neighbour; 3 the same over
  fluid-fluid pairs on all fluid particles;
* the viscous time-step term max_b h v_ab.r_ab/(r_ab^2+eta^2);
* shifting sums (Lind et al. 2012): grad C_a = sum_b m_b/rho_b grad_a W_ab and
  the free-surface detector div r_a = -sum_b m_b/rho_b r_ab.grad_a W_ab;
* advanced shifting options (``adv``, Shifting 4; DualSPHysics 5.4, Sun et al.
  2019), fluid particles only, V_b = m_b/rho_b, dv = shiftpos/dt (cst[20] = 1/dt;
  dv_b = 0 for boundary and floating b):
  ALE (adv & 1): drho_a/dt += sum_b V_b (rho_a dv_a + rho_b dv_b).grad_a W_ab
  + rho_a sum_b V_b (dv_a - dv_b).grad_a W_ab (SPH forms of div(rho dv) - rho div dv),
  dv_a/dt += rho0/rho_a sum_b V_b (v_a dv_a + v_b dv_b).grad_a W_ab
  + v_a sum_b V_b (dv_a - dv_b).grad_a W_ab (of (div(rho v (x) dv) - v div(rho dv))/rho);
  NCPress (adv & 2): where ``nctype`` is 1 and the Shepard sum
  sum_b V_b W_ab + V_a W(0) exceeds 0.95, the pressure term is
  L^-1 sum_b m_b (p_a - p_b)/(rho_a rho_b) grad_a W_ab, L = -sum_b V_b r_ab (x) grad_a W_ab
  (exact for a linear pressure field), instead of the symmetric one.

Boundary particles (DBC; ptype 0 fixed, 1 moving) get continuity only, from
their fluid and floating neighbours.  Floating particles (ptype 2) take the
momentum and continuity terms; their ``ace`` excludes gravity (the body solver
adds it).  Which neighbours they see follows DualSPHysics's FtMode
(InteractionForcesFluid / InteractionForcesBound, ``ftmode`` flag):
1, ``RigidAlgorithm`` 1 (FtMode Sph, the default): every neighbour, fixed and
moving walls (with Visco x ViscoBoundFactor) and other floating particles
included: that DBC repulsion is the body's only contact with the walls;
2, ``RigidAlgorithm`` 0, 2 or 3 (FtMode Ext, collisions left to the multibody
engine or, under 2, to the DEM contacts of :mod:`sphdvi.sph.dem`): fluid neighbours only, and the walls' continuity skips floating
particles; 0: no floating particles in the scene (those branches compiled out).
With ``Shifting`` 1 a floating neighbour switches a fluid particle's shifting
off, as a wall does.

mDBC slip modes 2 and 3 (flag mdbc2 = 1, :mod:`sphdvi.sph.mdbc`): for a wall
neighbour the continuity term keeps the wall's own (motion) velocity, while
the viscosity and the viscous time-step term see the wall's tangential
velocity ``tvel`` (one row per packed row); walls switched off by mDBC carry
zero packed mass.

Feature flags are ``numba.literally`` arguments (compile-time constants):
kern 1/2, visco 1/2/3, ddt 0..3, shift 0..3, adv 0..3, mdbc2 0/1, ftmode 0..2.  The 2D (x-z plane) and 3D
paths are separate functions.
"""
import math

from ._env import CHUNK
from numba import njit, prange, literally

from .kernels import kernel_fac, kernel_w
from .timestep import force_term_ace2


@njit(cache=True, error_model="numpy")
def _hydrostatic_drho(x, rhop0, inv_gamma):
    """rho0 ((1+x)^(1/gamma) - 1): hydrostatic density difference (Fourtakas).

    Called with x = -rho0 g_z (z_a - z_b) / B (cst[9] = rho0 g_z / B), this is
    rho^H_b - rho^H_a, so that (rho_b - rho_a) - rho^H_ba vanishes in a
    hydrostatic column (tests/sph/test_interaction.py checks the cancellation).
    DualSPHysics (JSph::ConfigConstants2, JSphCpu::InteractionForcesFluid)
    computes rh = 1 + DDTgz drz with DDTgz = rho0 |g_z| / B > 0, drz = z_a - z_b:
    the same x for downward gravity (g_z < 0).  Only for g_z > 0 do they differ:
    DualSPHysics keeps |g_z|, sphdvi follows the sign of gravity.

    Binomial series for |x| < 0.01 (relative error < 1e-10), pow otherwise.
    """
    if abs(x) < 0.01:
        a = inv_gamma
        c1 = a
        c2 = c1 * (a - 1.0) * 0.5
        c3 = c2 * (a - 2.0) / 3.0
        c4 = c3 * (a - 3.0) * 0.25
        c5 = c4 * (a - 4.0) * 0.2
        return rhop0 * x * (c1 + x * (c2 + x * (c3 + x * (c4 + x * c5))))
    return rhop0 * ((1.0 + x) ** inv_gamma - 1.0)


@njit(cache=True, error_model="numpy")
def _tensile(p, rho):
    """Monaghan (2000) tensile-correction coefficient R_a/(W/W(dp))^4."""
    return p / (rho * rho) * (0.01 if p > 0.0 else -0.2)


# --------------------------------------------------------------------------
# Packing of the neighbour data
# --------------------------------------------------------------------------
# 2D packed row: x, z, vx, vz, rho, p, m, 1/rho   (one 64-byte line)
# 3D packed row: x, y, z, vx, vy, vz, rho, p, m, 1/rho
@njit(cache=True, error_model="numpy")
def tait_pressure(rho, b, rhop0, gamma):
    """Tait equation of state p = B ((rho/rho0)^gamma - 1) (Batchelor 1967)."""
    x = rho / rhop0
    if gamma == 7.0:
        x2 = x * x
        x3 = x2 * x
        return b * (x3 * x3 * x - 1.0)
    return b * (x ** gamma - 1.0)


@njit(cache=True, error_model="numpy")
def _pack_row(k, i, is2d, pos, vel, rhop, mass, cst, nb):
    """Packed row k from particle i, with the pressure from Tait's EOS."""
    _pack_row_at(k, i, i, is2d, pos, vel, rhop, mass, cst, nb)


@njit(cache=True, error_model="numpy")
def _pack_row_at(k, e, i, is2d, pos, vel, rhop, mass, cst, nb):
    """Packed row k with the position of row e of ``pos`` and the rest from particle i (a
    periodic copy: its displaced position, its real particle's values)."""
    rho = rhop[i]
    p = tait_pressure(rho, cst[16], cst[10], cst[17])
    if is2d:
        nb[k, 0] = pos[e, 0]
        nb[k, 1] = pos[e, 2]
        nb[k, 2] = vel[i, 0]
        nb[k, 3] = vel[i, 2]
        nb[k, 4] = rho
        nb[k, 5] = p
        nb[k, 6] = mass[i]
        nb[k, 7] = 1.0 / rho
    else:
        for m in range(3):
            nb[k, m] = pos[e, m]
            nb[k, 3 + m] = vel[i, m]
        nb[k, 6] = rho
        nb[k, 7] = p
        nb[k, 8] = mass[i]
        nb[k, 9] = 1.0 / rho


@njit(cache=True, error_model="numpy")
def _pack_range(i0, i1, is2d, pos, vel, rhop, mass, cst, nb):
    for i in range(i0, i1):
        _pack_row(i, i, is2d, pos, vel, rhop, mass, cst, nb)


@njit(cache=True, error_model="numpy")
def _sort_pack_range(k0, k1, order, is2d, cst, nb, pos, vel, rhop, mass, ptype, ptype_s,
                     cell, cell_s, tau, tau_s):
    sps = tau_s.shape[0] == order.shape[0]
    for k in range(k0, k1):
        i = order[k]
        _pack_row(k, i, is2d, pos, vel, rhop, mass, cst, nb)
        ptype_s[k] = ptype[i]
        cell_s[k] = cell[i]
        if sps:
            for m in range(6):
                tau_s[k, m] = tau[i, m]


@njit(cache=True, error_model="numpy")
def sort_pack_serial(order, is2d, cst, nb, pos, vel, rhop, mass, ptype, ptype_s, cell, cell_s,
                     tau, tau_s):
    """Fill the packed neighbour array in cell order without moving the
    particles: row k holds particle order[k]; the type, cell (and, when tau_s
    has N rows, the SPS stress) are gathered alongside."""
    _sort_pack_range(0, order.shape[0], order, is2d, cst, nb, pos, vel, rhop, mass, ptype,
                     ptype_s, cell, cell_s, tau, tau_s)


@njit(cache=True, parallel=True, error_model="numpy")
def sort_pack_parallel(order, is2d, cst, nb, pos, vel, rhop, mass, ptype, ptype_s, cell, cell_s,
                       tau, tau_s):
    """Threaded :func:`sort_pack_serial`."""
    n = order.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _sort_pack_range(c * CHUNK, min(n, (c + 1) * CHUNK), order, is2d, cst, nb, pos, vel, rhop,
                         mass, ptype, ptype_s, cell, cell_s, tau, tau_s)


@njit(cache=True, error_model="numpy")
def pack_serial(is2d, pos, vel, rhop, mass, cst, nb):
    """Fill the packed neighbour array, computing the pressure from Tait's EOS."""
    _pack_range(0, pos.shape[0], is2d, pos, vel, rhop, mass, cst, nb)


@njit(cache=True, parallel=True, error_model="numpy")
def pack_parallel(is2d, pos, vel, rhop, mass, cst, nb):
    """Threaded :func:`pack_serial`."""
    n = pos.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _pack_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, pos, vel, rhop, mass, cst, nb)


@njit(cache=True, error_model="numpy")
def _periodic_pack_range(k0, k1, n, order, ghost_src, pos_x, is2d, cst, nb, vel, rhop, mass, ptype,
                         ptype_e, cell, cell_e, idx, oi, tau, tau_e):
    sps = tau_e.shape[0] == order.shape[0]
    for k in range(k0, k1):
        e = order[k]
        i = e if e < n else ghost_src[e - n]
        idx[k] = i
        oi[k] = e if e < n else -1 - i
        _pack_row_at(k, e, i, is2d, pos_x, vel, rhop, mass, cst, nb)
        ptype_e[k] = ptype[i]
        cell_e[k] = cell[e]
        if sps:
            for m in range(6):
                tau_e[k, m] = tau[i, m]


@njit(cache=True, error_model="numpy")
def periodic_pack_serial(n, order, ghost_src, pos_x, is2d, cst, nb, vel, rhop, mass, ptype, ptype_e,
                         cell, cell_e, idx, oi, tau, tau_e):
    """The periodic extended set (the n particles, then the copies of particles
    ``ghost_src``) packed in cell order, as :func:`sort_pack_serial`: row k is extended row
    e = order[k], at position ``pos_x[e]`` (a copy's displaced one), with the velocity,
    density, mass, type (and SPS stress, when tau_e has a row per packed row) of its real
    particle ``idx[k]``, and the cell ``cell[e]``.  ``oi[k]``: the particle's row for a
    real particle, -1 - idx[k] for a copy (the interaction computes the real rows only: as
    DualSPHysics's periodic particles, a copy is a neighbour only)."""
    _periodic_pack_range(0, order.shape[0], n, order, ghost_src, pos_x, is2d, cst, nb, vel, rhop, mass,
                         ptype, ptype_e, cell, cell_e, idx, oi, tau, tau_e)


@njit(cache=True, parallel=True, error_model="numpy")
def periodic_pack_parallel(n, order, ghost_src, pos_x, is2d, cst, nb, vel, rhop, mass, ptype, ptype_e,
                           cell, cell_e, idx, oi, tau, tau_e):
    """Threaded :func:`periodic_pack_serial`."""
    ne = order.shape[0]
    for c in prange((ne + CHUNK - 1) // CHUNK):
        _periodic_pack_range(c * CHUNK, min(ne, (c + 1) * CHUNK), n, order, ghost_src, pos_x, is2d, cst, nb,
                             vel, rhop, mass, ptype, ptype_e, cell, cell_e, idx, oi, tau, tau_e)


@njit(cache=True, error_model="numpy")
def _dt_maxima(i0, i1, is2d, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst):
    """Time-step terms of rows i0..i1 (eq. 10; DualSPHysics ``DtVariable``):
    dtmax[c] = (max |a|^2 over fluid and floating particles without gravity (DualSPHysics's
    ComputeAceMax: the fluid's ace minus cst[12:15]; a floating ace has no gravity), max |v|^2
    over ptype >= vel_type, max viscdt), read while the rows are in cache.  Periodic copies
    (oi < 0) do not count, as DualSPHysics's ComputeAceMax ignores periodic particles."""
    amax = 0.0
    vmax = 0.0
    cmax = 0.0
    gx = cst[12]
    gy = cst[13]
    gz = cst[14]
    for i in range(i0, i1):
        o = oi[i]
        if o < 0:
            continue
        if viscdt[o] > cmax:
            cmax = viscdt[o]
        pt = ptype[i]
        a = force_term_ace2(ace, o, pt, gx, gy, gz)
        if a > amax:
            amax = a
        if pt >= vel_type:
            if is2d:
                v = nb[i, 2] ** 2 + nb[i, 3] ** 2
            else:
                v = nb[i, 3] ** 2 + nb[i, 4] ** 2 + nb[i, 5] ** 2
            if v > vmax:
                vmax = v
    dtmax[c, 0] = amax
    dtmax[c, 1] = vmax
    dtmax[c, 2] = cmax


# --------------------------------------------------------------------------
# 2D (x-z plane)
# --------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _rates_range_2d(i0, i1, kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start,
                       ncx, ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet,
                       gradvel, tvel, nctype):
    kern = literally(kern)
    visco = literally(visco)
    ddt = literally(ddt)
    shift = literally(shift)
    adv = literally(adv)
    mdbc2 = literally(mdbc2)
    ftmode = literally(ftmode)
    h = cst[0]
    inv_h = 1.0 / h
    r2max = cst[1]
    eta2 = cst[2]
    eta2l = cst[21]
    ddt1_walls = cst[22] != 0.0     # Molteni DDT across mDBC walls (DualSPHysics: not DBC)
    ft_light = cst[23]              # 1.2 x fluid particle mass: a lighter floating neighbour stops DDT 1
    alpha = cst[3]
    alpha_h2 = cst[4]
    cs0h = cst[5] * h
    vis_f = cst[6]
    vis_b = cst[7]
    ddt_gz = cst[9]
    rhop0 = cst[10]
    inv_gamma = cst[11]
    od_wdp = cst[15]
    rs = int(cst[18])  # stencil radius in cells: 1 (cells of 2h) or 2 (cells of h)

    for i in range(i0, i1):
        o = oi[i]   # row of particle i in the output arrays
        if o < 0:
            continue    # a periodic copy: a neighbour only (see periodic_pack_serial)
        xi = nb[i, 0]
        zi = nb[i, 1]
        vxi = nb[i, 2]
        vzi = nb[i, 3]
        rhoi = nb[i, 4]
        pi = nb[i, 5]
        iri = nb[i, 7]
        pti = ptype[i]
        c = cell[i]
        cx = c % ncx
        cz = c // ncx
        xlo = max(cx - rs, 0)
        xhi = min(cx + rs, ncx - 1)
        zlo = max(cz - rs, 0)
        zhi = min(cz + rs, ncz - 1)

        if pti < 2:
            # DBC boundary particle: continuity with fluid/floating neighbours.
            arp = 0.0
            vmax = 0.0
            for z in range(zlo, zhi + 1):
                row = z * ncx
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    if ptype[j] < 2 or (ftmode == 2 and ptype[j] == 2):
                        continue    # FtMode Ext: walls do not see floating particles
                    dx = xi - nb[j, 0]
                    dz = zi - nb[j, 1]
                    r2 = dx * dx + dz * dz
                    if r2 >= r2max or r2 < 1e-18:
                        continue
                    fac = kernel_fac(kern, math.sqrt(r2) * inv_h, alpha_h2)
                    dot = (vxi - nb[j, 2]) * dx + (vzi - nb[j, 3]) * dz
                    arp += nb[j, 6] * fac * dot * nb[j, 7]
                    vmax = max(vmax, dot / (r2 + eta2))
            ace[o, 0] = 0.0
            ace[o, 1] = 0.0
            ace[o, 2] = 0.0
            ar[o] = rhoi * arp
            viscdt[o] = vmax
            continue

        acex = 0.0
        acez = 0.0
        arp = 0.0
        vmax = 0.0
        deltap = 0.0
        ddt_off = False
        shx = 0.0
        shz = 0.0
        shdet = 0.0
        sh_off = False
        gxx = 0.0
        gxz = 0.0
        gzz = 0.0
        tens_i = 0.0
        if kern == 1:
            tens_i = _tensile(pi, rhoi)
        txx_i = 0.0
        txz_i = 0.0
        tzz_i = 0.0
        if visco == 2:
            txx_i = tau[i, 0]
            txz_i = tau[i, 2]
            tzz_i = tau[i, 5]
        # advanced shifting (compile-time adv: 1 ALE, 2 non-conservative pressure)
        ale_i = (adv & 1) != 0 and pti == 3
        ncp_i = (adv & 2) != 0 and pti == 3
        inv_dt = 0.0
        sax = 0.0           # shifting velocity of i
        saz = 0.0
        s_a = 0.0           # sum V_b dv_a . grad W
        s_b = 0.0           # sum V_b dv_b . grad W
        s_vbx = 0.0         # sum V_b v_b (dv_b . grad W)
        s_vbz = 0.0
        s_rb = 0.0          # sum V_b rho_b (dv_b . grad W)
        if ale_i:
            inv_dt = cst[20]
            sax = shiftpos[o, 0] * inv_dt
            saz = shiftpos[o, 2] * inv_dt
        psx = 0.0           # symmetric pressure term
        psz = 0.0
        pax = 0.0           # non-conservative pressure term
        paz = 0.0
        lxx = 0.0           # correction matrix L = -sum V_b r_ab (x) grad W
        lxz = 0.0
        lzz = 0.0
        pou = 0.0           # Shepard sum
        for z in range(zlo, zhi + 1):
            row = z * ncx
            for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                dx = xi - nb[j, 0]
                dz = zi - nb[j, 1]
                r2 = dx * dx + dz * dz
                if r2 >= r2max or r2 < 1e-18:
                    continue
                ptj = ptype[j]
                if ftmode == 2 and pti == 2 and ptj != 3:
                    continue  # FtMode Ext: floating particles see fluid only
                boundj = ptj < 2
                q = math.sqrt(r2) * inv_h
                fac = kernel_fac(kern, q, alpha_h2)
                rhoj = nb[j, 4]
                pj = nb[j, 5]
                mfac = nb[j, 6] * fac
                irj = nb[j, 7]
                dvx = vxi - nb[j, 2]
                dvz = vzi - nb[j, 3]
                dot = dvx * dx + dvz * dz
                # continuity: rho_a m_b/rho_b v_ab.gradW (rho_a applied at the end)
                arp += mfac * dot * irj
                if mdbc2 == 1 and boundj:
                    # mDBC2: the viscosity sees the wall's tangential velocity (sphdvi.sph.mdbc)
                    dvx = vxi - tvel[j, 0]
                    dvz = vzi - tvel[j, 2]
                    dot = dvx * dx + dvz * dz
                ir2e = 1.0 / (r2 + eta2)
                dot_rr2 = dot * ir2e
                vmax = max(vmax, dot_rr2)
                # symmetric pressure term
                coef = -(pi + pj) * iri * irj
                if kern == 1:
                    wr = kernel_w(1, q, alpha) * od_wdp
                    wr = wr * wr
                    coef -= (tens_i + _tensile(pj, rhoj)) * (wr * wr)
                if ncp_i:
                    # both pressure forms are kept; the viscous part stays in coef
                    vf = mfac * irj
                    psx += coef * mfac * dx
                    psz += coef * mfac * dz
                    pnc = (pi - pj) * iri * irj
                    pax += pnc * mfac * dx
                    paz += pnc * mfac * dz
                    lxx -= vf * dx * dx
                    lxz -= vf * dx * dz
                    lzz -= vf * dz * dz
                    pou += nb[j, 6] * irj * kernel_w(kern, q, alpha)
                    coef = 0.0
                if ale_i:
                    vf = mfac * irj
                    ds_a = (sax * dx + saz * dz) * vf
                    ds_b = 0.0
                    if ptj == 3:
                        oj = oi[j]
                        if oj < 0:
                            oj = -1 - oj    # a periodic copy: its particle's shift
                        ds_b = (shiftpos[oj, 0] * dx + shiftpos[oj, 2] * dz) * inv_dt * vf
                    s_a += ds_a
                    s_b += ds_b
                    s_vbx += nb[j, 2] * ds_b
                    s_vbz += nb[j, 3] * ds_b
                    s_rb += rhoj * ds_b
                vis = vis_b if boundj else vis_f
                if visco == 1:
                    # Monaghan artificial viscosity, active for approaching pairs
                    coef += vis * cs0h * min(dot_rr2, 0.0) * 2.0 / (rhoi + rhoj)
                else:
                    # Lo & Shao laminar viscosity
                    vtemp = mfac * 4.0 * vis * r2 / ((r2 + eta2l) * (rhoi + rhoj))
                    acex += vtemp * dvx
                    acez += vtemp * dvz
                    if visco == 2:
                        mj = nb[j, 6]
                        sxx = txx_i + tau[j, 0]
                        sxz = txz_i + tau[j, 2]
                        szz = tzz_i + tau[j, 5]
                        acex += mj * fac * (sxx * dx + sxz * dz)
                        acez += mj * fac * (sxz * dx + szz * dz)
                        volj = -mfac * irj
                        gxx += dvx * volj * dx
                        gxz += dvx * volj * dz + dvz * volj * dx
                        gzz += dvz * volj * dz
                acex += coef * mfac * dx
                acez += coef * mfac * dz
                # density diffusion
                if ddt == 1:
                    if ftmode != 0 and ptj == 2 and nb[j, 6] <= ft_light:
                        ddt_off = True      # DELTA_HEAVYFLOATING: no DDT next to a light body
                    if boundj and not ddt1_walls:
                        ddt_off = True
                    else:
                        deltap += (rhoi * irj - 1.0) * ir2e * r2 * mfac
                elif ddt == 2 or ddt == 3:
                    if boundj:
                        if ddt == 2:
                            ddt_off = True
                    elif ptj == 3:
                        drh = _hydrostatic_drho(-ddt_gz * dz, rhop0, inv_gamma)
                        deltap -= ((rhoj - rhoi) - drh) * ir2e * r2 * mfac * irj
                # shifting
                if shift > 0:
                    if boundj and (shift == 1 or (shift == 2 and ptj == 0)):
                        sh_off = True
                    if shift == 1 and ftmode != 0 and ptj == 2:
                        sh_off = True       # SHIFT_NoBound: floating neighbours too
                    mr = mfac * irj
                    shx += mr * dx
                    shz += mr * dz
                    shdet -= mr * r2
        arp *= rhoi
        if ncp_i:
            pou += nb[i, 6] * iri * kernel_w(kern, 0.0, alpha)
            det = lxx * lzz - lxz * lxz
            if nctype[o] != 0 and pou > 0.95 and det != 0.0:
                acex += (lzz * pax - lxz * paz) / det
                acez += (lxx * paz - lxz * pax) / det
            else:
                acex += psx
                acez += psz
        if ale_i:
            r0i = rhop0 * iri
            sab = s_a - s_b
            acex += r0i * (vxi * s_a + s_vbx) + vxi * sab
            acez += r0i * (vzi * s_a + s_vbz) + vzi * sab
            arp += rhoi * s_a + s_rb + rhoi * sab
        if pti == 3:
            ace[o, 0] = acex + cst[12]
            ace[o, 1] = cst[13]
            ace[o, 2] = acez + cst[14]
            if ddt != 0 and not ddt_off:
                arp += cst[8] * deltap
        else:
            ace[o, 0] = acex
            ace[o, 1] = 0.0
            ace[o, 2] = acez
        ar[o] = arp
        viscdt[o] = vmax
        if shift > 0:
            if sh_off or pti != 3:
                shiftpos[o, 0] = 0.0
                shiftpos[o, 2] = 0.0
            else:
                shiftpos[o, 0] = shx
                shiftpos[o, 2] = shz
            shiftpos[o, 1] = 0.0
            shiftdet[o] = shdet
        if visco == 2:
            gradvel[o, 0] = gxx
            gradvel[o, 2] = gxz
            gradvel[o, 5] = gzz


@njit(cache=True, error_model="numpy")
def rates_2d_serial(kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start, ncx,
                    ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, dtmax, nctype):
    """Serial driver of the 2D interaction (use below ~10k particles).

    Chunk c of CHUNK rows also leaves its time-step maxima in dtmax[c]
    (cst[19] is the lowest particle type whose speed counts)."""
    kern = literally(kern)
    visco = literally(visco)
    ddt = literally(ddt)
    shift = literally(shift)
    adv = literally(adv)
    mdbc2 = literally(mdbc2)
    ftmode = literally(ftmode)
    n = nb.shape[0]
    vel_type = int(cst[19])
    for c in range((n + CHUNK - 1) // CHUNK):
        i0 = c * CHUNK
        i1 = min(n, i0 + CHUNK)
        _rates_range_2d(i0, i1, kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start,
                        ncx, ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, nctype)
        _dt_maxima(i0, i1, True, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst)


@njit(cache=True, parallel=True, error_model="numpy")
def rates_2d_parallel(kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start, ncx,
                      ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, dtmax, nctype):
    """Threaded driver of the 2D interaction (prange over chunks of particles)."""
    kern = literally(kern)
    visco = literally(visco)
    ddt = literally(ddt)
    shift = literally(shift)
    adv = literally(adv)
    mdbc2 = literally(mdbc2)
    ftmode = literally(ftmode)
    n = nb.shape[0]
    vel_type = int(cst[19])
    for c in prange((n + CHUNK - 1) // CHUNK):
        i0 = c * CHUNK
        i1 = min(n, i0 + CHUNK)
        _rates_range_2d(i0, i1, kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start,
                        ncx, ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, nctype)
        _dt_maxima(i0, i1, True, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst)


# --------------------------------------------------------------------------
# 3D
# --------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _rates_range_3d(i0, i1, kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start,
                       ncx, ncy, ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet,
                       gradvel, tvel, nctype):
    kern = literally(kern)
    visco = literally(visco)
    ddt = literally(ddt)
    shift = literally(shift)
    adv = literally(adv)
    mdbc2 = literally(mdbc2)
    ftmode = literally(ftmode)
    h = cst[0]
    inv_h = 1.0 / h
    r2max = cst[1]
    eta2 = cst[2]
    eta2l = cst[21]
    ddt1_walls = cst[22] != 0.0     # Molteni DDT across mDBC walls (DualSPHysics: not DBC)
    ft_light = cst[23]              # 1.2 x fluid particle mass: a lighter floating neighbour stops DDT 1
    alpha = cst[3]
    alpha_h2 = cst[4]
    cs0h = cst[5] * h
    vis_f = cst[6]
    vis_b = cst[7]
    ddt_gz = cst[9]
    rhop0 = cst[10]
    inv_gamma = cst[11]
    od_wdp = cst[15]
    rs = int(cst[18])  # stencil radius in cells: 1 (cells of 2h) or 2 (cells of h)

    for i in range(i0, i1):
        o = oi[i]   # row of particle i in the output arrays
        if o < 0:
            continue    # a periodic copy: a neighbour only (see periodic_pack_serial)
        xi = nb[i, 0]
        yi = nb[i, 1]
        zi = nb[i, 2]
        vxi = nb[i, 3]
        vyi = nb[i, 4]
        vzi = nb[i, 5]
        rhoi = nb[i, 6]
        pi = nb[i, 7]
        iri = nb[i, 9]
        pti = ptype[i]
        c = cell[i]
        cx = c % ncx
        cy = (c // ncx) % ncy
        cz = c // (ncx * ncy)
        xlo = max(cx - rs, 0)
        xhi = min(cx + rs, ncx - 1)
        ylo = max(cy - rs, 0)
        yhi = min(cy + rs, ncy - 1)
        zlo = max(cz - rs, 0)
        zhi = min(cz + rs, ncz - 1)

        if pti < 2:
            arp = 0.0
            vmax = 0.0
            for z in range(zlo, zhi + 1):
                for y in range(ylo, yhi + 1):
                    row = (z * ncy + y) * ncx
                    for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                        if ptype[j] < 2 or (ftmode == 2 and ptype[j] == 2):
                            continue    # FtMode Ext: walls do not see floating particles
                        dx = xi - nb[j, 0]
                        dy = yi - nb[j, 1]
                        dz = zi - nb[j, 2]
                        r2 = dx * dx + dy * dy + dz * dz
                        if r2 >= r2max or r2 < 1e-18:
                            continue
                        fac = kernel_fac(kern, math.sqrt(r2) * inv_h, alpha_h2)
                        dot = ((vxi - nb[j, 3]) * dx + (vyi - nb[j, 4]) * dy
                               + (vzi - nb[j, 5]) * dz)
                        arp += nb[j, 8] * fac * dot * nb[j, 9]
                        vmax = max(vmax, dot / (r2 + eta2))
            ace[o, 0] = 0.0
            ace[o, 1] = 0.0
            ace[o, 2] = 0.0
            ar[o] = rhoi * arp
            viscdt[o] = vmax
            continue

        acex = 0.0
        acey = 0.0
        acez = 0.0
        arp = 0.0
        vmax = 0.0
        deltap = 0.0
        ddt_off = False
        shx = 0.0
        shy = 0.0
        shz = 0.0
        shdet = 0.0
        sh_off = False
        gxx = 0.0
        gxy = 0.0
        gxz = 0.0
        gyy = 0.0
        gyz = 0.0
        gzz = 0.0
        tens_i = 0.0
        if kern == 1:
            tens_i = _tensile(pi, rhoi)
        t0 = 0.0
        t1 = 0.0
        t2 = 0.0
        t3 = 0.0
        t4 = 0.0
        t5 = 0.0
        if visco == 2:
            t0 = tau[i, 0]
            t1 = tau[i, 1]
            t2 = tau[i, 2]
            t3 = tau[i, 3]
            t4 = tau[i, 4]
            t5 = tau[i, 5]
        # advanced shifting (compile-time adv: 1 ALE, 2 non-conservative pressure)
        ale_i = (adv & 1) != 0 and pti == 3
        ncp_i = (adv & 2) != 0 and pti == 3
        inv_dt = 0.0
        sax = 0.0
        say = 0.0
        saz = 0.0
        s_a = 0.0
        s_b = 0.0
        s_vbx = 0.0
        s_vby = 0.0
        s_vbz = 0.0
        s_rb = 0.0
        if ale_i:
            inv_dt = cst[20]
            sax = shiftpos[o, 0] * inv_dt
            say = shiftpos[o, 1] * inv_dt
            saz = shiftpos[o, 2] * inv_dt
        psx = 0.0
        psy = 0.0
        psz = 0.0
        pax = 0.0
        pay = 0.0
        paz = 0.0
        lxx = 0.0
        lxy = 0.0
        lxz = 0.0
        lyy = 0.0
        lyz = 0.0
        lzz = 0.0
        pou = 0.0
        for z in range(zlo, zhi + 1):
            for y in range(ylo, yhi + 1):
                row = (z * ncy + y) * ncx
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    dx = xi - nb[j, 0]
                    dy = yi - nb[j, 1]
                    dz = zi - nb[j, 2]
                    r2 = dx * dx + dy * dy + dz * dz
                    if r2 >= r2max or r2 < 1e-18:
                        continue
                    ptj = ptype[j]
                    if ftmode == 2 and pti == 2 and ptj != 3:
                        continue  # FtMode Ext: floating particles see fluid only
                    boundj = ptj < 2
                    q = math.sqrt(r2) * inv_h
                    fac = kernel_fac(kern, q, alpha_h2)
                    rhoj = nb[j, 6]
                    pj = nb[j, 7]
                    mfac = nb[j, 8] * fac
                    irj = nb[j, 9]
                    dvx = vxi - nb[j, 3]
                    dvy = vyi - nb[j, 4]
                    dvz = vzi - nb[j, 5]
                    dot = dvx * dx + dvy * dy + dvz * dz
                    arp += mfac * dot * irj
                    if mdbc2 == 1 and boundj:
                        dvx = vxi - tvel[j, 0]
                        dvy = vyi - tvel[j, 1]
                        dvz = vzi - tvel[j, 2]
                        dot = dvx * dx + dvy * dy + dvz * dz
                    ir2e = 1.0 / (r2 + eta2)
                    dot_rr2 = dot * ir2e
                    vmax = max(vmax, dot_rr2)
                    coef = -(pi + pj) * iri * irj
                    if kern == 1:
                        wr = kernel_w(1, q, alpha) * od_wdp
                        wr = wr * wr
                        coef -= (tens_i + _tensile(pj, rhoj)) * (wr * wr)
                    if ncp_i:
                        vf = mfac * irj
                        psx += coef * mfac * dx
                        psy += coef * mfac * dy
                        psz += coef * mfac * dz
                        pnc = (pi - pj) * iri * irj
                        pax += pnc * mfac * dx
                        pay += pnc * mfac * dy
                        paz += pnc * mfac * dz
                        lxx -= vf * dx * dx
                        lxy -= vf * dx * dy
                        lxz -= vf * dx * dz
                        lyy -= vf * dy * dy
                        lyz -= vf * dy * dz
                        lzz -= vf * dz * dz
                        pou += nb[j, 8] * irj * kernel_w(kern, q, alpha)
                        coef = 0.0
                    if ale_i:
                        vf = mfac * irj
                        ds_a = (sax * dx + say * dy + saz * dz) * vf
                        ds_b = 0.0
                        if ptj == 3:
                            oj = oi[j]
                            if oj < 0:
                                oj = -1 - oj    # a periodic copy: its particle's shift
                            ds_b = ((shiftpos[oj, 0] * dx + shiftpos[oj, 1] * dy + shiftpos[oj, 2] * dz)
                                    * inv_dt * vf)
                        s_a += ds_a
                        s_b += ds_b
                        s_vbx += nb[j, 3] * ds_b
                        s_vby += nb[j, 4] * ds_b
                        s_vbz += nb[j, 5] * ds_b
                        s_rb += rhoj * ds_b
                    vis = vis_b if boundj else vis_f
                    if visco == 1:
                        coef += vis * cs0h * min(dot_rr2, 0.0) * 2.0 / (rhoi + rhoj)
                    else:
                        vtemp = mfac * 4.0 * vis * r2 / ((r2 + eta2l) * (rhoi + rhoj))
                        acex += vtemp * dvx
                        acey += vtemp * dvy
                        acez += vtemp * dvz
                        if visco == 2:
                            mj = nb[j, 8]
                            sxx = t0 + tau[j, 0]
                            sxy = t1 + tau[j, 1]
                            sxz = t2 + tau[j, 2]
                            syy = t3 + tau[j, 3]
                            syz = t4 + tau[j, 4]
                            szz = t5 + tau[j, 5]
                            acex += mj * fac * (sxx * dx + sxy * dy + sxz * dz)
                            acey += mj * fac * (sxy * dx + syy * dy + syz * dz)
                            acez += mj * fac * (sxz * dx + syz * dy + szz * dz)
                            volj = -mfac * irj
                            ax = dvx * volj
                            ay = dvy * volj
                            az = dvz * volj
                            gxx += ax * dx
                            gxy += ax * dy + ay * dx
                            gxz += ax * dz + az * dx
                            gyy += ay * dy
                            gyz += ay * dz + az * dy
                            gzz += az * dz
                    acex += coef * mfac * dx
                    acey += coef * mfac * dy
                    acez += coef * mfac * dz
                    if ddt == 1:
                        if ftmode != 0 and ptj == 2 and nb[j, 8] <= ft_light:
                            ddt_off = True      # DELTA_HEAVYFLOATING: no DDT next to a light body
                        if boundj and not ddt1_walls:
                            ddt_off = True
                        else:
                            deltap += (rhoi * irj - 1.0) * ir2e * r2 * mfac
                    elif ddt == 2 or ddt == 3:
                        if boundj:
                            if ddt == 2:
                                ddt_off = True
                        elif ptj == 3:
                            drh = _hydrostatic_drho(-ddt_gz * dz, rhop0, inv_gamma)
                            deltap -= ((rhoj - rhoi) - drh) * ir2e * r2 * mfac * irj
                    if shift > 0:
                        if boundj and (shift == 1 or (shift == 2 and ptj == 0)):
                            sh_off = True
                        if shift == 1 and ftmode != 0 and ptj == 2:
                            sh_off = True       # SHIFT_NoBound: floating neighbours too
                        mr = mfac * irj
                        shx += mr * dx
                        shy += mr * dy
                        shz += mr * dz
                        shdet -= mr * r2
        arp *= rhoi
        if ncp_i:
            pou += nb[i, 8] * iri * kernel_w(kern, 0.0, alpha)
            # L^-1 by cofactors (L is symmetric)
            cxx = lyy * lzz - lyz * lyz
            cxy = lxz * lyz - lxy * lzz
            cxz = lxy * lyz - lxz * lyy
            det = lxx * cxx + lxy * cxy + lxz * cxz
            if nctype[o] != 0 and pou > 0.95 and det != 0.0:
                cyy = lxx * lzz - lxz * lxz
                cyz = lxy * lxz - lxx * lyz
                czz = lxx * lyy - lxy * lxy
                acex += (cxx * pax + cxy * pay + cxz * paz) / det
                acey += (cxy * pax + cyy * pay + cyz * paz) / det
                acez += (cxz * pax + cyz * pay + czz * paz) / det
            else:
                acex += psx
                acey += psy
                acez += psz
        if ale_i:
            r0i = rhop0 * iri
            sab = s_a - s_b
            acex += r0i * (vxi * s_a + s_vbx) + vxi * sab
            acey += r0i * (vyi * s_a + s_vby) + vyi * sab
            acez += r0i * (vzi * s_a + s_vbz) + vzi * sab
            arp += rhoi * s_a + s_rb + rhoi * sab
        if pti == 3:
            ace[o, 0] = acex + cst[12]
            ace[o, 1] = acey + cst[13]
            ace[o, 2] = acez + cst[14]
            if ddt != 0 and not ddt_off:
                arp += cst[8] * deltap
        else:
            ace[o, 0] = acex
            ace[o, 1] = acey
            ace[o, 2] = acez
        ar[o] = arp
        viscdt[o] = vmax
        if shift > 0:
            if sh_off or pti != 3:
                shiftpos[o, 0] = 0.0
                shiftpos[o, 1] = 0.0
                shiftpos[o, 2] = 0.0
            else:
                shiftpos[o, 0] = shx
                shiftpos[o, 1] = shy
                shiftpos[o, 2] = shz
            shiftdet[o] = shdet
        if visco == 2:
            gradvel[o, 0] = gxx
            gradvel[o, 1] = gxy
            gradvel[o, 2] = gxz
            gradvel[o, 3] = gyy
            gradvel[o, 4] = gyz
            gradvel[o, 5] = gzz


@njit(cache=True, error_model="numpy")
def rates_3d_serial(kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start, ncx, ncy,
                    ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, dtmax, nctype):
    """Serial driver of the 3D interaction (27-cell stencil as 9 x-rows);
    time-step maxima per chunk in dtmax as :func:`rates_2d_serial`."""
    kern = literally(kern)
    visco = literally(visco)
    ddt = literally(ddt)
    shift = literally(shift)
    adv = literally(adv)
    mdbc2 = literally(mdbc2)
    ftmode = literally(ftmode)
    n = nb.shape[0]
    vel_type = int(cst[19])
    for c in range((n + CHUNK - 1) // CHUNK):
        i0 = c * CHUNK
        i1 = min(n, i0 + CHUNK)
        _rates_range_3d(i0, i1, kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start,
                        ncx, ncy, ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, nctype)
        _dt_maxima(i0, i1, False, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst)


@njit(cache=True, parallel=True, error_model="numpy")
def rates_3d_parallel(kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start, ncx, ncy,
                      ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, dtmax, nctype):
    """Threaded driver of the 3D interaction."""
    kern = literally(kern)
    visco = literally(visco)
    ddt = literally(ddt)
    shift = literally(shift)
    adv = literally(adv)
    mdbc2 = literally(mdbc2)
    ftmode = literally(ftmode)
    n = nb.shape[0]
    vel_type = int(cst[19])
    for c in prange((n + CHUNK - 1) // CHUNK):
        i0 = c * CHUNK
        i1 = min(n, i0 + CHUNK)
        _rates_range_3d(i0, i1, kern, visco, ddt, shift, adv, mdbc2, ftmode, nb, ptype, cell, oi, cell_start,
                        ncx, ncy, ncz, cst, tau, ace, ar, viscdt, shiftpos, shiftdet, gradvel, tvel, nctype)
        _dt_maxima(i0, i1, False, nb, ptype, oi, ace, viscdt, vel_type, dtmax, c, cst)


# --------------------------------------------------------------------------
# Fused reorder + pack (one pass, one thread launch per step)
# --------------------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def _reorder_pack_range(k0, k1, order, is2d, cst, nb, f2_src, f2_dst, f1_src, f1_dst,
                        ptype_src, ptype_dst, idp_src, idp_dst, mk_src, mk_dst,
                        cell_src, cell_dst):
    for k in range(k0, k1):
        i = order[k]
        for a in range(len(f2_src)):
            src = f2_src[a]
            dst = f2_dst[a]
            for m in range(src.shape[1]):
                dst[k, m] = src[i, m]
        for a in range(len(f1_src)):
            f1_dst[a][k] = f1_src[a][i]
        ptype_dst[k] = ptype_src[i]
        idp_dst[k] = idp_src[i]
        mk_dst[k] = mk_src[i]
        cell_dst[k] = cell_src[i]
    # pack from the reordered arrays: f2 = (pos, vel, ...), f1 = (rhop, mass, ...)
    _pack_range(k0, k1, is2d, f2_dst[0], f2_dst[1], f1_dst[0], f1_dst[1], cst, nb)


@njit(cache=True, error_model="numpy")
def reorder_pack_serial(order, is2d, cst, nb, f2_src, f2_dst, f1_src, f1_dst, ptype_src,
                        ptype_dst, idp_src, idp_dst, mk_src, mk_dst, cell_src, cell_dst):
    """Permute every per-particle array by ``order`` (dst[k] = src[order[k]]) and
    fill the packed neighbour array from the result.

    ``f2_*`` are tuples of (N, m) float arrays starting with (pos, vel), ``f1_*``
    tuples of (N,) float arrays starting with (rhop, mass).
    """
    _reorder_pack_range(0, order.shape[0], order, is2d, cst, nb, f2_src, f2_dst, f1_src,
                        f1_dst, ptype_src, ptype_dst, idp_src, idp_dst, mk_src, mk_dst,
                        cell_src, cell_dst)


@njit(cache=True, parallel=True, error_model="numpy")
def reorder_pack_parallel(order, is2d, cst, nb, f2_src, f2_dst, f1_src, f1_dst, ptype_src,
                          ptype_dst, idp_src, idp_dst, mk_src, mk_dst, cell_src, cell_dst):
    """Threaded :func:`reorder_pack_serial`."""
    n = order.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _reorder_pack_range(c * CHUNK, min(n, (c + 1) * CHUNK), order, is2d, cst, nb, f2_src,
                            f2_dst, f1_src, f1_dst, ptype_src, ptype_dst, idp_src, idp_dst,
                            mk_src, mk_dst, cell_src, cell_dst)

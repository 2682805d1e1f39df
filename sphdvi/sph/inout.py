r"""Inlet/outlet (open) boundaries: DualSPHysics's ``<inout>`` zones (Tafuni et al. 2018,
"A versatile algorithm for the treatment of open boundary conditions in Smoothed particle
hydrodynamics GPU models", CMAME 342; DualSPHysics's JSphInOut, JSphCpu_InOut).

A zone is a plane with a direction n pointing into the fluid and a buffer of ``layers`` rows of
fluid particles behind it, width L = layers dp.  The plane lies dp/2 in front of the zone's points
(the ``<line>``/``<box>``/``<circle>`` lattice, or the ``<particles mkfluid>`` layer), which are the
buffer's first row; the others follow dp apart behind it.  Its lateral extent is the points' extent
plus dp/2 (a circle's radius plus dp/2); with ``useboxlimit`` the zone is that prism, L + dp/2 deep.

Buffer particles are fluid particles (ptype 3) marked by their id (:attr:`InOut.zone_of_idp`).  The
fluid sees them as fluid; their own velocity and density are imposed at the start of each step
(:func:`impose_serial`), their accelerations and density rates are zeroed (:func:`zero_rates_serial`), so
they move r += v dt with the imposed velocity:

* velocity along n: fixed (uniform, linear v = m z + b, parabolic a z^2 + b z + c through three
  points), variable (those profiles from rows in time, linearly interpolated between rows), zero
  above zsurf unless refilling is 0 (simple full); or extrapolated;
* density: rho0, hydrostatic rho0 max(1, (1 + rho0 |g_z| (zsurf - z)/B)^(1/gamma)), or extrapolated.

Extrapolation (JSphCpu::InteractionInOutExtrap): the ghost node g = r + 2|d| n mirrors the
particle (d its signed distance to the plane) into the fluid; over the fluid particles j near g
(buffer particles excluded), with V = m/rho,

  A = [[sum V w,        sum V w (r_j - g)^T     ],
       [sum V grad w,   sum V grad w (r_j - g)^T]]

(mDBC's moment matrix, :func:`sphdvi.sph.mdbc._ghost_sums`) and the right-hand sides (sum m w, sum m grad w) for the density and (sum V w u, sum V grad w u)
for each velocity component u, the first-order value f_b = f_g + (r_b - g).grad f where
|det A| >= ``determlimit``, else the Shepard value (sum m w / sum V w; sum V w u / sum V w) when
sum V w > 0 (DualSPHysics's default determlimit 1e+3 is zeroth order everywhere; 1e-3 first order).
A fluid particle on the ghost node counts with W(0) (its gradient term zero), as in sphdvi's mDBC;
DualSPHysics leaves it out (``rr2 >= ALMOSTZERO``), which on a regular lattice, where the plane lies
half-way between rows and every ghost node falls on a fluid particle, drops the nearest neighbour of
every buffer particle from its Shepard average.

At the end of each step (:func:`classify_serial`, JSphInOut::ComputeStepCpu):

* a buffer particle that crossed the plane (d >= 0) becomes ordinary fluid; with refilling 0, or
  1 and z <= zsurf, a new buffer particle takes its place at r - L n (refilling 2, DualSPHysics's
  "advanced" mode for reverse flows, instead fills each lattice point's column up to L: see
  :func:`refill_columns`);
* a buffer particle deeper than L (it left through the back), or above zsurf when ``remove``, is
  removed (not counted as excluded);
* an ordinary fluid particle inside a zone: inputtreatment 0 leaves it, 1 converts it to a buffer
  particle (an outlet), 2 removes it (an inlet); with ``remove`` one above zsurf is removed.

zsurf: fixed, variable (rows in time), or calculated (mode 2): the free surface measured on the
vertical line through the centre of the zone's points, 2h in front of them (the ``swl`` gauge's kernel-sum
rule, :class:`sphdvi.sph.surface_gauge.VerticalSurfaceGauge`), from ``zsurfmin`` up, plus the fit
(-dp/2 by default), as JSphInOutZsurf's gauge.

Periodic boundaries: the extrapolation runs on the extended set (the copies across the periodic
boundary are neighbours), the copies of buffer particles take their particles' imposed values
(:func:`refresh_buffer_copies`), and a buffer particle the wrap took to the other end is classified
at its image nearest the zone (:func:`nearest_image`).

At the start (:func:`place_buffers`, JSphCpuSingle::InOutInit): the particles of ``<particles
mkfluid>`` zones are replaced by the buffer's rows, and ordinary fluid inside a zone's box is
removed (DualSPHysics excludes fluid "too close to inout particles").
"""
from __future__ import annotations

import math

import numpy as np

from . import _env  # noqa: F401
from ._env import CHUNK
from numba import njit, prange

from .interaction import _pack_row
from .linalg import solve_pivoted
from .mdbc import _ghost_sums, _set_packed

# columns of the zone geometry array
G_N = 0          # 0:3 the unit direction n into the fluid
G_D0 = 3         # n . p on the plane
G_T1 = 4         # 4:7 first lateral axis
G_T2 = 7         # 7:10 second lateral axis (3D)
G_C = 10         # 10:13 a point on the plane (the lateral origin)
G_A1 = 13        # 13, 14: the lateral extent along T1
G_A2 = 15        # 15, 16: along T2
G_R = 17         # a circle's radius (0: a rectangle)
G_W = 18         # the buffer's width L = layers dp
G_BOX = 19       # 1: the zone is limited to its box (useboxlimit)
NGEO = 20
# columns of the zone configuration array
C_REFILL = 0
C_INPUT = 1
C_RHOP = 2
C_VEL = 3
C_REMOVE = 4
NCFG = 5
# a height within ZTOL dp above zsurf counts as below it: GenCase's lattice puts a row meant to be at
# zsurf 4e-17 m above it, which DualSPHysics's float comparison (float(z) <= zsurf) rounds away
ZTOL = 1e-6
# actions of classify_serial
KEEP, TO_FLUID, TO_FLUID_REFILL, REMOVE = 0, 1, 2, 3
TO_BUFFER = 4        # + zone index


@njit(cache=True)
def plane_depth(geo, z, x, y, w):
    """Signed distance of (x, y, w) to zone z's plane, positive in the fluid."""
    return geo[z, 0] * x + geo[z, 1] * y + geo[z, 2] * w - geo[z, G_D0]


@njit(cache=True)
def in_lateral(geo, z, x, y, w):
    """Is the point within zone z's lateral extent?"""
    dx = x - geo[z, G_C]
    dy = y - geo[z, G_C + 1]
    dz = w - geo[z, G_C + 2]
    a1 = dx * geo[z, G_T1] + dy * geo[z, G_T1 + 1] + dz * geo[z, G_T1 + 2]
    a2 = dx * geo[z, G_T2] + dy * geo[z, G_T2 + 1] + dz * geo[z, G_T2 + 2]
    r = geo[z, G_R]
    if r > 0.0:
        return a1 * a1 + a2 * a2 <= r * r
    return geo[z, G_A1] <= a1 <= geo[z, G_A1 + 1] and geo[z, G_A2] <= a2 <= geo[z, G_A2 + 1]


@njit(cache=True)
def in_zone(geo, z, x, y, w, dp):
    """DualSPHysics's InZone: behind the plane, and inside the zone's box (L + dp/2 deep, the
    lateral extent) when it uses its box limit."""
    d = plane_depth(geo, z, x, y, w)
    if d >= 0.0:
        return False
    if geo[z, G_BOX] == 0.0:
        return True
    return d >= -(geo[z, G_W] + 0.5 * dp) and in_lateral(geo, z, x, y, w)


@njit(cache=True)
def nearest_image(geo, z, x, y, w, paxes, pshift):
    """The periodic image of (x, y, w) nearest zone z's centre (along each periodic axis a: the point,
    or it plus or minus the period vector pshift[a]); the point itself without periodic axes."""
    for m in range(paxes.shape[0]):
        a = paxes[m]
        best = (x - geo[z, G_C]) ** 2 + (y - geo[z, G_C + 1]) ** 2 + (w - geo[z, G_C + 2]) ** 2
        bx, by, bw = x, y, w
        for sgn in (-1.0, 1.0):
            cx = x + sgn * pshift[a, 0]
            cy = y + sgn * pshift[a, 1]
            cw = w + sgn * pshift[a, 2]
            d2 = (cx - geo[z, G_C]) ** 2 + (cy - geo[z, G_C + 1]) ** 2 + (cw - geo[z, G_C + 2]) ** 2
            if d2 < best:
                best, bx, by, bw = d2, cx, cy, cw
        x, y, w = bx, by, bw
    return x, y, w


@njit(cache=True)
def _classify_range(i0, i1, pos, ptype, idp, zone_of_idp, geo, cfg, zsurf, dp, action, paxes, pshift):
    nz = geo.shape[0]
    for i in range(i0, i1):
        action[i] = KEEP
        if ptype[i] != 3:
            continue
        x, y, w = pos[i, 0], pos[i, 1], pos[i, 2]
        z = zone_of_idp[idp[i]]
        if z >= 0:
            # a buffer particle the periodic wrap took to the other end is judged where it was
            x, y, w = nearest_image(geo, z, x, y, w, paxes, pshift)
            d = plane_depth(geo, z, x, y, w)
            above = w > zsurf[z] + ZTOL * dp
            if d < -geo[z, G_W] or (cfg[z, C_REMOVE] != 0 and above):
                action[i] = REMOVE
            elif d >= 0.0:
                refill = cfg[z, C_REFILL] == 0 or (cfg[z, C_REFILL] == 1 and not above)
                action[i] = TO_FLUID_REFILL if refill else TO_FLUID
            continue
        for k in range(nz):
            if cfg[k, C_INPUT] == 0 and cfg[k, C_REMOVE] == 0:
                continue
            if in_zone(geo, k, x, y, w, dp):
                if cfg[k, C_INPUT] == 2 or (cfg[k, C_REMOVE] != 0 and w > zsurf[k] + ZTOL * dp):
                    action[i] = REMOVE
                elif cfg[k, C_INPUT] == 1:
                    action[i] = TO_BUFFER + k
                break


@njit(cache=True)
def classify_serial(pos, ptype, idp, zone_of_idp, geo, cfg, zsurf, dp, action, paxes, pshift):
    """The end-of-step actions (module docstring) of every particle into ``action``; ``paxes`` and
    ``pshift``: the periodic axes and period vectors (none: empty)."""
    _classify_range(0, pos.shape[0], pos, ptype, idp, zone_of_idp, geo, cfg, zsurf, dp, action, paxes, pshift)


@njit(cache=True, parallel=True)
def classify_parallel(pos, ptype, idp, zone_of_idp, geo, cfg, zsurf, dp, action, paxes, pshift):
    """Threaded :func:`classify_serial`."""
    n = pos.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _classify_range(c * CHUNK, min(n, (c + 1) * CHUNK), pos, ptype, idp, zone_of_idp, geo, cfg, zsurf, dp,
                        action, paxes, pshift)


@njit(cache=True)
def _zero_rates_range(i0, i1, ptype, idp, zone_of_idp, ace, ar, shiftpos):
    shift = shiftpos.shape[0] == ptype.shape[0]
    for i in range(i0, i1):
        if ptype[i] == 3 and zone_of_idp[idp[i]] >= 0:
            ace[i, 0] = 0.0
            ace[i, 1] = 0.0
            ace[i, 2] = 0.0
            ar[i] = 0.0
            if shift:
                shiftpos[i, 0] = 0.0
                shiftpos[i, 1] = 0.0
                shiftpos[i, 2] = 0.0


@njit(cache=True)
def zero_rates_serial(ptype, idp, zone_of_idp, ace, ar, shiftpos):
    """Buffer particles take no acceleration, density rate or shift: they move with the velocity
    imposed on them (``shiftpos`` of one row: no shifting in the run)."""
    _zero_rates_range(0, ptype.shape[0], ptype, idp, zone_of_idp, ace, ar, shiftpos)


@njit(cache=True, parallel=True)
def zero_rates_parallel(ptype, idp, zone_of_idp, ace, ar, shiftpos):
    """Threaded :func:`zero_rates_serial`."""
    n = ptype.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _zero_rates_range(c * CHUNK, min(n, (c + 1) * CHUNK), ptype, idp, zone_of_idp, ace, ar, shiftpos)


@njit(cache=True)
def profile_velocity(coef, z, w):
    """Zone z's velocity along n at height w: coef[z] = (a, b, c) of a w^2 + b w + c."""
    return (coef[z, 0] * w + coef[z, 1]) * w + coef[z, 2]


@njit(cache=True)
def hydrostatic_density(zsurf, w, rhop0, coef_hydro, inv_gamma):
    """rho0 max(1, (1 + rho0 |g_z| (zsurf - w)/B)^(1/gamma)) (JSphInOut::SetAnalyticalDataCpu)."""
    f = (1.0 + coef_hydro * (zsurf - w)) ** inv_gamma if 1.0 + coef_hydro * (zsurf - w) > 0.0 else 0.0
    return rhop0 * (f if f > 1.0 else 1.0)


@njit(cache=True, error_model="numpy")
def _extrapolate(kern, is2d, nb, ptype_s, oi, idp, zone_of_idp, cell_start, pmin, inv_cell, ncx, ncy, ncz,
                 cst, k, nx, ny, nz, a, b, vsum, determlimit, want_vel, out):
    """Density and velocity at the buffer particle of packed row k extrapolated from its ghost node
    r + 2N, N = (nx, ny, nz) (module docstring; the sums are mDBC's, buffers left out), into
    out[0:4] (rho, vx, vy, vz); False with no fluid in reach (out untouched)."""
    n = 3 if is2d else 4
    _ghost_sums(kern, is2d, nb, ptype_s, cell_start, pmin, inv_cell, ncx, ncy, ncz, cst, k, nx, ny, nz, a, b,
                vsum, zone_of_idp, idp, oi)
    if a[0, 0] <= 0.0:
        return False
    shep = 1.0 / a[0, 0]
    out[0] = b[0, 0] * shep
    for c in range(3):
        out[1 + c] = vsum[c] * shep
    m = 4 if want_vel else 1
    det = solve_pivoted(a, b, n, m, 0.0)
    if det > 0.0 and det >= determlimit:
        # the unknowns are f_g and grad f (columns r_j - g): f_b = f_g + (r_b - g).grad f = f_g - 2 N.grad f
        for c in range(m):
            if is2d:
                out[c] = b[0, c] - 2.0 * (nx * b[1, c] + nz * b[2, c])
            else:
                out[c] = b[0, c] - 2.0 * (nx * b[1, c] + ny * b[2, c] + nz * b[3, c])
    return True


@njit(cache=True, error_model="numpy")
def _impose_range(k0, k1, kern, is2d, nb, ptype_s, oi, prow, pos, vel, rhop, mass, idp, zone_of_idp, cell_start,
                  pmin, inv_cell, ncx, ncy, ncz, cst, geo, cfg, coef, zsurf, determlimit, coef_hydro, vel_m1,
                  rhop_m1, dp):
    """:func:`impose_serial` over the packed rows k0 <= k < k1 (work arrays once per range)."""
    verlet = vel_m1.shape[0] == pos.shape[0]
    rhop0 = cst[10]
    inv_gamma = cst[11]
    a = np.empty((4, 4))
    b = np.empty((4, 4))
    vsum = np.empty(4)
    out = np.empty(4)
    for k in range(k0, k1):
        if ptype_s[k] != 3:
            continue
        o = oi[k]
        if o < 0:           # a periodic copy: refresh_buffer_copies gives it its particle's values
            continue
        z = zone_of_idp[idp[o]]
        if z < 0:
            continue
        x, y, w = pos[o, 0], pos[o, 1], pos[o, 2]
        rmode = cfg[z, C_RHOP]
        vmode = cfg[z, C_VEL]
        rho = rhop[o]
        if rmode == 0:
            rho = rhop0
        elif rmode == 1:
            rho = hydrostatic_density(zsurf[z], w, rhop0, coef_hydro, inv_gamma)
        if vmode != 2:
            v = 0.0
            if cfg[z, C_REFILL] == 0 or w <= zsurf[z] + ZTOL * dp:
                v = profile_velocity(coef, z, w)
            vel[o, 0] = v * geo[z, 0]
            vel[o, 1] = v * geo[z, 1]
            vel[o, 2] = v * geo[z, 2]
        if rmode == 2 or vmode == 2:
            d = -plane_depth(geo, z, x, y, w)        # > 0 behind the plane: N = d n reaches it
            if d < 0.0:
                d = 0.0
            if _extrapolate(kern, is2d, nb, ptype_s, prow, idp, zone_of_idp, cell_start, pmin, inv_cell, ncx, ncy,
                            ncz, cst, k, d * geo[z, 0], 0.0 if is2d else d * geo[z, 1], d * geo[z, 2], a, b, vsum,
                            determlimit, vmode == 2, out):
                if rmode == 2:
                    rho = out[0]
                if vmode == 2:
                    vel[o, 0] = out[1]
                    vel[o, 1] = 0.0 if is2d else out[2]
                    vel[o, 2] = out[3]
        rhop[o] = rho
        if verlet:
            vel_m1[o, 0] = vel[o, 0]
            vel_m1[o, 1] = vel[o, 1]
            vel_m1[o, 2] = vel[o, 2]
            rhop_m1[o] = rho
        _pack_row(k, o, is2d, pos, vel, rhop, mass, cst, nb)


@njit(cache=True, error_model="numpy")
def impose_serial(kern, is2d, nb, ptype_s, oi, prow, pos, vel, rhop, mass, idp, zone_of_idp, cell_start, pmin,
                  inv_cell, ncx, ncy, ncz, cst, geo, cfg, coef, zsurf, determlimit, coef_hydro, vel_m1, rhop_m1, dp):
    """Impose the velocity and density of every buffer particle (packed row k, particle oi[k]; oi[k] < 0
    for a periodic copy, left to :func:`refresh_buffer_copies`): the state rows, the packed rows (so the
    coming interaction sees them) and, for Verlet, the previous-step values ``vel_m1``/``rhop_m1``
    (zero rows: Symplectic).  ``prow``: every packed row's particle (copies too), for the buffers the
    extrapolation leaves out."""
    _impose_range(0, nb.shape[0], kern, is2d, nb, ptype_s, oi, prow, pos, vel, rhop, mass, idp, zone_of_idp,
                  cell_start, pmin, inv_cell, ncx, ncy, ncz, cst, geo, cfg, coef, zsurf, determlimit, coef_hydro,
                  vel_m1, rhop_m1, dp)


@njit(cache=True, parallel=True, error_model="numpy")
def impose_parallel(kern, is2d, nb, ptype_s, oi, prow, pos, vel, rhop, mass, idp, zone_of_idp, cell_start, pmin,
                    inv_cell, ncx, ncy, ncz, cst, geo, cfg, coef, zsurf, determlimit, coef_hydro, vel_m1, rhop_m1,
                    dp):
    """Threaded :func:`impose_serial` (``CHUNK`` rows a work item)."""
    n = nb.shape[0]
    for c in prange((n + CHUNK - 1) // CHUNK):
        _impose_range(c * CHUNK, min(n, (c + 1) * CHUNK), kern, is2d, nb, ptype_s, oi, prow, pos, vel, rhop, mass,
                      idp, zone_of_idp, cell_start, pmin, inv_cell, ncx, ncy, ncz, cst, geo, cfg, coef, zsurf,
                      determlimit, coef_hydro, vel_m1, rhop_m1, dp)


@njit(cache=True, error_model="numpy")
def refresh_buffer_copies(nb, ptype_s, oi, prow, idp, zone_of_idp, vel, rhop, is2d, cst):
    """Periodic runs: the packed velocity, density, pressure and 1/rho of the copies of buffer particles
    from their particles (imposed by :func:`impose_serial`); positions stay the copies'."""
    for k in range(nb.shape[0]):
        if oi[k] >= 0 or ptype_s[k] != 3:
            continue
        i = prow[k]
        if zone_of_idp[idp[i]] < 0:
            continue
        rho = rhop[i]
        if is2d:
            nb[k, 2] = vel[i, 0]
            nb[k, 3] = vel[i, 2]
        else:
            nb[k, 3] = vel[i, 0]
            nb[k, 4] = vel[i, 1]
            nb[k, 5] = vel[i, 2]
        _set_packed(nb, k, is2d, rho, cst, False)


@njit(cache=True)
def _lateral_bin(geo, z, x, y, w, dp):
    """The (i1, i2) cell of dp x dp of a point's lateral coordinates in zone z's frame."""
    dx = x - geo[z, G_C]
    dy = y - geo[z, G_C + 1]
    dz = w - geo[z, G_C + 2]
    a1 = dx * geo[z, G_T1] + dy * geo[z, G_T1 + 1] + dz * geo[z, G_T1 + 2]
    a2 = dx * geo[z, G_T2] + dy * geo[z, G_T2 + 1] + dz * geo[z, G_T2 + 2]
    return int(math.floor(a1 / dp)), int(math.floor(a2 / dp))


@njit(cache=True)
def refill_columns(pts, ptzone, geo, zsurf, pos, rows, rowzone, dp, depth_out):
    """Advanced refilling (refilling 2, JSphInOut::ComputeStepFillingCpu): for each lattice point
    of the plane below zsurf, the depth behind the plane where its column of buffer particles
    ends: the deepest buffer particle (``rows`` of zones ``rowzone``) whose projection lies within
    dp of the point, plus the rest of dp along n (sqrt(dp^2 - s^2), s its lateral distance); dp
    without one.  A new buffer particle goes there when it is less than L deep (``depth_out`` -1
    otherwise).  The buffer particles are binned by their lateral position (cells of dp), so each
    point looks at the 3 x 3 cells around its own."""
    npt = pts.shape[0]
    m = rows.shape[0]
    for k in range(npt):
        depth_out[k] = -1.0
    # bin the buffer particles: key (zone, i1, i2) sorted
    key1 = np.empty(m, np.int64)
    key2 = np.empty(m, np.int64)
    for r in range(m):
        i = rows[r]
        b1, b2 = _lateral_bin(geo, rowzone[r], pos[i, 0], pos[i, 1], pos[i, 2], dp)
        key1[r] = b1
        key2[r] = b2
    order = np.argsort(rowzone * 4000000000 + (key1 + 1000000) * 2000000 + (key2 + 1000000)) if m else \
        np.empty(0, np.int64)
    skey = np.empty(m, np.int64)
    for r in range(m):
        o = order[r]
        skey[r] = rowzone[o] * 4000000000 + (key1[o] + 1000000) * 2000000 + (key2[o] + 1000000)
    dp2 = dp * dp
    for k in range(npt):
        z = ptzone[k]
        if pts[k, 2] > zsurf[z] + ZTOL * dp:
            continue
        p1, p2 = _lateral_bin(geo, z, pts[k, 0], pts[k, 1], pts[k, 2], dp)
        dmax = 0.0
        for c1 in range(p1 - 1, p1 + 2):
            for c2 in range(p2 - 1, p2 + 2):
                want = z * 4000000000 + (c1 + 1000000) * 2000000 + (c2 + 1000000)
                r = np.searchsorted(skey, want)
                while r < m and skey[r] == want:
                    i = rows[order[r]]
                    d = -plane_depth(geo, z, pos[i, 0], pos[i, 1], pos[i, 2])
                    sx = pos[i, 0] + d * geo[z, 0] - pts[k, 0]
                    sy = pos[i, 1] + d * geo[z, 1] - pts[k, 1]
                    sz = pos[i, 2] + d * geo[z, 2] - pts[k, 2]
                    s2 = sx * sx + sy * sy + sz * sz
                    if s2 < dp2:
                        e = d + math.sqrt(dp2 - s2)
                        if e > dmax:
                            dmax = e
                    r += 1
        if dmax == 0.0:
            dmax = dp
        if dmax < geo[z, G_W]:
            depth_out[k] = dmax


def rotation_matrix(axis_p1, axis_p2, angle):
    """Rotation by ``angle`` (radians) about the axis through p1 and p2 (right hand): (R, t) with
    x' = R x + t."""
    p1 = np.asarray(axis_p1, float)
    u = np.asarray(axis_p2, float) - p1
    u /= np.linalg.norm(u)
    c, s = math.cos(angle), math.sin(angle)
    ux = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    rot = c * np.eye(3) + s * ux + (1 - c) * np.outer(u, u)
    return rot, p1 - rot @ p1


def zone_points(shape: dict, dp: float, particles: dict | None) -> tuple[np.ndarray, np.ndarray]:
    """The zone's points (its buffer's first row) and unit direction, as JSphInOutPoints builds
    them: the ``<particles mkfluid>`` layer, a ``<line>`` from point to point2 (spacing dp, the last
    gap stretched when it would exceed 0.95 dp), a ``<box>`` lattice likewise on its two non-zero
    sides, or a ``<circle>``'s rings (radius/dp + 1/4 of them, each about 2 pi r/dp points); then the
    rotation."""
    kind = shape["kind"]
    d = np.asarray(shape["direction"], float)
    if kind == "particles":
        sel = (particles["type"] == 3) & (particles["mk"] == shape["mkfluid"] + 1)
        pts = np.asarray(particles["pos"], float)[sel]
    elif kind == "line":
        p1, p2 = np.asarray(shape["point"], float), np.asarray(shape["point2"], float)
        pts = _segment(p1, p2, dp)
    elif kind == "box":
        p0, size = np.asarray(shape["point"], float), np.asarray(shape["size"], float)
        axes = [_segment(np.zeros(3), np.eye(3)[a] * size[a], dp) if size[a] > 0 else np.zeros((1, 3))
                for a in range(3)]
        pts = (p0 + axes[0][None, None, :, :] + axes[1][None, :, None, :] + axes[2][:, None, None, :]).reshape(-1, 3)
    else:
        p0, radius = np.asarray(shape["point"], float), float(shape["radius"])
        v2 = _orthogonal(d)
        v3 = np.cross(d, v2)
        nra = max(1, int((radius + 0.25 * dp) / dp))
        rows = []
        for cr in range(nra + 1):
            ra = radius / nra * cr
            nang = max(1, int((2 * math.pi * ra + dp / 2) / dp))
            ang = 2 * math.pi / nang * np.arange(nang)
            rows.append(p0 + np.outer(ra * np.cos(ang), v2) + np.outer(ra * np.sin(ang), v3))
        pts = np.concatenate(rows)
    rot = shape.get("rotation")
    if rot is not None and rot["angle"] != 0.0:
        r, t = rotation_matrix(rot["p1"], rot["p2"], rot["angle"])
        p0 = pts[0].copy() if len(pts) else np.zeros(3)
        pts = pts @ r.T + t
        d = (r @ (p0 + d) + t) - (r @ p0 + t)
    return pts, d / np.linalg.norm(d)


def _segment(p1, p2, dp):
    dist = float(np.linalg.norm(p2 - p1))
    npt = int(dist / dp)
    step = dp
    if dist - dp * npt > 0.95 * dp:
        npt += 1
        step = dist / npt
    npt += 1
    return p1 + np.outer(np.arange(npt) * step, (p2 - p1) / dist)


def _orthogonal(d):
    """A unit vector orthogonal to ``d``: the coordinate axis least along d, made orthogonal."""
    e = np.eye(3)[int(np.argmin(np.abs(d)))]
    v = e - d * (e @ d)
    return v / np.linalg.norm(v)


class InOutError(ValueError):
    """A zone that cannot be built (its points off their plane, outside the domain, ...)."""


class InOut:
    """The inlet/outlet zones of a run (module docstring): their geometry and configuration as
    arrays for the kernels, the imposed velocity and zsurf at the current time, and which
    particle ids are buffer particles."""

    def __init__(self, spec: dict, constants: dict, dp: float, is2d: bool, zone_points_dirs: list):
        self.spec = spec
        self.dp = float(dp)
        self.is2d = bool(is2d)
        self.determlimit = float(spec.get("determlimit", 1e3))
        zones = spec["zones"]
        nz = len(zones)
        self.geo = np.zeros((nz, NGEO))
        self.cfg = np.zeros((nz, NCFG), np.int64)
        self.coef = np.zeros((nz, 3))
        self.zsurf = np.full(nz, np.inf)
        self.points = []          # each zone's plane lattice (advanced refilling)
        g = np.asarray(constants["gravity"], float)
        b = float(constants.get("b") or constants["cs0"] ** 2 * constants["rhop0"] / constants["gamma"])
        self.coef_hydro = float(constants["rhop0"]) * (-g[2]) / b
        self.gauges = {}
        for k, (zone, (pts, n)) in enumerate(zip(zones, zone_points_dirs)):
            self._set_geometry(k, zone, pts, n, bool(spec.get("useboxlimit", True)))
            self.cfg[k] = (zone["refilling"], zone["inputtreatment"], zone["rhop"]["mode"], zone["velocity"]["mode"],
                           1 if zone["zsurf"].get("remove") else 0)
            self.points.append(pts + 0.5 * self.dp * n)
        self._coef_tables = [_coefficient_table(z["velocity"]) for z in zones]
        # fixed or variable zsurf: (t, zsurf) rows, read once
        self._zsurf_tables = [np.asarray(z["zsurf"]["rows"], float) if z["zsurf"]["mode"] in (0, 1) else None
                              for z in zones]
        self.pts_all = np.concatenate([p for k, p in enumerate(self.points) if self.cfg[k, C_REFILL] == 2]
                                      or [np.zeros((0, 3))])
        self.pts_zone = np.concatenate([np.full(len(p), k, np.int64) for k, p in enumerate(self.points)
                                        if self.cfg[k, C_REFILL] == 2] or [np.zeros(0, np.int64)])
        self.refill2 = self.cfg[:, C_REFILL] == 2
        self.zone_of_idp = np.zeros(0, np.int8)
        self.next_idp = 0
        self.counts = {"created": 0, "removed": 0, "to_fluid": 0, "to_buffer": 0}

    # -- geometry ---------------------------------------------------------------------------------
    def _set_geometry(self, k: int, zone: dict, pts: np.ndarray, n: np.ndarray, box: bool) -> None:
        dp = self.dp
        if len(pts) == 0:
            raise InOutError(f"inout zone {k}: no points (no particles of its mkfluid, or an empty shape)")
        plane = pts[0] + 0.5 * dp * n
        off = (pts - pts[0]) @ n
        if np.max(np.abs(off)) > 0.01 * dp:
            raise InOutError(f"inout zone {k}: its points are not on one plane orthogonal to the direction "
                             f"({np.max(np.abs(off)):.3g} m off it; expected all within 0.01 dp)")
        geo = self.geo[k]
        geo[G_N:G_N + 3] = n
        geo[G_D0] = float(n @ plane)
        shape = zone["shape"]
        if self.is2d:
            t1 = np.array([n[2], 0.0, -n[0]])
            t2 = np.array([0.0, 1.0, 0.0])
        elif shape["kind"] == "box" and shape.get("rotation") is None:
            sides = [np.eye(3)[a] for a in range(3) if abs(np.eye(3)[a] @ n) < 1 - 1e-9]
            t1 = sides[0] - n * (sides[0] @ n)
            t1 /= np.linalg.norm(t1)
            t2 = np.cross(n, t1)
        else:
            t1 = _orthogonal(n)
            t2 = np.cross(n, t1)
        geo[G_T1:G_T1 + 3] = t1
        geo[G_T2:G_T2 + 3] = t2
        centre = plane if shape["kind"] != "circle" else pts[0] + 0.5 * dp * n
        geo[G_C:G_C + 3] = centre
        rel = pts + 0.5 * dp * n - centre
        a1, a2 = rel @ t1, rel @ t2
        geo[G_A1:G_A1 + 2] = (a1.min() - 0.5 * dp, a1.max() + 0.5 * dp)
        geo[G_A2:G_A2 + 2] = ((-1e30, 1e30) if self.is2d else (a2.min() - 0.5 * dp, a2.max() + 0.5 * dp))
        geo[G_R] = float(np.sqrt(a1 ** 2 + a2 ** 2).max()) + 0.5 * dp if shape["kind"] == "circle" else 0.0
        geo[G_W] = zone["layers"] * dp
        geo[G_BOX] = 1.0 if box else 0.0

    # -- values in time ----------------------------------------------------------------------------
    def update_time(self, t: float, state=None) -> None:
        """The velocity profiles' coefficients and zsurf at time ``t`` (a calculated zsurf measured in
        ``state``)."""
        for k, zone in enumerate(self.spec["zones"]):
            tab = self._coef_tables[k]
            if tab is not None:
                for c in range(3):
                    self.coef[k, c] = np.interp(t, tab[:, 0], tab[:, 1 + c])
            zs = zone["zsurf"]
            rows = self._zsurf_tables[k]
            if rows is not None:
                self.zsurf[k] = float(np.interp(t, rows[:, 0], rows[:, 1]))
            elif zs["mode"] == 2 and state is not None:
                self.zsurf[k] = self._measured_zsurf(k, zs, state)

    def _measured_zsurf(self, k: int, zs: dict, state) -> float:
        gauge = self.gauges.get(k)
        if gauge is None:
            return self.zsurf[k]
        g, x, y = gauge
        level = g.level(state, x, y)
        fit = zs["fit"]
        shift = -float(fit["value"]) if "value" in fit else -float(fit["valuedp"]) * self.dp
        if math.isfinite(level):
            return level + shift
        # no water at the gauge: the level stays; before any measurement, the gauge's bottom
        return self.zsurf[k] if math.isfinite(self.zsurf[k]) else g.zmin

    def add_gauges(self, h: float, kernel: int, top: float) -> None:
        """zsurf mode 2: a vertical gauge 2h in front of the centre of each such zone's points
        (JSphInOutZsurf::ComputeZsurfLine: from ``zsurfmin`` (the points' lowest) to the top)."""
        from .surface_gauge import VerticalSurfaceGauge
        for k, zone in enumerate(self.spec["zones"]):
            zs = zone["zsurf"]
            if zs["mode"] != 2:
                continue
            geo = self.geo[k]
            pts = self.points[k] - 0.5 * self.dp * geo[G_N:G_N + 3]       # the zone's points (its first row)
            n = geo[G_N:G_N + 3]
            if abs(n[2]) > 1e-4:
                raise InOutError(f"inout zone {k}: a calculated zsurf (<imposezsurf mode=\"2\">) needs a horizontal "
                                 "direction (DualSPHysics: \"Only horizontal direction is valid\")")
            centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0)) + 2.0 * h * n
            zmin = max(float(zs["zsurfmin"]) if zs.get("zsurfmin") is not None else -np.inf, float(pts[:, 2].min()))
            zmax = max(float(pts[:, 2].max()), top)
            self.gauges[k] = (VerticalSurfaceGauge(zmin, zmax, self.dp, 0.4 if self.is2d else 0.5, kernel, h,
                                                   self.is2d), float(centre[0]), float(centre[1]))

    def initial_values(self, pos: np.ndarray, zone: np.ndarray, rhop0: float, inv_gamma: float):
        """The imposed velocity and density of buffer particles at ``pos`` of ``zone`` now (those to
        be extrapolated: at rest, rho0), for the outputs before the first step."""
        vel = np.zeros((len(pos), 3))
        rho = np.full(len(pos), rhop0)
        for k in np.unique(zone):
            sel = zone == k
            w = pos[sel, 2]
            if self.cfg[k, C_VEL] != 2:
                c = self.coef[k]
                v = (c[0] * w + c[1]) * w + c[2]
                if self.cfg[k, C_REFILL] != 0:
                    v = np.where(w <= self.zsurf[k] + ZTOL * self.dp, v, 0.0)
                vel[sel] = v[:, None] * self.geo[k, G_N:G_N + 3]
            if self.cfg[k, C_RHOP] == 1:
                base = np.maximum(1.0 + self.coef_hydro * (self.zsurf[k] - w), 0.0)
                rho[sel] = rhop0 * np.maximum(base ** inv_gamma, 1.0)
        return vel, rho

    # -- ids ---------------------------------------------------------------------------------------
    def mark(self, idp: np.ndarray, zone) -> None:
        """Set the zone (-1: none) of the particle ids ``idp``, growing the table as needed."""
        idp = np.asarray(idp, np.int64)
        if idp.size == 0:
            return
        top = int(idp.max()) + 1
        if top > self.zone_of_idp.shape[0]:
            grown = np.full(max(top, int(1.25 * self.zone_of_idp.shape[0]) + 1024), -1, np.int8)
            grown[:self.zone_of_idp.shape[0]] = self.zone_of_idp
            self.zone_of_idp = grown
        self.zone_of_idp[idp] = zone

    def take_ids(self, n: int) -> np.ndarray:
        ids = np.arange(self.next_idp, self.next_idp + n, dtype=np.int64)
        self.next_idp += n
        return ids

    def get_state(self) -> dict:
        return {"inout_zone_of_idp": self.zone_of_idp, "inout_next_idp": np.array([self.next_idp], np.int64),
                "inout_zsurf": self.zsurf.copy(),
                "inout_counts": np.array([self.counts[k] for k in sorted(self.counts)], np.int64)}

    def set_state(self, st: dict) -> None:
        self.zone_of_idp = np.ascontiguousarray(st["inout_zone_of_idp"], np.int8)
        self.next_idp = int(np.asarray(st["inout_next_idp"])[0])
        self.zsurf[:] = np.asarray(st["inout_zsurf"], float)
        for k, v in zip(sorted(self.counts), np.asarray(st["inout_counts"]).tolist()):
            self.counts[k] = int(v)


def _coefficient_table(vel: dict):
    """(t, a, b, c) rows of a fixed or variable velocity: v = a z^2 + b z + c through the row's
    values (uniform v; linear (z, v), (z2, v2); parabolic through three points); None when
    extrapolated."""
    if vel["mode"] == 2:
        return None
    out = []
    for r in vel["rows"]:
        t = r[0]
        if vel["profile"] == "uniform":
            out.append([t, 0.0, 0.0, r[1]])
        elif vel["profile"] == "linear":
            v1, v2, z1, z2 = r[1:5]
            m = (v2 - v1) / (z2 - z1)
            out.append([t, 0.0, m, v1 - m * z1])
        else:
            v = np.asarray(r[1:4], float)
            zz = np.asarray(r[4:7], float)
            a, b, c = np.linalg.solve(np.vander(zz, 3), v)
            out.append([t, a, b, c])
    return np.asarray(out, float)


def place_buffers(spec: dict, particles: dict, constants: dict, domain, extra: dict | None = None, *,
                  kernel: int = 2):
    """The run's initial particles with the inlet/outlet buffers in place (module docstring) and
    the :class:`InOut` that follows them.  ``particles``: the case's arrays (pos, vel, rhop, mass,
    type, mk, idp); ``extra``: other per-particle arrays to keep aligned (new rows zero).
    Returns (particles, extra, inout, notes) with ``notes`` lines for the log."""
    dp = float(constants["dp"])
    is2d = bool(constants["is2d"])
    zones = spec["zones"]
    geom = [zone_points(z["shape"], dp, particles) for z in zones]
    io = InOut(spec, constants, dp, is2d, geom)
    io.add_gauges(float(constants["h"]), kernel, float(domain[1][2]))
    # a calculated zsurf starts from the level the case's water has at its gauge (JSphInOutZsurf: the
    # gauge's first measurement, before the zones' particles are placed)
    io.update_time(0.0, _ParticleView(particles))
    n = particles["pos"].shape[0]
    pos = np.asarray(particles["pos"], float)
    ptype = np.asarray(particles["type"])
    mk = np.asarray(particles["mk"])
    drop = np.zeros(n, bool)
    for z in zones:
        if z["shape"]["kind"] == "particles":
            drop |= (ptype == 3) & (mk == z["shape"]["mkfluid"] + 1)
    fluid = np.flatnonzero((ptype == 3) & ~drop)
    near = np.zeros(fluid.size, bool)
    for k in range(len(zones)):
        near |= _in_zone_rows(io.geo, k, pos[fluid], dp)
    drop[fluid[near]] = True
    fluid_mks = mk[(ptype == 3)]
    default_mk = int(fluid_mks.min()) if fluid_mks.size else 1
    new_pos, new_zone, new_mk = [], [], []
    for k, (z, (pts, nvec)) in enumerate(zip(zones, geom)):
        keep = np.ones(len(pts), bool)
        if z["refilling"] != 0 and z["zsurf"]["mode"] is not None:
            keep = pts[:, 2] <= io.zsurf[k] + ZTOL * dp
        rows = np.concatenate([pts[keep] - c * dp * nvec for c in range(z["layers"])])
        lo, hi = domain
        bad = np.any((rows < lo) | (rows > hi), axis=1)
        if bad.any():
            p = rows[np.argmax(bad)]
            raise InOutError(f"inout zone {k} (line {z['line']}): its buffer reaches ({p[0]:.6g}, {p[1]:.6g}, "
                             f"{p[2]:.6g}), outside the simulation domain (expected the zone's {z['layers']} layers "
                             "behind its plane inside <simulationdomain>)")
        new_pos.append(rows)
        new_zone.append(np.full(len(rows), k, np.int8))
        zmk = z["shape"]["mkfluid"] + 1 if z["shape"]["kind"] == "particles" else default_mk
        new_mk.append(np.full(len(rows), zmk))
    add_pos = np.concatenate(new_pos)
    m = add_pos.shape[0]
    keep = ~drop
    out = {k: np.asarray(v)[keep] if np.ndim(v) and np.shape(v)[0] == n else v for k, v in particles.items()}
    idmax = int(np.max(particles["idp"])) + 1 if n else 0
    vel, rho = io.initial_values(add_pos, np.concatenate(new_zone).astype(np.int64), float(constants["rhop0"]),
                                 1.0 / float(constants["gamma"]))
    add = {"pos": add_pos, "vel": vel, "rhop": rho,
           "mass": np.full(m, float(constants["massfluid"])), "type": np.full(m, 3),
           "mk": np.concatenate(new_mk), "idp": np.arange(idmax, idmax + m)}
    for k, v in add.items():
        out[k] = np.concatenate([out[k], v.astype(np.asarray(particles[k]).dtype)])
    ext = {}
    for k, v in (extra or {}).items():
        if v is None:
            ext[k] = None
            continue
        v = np.asarray(v)[keep]
        ext[k] = np.concatenate([v, np.zeros((m,) + v.shape[1:], v.dtype)])
    io.next_idp = idmax + m
    io.mark(np.arange(idmax, idmax + m), np.concatenate(new_zone))
    notes = [f"inout: {len(zones)} zone(s), {m} buffer particles placed"
             + (f", {int(drop.sum())} fluid particles replaced or removed from the zones" if drop.any() else "")]
    return out, ext, io, notes


class _ParticleView:
    """The case's particle arrays as the surface gauge reads a state (pos, mass, rhop, ptype)."""

    def __init__(self, p: dict):
        self.pos = np.ascontiguousarray(p["pos"], float)
        self.mass = np.ascontiguousarray(p["mass"], float)
        self.rhop = np.ascontiguousarray(p["rhop"], float)
        self.ptype = np.ascontiguousarray(p["type"], np.int8)


def _in_zone_rows(geo, k, pos, dp):
    out = np.zeros(pos.shape[0], bool)
    _in_zone_many(geo, k, pos, dp, out)
    return out


@njit(cache=True)
def _in_zone_many(geo, k, pos, dp, out):
    for i in range(pos.shape[0]):
        out[i] = in_zone(geo, k, pos[i, 0], pos[i, 1], pos[i, 2], dp)


def boundcorr_normals(spec: dict, pos: np.ndarray, ptype: np.ndarray, label: np.ndarray, dp: float) -> np.ndarray:
    """``<boundcorr>`` as mDBC normals (JSphBoundCorr): for the particles of each zone's mkbounds the
    vector to their limit plane along its direction, N = -((r - L).d) d (ghost node r + 2N, the mirror
    image through the plane); zero rows elsewhere.  The plane: ``autoconfig`` dp/2 beyond the
    particles' extreme on that side (through the middle of their extent, JSphBoundCorrZone::
    ConfigAutoLimit), ``autolimitpoint`` dpfactor dp beyond the particle furthest along the direction,
    or ``limitpoint``."""
    normals = np.zeros((pos.shape[0], 3))
    for z in spec["zones"]:
        sel = np.flatnonzero((ptype != 3) & np.isin(label, z["mkbound"]))
        if sel.size == 0:
            continue
        p = pos[sel]
        d = np.asarray(z["direction"], float)
        if "auto" in z:
            limit = 0.5 * (p.min(axis=0) + p.max(axis=0))
            a = int(np.argmax(np.abs(d)))
            limit[a] = (p[:, a].max() if d[a] > 0 else p[:, a].min()) + 0.5 * dp * d[a]
        elif "dpfactor" in z:
            k = int(np.argmax(p @ d))
            limit = p[k] + float(z["dpfactor"]) * dp * d
        else:
            limit = np.asarray(z["limitpoint"], float)
        depth = (limit - p) @ d
        normals[sel] = np.maximum(depth, 0.0)[:, None] * d[None, :]
    return normals


r"""Time integrators in the DualSPHysics form (Crespo et al. 2015 §3.3).

Verlet (Verlet 1967), with an Euler step every ``VerletSteps`` steps:
  r^{n+1} = r^n + v^n dt + a^n dt^2/2,
  v^{n+1} = v^{n-1} + 2 dt a^n,      rho^{n+1} = rho^{n-1} + 2 dt D^n,
  Euler:  v^{n+1} = v^n + dt a^n,    rho^{n+1} = rho^n + dt D^n.

Symplectic position Verlet (Leimkuhler 1996), DualSPHysics form:
  predictor  rho^{n+1/2} = rho^n + dt/2 D^n, v^{n+1/2} = v^n + dt/2 a^n,
             r^{n+1/2} = r^n + dt/2 v^n;
  corrector  eps = -(D^{n+1/2}/rho^{n+1/2}) dt,
             rho^{n+1} = rho^n (2 - eps)/(2 + eps),
             v^{n+1} = v^n + dt a^{n+1/2},
             r^{n+1} = r^n + dt/2 (v^n + v^{n+1}).

Boundary particles (DBC) integrate their density only, clamped to
rho >= rho0; moving and floating particles (ptype 1, 2) move with their
imposed velocity, r += v dt.  Fluid particles whose values are not finite,
that leave the domain box (when a domain is given), whose density leaves
[RhopOutMin, RhopOutMax], or whose displacement in the update exceeds
MovLimit in a component are flagged in ``out`` (3 not finite, 2 position,
1 density, 4 movement: the first that applies, DualSPHysics's order in
JSphCpu::UpdatePos after sphdvi's own "not finite"); the drivers return how
many were flagged.  As DualSPHysics (ComputeSymplecticPre), the Symplectic
predictor checks too, on the state at t + dt/2 (the solver removes those
particles before the corrector).  MovLimit is DualSPHysics's 0.9 Scell with
Scell = 2h (its default CellMode "full"; JSph::ConfigCellDivision), whatever
cell size sphdvi's own neighbour search uses.  A particle exactly on the
domain's upper limit stays in: DualSPHysics takes it out (dx >= MapRealSize),
but its domain has a margin of 0.05 h (BORDER_MAP) beyond the case's that
sphdvi's has not.

Shifting 1-3 (Lind et al. 2012, DualSPHysics JSphShifting::RunCpu):
dr_s = A h |v| dt grad C; with ShiftTFS > 0 it is zero where the free-surface
detector div r < ShiftTFS and ramps up above it, times (div r - ShiftTFS)/(d - ShiftTFS)
(d the dimension: 1 in the bulk); each component is then limited to +-0.1 dp.  It
is added to the fluid displacement (Verlet step, Symplectic corrector) when
``shift`` is on.
With ``shift`` 4 (advanced shifting) ``shiftpos`` already holds the displacement
(:mod:`sphdvi.sph.shifting_adv`).

``ip`` holds the step parameters: [dt, rhop0, RhopOutMin, RhopOutMax,
ShiftCoef*h, ShiftTFS, use_domain, xmin, ymin, zmin, xmax, ymax, zmax,
move, 0.1 dp, d - ShiftTFS, MovLimit] where move = 1 lets moving/floating
particles advance with their velocity (no motion hook); 0.1 dp and d - ShiftTFS
are read with Shifting 1-3 only; MovLimit <= 0 switches the movement check off.
"""
import math

from ._env import CHUNK
from numba import njit, prange, literally


@njit(cache=True, error_model="numpy")
def _out_code(x, y, z, rho, rmin, rmax, usedom, x0, y0, z0, x1, y1, z1, moved=False):
    """Exclusion code of a fluid particle (0 keep, 1 density, 2 position, 3 not finite,
    4 movement: ``moved``); position before density before movement, as DualSPHysics's
    JSphCpu::UpdatePos labels them (CODE_SetOutPos, OutRho, OutMov)."""
    if not (math.isfinite(rho) and math.isfinite(x) and math.isfinite(y)
            and math.isfinite(z)):
        return 3
    if usedom:
        if x < x0 or y < y0 or z < z0 or x > x1 or y > y1 or z > z1:
            return 2
    if rho < rmin or rho > rmax:
        return 1
    if moved:
        return 4
    return 0


@njit(cache=True, error_model="numpy")
def _too_far(d, movlim):
    """A displacement component beyond MovLimit (DualSPHysics's UpdatePos outmov; off when
    movlim <= 0)."""
    return movlim > 0.0 and abs(d) > movlim


@njit(cache=True, error_model="numpy")
def _shift_factor(vx, vy, vz, det, coefh, tfs, coeftfs, dt):
    """JSphShifting::RunCpu's magnitude: A h |v| dt; with ShiftTFS > 0, 0 where
    div r < ShiftTFS and times (div r - ShiftTFS)/(d - ShiftTFS) elsewhere."""
    umagn = coefh * math.sqrt(vx * vx + vy * vy + vz * vz) * dt
    if tfs != 0.0:
        if det < tfs:
            return 0.0
        umagn *= (det - tfs) / coeftfs
    return umagn


@njit(cache=True, inline="always")
def _shift_limits(ip, shift):
    """(max displacement per component, dim - ShiftTFS) of Shifting 1-3 from ``ip`` (ip[14], ip[15]);
    (0, 1) otherwise."""
    if shift > 0 and shift < 4:
        return ip[14], ip[15]
    return 0.0, 1.0


@njit(cache=True, error_model="numpy")
def _limited(d, maxd):
    """A shifting component limited to +-0.1 dp (JSphShifting::RunCpu's maxdist; DualSPHysics
    v5.4 clamps both signs, some earlier versions only the positive one)."""
    if d > maxd:
        return maxd
    if d < -maxd:
        return -maxd
    return d


@njit(cache=True, error_model="numpy")
def _verlet_range(i0, i1, shift, euler, pos, vel, rhop, vel_m1, rhop_m1, ace, ar,
                  ptype, shiftpos, shiftdet, ip, out):
    dt = ip[0]
    rhop0 = ip[1]
    rmin = ip[2]
    rmax = ip[3]
    coefh = ip[4]
    tfs = ip[5]
    usedom = ip[6] != 0.0
    x0 = ip[7]
    y0 = ip[8]
    z0 = ip[9]
    x1 = ip[10]
    y1 = ip[11]
    z1 = ip[12]
    move = ip[13] != 0.0
    maxd, coeftfs = _shift_limits(ip, shift)
    movlim = ip[16]
    dt205 = 0.5 * dt * dt
    dt2 = dt if euler else 2.0 * dt
    nout = 0
    for i in range(i0, i1):
        pt = ptype[i]
        r = rhop[i]
        if euler:
            rn = r + dt2 * ar[i]
        else:
            rn = rhop_m1[i] + dt2 * ar[i]
        rhop_m1[i] = r
        if pt == 3:
            sf = 0.0
            if shift > 0 and shift < 4:     # (shift 4: shiftpos is the displacement itself)
                sf = _shift_factor(vel[i, 0], vel[i, 1], vel[i, 2], shiftdet[i],
                                   coefh, tfs, coeftfs, dt)
            moved = False
            for k in range(3):
                v = vel[i, k]
                a = ace[i, k]
                dx = v * dt + a * dt205
                if shift == 4:
                    dx += shiftpos[i, k]
                elif shift > 0:
                    dx += _limited(sf * shiftpos[i, k], maxd)
                moved |= _too_far(dx, movlim)
                pos[i, k] += dx
                if euler:
                    vn = v + a * dt
                else:
                    vn = vel_m1[i, k] + dt2 * a
                vel_m1[i, k] = v
                vel[i, k] = vn
            rhop[i] = rn
            code = _out_code(pos[i, 0], pos[i, 1], pos[i, 2], rn, rmin, rmax, usedom,
                             x0, y0, z0, x1, y1, z1, moved)
            out[i] = code
            if code != 0:
                nout += 1
        else:
            rhop[i] = max(rn, rhop0)
            out[i] = 0
            if pt >= 1:
                for k in range(3):
                    if move:
                        pos[i, k] += vel[i, k] * dt
                    vel_m1[i, k] = vel[i, k]
    return nout


@njit(cache=True, error_model="numpy")
def verlet_serial(shift, euler, pos, vel, rhop, vel_m1, rhop_m1, ace, ar, ptype,
                  shiftpos, shiftdet, ip, out):
    """One Verlet (or Euler, ``euler=True``) step; returns the count of flagged particles."""
    shift = literally(shift)
    return _verlet_range(0, pos.shape[0], shift, euler, pos, vel, rhop, vel_m1, rhop_m1,
                         ace, ar, ptype, shiftpos, shiftdet, ip, out)


@njit(cache=True, parallel=True, error_model="numpy")
def verlet_parallel(shift, euler, pos, vel, rhop, vel_m1, rhop_m1, ace, ar, ptype,
                    shiftpos, shiftdet, ip, out):
    """Threaded :func:`verlet_serial`."""
    shift = literally(shift)
    n = pos.shape[0]
    nout = 0
    for c in prange((n + CHUNK - 1) // CHUNK):
        nout += _verlet_range(c * CHUNK, min(n, (c + 1) * CHUNK), shift, euler, pos, vel,
                              rhop, vel_m1, rhop_m1, ace, ar, ptype, shiftpos, shiftdet,
                              ip, out)
    return nout


@njit(cache=True, error_model="numpy")
def _sym_pre_range(i0, i1, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                   ptype, ip, out):
    dt05 = 0.5 * ip[0]
    rhop0 = ip[1]
    rmin = ip[2]
    rmax = ip[3]
    usedom = ip[6] != 0.0
    move = ip[13] != 0.0
    movlim = ip[16]
    nout = 0
    for i in range(i0, i1):
        pt = ptype[i]
        for k in range(3):
            pos_pre[i, k] = pos[i, k]
            vel_pre[i, k] = vel[i, k]
        rhop_pre[i] = rhop[i]
        if pt == 3:
            rn = rhop_pre[i] + dt05 * ar[i]
            rhop[i] = rn
            moved = False
            for k in range(3):
                dx = dt05 * vel_pre[i, k]
                moved |= _too_far(dx, movlim)
                pos[i, k] = pos_pre[i, k] + dx
                vel[i, k] = vel_pre[i, k] + dt05 * ace[i, k]
            # DualSPHysics's ComputeSymplecticPre: density and UpdatePos at t + dt/2
            code = _out_code(pos[i, 0], pos[i, 1], pos[i, 2], rn, rmin, rmax, usedom,
                             ip[7], ip[8], ip[9], ip[10], ip[11], ip[12], moved)
            out[i] = code
            if code != 0:
                nout += 1
        else:
            out[i] = 0
            rhop[i] = max(rhop_pre[i] + dt05 * ar[i], rhop0)
            if pt >= 1 and move:
                for k in range(3):
                    pos[i, k] = pos_pre[i, k] + dt05 * vel[i, k]
    return nout


@njit(cache=True, error_model="numpy")
def symplectic_pre_serial(pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                          ptype, ip, out):
    """Symplectic predictor: saves the state at n in ``*_pre`` and advances dt/2; returns
    the count of fluid particles flagged in ``out`` at the half step."""
    return _sym_pre_range(0, pos.shape[0], pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                          ar, ptype, ip, out)


@njit(cache=True, parallel=True, error_model="numpy")
def symplectic_pre_parallel(pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                            ptype, ip, out):
    """Threaded :func:`symplectic_pre_serial`."""
    n = pos.shape[0]
    nout = 0
    for c in prange((n + CHUNK - 1) // CHUNK):
        nout += _sym_pre_range(c * CHUNK, min(n, (c + 1) * CHUNK), pos, vel, rhop, pos_pre,
                               vel_pre, rhop_pre, ace, ar, ptype, ip, out)
    return nout


@njit(cache=True, error_model="numpy")
def _sym_corr_range(i0, i1, shift, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                    ar, ptype, shiftpos, shiftdet, ip, out):
    dt = ip[0]
    dt05 = 0.5 * dt
    rhop0 = ip[1]
    rmin = ip[2]
    rmax = ip[3]
    coefh = ip[4]
    tfs = ip[5]
    usedom = ip[6] != 0.0
    x0 = ip[7]
    y0 = ip[8]
    z0 = ip[9]
    x1 = ip[10]
    y1 = ip[11]
    z1 = ip[12]
    move = ip[13] != 0.0
    maxd, coeftfs = _shift_limits(ip, shift)
    movlim = ip[16]
    nout = 0
    for i in range(i0, i1):
        pt = ptype[i]
        eps = -(ar[i] / rhop[i]) * dt
        rn = rhop_pre[i] * (2.0 - eps) / (2.0 + eps)
        if pt == 3:
            sf = 0.0
            if shift > 0 and shift < 4:     # (shift 4: shiftpos is the displacement itself)
                sf = _shift_factor(vel[i, 0], vel[i, 1], vel[i, 2], shiftdet[i],
                                   coefh, tfs, coeftfs, dt)
            rhop[i] = rn
            moved = False
            for k in range(3):
                vn = vel_pre[i, k] + dt * ace[i, k]
                dx = (vel_pre[i, k] + vn) * dt05
                if shift == 4:
                    dx += shiftpos[i, k]
                elif shift > 0:
                    dx += _limited(sf * shiftpos[i, k], maxd)
                moved |= _too_far(dx, movlim)
                vel[i, k] = vn
                pos[i, k] = pos_pre[i, k] + dx
            code = _out_code(pos[i, 0], pos[i, 1], pos[i, 2], rn, rmin, rmax, usedom,
                             x0, y0, z0, x1, y1, z1, moved)
            out[i] = code
            if code != 0:
                nout += 1
        else:
            rhop[i] = max(rn, rhop0)
            out[i] = 0
            if pt >= 1 and move:
                for k in range(3):
                    pos[i, k] = pos_pre[i, k] + dt * vel[i, k]
    return nout


@njit(cache=True, error_model="numpy")
def symplectic_corr_serial(shift, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                           ar, ptype, shiftpos, shiftdet, ip, out):
    """Symplectic corrector; returns the count of flagged particles."""
    shift = literally(shift)
    return _sym_corr_range(0, pos.shape[0], shift, pos, vel, rhop, pos_pre, vel_pre,
                           rhop_pre, ace, ar, ptype, shiftpos, shiftdet, ip, out)


@njit(cache=True, parallel=True, error_model="numpy")
def symplectic_corr_parallel(shift, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                             ar, ptype, shiftpos, shiftdet, ip, out):
    """Threaded :func:`symplectic_corr_serial`."""
    shift = literally(shift)
    n = pos.shape[0]
    nout = 0
    for c in prange((n + CHUNK - 1) // CHUNK):
        nout += _sym_corr_range(c * CHUNK, min(n, (c + 1) * CHUNK), shift, pos, vel, rhop,
                                pos_pre, vel_pre, rhop_pre, ace, ar, ptype, shiftpos,
                                shiftdet, ip, out)
    return nout

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
imposed velocity, r += v dt.  Fluid particles whose density leaves
[RhopOutMin, RhopOutMax], whose values are not finite, or (when a domain is
given) that leave the domain box are flagged in ``out`` (1 density, 2
position, 3 not finite); the drivers return how many were flagged.

Shifting (Lind et al. 2012, DualSPHysics form): dr_s = A h |v| dt grad C,
set to zero where the free-surface detector div r < ShiftTFS.  It is added to
the fluid displacement (Verlet step, Symplectic corrector) when ``shift`` is on.

``ip`` holds the step parameters: [dt, rhop0, RhopOutMin, RhopOutMax,
ShiftCoef*h, ShiftTFS, use_domain, xmin, ymin, zmin, xmax, ymax, zmax].
"""
import math

from . import _env  # noqa: F401
from numba import njit, prange, literally


@njit(cache=True)
def _check_out(i, pos, rho, ip, out):
    """Flag code of fluid particle i (0 keep, 1 density, 2 position, 3 not finite)."""
    if not (math.isfinite(rho) and math.isfinite(pos[i, 0])
            and math.isfinite(pos[i, 1]) and math.isfinite(pos[i, 2])):
        out[i] = 3
        return 1
    if rho < ip[2] or rho > ip[3]:
        out[i] = 1
        return 1
    if ip[6] != 0.0:
        for k in range(3):
            if pos[i, k] < ip[7 + k] or pos[i, k] > ip[10 + k]:
                out[i] = 2
                return 1
    out[i] = 0
    return 0


@njit(cache=True)
def _shift_factor(i, vel, shiftdet, ip):
    """A h |v| dt, or 0 at the free surface (div r < ShiftTFS)."""
    if shiftdet[i] < ip[5]:
        return 0.0
    vm = math.sqrt(vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2)
    return ip[4] * vm * ip[0]


@njit(cache=True)
def _verlet_particle(i, shift, euler, pos, vel, rhop, vel_m1, rhop_m1, ace, ar,
                     ptype, shiftpos, shiftdet, ip, out):
    dt = ip[0]
    pt = ptype[i]
    if pt == 3:
        sf = 0.0
        if shift > 0:
            sf = _shift_factor(i, vel, shiftdet, ip)
        dt205 = 0.5 * dt * dt
        for k in range(3):
            v = vel[i, k]
            a = ace[i, k]
            dx = v * dt + a * dt205
            if shift > 0:
                dx += sf * shiftpos[i, k]
            pos[i, k] += dx
            if euler:
                vn = v + a * dt
            else:
                vn = vel_m1[i, k] + 2.0 * dt * a
            vel_m1[i, k] = v
            vel[i, k] = vn
        r = rhop[i]
        if euler:
            rn = r + dt * ar[i]
        else:
            rn = rhop_m1[i] + 2.0 * dt * ar[i]
        rhop_m1[i] = r
        rhop[i] = rn
        return _check_out(i, pos, rn, ip, out)
    r = rhop[i]
    if euler:
        rn = r + dt * ar[i]
    else:
        rn = rhop_m1[i] + 2.0 * dt * ar[i]
    rhop_m1[i] = r
    rhop[i] = max(rn, ip[1])
    if pt >= 1:
        for k in range(3):
            pos[i, k] += vel[i, k] * dt
            vel_m1[i, k] = vel[i, k]
    out[i] = 0
    return 0


@njit(cache=True)
def verlet_serial(shift, euler, pos, vel, rhop, vel_m1, rhop_m1, ace, ar, ptype,
                  shiftpos, shiftdet, ip, out):
    """One Verlet (or Euler, ``euler=True``) step; returns the count of flagged particles."""
    shift = literally(shift)
    nout = 0
    for i in range(pos.shape[0]):
        nout += _verlet_particle(i, shift, euler, pos, vel, rhop, vel_m1, rhop_m1,
                                 ace, ar, ptype, shiftpos, shiftdet, ip, out)
    return nout


@njit(cache=True, parallel=True)
def verlet_parallel(shift, euler, pos, vel, rhop, vel_m1, rhop_m1, ace, ar, ptype,
                    shiftpos, shiftdet, ip, out):
    """Threaded :func:`verlet_serial`."""
    shift = literally(shift)
    nout = 0
    for i in prange(pos.shape[0]):
        nout += _verlet_particle(i, shift, euler, pos, vel, rhop, vel_m1, rhop_m1,
                                 ace, ar, ptype, shiftpos, shiftdet, ip, out)
    return nout


@njit(cache=True)
def _sym_pre_particle(i, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                      ptype, ip):
    dt05 = 0.5 * ip[0]
    pt = ptype[i]
    for k in range(3):
        pos_pre[i, k] = pos[i, k]
        vel_pre[i, k] = vel[i, k]
    rhop_pre[i] = rhop[i]
    if pt == 3:
        rhop[i] = rhop_pre[i] + dt05 * ar[i]
        for k in range(3):
            pos[i, k] = pos_pre[i, k] + dt05 * vel_pre[i, k]
            vel[i, k] = vel_pre[i, k] + dt05 * ace[i, k]
    else:
        rhop[i] = max(rhop_pre[i] + dt05 * ar[i], ip[1])
        if pt >= 1:
            for k in range(3):
                pos[i, k] = pos_pre[i, k] + dt05 * vel[i, k]


@njit(cache=True)
def symplectic_pre_serial(pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                          ptype, ip):
    """Symplectic predictor: saves the state at n in ``*_pre`` and advances dt/2."""
    for i in range(pos.shape[0]):
        _sym_pre_particle(i, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                          ptype, ip)


@njit(cache=True, parallel=True)
def symplectic_pre_parallel(pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                            ptype, ip):
    """Threaded :func:`symplectic_pre_serial`."""
    for i in prange(pos.shape[0]):
        _sym_pre_particle(i, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace, ar,
                          ptype, ip)


@njit(cache=True)
def _sym_corr_particle(i, shift, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                       ar, ptype, shiftpos, shiftdet, ip, out):
    dt = ip[0]
    dt05 = 0.5 * dt
    pt = ptype[i]
    eps = -(ar[i] / rhop[i]) * dt
    rn = rhop_pre[i] * (2.0 - eps) / (2.0 + eps)
    if pt == 3:
        sf = 0.0
        if shift > 0:
            sf = _shift_factor(i, vel, shiftdet, ip)
        rhop[i] = rn
        for k in range(3):
            vn = vel_pre[i, k] + dt * ace[i, k]
            dx = (vel_pre[i, k] + vn) * dt05
            if shift > 0:
                dx += sf * shiftpos[i, k]
            vel[i, k] = vn
            pos[i, k] = pos_pre[i, k] + dx
        return _check_out(i, pos, rn, ip, out)
    rhop[i] = max(rn, ip[1])
    if pt >= 1:
        for k in range(3):
            pos[i, k] = pos_pre[i, k] + dt * vel[i, k]
    out[i] = 0
    return 0


@njit(cache=True)
def symplectic_corr_serial(shift, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                           ar, ptype, shiftpos, shiftdet, ip, out):
    """Symplectic corrector; returns the count of flagged particles."""
    shift = literally(shift)
    nout = 0
    for i in range(pos.shape[0]):
        nout += _sym_corr_particle(i, shift, pos, vel, rhop, pos_pre, vel_pre,
                                   rhop_pre, ace, ar, ptype, shiftpos, shiftdet,
                                   ip, out)
    return nout


@njit(cache=True, parallel=True)
def symplectic_corr_parallel(shift, pos, vel, rhop, pos_pre, vel_pre, rhop_pre, ace,
                             ar, ptype, shiftpos, shiftdet, ip, out):
    """Threaded :func:`symplectic_corr_serial`."""
    shift = literally(shift)
    nout = 0
    for i in prange(pos.shape[0]):
        nout += _sym_corr_particle(i, shift, pos, vel, rhop, pos_pre, vel_pre,
                                   rhop_pre, ace, ar, ptype, shiftpos, shiftdet,
                                   ip, out)
    return nout

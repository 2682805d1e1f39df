"""Imposed accelerations of fluid blocks: DualSPHysics's ``<accinputs>`` (JDsAccInput).

A block (its mkfluid values) in a frame that accelerates and turns: at each step its
particles get, on top of the SPH forces,

    a += a_lin                                  (linear acceleration of the frame)
         − g                                    (only with globalgravity = 0: the table holds it)
         + α × d + ω × (ω × d)                  (angular acceleration, centripetal term)
         + 2 ω × (v − v_lin)                    (Coriolis term)

with d = x − centre, α the angular acceleration of the table and ω, v_lin the velocities
integrated from it.  As DualSPHysics 5.4 does, so that its cases give its results:

* the velocities are integrated by rectangles with each row's own acceleration,
  v_k = v_(k−1) + a_k (t_k − t_(k−1)), v_0 = 0, and interpolated linearly;
* the angular terms are added only while the angular acceleration α is not zero (a
  rotation held at constant ω gets no centripetal or Coriolis term);
* in the Coriolis term, the component along an axis subtracts v_lin only in the second
  product (x: 2(ω_y v_z − ω_z (v_y − v_lin,y)), and cyclically);
* the table is read at the time the step starts (both stages of Symplectic), and outside
  ``<time start end>`` nothing is added.

In 2D (x-z) the y component of the addition is dropped.
"""
from __future__ import annotations

import math

import numpy as np

from . import _env  # noqa: F401
from numba import njit, prange

from .timestep import force_term_ace2


def integrated_velocities(table: np.ndarray) -> np.ndarray:
    """Rows (t, v_lin (3), ω (3)) of DualSPHysics's ComputeVelocity: v_0 = 0,
    v_k = v_(k−1) + a_k (t_k − t_(k−1)) with the acceleration a_k of row k."""
    t = table[:, 0]
    vel = np.zeros((t.size, 6))
    for k in range(1, t.size):
        vel[k] = vel[k - 1] + table[k, 1:7] * (t[k] - t[k - 1])
    return np.column_stack([t, vel])


class AccInput:
    """One ``<accinput>``: its fluid mk values (particle ``mk`` = mkfluid + 1), active
    interval, centre, gravity flag and (time, acceleration) table."""

    def __init__(self, spec: dict):
        self.mk = np.asarray([m + 1 for m in spec["mkfluid"]], np.int32)
        self.start = float(spec.get("start", 0.0))
        end = spec.get("end")
        self.end = math.inf if end is None else float(end)
        self.centre = np.asarray(spec["centre"], float)
        self.globalgravity = bool(spec["globalgravity"])
        self.table = np.asarray(spec["table"], float)
        self.velocities = integrated_velocities(self.table)
        self.times = np.ascontiguousarray(self.table[:, 0])     # searched every step: no copy per look-up

    def values(self, t: float):
        """(a_lin, α, v_lin, ω) at time t (linear interpolation, end values outside the
        table), or None outside the active interval."""
        if not (self.start <= t <= self.end):
            return None
        acc = linear_value(self.times, self.table[:, 1:7], t)
        vel = linear_value(self.times, self.velocities[:, 1:7], t)
        return acc[:3], acc[3:], vel[:3], vel[3:]


def linear_value(times: np.ndarray, values: np.ndarray, t: float) -> np.ndarray:
    """The row of ``values`` at time t, as DualSPHysics's JLinearValue::FindTime/GetValue3d3d:
    linear between the rows around t, the first or last row outside the table; at a time
    the table repeats (a step), the first of its rows (the value before the step), the last
    one just after it."""
    nxt = min(max(int(np.searchsorted(times, t, side="left")), 1), times.size - 1)
    pre = nxt - 1
    if t <= times[pre]:
        return values[pre].copy()
    if t >= times[nxt]:
        return values[nxt].copy()
    return values[pre] + (values[nxt] - values[pre]) * ((t - times[pre]) / (times[nxt] - times[pre]))


def acc_inputs(specs) -> list:
    """The case's ``<accinputs>`` (``special["accinputs"]``) as AccInput objects ([] when none)."""
    return [AccInput(s) for s in specs or []]


def _add_range(i0, i1, ace, pos, vel, mk, ptype, mks, lin, ang, vlin, w, centre, angular, is2d):
    for i in range(i0, i1):
        if ptype[i] != 3:
            continue
        hit = False
        for m in mks:
            if mk[i] == m:
                hit = True
                break
        if not hit:
            continue
        ax = lin[0]
        ay = lin[1]
        az = lin[2]
        if angular:
            dx = pos[i, 0] - centre[0]
            dy = pos[i, 1] - centre[1]
            dz = pos[i, 2] - centre[2]
            # α × d
            ax += ang[1] * dz - ang[2] * dy
            ay += ang[2] * dx - ang[0] * dz
            az += ang[0] * dy - ang[1] * dx
            # ω × (ω × d)
            cx = w[1] * dz - w[2] * dy
            cy = w[2] * dx - w[0] * dz
            cz = w[0] * dy - w[1] * dx
            ax += w[1] * cz - w[2] * cy
            ay += w[2] * cx - w[0] * cz
            az += w[0] * cy - w[1] * cx
            # Coriolis, in DualSPHysics's form
            vx = vel[i, 0]
            vy = vel[i, 1]
            vz = vel[i, 2]
            ax += 2.0 * w[1] * vz - 2.0 * w[2] * (vy - vlin[1])
            ay += 2.0 * w[2] * vx - 2.0 * w[0] * (vz - vlin[2])
            az += 2.0 * w[0] * vy - 2.0 * w[1] * (vx - vlin[0])
        ace[i, 0] += ax
        if not is2d:
            ace[i, 1] += ay
        ace[i, 2] += az


_add_serial = njit(cache=True)(_add_range)


@njit(cache=True, parallel=True)
def _add_parallel(ace, pos, vel, mk, ptype, mks, lin, ang, vlin, w, centre, angular, is2d):
    n = ace.shape[0]
    nchunks = (n + 4095) // 4096
    for c in prange(nchunks):
        _add_serial(c * 4096, min(n, (c + 1) * 4096), ace, pos, vel, mk, ptype, mks, lin, ang, vlin, w, centre,
                    angular, is2d)


def add_acc_input(ace, pos, vel, mk, ptype, inp: AccInput, t: float, gravity: np.ndarray, is2d: bool,
                  parallel: bool = False) -> bool:
    """Add input ``inp`` at time ``t`` to the accelerations of its fluid particles (state
    order); returns False when it is not active at t."""
    v = inp.values(t)
    if v is None:
        return False
    lin, ang, vlin, w = v
    if not inp.globalgravity:
        lin = lin - gravity
    args = (ace, pos, vel, mk, ptype, inp.mk, lin, ang, vlin, w, inp.centre, bool(np.any(ang != 0.0)), bool(is2d))
    if parallel:
        _add_parallel(*args)
    else:
        _add_serial(0, ace.shape[0], *args)
    return True


@njit(cache=True)
def fluid_ace_max2(ace, ptype, gx=0.0, gy=0.0, gz=0.0):
    """max |a|² of the force term of the time step, as DualSPHysics's ComputeAceMax: over
    fluid (their ace less the gravity (gx, gy, gz) it holds) and floating particles."""
    amax = 0.0
    for i in range(ace.shape[0]):
        a = force_term_ace2(ace, i, ptype[i], gx, gy, gz)
        if a > amax:
            amax = a
    return amax

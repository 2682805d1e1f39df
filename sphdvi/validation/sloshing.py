"""S7: linear standing wave (sloshing mode 1) in a 2D tank.

The free surface starts at η(x) = a cos(k x), k = π/L, at rest; linear theory gives the
period T = 2π/ω with ω² = g k tanh(k d). The period is read from the horizontal
centre of mass of the fluid, which oscillates with the mode.
"""
from __future__ import annotations

import math

import numpy as np


def linear_period(length: float, depth: float, g: float = 9.81, mode: int = 1) -> float:
    k = mode * math.pi / length
    return 2 * math.pi / math.sqrt(g * k * math.tanh(k * depth))


def sloshing_particles(length=1.0, depth=0.5, amplitude=0.02, dp=0.0125, rhop0=1000.0, gamma=7.0,
                       coefsound=20.0, g=9.81, layers=1):
    """Fluid lattice under η = a cos(kx) in a tank with ``layers`` layers of boundary
    particles (bottom, left, right; the tank walls lie dp/2 inside the first layer) and
    the matching constants (DualSPHysics rules, coefh 1.0)."""
    k = math.pi / length
    nx = int(round(length / dp))
    xs = (np.arange(nx) + 0.5) * dp
    zs = (np.arange(int((depth + 2 * amplitude) / dp)) + 0.5) * dp
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    surf = depth + amplitude * np.cos(k * X)
    inside = Z <= surf
    fx, fz = X[inside], Z[inside]
    top = np.max(np.where(inside, Z, -np.inf), axis=1)[:, None] * np.ones_like(Z)
    ftop = top[inside]
    cs0 = coefsound * math.sqrt(g * depth)
    b = cs0 * cs0 * rhop0 / gamma
    rho_f = rhop0 * (1 + rhop0 * g * (ftop - fz) / b) ** (1 / gamma)
    # one layer of boundary particles one dp from the fluid lattice: bottom at z = −dp/2,
    # walls at x = −dp/2 and x = L + dp/2 (the fluid occupies [0, L] x [0, η])
    parts = []
    for m in range(layers):
        off = (m + 0.5) * dp
        bottom_x = (np.arange(-1 - m, nx + 1 + m) + 0.5) * dp
        parts.append(np.column_stack([bottom_x, np.full(bottom_x.size, -off)]))
        wall_z = (np.arange(0, int(depth * 1.6 / dp)) + 0.5) * dp
        parts.append(np.column_stack([np.full(wall_z.size, -off), wall_z]))
        parts.append(np.column_stack([np.full(wall_z.size, length + off), wall_z]))
    bnd = np.vstack(parts)
    n_b, n_f = bnd.shape[0], fx.size
    pos = np.zeros((n_b + n_f, 3))
    pos[:n_b, 0], pos[:n_b, 2] = bnd[:, 0], bnd[:, 1]
    pos[n_b:, 0], pos[n_b:, 2] = fx, fz
    rhop = np.concatenate([np.full(n_b, rhop0), rho_f])
    ptype = np.concatenate([np.zeros(n_b, np.int8), np.full(n_f, 3, np.int8)])
    mass = np.full(n_b + n_f, rhop0 * dp * dp)
    constants = {"dp": dp, "h": math.sqrt(2) * dp, "b": b, "cs0": cs0, "rhop0": rhop0, "gamma": gamma,
                 "gravity": [0.0, 0.0, -g], "is2d": True, "cflnumber": 0.2}
    return pos, rhop, ptype, mass, constants


def period_from_signal(t, x) -> tuple[float, float]:
    """Mean period from up-crossings of x − mean(x) (with hysteresis: the signal must swing
    below −30 % of its amplitude between two crossings, so noise does not count), and the
    mean relative amplitude loss per period (from successive maxima)."""
    t, y = np.asarray(t, float), np.asarray(x, float)
    y = y - y.mean()
    amp = np.abs(y).max()
    if amp == 0:
        return float("nan"), float("nan")
    armed, cross, peaks, peak = False, [], [], 0.0
    for i in range(1, y.size):
        if y[i] < -0.3 * amp:
            armed = True
        if armed and y[i - 1] < 0 <= y[i]:
            cross.append(t[i - 1] - y[i - 1] * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))
            armed = False
            if len(cross) > 1:
                peaks.append(peak)
            peak = 0.0
        peak = max(peak, y[i])
    period = float(np.mean(np.diff(cross))) if len(cross) >= 2 else float("nan")
    decay = float(1 - np.mean(np.array(peaks[1:]) / np.array(peaks[:-1]))) if len(peaks) >= 2 else float("nan")
    return period, decay

"""The free-surface level on one vertical line, measured inside the time loop from the solver's
arrays (the gauge of an absorbing piston, :mod:`sphdvi.wave_absorption`).

As the ``swl`` gauges (DualSPHysics's JGaugeSwl, sphdvi's :func:`sphdvi.measure.core.surface_along_lines`):
the kernel sum Σ_b (m_b/ρ_b) W(x − x_b) of the fluid particles is sampled every ``dz`` up the line and the
surface is the first point where it drops below the threshold (0.4 in 2D, 0.5 in 3D) after having
reached it, linearly interpolated between samples. One pass over the particles picks those within 2h
of the line (a few hundred), so it costs about as much as one light kernel per step.
"""
from __future__ import annotations

import math

import numpy as np

from . import _env  # noqa: F401
from numba import njit

from .kernels import kernel_alpha, kernel_w
from ..measure._kernels import first_drop_below


@njit(cache=True)
def vertical_kernel_sum(pos, mass, rhop, ptype, x, y, z0, dz, kind, h, alpha, is2d, out):
    """``out[k]`` = Σ_b V_b W at (x, y, z0 + k dz) over the fluid particles (ptype 3), V_b = m_b/ρ_b
    (in 2D y is not used)."""
    ns = out.shape[0]
    for k in range(ns):
        out[k] = 0.0
    r2max = 4.0 * h * h
    inv_h = 1.0 / h
    for j in range(pos.shape[0]):
        if ptype[j] != 3:
            continue
        dx = pos[j, 0] - x
        rh2 = dx * dx
        if not is2d:
            dy = pos[j, 1] - y
            rh2 += dy * dy
        if rh2 >= r2max:
            continue
        reach = math.sqrt(r2max - rh2)
        zj = pos[j, 2]
        k0 = max(0, int(math.ceil((zj - reach - z0) / dz)))
        k1 = min(ns - 1, int(math.floor((zj + reach - z0) / dz)))
        vol = mass[j] / rhop[j]
        for k in range(k0, k1 + 1):
            ddz = z0 + k * dz - zj
            r2 = rh2 + ddz * ddz
            if r2 < r2max:
                out[k] += vol * kernel_w(kind, math.sqrt(r2) * inv_h, alpha)


class VerticalSurfaceGauge:
    """The free surface on the vertical line at (x, y) between ``zmin`` and ``zmax``, sampled every
    ``dz``: :meth:`level` → its z, or NaN where the line meets no fluid."""

    def __init__(self, zmin: float, zmax: float, dz: float, threshold: float, kind: int, h: float, is2d: bool):
        self.nsample = max(2, int(math.floor((zmax - zmin) / dz)) + 1)
        self.zmin, self.dz = float(zmin), float(dz)
        self.threshold = float(threshold)
        self.kind, self.h, self.is2d = int(kind), float(h), bool(is2d)
        self.alpha = kernel_alpha(self.kind, self.h, self.is2d)
        self._ksum = np.zeros(self.nsample)
        self._frac = np.zeros(1)

    def level(self, state, x: float, y: float) -> float:
        vertical_kernel_sum(state.pos, state.mass, state.rhop, state.ptype, float(x), float(y), self.zmin,
                            self.dz, self.kind, self.h, self.alpha, self.is2d, self._ksum)
        first_drop_below(self._ksum, self.nsample, self.threshold, self._frac)
        frac = self._frac[0]
        return math.nan if frac < 0 else self.zmin + frac * self.dz

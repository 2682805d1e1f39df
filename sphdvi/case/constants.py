"""DualSPHysics's rules for the constants a case leaves on ``auto``.

From GenCase (``../shared/design/case-format.md`` §2.1):

* hswl (auto)        = height of the fluid: max z − min z of the fluid particles;
* speedsystem (auto) = sqrt(|g| · hswl) (dam-break front speed);
* speedsound (auto)  = coefsound · speedsystem  (c0);
* h                  = coefh · sqrt(3 dp²) in 3D, coefh · sqrt(2 dp²) in 2D, or hdp · dp;
* B                  = c0² ρ0 / γ (Tait); an explicit B sets c0 = sqrt(γ B / ρ0) instead,
  as the DualSPHysics solver derives c0 from B (whatever speedsound says);
* massfluid = massbound = ρ0 dp³ (ρ0 dp² in 2D, per metre of width).
"""
from __future__ import annotations

import math

import numpy as np

from .model import Constants, ConstantsDef

DEFAULT_COEFH = 0.866025


def resolve_constants(cdef: ConstantsDef, dp: float, is2d: bool, posy2d: float,
                      fluid_z: np.ndarray) -> Constants:
    """Apply the auto rules; ``fluid_z`` are the z coordinates of the fluid particles."""
    g = float(np.linalg.norm(cdef.gravity))
    if cdef.hswl is not None:
        hswl = cdef.hswl
    elif fluid_z.size:
        hswl = float(fluid_z.max() - fluid_z.min())
    else:
        hswl = 0.0
    speedsystem = cdef.speedsystem if cdef.speedsystem is not None else math.sqrt(g * hswl)
    cs0 = cdef.speedsound if cdef.speedsound is not None else cdef.coefsound * speedsystem
    if cdef.hdp is not None:
        h = cdef.hdp * dp
        coefh = h / (dp * math.sqrt(2.0 if is2d else 3.0))
    else:
        coefh = cdef.coefh if cdef.coefh is not None else DEFAULT_COEFH
        h = coefh * math.sqrt((2.0 if is2d else 3.0) * dp * dp)
    if cdef.h is not None:
        h = cdef.h
    if cdef.b is not None:
        b = cdef.b
        cs0 = math.sqrt(cdef.gamma * b / cdef.rhop0)      # DualSPHysics's JSph::ConfigConstants
    else:
        b = cs0 * cs0 * cdef.rhop0 / cdef.gamma
    vol = dp * dp if is2d else dp ** 3
    massfluid = cdef.massfluid if cdef.massfluid is not None else cdef.rhop0 * vol
    massbound = cdef.massbound if cdef.massbound is not None else cdef.rhop0 * vol
    return Constants(dp=dp, h=h, b=b, cs0=cs0, rhop0=cdef.rhop0, gamma=cdef.gamma,
                     gravity=list(map(float, cdef.gravity)), cflnumber=cdef.cflnumber, hswl=hswl,
                     speedsystem=speedsystem, coefsound=cdef.coefsound, coefh=coefh,
                     massfluid=massfluid, massbound=massbound, is2d=bool(is2d), posy2d=float(posy2d),
                     rhopgradient=cdef.rhopgradient)


def hydrostatic_density(depth: np.ndarray, rhop0: float, gravity_z: float, b: float, gamma: float) -> np.ndarray:
    """Tait density of a hydrostatic column: ρ = ρ0 (1 + ρ0 |g| depth / B)^(1/γ)."""
    if b <= 0:
        return np.full(depth.shape, rhop0)
    return rhop0 * np.power(1.0 + rhop0 * abs(gravity_z) * np.maximum(depth, 0.0) / b, 1.0 / gamma)

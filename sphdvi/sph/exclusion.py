"""Particle exclusion bookkeeping (DualSPHysics "particles out").

DualSPHysics removes a fluid particle from the run when its density leaves
[RhopOutMin, RhopOutMax], when it leaves the simulation domain, when it moves
more than MovLimit (0.9 x 2h) in one update ("movement", DualSPHysics's
CODE_OUTMOV), or (sphdvi's own) when its values are not finite.  These helpers return masks and counts (numpy only).
"""
import numpy as np

from .state import FLUID

REASON_RHOP = 1
REASON_POS = 2
REASON_NAN = 3
REASON_MOV = 4
REASON_NAMES = {REASON_RHOP: "rhop", REASON_POS: "position", REASON_NAN: "not finite",
                REASON_MOV: "movement"}


def rhop_out_mask(rhop, ptype, rhop_min, rhop_max):
    """Fluid particles with density outside [rhop_min, rhop_max]."""
    return (ptype == FLUID) & ((rhop < rhop_min) | (rhop > rhop_max))


def domain_out_mask(pos, ptype, pmin, pmax):
    """Fluid particles outside the box [pmin, pmax]."""
    pmin = np.asarray(pmin, float)
    pmax = np.asarray(pmax, float)
    return (ptype == FLUID) & np.any((pos < pmin) | (pos > pmax), axis=1)


def not_finite_mask(pos, vel, rhop):
    """Particles with a NaN or inf position, velocity or density."""
    return ~(np.isfinite(pos).all(1) & np.isfinite(vel).all(1) & np.isfinite(rhop))


def count_reasons(codes):
    """{reason name: count} for the non-zero exclusion codes."""
    codes = np.asarray(codes)
    return {name: int(np.count_nonzero(codes == c)) for c, name in REASON_NAMES.items()}

"""Damping zones (DualSPHysics ``<special><damping>``, JDamping): fluid velocities
reduced progressively towards an outflow end of the domain, to absorb waves."""
import numpy as np

from .state import FLUID


class DampingZone:
    """``<special><damping><dampingzone>``: fluid velocities are reduced progressively
    from ``limitmin`` (no reduction) to ``limitmax`` (full) along the line between them,
    and fully over ``overlimit`` beyond it: v ← v (1 − min(1, dt·redumax·f²)·factorxyz),
    f ∈ [0, 1] the normalised distance (DualSPHysics JDamping)."""

    def __init__(self, spec: dict):
        self.p0 = np.asarray(spec["limitmin"], float)
        p1 = np.asarray(spec["limitmax"], float)
        self.length = float(np.linalg.norm(p1 - self.p0))
        self.dir = (p1 - self.p0) / self.length
        self.overlimit = float(spec.get("overlimit", 0.0))
        self.redumax = float(spec.get("redumax", 10.0))
        self.factor = np.asarray(spec.get("factorxyz", [1.0, 1.0, 1.0]), float)

    def apply(self, state, dt: float) -> None:
        fluid = np.flatnonzero(state.ptype == FLUID)
        d = (state.pos[fluid] - self.p0) @ self.dir
        inside = (d > 0) & (d < self.length + self.overlimit)
        if not inside.any():
            return
        rows = fluid[inside]
        f = np.minimum(d[inside] / self.length, 1.0)
        redu = np.minimum(1.0, dt * self.redumax * f * f)
        state.vel[rows] *= 1.0 - redu[:, None] * self.factor[None, :]


def damping_zones(specs) -> list:
    """The zones of a case's ``<special><damping>`` list (none: an empty list)."""
    return [DampingZone(z) for z in specs or []]

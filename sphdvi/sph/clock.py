"""When has the clock reached a time?  Shared by the solver's own ``run`` and the simulation
loop, so that both end on the same step (the time after n DtFixed steps is n*dt only to
round-off: 2000 steps of 5e-4 s end at 0.99999999999995 s)."""
from __future__ import annotations

TIME_TOLERANCE = 1e-12      # relative


def time_reached(time: float, target: float, scale: float | None = None) -> bool:
    """True once ``time`` is at ``target`` to round-off (relative to max(1, scale or |target|))."""
    return time >= target - TIME_TOLERANCE * max(1.0, abs(target) if scale is None else scale)

"""Periodic boundaries by ghost copies (numpy bookkeeping, kernels unchanged).

A periodic axis k has a period vector S_k (S_k[k] = L_k, the other two
components are DualSPHysics's ``*PeriodicInc*`` offsets).  Before every
interaction the particles within 2h of either end of the periodic box get
ghost copies shifted by -S_k or +S_k (axes processed in turn, so corner
ghosts of ghosts exist for two periodic axes); the interaction runs on the
extended set and the rates of the real particles are copied back.  After
every step the real particles that left the box are wrapped back by S_k.

The periodic box starts at the minimum particle coordinate of the initial
state and its length is the extent of the particles along the axis plus dp
(so that the first and last lattice planes are dp apart across the
boundary), as DualSPHysics defines it.
"""
import numpy as np

AXES = {"x": 0, "y": 1, "z": 2}


class Periodicity:
    """Periodic axes, box and period vectors."""

    def __init__(self, axes, pos, dp, params):
        self.axes = sorted({AXES[a] if isinstance(a, str) else int(a) for a in axes})
        self.lo = np.zeros(3)
        self.length = np.zeros(3)
        self.shift = np.zeros((3, 3))
        inc = {0: ("XPeriodicIncY", "XPeriodicIncZ"), 1: ("YPeriodicIncX", "YPeriodicIncZ"),
               2: ("ZPeriodicIncX", "ZPeriodicIncY")}
        for k in self.axes:
            self.lo[k] = pos[:, k].min()
            self.length[k] = pos[:, k].max() - self.lo[k] + dp
            self.shift[k, k] = self.length[k]
            others = [m for m in range(3) if m != k]
            for m, key in zip(others, inc[k]):
                self.shift[k, m] = float(params.get(key) or 0.0)

    def wrap(self, pos):
        """Bring particles that left the periodic box back in (in place)."""
        for k in self.axes:
            lo, hi = self.lo[k], self.lo[k] + self.length[k]
            below = pos[:, k] < lo
            above = pos[:, k] >= hi
            if below.any():
                pos[below] += self.shift[k]
            if above.any():
                pos[above] -= self.shift[k]

    def ghosts(self, pos, width):
        """(source index, displacement) of the ghost copies of ``pos``."""
        src = np.arange(pos.shape[0])
        disp = np.zeros((pos.shape[0], 3))
        for k in self.axes:
            p = pos[src, k] + disp[:, k]
            lo, hi = self.lo[k], self.lo[k] + self.length[k]
            low = np.flatnonzero(p < lo + width)
            high = np.flatnonzero(p >= hi - width)
            src = np.concatenate([src, src[low], src[high]])
            disp = np.concatenate([disp, disp[low] + self.shift[k], disp[high] - self.shift[k]])
        n = pos.shape[0]
        return src[n:], disp[n:]

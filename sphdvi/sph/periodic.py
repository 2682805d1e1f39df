"""Periodic boundaries by ghost copies (compiled bookkeeping, kernels unchanged).

A periodic axis k has a period vector S_k: S_k[k] = L_k and, on the other two
axes, minus DualSPHysics's ``*PeriodicInc*`` offsets, i.e. S_k is minus
DualSPHysics's PeriXinc/PeriYinc/PeriZinc (JSph::LoadCaseParticles sets
PeriXinc = (-Lx, XPeriodicIncY, XPeriodicIncZ)).  As JSphCpu::UpdatePos, a
particle leaving through the high end comes back at the low end with the
increment added (x - Lx, z + XPeriodicIncZ), one leaving through the low end
with it subtracted (pos + S_k).  Before every interaction the particles within
2h of the low end get ghost copies at pos + S_k (above the high end, the
increment subtracted) and those within 2h of the high end at pos - S_k (as
JSphCpuSingle::PeriodicMakeList; axes processed in turn, so corner ghosts of
ghosts exist for two periodic axes); the interaction runs on the extended set
and the rates of the real particles are copied back.

The periodic box starts at the minimum particle coordinate of the initial
state and its length is the extent of the particles along the axis plus dp
(so that the first and last lattice planes are dp apart across the
boundary), as DualSPHysics defines it.
"""
import numpy as np
from numba import njit

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
        self._axes = np.array(self.axes, np.int64)
        for k in self.axes:
            self.lo[k] = pos[:, k].min()
            self.length[k] = pos[:, k].max() - self.lo[k] + dp
            self.shift[k, k] = self.length[k]
            others = [m for m in range(3) if m != k]
            for m, key in zip(others, inc[k]):
                self.shift[k, m] = -float(params.get(key) or 0.0)

    def check_length(self, support):
        """ValueError when a periodic length is below the kernel support ``support`` (2h): the
        ghosts (one copy per side, as JSphCpuSingle::PeriodicMakeList) then miss the images
        beyond one period that lie within the support."""
        for k in self.axes:
            if self.length[k] < support:
                a = "xyz"[k]
                raise ValueError(f"the periodic length along {a}, L = {self.length[k]:.6g} m (the particles' extent "
                                 f"plus dp, as DualSPHysics), is shorter than the kernel support 2h = {support:.6g} m: "
                                 f"the periodic images beyond one period are not made; make the domain at least 2h "
                                 f"long along {a}")

    def wrap(self, pos):
        """Bring particles that left the periodic box back in (in place), as
        JSphCpu::UpdatePos: above the box pos - S_k, below it pos + S_k."""
        _wrap_into_box(pos, self._axes, self.lo, self.length, self.shift)

    def ghosts(self, pos, width, bufs=None):
        """(source index, displacement) of the ghost copies of ``pos``: along each periodic
        axis in turn, the copies of the particles (and of the ghosts made so far) within
        ``width`` of the low end displaced by +S_k, then those within ``width`` of the high end
        by -S_k (JSphCpuSingle::PeriodicMakeList).  ``bufs``: a dict whose "src"/"disp" work
        arrays are kept between calls (grown as needed); the returned arrays are then views
        of them, valid until the next call."""
        n = pos.shape[0]
        own = bufs is None
        bufs = {} if own else bufs
        src, disp = bufs.get("src"), bufs.get("disp")
        if src is None:
            src, disp = np.empty(n // 4 + 16, np.int64), np.empty((n // 4 + 16, 3))
        m = _make_ghosts(pos, self._axes, self.lo, self.length, self.shift, width, src, disp)
        while m > src.shape[0]:
            cap = 2 * m + 16
            src, disp = np.empty(cap, np.int64), np.empty((cap, 3))
            m = _make_ghosts(pos, self._axes, self.lo, self.length, self.shift, width, src, disp)
        bufs["src"], bufs["disp"] = src, disp
        if own:
            return src[:m].copy(), disp[:m].copy()
        return src[:m], disp[:m]

    def min_image(self, r):
        """The shortest periodic image of the separations ``r`` (N, 3), in place:
        along each periodic axis the period vector is added or subtracted until
        the component lies within half a period (DualSPHysics's FtPeriodicDist
        for the distance of a floating particle to its body's centre)."""
        for k in self.axes:
            n = np.rint(r[:, k] / self.length[k])
            if n.any():
                r -= n[:, None] * self.shift[k]
        return r


INC_KEYS = {"x": ("XPeriodicIncY", "XPeriodicIncZ"), "y": ("YPeriodicIncX", "YPeriodicIncZ"),
            "z": ("ZPeriodicIncX", "ZPeriodicIncY")}
PAIR_KEYS = (("XYPeriodic", "xy"), ("XZPeriodic", "xz"), ("YZPeriodic", "yz"))
# every periodic execution parameter
PERIODIC_KEYS = tuple(k for keys in INC_KEYS.values() for k in keys) + tuple(k for k, _ in PAIR_KEYS)


def periodic_config(written, params, is2d):
    """Periodic axes and increments of a case as JSph::LoadConfigParameters sets them.

    ``written``: the parameter keys the case writes.  An axis is periodic when one
    of its ``*PeriodicInc*`` keys is written (any value, even 0); a written
    XYPeriodic / XZPeriodic / YZPeriodic (any value, even 0) makes that pair
    periodic and the third axis not, and resets every increment to 0 (in that
    order, the last written pair winning).  Returns (sorted axes, {Inc key: value});
    a periodic y in a 2D case is a ValueError, as in DualSPHysics."""
    written = set(written)
    axes = {a for a, keys in INC_KEYS.items() if written.intersection(keys)}
    incs = {k: float(params.get(k) or 0.0) for keys in INC_KEYS.values() for k in keys if k in written}
    for key, pair in PAIR_KEYS:
        if key in written:
            axes = set(pair)
            incs = {}
    if is2d and "y" in axes:
        why = next((k for k, pair in PAIR_KEYS if k in written and "y" in pair), None) \
            or next(k for k in INC_KEYS["y"] if k in written)
        raise ValueError(f"{why}: cannot use periodic conditions in Y with 2D simulations "
                         "(DualSPHysics refuses it too)")
    return sorted(axes), incs


@njit(cache=True)
def _wrap_into_box(pos, axes, lo, length, shift):
    """Periodicity.wrap's loop: per particle and periodic axis k in turn, + S_k below the
    box, - S_k at or above its high end (JSphCpu::UpdatePos)."""
    for i in range(pos.shape[0]):
        for a in range(axes.shape[0]):
            k = axes[a]
            p = pos[i, k]
            if p < lo[k]:
                for m in range(3):
                    pos[i, m] += shift[k, m]
            elif p >= lo[k] + length[k]:
                for m in range(3):
                    pos[i, m] -= shift[k, m]


@njit(cache=True)
def _make_ghosts(pos, axes, lo, length, shift, width, src, disp):
    """Periodicity.ghosts's loop into ``src``/``disp``; returns the number of ghosts.  When
    that exceeds their length (the capacity) the ghosts beyond it are counted, not stored,
    and the count is a lower bound: the caller calls again with larger arrays.  A ghost of a
    ghost keeps the real source and adds the displacements, as numpy's concatenation did
    (the same sums, so bitwise)."""
    n = pos.shape[0]
    cap = src.shape[0]
    m = 0
    for a in range(axes.shape[0]):
        k = axes[a]
        hi = lo[k] + length[k]
        m0 = min(m, cap)
        for side in range(2):
            sgn = 1.0 if side == 0 else -1.0
            for e in range(n + m0):
                if e < n:
                    p = pos[e, k]
                else:
                    p = pos[src[e - n], k] + disp[e - n, k]
                if (p < lo[k] + width) if side == 0 else (p >= hi - width):
                    if m < cap:
                        if e < n:
                            src[m] = e
                            for c in range(3):
                                disp[m, c] = sgn * shift[k, c]
                        else:
                            src[m] = src[e - n]
                            for c in range(3):
                                disp[m, c] = disp[e - n, c] + sgn * shift[k, c]
                    m += 1
    return m

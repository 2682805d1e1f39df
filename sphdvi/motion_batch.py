"""All moving objects' transforms at one time, the translations in one compiled pass (audit e,
finding 7): DualSPHysics's JDsMotion::ProcesTime evaluates every object's motion in compiled code
each step; sphdvi walked each object's chain in Python (~19 us per object per step).

:class:`sphdvi.motion._Walk` stays the one definition of a chain's motion.  After it has placed an
object, :class:`MotionBatch` reads where the walk stands (:meth:`MotionBatch._plan`): the movement
under way, its start, the transform of the movements done before it and what they carried into it.
Until the walk would do anything else than evaluate that movement (the movement ends, the finish,
a time before the movement's start), the object's transform is that movement's formula, which
:func:`eval_translations` evaluates for every such object in one call, in the same floating-point
operations as :func:`sphdvi.motion._segment` and :meth:`sphdvi.motion.Rigid.then` (bitwise the
same d and V).  Objects that turn (rotations, circular movements, files of angles), wave paddles,
objects with several events or parent ``<obj>`` chains, file movements, and any object outside the
interval its plan covers are evaluated by the walk, as before.
"""
from __future__ import annotations

import math

import numpy as np

from .sph import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit

# movement kinds of the compiled evaluation: 0 no motion (wait, mvnull), 1 d = v0 τ + a τ²/2,
# 2 d = A [sin(2π f τ + φ) − sin φ]
KINDS = {"wait": 0, "mvnull": 0, "mvrect": 1, "mvrectace": 1, "mvrectsinu": 2}
MOVING, RESTING, WAITING, FINISHED = 1, 2, 3, 4    # plan modes (0: none: the walk evaluates the object)
TWO_PI = 2 * math.pi                    # Python's 2 * math.pi, as _segment's product starts


@njit(cache=True)
def eval_translations(t, mode, lo, hi, start, finish, kind, par, done_ident, done_d, seen,
                      d, V, fast):
    """Each planned object's displacement d and velocity V at time t (``fast``: whether its plan
    covers t; the others are left to the walk).  MOVING: done.then(segment(τ = t − lo)) for
    lo < t < hi; RESTING (the chain is over) and FINISHED (its finish has passed): the walk's final
    transform, no velocity, where the walk would not go back (_Walk._go_back; lo its t0); WAITING:
    at rest before the event's start (t <= start).  ``seen``: the latest time the walk would have
    recorded (:attr:`sphdvi.motion._Walk.seen`)."""
    for g in range(mode.shape[0]):
        fast[g] = False
        m = mode[g]
        if m == MOVING:
            if not (t > lo[g] and t < hi[g]):
                continue
            tau = t - lo[g]
            for k in range(3):
                if kind[g] == 0:
                    sd = 0.0
                    sv = 0.0
                elif kind[g] == 1:
                    v0 = par[g, 0, k]
                    a = par[g, 1, k]
                    sd = v0 * tau + 0.5 * a * tau * tau
                    sv = v0 + a * tau
                else:
                    f = par[g, 0, k]
                    A = par[g, 1, k]
                    ph = par[g, 2, k]
                    arg = TWO_PI * f * tau + ph
                    sd = A * (math.sin(arg) - math.sin(ph))
                    sv = A * 2 * math.pi * f * math.cos(arg)
                if kind[g] == 0:            # an identity segment: the transform is the done one's
                    d[g, k] = done_d[g, k]
                    V[g, k] = 0.0
                elif done_ident[g]:         # Rigid().then(segment): the segment's own arrays
                    d[g, k] = sd
                    V[g, k] = sv
                else:                       # done.then(segment): sums, V from done's zero
                    d[g, k] = done_d[g, k] + sd
                    V[g, k] = 0.0 + sv
            seen[g] = max(seen[g], t)
        elif m == RESTING or m == FINISHED:
            te = min(t, finish[g])
            if not t > start[g]:
                continue
            if m == FINISHED and not t >= finish[g]:
                continue
            if m == RESTING and not (te >= seen[g] or te > lo[g]):
                continue
            for k in range(3):
                d[g, k] = done_d[g, k]
                V[g, k] = 0.0
            seen[g] = max(seen[g], te)
        elif m == WAITING:
            if not t <= start[g]:
                continue
            for k in range(3):
                d[g, k] = 0.0
                V[g, k] = 0.0
        else:
            continue
        fast[g] = True


class MotionBatch:
    """The transforms of the mkbounds ``mkbounds`` of a :class:`sphdvi.motion.MotionSet` at a time:
    :meth:`evaluate` fills ``d``, ``V`` and ``fast`` for the objects whose plan covers it (a
    translation: R = I, Ω = 0, centre d) and returns the indices of the others, which
    :meth:`transform` evaluates by the walk (and plans again)."""

    def __init__(self, motions, mkbounds: list):
        self.motions = motions
        self.mkbounds = list(mkbounds)
        G = len(self.mkbounds)
        self.eligible = [self._eligible(m) for m in self.mkbounds]
        self.mode = np.zeros(G, np.int64)
        self.lo = np.zeros(G)
        self.hi = np.zeros(G)
        self.start = np.zeros(G)
        self.finish = np.full(G, np.inf)
        self.kind = np.zeros(G, np.int64)
        self.par = np.zeros((G, 3, 3))
        self.done_ident = np.ones(G, np.bool_)
        self.done_d = np.zeros((G, 3))
        self.seen = np.full(G, -np.inf)
        self.d = np.zeros((G, 3))
        self.V = np.zeros((G, 3))
        self.fast = np.zeros(G, np.bool_)
        self.d_bits = self.d.view(np.int64)

    def _eligible(self, mkb) -> bool:
        """An object the compiled pass may evaluate: one motion (no paddle), one event, no parent
        chain, translations only."""
        ms = self.motions
        m = ms.motions.get(mkb)
        if m is None or mkb in ms.paddles or m.get("parents"):
            return False
        events = m.get("events") or ([m["begin"]] if m.get("begin") else [])
        return len(events) == 1 and all(mv["type"] in KINDS for mv in m["movements"])

    def evaluate(self, t: float) -> np.ndarray:
        """Plans at time t; the indices of the objects left to :meth:`transform`."""
        eval_translations(float(t), self.mode, self.lo, self.hi, self.start, self.finish, self.kind,
                          self.par, self.done_ident, self.done_d, self.seen, self.d, self.V, self.fast)
        return np.flatnonzero(~self.fast)

    def transform(self, g: int, t: float):
        """The walk's transform of object g at t (the Rigid of MotionSet.transform), then its plan."""
        mkb = self.mkbounds[g]
        if not self.eligible[g]:
            return self.motions.transform(mkb, t)
        walk = self._walk(g)
        if walk is not None and self.seen[g] > walk.seen:
            walk.seen = float(self.seen[g])     # what the compiled evaluations would have recorded
        rig = self.motions.transform(mkb, t)
        self._plan(g, self._walk(g))
        return rig

    def sync(self) -> None:
        """Give each walk the latest time the compiled pass evaluated it at (before this batch is
        dropped: the walks then go on alone)."""
        for g, ok in enumerate(self.eligible):
            walk = self._walk(g) if ok else None
            if walk is not None and self.seen[g] > walk.seen:
                walk.seen = float(self.seen[g])

    def _walk(self, g: int):
        m = self.motions.motions[self.mkbounds[g]]
        return self.motions._walks.get((id(m), 0))

    def _plan(self, g: int, walk) -> None:
        """Where the walk of object g stands -> the interval and formula of its next evaluations."""
        from .motion import _rect_params, _rectsinu_params
        self.mode[g] = 0
        if walk is None:
            return
        self.seen[g] = walk.seen
        self.start[g] = walk.start
        self.finish[g] = np.inf if walk.finish is None else walk.finish
        if not walk.begun:
            self.mode[g] = WAITING
            return
        if walk.final is not None:
            r = walk.final[0]
            if r.rot:
                return
            self.done_d[g] = r.d
            self.lo[g] = walk.t0
            self.mode[g] = FINISHED if walk.final[2] else RESTING
            return
        cur = walk.current
        if cur is None or cur["duration"] < 0 or walk.done.rot:
            return
        kind = KINDS[cur["type"]]
        self.kind[g] = kind
        self.par[g] = 0.0
        if kind == 1:
            self.par[g, 0], self.par[g, 1] = _rect_params(cur, walk.state)
        elif kind == 2:
            self.par[g, 0], self.par[g, 1], self.par[g, 2] = _rectsinu_params(cur, walk.state)
        self.done_ident[g] = walk.done.ident
        self.done_d[g] = walk.done.d
        self.lo[g] = walk.t0
        self.hi[g] = min(walk.t0 + cur["duration"], self.finish[g])
        self.mode[g] = MOVING


_EYE_BITS = np.eye(3).reshape(-1).view(np.int64)


@njit(cache=True)
def place_translations(fast, dt_on, still_test, d, V, d_bits, eye_bits, last_R, last_d, has_last, rest,
                       active, first, last, x0all, x, n0all, n, normals_on, vwc):
    """ImposedMotions._place for the objects the compiled pass evaluated (``fast``: translations):
    the at-rest test on the bits of (R = I, d) against the placement each was last put at (two
    placements in a row at the same place: left there from then on, ``still_test`` with a dt and
    no periodic wrap), then x = x0 + d of its rows first..last (and its normals unturned); without
    dt the velocity field (V, Ω = 0, centre d)."""
    for g in range(fast.shape[0]):
        if not fast[g]:
            continue
        same = has_last[g]
        if same:
            for k in range(9):
                if last_R[g, k] != eye_bits[k]:
                    same = False
            for k in range(3):
                if last_d[g, k] != d_bits[g, k]:
                    same = False
        if still_test and same:
            if rest[g]:
                active[g] = False
                continue
            rest[g] = True
        else:
            rest[g] = False
        has_last[g] = dt_on
        if dt_on:
            for k in range(9):
                last_R[g, k] = eye_bits[k]
            for k in range(3):
                last_d[g, k] = d_bits[g, k]
        active[g] = True
        for r in range(first[g], last[g]):
            for k in range(3):
                x[r, k] = x0all[r, k] + d[g, k]
            if normals_on:
                for k in range(3):
                    n[r, k] = n0all[r, k]
        if not dt_on:
            for k in range(3):
                vwc[0, g, k] = V[g, k]
                vwc[1, g, k] = 0.0
                vwc[2, g, k] = d[g, k]

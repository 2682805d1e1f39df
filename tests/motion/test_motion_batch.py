"""The translations of many moving objects evaluated and placed in one compiled pass
(sphdvi.motion_batch, audit e finding 7): bitwise the walk's transforms and placements, at a cost
that does not grow with the number of objects by a Python loop (~19 us per object per step before)."""
import math
import time

import numpy as np
import pytest

from sphdvi.coupling import ImposedMotions
from sphdvi.motion import MotionSet
from sphdvi.motion_batch import MotionBatch


def _random_movement(rng, i, last):
    kind = rng.choice(["mvrect", "mvrectace", "mvrectsinu", "wait", "mvnull"], p=[0.3, 0.25, 0.3, 0.1, 0.05])
    dur = float(rng.choice([rng.uniform(0.01, 0.2), -rng.uniform(0.01, 0.05)], p=[0.9, 0.1]))
    m = {"type": str(kind), "id": i, "duration": dur, "next": None if last else i + 1}
    vec = lambda s: (rng.normal(size=3) * s * (rng.random(3) < 0.7)).tolist()  # noqa: E731
    if kind == "mvrect":
        m["vel"] = vec(1.0)
    elif kind == "mvrectace":
        m["ace"] = vec(5.0)
        if rng.random() < 0.5:
            m["velini"] = vec(1.0)
    elif kind == "mvrectsinu":
        m.update(freq=np.abs(vec(3.0)).tolist(), ampl=vec(0.05), anglesunits="degrees")
        if rng.random() < 0.5:
            m["phase"] = vec(90.0)
    elif kind == "mvnull":
        m["duration"] = abs(dur)
    return m


def _random_chain(rng, ref):
    n = int(rng.integers(1, 6))
    movs = [_random_movement(rng, i + 1, i == n - 1) for i in range(n)]
    if rng.random() < 0.4:
        movs[-1]["next"] = int(rng.integers(1, n + 1))          # a loop
        if all(m["duration"] <= 0 for m in movs[movs[-1]["next"] - 1:]):
            movs[-1]["duration"] = 0.05
    start = float(rng.choice([0.0, rng.uniform(0.0, 0.1)]))
    finish = float(rng.uniform(0.2, 0.6)) if rng.random() < 0.3 else None
    return {"ref": ref, "movements": movs, "begin": {"mov": 1, "start": start, "finish": finish}, "parents": []}


def _times(rng, n=700):
    """Rising step ends with a Symplectic-like half step before each, now and then a step back."""
    t, out = 0.0, []
    for _ in range(n):
        dt = float(rng.uniform(1e-4, 2e-3))
        out += [t + 0.5 * dt, t + dt]
        if rng.random() < 0.02:
            out.append(max(0.0, t - float(rng.uniform(0.0, 0.05))))
        t += dt
    return out


def test_batch_transforms_are_the_walks_bitwise():
    rng = np.random.default_rng(11)
    chains = [_random_chain(rng, ref) for ref in range(60)]
    plain = MotionSet([dict(c) for c in chains])
    batched = MotionSet([dict(c) for c in chains])
    batch = MotionBatch(batched, list(range(60)))
    assert all(batch.eligible)
    fast_count = 0
    for t in _times(rng):
        others = set(batch.evaluate(t).tolist())
        for g in range(60):
            want = plain.transform(g, t)
            if g in others:
                got = batch.transform(g, t)
                assert got.d.tobytes() == want.d.tobytes() and got.V.tobytes() == want.V.tobytes()
                continue
            fast_count += 1
            assert not want.rot
            assert batch.d[g].tobytes() == want.d.tobytes(), (g, t)
            assert batch.V[g].tobytes() == want.V.tobytes(), (g, t)
            assert want.c.tobytes() == want.d.tobytes() and not np.any(want.W)
    assert fast_count > 0.9 * 60 * 1400


def _boxes(n, kinds=("mvrectsinu",)):
    """n boxes of 4 particles (and a fixed wall), each moved by a chain of ``kinds``."""
    pos0, mk, motions = [[0.0, 0.0, -1.0]], [0], []
    for i in range(n):
        for k in range(4):
            pos0.append([0.1 * i + 0.01 * k, 0.0, 0.02 * k])
            mk.append(i + 2)                # mkbound i + 1 (GenCase: mk = mkbound + fluidcount + 1)
        movs = []
        for j, kind in enumerate(kinds):
            m = {"type": kind, "id": j + 1, "duration": 0.05 + 0.01 * i, "next": j + 2 if j + 1 < len(kinds) else 1}
            if kind == "mvrectsinu":
                m.update(freq=[2.0 + i, 0.0, 1.0], ampl=[0.01, 0.0, 0.02], anglesunits="degrees")
            elif kind == "mvrect":
                m["vel"] = [0.1 * (i + 1), 0.0, -0.2]
            elif kind == "mvrectace":
                m["ace"] = [1.0, 0.0, 0.5 * i]
            elif kind == "mvrot":
                m.update(vel=30.0, anglesunits="degrees", axisp1=[0.1 * i, -1, 0], axisp2=[0.1 * i, 1, 0])
            movs.append(m)
        motions.append({"ref": i + 1, "movements": movs, "begin": {"mov": 1, "start": 0.01 * (i % 3)},
                        "parents": []})
    return np.array(pos0), np.array(mk), motions


class _Solver:
    """What ImposedMotions.apply reads of a solver."""

    def __init__(self, pos0, mk):
        from sphdvi.sph.state import FluidState
        n = len(pos0)
        self.state = FluidState(pos0.copy(), np.zeros((n, 3)), np.full(n, 1000.0), 1.0,
                                np.where(mk > 0, 1, 0).astype(np.int8), mk=mk.astype(np.int32))
        self.is2d = True
        self.periodicity = None


class _Walks:
    """A MotionSet seen without its walks: ImposedMotions places every object by the walk."""

    def __init__(self, ms):
        self.ms = ms

    def transform(self, mkb, t):
        return self.ms.transform(mkb, t)


@pytest.mark.parametrize("kinds", [("mvrectsinu",), ("mvrect", "wait", "mvrectace"), ("mvrect", "mvrot")])
def test_batch_placement_is_the_walks_bitwise(kinds):
    pos0, mk, motions = _boxes(12, kinds)
    runs = []
    for batched in (True, False):
        ms = MotionSet([dict(m) for m in motions])
        im = ImposedMotions(ms if batched else _Walks(ms), pos0, fluidcount=0)
        sol = _Solver(pos0, mk + 0)
        im.apply(sol, 0.0)               # a placement without dt: the motion's velocity
        out = [(sol.state.pos.copy(), sol.state.vel.copy())]
        t = 0.0
        for k in range(400):
            dt = 1e-3 * (1 + (k % 3))
            t += dt
            im.apply(sol, t, dt)
            out.append((sol.state.pos.copy(), sol.state.vel.copy()))
        runs.append(out)
    for (pa, va), (pb, vb) in zip(*runs):
        assert pa.tobytes() == pb.tobytes() and va.tobytes() == vb.tobytes()


def _apply_cost(n):
    pos0, mk, motions = _boxes(n)
    im = ImposedMotions(MotionSet(motions), pos0, fluidcount=0)
    sol = _Solver(pos0, mk)
    t = 0.02
    for _ in range(20):
        t += 1e-4
        im.apply(sol, t, 1e-4)
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(200):
            t += 1e-4
            im.apply(sol, t, 1e-4)
        best = min(best, (time.perf_counter() - t0) / 200)
    return best


def test_placing_fifty_moving_boxes_costs_about_what_one_costs():
    """50 objects with a sinusoidal motion: ~1 ms per step through the walk one by one (the audit's
    50-box case: 50 % of the step); the compiled pass: about what one object costs."""
    one, fifty = _apply_cost(1), _apply_cost(50)
    assert fifty < 3.0 * one + 20e-6, (one, fifty)

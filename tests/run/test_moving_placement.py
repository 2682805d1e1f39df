"""The moving boundary particles' placement at each step end (ImposedMotions, JSph's CalcMotion /
MoveLinBound / MoveMatBound): one compiled pass over the rows, whatever order the solver's cell
sort left them in, bitwise the per-mkbound transform of their initial positions; an mkbound at
rest is not placed again; the motions compose without numpy's per-call overhead on 3-vectors."""
import math

import numpy as np
import pytest

import sphdvi.coupling as coupling
import sphdvi.motion as motion
from sphdvi.coupling import ImposedMotions, body_labels
from sphdvi.motion import MotionSet, Rigid
from sphdvi.sph.periodic import Periodicity

AXZ = {"axisp1": [0.3, 0.1, 0], "axisp2": [0.3, 0.1, 1], "anglesunits": "degrees"}
AXY = {"axisp1": [0.5, 0, 0.2], "axisp2": [0.5, -1, 0.2], "anglesunits": "degrees"}
FLUIDCOUNT = 1


def chain(ref, movs, start=0.0, finish=None):
    begin = dict(mov=1, start=start, finish=finish)
    return {"ref": ref, "movements": movs, "begin": begin, "events": [begin], "parents": []}


MOTIONS = [
    chain(0, [dict(type="mvrot", id=1, duration=0.05, next=2, vel=90.0, **AXZ),
              dict(type="mvrotsinu", id=2, duration=0.05, freq=3.0, ampl=20.0, next=3, **AXY),
              dict(type="mvnull", id=3, duration=math.inf)], start=0.01),
    chain(1, [dict(type="mvrectsinu", id=1, duration=0.04, freq=[2.0, 0, 1.0], ampl=[0.05, 0, 0.02], next=2),
              dict(type="mvrect", id=2, duration=0.02, vel=[0.3, 0.1, -0.2], next=1)]),
    chain(2, [dict(type="mvcir", id=1, duration=0.03, next=1, vel=180.0, ref=[1, 0, 0], **AXZ)], finish=0.15),
    chain(3, [dict(type="mvrect", id=1, duration=0.02, vel=[0.5, 0, 0.1], next=2),
              dict(type="mvnull", id=2, duration=math.inf)]),
]
PADDLES = [dict(type="flap", mkbound=4, depth=0.4, waveheight=0.05, waveperiod=0.8, flapaxis0=[0, -1, 0],
                flapaxis1=[0, 1, 0], ramp=1.0)]


class _Periodic:
    """A periodic x axis of 1.3 m (with a z increment), as the solver's Periodicity."""
    axes = [0]
    lo = np.zeros(3)
    length = np.array([1.3, 0.0, 0.0])
    shift = np.array([[1.3, 0.0, 0.1], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    min_image = Periodicity.min_image


class _Solver:
    def __init__(self, ptype, mk, pos0, flat, per, normals0):
        n = ptype.size
        self.state = type("State", (), {})()
        s = self.state
        s.ptype, s.mk, s.idp, s.pos, s.vel, s.n = ptype, mk, np.arange(n), pos0.copy(), np.zeros((n, 3)), n
        self.is2d, self.periodicity = flat, per
        self.normals = None if normals0 is None else normals0.copy()

    def shuffle(self, perm, wrap=None):
        """The solver's cell reorder (and its periodic wrap of some particles)."""
        s = self.state
        for f in ("ptype", "mk", "idp", "pos", "vel"):
            setattr(s, f, getattr(s, f)[perm].copy())
        if self.normals is not None:
            self.normals = self.normals[perm].copy()
        if wrap is not None:
            s.pos[wrap & (s.ptype == 1)] += _Periodic.shift[0]


def reference_apply(motions, pos0, normals0, solver, t, dt):
    """The placement per mkbound with numpy: x = x0 Rᵀ + d (2D: y kept), v = (x − old x)/dt at its
    shortest periodic image, or the motion's V + Ω × (x − c) without dt; normals n0 Rᵀ."""
    s = solver.state
    sel = np.flatnonzero(s.ptype == 1)
    label = body_labels(s.mk[sel], FLUIDCOUNT)
    for mkb in np.unique(label):
        rows = sel[label == mkb]
        rig = motions.transform(int(mkb), t)
        x0 = pos0[s.idp[rows]]
        x = x0 @ rig.R.T + rig.d
        v = rig.V + np.cross(rig.W, x - rig.c)
        if solver.is2d:
            x[:, 1] = x0[:, 1]
            v[:, 1] = 0.0
        if dt:
            step = x - s.pos[rows]
            if solver.periodicity is not None:
                solver.periodicity.min_image(step)
            v = step / dt
        s.pos[rows] = x
        s.vel[rows] = v
        if normals0 is not None:
            solver.normals[rows] = normals0[s.idp[rows]] @ rig.R.T


@pytest.mark.parametrize("flat", [False, True], ids=["3d", "2d"])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
@pytest.mark.parametrize("normals", [False, True], ids=["dbc", "mdbc"])
def test_placement_is_the_per_mkbound_transform_bitwise(flat, periodic, normals):
    """Rotations, translations, a circle, a flap, a movement that ends, rows reordered every step,
    some moving particles wrapped by the periodic box: the compiled placement gives the numpy
    per-mkbound placement's positions, velocities and normals bit for bit (zeros' signs too)."""
    rng = np.random.default_rng(3)
    n = 400
    ptype = rng.choice([0, 1, 3], size=n).astype(np.int8)
    mk = np.where(ptype == 3, 1, rng.integers(2, 7, n))       # mkbounds 0-4
    mk[ptype == 0] = 9
    pos0 = rng.normal(size=(n, 3))
    if flat:
        pos0[:, 1] = 0.0
    normals0 = rng.normal(size=(n, 3)) if normals else None
    per = _Periodic() if periodic else None
    ref, new = _Solver(ptype, mk, pos0, flat, per, normals0), _Solver(ptype, mk, pos0, flat, per, normals0)
    ref_motions = MotionSet([dict(m) for m in MOTIONS], PADDLES)
    moving = ImposedMotions(MotionSet([dict(m) for m in MOTIONS], PADDLES), pos0, FLUIDCOUNT, normals0)
    t = 0.0
    for k in range(300):
        dt = float(rng.uniform(2e-4, 1e-3))
        t += dt
        perm = rng.permutation(n)
        wrap = (rng.random(n) < 0.05) if periodic else None
        ref.shuffle(perm, wrap)
        new.shuffle(perm, wrap)
        step_dt = None if k % 37 == 5 else dt              # now and then a placement without dt
        reference_apply(ref_motions, pos0, normals0, ref, t, step_dt)
        moving.apply(new, t, step_dt)
        for a, b in ((ref.state.pos, new.state.pos), (ref.state.vel, new.state.vel), (ref.normals, new.normals)):
            if a is not None:
                assert np.array_equal(a, b) and np.array_equal(np.signbit(a), np.signbit(b)), (k, t)


def test_an_mkbound_at_rest_is_not_placed_again(monkeypatch):
    """After its movement ends, an mkbound is placed twice more (its particles then at rest) and
    then left alone: no compiled pass while nothing moves; they stay where the motion ended."""
    calls = []
    kernel = coupling.place_moving
    monkeypatch.setattr(coupling, "place_moving", lambda *a: calls.append(a[7].copy()) or kernel(*a))
    n = 20
    ptype = np.ones(n, np.int8)
    mk = np.full(n, 5)                                          # mkbound 3: mvrect for 0.02 s, then mvnull
    pos0 = np.random.default_rng(0).normal(size=(n, 3))
    solver = _Solver(ptype, mk, pos0, False, None, None)
    moving = ImposedMotions(MotionSet([MOTIONS[3]]), pos0, FLUIDCOUNT)
    dt = 1e-3
    for k in range(1, 41):
        moving.apply(solver, k * dt, dt)
    # 20 passes up to the movement's end at t = 0.02, one more at rest there (t = 0.021), then none
    assert len(calls) == 21
    assert np.allclose(solver.state.pos, pos0 + [0.01, 0.0, 0.002], rtol=0, atol=1e-15)
    assert not solver.state.vel.any()


def test_a_null_motion_is_the_identity():
    """An <mvnull> chain composes to Rigid() itself: nothing to multiply (85 us a step before)."""
    ms = MotionSet([chain(7, [dict(type="mvnull", id=1, duration=math.inf)])])
    for t in (0.0, 0.5, 3.0):
        assert ms.transform(7, t).ident


def _then(a: Rigid, b: Rigid) -> Rigid:
    """Rigid.then with numpy's products (the composition it implements)."""
    c = b.R @ a.c + b.d
    return Rigid(b.R @ a.R, b.R @ a.d + b.d, b.R @ a.V + b.V + np.cross(b.W, c - b.c), b.R @ a.W + b.W, c)


def test_rigid_then_composes_without_numpy_cross(monkeypatch):
    """Rigid.then gives numpy's composition (bit for bit) of rotations, translations and the
    identity, without calling np.cross on 3-vectors (15-20 us a call)."""
    rng = np.random.default_rng(1)
    rot = Rigid(motion._rotation(np.array([0.0, 0.6, 0.8]), 0.7), rng.normal(size=3), rng.normal(size=3),
                rng.normal(size=3), rng.normal(size=3))
    turn = Rigid(motion._rotation(np.array([1.0, 0.0, 0.0]), -0.3), rng.normal(size=3), rng.normal(size=3),
                 rng.normal(size=3), rng.normal(size=3))
    shift = Rigid(d=rng.normal(size=3), V=rng.normal(size=3))
    cases = [(a, b) for a in (rot, turn, shift, Rigid()) for b in (rot, turn, shift, Rigid())]
    expected = [_then(a, b) for a, b in cases]

    def no_cross(*args, **kwargs):
        raise AssertionError("np.cross called")
    monkeypatch.setattr(motion.np, "cross", no_cross)
    for (a, b), e in zip(cases, expected):
        got = a.then(b)
        for f in ("R", "d", "V", "W", "c"):
            assert np.array_equal(getattr(got, f), getattr(e, f)), f

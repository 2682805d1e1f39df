"""sphdvi.coupling on its own: the loads the fluid puts on a floating body (sums of m a and
of (r - R) x m a over its particles, DualSPHysics's FtPartsSumAce) and the rigid-body motion
the body gives its particles back (FtPartsUpdate), checked against closed forms."""
import math
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.coupling import FloatingBodies, ImposedMotions, quat_matrix
from sphdvi.io.casefile import read_case_h5
from sphdvi.motion import MotionSet
from sphdvi.sph.state import FluidState

CASE = Path(__file__).resolve().parents[2] / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"


@pytest.fixture(scope="module")
def case_data(tmp_path_factory):
    d = tmp_path_factory.mktemp("fb")
    shutil.copy(CASE, d / CASE.name)
    r = CliRunner().invoke(main, ["gencase", str(d / CASE.name), "-o", str(d / "out")])
    assert r.exit_code == 0, r.output
    return read_case_h5(str(next((d / "out").glob("*.h5"))))


def _coupling(data):
    fluidcount = int(data["json"]["mkconfig"]["fluidcount"])
    motions = MotionSet(data["json"].get("motions", []), [])
    return FloatingBodies(data, motions, fluidcount)


def _solver(data):
    p = data["particles"]
    state = FluidState(p["pos"].copy(), p["vel"].copy(), p["rhop"].copy(), p["mass"].copy(), p["type"],
                       p["idp"], p["mk"])
    return SimpleNamespace(state=state, ace=np.zeros_like(state.pos), time=0.0, normals=None)


def test_loads_of_a_rigid_acceleration_field(case_data):
    """Particles accelerated as a rigid body turning about the body's centre with angular
    acceleration alpha (a = alpha x (r - R)) plus a uniform a0: the force is M_p a0 +
    alpha x M_p (rbar - R) and the moment about R is I_p alpha + M_p (rbar - R) x a0, with M_p,
    rbar, I_p the particles' mass, centroid and polar moment of inertia about R."""
    fb = _coupling(case_data)
    sol = _solver(case_data)
    s = sol.state
    sel = np.flatnonzero(s.ptype == 2)
    assert sel.size > 50 and fb.system.nb == 1
    body = fb.body_of_idp[s.idp[sel]]
    R = fb.system.pos[0]
    alpha = np.array([0.0, 3.7, 0.0])            # about y: the 2D plane is x-z
    a0 = np.array([0.4, 0.0, -1.3])
    r = s.pos[sel] - R
    sol.ace[sel] = np.cross(alpha, r) + a0
    F, T = fb.loads(sol, sel, body)
    m = s.mass[sel]
    mp = m.sum()
    rbar = (m[:, None] * r).sum(0) / mp
    ip = (m * (r[:, 0] ** 2 + r[:, 2] ** 2)).sum()
    assert np.allclose(F[0], mp * a0 + np.cross(alpha, mp * rbar), rtol=1e-12, atol=1e-9 * mp)
    assert T[0, 1] == pytest.approx(ip * alpha[1] + mp * np.cross(rbar, a0)[1], rel=1e-12)
    # 2D: no force out of the plane, no moment about in-plane axes
    sol.ace[sel, 1] = 5.0
    F, T = fb.loads(sol, sel, body)
    assert F[0, 1] == 0.0 and T[0, 0] == 0.0 and T[0, 2] == 0.0


def test_particles_follow_the_body(case_data):
    """After the body is moved to R' and turned by theta about y, with velocity V and spin
    omega, each particle sits at R' + Rot(theta) (r0 - R0) and moves at V + omega x (r - R')."""
    fb = _coupling(case_data)
    sol = _solver(case_data)
    s = sol.state
    sel = np.flatnonzero(s.ptype == 2)
    body = fb.body_of_idp[s.idp[sel]]
    r0 = s.pos[sel] - fb.system.pos[0]
    theta = 0.3
    q = np.array([math.cos(theta / 2), 0.0, math.sin(theta / 2), 0.0])     # about +y
    sysb = fb.system
    sysb.pos[0] = sysb.pos[0] + np.array([0.05, 0.0, -0.02])
    sysb.quat[0] = q
    sysb.vel[0] = np.array([0.2, 0.0, -0.1])
    omega = np.array([0.0, 1.5, 0.0])
    sysb.omega_b[0] = omega                   # about y, the same in body and world frames
    fb.carry_particles(sol, sel, body)
    R = quat_matrix(q)
    assert np.allclose(s.pos[sel], sysb.pos[0] + r0 @ R.T, atol=1e-12)
    assert np.allclose(s.vel[sel], sysb.vel[0] + np.cross(omega, s.pos[sel] - sysb.pos[0]), atol=1e-12)
    # a rigid motion: every distance between particles is kept
    d0 = np.linalg.norm(r0[:, None] - r0[None], axis=-1)
    d1 = np.linalg.norm(s.pos[sel][:, None] - s.pos[sel][None], axis=-1)
    assert np.allclose(d0, d1, atol=1e-12)


def test_frozen_bodies_during_ftpause(case_data):
    """FtPause: the body does not move and its particles stay, but the clock goes on; the
    pause holds while the step's start time is below FtPause (DualSPHysics's RunFloating:
    TimeStep < FtPause), and bodies.csv's loads are then what acts on the held body, its weight
    plus the fluid's force and moment (DualSPHysics keeps computing them for its output; sphdvi
    only when a row is written: FloatingBodies.held_loads, BodyLog's prepare)."""
    fluidcount = int(case_data["json"]["mkconfig"]["fluidcount"])
    fb = FloatingBodies(case_data, MotionSet([], []), fluidcount, ftpause=0.1)
    sol = _solver(case_data)
    sel = sol.state.ptype == 2
    sol.ace[sel] = [0.0, 0.0, -9.81]
    sol.ace[sel, 0] = sol.state.pos[sel, 2] - sol.state.pos[sel, 2].mean()     # a moment about y
    before = sol.state.pos.copy()
    sol.time = 0.05
    calls = []
    loads = fb.loads
    fb.loads = lambda *a: calls.append(1) or loads(*a)
    fb.step(sol, 1e-3)
    assert np.array_equal(sol.state.pos, before) and fb.system.time == 0.05
    # the held loads wait for a bodies.csv row (audit e, finding 6: they were summed every step)
    assert not calls
    fb.held_loads()
    assert len(calls) == 1
    fb.held_loads()                     # once per held step
    assert len(calls) == 1
    fb.loads = loads
    F, T = fb.loads(sol, np.flatnonzero(sel), np.zeros(int(sel.sum()), np.int64))
    m = fb.system.mass[0]
    assert np.allclose(fb.system.total_force[0], F[0] + m * fb.system.gravity, rtol=1e-12)
    assert np.allclose(fb.system.total_torque[0], T[0], rtol=1e-12) and abs(T[0, 1]) > 0
    sol.time = 0.1005           # a step from 0.0995 to 0.1005: started in the pause
    fb.step(sol, 1e-3)
    assert np.array_equal(sol.state.pos, before)
    sol.time = 0.2
    fb.step(sol, 1e-3)
    assert sol.state.pos[sel, 2].max() < before[sel, 2].max()     # free fall once released


def test_imposed_motion_moves_its_mk_only():
    """A constant-velocity motion (mvrect) of mkbound 1 moves the type-1 particles of that mk to
    pos0 + v t with velocity v; fluid and fixed particles stay."""
    motions = MotionSet([{"ref": 1, "begin": {"mov": 1, "start": 0.0},
                          "movements": [{"id": 1, "type": "mvrect", "duration": 10.0, "vel": [0.3, 0.0, -0.2]}]}])
    pos0 = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 1], [3.0, 0, 1]])
    fluidcount = 1
    mk = np.array([fluidcount + 1 + 1, fluidcount + 1 + 1, fluidcount + 1 + 0, 0], np.int32)
    ptype = np.array([1, 1, 0, 3], np.int8)
    state = FluidState(pos0.copy(), np.zeros((4, 3)), np.full(4, 1000.0), np.ones(4), ptype, np.arange(4), mk)
    sol = SimpleNamespace(state=state, normals=None)
    ImposedMotions(motions, pos0, fluidcount).apply(sol, 0.5)
    v = np.array([0.3, 0.0, -0.2])
    assert np.allclose(state.pos[:2], pos0[:2] + 0.5 * v, atol=1e-12)
    assert np.allclose(state.vel[:2], v)
    assert np.array_equal(state.pos[2:], pos0[2:]) and not state.vel[2:].any()


@pytest.mark.parametrize("algo", [2, 1])
def test_symplectic_corrector_sees_the_bodies_at_the_half_step(case_data, tmp_path, algo):
    """DualSPHysics's ComputeStep_Sym moves the floating bodies to t + dt/2 after the predictor
    (RunFloating(dt/2, predictor)) and advances them by dt from the step's start after the
    corrector: the floating particles the corrector's interaction sees are displaced by
    V dt/2 from those the predictor's saw, and the step ends at x^n + dt V^(n+1) (the multibody
    state put back after the half step).  Verlet evaluates once, with the bodies at t^n."""
    from sphdvi.run_options import apply_overrides
    from sphdvi.simulation import SPHRun, special_parameters
    params = apply_overrides(special_parameters(case_data), ["FtPause=0", f"StepAlgorithm={algo}"])
    sph = SPHRun(case_data, params, str(tmp_path))
    sol, fb = sph.solver, sph.floating
    s = sol.state
    sel = np.flatnonzero(s.ptype == 2)
    fb.system.vel[0] = [0.5, 0.0, 0.3]
    fb.carry_particles(sol, sel, fb.body_of_idp[s.idp[sel]])
    seen = []
    rates = sol.compute_rates

    def spy():
        fl = sol.state.ptype == 2
        seen.append(sol.state.pos[fl].mean(axis=0))
        rates()

    sol.compute_rates = spy
    for _ in range(3):
        seen.clear()
        x0 = fb.system.pos[0].copy()
        dt = sol.step()
        v1 = fb.system.vel[0]
        assert np.allclose(fb.system.pos[0], x0 + dt * v1, rtol=0, atol=1e-12)
        if algo == 1:
            assert len(seen) == 1
            continue
        assert len(seen) == 2
        shift = seen[1] - seen[0]
        # the half step's velocity, V^n + a dt/2, is within dt |a| of V^(n+1)
        assert np.allclose(shift[[0, 2]], 0.5 * dt * v1[[0, 2]], rtol=2e-2)
        assert shift[1] == 0.0

"""A floating body across a periodic boundary: its particles are wrapped into the periodic box,
its centre is not; the moment takes the particle-to-centre distance as its shortest periodic
image (DualSPHysics's FtPeriodicDist in FtPartsSumAce / FtPartsUpdate)."""
import numpy as np
import pytest

from sphdvi.coupling import FloatingBodies, quat_matrix
from sphdvi.motion import MotionSet
from sphdvi.sph.periodic import Periodicity

from test_coupling import _coupling, _solver, case_data  # noqa: F401 (case_data: the gencased floatingbox2d)


def _setup(data, periodicity):
    fb, sol = _coupling(data), _solver(data)
    sol.periodicity = periodicity
    sel = np.flatnonzero(sol.state.ptype == 2)
    return fb, sol, sel, fb.body_of_idp[sol.state.idp[sel]]


def _edge_through_the_body(data, inc=0.0):
    """x periodic with its high end through the body's centre (period = centre x + 0.013)."""
    p = data["particles"]
    per = Periodicity(["x"], p["pos"], 0.01, {"XPeriodicIncZ": inc})
    per.lo[0] = 0.0
    fb = FloatingBodies(data, MotionSet([], []), int(data["json"]["mkconfig"]["fluidcount"]))
    per.length[0] = per.shift[0, 0] = fb.system.pos[0][0] + 0.013
    return per


@pytest.mark.parametrize("inc", [0.0, 0.05])
def test_moment_of_a_body_split_by_the_periodic_edge(case_data, inc):
    per = _edge_through_the_body(case_data, inc)
    fb, sol, sel, body = _setup(case_data, None)
    s = sol.state
    R = fb.system.pos[0]
    alpha, a0 = np.array([0.0, 3.7, 0.0]), np.array([0.4, 0.0, -1.3])
    sol.ace[sel] = np.cross(alpha, s.pos[sel] - R) + a0
    F0, T0 = fb.loads(sol, sel, body)
    assert abs(T0[0, 1]) > 1e-3
    pw = s.pos.copy()
    per.wrap(pw)
    moved = (pw != s.pos).any(axis=1)
    assert 0 < moved[sel].sum() < sel.size          # the edge cuts the body
    fb2, sol2, sel2, body2 = _setup(case_data, per)
    sol2.state.pos[:] = pw
    sol2.ace[:] = sol.ace
    F1, T1 = fb2.loads(sol2, sel2, body2)
    np.testing.assert_allclose(F1, F0, rtol=1e-12)
    np.testing.assert_allclose(T1, T0, rtol=1e-10, atol=1e-12)


def test_carried_particles_stay_in_the_periodic_box(case_data):
    per = _edge_through_the_body(case_data)
    fb, sol, sel, body = _setup(case_data, per)
    fb.system.vel[0] = [0.2, 0.0, 0.0]
    fb.carry_particles(sol, sel, body)
    x = sol.state.pos[sel, 0]
    assert x.max() < per.length[0] and (x < 0.1).any()      # the part past the edge is at the low end
    v = sol.state.vel[sel]
    np.testing.assert_allclose(v, np.tile([0.2, 0.0, 0.0], (sel.size, 1)), atol=1e-12)


# ---------------------------------------------------------------------------------------
# a free body crossing the periodic end: its centre wrapped as DualSPHysics's FtUpdateFloatings
# (center = UpdatePeriodicPos(fcenter)), its motion that of the same body far from the ends
# ---------------------------------------------------------------------------------------
def _drive(data, lo, nstep=400, dt=1e-3):
    """A free body launched along x at 1 m/s in an x-periodic box starting at ``lo`` (the tank's
    period), driven for ``nstep`` steps by a rigid acceleration field fixed in the body (a0 plus
    alpha x arm, the arm from its body-frame offsets, so the same whatever the wrap): its centre,
    velocity, angular velocity and fluid loads after each step."""
    per = Periodicity(["x"], data["particles"]["pos"], 0.01, {})
    per.lo[0] = lo
    fb, sol, _, _ = _setup(data, per)
    sol.nstep = 0
    fb.system.vel[0] = [1.0, 0.0, 0.0]
    alpha, a0 = np.array([0.0, 2.0, 0.0]), np.array([0.3, 0.0, 4.0])
    out = {k: [] for k in ("pos", "vel", "omega", "F", "T")}
    for _ in range(nstep):
        sel, body = fb.rows(sol)
        arm = fb.local_of_idp[sol.state.idp[sel]] @ quat_matrix(fb.system.quat[0]).T
        sol.ace[sel] = a0 + np.cross(alpha, arm)
        sol.time += dt
        fb.step(sol, dt)
        for k, v in (("pos", fb.system.pos[0]), ("vel", fb.system.vel[0]), ("omega", fb.system.omega_world[0]),
                     ("F", fb.system.fluid_force[0]), ("T", fb.system.fluid_torque[0])):
            out[k].append(np.array(v, float))
    return {k: np.array(v) for k, v in out.items()}, per, sol


def test_free_body_crossing_the_periodic_end(case_data):
    """The body (centre x 0.5 -> 0.9, its particles 0.1 either side) crosses the high end of the box
    [-0.2, L - 0.2) at t ~ 0.32 s; the reference, the same body in the box [0.24, L + 0.24), stays
    far from its ends. The crossing body's centre is in the box at every step (before: it went on
    past the end while its particles wrapped), and everything else matches the reference: position
    modulo the period, velocity, angular velocity, force and torque, with no jump at the crossing.
    Measured differences: positions 1.1e-16 m (the wrap's subtraction of L rounds once, then the same
    increments are added to numbers a period apart), torque 7.5e-16 N m (of 0.1: the lever arms'
    minimum images round differently), velocities exact;
    asserted at 1e-12 (positions of order 1 m, 400 steps: a few hundred ulps)."""
    cross, per, _ = _drive(case_data, -0.2)
    ref, per_ref, _ = _drive(case_data, 0.24)
    L = per.length[0]
    x = cross["pos"][:, 0]
    assert x.min() >= -0.2 and x.max() < L - 0.2                       # always in the box
    crossed = ref["pos"][:, 0] >= L - 0.2
    assert 50 < crossed.sum() < crossed.size - 50                      # the crossing is mid-run
    assert ref["pos"][:, 0].min() > per_ref.lo[0] + 0.15 and ref["pos"][:, 0].max() < per_ref.lo[0] + L - 0.15
    expect = ref["pos"].copy()
    expect[crossed, 0] -= L
    np.testing.assert_allclose(cross["pos"], expect, rtol=0, atol=1e-12)
    for k in ("vel", "omega", "F", "T"):
        np.testing.assert_allclose(cross[k], ref[k], rtol=0, atol=1e-12, err_msg=k)
    assert np.abs(ref["omega"][:, 1]).max() > 0.1 and np.abs(ref["T"][:, 1]).max() > 1e-3   # it does turn


def test_linked_body_crossing_the_periodic_end_is_refused(case_data):
    """A floating body with a link (or a collision shape) is integrated without the periodic
    conditions, as DualSPHysics's Chrono integrates it: its centre leaving the periodic box stops
    the run with an InputError (exit 2) naming the body and the link, not wrong contacts/links."""
    from sphdvi.errors import EXIT_INPUT, InputError
    per = Periodicity(["x"], case_data["particles"]["pos"], 0.01, {})
    fb, sol, _, _ = _setup(case_data, per)
    fb.system.add_link("spherical", 0, -1, point=fb.system.pos[0].tolist(), name="Link_box")
    from sphdvi.coupling import _periodic_roles
    fb._free_rows, fb._tied_rows = _periodic_roles(fb.system)
    assert fb._free_rows.size == 0 and fb._tied_rows.tolist() == [0]
    fb.wrap_centres(sol)                                                # inside: nothing to say
    fb.system.pos[0, 0] = per.lo[0] + per.length[0] + 0.01
    with pytest.raises(InputError, match=r"floating body mkbound \d+ \('\w+'\) crossed the periodic boundary along "
                                         r"x .* it has link 'Link_box'") as exc:
        fb.wrap_centres(sol)
    assert exc.value.exit_code == EXIT_INPUT

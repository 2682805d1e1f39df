"""BB, PSOR and APGD solve the islands that hold only joints exactly (audit hunt11/x, after hunt11/b
finding 1): at their default 100 iterations they did not hold a 5-link chain of 0.2 m cubes in its
plane (0.24 m BB, 0.25 m PSOR, 0.55 m APGD, PSOR not even at 1000: the out-of-plane rows' condition
number ~1.6e4 after Jacobi scaling).  An island whose rows are all equalities (joints, compliance rows of
springs, dampers and motors, explicit springs' fixed impulses) is a linear system; solve_iterative now
hands it to an envelope Cholesky factorisation, as `direct` solves it, and leaves every island with
contacts or bounded rows (friction, Coulomb dampers) to the iterative solver as before.  Opt-out:
System(exact_joints=False), <chrono><solver exactjoints="false">."""
import warnings

import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

from sphdvi.case.gencase import build_case
from sphdvi.dvi import System
from sphdvi.dvi import solvers as sv
from test_hinge_locked_rotations import _chain, _run_planar      # tests/dvi (on the path)
from test_step_allocations import _python_side, traced_kernels  # noqa: F401  (the fixture)

ITERATIVE = ("bb", "psor", "apgd")


def _state(s):
    return [a.copy() for a in (s.pos, s.quat, s.vel, s.omega_b, s.contact_force, s.link_force,
                               s.link_torque)]


def _same(a, b):
    return all(np.array_equal(x, y) for x, y in zip(a, b))


def _run(make, steps, **kw):
    s, *_ = make(**kw)
    its = []
    s.contacts_seen = 0
    for _ in range(steps):
        s.step(1e-3)
        its.append(s.last_iterations)
        s.contacts_seen = max(s.contacts_seen, s.n_contacts)
    return s, _state(s), its


def _plan(s):
    """plan_exact_islands on the System's rows of its last step: (islands, label)."""
    nr = s.n_rows
    label = np.empty(nr, np.int64)
    xorder = np.empty(nr, np.int64)
    xstart = np.empty(nr + 1, np.int64)
    nx, nxr, big = sv.plan_exact_islands(nr, s.nb, s.r_a, s.r_b, s.r_MiJ, s.r_kind, s.r_lo, s.r_hi,
                                         sv.EXACT_JOINT_MAX_ROWS, label, xorder, xstart)
    if nx == 0:
        label[:] = -1
    assert nxr == (label >= 0).sum() and (nx == 0 or big == np.diff(xstart[:nx + 1]).max())
    return nx, label


# ------------------------------------------------------------------ scenes
def _flap(s, m):
    """A 0.4 m flap hinged to the ground at x = 0 about y, its lower face 1 mm above the floor it
    falls onto (an island with contacts)."""
    f = s.add_body(mass=2.0, inertia=(0.03, 0.03, 0.03), pos=(0.2, 0, 0.021), name="flap")
    s.add_box(f, (0.2, 0.05, 0.02), material=m)
    s.add_link("hinge", f, -1, point=(0.0, 0, 0.021), axis=(0, 1, 0))
    return [f]


def _pendulum(s, x0=2.0):
    """An equal-mass double pendulum released horizontal, no shapes (an island of joints only)."""
    a = s.add_body(mass=1.0, inertia=(0.01,) * 3, pos=(x0 + 0.5, 0, 1.0), name="p1")
    b = s.add_body(mass=1.0, inertia=(0.01,) * 3, pos=(x0 + 1.0, 0, 1.0), name="p2")
    s.add_link("hinge", a, -1, point=(x0, 0, 1.0), axis=(0, 1, 0))
    s.add_link("hinge", b, a, point=(x0 + 0.5, 0, 1.0), axis=(0, 1, 0))
    return [a, b]


def _chain_on_box(s, m):
    """Three hinged links whose last one carries a ball resting on a free 0.9 m box on the floor,
    which it slides along while the chain sags."""
    box = s.add_body(mass=5.0, inertia=(0.35, 0.35, 0.35), pos=(-1.3, 0, 0.1), name="box")
    s.add_box(box, (0.45, 0.1, 0.1), material=m)
    prev, ids = -1, [box]
    for k in range(3):
        b = s.add_body(mass=0.5, inertia=(0.002,) * 3, pos=(-1.0 - 0.2 * (k + 1), 0, 0.25),
                       name=f"c{k}")
        s.add_link("hinge", b, prev, point=(-1.0 - 0.2 * k, 0, 0.25), axis=(0, 1, 0))
        prev = b
        ids.append(b)
    s.add_sphere(prev, 0.05, material=m)
    return ids


def _scene(solver="bb", flap=True, pendulum=True, chain=True, **kw):
    s = System(solver=solver, **kw)
    m = s.add_material("m", friction=0.5)
    s.add_plane(material=m)
    out = [_flap(s, m) if flap else [], _chain_on_box(s, m) if chain else [],
           _pendulum(s) if pendulum else []]
    return (s, *out)


def _stack(solver="bb", **kw):
    """Three 0.1 m cubes stacked on the floor, μ 0.5."""
    s = System(solver=solver, **kw)
    m = s.add_material("m", friction=0.5)
    s.add_plane(material=m)
    for k in range(3):
        b = s.add_body(1.0, (0.1 ** 2 / 6,) * 3, pos=(0.003 * k, 0, 0.05 + 0.1 * k))
        s.add_box(b, (0.05,) * 3, material=m)
    return (s,)


def _ball(solver="bb", **kw):
    """A ball dropped from 0.3 m onto the floor, restitution 0.6, with some spin."""
    s = System(solver=solver, **kw)
    m = s.add_material("m", friction=0.3, restitution=0.6)
    s.add_plane(material=m)
    b = s.add_body(1.0, (0.004,) * 3, pos=(0, 0, 0.3), vel=(0.5, 0, 0), omega=(0, 3, 0))
    s.add_sphere(b, 0.1, material=m)
    return (s,)


# ------------------------------------------------------------------ the split
def test_plan_hands_over_only_the_islands_without_contacts():
    """A flap touching the floor, a chain whose end ball rests on a box on the floor (one island
    through the contacts) and a double pendulum: only the pendulum's rows are an exact island; the
    flap's and the chain's hinges stay with their contacts."""
    s, flap, chain, pend = _scene()
    for _ in range(3):
        s.step(1e-3)
    assert s.n_contacts > 0
    nx, label = _plan(s)
    nr = s.n_rows
    touches = lambda ids: np.isin(s.r_a[:nr], ids) | np.isin(s.r_b[:nr], ids)   # noqa: E731
    assert nx == 1
    assert np.array_equal(label >= 0, touches(pend)) and touches(pend).sum() == 10
    # the chain's hinges and the box's contacts are one island, the flap's another
    lab = np.empty(nr, np.int64)
    sv.row_islands(nr, s.nb, s.r_a, s.r_b, s.r_MiJ, lab)
    assert len(set(lab[touches(chain)])) == 1 and len(set(lab[touches(flap)])) == 1
    assert set(lab[touches(chain)]) != set(lab[touches(flap)])
    assert (s.r_kind[:nr][touches(chain)] == sv.FRIC_N).any()
    assert (s.r_kind[:nr][touches(flap)] == sv.FRIC_N).any()


def test_bounded_rows_keep_their_island_iterative():
    """A Coulomb damper (boxed row, lo < hi) on the pendulum: its island is not a linear system;
    a spring (compliance row) keeps it exact."""
    s = System()
    p = _pendulum(s)
    s.add_coulomb_damper(p[1], -1, point1=(3.0, 0, 1.0), point2=(3.0, 0, 0.0), force=1.0)
    s.step(1e-3)
    assert _plan(s)[0] == 0 and s.last_iterations > 0
    s = System()
    p = _pendulum(s)
    s.add_spring(p[1], -1, point1=(3.0, 0, 1.0), point2=(3.0, 0, 0.0), stiffness=50.0, damping=2.0)
    s.step(1e-3)
    assert _plan(s)[0] == 1 and s.last_iterations == 0


@pytest.mark.parametrize("solver", ITERATIVE)
@pytest.mark.parametrize("make, steps", [(_stack, 300), (_ball, 400),
                                         (lambda **kw: _scene(pendulum=False, **kw), 300)],
                         ids=["box stack", "ball bouncing", "flap and chain in contact"])
def test_scenes_whose_islands_all_have_contacts_are_bitwise_unchanged(solver, make, steps):
    """Every island has contacts: solve_iterative takes solve_ccp as before, bit for bit."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")         # (PSOR's creep, not-converged: the same both ways)
        s1, a, it1 = _run(make, steps, solver=solver)
        s0, b, it0 = _run(make, steps, solver=solver, exact_joints=False)
    assert _same(a, b) and it1 == it0 and s1.contacts_seen > 0


@pytest.mark.parametrize("solver", ITERATIVE)
def test_islands_with_contacts_solve_as_without_the_joint_island(solver):
    """Adding a joint-only island (the pendulum) to the flap-and-chain scene leaves the others'
    motion bit for bit (the iterative solver sees the same rows), and the pendulum moves as it does
    alone."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s, a, _ = _run(_scene, 300, solver=solver)
        s0, b, _ = _run(_scene, 300, solver=solver, pendulum=False)
        sp, c, _ = _run(_scene, 300, solver=solver, flap=False, chain=False)
    n0 = s0.nb
    assert all(np.array_equal(x[:n0], y) for x, y in zip(a[:4], b[:4]))
    assert all(np.array_equal(x[n0:], y) for x, y in zip(a[:4], c[:4]))
    assert np.array_equal(a[4][:n0], b[4])


# ------------------------------------------------------------------ exactness
@pytest.mark.parametrize("solver", ITERATIVE)
def test_five_link_chain_matches_direct_at_default_iterations(solver):
    """The audit's 5-link chain (0.2 m cubes, h 1e-3 s, 3 s) at 100 iterations: in its plane to
    1e-9 m and within round-off of `direct` (1e-12 m), no iteration spent."""
    s, ids = _chain(5, solver, 0.2)
    d, _ = _chain(5, "direct", 0.2)
    worst = 0.0
    for _ in range(3000):
        s.step(1e-3)
        d.step(1e-3)
        worst = max(worst, np.abs(s.pos - d.pos).max())
        assert s.last_iterations == 0 and s.last_residual < 1e-10
    assert worst < 1e-12, worst
    assert np.abs(s.pos[:, 1]).max() < 1e-9


def test_mass_ratio_chain_at_default_iterations():
    """test_force_elements' spherical-joint chain of masses 1, 100, 1e4 released horizontal, 1 s: BB at
    100 iterations holds it (violation 8e-6 m, energy within 1e-3 of its scale); every row iterative it
    came apart (violation 0.049 m, energy +11 %: it needed 2000 iterations)."""
    G = 9.81
    s = System(gravity=(0, 0, -G), solver="bb")
    masses = [1.0, 100.0, 1e4]
    prev = -1
    for i, m in enumerate(masses):
        b = s.add_body(m, (m * 0.01,) * 3, pos=(0.5 + i, 0, 0))
        s.add_link("spherical", b, prev, point=(float(i), 0, 0))
        prev = b
    e0 = s.kinetic_energy() + s.potential_energy()
    viol = 0.0
    for k in range(1000):
        s.step(1e-3)
        viol = max(viol, s.constraint_violation())
    e1 = s.kinetic_energy() + s.potential_energy()
    assert viol < 1e-4 and abs(e1 - e0) < 1e-3 * sum(m * G * (0.5 + i) for i, m in enumerate(masses))


def test_soft_rows_match_direct():
    """A double pendulum with a spring to the ground, a pendulum hinged with stiffness and damping
    and a speed motor (compliance rows, implicit; fixed impulses, explicit): exact as `direct`, to
    round-off."""
    def make(solver, scheme):
        s = System(solver=solver, spring_integration=scheme)
        p = _pendulum(s)
        s.add_spring(p[1], -1, point1=(3.0, 0, 1.0), point2=(3.0, 0, 0.0), stiffness=80.0,
                     damping=1.0, rest_length=0.8)
        q = s.add_body(mass=1.0, inertia=(0.01,) * 3, pos=(5.5, 0, 1.0))
        s.add_link("hinge", q, -1, point=(5.0, 0, 1.0), axis=(0, 1, 0), stiffness=20.0, damping=0.3)
        w = s.add_body(mass=1.0, inertia=(0.01,) * 3, pos=(7.0, 0, 1.0))
        s.add_link("hinge", w, -1, point=(7.0, 0, 1.0), axis=(0, 0, 1), motor="speed",
                   motor_target=2.0)
        return s
    for solver, scheme in (("bb", "implicit"), ("psor", "explicit"), ("apgd", "auto")):
        s, d = make(solver, scheme), make("direct", scheme)
        for _ in range(1000):
            s.step(1e-3)
            d.step(1e-3)
            assert s.last_iterations == 0
        assert np.abs(s.pos - d.pos).max() < 1e-11 and np.abs(s.vel - d.vel).max() < 1e-9


def test_redundant_joints_stay_iterative():
    """A door on two coaxial hinges (10 rows for 6 freedoms): the Cholesky pivots of the dependent
    rows vanish, so the island goes back to the iterative solver, bit for bit as without the
    exact path."""
    def make(**kw):
        s = System(**kw)
        d = s.add_body(mass=5.0, inertia=(0.2, 0.3, 0.1), pos=(0.4, 0, 0.5), vel=(0, 0.3, 0))
        s.add_link("hinge", d, -1, point=(0, 0, 0.0), axis=(0, 0, 1))
        s.add_link("hinge", d, -1, point=(0, 0, 1.0), axis=(0, 0, 1))
        return (s,)
    s1, a, it1 = _run(make, 300)
    s0, b, it0 = _run(make, 300, exact_joints=False)
    assert _plan(s1)[0] == 1
    assert _same(a, b) and it1 == it0 and max(it1) > 0


def test_islands_beyond_the_row_limit_stay_iterative(monkeypatch):
    """An island of more than EXACT_JOINT_MAX_ROWS rows keeps the iterative solver (bit for bit)."""
    monkeypatch.setattr(sv, "EXACT_JOINT_MAX_ROWS", 24)

    def make(exact):
        s, ids = _chain(5, "bb", 0.2)         # 25 rows
        s.exact_joints = exact
        return (s,)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")         # (not converged: the same both ways)
        s1, a, it1 = _run(make, 200, exact=True)
        s0, b, it0 = _run(make, 200, exact=False)
    assert _same(a, b) and it1 == it0 and max(it1) > 0


def test_long_chain_exact_and_hub_iterative():
    """A 100-link chain (500 rows, banded: envelope factor ~3.3e4) is solved exactly; 100 pendulums
    hinged to one floating hub (503 rows, every pair sharing the hub: a dense factor of ~4.3e7, above
    EXACT_JOINT_MAX_WORK) stays iterative, bit for bit as without the exact path."""
    s, ids = _chain(100, "bb", 0.1, arm=0.2)
    for _ in range(5):
        s.step(1e-3)
    assert s.n_rows == 500 and s.last_iterations == 0 and s.last_residual < 1e-10

    def hub(exact):
        s = System(exact_joints=exact)
        h = s.add_body(mass=50.0, inertia=(5.0,) * 3, pos=(0, 0, 0))
        s.add_link("spherical", h, -1, point=(0, 0, 0))
        for k in range(100):
            a = 2 * np.pi * k / 100
            p = s.add_body(mass=0.1, inertia=(1e-3,) * 3, pos=(np.cos(a), np.sin(a), 0))
            s.add_link("hinge", p, h, point=(0.5 * np.cos(a), 0.5 * np.sin(a), 0),
                       axis=(-np.sin(a), np.cos(a), 0))
        return (s,)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s1, a, it1 = _run(hub, 5, exact=True)
        s0, b, it0 = _run(hub, 5, exact=False)
    assert s1.n_rows == 503 and _plan(s1)[0] == 1
    assert _same(a, b) and it1 == it0 and max(it1) > 0


def test_opt_out_keeps_every_row_iterative():
    """exact_joints=False: the chain's rows go to BB as before (iterations spent, the
    out-of-plane rows not held to 1e-9 m in 1.5 s at 100 iterations)."""
    s, ids = _chain(5, "bb", 0.2)
    s.exact_joints = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ymax, amax = _run_planar(s, ids, 1.5)
    assert s.last_iterations > 0 and ymax > 1e-9


def test_solve_iterative_without_joint_islands_is_solve_ccp(rng):
    """Random contact problems through solve_iterative(exact_joints=True): solve_ccp, bit for bit."""
    from test_solvers import random_problem
    for solver in ITERATIVE:
        P = random_problem(rng, nb=4, nc=6, nbil=0)
        out = []
        for f in (lambda *a: sv.solve_iterative(*a, exact_joints=True), sv.solve_ccp):
            g = np.zeros(P["nr"])
            v = np.empty_like(P["vfree"])
            it, res = f(sv.SOLVER_NAMES[solver], P["nr"], P["nb"], P["ra"], P["rb"], P["J"],
                        P["MiJ"], P["b"], P["E"], P["kind"], P["mu"], P["lo"], P["hi"], P["g"], g,
                        P["vfree"], v, 100, 1e-10, 1.0)
            out.append((g, v, it, res))
        assert np.array_equal(out[0][0], out[1][0]) and np.array_equal(out[0][1], out[1][1])
        assert out[0][2:] == out[1][2:]


# ------------------------------------------------------------------ allocations
def test_exact_path_allocates_nothing_per_step(traced_kernels):
    """A 20-hinge chain (one exact island of 100 rows): the work arrays are kept on the System;
    the step's Python side allocates under 1 kB (test_step_allocations' measure)."""
    s, ids = _chain(20, "bb", 0.1, arm=0.3)
    worst, left = _python_side(s, traced_kernels)
    assert worst < 1024, worst
    assert s.last_iterations == 0 and s.n_rows == 100


# ------------------------------------------------------------------ case settings
def _case(tmp_path, solver):
    """test_chrono_solver_settings' case (a floating box on a hinge) with ``solver``: its file."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    bodies = """
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.1" y="-0.1" z="0.3" />
                        <size x="0.1" y="0.2" z="0.1" /></drawbox>"""
    hinge = ('<link_hinge idbody1="A"><rotpoint x="0" y="0" z="0.35"/><rotvector x="0" y="1" z="0"/>'
             '</link_hinge>')
    chrono = f'<chrono><bodyfloating id="A" mkbound="1"/>{hinge}{solver}</chrono>'
    text = case_xml(pointmin=("-0.5", "-0.5", "-0.5"), pointmax=("0.7", "0.5", "0.8"), commands=bodies,
                    casedef_extra='<floatings><floating mkbound="1" rhopbody="500" /></floatings>',
                    special=chrono, parameters='<parameter key="RigidAlgorithm" value="3" />', dp="0.05")
    return write_case(tmp_path, text)


def _build(tmp_path, solver):
    return build_case(_case(tmp_path, solver), str(tmp_path / "out"))


def test_exactjoints_setting_is_read_and_reaches_the_system(tmp_path):
    """<solver exactjoints="false"> (an sphdvi extension): read, carried to System(exact_joints)."""
    from click.testing import CliRunner

    from sphdvi.cli import main
    from sphdvi.dvi.runner import build_system
    from sphdvi.io.casefile import read_case_h5
    from sphdvi.mechanism import mechanism_from_case
    r = _build(tmp_path, '<solver type="PSOR" exactjoints="false"/>')
    assert r.case.special["chrono"]["solver"] == {"type": "psor", "exactjoints": False}
    assert not [w for w in r.warnings if "solver" in w]
    case = _case(tmp_path / "cli", '<solver type="PSOR" exactjoints="0"/>')
    res = CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    data = read_case_h5(str(next((tmp_path / "out").glob("*.h5"))))
    mech = mechanism_from_case(data)
    system, _ = build_system(mech["bodies"], mech["links"], mech["materials"], **mech["system"])
    assert system.exact_joints is False and system.solver == "psor"
    assert System().exact_joints is True


def test_bad_exactjoints_is_an_error_and_direct_warns(tmp_path):
    from sphdvi.errors import CaseError
    with pytest.raises(CaseError, match=r"<solver>: exactjoints='maybe' is not a boolean"):
        _build(tmp_path / "a", '<solver exactjoints="maybe"/>')
    r = _build(tmp_path / "b", '<solver type="direct" exactjoints="true"/>')
    (w,) = [w for w in r.warnings if "solver" in w]
    assert "exactjoints" in w and "ignored" in w

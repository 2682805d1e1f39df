"""Contact problems at large mass ratios: the `direct` solver (dense projected gradient, then
the dense interior-point method where that does not converge) against a heavy box resting on
a light one, and the interior-point method against the other solvers and clarabel."""
import math

import numpy as np
import pytest

from sphdvi.dvi import System
from sphdvi.dvi import solvers as sv
from test_solvers import _clarabel_solve, dense_N, random_problem  # tests/dvi (on the path)


def _stack(solver, ratio, dx=0.0, yaw=0.0, T=1.0, max_iter=100):
    """A 1 kg 0.1 m box on a plane under a ``ratio`` kg one (offset ``dx``, turned ``yaw``
    degrees), μ 0.5, e 0, h 1e-3 s: the largest gap error (m) over ``T`` and the iterations."""
    s = System(solver=solver, max_iter=max_iter)
    m = s.add_material("m", friction=0.5, restitution=0.0)
    s.add_plane((0, 0, 0), (0, 0, 1), material=m)
    a = s.add_body(mass=1.0, inertia=(1 / 600,) * 3, pos=(0, 0, 0.05))
    s.add_box(a, (0.05, 0.05, 0.05), material=m)
    q = (math.cos(math.radians(yaw) / 2), 0, 0, math.sin(math.radians(yaw) / 2))
    b = s.add_body(mass=ratio, inertia=(ratio / 600,) * 3, pos=(dx, 0, 0.15), quat=q)
    s.add_box(b, (0.05, 0.05, 0.05), material=m)
    worst, its = 0.0, []
    for _ in range(int(round(T / 1e-3))):
        s.step(1e-3)
        its.append(s.last_iterations)
        za, zb = s.pos[a, 2], s.pos[b, 2]
        if not np.isfinite(s.pos).all():
            return np.inf, its, s
        worst = max(worst, abs(za - 0.05), abs(zb - za - 0.1))
    return worst, its, s


@pytest.mark.parametrize("ratio,dx,yaw", [(1e6, 0.0, 0.0), (1e7, 0.0, 0.0), (1e6, 0.01, 0.0),
                                          (1e5, 0.0, 10.0)])
def test_direct_holds_a_heavy_box_on_a_light_one(ratio, dx, yaw):
    """Was: the dense projected gradient alone, 100 iterations, did not converge on this
    N (eigenvalues 1 and 1e-6 after the Jacobi scaling) and wandered until the light box was
    thrown 0.95 m (1:1e6) or crushed (an offset stack already at 1:1e4).  Now the interior-point
    method finishes each solve: the stack rests to 1e-12 m."""
    worst, its, s = _stack("direct", ratio, dx, yaw)
    assert worst < 1e-6, worst
    assert s.last_residual <= 1e-9
    assert max(its) <= 200        # at most max_iter BB iterations + max_iter Newton steps
    print(f"direct 1:{ratio:g} dx {dx} yaw {yaw}: gap error {worst:.2g} m, iterations mean "
          f"{np.mean(its):.1f} max {max(its)}")


def test_bb_at_an_offset_stack_is_no_better_than_its_symmetric_luck():
    """The matrix-free BB rests a symmetric 1:1e6 stack only because its Schur product keeps
    the friction rows bit-exactly zero there (4 identical contacts): offset by 1 cm the stack
    fails from about 1:3e3 at 100 iterations, as the dense BB does (same algorithm, same
    iterates up to rounding).  This pins that limit (README, bodychecks) and that `direct`
    holds the same case."""
    with pytest.warns(UserWarning, match="not converged"):
        worst_bb, _, _ = _stack("bb", 1e4, dx=0.01, T=0.3)
    assert worst_bb > 1e-3
    worst_d, _, _ = _stack("direct", 1e4, dx=0.01, T=0.3)
    assert worst_d < 1e-9


def _ill_problem(rng, nb=4, nc=6, spread=1e6, nbil=0):
    """random_problem with body masses (and inertias) spread over ``spread``."""
    P = random_problem(rng, nb=nb, nc=nc, nbil=nbil)
    f = np.exp(rng.uniform(0.0, math.log(spread), nb))
    P["invm3"] = P["invm3"] / f[:, None]
    P["invI"] = P["invI"] / f[:, None, None]
    sv.prepare_rows(P["nr"], P["ra"], P["rb"], P["J"], P["E"], P["kind"], P["invm3"], P["invI"],
                    P["MiJ"], P["g"])
    return P


def _rhs(P):
    r = np.empty(P["nr"])
    sv.rows_times_v(P["nr"], P["ra"], P["rb"], P["J"], P["vfree"], r)
    return r + P["b"]


def _res_vel(P, N, r, g):
    """The natural-map residual in velocity units, as the solvers measure it."""
    d = np.maximum(np.diag(N).copy(), 1e-300)
    sv.average_friction_triplets(d, P["kind"], d.size)
    s = np.sqrt(d)
    tmp = np.empty(d.size)
    return sv._natural_residual(g * s, (N @ g + r) / s, s, P["kind"], P["mu"], P["lo"], P["hi"], tmp)


def _direct(P, max_iter=100, tol=1e-10):
    g = np.zeros(P["nr"])
    v = np.zeros((P["nb"], 6))
    it, res = sv.solve_direct(P["nr"], P["nb"], P["ra"], P["rb"], P["J"], P["MiJ"], P["b"],
                              P["E"], P["kind"], P["mu"], P["lo"], P["hi"], P["g"], g,
                              P["vfree"], v, max_iter, tol)
    return g, it, res


def test_direct_agrees_with_clarabel_on_ill_conditioned_problems(rng):
    """Random frictional CCPs with body masses spread 1e6 (and some well conditioned): the
    dense projected gradient does not converge in 100 iterations, the interior-point method
    then reaches the residual (velocity units) 1e-9 within 100 Newton steps (1e-10 in all but
    about 1 in 200), and the velocities equal clarabel's where clarabel is itself accurate."""
    pytest.importorskip("clarabel")
    compared, its, bb_only = 0, [], 0
    for trial in range(40):
        P = random_problem(rng, nb=4, nc=5) if trial % 4 == 3 else _ill_problem(rng)
        N = dense_N(P)
        r = _rhs(P)
        gb = np.zeros(P["nr"])
        _, res_bb = sv.solve_dense_bb(N, r, P["kind"], P["mu"], P["lo"], P["hi"], gb, 100, 1e-10)
        bb_only += res_bb <= 1e-10
        g, it, res = _direct(P)
        its.append(it)
        assert res <= 1e-9, (trial, it, res)
        assert it <= 200
        f = lambda x: 0.5 * x @ N @ x + r @ x
        ref = min([_clarabel_solve(P, N, r, False), _clarabel_solve(P, N, r, True)], key=f)
        if _res_vel(P, N, r, ref) < 1e-6:   # clarabel accurate (1e-8 in only a few of these)
            # the velocities are unique (the impulses need not be): they agree
            assert np.abs(N @ (g - ref)).max() < 1e-5, (trial, it, res)
            compared += 1
        assert f(g) <= f(ref) + 1e-9 * (1 + abs(f(ref)))
    assert compared >= 15
    assert bb_only <= 15          # the projected gradient alone mostly does not converge
    print(f"direct iterations (100 BB + Newton steps): mean {np.mean(its):.1f}, max {max(its)}")


def test_direct_boxed_unilateral_and_frictionless_rows(rng):
    """Row kinds besides friction cones (boxed rows with finite and half-infinite bounds,
    unilateral rows, μ = 0 triplets), masses spread 1e4: the direct solution is feasible, at
    the tolerance, and its objective is the projected gradient's run to convergence."""
    for trial in range(20):
        P = _ill_problem(rng, nc=4, spread=1e4)
        nr = P["nr"]
        P["mu"][0] = 0.0                                             # frictionless contact
        P["kind"][3:6] = (sv.UNILATERAL, sv.BOXED, sv.BOXED)         # a triplet's rows reused
        P["mu"][3] = 0.0
        P["lo"][4], P["hi"][4] = -0.3, 0.2
        P["lo"][5], P["hi"][5] = -0.1, 1e300                         # lower bound only
        sv.prepare_rows(nr, P["ra"], P["rb"], P["J"], P["E"], P["kind"], P["invm3"], P["invI"],
                        P["MiJ"], P["g"])
        N = dense_N(P)
        r = _rhs(P)
        g, it, res = _direct(P)
        assert res <= 1e-9, (trial, it, res)
        gb = np.zeros(nr)
        sv.solve_dense_bb(N, r, P["kind"], P["mu"], P["lo"], P["hi"], gb, 100000, 1e-12)
        f = lambda x: 0.5 * x @ N @ x + r @ x
        assert f(g) <= f(gb) + 1e-9 * (1 + abs(f(gb))), trial
        assert g[1] == 0.0 and g[2] == 0.0        # μ = 0: no tangential impulse
        assert g[3] >= 0.0 and -0.3 <= g[4] <= 0.2 and g[5] >= -0.1


def test_direct_agrees_with_bb_and_apgd_with_joints(rng):
    """solve_direct (bilateral rows by Cholesky, contacts by BB then the interior-point method)
    against the matrix-free BB and APGD given many iterations, on problems with joints and
    masses spread 1e4: direct reaches the tolerance at its default 100 iterations and its
    objective is not above theirs."""
    for trial in range(15):
        P = _ill_problem(rng, nc=5, spread=1e4, nbil=3)
        N = dense_N(P)
        r = _rhs(P)
        obj = lambda x: 0.5 * x @ N @ x + r @ x
        gd, it, res = _direct(P)
        assert res <= 1e-9, (trial, it, res)
        args = (P["nr"], P["nb"], P["ra"], P["rb"], P["J"], P["MiJ"], P["b"], P["E"], P["kind"],
                P["mu"], P["lo"], P["hi"], P["g"])
        for name in ("bb", "apgd"):
            g = np.zeros(P["nr"])
            v = np.zeros((P["nb"], 6))
            sv.solve_ccp(sv.SOLVER_NAMES[name], *args, g, P["vfree"], v, 20000, 1e-12, 1.0)
            assert obj(gd) <= obj(g) + 1e-8 * (1 + abs(obj(g))), (trial, name)

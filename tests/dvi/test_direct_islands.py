"""The `direct` solver island by island: N = D M⁻¹ Dᵀ + E is block-diagonal over the connected
components of the bodies that the rows link (the world and fixed bodies link nothing), so each
island's dense problem (Cholesky, projected gradient, interior-point finish) is solved on its own
(audit hunt11/b finding 9: the interior-point finish was skipped whenever the WHOLE scene had
more than IPM_MAX_ROWS contact rows)."""
import math
import warnings

import numpy as np
import pytest

from sphdvi.dvi import System
from sphdvi.dvi import solvers as sv
from test_solvers import dense_N, random_problem  # tests/dvi (on the path)


def _direct(P, g0=None):
    g = np.zeros(P["nr"]) if g0 is None else g0.copy()
    vout = np.empty_like(P["vfree"])
    it, res = sv.solve_direct(P["nr"], P["nb"], P["ra"], P["rb"], P["J"], P["MiJ"], P["b"],
                              P["E"], P["kind"], P["mu"], P["lo"], P["hi"], P["g"], g, P["vfree"],
                              vout, 100, 1e-10)
    return g, vout, it, res


def _labels(P):
    lab = np.empty(P["nr"], np.int64)
    n = sv.row_islands(P["nr"], P["nb"], P["ra"], P["rb"], P["MiJ"], lab)
    return n, lab


def _join(P1, P2):
    """One problem holding P2's rows, then P1's (P1's bodies first, P2's after them)."""
    nb1 = P1["nb"]
    rb2 = {k: np.where(P2[k] >= 0, P2[k] + nb1, -1).astype(P2[k].dtype) for k in ("ra", "rb")}
    P = {"nr": P1["nr"] + P2["nr"], "nb": nb1 + P2["nb"]}
    for k in ("J", "MiJ", "E", "kind", "mu", "lo", "hi", "g", "b"):
        P[k] = np.concatenate([P2[k], P1[k]])
    for k in ("ra", "rb"):
        P[k] = np.concatenate([rb2[k], P1[k]])
    P["vfree"] = np.concatenate([P1["vfree"], P2["vfree"]])
    for k in ("invm3", "invI"):
        P[k] = np.concatenate([P1[k], P2[k]])
    return P


def test_row_islands_are_the_components_of_the_moving_bodies():
    """Rows link bodies only through a side with M⁻¹Jᵀ ≠ 0: the ground (-1) and a fixed body
    (zero inverse mass) join nothing; a row with no live side is -1."""
    nb = 5
    invm3 = np.ones((nb, 3))
    invI = np.repeat(np.eye(3)[None], nb, axis=0)
    invm3[4] = 0.0                      # body 4 fixed
    invI[4] = 0.0
    pairs = [(0, -1), (0, 1), (2, -1), (3, 4), (4, 2), (-1, 4), (1, 0)]
    nr = len(pairs)
    ra = np.array([p[0] for p in pairs], np.int32)
    rb = np.array([p[1] for p in pairs], np.int32)
    J = np.zeros((nr, 12))
    J[:, 2] = -1.0
    J[:, 8] = 1.0
    MiJ = np.zeros((nr, 12))
    gd = np.zeros(nr)
    sv.prepare_rows(nr, ra, rb, J, np.zeros(nr), np.full(nr, sv.UNILATERAL, np.int8), invm3,
                    invI, MiJ, gd)
    lab = np.empty(nr, np.int64)
    n = sv.row_islands(nr, nb, ra, rb, MiJ, lab)
    assert n == 3
    assert lab.tolist() == [0, 0, 1, 2, 1, -1, 0]


def test_direct_solves_each_island_on_its_own(rng):
    """Two independent problems written as one: the impulses and velocities are those of the
    two problems solved apart, bit for bit, and the joint solution is a CCP solution."""
    P1 = random_problem(rng, nb=4, nc=6, nbil=2)
    P2 = random_problem(rng, nb=3, nc=5, nbil=1)
    P = _join(P1, P2)
    assert _labels(P)[0] == _labels(P1)[0] + _labels(P2)[0]
    g, v, it, res = _direct(P)
    g1, v1, it1, res1 = _direct(P1)
    g2, v2, it2, res2 = _direct(P2)
    assert np.array_equal(g, np.concatenate([g2, g1]))
    assert np.array_equal(v, np.concatenate([v1, v2]))
    assert res == max(res1, res2) <= 1e-10 and it == max(it1, it2)
    N = dense_N(P)
    r = np.empty(P["nr"])
    sv.rows_times_v(P["nr"], P["ra"], P["rb"], P["J"], P["vfree"], r)
    u = N @ g + r + P["b"]
    # complementarity γ·u = 0 per contact triplet, bilateral rows satisfied
    kn = np.nonzero(P["kind"] == sv.FRIC_N)[0]
    assert np.abs(sum(g[kn + q] * u[kn + q] for q in range(3))).max() < 1e-8
    assert np.abs(u[P["kind"] == sv.BILATERAL]).max() < 1e-8


def test_direct_on_one_island_is_the_whole_problem_solve(rng):
    """A scene that is one island goes through the same dense solve as before the split, bit for
    bit (the island's arrays are the rows themselves)."""
    for _ in range(50):
        P = random_problem(rng, nb=3, nc=7, nbil=1)
        n, lab = _labels(P)
        if n == 1 and lab.min() == 0:
            break
    else:
        pytest.fail("no single-island problem drawn")
    g, v, it, res = _direct(P)
    g0 = np.zeros(P["nr"])
    nr = P["nr"]
    it0, res0, skipped = sv._solve_direct_island(P["ra"], P["rb"], P["J"], P["MiJ"], P["b"],
                                                 P["E"], P["kind"], P["mu"], P["lo"], P["hi"], g0,
                                                 P["vfree"], 100, 1e-10)
    v0 = P["vfree"].copy()
    sv.scatter_impulses(nr, P["ra"], P["rb"], P["MiJ"], g0, v0)
    assert np.array_equal(g, g0) and np.array_equal(v, v0) and (it, res) == (it0, res0)
    assert not skipped


def _heavy_on_light(ratio, bystanders, T, **kw):
    """The audit's scene (s22_direct_big.py): a ``ratio`` kg 0.1 m cube turned 10° and offset
    1 cm on a 1 kg cube on a plane, μ 0.5, h 1e-3 s, and ``bystanders`` 1 kg cubes resting on the
    plane 0.3–1.8 m away.  Returns the System and the largest error of the heavy cube's height."""
    s = System(solver="direct", **kw)
    s.add_material("m", friction=0.5)
    s.add_plane((0, 0, 0), (0, 0, 1), material="m")
    a = 0.1
    light = s.add_body(mass=1, inertia=(a * a / 6,) * 3, pos=(0, 0, a / 2), name="light")
    s.add_box(light, (a / 2,) * 3, material="m")
    heavy = s.add_body(mass=ratio, inertia=(ratio * a * a / 6,) * 3, pos=(0.01, 0, 1.5 * a),
                       quat=(math.cos(0.087), 0, 0, math.sin(0.087)), name="heavy")
    s.add_box(heavy, (a / 2,) * 3, material="m")
    for k in range(bystanders):
        b = s.add_body(mass=1, inertia=(a * a / 6,) * 3,
                       pos=(0.3 + 0.15 * (k % 10), 0.15 * (k // 10), a / 2))
        s.add_box(b, (a / 2,) * 3, material="m")
    worst = 0.0
    for _ in range(int(round(T / 1e-3))):
        s.step(1e-3)
        worst = max(worst, abs(s.pos[heavy][2] - 1.5 * a))
    return s, worst


def test_direct_holds_a_heavy_box_on_a_light_one_among_bystanders():
    """Was: 30 unrelated resting cubes took the scene past IPM_MAX_ROWS (384 rows), the
    interior-point finish was skipped for the whole scene, and the 1e4 kg cube went through the
    1 kg one (height error 0.1 m, 'not converged' warnings).  Now the pair is an island of 24 rows
    and holds as it does alone."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s, worst = _heavy_on_light(1e4, 30, T=0.3)
    assert s.n_rows > sv.IPM_MAX_ROWS
    assert worst < 1e-6, worst
    assert s.last_residual <= 1e-9


def test_direct_warns_once_when_an_island_too_large_skips_the_interior_point(monkeypatch):
    """An island of more than IPM_MAX_ROWS contact rows keeps the projected gradient only: where
    that has not converged and the island's mass ratio is beyond BB's limit, the run warns once,
    naming the island's bodies (here IPM_MAX_ROWS lowered below the pair's 24 rows)."""
    monkeypatch.setattr(sv, "IPM_MAX_ROWS", 20)
    with pytest.warns(UserWarning) as rec:
        s, worst = _heavy_on_light(1e4, 2, T=0.3)
    lines = [str(w.message) for w in rec if "interior-point" in str(w.message)]
    assert len(lines) == 1, lines
    assert "light" in lines[0] and "heavy" in lines[0] and "1e+04" in lines[0]
    assert s.pending_warnings.count(lines[0]) == 1
    # below BB's mass-ratio limit: nothing said even though the finish is skipped
    monkeypatch.setattr(sv, "IPM_MAX_ROWS", 0)
    with warnings.catch_warnings(record=True) as rec2:
        warnings.simplefilter("always")
        _heavy_on_light(500.0, 0, T=0.05, max_iter=3)
    assert not [w for w in rec2 if "interior-point" in str(w.message)]

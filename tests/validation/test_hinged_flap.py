"""S18: a hinged buoyant flap in still water (cases/hingedflap2d/CaseHingedFlap2D_Def.xml through
the CLI): SPH water, a floating flap on a Chrono link_hinge with a torsional spring, two-way
coupled. sphdvi.validation.hingedflap.case_errors scores the settled tilt against the moment
balance F r_c sin φ = K (φ0 − φ) and the hinge's reaction against the net buoyancy F.
"""
from pathlib import Path

import pytest
from _caseruns import cached_runs
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation import hingedflap as HF

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "hingedflap2d" / "CaseHingedFlap2D_Def.xml"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """run(dp, threads=1) -> case_errors of that run (cached by dp)."""
    def report(dp, case, e):
        return ("S18 hinged flap, dp %g: settled tilt %.2f deg against %.2f (%+.2f deg; drawn %.2f), hinge reaction "
                "%+.1f %% of the net buoyancy (horizontal %.1f %%), torque %+.2f %% of the spring's; %d particles, "
                "%d steps, %.1f s"
                % (dp, e["settled_deg"], e["equilibrium_deg"], e["tilt_error"], e["phi0_deg"],
                   100 * e["reaction_error"], 100 * e["reaction_x"], 100 * e["torque_error"], e["particles"],
                   e["steps"], e["runtime_s"]))
    def score(out):
        return dict(HF.case_errors(out), outdir=out)
    serial = cached_runs(tmp_path_factory, score, report, threads=1)
    threaded = cached_runs(tmp_path_factory, score, report, threads=2)
    return lambda dp, threads=1: (serial if threads == 1 else threaded)(dp, CASE)


def test_equilibrium_tilt_solves_the_moment_balance():
    """eq. (1) by Newton: F r_c sin φ = K (φ0 − φ) holds at the root, for either sense of tilt,
    and φ lies between 0 and φ0."""
    import math
    for phi0 in (0.35, -0.35):
        phi = HF.equilibrium_tilt(233.5, 0.165, 30.0, phi0)
        assert 0 < phi / phi0 < 1
        assert abs(233.5 * 0.165 * math.sin(abs(phi)) - 30.0 * (abs(phi0) - abs(phi))) < 1e-10


def test_coupled_hinge_at_dp_0_04(run):
    """The coarse run (the flap 3 particles thick, 738 particles, ~20 s on 1 thread) as a check of
    the coupling through a joint: the hinge holds (the centroid keeps its distance from it to
    1e-6 m), the flap turns towards the vertical and settles (within 0.5 deg over the last
    second), and the link's torque is its spring's K (φ0 − φ) within 2 % (measured −0.7 %).
    The analytic equilibrium needs dp 0.02: here the water under the flap, two particles deep,
    carries part of the net buoyancy (the hinge holds 40 % of it) and the flap stays 3.4 deg short
    of the balance (settled −11.27 deg against −7.90).

    That shortfall is asserted as a coarse-resolution regression bound, −4.3 < error < −2.5 deg:
    it is what makes the test see the size of the fluid's load on the flap (the fluid's force and
    moment on the body scaled by 0.9 / 1.15 settle it at −5.0 / −2.3 deg from the balance, by
    0.8 / 1.5 at −6.1 / −1.1 deg; none of the other checks notices).  And the settled flap is in
    equilibrium under its three loads, the fluid's force (bodies.csv ff*), the link's (links.csv)
    and its weight, within 1 % of the weight: a check of the body's books that does not depend on
    the water under the flap."""
    import numpy as np
    from sphdvi.validation.runs import body_log, case_data
    e = run(0.04)
    assert e["hinge_drift"] < 1e-6
    assert abs(e["settled_deg"]) < abs(e["phi0_deg"]) and e["swing"] < 0.5
    assert abs(e["torque_error"]) < 0.02
    assert -4.3 < e["tilt_error"] < -2.5, e["tilt_error"]
    geo = HF.case_geometry(e["outdir"])
    bodies, links = body_log(e["outdir"]), body_log(e["outdir"], "links")
    late = np.asarray(bodies["time"], dtype=float) >= HF.SETTLED_FROM - 1e-9
    assert np.array_equal(np.asarray(links["time"], dtype=float) >= HF.SETTLED_FROM - 1e-9, late)
    weight = -geo["mass"] * float(np.asarray(case_data(e["outdir"])["constants"]["gravity"], dtype=float)[2])
    fx = np.mean(np.asarray(bodies["ffx"])[late] + np.asarray(links["fx"])[late])
    fz = np.mean(np.asarray(bodies["ffz"])[late] + np.asarray(links["fz"])[late]) - weight
    assert abs(fx) < 0.01 * weight and abs(fz) < 0.01 * weight, (fx, fz, weight)


@pytest.mark.slow
def test_s18_equilibrium_at_dp_0_02(run):
    """TOLERANCES S18 at dp 0.02 (2,676 particles, ~1.5 min on 2 threads): the settled tilt within
    1 deg of the moment balance (measured −0.91 deg: 9.96 against 9.05 deg from a drawn 20.35);
    the hinge holds the net buoyancy within 3 % (−2.8 %), its horizontal force below 3 % of it
    (2.6 %)."""
    e = run(0.02, threads=2)
    assert abs(e["tilt_error"]) < 1.0
    assert abs(e["reaction_error"]) < 0.03 and abs(e["reaction_x"]) < 0.03
    assert e["hinge_drift"] < 1e-6


@pytest.mark.slow
def test_s18_converges_at_dp_0_01(run):
    """dp 0.01 (10,351 particles, ~7 min on 2 threads): the tilt within 0.1 deg of the moment
    balance (measured +0.04 deg), below the dp 0.02 error; the hinge holds the net buoyancy within
    2 % (−1.6 %)."""
    e = run(0.01, threads=2)
    assert abs(e["tilt_error"]) < 0.1
    assert abs(e["tilt_error"]) < abs(run(0.02, threads=2)["tilt_error"])
    assert abs(e["reaction_error"]) < 0.02


@pytest.mark.slow
def test_s18_swing_period_above_the_bound(tmp_path):
    """CaseHingedFlapSwing2D_Def.xml (no damper) at dp 0.02, ~35 s on 2 threads: the flap's first
    half-swing, from the release to its turning point (t = 0.82 s, at 10.5 deg against the
    equilibrium's 9.05: the water damps it so much that it does not overshoot), makes a period of
    1.64 s, above TOLERANCES S18's bound 2π √(I_h / (F r_c cos φ + K)) = 0.72 s (the water's added
    inertia is about 4 times the flap's own)."""
    case = REPO / "cases" / "hingedflap2d" / "CaseHingedFlapSwing2D_Def.xml"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(tmp_path), "--dp", "0.02", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    s = HF.first_swing_period(str(tmp_path))
    print("S18 swing, dp 0.02: first half-swing to %.2f deg, period %.3f s against the bound %.3f s"
          % (s["turn_deg"], s["period"], s["period_bound"]))
    assert s["period"] > s["period_bound"]
    assert abs(s["turn_deg"]) < abs(s["phi0_deg"])

"""S19: a dam break through a lifted gate against a flexible plate (Liao et al. 2015;
cases/flexobstacle2d/CaseFlexibleObstacle2D_Def.xml, DualSPHysics's chrono/13_FlexibleObstacle set-up):
the plate is ten rigid trunks on Chrono link_hinge joints with torsional springs EI/Δ.

Fast: the case's hinge chain against beam theory (tip compliance and first mode), and the multibody
solver's dry chain against the chain's own linearised modes. Slow: the coupled run at dp 0.002
against the experiment's Marker 1 record (sphdvi.validation.flexobstacle)."""
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.dvi.runner import run_bodies
from sphdvi.mechanism import mechanism_from_case
from sphdvi.validation import flexobstacle as FO
from sphdvi.validation.runs import case_data

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "flexobstacle2d" / "CaseFlexibleObstacle2D_Def.xml"
REF = REPO.parent / "shared" / "reference"

E, RHO, THICK, LENGTH, TRUNKS = 4.67e6, 1114.0, 0.004, 0.09, 10      # the case file's plate
EI = E * THICK ** 3 / 12


@pytest.fixture(scope="module")
def chain_case(tmp_path_factory):
    """The gencase output of the case at dp 0.001 (DualSPHysics's resolution: each trunk 9 rows
    of 4 particles) and its multibody inputs."""
    out = tmp_path_factory.mktemp("flex")
    r = CliRunner().invoke(main, ["gencase", str(CASE), "-o", str(out), "--dp", "0.001", "-q"])
    assert r.exit_code == 0, r.output
    return out, mechanism_from_case(case_data(str(out)))


def test_the_hinge_chain_is_the_cantilever_of_beam_theory(chain_case):
    """The chain as the case file builds it: trunks of Δ = L/N between hinges at their joints (the
    clamp at the floor's surface, z = −dp/2, with 2EI/Δ), the plate L tall. Under a tip load its
    deflection is Σ P (L − z_i)²/k_i = P Δ³/EI (N²/2 + (N − 1) N (2N − 1)/6): for N = 10, 335/333.3
    of the beam's P L³/(3EI), +0.50 %. Its first mode without gravity is −0.49 % off the
    Euler-Bernoulli cantilever's 1.8751² √(EI/(μL⁴)) = 5.17 Hz (μ the trunks' mass per length; their
    inertia comes from the particles, as DualSPHysics takes it). The plate stands upright, so its own
    weight, 16 % of the buckling load 7.84 EI/L², lowers that mode to 4.70 Hz (−8.5 %)."""
    _, mech = chain_case
    chain = FO.chain_model(mech)
    assert len(chain["names"]) == TRUNKS
    assert chain["top"] - chain["zh"][0] == pytest.approx(LENGTH, abs=1e-12)
    n = TRUNKS
    exact = (n * n / 2 + (n - 1) * n * (2 * n - 1) / 6) / (n ** 3 / 3)
    assert FO.chain_tip_compliance(chain) / (LENGTH ** 3 / (3 * EI)) == pytest.approx(exact, rel=1e-9)
    assert exact - 1 == pytest.approx(0.005, abs=1e-12)
    mu = float(np.sum(chain["mass"])) / LENGTH
    assert mu == pytest.approx(RHO * THICK, rel=1e-12)
    w_dry, _ = FO.chain_modes(chain, gravity=False)
    beam = FO.beam_first_mode(EI, mu, LENGTH)
    assert beam / (2 * math.pi) == pytest.approx(5.165, abs=1e-3)
    assert w_dry[0] / beam - 1 == pytest.approx(-0.0049, abs=0.0005)      # the chain of 10 trunks
    w, _ = FO.chain_modes(chain)
    assert w[0] / (2 * math.pi) == pytest.approx(4.70, abs=0.005)
    q_ratio = mu * LENGTH * 9.81 / (7.837 * EI / LENGTH ** 2)
    assert q_ratio == pytest.approx(0.163, abs=0.002)
    # the upright weight: ω² falls about in proportion to q/q_cr (Rayleigh, first mode)
    assert (w[0] / w_dry[0]) ** 2 == pytest.approx(1 - q_ratio, abs=0.02)


def test_the_multibody_chain_swings_in_its_linear_first_mode(chain_case):
    """The case's ten trunks and hinges in the multibody solver, no water, gravity on, started at
    the upright pose with the velocities of the linearised chain's first mode (a tip speed of
    0.1 mm/s): the top trunk swings at that mode's period and amplitude (measured at dt 1e-5, the
    coupled run's step: period and amplitude within 1e-8). A spring acting on the wrong trunk, a
    hinge off its point or the trunks' inertia misread shifts the period by percents."""
    _, mech = chain_case
    chain = FO.chain_model(mech)
    w, modes = FO.chain_modes(chain)
    _, _, A = FO._chain_matrices(chain)
    theta_dot = 1e-4 / float((A @ modes[:, 0])[-1]) * modes[:, 0]     # top centre at 0.1 mm/s
    vx = A @ theta_dot
    bodies = [dict(b) for b in mech["bodies"]]
    where = {b["name"]: i for i, b in enumerate(bodies)}
    for j, name in enumerate(chain["names"]):
        bodies[where[name]].update(vel=[float(vx[j]), 0.0, 0.0], omega=[0.0, float(theta_dot[j]), 0.0])
    period, dt = 2 * math.pi / w[0], 1e-5
    h = run_bodies(bodies, mech["links"], tmax=1.3 * period, tout=dt, dt=dt, materials=mech["materials"],
                   **mech["system"])
    top = where[chain["names"][-1]]
    t, x = h.time, h.pos[:, top, 0] - h.pos[0, top, 0]
    down = np.flatnonzero((x[:-1] > 0) & (x[1:] <= 0))                 # half a period, then one and a half
    crossings = [t[k] + x[k] * (t[k + 1] - t[k]) / (x[k] - x[k + 1]) for k in down]
    assert len(crossings) == 1
    assert crossings[0] == pytest.approx(0.5 * period, rel=1e-5)
    assert float(x.max()) == pytest.approx(float(vx[-1]) / w[0], rel=1e-5)
    assert float(-x.min()) == pytest.approx(float(vx[-1]) / w[0], rel=1e-5)


def test_the_marker_rides_on_the_top_trunk(chain_case):
    """Marker 1 starts on the plate's centre line 2.5 mm below its top (the top of its particles'
    volume, L above the floor's surface at dp 0.001), and eq. (1) moves it with the top trunk: a
    trunk turned by θ about its centre moves the marker by (z_m − z_c) sin θ."""
    out, _ = chain_case
    geo = FO.plate_geometry(str(out))
    assert geo["p0"][2] == pytest.approx(LENGTH - 0.0005 - 0.0025, abs=1e-12)
    assert geo["height"] == pytest.approx(LENGTH, abs=1e-12)
    theta = 0.1
    q = np.array([[math.cos(theta / 2), 0.0, math.sin(theta / 2), 0.0]])
    arm = geo["p0"] - geo["c0"]
    from sphdvi.dvi._math import np_quat_to_mat
    moved = np_quat_to_mat(q[0]) @ arm
    assert moved[0] == pytest.approx(arm[2] * math.sin(theta), abs=1e-15)


def test_the_scoring_reads_the_references_and_scores_one_against_another():
    """The three records as read (the experiment peaks at 0.063 m at t = 0.70 s; DualSPHysics's run
    0.055 m at 0.33 s), and :func:`compare` of DualSPHysics's run against the experiment: its
    deflection under the running water (t = 0.35-0.70 s) is 14 % low, its largest 12 % low, it arrives
    (d = 1 cm) 0.009 s early, and over t = 0.25-0.75 s it is off by 16 % of the measured peak (rms),
    correlation 0.89 (the records on a uniform 1 ms grid). Sun et al.'s (2019) SPH: 17 % and 9 % low,
    0.008 s early, rms 14 %, correlation 0.95."""
    if not (REF / FO.REFERENCE_FOLDER).is_dir():
        pytest.skip("reference data not found")
    t, d = FO.reference_series(str(REF))
    assert d.max() == pytest.approx(0.0627, abs=1e-4) and t[np.argmax(d)] == pytest.approx(0.697, abs=1e-3)
    td, dd = FO.reference_series(str(REF), "DualSPHysics_Chrono")
    assert dd.max() == pytest.approx(0.0550, abs=1e-4)
    e = FO.compare(td, dd, t, d)
    assert e["plateau"] == pytest.approx(-0.14, abs=0.01)
    assert e["peak"] == pytest.approx(-0.12, abs=0.01)
    assert e["arrival"] == pytest.approx(-0.009, abs=0.001)
    assert e["rms"] == pytest.approx(0.16, abs=0.01) and e["corr"] == pytest.approx(0.89, abs=0.01)
    ts, ds = FO.reference_series(str(REF), "SPH_Sun2019")
    sun = FO.compare(ts, ds, t, d)
    assert sun["plateau"] == pytest.approx(-0.17, abs=0.01) and sun["peak"] == pytest.approx(-0.09, abs=0.01)
    assert sun["arrival"] == pytest.approx(-0.008, abs=0.001)
    assert sun["rms"] == pytest.approx(0.14, abs=0.01) and sun["corr"] == pytest.approx(0.95, abs=0.01)
    same = FO.compare(t, d, t, d)
    assert same["plateau"] == same["peak"] == same["rms"] == same["arrival"] == 0.0


@pytest.mark.slow
def test_the_coupled_plate_deflects_as_measured_at_dp_0_002(tmp_path):
    """The coupled run at dp 0.002 (13,595 particles, ~90,000 steps, ~10 min on 2 threads) against
    the experiment; figures in README (S19)."""
    if not (REF / FO.REFERENCE_FOLDER).is_dir():
        pytest.skip("reference data not found")
    out = tmp_path / "dp0.002"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", "0.002", "--threads", "2", "-q",
                                  "--tmax", str(FO.WINDOW[1] + 0.01)])
    assert r.exit_code == 0, r.output
    e = FO.case_errors(str(out), str(REF))
    print({k: round(v, 4) if isinstance(v, float) else v for k, v in e.items()})
    assert abs(e["plateau"]) <= 0.20
    assert abs(e["arrival"]) <= 0.02

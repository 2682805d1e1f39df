"""A <floating>'s imposed velocity (<linearvel>/<angularvel>, 'none' = free) and external
loads (<linearforce>/<angularforce>) reach the multibody engine, linearly interpolated in
time (the DualSPHysics chrono/12_ExternalVelocity examples; they were read and dropped)."""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
PENDULUM = (REPO / "cases" / "pendulum" / "CasePendulum_Def.xml").read_text()
HINGE = PENDULUM[PENDULUM.index("<link_hinge"):PENDULUM.index("</link_hinge>") + len("</link_hinge>")]


def run_box(tmp_path, drivers, tmax=0.5):
    """The pendulum case's 10 kg box, unhinged, with ``drivers`` in its <floating>; the
    rows of bodies.csv as (time, x, z, vx, vz, wy)."""
    text = PENDULUM.replace(HINGE, "").replace("</floating>", drivers + "</floating>")
    case = tmp_path / "CaseBox_Def.xml"
    case.write_text(text)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "-q", "--tmax", str(tmax), "--tout", "0.05"])
    assert r.exit_code == 0, r.output
    rows = [ln.split(",") for ln in (out / "bodies.csv").read_text().splitlines()[1:]]
    head = (out / "bodies.csv").read_text().splitlines()[0].split(",")
    cols = [head.index(c) for c in ("time", "x", "z", "vx", "vz", "wy")]
    return np.array([[float(r[c]) for c in cols] for r in rows])


def test_imposed_linear_velocity_with_a_free_component(tmp_path):
    """vx = 2t and vz = 1 imposed (against gravity), vy free: x = x0 + t², z = z0 + t."""
    drivers = ('<linearvel><vel time="0" x="0" y="none" z="1"/><vel time="1" x="2" y="none" z="1"/></linearvel>')
    a = run_box(tmp_path, drivers)
    t, x, z, vx, vz = a[:, 0], a[:, 1], a[:, 2], a[:, 3], a[:, 4]
    later = t > 0
    assert np.allclose(vx[later], 2 * t[later], atol=2e-3) and np.allclose(vz[later], 1.0, atol=1e-9)
    assert np.allclose(x - x[0], t ** 2, atol=2e-3) and np.allclose(z - z[0], t, atol=2e-3)


def test_imposed_angular_velocity(tmp_path):
    drivers = '<angularvel><vel time="0" x="0" y="3" z="0"/><vel time="1" x="0" y="3" z="0"/></angularvel>'
    a = run_box(tmp_path, drivers, tmax=0.2)
    assert np.allclose(a[1:, 5], 3.0, atol=1e-9)


def test_external_force_table(tmp_path):
    """10 kg, F = (10, 0, 98.1) N against g = 9.81: a = (1, 0, 0), from vx0 = -0.1 m/s."""
    drivers = ('<linearforce><force time="0" x="10" y="0" z="98.1"/><force time="2" x="10" y="0" z="98.1"/>'
               '</linearforce>')
    a = run_box(tmp_path, drivers)
    t, x, z, vx = a[:, 0], a[:, 1], a[:, 2], a[:, 3]
    assert np.allclose(vx, -0.1 + t, atol=1e-6)
    assert np.allclose(x - x[0], -0.1 * t + 0.5 * t ** 2, atol=1e-3)
    assert np.allclose(z, z[0], atol=1e-9)


FLOATING_BOX = (REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml").read_text()


@pytest.mark.parametrize("algo", [1, 2])
def test_initial_velocity_in_an_sph_run_flies_ballistic(tmp_path, algo):
    """DualSPHysics issue #74 (a floating body with an initial velocity moves wrongly, Verlet
    against Symplectic): the S12 box lifted into the air with <linearvelini> (0.5, 0, 2) m/s and
    <angularvelini> 3 rad/s about y, through the SPH time loop and either integrator: x = x0 +
    0.5 t exactly, the pitch 3t exactly, z = z0 + 2t − g t²/2 within the first-order offset of
    the body solver's semi-implicit Euler step (g t dt)."""
    text = FLOATING_BOX.replace('<pointmax x="1.1" y="0" z="1" />', '<pointmax x="1.1" y="0" z="2" />')
    text = text.replace('<point x="0.4" y="-1" z="0.2500001" /><size x="0.2" y="2" z="0.1" />',
                        '<point x="0.4" y="-1" z="0.7500001" /><size x="0.2" y="2" z="0.1" />')
    text = text.replace('<floating mkbound="5" rhopbody="500" />',
                        '<floating mkbound="5" rhopbody="500"><linearvelini x="0.5" y="0" z="2" />'
                        '<angularvelini x="0" y="3" z="0" /></floating>')
    # the flight reaches z ~ 1.1: the domain must hold it (a floating particle out of it stops the run)
    text = text.replace("</parameters>", '<simulationdomain><posmin x="default" y="default" z="default" />'
                        '<posmax x="default" y="default" z="2" /></simulationdomain></parameters>')
    assert text.count('z="0.7500001"') == 2 and "linearvelini" in text and "simulationdomain" in text
    case = tmp_path / "CaseBallistic_Def.xml"
    case.write_text(text)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "-q", "--dp", "0.02", "--tmax", "0.3",
                                  "--tout", "0.05", "--threads", "1", "--set", "FtPause=0",
                                  "--set", f"StepAlgorithm={algo}"])
    assert r.exit_code == 0, r.output
    d = np.genfromtxt(out / "bodies.csv", delimiter=",", names=True)
    dtmax = max(float(ln.split(",")[6]) for ln in (out / "run.csv").read_text().splitlines()[1:])
    t = d["time"]
    assert len(t) == 7 and t[-1] >= 0.3
    # exact to the 9 digits bodies.csv prints
    assert np.abs(d["x"] - d["x"][0] - 0.5 * t).max() < 1e-8
    assert np.abs(d["pitch"] - np.degrees(3.0 * t)).max() < 1e-5
    assert np.allclose(d["vx"], 0.5) and np.allclose(d["wy"], 3.0)
    z_exact = d["z"][0] + 2.0 * t - 0.5 * 9.81 * t ** 2
    assert np.abs(d["z"] - z_exact).max() <= 9.81 * t[-1] * dtmax
    assert np.abs(d["vz"] - (2.0 - 9.81 * t)).max() < 1e-8


def test_initial_velocity_along_a_locked_dof_is_ignored_with_a_warning(tmp_path):
    """translationDOF x=0 with <linearvelini x=0.5>: the body's velocity is masked by its DOF
    (System.add_body), and now its particles' too, so that the first step does not push the
    water at 0.5 m/s (a pressure pulse that tilted the symmetric box by 3 degrees); gencase
    warns that the velocity along the locked DOF is ignored.  The free components stay: vz
    and the spin about y give the particles v = (0, 0, 0.2) + w x (r - c)."""
    from sphdvi.io.casefile import read_case_h5
    text = FLOATING_BOX.replace('<floating mkbound="5" rhopbody="500" />',
                                '<floating mkbound="5" rhopbody="500"><translationDOF x="0" y="1" z="1"/>'
                                '<rotationDOF x="1" y="1" z="1"/><linearvelini x="0.5" y="0" z="0.2"/>'
                                '<angularvelini x="0" y="1.5" z="0"/></floating>')
    assert "translationDOF" in text
    case = tmp_path / "CaseDof_Def.xml"
    case.write_text(text)
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out"), "--dp", "0.02"])
    assert r.exit_code == 0, r.output
    assert "floating mkbound 5: the initial velocity along a locked degree of freedom is ignored" in r.output
    assert "linearvelini x=0.5" in r.output and "CaseDof_Def.xml:" in r.output
    data = read_case_h5(str(next((tmp_path / "out").glob("*.h5"))))
    p = data["particles"]
    sel = p["type"] == 2
    c = p["pos"][sel].mean(axis=0)          # the body's centre (no <center>)
    w = np.array([0.0, 1.5, 0.0])
    expected = np.array([0.0, 0.0, 0.2]) + np.cross(w, p["pos"][sel] - c)
    assert np.allclose(p["vel"][sel], expected, atol=1e-12)
    assert not p["vel"][p["type"] != 2].any()

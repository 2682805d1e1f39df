"""A <floating>'s imposed velocity (<linearvel>/<angularvel>, 'none' = free) and external
loads (<linearforce>/<angularforce>) reach the multibody engine, linearly interpolated in
time (the DualSPHysics chrono/12_ExternalVelocity examples; they were read and dropped)."""
from pathlib import Path

import numpy as np
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

"""sphdvi measure bodies: from bodies.csv/links.csv, and from floating-particle snapshots."""
import csv
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from click.testing import CliRunner

from _tank import lattice
from sphdvi.cli import main
from sphdvi.io.casefile import write_case_h5
from sphdvi.io.vtkhdf import VTKHDFParticleWriter
from sphdvi.measure.post import measure_bodies, rotation_to_euler_deg
from sphdvi.measure.tables import read_table
from sphdvi.simulation import POINT_ARRAYS

PENDULUM = (Path(__file__).resolve().parents[2] / "cases" / "pendulum" / "CasePendulum_Def.xml").read_text()


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def rot(roll, pitch, yaw):
    """R = Rz(yaw) Ry(pitch) Rx(roll) (angles in degrees)."""
    r, p, y = np.radians([roll, pitch, yaw])
    rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def test_euler_convention():
    np.testing.assert_allclose(rotation_to_euler_deg(rot(3.0, -5.0, 10.0)), [3.0, -5.0, 10.0], atol=1e-12)


def test_bodies_from_snapshots(tmp_path):
    """A rigid floating box moved by a known rotation + translation: centre, motion, angles
    and velocities recovered to round-off (float32 velocities in the file: 1e-6)."""
    dp = 0.05
    box = lattice(np.array([0.0, 0.0, 0.0]), np.array([0.4, 0.3, 0.2]), dp, False)
    c0 = box.mean(axis=0) + np.array([0.01, 0.0, 0.0])       # body centre need not be the particle mean
    n = box.shape[0]
    mk = 12
    parts = {"pos": box, "vel": np.zeros((n, 3)), "rhop": np.full(n, 1000.0), "mass": np.full(n, 0.1),
             "type": np.full(n, 2, np.uint8), "mk": np.full(n, mk, np.int32), "idp": np.arange(n, dtype=np.int64)}
    body = SimpleNamespace(mkbound=10, mk=mk, begin=0, count=n, mass=0.1 * n, masspart=0.1, center=c0.tolist(),
                           inertia=np.eye(3).tolist(), translation_dof=[1, 1, 1], rotation_dof=[1, 1, 1],
                           linearvelini=[0, 0, 0], angularvelini=[0, 0, 0])
    consts = {"dp": dp, "h": 1.2 * dp, "b": 1e5, "cs0": 10.0, "rhop0": 1000.0, "gamma": 7.0,
              "gravity": [0, 0, -9.81], "massfluid": 0.125, "massbound": 0.125, "is2d": False, "posy2d": 0.0}
    out = tmp_path / "run"
    out.mkdir()
    write_case_h5(str(out / "Body.h5"), casename="Body", source_file="x", source_xml="<case/>", version="t",
                  particles=parts, constants=consts, parameters={"Kernel": 2, "TimeOut": 0.1},
                  domain={"posmin": [-1, -1, -1], "posmax": [1, 1, 1]}, bodies=[body],
                  json_items={"mkconfig": {"fluidcount": 1},
                              "bodies_extra": [{"mkbound": 10, "mass": 0.1 * n, "inertia": np.eye(3).tolist(),
                                                "center": c0.tolist(), "linearvelini": [0, 0, 0],
                                                "angularvelini": [0, 0, 0], "translation_dof": [1, 1, 1],
                                                "rotation_dof": [1, 1, 1]}]})
    w = VTKHDFParticleWriter(str(out / "particles.vtkhdf"), POINT_ARRAYS)
    motions = [((0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0)),
               ((3.0, -5.0, 10.0), (0.1, -0.2, 0.3), (0.5, 0.0, -0.2), (0.1, 0.2, -0.3)),
               ((-20.0, 30.0, 45.0), (1.0, 2.0, -0.5), (0.0, 1.0, 0.0), (1.0, 0.0, 0.5))]
    rng = np.random.default_rng(0)
    order = rng.permutation(n)                                  # file order is not idp order
    for k, (ang, disp, v, w_) in enumerate(motions):
        R = rot(*ang)
        c = c0 + np.asarray(disp)
        pos = c + (box - c0) @ R.T
        vel = np.asarray(v) + np.cross(np.asarray(w_), pos - c)
        w.append(0.1 * k, pos[order], {"Idp": parts["idp"][order], "Vel": vel[order], "Rhop": parts["rhop"],
                                        "Press": np.zeros(n), "Type": parts["type"], "Mk": parts["mk"]})
    w.close()
    t = measure_bodies(str(out))
    assert t.time.tolist() == [0.0, 0.1, 0.2]
    for k, (ang, disp, v, w_) in enumerate(motions):
        col = lambda name: t.column(f"mkbound10_{name}")[k]  # noqa: E731
        np.testing.assert_allclose([col("cx"), col("cy"), col("cz")], c0 + np.asarray(disp), atol=1e-12)
        np.testing.assert_allclose([col("surge"), col("sway"), col("heave")], disp, atol=1e-12)
        np.testing.assert_allclose([col("roll"), col("pitch"), col("yaw")], ang, atol=1e-9)
        np.testing.assert_allclose([col("vx"), col("vy"), col("vz")], v, atol=1e-6)
        np.testing.assert_allclose([col("wx"), col("wy"), col("wz")], w_, atol=1e-6)
        np.testing.assert_allclose([col("ffx"), col("ffy"), col("ffz")], 0.0)     # no fluid
        assert np.isnan(col("cfx"))                            # not in the snapshots (no bodies.csv here)
    r = invoke("measure", "bodies", out, "--sep", ";")
    assert r.exit_code == 0 and "mkbound10_heave [m]" in r.stdout

    # an SPH run with bodies also wrote bodies.csv / links.csv (at its outputs and, with
    # TimeOutExtra, in between): the contact and link forces come from there
    head = ("time,body,x,y,z,qw,qx,qy,qz,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz,"
            "cfx,cfy,cfz,ctx,cty,ctz")
    lines, links = [head], ["time,link,fx,fy,fz,tx,ty,tz"]
    for k, tt in enumerate((0.0, 0.05, 0.1, 0.2)):
        lines.append(f"{tt:.9g},floating10," + ",".join(["0"] * 22) + "," +
                     ",".join(f"{k + 0.1 * j:.9g}" for j in range(6)))
        links.append(f"{tt:.9g},spring1," + ",".join(f"{-k - 0.5 * j:.9g}" for j in range(6)))
    (out / "bodies.csv").write_text("\n".join(lines) + "\n")
    (out / "links.csv").write_text("\n".join(links) + "\n")
    t2 = measure_bodies(str(out))
    assert t2.time.tolist() == [0.0, 0.1, 0.2]
    np.testing.assert_array_equal(t2.data[:, :t.data.shape[1] - 6], t.data[:, :t.data.shape[1] - 6])
    for k, logged in enumerate((0, 2, 3)):                          # rows of t = 0, 0.1, 0.2
        np.testing.assert_allclose([t2.column(f"mkbound10_{c}")[k] for c in ("cfx", "cfy", "cfz", "ctx", "cty", "ctz")],
                                   logged + 0.1 * np.arange(6))
        np.testing.assert_allclose([t2.column(f"spring1_{c}")[k] for c in ("fx", "fy", "fz", "tx", "ty", "tz")],
                                   -logged - 0.5 * np.arange(6))


def test_bodies_from_csv(tmp_path):
    case = tmp_path / "Pend_Def.xml"
    case.write_text(PENDULUM)
    out = tmp_path / "out"
    r = invoke("run", case, "-o", out, "--tmax", "0.05", "-q")
    assert r.exit_code == 0, r.output
    t = measure_bodies(str(out))
    with open(out / "bodies.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert t.time.shape[0] == len(rows)
    x = np.array([float(r["x"]) for r in rows])
    np.testing.assert_allclose(t.column("pend_cx"), x)
    np.testing.assert_allclose(t.column("pend_surge"), x - x[0])
    np.testing.assert_allclose(t.column("pend_pitch"), [float(r["pitch"]) for r in rows])
    assert any(n.endswith("_fx") and not n.startswith("pend") for n in t.names)       # the hinge's force
    link_fz = [n for n in t.names if n.endswith("_fz") and not n.startswith("pend")][0]
    assert np.abs(t.column(link_fz)).max() > 1.0                                      # carries the weight
    r = invoke("measure", "bodies", out, "--csv", tmp_path / "b.csv")
    assert r.exit_code == 0, r.output
    back = read_table(str(tmp_path / "b.csv"))
    assert back.names == t.names

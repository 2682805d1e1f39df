"""Body-only case files (a DualSPHysics <chrono> section and no fluid) run through
`sphdvi run CASE.xml -o OUT` and write bodies.csv / links.csv."""
import csv
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5

PENDULUM = (Path(__file__).resolve().parents[2] / "cases" / "pendulum" / "CasePendulum_Def.xml").read_text()


def read_rows(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


def test_pendulum_case_period(tmp_path):
    case = tmp_path / "CasePendulum_Def.xml"
    case.write_text(PENDULUM)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "-q"])
    assert r.exit_code == 0, r.output
    rows = read_rows(out / "bodies.csv")
    header = open(out / "bodies.csv").readline().strip()
    assert header == ("time,body,x,y,z,qw,qx,qy,qz,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,"
                      "fx,fy,fz,tx,ty,tz,cfx,cfy,cfz,ctx,cty,ctz")
    assert open(out / "links.csv").readline().strip() == "time,link,fx,fy,fz,tx,ty,tz"
    t = np.array([float(x["time"]) for x in rows])
    x = np.array([float(x["x"]) for x in rows])
    z = np.array([float(x["z"]) for x in rows])
    assert np.allclose(np.hypot(x, z), 1.0, atol=1e-4)        # the hinge holds
    data = read_case_h5(str(next(out.glob("*.h5"))))
    m = float(data["bodies"]["mass"][0])
    iyy = float(data["bodies"]["inertia"][0][1, 1])
    t0 = 2 * math.pi * math.sqrt((iyy + m * 1.0) / (m * 9.81 * 1.0))
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    period = np.mean(np.diff(crossings))
    assert period == pytest.approx(t0, rel=5e-3)
    links = read_rows(out / "links.csv")
    fz = np.array([float(r["fz"]) for r in links])
    assert np.median(np.abs(fz)) == pytest.approx(m * 9.81, rel=0.02)

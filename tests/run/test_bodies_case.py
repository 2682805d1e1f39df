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
                      "fx,fy,fz,tx,ty,tz,cfx,cfy,cfz,ctx,cty,ctz,ffx,ffy,ffz,ftx,fty,ftz")
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


def test_pendulum_timeoutextra_rows_between_outputs(tmp_path):
    """TimeOutExtra in a body-only run: rows at its multiples between the outputs (and the
    output rows unchanged); 0 gives a row every step."""
    case = tmp_path / "CasePendulum_Def.xml"
    case.write_text(PENDULUM)
    runs = {}
    for name, sets in (("plain", []), ("extra", ["--set", "TimeOutExtra=0.01"]),
                       ("every", ["--set", "TimeOutExtra=0", "--set", "DtFixed=0.002"])):
        out = tmp_path / name
        r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "-q", "--tmax", "0.2",
                                      "--tout", "0.05"] + sets)
        assert r.exit_code == 0, r.output
        runs[name] = read_rows(out / "bodies.csv")
    t_plain = [float(r["time"]) for r in runs["plain"]]
    t_extra = np.array([float(r["time"]) for r in runs["extra"]])
    assert np.allclose(t_plain, np.arange(5) * 0.05)
    assert np.allclose(t_extra, np.arange(21) * 0.01)
    for r in runs["plain"]:
        same = [x for x in runs["extra"] if math.isclose(float(x["time"]), float(r["time"]), abs_tol=1e-9)]
        assert same == [r]
    assert np.allclose([float(r["time"]) for r in runs["every"]], np.arange(101) * 0.002)

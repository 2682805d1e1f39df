"""Body-only case files (a DualSPHysics <chrono> section and no fluid) run through
`sphdvi run CASE.xml -o OUT` and write bodies.csv / links.csv."""
import csv
import math

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5

PENDULUM = """<?xml version="1.0" encoding="UTF-8" ?>
<!-- A 0.2 m cube hinged 1 m above its centre: a compound pendulum (no fluid). -->
<case>
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <coefh value="1.0" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.05">
                <pointmin x="-2" y="-1" z="-2" />
                <pointmax x="2" y="1" z="1" />
            </definition>
            <commands>
                <mainlist>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.1" y="-0.1" z="-1.1" /><size x="0.2" y="0.2" z="0.2" /></drawbox>
                </mainlist>
            </commands>
        </geometry>
        <floatings>
            <floating mkbound="1">
                <massbody value="10" />
                <linearvelini x="-0.1" y="0" z="0" />
                <angularvelini x="0" y="0.1" z="0" />
            </floating>
        </floatings>
    </casedef>
    <execution>
        <special>
            <chrono>
                <bodyfloating id="pend" mkbound="1" />
                <link_hinge idbody1="pend">
                    <rotpoint x="0" y="0" z="0" />
                    <rotvector x="0" y="1" z="0" />
                </link_hinge>
            </chrono>
        </special>
        <parameters>
            <parameter key="RigidAlgorithm" value="3" />
            <parameter key="DtFixed" value="0.001" />
            <parameter key="TimeMax" value="4.5" />
            <parameter key="TimeOut" value="0.005" />
        </parameters>
    </execution>
</case>
"""


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

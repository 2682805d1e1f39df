"""Floating bodies against the tank's walls without <chrono> (hunt6/d findings 1 and 2).

RigidAlgorithm 1 (DualSPHysics's FtMode Sph, the default): a floating particle takes the
pressure and viscosity terms from fixed and moving wall particles and from other bodies'
particles (JSphCpu::InteractionForcesFluid), the DBC repulsion that is the body's only
contact with the walls; with 0 (collision-free) it sees the fluid only.  A floating body
whose particles leave the simulation domain stops the run as DualSPHysics's JSph::AbortBoundOut
("Fixed, moving or floating particles were excluded"), exit 3.
"""
import json

import numpy as np
from click.testing import CliRunner

from sphdvi.cli import main

DP = 0.02
# 2D tank 0.6 m wide with one layer of wall particles (the floor at z = 0), water 0.2 m deep,
# a box 0.12 x 0.08 m of density 2000 released in the water (the auditor's sink.xml)
TANK = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <coefsound value="20" />
            <coefh value="1.0" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.02">
                <pointmin x="-0.1" y="0" z="-0.1" />
                <pointmax x="0.7" y="0" z="0.5" />
            </definition>
            <commands>
                <mainlist>
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" />
                        <size x="WX" y="2" z="WZ" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" />
                        <size x="0.6" y="2" z="0.4" /></drawbox>
                    <setmkbound mk="5" />
                    <drawbox><boxfill>solid</boxfill><point x="BX" y="-1" z="BZ" />
                        <size x="0.12" y="2" z="0.08" /></drawbox>
                </mainlist>
            </commands>
        </geometry>
        <floatings>
            <floating mkbound="5" rhopbody="2000" />
        </floatings>
    </casedef>
    <execution>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.05" />
            <parameter key="DensityDT" value="2" />
            <parameter key="TimeMax" value="1.5" />
            <parameter key="TimeOut" value="0.05" />
        </parameters>
    </execution>
</case>
"""


def run_tank(tmp_path, name, water, box, rigid, tmax):
    """Run the tank with water (width, depth) and the box's lower-left corner ``box``; the
    CLI result, the out folder and bodies.csv as a structured array."""
    text = TANK.replace("WX", str(water[0])).replace("WZ", str(water[1]))
    text = text.replace("BX", str(box[0])).replace("BZ", str(box[1]))
    case = tmp_path / f"{name}.xml"
    case.write_text(text)
    out = tmp_path / f"out_{name}"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "-q", "--threads", "1", "--tmax", str(tmax),
                                  "--set", f"RigidAlgorithm={rigid}"])
    return r, out, np.genfromtxt(out / "bodies.csv", delimiter=",", names=True)


def test_heavy_box_comes_to_rest_on_the_floor(tmp_path):
    """RigidAlgorithm 1: the box (its bottom row 0.04 m below its centre) sinks, lands on the
    one-layer floor and stays there, its bottom row 1-2 dp above the floor particles (the DBC
    gap); before, it passed through the floor at t ~ 0.9 s and fell on at g."""
    r, out, d = run_tank(tmp_path, "sink", (0.6, 0.2), (0.24, 0.1), 1, 1.2)
    assert r.exit_code == 0, r.output
    bottom = d["z"] - 0.04
    assert bottom.min() > 0.5 * DP                      # never through the floor
    late = d["time"] >= 0.9
    assert np.all((bottom[late] > 1.0 * DP) & (bottom[late] < 2.5 * DP))
    assert np.abs(d["vz"][late]).max() < 0.05           # at rest
    assert np.ptp(bottom[late]) < 0.25 * DP


def test_without_contact_the_box_leaves_the_domain_and_the_run_stops(tmp_path):
    """A box dropped through the air onto the floor (the water elsewhere in the tank): with
    RigidAlgorithm 1 the floor holds it; with 0 (collision-free) it falls through, and when its
    particles leave the domain the run stops with exit 3 and a message naming the body, the
    time and the position, its outputs so far kept."""
    r, out, d = run_tank(tmp_path, "drop1", (0.2, 0.06), (0.4, 0.06), 1, 0.3)
    assert r.exit_code == 0, r.output
    assert (d["z"] - 0.04).min() > 0.5 * DP
    r, out, d = run_tank(tmp_path, "drop0", (0.2, 0.06), (0.4, 0.06), 0, 0.3)
    assert r.exit_code == 3, r.output
    for text in ("floating body mkbound 5", "left the simulation domain", "t=0.1", "its particle",
                 "Fixed, moving or floating particles were excluded"):
        assert text in r.output, (text, r.output)
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "diverged" and "mkbound 5" in info["message"]
    assert 0.1 < info["physical_time"] < 0.15
    assert d["time"][-1] >= 0.1 and (out / "particles.vtkhdf").exists()

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
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main

DP = 0.02


def tank_case(water, box):
    """2D tank 0.6 m wide with one layer of wall particles (the floor at z = 0), water (width,
    depth) in its left corner and a box 0.12 x 0.08 m of density 2000 with its lower-left corner
    at ``box`` (the auditor's sink.xml: water (0.6, 0.2), the box released in it)."""
    return case_xml(pointmin=("-0.1", "0", "-0.1"), pointmax=("0.7", "0", "0.5"), commands=f"""
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" />
                        <size x="{water[0]}" y="2" z="{water[1]}" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" />
                        <size x="0.6" y="2" z="0.4" /></drawbox>
                    <setmkbound mk="5" />
                    <drawbox><boxfill>solid</boxfill><point x="{box[0]}" y="-1" z="{box[1]}" />
                        <size x="0.12" y="2" z="0.08" /></drawbox>""",
                    casedef_extra='\n        <floatings><floating mkbound="5" rhopbody="2000" /></floatings>',
                    parameters='<parameter key="StepAlgorithm" value="2" /><parameter key="Visco" value="0.05" />'
                               '<parameter key="DensityDT" value="2" /><parameter key="TimeMax" value="1.5" />'
                               '<parameter key="TimeOut" value="0.05" />')


def run_tank(tmp_path, name, water, box, rigid, tmax):
    """Run ``tank_case(water, box)``; the CLI result, the out folder and bodies.csv as a
    structured array."""
    case = write_case(tmp_path, tank_case(water, box), f"{name}.xml")
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
    # its lowest particle centre (the box's centres span 0.12 x 0.08 m): the box may land tilted
    # (round-off decides how: 3 or 19 degrees as the domain's origin moved by 0.05 h)
    tilt = np.radians(d["pitch"])
    bottom = d["z"] - 0.06 * np.abs(np.sin(tilt)) - 0.04 * np.abs(np.cos(tilt))
    assert bottom.min() > 0.5 * DP                      # never through the floor
    late = d["time"] >= 0.9
    assert np.all((bottom[late] > 1.0 * DP) & (bottom[late] < 2.5 * DP))
    assert np.abs(d["vz"][late]).max() < 0.05           # at rest
    assert np.ptp(bottom[late]) < 0.25 * DP
    # bodies.csv's fluid load (ffx..ftz; under RigidAlgorithm 1 it holds the walls' terms too): the
    # total load less the weight, the body having no other load
    np.testing.assert_allclose(d["ffx"], d["fx"], rtol=1e-12, atol=1e-9)
    weight = d["fz"] - d["ffz"]
    assert np.ptp(weight) < 1e-8 * abs(weight[0]) and weight[0] < 0      # to the 9 printed digits
    assert d["ffz"][late].mean() == pytest.approx(-weight[0], rel=0.05)     # resting: the loads balance


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

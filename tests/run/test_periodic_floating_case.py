"""A floating box carried across the end of an x-periodic channel, from case files: its centre is
kept in the periodic box as DualSPHysics keeps it (FtUpdateFloatings: ``center =
UpdatePeriodicPos(fcenter)``, the centre bodies.csv and the floating outputs show) and its motion
is that of the same box launched half a period away; a <chrono> body with a collision shape that
crosses is refused (exit 2): DualSPHysics's Chrono integrates it without the periodic conditions."""
import csv

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main

# 2D channel x in [0, 1) (50 dp), 0.2 m of water flowing at 1 m/s; a 0.1 x 0.08 box (rhopbody 500)
# launched at 1 m/s with its centre at x = XB + 0.05
CASE = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><coefh value="1.0" /><coefsound value="20" /></constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.02"><pointmin x="0" y="0" z="-0.1" /><pointmax x="1" y="0" z="1" /></definition>
            <commands><mainlist>
                <setmkfluid mk="0" />
                <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0.02" /><size x="0.98" y="2" z="0.2" /></drawbox>
                <setmkbound mk="0" />
                <drawbox><boxfill>bottom</boxfill><point x="0" y="-1" z="0" /><size x="0.98" y="2" z="0.2" /></drawbox>
                <setmkbound mk="1" />
                <drawbox><boxfill>solid</boxfill><point x="XB" y="-1" z="0.16" /><size x="0.1" y="2" z="0.08" /></drawbox>
            </mainlist></commands>
        </geometry>
        <initials><velocity mkfluid="0" x="1.0" y="0" z="0" /></initials>
        <floatings><floating mkbound="1" rhopbody="500" property="steel"><velini x="1.0" y="0" z="0" /></floating></floatings>
        <properties><property name="steel" Kfric="0.3" Restitution_Coefficient="0.5" /><links><link mkbound="0" property="steel" /></links></properties>
    </casedef>
    <execution>
        <special>SPECIAL</special>
        <parameters>
            <parameter key="XPeriodicIncZ" value="0" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="RigidAlgorithm" value="RIGID" />
            <parameter key="Visco" value="0.01" />
            <parameter key="TimeMax" value="0.3" />
            <parameter key="TimeOut" value="0.01" />
            <simulationdomain><posmax z="default + 200%" /></simulationdomain>
        </parameters>
    </execution>
</case>
"""
CHRONO = ('<chrono><collision activate="true" /><bodyfloating id="box" mkbound="1" modelfile="AutoActual" />'
          '<bodyfixed id="floor" mkbound="0" modelfile="AutoActual" /></chrono>')


def _run(tmp_path, name, xb, special="", rigid="1"):
    case = tmp_path / f"{name}_Def.xml"
    case.write_text(CASE.replace("XB", xb).replace("SPECIAL", special).replace("RIGID", rigid))
    out = tmp_path / name
    return CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "-q"]), out


def _bodies(out):
    rows = list(csv.DictReader(open(out / "bodies.csv")))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0] if k != "body"}


def test_box_crossing_the_periodic_end(tmp_path):
    """The box starting at x = 0.85 crosses x = 1 at t ~ 0.15 s; the reference starts at 0.35 and
    stays inside. bodies.csv: the crossing box's centre is in [0, 1) throughout and equals the
    reference's + 0.5 modulo 1; its velocity, rotation and fluid loads equal the reference's, with
    no jump at the crossing. The fluid lattice is the same translated by 25 dp, so the runs differ by
    round-off only: measured, they agree to bodies.csv's 9 significant digits (x within 5e-10 m,
    the torque within 7e-13 N m of 0.08); asserted at 1e-7 m and 1e-5 of each column's largest."""
    r, out = _run(tmp_path, "cross", "0.80")
    assert r.exit_code == 0, r.output
    r, out_ref = _run(tmp_path, "ref", "0.30")
    assert r.exit_code == 0, r.output
    c, ref = _bodies(out), _bodies(out_ref)
    assert c["x"].min() >= 0.0 and c["x"].max() < 1.0                  # before: up to 1.15
    expect = ref["x"] + 0.5
    crossed = expect >= 1.0
    assert 5 < crossed.sum() < crossed.size - 5
    expect[crossed] -= 1.0
    np.testing.assert_allclose(c["x"], expect, rtol=0, atol=1e-7)
    np.testing.assert_allclose(c["z"], ref["z"], rtol=0, atol=1e-7)
    for k in ("vx", "vz", "wy", "pitch", "ffx", "ffz", "fty"):
        np.testing.assert_allclose(c[k], ref[k], rtol=0, atol=1e-5 * np.abs(ref[k]).max(), err_msg=k)
    assert np.abs(ref["wy"]).max() > 0.02 and np.abs(ref["fty"]).max() > 0.01        # it does turn


def test_colliding_chrono_body_crossing_is_refused(tmp_path):
    """The same box as a <chrono> body colliding (modelfile AutoActual) with the floor: DualSPHysics
    integrates it in Chrono, whose contacts know nothing of the periodic ends; at the crossing sphdvi
    stops with exit 2 naming the body (before: it ran on with contacts on the wrong image)."""
    r, _ = _run(tmp_path, "collide", "0.80", special=CHRONO, rigid="3")
    assert r.exit_code == 2, r.output
    assert "floating body mkbound 1 ('box') crossed the periodic boundary along x" in r.output
    assert "a collision shape" in r.output

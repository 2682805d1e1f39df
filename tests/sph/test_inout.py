"""Inlet/outlet zones (``<special><inout>``, :mod:`sphdvi.sph.inout`): exact solutions, the
extrapolation's order, the buffers' bookkeeping, resume."""
import math

import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.io.vtkhdf import read_step, step_times
from sphdvi.sph import inout as IO

NO_GRAVITY = """
        <constantsdef>
            <gravity x="0" y="0" z="0" />
            <rhop0 value="1000" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="15" auto="false" />
            <coefh value="1.2" />
            <cflnumber value="0.2" />
        </constantsdef>"""

SLAB = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.2" /></drawbox>
                    <setmkfluid mk="1" />
                    <drawbox><boxfill>left</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.2" /></drawbox>
                    <setmkfluid mk="2" />
                    <drawbox><boxfill>right</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.2" /></drawbox>"""

INLET = """
                <inoutzone>
                    <refilling value="{refill}" /><inputtreatment value="2" /><layers value="4" />
                    <zone2d><particles mkfluid="1" direction="right" /></zone2d>
                    <imposevelocity mode="0"><velocity v="{u}" /></imposevelocity>
                    <imposerhop mode="{rin}" />
                </inoutzone>"""
OUTLET = """
                <inoutzone>
                    <refilling value="0" /><inputtreatment value="1" /><layers value="4" />
                    <zone2d><particles mkfluid="2" direction="left" /></zone2d>
                    <imposevelocity mode="2" />
                    <imposerhop mode="{rout}" />
                </inoutzone>"""


def slab_case(tmp_path, *, u=1.0, rin=0, rout=2, refill=0, inout=None, tmax=0.2, extra_params="", name="CaseSlab",
              special_extra="", commands=SLAB):
    """A free slab of water 0.6 x 0.2 m (no walls, no gravity) moving at ``u`` along x between an
    inlet (its left face) and an outlet (its right face)."""
    zones = inout if inout is not None else INLET.format(u=u, rin=rin, refill=refill) + OUTLET.format(rout=rout)
    special = f"""
            <initialize><fluidvelocity mkfluid="0"><direction x="1" y="0" z="0" /><velocity v="{u}" />
            </fluidvelocity></initialize>
            <inout>{zones}
            </inout>{special_extra}"""
    params = (f'<parameter key="StepAlgorithm" value="2" /><parameter key="Visco" value="0.01" />'
              f'<parameter key="DensityDT" value="1" /><parameter key="TimeMax" value="{tmax}" />'
              f'<parameter key="TimeOut" value="{tmax / 2}" />{extra_params}'
              '<simulationdomain><posmin x="-0.2" y="default" z="-0.1" /><posmax x="0.8" y="default" z="0.3" />'
              '</simulationdomain>')
    text = case_xml(dp="0.02", pointmin=("-0.2", "0", "-0.1"), pointmax=("0.8", "0", "0.3"), constants=NO_GRAVITY,
                    commands=commands, special=special, parameters=params)
    return write_case(tmp_path, text, f"{name}_Def.xml")


def run(case, out, *args):
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "--quiet", *args])
    return r


def last_step(out):
    times = step_times(str(out / "particles.vtkhdf"))
    return read_step(str(out / "particles.vtkhdf"), len(times) - 1)


def test_a_slab_moves_exactly_through_an_inlet_and_an_outlet(tmp_path):
    """Uniform translation is an exact solution (no pressure, no relative velocity): the buffers
    must keep it to round-off: every fluid velocity U, every density rho0, the particle count
    constant, as many particles created at the inlet as removed at the outlet, U T / dp columns."""
    case = slab_case(tmp_path)
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    first = read_step(str(out / "particles.vtkhdf"), 0)
    last = last_step(out)
    fluid = last["Type"] == 3
    assert int(fluid.sum()) == int((first["Type"] == 3).sum())
    assert np.abs(last["Vel"][fluid, 0] - 1.0).max() < 1e-9
    assert np.abs(last["Vel"][fluid, 2]).max() < 1e-9
    assert np.abs(last["Rhop"][fluid] - 1000.0).max() < 1e-6
    import json
    counts = json.loads((out / "run.json").read_text())["inout"]
    t = json.loads((out / "run.json").read_text())["physical_time"]
    rows = 11                                     # z = 0 ... 0.2 at dp 0.02
    cols = math.floor(t * 1.0 / 0.02 + 1e-9)
    assert counts["created"] == counts["to_fluid"] == rows * cols
    assert counts["removed"] == counts["to_buffer"] == rows * cols
    # the lattice stays a lattice: x of every fluid particle a multiple of dp from x(t) = U t
    x = last["points"][fluid, 0] - t
    assert np.abs(x / 0.02 - np.round(x / 0.02)).max() < 1e-6

"""Boundaries outside the simulation domain and periodic lengths below the kernel support (hunt8/e
findings 4 and 7): DualSPHysics aborts when a fixed, moving or floating particle leaves the domain
(JSph::AbortBoundOut); sphdvi let a moving wall leave it silently and ran with a third of a tank's walls
cut off by <simulationdomain>, and with a periodic length below 2h (one ghost copy per side, as
DualSPHysics's PeriodicMakeList) missed the images beyond one period."""
import json
import warnings

from click.testing import CliRunner

from sphdvi.cli import main

from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

WATER = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.5" y="2" z="0.5" /></drawbox>"""
TANK = WATER + """
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="2" y="2" z="1" /></drawbox>"""
# a vertical wall of mkbound 10 in the tank, 10 m/s towards +x for 1 s: it leaves the domain (x <= 2)
WALL = TANK + """
                    <setmkbound mk="10" /><drawline><point x="0.8" y="0" z="0.05" /><point x="0.8" y="0" z="0.5" /></drawline>"""
MOTION = """
        <motion><objreal ref="10"><begin mov="1" start="0" />
            <mvrect id="1" duration="1"><vel x="10" y="0" z="0" /></mvrect></objreal></motion>"""
PARAMS = """
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="TimeMax" value="0.3" />
            <parameter key="TimeOut" value="0.05" />"""


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def drawn(tmp_path, commands, casedef_extra="", parameters=PARAMS, dp="0.05"):
    case = write_case(tmp_path, case_xml(dp=dp, commands=commands, casedef_extra=casedef_extra,
                                         parameters=parameters))
    r = invoke(["gencase", case, "-o", tmp_path / "g"])
    assert r.exit_code == 0, r.output
    return tmp_path / "g"


def run(folder, out, tmax="0.3"):
    with warnings.catch_warnings(record=True):      # exclusion warnings of the runs that go on, if any
        warnings.simplefilter("always")
        return invoke(["run", folder, "-o", out, "--tmax", tmax, "--threads", "1", "-q"])


def test_a_moving_wall_that_leaves_the_domain_stops_the_run(tmp_path):
    """The wall reaches x = 2 (the domain's x-max) at t = 0.12 s: the run stops there (exit 3) naming the
    mkbound, a particle, its position and the domain; it went on to x = 3.8 and ended "completed"."""
    g = drawn(tmp_path, WALL, casedef_extra=MOTION)
    r = run(g, tmp_path / "o")
    assert r.exit_code == 3, r.output
    meta = json.loads((tmp_path / "o" / "run.json").read_text())
    msg = meta["message"]
    assert meta["status"] == "diverged" and 0.12 <= meta["physical_time"] < 0.13
    assert "moving boundary mkbound 10 left the simulation domain (-0.0035355, -0.070711, -0.0035355) - (2.0035, 0.070711, 1.0035)" in msg
    assert "through its x-max face: its particle" in msg and "moving particles out" in msg
    assert "Fixed, moving or floating particles were excluded" in msg


def test_the_same_wall_inside_the_domain_runs_on(tmp_path):
    """The check costs nothing where the wall stays in: a domain to x = 5 holds it for the 0.3 s."""
    g = drawn(tmp_path, WALL, casedef_extra=MOTION, parameters=PARAMS + """
            <simulationdomain><posmax x="5" /></simulationdomain>""")
    r = run(g, tmp_path / "o")
    assert r.exit_code == 0, r.output


def test_walls_cut_by_the_simulation_domain_are_an_input_error(tmp_path):
    """<simulationdomain> posmax x = 1 cuts the tank's right half (the fluid is inside it): DualSPHysics
    excludes those fixed particles at its first cell division and aborts; sphdvi ran without them."""
    g = drawn(tmp_path, TANK, parameters=PARAMS + """
            <simulationdomain><posmax x="1" /></simulationdomain>""")
    r = run(g, tmp_path / "o")
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert "boundary particles lie outside the simulation domain (-0.0035355, -0.070711, -0.0035355) - (1, 0.070711, 1.0035)" in text
    assert "mkbound 0 (fixed): " in text and "enlarge <simulationdomain> to hold the walls" in text
    assert "Traceback" not in r.output


PERIODIC_LAYER = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0.05" /><size x="{L}" y="2" z="0.3" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="{L}" y="2" z="0.025" /></drawbox>"""
PERIODIC = PARAMS + """
            <parameter key="XPeriodicIncZ" value="0" />
            <simulationdomain><posmax z="default + 50%" /></simulationdomain>"""


def test_a_periodic_length_below_the_kernel_support_is_refused(tmp_path):
    """A water layer periodic in x one dp long (L = dp = 0.025 m < 2h = 0.0707 m): refused at start-up
    (exit 2); it ran with a different flow than the same layer 20 dp long, silently."""
    g = drawn(tmp_path, PERIODIC_LAYER.format(L="0.001"), parameters=PERIODIC, dp="0.025")
    r = run(g, tmp_path / "o", tmax="0.01")
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert ("the periodic length along x, L = 0.025 m (the particles' extent plus dp, as DualSPHysics), is "
            "shorter than the kernel support 2h = 0.0707107 m") in text
    assert "make the domain at least 2h long along x" in text


def test_a_periodic_length_of_the_kernel_support_runs(tmp_path):
    """Three columns (L = 0.075 m >= 2h): the run goes on."""
    g = drawn(tmp_path, PERIODIC_LAYER.format(L="0.07"), parameters=PERIODIC, dp="0.025")
    assert run(g, tmp_path / "o", tmax="0.01").exit_code == 0

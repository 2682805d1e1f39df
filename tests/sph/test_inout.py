"""Inlet/outlet zones (``<special><inout>``, :mod:`sphdvi.sph.inout`): exact solutions, the
extrapolation's order, the buffers' bookkeeping, resume."""
import math
import pathlib

import numpy as np
import pytest
from case.casetext import CONSTANTS, case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.io.vtkhdf import read_step, step_times
from sphdvi.sph import inout as IO

# casetext's constants without gravity, with c0 = 15 m/s and coefh 1.2
NO_GRAVITY = (CONSTANTS.replace('<gravity x="0" y="0" z="-9.81" />', '<gravity x="0" y="0" z="0" />')
              .replace('<speedsound value="0" auto="true" />', '<speedsound value="15" auto="false" />')
              .replace('<coefh value="1.0" />', '<coefh value="1.2" />'))

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
    return pathlib.Path(write_case(tmp_path, text, f"{name}_Def.xml"))


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


def solver_of(tmp_path, case, sets=()):
    """gencase + the run's set-up (SPHRun) without stepping."""
    from sphdvi.run_options import apply_overrides
    from sphdvi.simulation import SPHRun, find_case_file, special_parameters
    g = tmp_path / "g"
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(g)])
    assert r.exit_code == 0, r.output
    data = read_case_h5(find_case_file(str(g)))
    params = apply_overrides(special_parameters(data), list(sets))
    return SPHRun(data, params, str(tmp_path))


def _linear_fields(sol):
    """Fluid at rest but for a linear density and velocity field; returns the field functions."""
    s = sol.state
    rho = lambda p: 1000.0 + 20.0 * p[:, 0] - 15.0 * p[:, 2]        # noqa: E731
    u = lambda p: 0.5 + 0.3 * p[:, 0] + 0.2 * p[:, 2]              # noqa: E731
    fl = s.ptype == 3
    s.rhop[fl] = rho(s.pos[fl])
    s.vel[fl] = 0.0
    s.vel[fl, 0] = u(s.pos[fl])
    return rho, u


@pytest.mark.parametrize("order", ["first", "zeroth"])
def test_extrapolation_from_the_ghost_node(tmp_path, order):
    """The outlet's buffer takes the fluid's density and velocity mirrored through the plane: with
    determlimit 1e-3 (first order) a linear field is carried to the buffer particle exactly (the
    kernel-corrected value and gradient at the ghost node, then the Taylor step back); with the
    default 1e+3 it takes the Shepard average at the ghost node."""
    limit = "1e-3" if order == "first" else "1e+3"
    zones = INLET.format(u=1.0, rin=0, refill=0) + OUTLET.format(rout=2)
    case = slab_case(tmp_path, inout=zones)
    text = case.read_text().replace("<inout>", f'<inout><determlimit value="{limit}" />')
    case.write_text(text)
    sph = solver_of(tmp_path, case)
    sol = sph.solver
    rho, u = _linear_fields(sol)
    sol.compute_rates()
    s = sol.state
    io = sol.inout
    buf = (s.ptype == 3) & (io.zone_of_idp[s.idp] == 1)
    assert buf.sum() == 4 * 11
    p = s.pos[buf]
    if order == "first":
        assert np.abs(s.rhop[buf] - rho(p)).max() < 1e-8
        assert np.abs(s.vel[buf, 0] - u(p)).max() < 1e-10
    else:
        g = p.copy()
        plane = io.geo[1, IO.G_D0] * io.geo[1, 0]       # the plane's x (direction -x)
        g[:, 0] = 2 * plane - p[:, 0]
        # the Shepard average at the ghost node over the fluid (buffers left out), summed here
        h = sol.h
        src = (s.ptype == 3) & (io.zone_of_idp[s.idp] < 0)
        r = np.linalg.norm(g[:, None, [0, 2]] - s.pos[None, src][:, :, [0, 2]], axis=2) / h
        w = np.where(r < 2, (1 - r / 2) ** 4 * (2 * r + 1), 0.0)
        m = s.mass[src]
        shepard = (w * m).sum(1) / (w * m / s.rhop[src]).sum(1)
        assert np.abs(s.rhop[buf] - shepard).max() < 1e-9
        assert np.abs(s.rhop[buf] - rho(g)).max() < 0.6          # the ghost node's value, to O(h)
        assert np.abs(s.rhop[buf] - rho(p)).max() > 1.0          # not the buffer's own value
    # the inlet's buffer is imposed: U and rho0, and never seen by the extrapolation
    inlet = (s.ptype == 3) & (io.zone_of_idp[s.idp] == 0)
    assert np.all(s.vel[inlet, 0] == 1.0) and np.all(s.rhop[inlet] == 1000.0)


def test_buffers_take_no_acceleration(tmp_path):
    sph = solver_of(tmp_path, slab_case(tmp_path))
    sol = sph.solver
    _linear_fields(sol)
    sol.compute_rates()
    s = sol.state
    buf = sol.inout.zone_of_idp[s.idp] >= 0
    assert not sol.ace[buf].any() and not sol.ar[buf].any()
    assert np.abs(sol.ace[~buf]).max() > 0


def test_hydrostatic_buffer_density_and_zsurf_velocity(tmp_path):
    """imposerhop 1: rho0 (1 + rho0 g (zsurf - z)/B)^(1/gamma), rho0 above zsurf; refilling 1: the
    velocity is zero above zsurf and the buffer starts below it."""
    zones = """
                <inoutzone>
                    <refilling value="1" /><inputtreatment value="2" /><layers value="3" />
                    <zone2d><particles mkfluid="1" direction="right" /></zone2d>
                    <imposevelocity mode="0"><velocity v="0.5" /></imposevelocity>
                    <imposerhop mode="1" />
                    <imposezsurf mode="0"><zsurf value="0.11" /></imposezsurf>
                </inoutzone>"""
    case = slab_case(tmp_path, inout=zones)
    case.write_text(case.read_text().replace('<gravity x="0" y="0" z="0" />', '<gravity x="0" y="0" z="-9.81" />'))
    sph = solver_of(tmp_path, case)
    sol = sph.solver
    sol.compute_rates()
    s = sol.state
    buf = sol.inout.zone_of_idp[s.idp] == 0
    z = s.pos[buf, 2]
    assert z.max() <= 0.11 and buf.sum() == 3 * 6          # rows z = 0 ... 0.1
    b = sol.b
    want = 1000.0 * (1 + 1000.0 * 9.81 * (0.11 - z) / b) ** (1 / 7)
    assert np.allclose(s.rhop[buf], want, rtol=1e-12)
    assert np.all(s.vel[buf, 0] == 0.5)


def test_velocity_profiles_and_time_tables():
    """velocity2 is the line through (z, v), (z2, v2); velocity3 the parabola through its three
    points; a variable velocity interpolates those profiles linearly in time."""
    lin = IO._coefficient_table({"mode": 0, "profile": "linear", "rows": [[0.0, 1.0, 3.0, 2.0, 3.0]]})
    a, b, c = lin[0, 1:]
    assert a == 0 and math.isclose(b * 2 + c, 1.0) and math.isclose(b * 3 + c, 3.0)
    par = IO._coefficient_table({"mode": 0, "profile": "parabolic",
                                 "rows": [[0.0, 0.0, 0.608, 3.0, 4.0, 4.5, 5.0]]})
    f = lambda z: np.polyval(par[0, 1:], z)                              # noqa: E731
    assert np.allclose([f(4.0), f(4.5), f(5.0)], [0.0, 0.608, 3.0])
    spec = {"zones": [{"velocity": {"mode": 1, "profile": "uniform", "rows": [[0.0, 2.0], [2.0, 0.0], [4.5, 2.0]]},
                       "zsurf": {"mode": None}, "refilling": 0, "inputtreatment": 2, "rhop": {"mode": 0},
                       "layers": 2, "shape": {"kind": "line"}}]}
    pts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.1]])
    io = IO.InOut(spec, {"gravity": [0, 0, -9.81], "cs0": 10.0, "rhop0": 1000.0, "gamma": 7.0}, 0.1, True,
                  [(pts, np.array([1.0, 0.0, 0.0]))])
    for t, v in ((0.0, 2.0), (1.0, 1.0), (3.25, 1.0), (9.0, 2.0)):
        io.update_time(t)
        assert math.isclose(IO.profile_velocity(io.coef, 0, 0.3), v)


def test_zone_points_follow_dualsphysics():
    """A <line> 0.9 m long at dp 0.2: 4 gaps of 0.2 m and 0.1 left (< 0.95 dp): 5 points 0.2 apart;
    1.0 m: 6 points; a <box> 0.4 x 0.2 at dp 0.1: 5 x 3; a circle of radius 0.2 at dp 0.1: rings of
    1, 6 and 13 points; the plane dp/2 in front of the points."""
    line = {"kind": "line", "point": [0, 0, 0], "point2": [0, 0, 0.9], "direction": [1.0, 0, 0]}
    pts, n = IO.zone_points(line, 0.2, None)
    assert len(pts) == 5 and np.allclose(np.diff(pts[:, 2]), 0.2) and np.allclose(n, [1, 0, 0])
    line["point2"] = [0, 0, 1.0]
    assert len(IO.zone_points(line, 0.2, None)[0]) == 6
    box = {"kind": "box", "point": [0, 0, 0], "size": [0.4, 0, 0.2], "direction": [0, 1.0, 0]}
    assert len(IO.zone_points(box, 0.1, None)[0]) == 15
    circ = {"kind": "circle", "point": [0, 0, 0], "radius": 0.2, "direction": [0, 0, 1.0]}
    pts, n = IO.zone_points(circ, 0.1, None)
    assert len(pts) == 1 + 6 + 13 and np.allclose(pts[:, 2], 0.0)
    rot = dict(line, rotation={"angle": math.radians(90), "p1": [0, 0, 0], "p2": [0, 1, 0]})
    pts, n = IO.zone_points(rot, 0.2, None)
    assert np.allclose(n, [0, 0, -1], atol=1e-12) and np.allclose(pts[:, 2], 0.0, atol=1e-12)


def test_advanced_refilling_fills_an_emptied_buffer(tmp_path):
    """refilling 2: the columns of a buffer the flow leaves (velocity out of the fluid at an inlet-
    outlet, here an outlet pulled backwards) are refilled from the back, each to L deep."""
    zones = """
                <inoutzone>
                    <refilling value="2" /><inputtreatment value="1" /><layers value="4" />
                    <zone2d><particles mkfluid="1" direction="right" /></zone2d>
                    <imposevelocity mode="0"><velocity v="1.0" /></imposevelocity>
                    <imposerhop mode="0" />
                </inoutzone>""" + OUTLET.format(rout=2)
    case = slab_case(tmp_path, inout=zones, tmax=0.1)
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    last = last_step(out)
    fluid = last["Type"] == 3
    x = last["points"][fluid, 0]
    # the inlet buffer still holds its 4 layers behind the plane at x = dp/2 (a refilled one each
    # time the flow empties a column's back)
    behind = x < 0.01
    assert 4 * 11 - 11 <= int(behind.sum()) <= 4 * 11 + 11
    assert np.abs(last["Vel"][fluid, 0] - 1.0).max() < 1e-6


def test_resume_is_bitwise_with_inout(tmp_path):
    """A run stopped at an output and resumed ends where the uninterrupted run ends (1 thread): the
    buffers' ids, the next id and the counts are in restart.h5."""
    case = slab_case(tmp_path, tmax=0.1)
    a, b = tmp_path / "a", tmp_path / "b"
    assert run(case, a).exit_code == 0
    assert run(case, b, "--tmax", "0.05").exit_code == 0
    r = run(b, b, "--resume", "--tmax", "0.1")
    assert r.exit_code == 0, r.output
    la, lb = last_step(a), last_step(b)
    order_a, order_b = np.argsort(la["Idp"]), np.argsort(lb["Idp"])
    assert np.array_equal(la["Idp"][order_a], lb["Idp"][order_b])
    assert np.array_equal(la["points"][order_a], lb["points"][order_b])
    assert np.array_equal(la["Vel"][order_a], lb["Vel"][order_b])
    import json
    ia, ib = (json.loads((d / "run.json").read_text())["inout"] for d in (a, b))
    assert ia == ib


def test_measure_reads_the_particles_a_run_created(tmp_path):
    """`sphdvi measure points` on a run whose inlet created particles (ids past the case's): they
    take the fluid mass, and the gauge in the slab reads U and rho0."""
    case = slab_case(tmp_path, tmax=0.1)
    out = tmp_path / "out"
    assert run(case, out).exit_code == 0
    csv = tmp_path / "p.csv"
    r = CliRunner().invoke(main, ["measure", "points", str(out), "--points", "0.05,0,0.1",
                                  "--vars", "vel,rhop", "--csv", str(csv)])
    assert r.exit_code == 0, r.output
    rows = [ln.split(",") for ln in csv.read_text().splitlines() if ln and not ln.startswith("#")]
    head, last = rows[0], rows[-1]
    vals = dict(zip(head, last))
    ux = next(v for k, v in vals.items() if "vel" in k.lower() and "x" in k.lower())
    rho = next(v for k, v in vals.items() if "rho" in k.lower())
    assert abs(float(ux) - 1.0) < 1e-6 and abs(float(rho) - 1000.0) < 1e-3


BLOCK_3D = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0" /><size x="0.3" y="0.1" z="0.1" /></drawbox>
                    <setmkfluid mk="1" />
                    <drawbox><boxfill>left</boxfill><point x="0" y="0" z="0" /><size x="0.3" y="0.1" z="0.1" /></drawbox>
                    <setmkfluid mk="2" />
                    <drawbox><boxfill>right</boxfill><point x="0" y="0" z="0" /><size x="0.3" y="0.1" z="0.1" /></drawbox>"""
INLET_BOX = """
                <inoutzone>
                    <refilling value="0" /><inputtreatment value="2" /><layers value="3" />
                    <zone3d><box><point x="-0.02" y="0" z="0" /><size x="0" y="0.1" z="0.1" />
                        <direction x="1" y="0" z="0" /></box></zone3d>
                    <imposevelocity mode="0"><velocity v="1.0" /></imposevelocity>
                    <imposerhop mode="2" />
                </inoutzone>"""


@pytest.mark.parametrize("inlet", ["particles", "box"])
def test_a_3d_block_moves_exactly_through_its_zones(tmp_path, inlet):
    """3D: the exact translation of a free block through an inlet (the block's left face, or a
    <box> zone behind it) and an outlet (its right face); first-order extrapolation of density and
    velocity there (a 4 x 4 system)."""
    zones = (INLET.format(u=1.0, rin=2, refill=0) if inlet == "particles" else INLET_BOX) + OUTLET.format(rout=2)
    zones = zones.replace("zone2d", "zone3d")
    text = case_xml(dp="0.02", pointmin=("-0.12", "-0.04", "-0.04"), pointmax=("0.44", "0.14", "0.14"),
                    constants=NO_GRAVITY, commands=BLOCK_3D, special=f"""
            <initialize>{"".join(f'<fluidvelocity mkfluid="{m}"><direction x="1" y="0" z="0" /><velocity v="1" />'
                                 '</fluidvelocity>' for m in range(3))}</initialize>
            <inout><determlimit value="1e-3" />{zones}</inout>""",
                    parameters='<parameter key="StepAlgorithm" value="2" /><parameter key="TimeMax" value="0.1" />'
                               '<parameter key="TimeOut" value="0.05" />'
                               '<simulationdomain><posmin x="-0.12" y="default" z="default" />'
                               '<posmax x="0.45" y="default" z="default" /></simulationdomain>')
    case = write_case(tmp_path, text, "CaseBlock_Def.xml")
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    first, last = read_step(str(out / "particles.vtkhdf"), 0), last_step(out)
    fl = last["Type"] == 3
    assert int(fl.sum()) == int((first["Type"] == 3).sum())
    assert np.abs(last["Vel"][fl] - [1.0, 0.0, 0.0]).max() < 1e-8
    assert np.abs(last["Rhop"][fl] - 1000.0).max() < 1e-6
    import json
    info = json.loads((out / "run.json").read_text())
    cols = math.floor(info["physical_time"] / 0.02 + 1e-9)
    assert info["inout"]["created"] == info["inout"]["removed"] == 36 * cols      # 6 x 6 per column


def test_refill_columns_fills_each_column_from_its_back():
    """JSphInOut::ComputeStepFillingCpu's rule: a point's column ends at its deepest buffer particle
    within dp (laterally) plus sqrt(dp^2 - s^2); a new particle goes there while that is less than
    L deep; an empty column gets one at dp; a point above zsurf gets none."""
    dp, layers = 0.1, 4
    spec = {"zones": [{"velocity": {"mode": 2}, "zsurf": {"mode": 0, "rows": [[0.0, 0.55]]}, "refilling": 2,
                       "inputtreatment": 1, "rhop": {"mode": 0}, "layers": layers, "shape": {"kind": "line"}}]}
    pts = np.array([[0.0, 0.0, 0.1 * k] for k in range(7)])          # x = 0, z = 0 ... 0.6
    io = IO.InOut(spec, {"gravity": [0, 0, -9.81], "cs0": 10.0, "rhop0": 1000.0, "gamma": 7.0}, dp, True,
                  [(pts, np.array([1.0, 0.0, 0.0]))])
    io.update_time(0.0)
    # the plane is at x = dp/2, so rows at x = 0, -0.1, -0.2, -0.3 are 0.05, 0.15, 0.25, 0.35 deep.
    # column z=0: full; z=0.2: two rows and a third 0.06 off to the side; z=0.4: empty
    pos = [[-0.1 * c, 0, 0.0] for c in range(4)] + [[-0.1 * c, 0, 0.2] for c in range(2)] + [[-0.2, 0, 0.26]]
    pos = np.array(pos, float)
    depth = np.empty(len(io.pts_all))
    IO.refill_columns(io.pts_all, io.pts_zone, io.geo, io.zsurf, pos, np.arange(len(pos)),
                      np.zeros(len(pos), np.int64), dp, depth)
    assert depth[0] == -1.0                                   # full: 0.35 + 0.1 = 0.45 > L = 0.4
    assert math.isclose(depth[2], 0.25 + math.sqrt(0.01 - 0.06 ** 2))
    assert math.isclose(depth[4], 0.1)                         # empty: dp
    assert depth[6] == -1.0                                   # above zsurf 0.55


def test_calculated_zsurf_follows_the_water(tmp_path):
    """imposezsurf mode 2: the level measured 2h in front of the zone's centre by the swl rule, less
    dp/2 (the default zsurffit), or less a given zsurffit value."""
    import os
    tank = os.path.join(os.path.dirname(__file__), "..", "..", "cases", "inout2d", "CaseFlowTank2D_Def.xml")
    text = open(tank).read()
    i = text.index('<particles mkfluid="2"')
    j = text.index("</inoutzone>", i)
    outlet = text[i:j].replace('<imposezsurf mode="0"><zsurf value="#Depth" /></imposezsurf>',
                               '<imposezsurf mode="2"><zsurffit value="0.004" /></imposezsurf>')
    assert 'mode="2"' in outlet
    text = text[:i] + outlet + text[j:]
    case = tmp_path / "CaseTank_Def.xml"
    case.write_text(text)
    sph = solver_of(tmp_path, case)
    sol = sph.solver
    sol.compute_rates()
    io = sol.inout
    g, x, y = io.gauges[1]
    assert math.isclose(x, 0.99 - 2 * sol.h, abs_tol=1e-9)       # 2h in front of the outlet's points (x = 0.99)
    level = g.level(sol.state, x, y)
    assert 0.29 < level < 0.31                                   # the top row at 0.29 (the swl rule: ~0.30)
    assert math.isclose(io.zsurf[1], level - 0.004, rel_tol=1e-12)


def test_a_case_whose_only_water_comes_from_an_inlet_runs(tmp_path):
    """No fluid drawn (DualSPHysics's examples/inletoutlet/05_ShapesInlet3D): the zones make the
    run an SPH run, and the inlet fills the domain."""
    zones = INLET.format(u=1.0, rin=0, refill=0).replace(
        '<particles mkfluid="1" direction="right" />',
        '<line><point x="0" z="0.2" /><point2 x="0" z="0" /></line>')
    case = slab_case(tmp_path, inout=zones, tmax=0.06, commands="""
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.1" y="-1" z="-0.06" /><size x="0.8" y="2" z="0.04" />
                    </drawbox>""")
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    last = last_step(out)
    fl = last["Type"] == 3
    import json
    info = json.loads((out / "run.json").read_text())
    assert info["inout"]["created"] >= 11 * 2 and int(fl.sum()) == 4 * 11 + info["inout"]["created"]
    assert np.all(last["points"][fl, 0] < 0.06 + 1.0 * 0.06)


def test_imposevelocity_mode_2_ignores_a_velocity_child(tmp_path):
    """DualSPHysics reads no child of an extrapolated velocity (examples/inletoutlet/03_ReverseFlow
    keeps a <velocity v> there): read, warned as ignored."""
    zones = INLET.format(u=1.0, rin=0, refill=0) + OUTLET.format(rout=2).replace(
        '<imposevelocity mode="2" />', '<imposevelocity mode="2"><velocity v="0.5" /></imposevelocity>')
    case = slab_case(tmp_path, inout=zones)
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "g")])
    assert r.exit_code == 0, r.output
    assert "<velocity> is ignored" in r.output


def test_calculated_zsurf_is_measured_before_the_first_output(tmp_path):
    """A hydrostatic buffer under a calculated zsurf starts from the level measured in the case's
    water (it was infinite until the first step); its layers only below it."""
    import os
    tank = os.path.join(os.path.dirname(__file__), "..", "..", "cases", "inout2d", "CaseFlowTank2D_Def.xml")
    text = open(tank).read()
    i = text.index('<particles mkfluid="2"')
    j = text.index("</inoutzone>", i)
    outlet = text[i:j].replace('<imposezsurf mode="0"><zsurf value="#Depth" /></imposezsurf>',
                               '<imposezsurf mode="2" />')
    assert 'mode="2"' in outlet
    case = tmp_path / "CaseTank_Def.xml"
    case.write_text(text[:i] + outlet + text[j:])
    sph = solver_of(tmp_path, case)
    io = sph.inout
    assert 0.29 < io.zsurf[1] < 0.32
    s = sph.solver.state
    buf = io.zone_of_idp[s.idp] == 1
    assert np.isfinite(s.rhop[buf]).all() and s.pos[buf, 2].max() <= io.zsurf[1]


def test_boundcorr_normals_reach_the_limit_plane():
    """Each listed wall particle's normal points along the zone's direction to its limit plane:
    autoconfig dp/2 beyond the particles' top, autolimitpoint dpfactor dp beyond the particle furthest
    along the direction, limitpoint as given; other particles keep no normal."""
    dp = 0.1
    x, z = np.meshgrid(np.arange(5) * dp, np.arange(3) * dp - 0.3)
    bottom = np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])          # z = -0.3, -0.2, -0.1
    top = bottom + [0, 0, 1.3]                                                     # z = 1.0, 1.1, 1.2
    pos = np.vstack([bottom, top, [[0.2, 0.0, 0.5]]])
    ptype = np.r_[np.zeros(30, np.int8), np.int8(3)]
    label = np.r_[np.zeros(15, int), np.ones(15, int), 5]
    for spec, want_top in (({"zones": [{"mkbound": [0], "auto": "top", "direction": [0, 0, 1.0]},
                                        {"mkbound": [1], "direction": [0, 0, -1.0], "dpfactor": 0.5}]}, 0.95),
                           ({"zones": [{"mkbound": [0], "auto": "top", "direction": [0, 0, 1.0]},
                                        {"mkbound": [1], "direction": [0, 0, -1.0], "limitpoint": [0, 0, 0.9]}]}, 0.9)):
        n = IO.boundcorr_normals(spec, pos, ptype, label, dp)
        assert np.allclose(n[:15, :2], 0) and np.allclose(n[:15, 2], -0.05 - pos[:15, 2])     # plane z = -0.05
        assert np.allclose(n[15:30, 2], want_top - pos[15:30, 2])
        assert not n[30].any()


def test_a_wall_past_an_outlet_warns_and_boundcorr_holds_it(tmp_path):
    """A DBC wall behind an outlet's buffer compresses without end; the run warns once it passes
    RhopOutMax (naming the particle), and <boundcorr> keeps it near rho0."""
    walls = SLAB + """
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.15" y="-1" z="-0.05" /><size x="0.9" y="2" z="0.04" />
                    </drawbox>"""
    for bc in ("", '<boundcorr><mkzone mkbound="0"><autoconfig direction="top" /></mkzone></boundcorr>'):
        sub = tmp_path / ("bc" if bc else "dbc")
        sub.mkdir()
        case = slab_case(sub, tmax=0.3, commands=walls, special_extra=bc)
        out = sub / "out"
        if bc:
            r = run(case, out)
        else:
            with pytest.warns(UserWarning, match="past RhopOutMax"):
                r = run(case, out)
        assert r.exit_code == 0, r.output
        last = last_step(out)
        wall = last["Rhop"][last["Type"] == 0]
        log = (out / "run.log").read_text()
        if bc:
            assert wall.max() < 1010.0 and "past RhopOutMax" not in log
        else:
            assert wall.max() > 1300.0 and "past RhopOutMax" in log and "<boundcorr>" in log


def test_a_slab_periodic_across_the_flow_moves_exactly(tmp_path):
    """Inlet and outlet with a periodic axis across the flow (z, ZPeriodicIncX): the buffers' copies
    across the periodic boundary take their particles' imposed and extrapolated values, and the
    translation stays exact (no free surface at all now)."""
    case = slab_case(tmp_path, extra_params='<parameter key="ZPeriodicIncX" value="0" />')
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    first, last = read_step(str(out / "particles.vtkhdf"), 0), last_step(out)
    fluid = last["Type"] == 3
    assert int(fluid.sum()) == int((first["Type"] == 3).sum())
    assert np.abs(last["Vel"][fluid] - [1.0, 0.0, 0.0]).max() < 1e-9
    assert np.abs(last["Rhop"][fluid] - 1000.0).max() < 1e-6


def test_a_slab_moves_exactly_under_verlet(tmp_path):
    """Verlet: the buffers' previous-step velocity and density (vel_m1, rhop_m1) are imposed too, so
    the translation stays exact through the Euler and leap-frog steps."""
    case = slab_case(tmp_path, extra_params='<parameter key="VerletSteps" value="10" />')
    case.write_text(case.read_text().replace('<parameter key="StepAlgorithm" value="2" />',
                                             '<parameter key="StepAlgorithm" value="1" />'))
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    first, last = read_step(str(out / "particles.vtkhdf"), 0), last_step(out)
    fluid = last["Type"] == 3
    assert int(fluid.sum()) == int((first["Type"] == 3).sum())
    assert np.abs(last["Vel"][fluid] - [1.0, 0.0, 0.0]).max() < 1e-9
    assert np.abs(last["Rhop"][fluid] - 1000.0).max() < 1e-6


def test_the_exclusion_limit_counts_the_fluid_an_inlet_brings(tmp_path):
    """An inlet with no outlet: the water leaves the domain at the far end, excluded for its position,
    more than half the fluid the run started with; the run goes on, since the limit counts every
    fluid particle the run has had (the initial ones and those the inlet created)."""
    case = slab_case(tmp_path, inout=INLET.format(u=1.0, rin=0, refill=0), tmax=0.8,
                     extra_params='<parameter key="WrnPartsOut" value="0" />')
    out = tmp_path / "out"
    r = run(case, out)
    assert r.exit_code == 0, r.output
    import json
    info = json.loads((out / "run.json").read_text())
    first = read_step(str(out / "particles.vtkhdf"), 0)
    n0 = int((first["Type"] == 3).sum())
    assert info["excluded"]["position"] > 0.5 * n0 and info["status"] == "completed"

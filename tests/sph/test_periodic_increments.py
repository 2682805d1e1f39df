"""Periodic increments (``*PeriodicInc*``) and keys as DualSPHysics applies them.

JSph::LoadCaseParticles: PeriXinc = (-Lx, XPeriodicIncY, XPeriodicIncZ); JSphCpu::UpdatePos:
a particle leaving through x >= xmax gets pos += PeriXinc (x - Lx, z + IncZ), one leaving
through x < xmin pos -= PeriXinc; JSphCpuSingle::PeriodicMakeList: the images are ps +- PeriXinc.
JSph::LoadConfigParameters: key presence switches the axes on; XY/XZ/YZPeriodic reset the rest."""
import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.sph import SPHSolver
from sphdvi.sph.periodic import Periodicity, periodic_config

from _helpers import constants, jittered_block, random_state
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

DP = 0.1


def _channel(inc):
    xs = np.arange(0.0, 1.0, DP)                        # period 1.0
    pos = np.array([[x, 0.0, 0.5] for x in xs])
    return pos, Periodicity(["x"], pos, DP, {"XPeriodicIncZ": inc})


def test_leaving_through_the_high_end_adds_the_increment():
    _, per = _channel(0.2)
    p = np.array([[1.01, 0.0, 0.5], [-0.01, 0.0, 0.5]])
    per.wrap(p)
    assert np.allclose(p, [[0.01, 0.0, 0.7], [0.99, 0.0, 0.3]])


def test_ghosts_are_the_images_dualsphysics_makes():
    pos, per = _channel(0.2)
    src, disp = per.ghosts(pos, 0.15)
    for s, d in zip(src, disp):
        if pos[s, 0] < 0.5:       # low end: image above xmax, increment subtracted
            assert np.allclose(d, [1.0, 0.0, -0.2])
        else:                     # high end: image below xmin, increment added
            assert np.allclose(d, [-1.0, 0.0, 0.2])
    assert len(src) == 3          # x = 0, 0.1 (below 0.15) and 0.9 (at or above 0.85)


def test_min_image_undoes_wraps_with_increments():
    _, per = _channel(0.2)
    centre = np.array([1.9, 0.0, 0.5])                  # a body's centre, never wrapped
    true = np.array([[2.05, 0.0, 0.55], [1.75, 0.0, 0.45]])
    wrapped = true.copy()
    for _ in range(3):
        per.wrap(wrapped)
    assert wrapped[:, 0].max() < 1.0
    arm = per.min_image(wrapped - centre)
    assert np.allclose(arm, true - centre)


def test_inclined_channel_wraps_consistently_in_a_run():
    """A block moving in +x with XPeriodicIncZ: what leaves at xmax comes back IncZ higher."""
    rng, dp = np.random.default_rng(3), 0.01
    s = random_state(jittered_block(10, dp, True, rng, jitter=0.0), dp, True, rng, vscale=0.0)
    s.vel[:, 0] = 1.0
    sol = SPHSolver(s, constants(dp, True, g=0.0), {"StepAlgorithm": 2, "XPeriodicIncZ": 0.05},
                    periodic="x")
    z0 = dict(zip(sol.state.idp.tolist(), sol.state.pos[:, 2]))
    x0 = dict(zip(sol.state.idp.tolist(), sol.state.pos[:, 0]))
    sol.run(0.03)
    L = sol.periodicity.length[0]
    for i, x, z in zip(sol.state.idp.tolist(), sol.state.pos[:, 0], sol.state.pos[:, 2]):
        crossed = x < x0[i] - 0.5 * L
        assert abs(z - z0[i] - (0.05 if crossed else 0.0)) < 2e-3


@pytest.mark.parametrize("written,params,is2d,axes,incs", [
    ({"XPeriodicIncZ"}, {"XPeriodicIncZ": 0.0}, True, ["x"], {"XPeriodicIncZ": 0.0}),
    ({"XZPeriodic"}, {"XZPeriodic": 0}, True, ["x", "z"], {}),
    ({"XYPeriodic", "XPeriodicIncZ", "ZPeriodicIncX"}, {"XYPeriodic": 1, "XPeriodicIncZ": 0.1, "ZPeriodicIncX": 0.2},
     False, ["x", "y"], {}),
    ({"XYPeriodic", "XZPeriodic"}, {}, False, ["x", "z"], {}),
])
def test_keys_switch_axes_as_dualsphysics(written, params, is2d, axes, incs):
    assert periodic_config(written, params, is2d) == (axes, incs)


@pytest.mark.parametrize("key", ["YPeriodicIncX", "XYPeriodic", "YZPeriodic"])
def test_y_periodicity_in_2d_is_refused(key):
    with pytest.raises(ValueError, match="Y with 2D"):
        periodic_config({key}, {key: 0}, True)


def test_solver_refuses_y_periodicity_in_2d():
    rng = np.random.default_rng(1)
    pos = jittered_block(6, 0.01, True, rng, jitter=0.0)
    with pytest.raises(ValueError, match="Y with 2D"):
        SPHSolver(random_state(pos, 0.01, True, rng), constants(0.01, True), {}, periodic="xy")


def _case_text(params):
    """A 2D channel 0.38 m long (fluid on a solid bed) with ``params`` on a line of their own, first
    in <parameters>."""
    return case_xml(pointmin=("-0.06", "0", "-0.06"), pointmax=("0.5", "0", "0.4"), mkconfig="", commands="""
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0.02" /><size x="0.38" y="2" z="0.2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="-0.04" /><size x="0.38" y="2" z="0.04" /></drawbox>""",
                    parameters=f"\n{params}\n" '<parameter key="StepAlgorithm" value="2" />'
                               '<parameter key="TimeMax" value="0.01" /><parameter key="TimeOut" value="0.01" />')


def _gencase(tmp_path, params):
    """gencase of the channel: the CLI result and the line of the case file that holds ``params``."""
    from sphdvi.cli import main
    text = _case_text(params)
    case = write_case(tmp_path, text, "CasePer_Def.xml")
    line = text[:text.index(params)].count("\n") + 1
    return CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "g")]), line


def test_gencase_refuses_y_periodicity_in_2d_with_the_line(tmp_path):
    r, line = _gencase(tmp_path, '<parameter key="YPeriodicIncX" value="0" />')
    assert r.exit_code == 2, r.output
    assert "YPeriodicIncX" in r.output and "2D" in r.output and f":{line}:" in r.output


def test_gencase_warns_of_a_pair_key_with_value_0_and_reset_increments(tmp_path):
    r, _ = _gencase(tmp_path, '<parameter key="XZPeriodic" value="0" /><parameter key="XPeriodicIncZ" value="0.1" />')
    assert r.exit_code == 0, r.output
    assert "XZPeriodic=0" in r.output and "resets the periodic increments" in r.output
    from sphdvi.io.casefile import read_case_h5
    from sphdvi.simulation import periodic_axes, periodic_params
    data = read_case_h5(str(tmp_path / "g" / "CasePer.h5"))
    assert periodic_axes(data, data["parameters"]) == ["x", "z"]
    assert periodic_params(data, data["parameters"]).get("XPeriodicIncZ", 0.0) == 0.0

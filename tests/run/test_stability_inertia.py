"""Floating bodies with zero principal moments of inertia (hunt8/e findings 5 and 6): gencase accepted
<inertia x="0" .../> and `sphdvi run` died in np.linalg.inv ("internal error: LinAlgError"), in 3D and
in the 2D form the reader documented; a 3D body drawn as a line of particles (I_xx ~ 1e-18 from
round-off) spun about its axis under round-off torques."""
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.dvi.system import System, free_inverse_inertia

from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

TANK_3D = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0" /><size x="0.6" y="0.3" z="0.2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="0" z="0" /><size x="0.6" y="0.3" z="0.4" /></drawbox>
                    <setmkbound mk="5" />
                    <drawbox><boxfill>solid</boxfill><point x="0.2" y="0.1" z="0.25" /><size x="0.2" y="0.1" z="0.1" /></drawbox>"""
TANK_2D = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="0.5" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="1" /></drawbox>
                    <setmkvoid />
                    <drawbox><boxfill>solid</boxfill><point x="0.38" y="-1" z="0.43" /><size x="0.24" y="2" z="0.2" /></drawbox>
                    <setmkbound mk="5" />
                    <drawbox><boxfill>solid</boxfill><point x="0.4" y="-1" z="0.45" /><size x="0.2" y="2" z="0.1" /></drawbox>"""
PARAMS = """
            <parameter key="TimeMax" value="0.01" />
            <parameter key="TimeOut" value="0.005" />"""


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def floating(inertia, dof=""):
    return f'\n<floatings><floating mkbound="5" rhopbody="500">{inertia}{dof}</floating></floatings>'


def gencase(tmp_path, commands, extra, dp, pointmin, pointmax):
    case = write_case(tmp_path, case_xml(dp=dp, commands=commands, casedef_extra=extra, parameters=PARAMS,
                                         pointmin=pointmin, pointmax=pointmax))
    return invoke(["gencase", case, "-o", tmp_path / "g"])


def gencase_3d(tmp_path, extra):
    return gencase(tmp_path, TANK_3D, extra, "0.05", ("-1", "-1", "-1"), ("2", "2", "2"))


def gencase_2d(tmp_path, extra):
    return gencase(tmp_path, TANK_2D, extra, "0.025", ("-1", "0", "-1"), ("3", "0", "3"))


def test_a_zero_moment_about_a_free_axis_is_a_gencase_error(tmp_path):
    r = gencase_3d(tmp_path, floating('<inertia x="0" y="1" z="1" />'))
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert "Case_Def.xml:" in text and "<inertia>" in text
    assert "the principal moment of inertia about x is 0 kg m²" in text and "<rotationDOF>" in text
    assert "Traceback" not in r.output


def test_a_zero_moment_about_a_locked_axis_is_fine(tmp_path):
    r = gencase_3d(tmp_path, floating('<inertia x="0" y="1" z="1" />', '<rotationDOF x="0" />'))
    assert r.exit_code == 0, r.output


def test_the_2d_form_runs_and_a_zero_i_yy_is_refused(tmp_path):
    """2D: only I_yy is used (the other rotations are locked): <inertia x="0" y="0.5" z="0"/> runs (it
    crashed the run's start-up), <inertia x="1" y="0" z="1"/> is refused."""
    r = gencase_2d(tmp_path, floating('<inertia x="0" y="0.5" z="0" />'))
    assert r.exit_code == 0, r.output
    r = invoke(["run", tmp_path / "g", "-o", tmp_path / "o", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    (tmp_path / "b").mkdir()
    r = gencase_2d(tmp_path / "b", floating('<inertia x="1" y="0" z="1" />'))
    assert r.exit_code == 2 and "the principal moment of inertia about y is 0 kg m²" in " ".join(r.output.split())


def test_free_inverse_inertia():
    """Regular tensors: np.linalg.inv, bitwise; a zero moment about a locked axis: no rotation there,
    silently; about a free axis (a line body): no rotation there, with a warning."""
    I = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]])
    assert np.array_equal(free_inverse_inertia(I, np.eye(3), (1, 1, 1)), np.linalg.inv(I))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        inv = free_inverse_inertia(np.diag([0.0, 0.5, 0.0]), np.eye(3), (0, 1, 0))
    assert np.allclose(inv, np.diag([0.0, 2.0, 0.0]), rtol=0, atol=1e-15)
    with pytest.warns(UserWarning, match=r"floating body line has no moment of inertia about the axis \(1, 0, 0\) "
                                         r".*: its rotation about that axis is locked"):
        inv = free_inverse_inertia(np.diag([8.9e-19, 5.6e-3, 5.6e-3]), np.eye(3), (1, 1, 1), "line")
    assert inv[0, 0] == 0.0 and np.isclose(inv[1, 1], 1 / 5.6e-3)


def test_a_line_body_does_not_spin_about_its_axis():
    """A torque about the line (round-off in a run) turned a body of I_xx = 8.9e-19 at 1e18 rad/s2."""
    s = System(gravity=(0, 0, 0))
    with pytest.warns(UserWarning, match="its rotation about that axis is locked"):
        s.add_body(mass=1.0, inertia=(8.9e-19, 5.6e-3, 5.6e-3), torque=(1e-16, 0, 1e-3), name="line")
    for _ in range(10):
        s.step(1e-3)
    w = s.omega_world[0]
    assert abs(w[0]) < 1e-20 and w[2] == pytest.approx(10 * 1e-3 * 1e-3 / 5.6e-3)    # it was 1.1 rad/s

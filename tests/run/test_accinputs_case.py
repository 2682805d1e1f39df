"""``<special><accinputs>`` from a case file: read (``<acctimes>`` and ``<acctimesfile>``),
checked (clear errors, exit 2), and run: two free blocks, one without gravity and one pushed
sideways while it falls, whose mean velocities follow the imposed accelerations exactly."""
import json

import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main

BLOCKS = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="1" /><size x="0.2" y="2" z="0.2" /></drawbox>
                    <setmkfluid mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="1" y="-1" z="1" /><size x="0.2" y="2" z="0.2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom</boxfill><point x="-0.5" y="-1" z="0" /><size x="2" y="2" z="1" /></drawbox>"""

FLOAT = """
            <accinputs>
                <accinput mkfluid="0">
                    <acccentre x="0" y="0" z="0" />
                    <globalgravity value="0" />
                    <acctimes><timevalue time="0" /><timevalue time="1" /></acctimes>
                </accinput>
                <accinput mkfluid="1">
                    <acccentre x="0" y="0" z="0" />
                    <globalgravity value="1" />
                    <acctimesfile value="push.csv" />
                </accinput>
            </accinputs>"""

PARAMS = ('<parameter key="DtFixed" value="1e-4" /><parameter key="StepAlgorithm" value="2" />'
          '<simulationdomain><posmin x="-1" y="default" z="-1" /><posmax x="3" y="default" z="3" /></simulationdomain>')


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_two_free_blocks_follow_their_imposed_accelerations(tmp_path):
    (tmp_path / "push.csv").write_text("time;linx;liny;linz;angx;angy;angz\n0;1.5;0;0;0;0;0\n5;1.5;0;0;0;0;0\n")
    case = write_case(tmp_path, case_xml(dp="0.02", commands=BLOCKS, special=FLOAT, parameters=PARAMS,
                                         pointmin=("-1", "0", "-1"), pointmax=("2", "0", "2")))
    out = tmp_path / "out"
    r = invoke(["run", case, "-o", out, "--tmax", "0.05", "--tout", "0.05", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    t = meta["physical_time"]
    assert sum(meta["excluded"].values()) == 0
    from sphdvi.io.vtkhdf import read_step
    s = read_step(str(out / "particles.vtkhdf"), -1)
    fluid = s["Type"] == 3
    v0 = s["Vel"][fluid & (s["Mk"] == 1)].mean(axis=0)
    v1 = s["Vel"][fluid & (s["Mk"] == 2)].mean(axis=0)
    # float32 output: mean velocities to ~1e-6
    np.testing.assert_allclose(v0, [0.0, 0.0, 0.0], atol=2e-6)                  # gravity taken off
    np.testing.assert_allclose(v1, [1.5 * t, 0.0, -9.81 * t], rtol=1e-5, atol=2e-6)


@pytest.mark.parametrize("special, message", [
    (FLOAT.replace('mkfluid="1"', 'mkbound="0"'), "floating bodies (mkbound) is not supported"),
    (FLOAT.replace('<acctimesfile value="push.csv" />',
                   '<acctimesfile value="push.csv" /><acctimes><timevalue time="0" /></acctimes>'),
     "needs one of <acctimes> and <acctimesfile> (not both)"),
    (FLOAT.replace('mkfluid="1"', 'mkfluid="0"'), "mkfluid 0 already has an <accinput>"),
    (FLOAT.replace('mkfluid="1"', 'mkfluid="5"'), "<accinput> for mkfluid 5, which has no particles"),
    (FLOAT.replace('<acctimes><timevalue time="0" /><timevalue time="1" /></acctimes>',
                   '<acctimes><timevalue time="0" /></acctimes>'), "1 row(s) of accelerations"),
    (FLOAT.replace('<accinput mkfluid="0">', '<accinput><mkfluid value="0" />'), "before v5.0"),
    (FLOAT.replace('<globalgravity value="0" />', ""), "missing child element <globalgravity>"),
    (FLOAT.replace("push.csv", "nothere.csv"), "file 'nothere.csv' not found"),
])
def test_bad_accinputs_are_clear_errors(tmp_path, special, message):
    (tmp_path / "push.csv").write_text("0 1 0 0 0 0 0\n1 1 0 0 0 0 0\n")
    case = write_case(tmp_path, case_xml(dp="0.05", commands=BLOCKS, special=special, parameters=PARAMS))
    r = invoke(["gencase", case, "-o", tmp_path / "g", "-q"])
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output, r.output


def test_a_repeated_time_is_accepted_and_a_decreasing_one_refused(tmp_path):
    """Rows with one time twice are a step change of the acceleration (DualSPHysics's
    JLinearValue takes them; sphdvi refused them as "do not rise"); a time that goes back
    stays an error."""
    from sphdvi.case.gencase import build_case
    step = ('<acctimes><timevalue time="0" /><timevalue time="1" /><timevalue time="1" linx="2" />'
            '<timevalue time="3" linx="2" /></acctimes>')
    (tmp_path / "push.csv").write_text("0 1 0 0 0 0 0\n1 1 0 0 0 0 0\n")
    special = FLOAT.replace('<acctimes><timevalue time="0" /><timevalue time="1" /></acctimes>', step)
    case = write_case(tmp_path, case_xml(dp="0.05", commands=BLOCKS, special=special, parameters=PARAMS))
    r = build_case(case, str(tmp_path / "g"))
    assert [row[:2] for row in r.case.special["accinputs"][0]["table"]] == [[0, 0], [1, 0], [1, 2], [3, 2]]
    (tmp_path / "push.csv").write_text("0 1 0 0 0 0 0\n2 1 0 0 0 0 0\n1 1 0 0 0 0 0\n")
    r = invoke(["gencase", case, "-o", tmp_path / "g2", "-q"])
    assert r.exit_code == 2 and "the times of the accelerations go back (row 3: time 1 after 2)" in r.output, r.output


def test_a_short_file_row_is_reported_with_its_line(tmp_path):
    (tmp_path / "push.csv").write_text("0 1 0 0 0 0 0\n1 1 0 0\n")
    case = write_case(tmp_path, case_xml(dp="0.05", commands=BLOCKS, special=FLOAT, parameters=PARAMS))
    r = invoke(["gencase", case, "-o", tmp_path / "g", "-q"])
    assert r.exit_code == 2 and "push.csv:2" in r.output and "7 numbers per line" in r.output, r.output

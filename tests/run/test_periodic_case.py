"""A periodic-x channel from a case file (XPeriodicIncZ written ⇒ x periodic, as DualSPHysics):
fluid leaving at one end comes back at the other, nothing is excluded."""
import json

import numpy as np
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.vtkhdf import read_step, step_times

CASE = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef><gravity x="0" y="0" z="-9.81" /><coefh value="1.0" /><coefsound value="20" /></constantsdef>
        <geometry>
            <definition dp="0.02"><pointmin x="0" y="0" z="-0.1" /><pointmax x="0.98" y="0" z="1" /></definition>
            <commands><mainlist>
                <setmkfluid mk="0" />
                <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0.02" /><size x="0.98" y="2" z="0.2" /></drawbox>
                <setmkbound mk="0" />
                <drawbox><boxfill>bottom</boxfill><point x="0" y="-1" z="0" /><size x="0.98" y="2" z="0.2" /></drawbox>
            </mainlist></commands>
        </geometry>
        <initials><velocity mkfluid="0" x="1.0" y="0" z="0" /></initials>
    </casedef>
    <execution>
        <parameters>
            <parameter key="XPeriodicIncZ" value="0" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.01" />
            <parameter key="TimeMax" value="0.6" />
            <parameter key="TimeOut" value="0.1" />
            <simulationdomain><posmax z="default + 200%" /></simulationdomain>
        </parameters>
    </execution>
</case>
"""


def test_periodic_channel(tmp_path):
    case = tmp_path / "CasePeriodic_Def.xml"
    case.write_text(CASE)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert sum(meta["excluded"].values()) == 0
    path = str(out / "particles.vtkhdf")
    first, last = read_step(path, 0), read_step(path, len(step_times(path)) - 1)
    f0, f1 = first["Type"] == 3, last["Type"] == 3
    assert f0.sum() == f1.sum()
    x = last["points"][f1, 0]
    assert x.min() >= -1e-9 and x.max() < 1.0 + 1e-9
    # after 0.6 s at ~1 m/s every particle has crossed the periodic boundary at least once
    o0, o1 = np.argsort(first["Idp"][f0]), np.argsort(last["Idp"][f1])
    moved = (last["points"][f1][o1, 0] - first["points"][f0][o0, 0]) % 1.0
    assert np.median(last["Vel"][f1][:, 0]) > 0.8
    assert np.median(moved) > 0.3

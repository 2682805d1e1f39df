"""The JIT warm-up (sphdvi.simulation._warm_up, _warm_up_gauges) compiles, before the time loop,
the kernels of the features that switch on after t=0: the floating bodies' multibody step under
FtPause, an <accinput> whose <time start> is later, a gauge whose <computetime> starts later; and
the run itself stays where it was.  Checked in a fresh process (numba dispatchers' signatures:
loaded from the cache or compiled), so that no earlier test has loaded them."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"

SCRIPT = r'''
import json, sys
import numba
numba.set_num_threads(1)
import numpy as np
from numba.core.registry import CPUDispatcher
from sphdvi import simulation as S
from sphdvi.io.casefile import read_case_h5
from sphdvi.sph import accinput as A
from sphdvi.dvi import _kernels as DK, _math as DM
from sphdvi.measure import _kernels as GK

def loaded(mod):
    return sum(len(v.signatures) for v in vars(mod).values()
               if isinstance(v, CPUDispatcher) and v.__module__ == mod.__name__)

data = read_case_h5(sys.argv[1])
data["json"].setdefault("special", {})["accinputs"] = [
    {"mkfluid": [0], "start": 0.02, "centre": [0.0, 0.0, 0.0], "globalgravity": True,
     "table": [[0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0], [100.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0]]}]
data["json"]["gauges"] = {"default": {"output": True}, "items": [
    {"type": "swl", "name": "late", "line": 1, "point0": [0.5, 0.0, 0.0], "point2": [0.5, 0.0, 1.0],
     "computetime": {"start": 1.0}}]}
params = S.apply_overrides(S.special_parameters(data), ["FtPause=0.05"], 100.0, 1.0)
sph = S.SPHRun(data, params, sys.argv[2])
sol = sph.solver
before = [a.copy() for a in (sol.state.pos, sol.state.vel, sol.state.rhop, sph.bodies.pos, sph.bodies.quat,
                             sph.bodies.vel)]
out = {"dvi_before": loaded(DK) + loaded(DM), "acc_before": len(A._add_serial.signatures)}
S._warm_up(sph)
out["dvi_after"] = len(DK.step_free.signatures) + len(DK.step_end.signatures)
out["acc_after"] = len(A._add_serial.signatures) + len(A.fluid_ace_max2.signatures)
after = (sol.state.pos, sol.state.vel, sol.state.rhop, sph.bodies.pos, sph.bodies.quat, sph.bodies.vel)
out["unchanged"] = all(np.array_equal(a, b) for a, b in zip(before, after))
out["clock"] = [float(sol.time), int(sol.nstep), float(sph.floating.ftpause), float(sph.bodies.time)]
gauges = S._make_gauges(data, params, sys.argv[2], False, 0.0, None)
out["gauges_before"] = loaded(GK)
S._warm_up_gauges(gauges, sol)
out["gauges_after"] = loaded(GK)
out["gauge_rows"] = [len(s.rows) for s in gauges.slots]
print("RESULT " + json.dumps(out))
'''


@pytest.fixture(scope="module")
def case_h5(tmp_path_factory):
    d = tmp_path_factory.mktemp("fbw")
    shutil.copy(CASE, d / CASE.name)
    r = CliRunner().invoke(main, ["gencase", str(d / CASE.name), "-o", str(d / "out"), "--dp", "0.04", "-q"])
    assert r.exit_code == 0, r.output
    return next((d / "out").glob("*.h5"))


def test_warm_up_compiles_what_switches_on_later(case_h5, tmp_path):
    res = subprocess.run([sys.executable, "-c", SCRIPT, str(case_h5), str(tmp_path)], cwd=REPO,
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout.split("RESULT ", 1)[1])
    # nothing of the multibody step, the late accinput or the late gauge before
    assert out["acc_before"] == 0 and out["gauges_before"] == 0
    # FtPause 0.05: the bodies' step (step_free, step_end) is ready before the loop
    assert out["dvi_after"] >= 2, out
    # the <accinput> starting at t=0.02: its kernel and the dt term's
    assert out["acc_after"] >= 2, out
    # the gauge starting at t=1: its kernels, without a row
    assert out["gauges_after"] > 0 and out["gauge_rows"] == [0], out
    # the run itself: not moved, its clock and FtPause as they were
    assert out["unchanged"] and out["clock"] == [0.0, 0, 0.05, 0.0], out

"""What a run that goes unstable says (hunt8/e findings 1, 2, 3, 9): the term of the dt formula that
held dt at DtMin, the last particle of excluded.csv, the cause of a stop for too much fluid excluded,
and a NaN found in any exclusion event of the step."""
import json
import re
import types
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.errors import DivergenceError
from sphdvi.io.casefile import read_case_h5
from sphdvi.simulation import SPHRun

from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)

# a 0.5 m x 1 m water column in a 2 m wide tank, dp 0.05 (200 fluid particles)
COLUMN = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.5" y="2" z="1" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="2" y="2" z="1.5" /></drawbox>"""
# the same water with no wall at all: it falls out of the domain (the fluid's box, wider and taller)
DROP = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.5" y="2" z="0.5" /></drawbox>"""
PARAMS = """
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Kernel" value="2" />
            <parameter key="ViscoTreatment" value="1" />
            <parameter key="Visco" value="0.02" />
            <parameter key="DensityDT" value="2" />
            <parameter key="DensityDTvalue" value="0.1" />
            <parameter key="TimeMax" value="0.3" />
            <parameter key="TimeOut" value="0.05" />"""


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def drawn(tmp_path, commands=COLUMN, casedef_extra="", parameters=PARAMS):
    case = write_case(tmp_path, case_xml(dp="0.05", commands=commands, casedef_extra=casedef_extra,
                                         parameters=parameters))
    r = invoke(["gencase", case, "-o", tmp_path / "g"])
    assert r.exit_code == 0, r.output
    return tmp_path / "g"


def run(folder, out, *sets, tmax="0.3"):
    args = ["run", folder, "-o", out, "--tmax", tmax, "--threads", "1", "-q"]
    for s in sets:
        args += ["--set", s]
    r = invoke(args)
    return r, json.loads((out / "run.json").read_text())


def test_dtmin_stop_names_the_speed_term_of_a_flow_faster_than_c0_over_10(tmp_path):
    """30 m/s water with c0 ~ 63 m/s: dt2 = CFL h/(10|v|max) is below DtMin from the first step, with
    no blow-up; the message blamed "the largest acceleration on particle N" (dt1 was 20 times larger)."""
    g = drawn(tmp_path, casedef_extra='\n<initials><velocity mkfluid="0" x="30" y="0" z="0" /></initials>')
    with warnings.catch_warnings(record=True):        # -q: DtMin and exclusion warnings, if any
        warnings.simplefilter("always")
        r, meta = run(g, tmp_path / "o", tmax="0.1")
    assert r.exit_code == 3
    msg = meta["message"]
    assert "dt held at DtMin" in msg and "for 200 steps" in msg
    assert "the speed term CFL*h/(max(c0, 10|v|max) + h*ViscDtMax)" in msg
    assert re.search(r"with 10\|v\|max = [0-9.]+ m/s > c0 = 6[0-9.]+ m/s: fastest particle \d+ at \(.*\) "
                     r"\(\|v\| 3[0-9.]+ m/s\)", msg), msg
    assert "raise coefsound/speedsound" in msg
    assert "largest acceleration" not in msg


def test_dtmin_stop_names_the_speed_of_sound_for_a_dtmin_above_the_cfl_dt(tmp_path):
    """DtMin above CFL h/c0 for the whole run (DualSPHysics steps with DtMin to the end): the cause is
    DtMin itself, not an acceleration 10 times too small to matter."""
    g = drawn(tmp_path)
    c = read_case_h5(str(next(g.glob("*.h5"))))["constants"]
    dtmin = 1.3 * 0.2 * c["h"] / c["cs0"]
    with warnings.catch_warnings(record=True):        # -q: DtMin and exclusion warnings, if any
        warnings.simplefilter("always")
        r, meta = run(g, tmp_path / "o", f"DtMin={dtmin:.6g}")
    assert r.exit_code == 3
    msg = meta["message"]
    assert f"dt held at DtMin ({dtmin:.3g} s)" in msg
    assert "with the speed of sound c0" in msg and "lower DtMin (or CoefDtMin)" in msg
    assert "largest acceleration" not in msg


def test_exclusion_messages_name_the_last_row_of_excluded_csv(tmp_path):
    """A DtFixed 20 times the CFL dt excludes a quarter of the fluid in one step: the message's "last:"
    particle is excluded.csv's last row (it was the first particle of the step's event)."""
    g = drawn(tmp_path)
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        r, meta = run(g, tmp_path / "o", "DtFixed=0.003")
    assert r.exit_code == 3
    msg = meta["message"]
    last = (tmp_path / "o" / "excluded.csv").read_text().splitlines()[-1].split(",")
    assert "excluded in one step" in msg
    assert f"last: particle {last[1]} at (" in msg and msg.split(f"last: particle {last[1]} at (")[1].split(")")[0] \
        == ", ".join(f"{float(v):.5g}" for v in last[2:5])
    assert f"reason {last[-1]}" in msg


def test_a_fall_out_of_the_domain_names_its_face(tmp_path):
    """No wall: the water falls out through the domain's z-min face; the stop for more than half the
    fluid excluded gave no cause ("diverged" only)."""
    g = drawn(tmp_path, commands=DROP, parameters=PARAMS + """
            <simulationdomain>
                <posmin x="default - 50%" y="default" z="default" />
                <posmax x="default + 50%" y="default" z="default + 50%" />
            </simulationdomain>""")
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        r, meta = run(g, tmp_path / "o", tmax="0.5")
    assert r.exit_code == 3
    msg = meta["message"]
    assert "fluid particles excluded (limit" in msg and "excluded so far: position" in msg
    assert "cause: the fluid left the simulation domain through its" in msg and "z-min" in msg
    assert "(no wall there? enlarge <simulationdomain>)" in msg


# -- the logic of SPHRun.check on a stand-in solver -------------------------------------------------
def _event(idp, pos, reason):
    n = len(idp)
    return {"time": 0.1, "idp": np.array(idp), "pos": np.array(pos, float), "vel": np.zeros((n, 3)),
            "rhop": np.full(n, 1000.0), "reason": list(reason)}


def _stand_in(events, counts, cfl=0.2):
    sol = types.SimpleNamespace(excluded=list(events), n_dtmin=0, time=0.1, nstep=10, last_dt=1e-4, cfl=cfl,
                                _domain=(np.zeros(3), np.ones(3)),
                                n_excluded={"rhop": 0, "position": 0, "not finite": 0, "movement": 0, **counts})
    run = object.__new__(SPHRun)
    run.solver, run.dtmin_seen, run.dtmin_run, run.excluded_seen = sol, 0, 0, 0
    run.excluded_step_limit, run.excluded_limit, run.bodies, run.n0_fluid = 100, 500, None, 1000
    run.out_faces = set()
    run.excluded_seen = sum(sol.n_excluded.values()) - sum(len(ev["idp"]) for ev in events)
    return run


def test_a_nan_in_the_predictors_event_stops_the_run():
    """A Symplectic step excluded a NaN particle in its predictor and another in its corrector: only
    the last event was searched, and the run went on."""
    pre = _event([7], [[np.nan, 0, np.nan]], ["not finite"])
    cor = _event([9], [[0.5, 0, 0.5]], ["rhop"])
    run = _stand_in([_event([3], [[0.2, 0, 0.2]], ["rhop"]), pre, cor], {"not finite": 1, "rhop": 2})
    with pytest.raises(DivergenceError, match=r"step 10: particle 7 at \(nan, 0, nan\) has a non-finite value"):
        run.check(1)


def test_the_cause_of_a_stop_for_half_the_fluid_names_a_large_cflnumber():
    run = _stand_in([_event([5, 8], [[0.5, 0, 0.5], [0.6, 0, 0.4]], ["rhop", "rhop"])],
                    {"rhop": 480, "position": 21}, cfl=1.0)
    with pytest.raises(DivergenceError) as err:
        run.check(0)          # 480 + 21 excluded, 2 of them in this step
    msg = str(err.value)
    assert "501 of 1000 fluid particles excluded (limit 500); last: particle 8 at (0.6, 0, 0.4), reason rhop" in msg
    assert "excluded so far: position 21, rhop 480" in msg
    assert "cause: the solution went unstable: cflnumber 1 is large" in msg


@pytest.mark.parametrize("a, visc, expect", [
    (1e6, 0.0, "the force term CFL*sqrt(h/|a|max) = 6.32e-05 s set dt (the speed term gives 0.0002 s): largest "
               "acceleration on particle 11 at (0.2, 0, 0.1) (1e+06 m/s2)"),
    (0.0, 1e5, "its viscous part h*ViscDtMax = 1e+04 m/s is above c0 = 100 m/s and 10|v|max = 10 m/s"),
])
def test_the_dtmin_cause_names_the_force_or_the_viscous_term(a, visc, expect):
    """dt1 = CFL sqrt(h/|a|max), dt2 = CFL h/(max(c0, 10|v|max) + h ViscDtMax) (JSphCpu::DtVariable)."""
    from sphdvi.sph.state import FluidState
    pos = np.array([[0.1, 0, 0.1], [0.2, 0, 0.1]])
    state = FluidState(pos, np.array([[1.0, 0, 0], [0.5, 0, 0]]), np.full(2, 1000.0), np.ones(2),
                       np.array([3, 3]), np.array([10, 11]), np.zeros(2, int), rhop0=1000.0)
    ace = np.array([[0, 0, -9.81], [0, 0, a - 9.81]])
    run = _stand_in([], {})
    run.solver.__dict__.update(state=state, ace=ace, gravity=np.array([0, 0, -9.81]), dt_vel_type=2, h=0.1,
                               cs0=100.0, dtmax=np.array([[a * a, 1.0, visc]]))
    msg = run._dtmin_cause()
    assert expect in msg, msg

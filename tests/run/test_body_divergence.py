"""A multibody run that goes wrong stops and says so (audit hunt10/c findings 1, 3-9): a chain whose
joint comes apart (exit 3, not "completed"), a body leaving the domain of a body-only run, a blow-up
in the JIT warm-up, a non-finite body in an SPH run (named, before it reaches the fluid), the body
with the absurd load named first, a contact embedded for good, an inertia far below m L², a contact
mass ratio the chosen solver cannot hold (sphdvi.bodychecks)."""
import json
import re

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.bodychecks import BodyWatch, solver_hint, startup_warnings
from sphdvi.cli import main
from sphdvi.dvi import System
from sphdvi.errors import DivergenceError


def chain(m1=1, m2=1, extra="", dt="0.001", tmax="2", floating2="", tout="0.1"):
    """Two 0.2 m cubes (dp 0.05) hinged in a chain about +y (a at the origin, b to a at x = 0.5),
    body-only, 3D; the drawing box -3..3 x -1..1 x -3..1 (the audit's cases/chain.py)."""
    return f"""<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef><constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><coefh value="1.0" />
</constantsdef><mkconfig boundcount="240" fluidcount="9" />
<geometry><definition dp="0.05"><pointmin x="-3" y="-1" z="-3" /><pointmax x="3" y="1" z="1" /></definition>
<commands><mainlist>
<setmkbound mk="1" /><drawbox><boxfill>solid</boxfill><point x="0.4" y="-0.1" z="-0.1" />
<size x="0.2" y="0.2" z="0.2" /></drawbox>
<setmkbound mk="2" /><drawbox><boxfill>solid</boxfill><point x="0.9" y="-0.1" z="-0.1" />
<size x="0.2" y="0.2" z="0.2" /></drawbox>
</mainlist></commands></geometry>
<floatings><floating mkbound="1"><massbody value="{m1}" /></floating>
<floating mkbound="2"><massbody value="{m2}" />{floating2}</floating></floatings>
</casedef><execution><special><chrono>
<bodyfloating id="a" mkbound="1" /><bodyfloating id="b" mkbound="2" />
<link_hinge idbody1="a"><rotpoint x="0" y="0" z="0" /><rotvector x="0" y="1" z="0" /></link_hinge>
<link_hinge idbody1="b" idbody2="a"><rotpoint x="0.5" y="0" z="0" /><rotvector x="0" y="1" z="0" /></link_hinge>
{extra}
</chrono></special><parameters>
<parameter key="RigidAlgorithm" value="3" /><parameter key="DtFixed" value="{dt}" />
<parameter key="TimeMax" value="{tmax}" /><parameter key="TimeOut" value="{tout}" />
</parameters></execution></case>"""


def drop(vz, dt, layers, tmax):
    """A 0.1 m cube (1 kg, AutoActual) thrown at vz onto a floor plate of ``layers`` particle layers
    (dp 0.02), drawing box z -1..1 (the audit's cases/drop.py)."""
    dp = 0.02
    return f"""<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef><constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><coefh value="1.0" />
</constantsdef><mkconfig boundcount="240" fluidcount="9" />
<geometry><definition dp="{dp}"><pointmin x="-0.5" y="-0.5" z="-1" /><pointmax x="0.5" y="0.5" z="1" /></definition>
<commands><mainlist>
<setmkbound mk="0" /><drawbox><boxfill>solid</boxfill><point x="-0.2" y="-0.2" z="{-(layers - 1) * dp}" />
<size x="0.4" y="0.4" z="{(layers - 1) * dp}" /></drawbox>
<setmkbound mk="1" /><drawbox><boxfill>solid</boxfill><point x="-0.05" y="-0.05" z="0.1" />
<size x="0.1" y="0.1" z="0.1" /></drawbox>
</mainlist></commands></geometry>
<properties><property name="mat" Kfric="0.5" Restitution_Coefficient="0" Young_Modulus="1e8" PoissonRatio="0.3" />
<links><link mkbound="0,1" property="mat" /></links></properties>
<floatings><floating mkbound="1"><massbody value="1" /><linearvelini x="0" y="0" z="{vz}" /></floating></floatings>
</casedef><execution><special><chrono><collision activate="true"><distancedp value="0.5" /></collision>
<bodyfloating id="cube" mkbound="1" modelfile="AutoActual" /><bodyfixed id="floor" mkbound="0" modelfile="AutoActual" />
</chrono></special>
<parameters><parameter key="RigidAlgorithm" value="3" /><parameter key="DtFixed" value="{dt}" />
<parameter key="TimeMax" value="{tmax}" /><parameter key="TimeOut" value="0.05" /></parameters></execution></case>"""


def run_case(tmp_path, text, name="Case_Def.xml", args=()):
    case = tmp_path / name
    case.write_text(text)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "-q", "--threads", "1", *args])
    meta = json.loads((out / "run.json").read_text()) if (out / "run.json").exists() else None
    return r, out, meta


def test_chain_coming_apart_stops_the_run(tmp_path):
    """A 1:1e6 chain with the default BB (100 iterations) on every row (exactjoints="false": by default BB
    solves a joint-only island exactly, and the chain holds): before, exit 0 "completed" with the hinges
    metres apart (bodies at y = -14 m in a 2 m wide domain); now exit 3 at the joint that came apart."""
    r, out, meta = run_case(tmp_path, chain(1, 1e6, '<solver exactjoints="false"/>'))
    assert r.exit_code == 3, r.output
    msg = meta["message"]
    assert meta["status"] == "diverged" and meta["physical_time"] < 0.3, msg
    assert re.match(r"t=[\d.]+ s, step \d+: the joint 'Link_a' between 'a' \(mkbound 1\) and the ground has come "
                    r"apart: its position violation is [\d.]+ m \(above 0.05 m", msg), msg
    assert "mass ratio of the jointed bodies 1e+06" in msg and "solver 'bb' (100 iterations at most" in msg
    assert '<chrono><solver type="direct"/>' in msg and '<solver maxiter="1000"/>' in msg
    assert (out / "bodies.csv").read_text().count("\n") >= 3      # the outputs before it stay


def test_chain_with_the_direct_solver_holds(tmp_path):
    """The same chain with <solver type="direct"/>: the joints hold, the run completes (no false alarm)."""
    r, out, meta = run_case(tmp_path, chain(1, 1e6, '<solver type="direct"/>', tmax="0.4"))
    assert r.exit_code == 0 and meta["status"] == "completed", r.output


def test_detached_body_at_a_long_step_stops(tmp_path):
    """DtFixed 0.2 s (omega dt ~ 0.9): the solver converges but the joints drift apart faster than the
    0.6 m/s recovery (as Chrono's clamp); before, exit 0 with body b falling freely 34 m away."""
    r, out, meta = run_case(tmp_path, chain(dt="0.2", tmax="5", tout="0.2"))
    assert r.exit_code == 3, r.output
    assert "body 'b' (mkbound 2)" in meta["message"] or "the joint 'Link_b_a'" in meta["message"], meta["message"]


def test_body_only_run_checks_the_domain(tmp_path):
    """A cube at -60 m/s through a 5-layer plate at DtFixed 5e-3 (0.3 m a step): before, it fell to
    z = -65 m and the run completed; now it stops when the cube leaves the drawing box (z >= -1)."""
    r, out, meta = run_case(tmp_path, drop(-60, 5e-3, 5, 1.0))
    assert r.exit_code == 3, r.output
    msg = meta["message"]
    assert re.match(r"t=0.02 s, step 4: body 'cube' \(mkbound 1\) \(centre \(0.01, 0.01, -1.0\d*\)\) left the "
                    r"simulation domain: its particle at \(.*\) is outside \(-0.5, -0.5, -1\) - \(0.5, 0.5, 1\)",
                    msg), msg


def test_blow_up_in_the_warm_up_is_a_divergence(tmp_path):
    """A torque of 1e300 N m on body b: before, "internal error: ZeroDivisionError" from the JIT
    warm-up (exit 1, no run.json, no bodies.csv); now exit 3 naming b and its load."""
    force = '<angularforce><force time="0" x="0" y="1e300" z="0" /></angularforce>'
    r, out, meta = run_case(tmp_path, chain(floating2=force))
    assert r.exit_code == 3, r.output
    assert meta["status"] == "diverged" and (out / "bodies.csv").exists()
    msg = meta["message"]
    assert msg.startswith("t=0.001 s, step 1: body 'b' (mkbound 2) has a non-finite"), msg
    assert "cause: its imposed load is absurdly large for its mass (1 kg)" in msg
    assert "torque (0, 1e+300, 0) N m" in msg and "<angularforce>" in msg


def test_the_loaded_body_is_named(tmp_path):
    """A torque table reaching 1e308 on b at 0.5 s (its interpolation overflows): before, the message
    named body 'a' (the first index) and "the forces on it are not finite"; now b and its table."""
    force = ('<angularforce><force time="0" x="0" y="0" z="0" /><force time="0.4" x="0" y="0" z="0" />'
             '<force time="0.5" x="0" y="1e308" z="0" /></angularforce>')
    r, out, meta = run_case(tmp_path, chain(floating2=force, tmax="0.6"))
    assert r.exit_code == 3, r.output
    msg = meta["message"]
    assert re.match(r"t=0.4 s, step 400: body 'b' \(mkbound 2\) has a non-finite .* \(and 1 other body: a\); "
                    r"its last finite state \(t=0.399 s\): position \(.*\) m, velocity \(.*\) m/s; cause: its imposed "
                    r"load is not finite", msg), msg


def test_absurd_load_named_when_another_body_leaves_the_domain(tmp_path):
    """1e12 N m on b throws a out of the domain in one step: the message names b's load."""
    force = '<angularforce><force time="0" x="0" y="1e12" z="0" /></angularforce>'
    r, out, meta = run_case(tmp_path, chain(floating2=force))
    assert r.exit_code == 3, r.output
    assert "body 'b' (mkbound 2) has an absurd imposed load (force (0, 0, 0) N, torque (0, 1e+12, 0) N m" \
        in meta["message"], meta["message"]


def test_embedded_contact_is_warned_about(tmp_path):
    """A cube driven at -20 m/s into a one-layer plate at DtFixed 5e-3 stays embedded, jittering:
    before, no word of it; now one warning naming both bodies."""
    r, out, meta = run_case(tmp_path, drop(-20, 5e-3, 1, 0.6))
    assert r.exit_code == 0, r.output
    lines = [x for x in (out / "run.log").read_text().splitlines() if "embedded" in x]
    assert len(lines) == 1 and lines[0].startswith(
        "WARNING: bodies 'cube' (mkbound 1) and 'floor' (mkbound 0) have been embedded in each other for 50 "
        "steps"), lines
    assert "it does not recover" in lines[0]


def test_tiny_inertia_is_warned_about(tmp_path):
    """<inertia> 1e-30 on a 1 kg, 0.25 m body (a unit slip): a start-up warning naming it."""
    inertia = '<inertia x="1e-30" y="1e-30" z="1e-30" />'
    with pytest.warns(UserWarning, match=r"floating body 'b' \(mkbound 2\): its moment of inertia about x, 1e-30 "
                                         r"kg m2, is below 1e-06 of m L2 \(1 kg x \(0.25 m\)2"):
        r, out, meta = run_case(tmp_path, chain(floating2=inertia, tmax="0.01"))
    assert r.exit_code == 0, r.output
    assert "moment of inertia about x" in (out / "run.log").read_text()


def test_contact_mass_ratio_is_not_a_start_up_warning():
    """Colliding bodies of mass ratio 1e6 are not warned about at the start any more (they may never be
    one under the other, audit hunt11/b finding 4): the run-time check does it where a heavy body rests
    on a light one (tests/run/test_bodychecks_warnings.py)."""
    box = {"kind": "floating", "inertia": (1.0, 1.0, 1.0), "rotation_dof": (1, 1, 1), "shapes": [{"shape": "cloud"}]}
    bodies = [dict(box, name="light", mass=1.0), dict(box, name="heavy", mass=1e6, inertia=(1e6,) * 3)]
    assert startup_warnings(bodies, [0.1, 0.1], [1, 2], "bb", False) == []
    assert startup_warnings(bodies, [0.1, 0.1], [1, 2], "direct", False) == []


def test_not_converged_warning_names_the_case_settings():
    line = solver_hint("multibody solver not converged at t=0.1 s for 10 steps: residual 1 m/s")
    assert line.endswith('in the case file: <chrono><solver maxiter="1000"/> (more iterations) or '
                         '<solver type="direct"/> (joint chains), or a smaller DtFixed')
    assert solver_hint("something else") == "something else"


def test_joint_watch_on_a_system():
    """BodyWatch on a System: a hinge pulled apart by an absurd load stops after JOINT_BREAK_STEPS; a
    drawn joint point off by more than the limit but recovering does not."""
    s = System(solver="bb")
    b = s.add_body(mass=1.0, inertia=(0.01,) * 3, pos=(0.5, 0, 0), name="arm")
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 1, 0))
    s.set_external_load(b, force=(0, 0, -1e8))
    watch = BodyWatch(s, ["arm"], [7], [0.2], 0.01)
    with pytest.raises(DivergenceError, match=r"the joint '.*' between 'arm' \(mkbound 7\) and the ground has come "
                                              r"apart.*body 'arm' \(mkbound 7\) has an absurd imposed load"):
        for k in range(200):
            s.step(1e-3)
            watch.after_step(k + 1)
    s = System(solver="direct")
    b = s.add_body(mass=1.0, inertia=(0.01,) * 3, pos=(0.5, 0, 0.05), name="arm")    # 5 cm off the hinge's circle
    s.add_link("hinge", b, -1, point=(0, 0, 0), axis=(0, 1, 0))
    s.pos[b] = (0.5, 0, 0.06)
    watch = BodyWatch(s, ["arm"], None, [0.2], 0.01)
    for k in range(300):
        s.step(1e-3)
        watch.after_step(k + 1)
    assert watch.joint_violations()[0] < 1e-3


@pytest.mark.parametrize("tag, y, what", [("angularforce", 'x="0" y="{}" z="0"', "orientation, angular velocity"),
                                          ("linearforce", 'x="{}" y="0" z="0"', "position, velocity")])
def test_non_finite_floating_body_in_sph_run_is_named(tmp_path, tag, y, what):
    """A 2D floating box whose <angularforce> table overflows to -inf: before, its NaN orientation was not
    checked, its NaN particles reached the fluid and a fluid particle was blamed ("the solution blew up,
    try a smaller cflnumber"); with a <linearforce> table the message had no body, no cause. Now the
    body, its mkbound, its last finite state and its table, before the fluid sees it."""
    text = FLOATING_BOX.format(table=f'<{tag}><force time="0" {y.format("1e308")} />'
                                     f'<force time="1" {y.format("-1e308")} /></{tag}>')
    r, out, meta = run_case(tmp_path, text)
    assert r.exit_code == 3, r.output
    msg = meta["message"]
    assert re.match(r"t=0.000\d+ s, step 1: body 'floating5' \(mkbound 5\)( at \(0.5, 0, 0.3\d*\))? has a "
                    rf"non-finite {what} \(NaN or inf\); its last finite state \(t=0 s\): position "
                    r"\(0.5, 0, 0.3\d*\) m, velocity \(0, 0, 0\) m/s; cause: its imposed load is not finite", msg), msg
    assert "particle" not in msg


FLOATING_BOX = """<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef><constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><coefsound value="20" />
<coefh value="1.0" /><cflnumber value="0.2" /></constantsdef>
<mkconfig boundcount="240" fluidcount="9" />
<geometry><definition dp="0.02"><pointmin x="-0.1" y="0" z="-0.1" /><pointmax x="1.1" y="0" z="1" /></definition>
<commands><mainlist>
<setmkfluid mk="0" /><drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="0.3" /></drawbox>
<setmkbound mk="0" /><drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" />
<size x="1" y="2" z="0.6" /></drawbox>
<setmkvoid /><drawbox><boxfill>solid</boxfill><point x="0.38" y="-1" z="0.23" />
<size x="0.24" y="2" z="0.16" /></drawbox>
<setmkbound mk="5" /><drawbox><boxfill>solid</boxfill><point x="0.4" y="-1" z="0.25" />
<size x="0.2" y="2" z="0.12" /></drawbox>
</mainlist></commands></geometry>
<floatings><floating mkbound="5" rhopbody="500">{table}</floating></floatings>
</casedef><execution><parameters>
<parameter key="StepAlgorithm" value="2" /><parameter key="Visco" value="0.05" /><parameter key="DensityDT" value="2" />
<parameter key="TimeMax" value="0.01" /><parameter key="TimeOut" value="0.005" />
</parameters></execution></case>"""

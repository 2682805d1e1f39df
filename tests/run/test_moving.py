"""Moving boundaries in an SPH run follow their <motion> exactly; wave paddles follow the
first-order stroke; the fluid is pushed (the moving particles drive it)."""
import math

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.io.vtkhdf import read_step, step_times
from sphdvi.motion import MotionSet, WavePaddle

TANK = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <coefsound value="20" />
            <coefh value="1.0" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.02">
                <pointmin x="-0.2" y="0" z="-0.1" />
                <pointmax x="2" y="0" z="1" />
            </definition>
            <commands>
                <mainlist>
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1.5" y="2" z="0.3" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | right</boxfill><point x="-0.2" y="-1" z="0" /><size x="1.7" y="2" z="0.6" /></drawbox>
                    <setmkbound mk="10" />
                    <drawbox><boxfill>solid</boxfill><point x="-0.06" y="-1" z="0.02" /><size x="0.04" y="2" z="0.5" /></drawbox>
                </mainlist>
            </commands>
        </geometry>
        <motion>
            <objreal ref="10">
                <begin mov="1" start="0" />
                MOTION
            </objreal>
        </motion>
    </casedef>
    <execution>
        <special>SPECIAL</special>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.05" />
            <parameter key="DensityDT" value="2" />
            <parameter key="TimeMax" value="0.2" />
            <parameter key="TimeOut" value="0.05" />
        </parameters>
    </execution>
</case>
"""


def run_case(tmp_path, motion, special="", dtfixed=None):
    case = tmp_path / "CaseMoving_Def.xml"
    text = TANK.replace("MOTION", motion).replace("SPECIAL", special)
    if dtfixed:
        text = text.replace('<parameter key="TimeMax"', f'<parameter key="DtFixed" value="{dtfixed}" />'
                            '<parameter key="TimeMax"')
    case.write_text(text)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    return out


def moving_positions(out):
    data = read_case_h5(str(next(out.glob("Case*.h5"))))
    path = str(out / "particles.vtkhdf")
    res = []
    for k, t in enumerate(step_times(path)):
        s = read_step(path, k)
        sel = s["Type"] == 1
        o = np.argsort(s["Idp"][sel])
        res.append((t, s["points"][sel][o], s["Vel"][sel][o], s))
    p0 = data["particles"]["pos"][data["particles"]["type"] == 1]
    return p0, res


def test_rectilinear_motion_is_exact_and_pushes_fluid(tmp_path):
    out = run_case(tmp_path, '<mvrect id="1" duration="100"><vel x="0.5" y="0" z="0" /></mvrect>')
    p0, res = moving_positions(out)
    for t, x, v, _ in res:
        assert np.allclose(x, p0 + [0.5 * t, 0, 0], atol=1e-12)
        if t > 0:
            assert np.allclose(v, [0.5, 0, 0], atol=1e-6)
    s0, s1 = res[0][3], res[-1][3]
    fluid0 = s0["Vel"][s0["Type"] == 3]
    fluid1 = s1["Vel"][s1["Type"] == 3]
    assert np.abs(fluid0[:, 0]).max() == 0
    assert fluid1[:, 0].mean() > 0.01          # the piston pushes the water


def test_piston_wave_paddle_follows_stroke(tmp_path):
    special = ('<wavepaddles><piston><mkbound value="10"/><depth value="0.3"/><waveorder value="1"/>'
               '<waveheight value="0.02"/><waveperiod value="1.0"/><ramp value="0"/></piston></wavepaddles>')
    out = run_case(tmp_path, '<mvnull id="1" />', special)
    p0, res = moving_positions(out)
    paddle = WavePaddle({"type": "piston", "mkbound": 10, "depth": 0.3, "waveheight": 0.02, "waveperiod": 1.0,
                         "ramp": 0, "waveorder": 1})
    for t, x, _, _ in res:
        xs = paddle.stroke_position(t)[0]
        assert np.allclose(x[:, 0] - p0[:, 0], xs, atol=1e-12)
    assert paddle.stroke_position(0.2)[0] == pytest.approx(0.5 * paddle.stroke * math.sin(2 * math.pi * 0.2))


@pytest.mark.parametrize("tag, extra", [("piston_spectrum", ""),
                                        ("flap_spectrum", '<flapaxis0 x="0" y="-1" z="0"/><flapaxis1 x="0" y="1" z="0"/>')])
def test_spectrum_paddle_follows_its_series(tmp_path, tag, extra):
    """An irregular-wave paddle moves its particles with SpectrumPaddle's stroke (a flap: turned
    about its hinge by atan(X / depth)) through the run, their velocity the step's displacement
    over dt (DualSPHysics's MoveLinBound / MoveMatBound), not the stroke's velocity at the step's end."""
    special = (f'<wavepaddles><{tag}><mkbound value="10"/><depth value="0.3"/><spectrum value="jonswap"/>'
               f'<waveheight value="0.02"/><waveperiod value="1.0"/><waves value="20"/><randomseed value="4"/>'
               f'{extra}</{tag}></wavepaddles>')
    dt = 2e-4
    out = run_case(tmp_path, '<mvnull id="1" />', special, dtfixed=dt)
    p0, res = moving_positions(out)
    from sphdvi.validation.runs import case_data
    paddle = MotionSet([], case_data(out)["json"]["special"]["wavepaddles"]).paddles[10]
    moved = 0.0
    for t, x, v, _ in res:
        rigid = paddle.transform(t)
        expect = p0 @ rigid.R.T + rigid.d
        assert np.allclose(x, expect, atol=1e-12)
        if t > 0:
            before = paddle.transform(t - dt)
            mean = (expect - (p0 @ before.R.T + before.d)) / dt
            assert np.allclose(v, mean, rtol=1e-6, atol=1e-7)
            assert not np.allclose(v, rigid.V + np.cross(rigid.W, x - rigid.c), rtol=1e-6, atol=1e-7)
        moved = max(moved, float(np.abs(x - p0).max()))
    assert moved > 1e-3


def test_euler_file_motion_moves_the_particles(tmp_path):
    """An <mvrotadvfile> (a Y angle from a file, about the paddle's centre) through the run: the
    particles at the motion's exact transform."""
    (tmp_path / "euler.csv").write_text("time;ay;ax;az\n0;0;0;0\n0.2;6;0;0\n")
    motion = ('<mvrotadvfile id="1" duration="10" anglesunits="degrees"><file name="euler.csv" fields="4" '
              'fieldang1="1" fieldang2="2" fieldang3="3"/><center x="-0.04" y="0" z="0.27"/>'
              '<intrinsic value="true"/><axes value="YXZ"/></mvrotadvfile>')
    out = run_case(tmp_path, motion)
    p0, res = moving_positions(out)
    from sphdvi.motion import chain_transform
    from sphdvi.validation.runs import case_data
    (m,) = case_data(out)["json"]["motions"]
    for t, x, _, _ in res:
        expect = chain_transform(m, t).apply(p0)[0]
        assert np.allclose(x, expect, atol=1e-12)
    assert float(np.abs(res[-1][1] - p0).max()) > 0.01


def test_focused_paddle_counts_its_focus_from_its_face(tmp_path):
    """A <piston_focused> moves its particles with FocusedPaddle's stroke, its focus distance
    counted from the piston's front face at rest (x = -0.02 here), not from x = 0."""
    special = ('<wavepaddles><piston_focused><mkbound value="10"/><depth value="0.3"/><spectrum value="jonswap"/>'
               '<waveheight value="0.02"/><waveperiod value="1.0"/><waves value="20"/><xf value="1.0"/>'
               '<fpretime value="0"/></piston_focused></wavepaddles>')
    out = run_case(tmp_path, '<mvnull id="1" />', special, dtfixed=2e-4)
    p0, res = moving_positions(out)
    from sphdvi.validation.runs import case_data
    paddle = MotionSet([], case_data(out)["json"]["special"]["wavepaddles"]).paddles[10]
    assert paddle.distance == pytest.approx(1.0)
    paddle.place(float(p0[:, 0].max()))
    assert paddle.distance == pytest.approx(1.02)
    for t, x, _, _ in res:
        assert np.allclose(x, p0 + paddle.transform(t).d, atol=1e-12)
    assert float(np.abs(res[-1][1] - p0).max()) > 1e-5


def test_focus_behind_the_piston_is_a_case_error(tmp_path):
    """xf behind the piston's face (here at x = -0.02) is exit 2 at gencase, naming <xf> and its line."""
    special = ('<wavepaddles><piston_focused><mkbound value="10"/><depth value="0.3"/><spectrum value="jonswap"/>'
               '<waveheight value="0.02"/><waveperiod value="1.0"/><xf value="-0.1"/></piston_focused></wavepaddles>')
    case = tmp_path / "CaseMoving_Def.xml"
    case.write_text(TANK.replace("MOTION", '<mvnull id="1" />').replace("SPECIAL", special))
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out")])
    assert r.exit_code == 2
    assert "<xf>: the focus xf=-0.1 m is not in front of the piston's face at -0.02 m" in r.output


def test_damping_zone_reduces_velocity():
    from sphdvi.sph.damping import DampingZone
    from sphdvi.sph.state import FluidState
    pos = np.array([[0.0, 0, 0], [0.5, 0, 0], [1.0, 0, 0], [1.5, 0, 0], [3.0, 0, 0]])
    st = FluidState(pos, np.ones((5, 3)), None, 1.0, np.array([3, 3, 3, 3, 0]))
    zone = DampingZone({"limitmin": [0, 0, 0], "limitmax": [1, 0, 0], "overlimit": 1.0, "redumax": 10.0,
                        "factorxyz": [1, 1, 0]})
    zone.apply(st, 0.01)
    assert st.vel[0] == pytest.approx([1, 1, 1])                  # at limitmin: nothing
    assert st.vel[1] == pytest.approx([1 - 0.1 * 0.25, 1 - 0.1 * 0.25, 1])
    assert st.vel[2] == pytest.approx([0.9, 0.9, 1]) and st.vel[3] == pytest.approx([0.9, 0.9, 1])
    assert st.vel[4] == pytest.approx([1, 1, 1])                  # boundary particle untouched


@pytest.mark.filterwarnings("ignore:mDBC on mkbound 0. a wall one particle thick")     # the tank's one-layer floor
def test_resume_from_a_checkpoint_without_wall_acceleration(tmp_path):
    """mDBC SlipMode 2 with a moving wall keeps the wall acceleration (pressure cloning)
    in the checkpoint; a checkpoint written before that array existed still resumes,
    with a warning, the acceleration restarting from zero."""
    import h5py
    import json
    case = tmp_path / "CaseMoving_Def.xml"
    case.write_text(TANK.replace("MOTION", '<mvrect id="1" duration="100"><vel x="0.5" y="0" z="0" /></mvrect>')
                    .replace("SPECIAL", ""))
    out = tmp_path / "out"
    opts = ["--threads", "1", "-q", "--set", "Boundary=2", "--set", "SlipMode=2"]
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--tmax", "0.05", "--tout", "0.025"] + opts)
    assert r.exit_code == 0, r.output
    with h5py.File(out / "restart.h5", "a") as f:
        assert f["aux/wall_ace"].shape[1] == 3
        del f["aux/wall_ace"]
    with pytest.warns(UserWarning, match="wall_ace"):
        r = CliRunner().invoke(main, ["run", str(out), "--resume", "--tmax", "0.1", "--tout", "0.025"] + opts)
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "completed" and meta["physical_time"] >= 0.1


AWAS_PISTON = ('<wavepaddles><piston><mkbound value="10"/><depth value="0.3"/><waveorder value="1"/>'
               '<waveheight value="0.02"/><waveperiod value="1.0"/><ramp value="0"/>'
               '<awas_zsurf><swl value="0.3"/><elevation value="1"/><gaugey value="0"/>'
               '<gaugezmin value="0.1"/><gaugezmax value="0.5"/></awas_zsurf></piston></wavepaddles>')


AWAS_SPECTRUM = AWAS_PISTON.replace("<piston>", "<piston_spectrum>").replace("</piston>", "</piston_spectrum>").replace(
    '<waveorder value="1"/>', '<spectrum value="jonswap"/><waves value="20"/><randomseed value="3"/>').replace(
    '<ramp value="0"/>', "")


AWAS_FOCUSED = AWAS_SPECTRUM.replace("piston_spectrum>", "piston_focused>").replace(
    '<waves value="20"/>', '<waves value="20"/><xf value="0.8"/><fpretime value="0"/>')


@pytest.mark.parametrize("special", [AWAS_PISTON, AWAS_SPECTRUM, AWAS_FOCUSED], ids=["regular", "irregular", "focused"])
def test_absorbing_piston_moves_with_its_correction(tmp_path, special):
    """With <awas_zsurf> the piston's particles move as the theory's stroke plus the absorber's
    correction: at the start its gauge reads the still water where the target already has the
    wave, so the correction is not zero; every particle keeps the rigid motion."""
    from sphdvi.validation.runs import case_data
    out = run_case(tmp_path, '<mvnull id="1" />', special)
    p0, res = moving_positions(out)
    paddle = MotionSet([], case_data(out)["json"]["special"]["wavepaddles"]).paddles[10]
    assert paddle.absorber is None
    offsets = []
    for t, x, v, _ in res:
        d = x - p0
        assert np.ptp(d[:, 0]) < 1e-12 and np.abs(d[:, 1:]).max() == 0.0
        offsets.append(d[0, 0] - paddle.stroke_position(t)[0])
        assert np.ptp(v[:, 0]) < 1e-6
    assert abs(offsets[0]) == 0.0 and max(abs(o) for o in offsets) > 1e-4


def test_absorbing_piston_resumes_bitwise(tmp_path):
    """The absorber's state is in restart.h5: a resumed run ends in the bitwise same state."""
    import h5py

    def final_state(outdir):
        with h5py.File(outdir / "restart.h5", "r") as f:
            o = np.argsort(f["state/idp"][...])
            return {k: f["state"][k][...][o] for k in ("pos", "vel", "rhop")}, dict(f["scalars"].attrs)
    case = tmp_path / "CaseMoving_Def.xml"
    case.write_text(TANK.replace("MOTION", '<mvnull id="1" />').replace("SPECIAL", AWAS_PISTON))
    common = ["--tout", "0.05", "--threads", "1", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert CliRunner().invoke(main, ["run", str(case), "-o", str(a), "--tmax", "0.2"] + common).exit_code == 0
    assert CliRunner().invoke(main, ["run", str(case), "-o", str(b), "--tmax", "0.1"] + common).exit_code == 0
    r = CliRunner().invoke(main, ["run", str(b), "--resume", "--tmax", "0.2"] + common)
    assert r.exit_code == 0, r.output
    sa, ka = final_state(a)
    sb, kb = final_state(b)
    assert ka["nstep"] == kb["nstep"] and ka["awas"] == kb["awas"]
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k


def test_absorber_reads_the_still_water_and_warns_of_a_wrong_swl(tmp_path):
    """The absorber's gauge reads the still water at the start (η is measured from that level); a
    <swl> more than dp from it is warned, with the level found."""
    case = tmp_path / "CaseMoving_Def.xml"
    case.write_text(TANK.replace("MOTION", '<mvnull id="1" />')
                    .replace("SPECIAL", AWAS_PISTON.replace('<swl value="0.3"/>', '<swl value="0.5"/>')))
    with pytest.warns(UserWarning, match="mkbound=10") as rec:
        r = CliRunner().invoke(main, ["run", str(case), "-o", str(tmp_path / "o"), "--tmax", "0.02", "--threads", "1",
                                      "-q"])
    assert r.exit_code == 0, r.output
    text = next(str(w.message) for w in rec if "awas_zsurf" in str(w.message))
    assert "from <swl> 0.5" in text
    level = float(text.split("is at z = ")[1].split(" m")[0])
    assert 0.3 < level < 0.32            # the water drawn up to z = 0.3 (particles every 0.02): its edge at 0.31


def test_2d_moving_wall_keeps_its_plane_and_its_step_velocity(tmp_path):
    """A 2D case whose wall accelerates with a y component: DualSPHysics drops the y of a
    translation (JDsMotion::ProcesTime), so the wall stays in the plane and the run goes to its end
    (it stopped at t = 0.09 s "left the simulation domain through its y-max face"); the wall's
    velocity is the step's displacement over dt (MoveLinBound), v0 + a (t - dt/2), not v0 + a t."""
    dt = 2e-4
    motion = ('<mvrectace id="1" duration="100"><ace x="2" y="3" z="0" /><velini x="0.1" y="0.3" z="0" />'
              '</mvrectace>')
    out = run_case(tmp_path, motion, dtfixed=dt)
    p0, res = moving_positions(out)
    assert res[-1][0] == pytest.approx(0.2)
    for t, x, v, _ in res[1:]:
        assert np.array_equal(x[:, 1], p0[:, 1]) and not v[:, 1].any()
        assert np.allclose(x[:, 0], p0[:, 0] + 0.1 * t + t * t, atol=1e-12)
        assert np.allclose(v[:, 0], 0.1 + 2 * (t - dt / 2), rtol=1e-6)

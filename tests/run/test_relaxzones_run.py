"""Relaxation zones in a run (``<special><relaxationzones>``): the zone's water follows the waves'
orbital velocity, its ``<savemotion>`` file holds the theory, a zone over no water is warned about,
and a resumed run ends bitwise as an uninterrupted one (the zones hold no state)."""
import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.motion import WavePaddle

FLUME = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><hswl value="0" auto="true" />
            <gamma value="7" /><speedsystem value="0" auto="true" /><coefsound value="20" />
            <speedsound value="0" auto="true" /><coefh value="1.2" /><cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.02">
                <pointmin x="-0.1" y="0" z="-0.1" /><pointmax x="1.6" y="0" z="0.6" />
            </definition>
            <commands>
                <mainlist>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1.5" y="2" z="0.3" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="#-Dp" y="-1" z="#-Dp" />
                        <size x="#1.5+2*Dp" y="2" z="0.5" /></drawbox>
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <special>
            <relaxationzones>
                <rzwaves_regular>
                    <waveheight value="0.03" /><waveperiod value="1.2" /><depth value="0.3" /><swl value="0.3" />
                    <center x="CENTRE" y="0" z="0" /><width value="0.6" /><coefdir x="1" y="0" z="1" />
                    <savemotion periods="2" periodsteps="12" xpos="0.5" zpos="-0.1" />
                </rzwaves_regular>
            </relaxationzones>
        </special>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="ViscoTreatment" value="1" /><parameter key="Visco" value="0.01" />
            <parameter key="DensityDT" value="2" /><parameter key="DensityDTvalue" value="0.1" />
            <parameter key="TimeMax" value="0.3" /><parameter key="TimeOut" value="0.1" />
            <simulationdomain><posmin x="default" y="default" z="default" />
                <posmax x="default" y="default" z="default + 50%" /></simulationdomain>
        </parameters>
    </execution>
</case>
"""
THEORY = WavePaddle({"type": "piston", "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.2})


def run(tmp_path, name, extra=(), centre="0.3"):
    case = tmp_path / "CaseRZ_Def.xml"
    case.write_text(FLUME.replace("CENTRE", centre))
    out = tmp_path / name
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "-q", *extra])
    assert r.exit_code == 0, r.output
    return out


def final_state(outdir):
    with h5py.File(outdir / "restart.h5", "r") as f:
        o = np.argsort(f["state/idp"][...])
        return {k: f["state"][k][...][o] for k in ("pos", "vel", "rhop", "ptype")}, dict(f["scalars"].attrs)


def test_the_zones_water_moves_with_the_waves(tmp_path):
    out = run(tmp_path, "a")
    s, scal = final_state(out)
    t = float(scal["time"])
    fluid = s["ptype"] == 3
    # the middle of the zone (weight > 0.99): each step takes coefdt dt of the way to the target, so the
    # water lags it by (its SPH acceleration − the wave's)/coefdt, below g/coefdt = 0.0098 m/s (measured
    # 0.0033 m/s at 0.3 s, 0.0062 m/s at 1.2 s; the waves' surface speed is 0.08 m/s)
    core = fluid & (np.abs(s["pos"][:, 0] - 0.3) < 0.03) & (s["pos"][:, 2] < 0.28)
    assert core.sum() >= 20
    for i in np.flatnonzero(core):
        u, w = THEORY.orbital_velocity(s["pos"][i, 0] - 0.3, s["pos"][i, 2] - 0.3, t)
        assert s["vel"][i, 0] == pytest.approx(float(u[0]), abs=9.81 / 1000)
        assert s["vel"][i, 2] == pytest.approx(float(w[0]), abs=9.81 / 1000)
    assert np.linalg.norm(s["vel"][core], axis=1).max() > 0.03  # and the waves' speed is not small there
    rows = np.loadtxt(out / "RelaxZoneMotion_1_1.csv", delimiter=";", skiprows=1)
    head = (out / "RelaxZoneMotion_1_1.csv").read_text().splitlines()[0]
    assert head == "time [s];eta [m];u [m/s];w [m/s]" and rows.shape == (25, 4)
    # xpos 0.5 is 0.2 m in front of the zone's centre at x = 0.3
    assert rows[:, 1] == pytest.approx(THEORY.elevation(0.2, rows[:, 0]), abs=1e-9)
    u, w = THEORY.orbital_velocity(0.2, -0.1, rows[:, 0])
    assert rows[:, 2] == pytest.approx(u, abs=1e-9) and rows[:, 3] == pytest.approx(w, abs=1e-9)


def test_a_resumed_run_ends_bitwise_as_an_uninterrupted_one(tmp_path):
    a = run(tmp_path, "a", ["--tmax", "0.2", "--tout", "0.05"])
    b = run(tmp_path, "b", ["--tmax", "0.1", "--tout", "0.05"])
    r = CliRunner().invoke(main, ["run", str(b), "--resume", "--tmax", "0.2", "--tout", "0.05", "--threads", "1",
                                  "-q"])
    assert r.exit_code == 0, r.output
    (sa, ka), (sb, kb) = final_state(a), final_state(b)
    assert ka["nstep"] == kb["nstep"]
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k


def test_a_zone_over_no_water_is_warned_about(tmp_path):
    with pytest.warns(UserWarning, match=r"<rzwaves_regular> 1: the zone holds no fluid particle"):
        run(tmp_path, "a", ["--tmax", "0.01"], centre="3.0")

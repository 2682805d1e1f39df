"""<savemotion>: the paddle's theory written at the run's start: the lines as DualSPHysics's format
doc writes them, the times, and the theory's velocity against the linear wave's own conditions
(incompressible, the kinematic free-surface condition) and Stokes's second order."""
import math

import numpy as np
import pytest
from click.testing import CliRunner
from lxml import etree

from sphdvi.case.wavepaddles_xml import read_wavepaddles
from sphdvi.case.xmldoc import CaseReader
from sphdvi.cli import main
from sphdvi.errors import CaseError
from sphdvi.io.paddle_motion import motion_table, motion_times
from sphdvi.motion import FocusedPaddle, SpectrumPaddle, WavePaddle, wave_number

REGULAR = {"type": "piston", "mkbound": 10, "depth": 0.4, "waveheight": 0.05, "waveperiod": 1.3, "waveorder": 1,
           "start": 0.0, "duration": 0.0, "gainstroke": 1.0, "phase": 0.3, "ramp": 0.0, "pistondir": [1.0, 0, 0]}
SPECTRUM = {"type": "piston_spectrum", "mkbound": 10, "depth": 0.4, "waveheight": 0.04, "waveperiod": 1.4,
            "spectrum": "jonswap", "discretization": "stretched", "peakcoef": 3.3, "waves": 30, "randomseed": 2,
            "ramptime": 0.0, "serieini": 0.0, "start": 0.0, "duration": 0.0, "gainstroke": 1.0,
            "pistondir": [1.0, 0, 0], "waveorder": 1}


def paddles(tmp_path, tag, inner):
    extra = '<flapaxis0 x="0" y="0" z="0"/><flapaxis1 x="0" y="1" z="0"/>' if tag.startswith("flap") else ""
    spectral = '<spectrum value="jonswap"/>' if tag.endswith("spectrum") else ""
    xml = (f'<wavepaddles>\n<{tag}><mkbound value="10"/><depth value="0.4"/><waveheight value="0.05"/>'
           f'<waveperiod value="1.3"/>{extra}{spectral}\n{inner}</{tag}></wavepaddles>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_wavepaddles(reader, etree.fromstring(xml)), reader


def test_lines_as_the_format_doc_writes_them(tmp_path):
    (d,), reader = paddles(tmp_path, "piston", '<savemotion xpos="0" zpos="-0.2" comment="x"/>'
                                               '<savemotion periods="24" periodsteps="20" xpos="2" zpos="-0.2"/>')
    assert [{k: v for k, v in e.items() if k != "line"} for e in d["savemotion"]] == [
        {"xpos": 0.0, "zpos": -0.2}, {"xpos": 2.0, "zpos": -0.2, "periods": 24.0, "periodsteps": 24 - 4}]
    assert not reader.warnings
    (d,), _ = paddles(tmp_path, "flap_spectrum", '<savemotion time="10" timedt="0.02" xpos="0.1"/>')
    assert d["savemotion"][0]["time"] == 10.0 and d["savemotion"][0]["timedt"] == 0.02


@pytest.mark.parametrize("tag, inner, match", [
    ("piston", '<savemotion time="10"/>', "unknown attribute 'time'"),
    ("piston_spectrum", '<savemotion periods="3"/>', "unknown attribute 'periods'"),
    ("piston", '<savemotion zpos="-0.5"/>', "zpos=-0.5 is not in the water"),
    ("piston", '<savemotion zpos="0.1"/>', "zpos=0.1 is not in the water"),
    ("piston", '<savemotion periods="0"/>', "periods=0"),
    ("piston_spectrum", '<savemotion timedt="-1"/>', "timedt=-1"),
])
def test_bad_lines(tmp_path, tag, inner, match):
    with pytest.raises(CaseError, match=match) as e:
        paddles(tmp_path, tag, inner)
    assert e.value.element == "savemotion"


def test_times():
    reg = WavePaddle(REGULAR)
    t = motion_times(reg, {"periods": 2, "periodsteps": 10}, 5.0, 0.1)
    np.testing.assert_allclose(t, np.arange(21) * 0.13)
    t = motion_times(reg, {}, 2.6, 0.1)           # TimeMax's periods, one row a TimeOut (13 a period)
    assert t[-1] == pytest.approx(2.6) and t[1] == pytest.approx(0.1)
    irr = SpectrumPaddle(SPECTRUM)
    np.testing.assert_allclose(motion_times(irr, {"time": 1.0, "timedt": 0.25}, 9.0, 0.1), [0, 0.25, 0.5, 0.75, 1.0])
    assert motion_times(irr, {}, 3.0, 0.5)[-1] == pytest.approx(3.0)


@pytest.mark.parametrize("make", [lambda: WavePaddle(REGULAR), lambda: SpectrumPaddle(SPECTRUM)],
                         ids=["regular", "irregular"])
def test_velocity_is_the_linear_waves(make):
    """Incompressible (∂u/∂x + ∂w/∂z = 0) and, at the still-water level, w = ∂η/∂t (linear kinematic
    condition); at the bottom w = 0."""
    p = make()
    t = np.linspace(0.5, 6.0, 23)
    h = 1e-5
    for x, z in ((0.7, -0.1), (2.0, -0.3)):
        dudx = (p.orbital_velocity(x + h, z, t)[0] - p.orbital_velocity(x - h, z, t)[0]) / (2 * h)
        dwdz = (p.orbital_velocity(x, z + h, t)[1] - p.orbital_velocity(x, z - h, t)[1]) / (2 * h)
        np.testing.assert_allclose(dudx + dwdz, 0, atol=1e-7)
    detadt = (p.elevation(1.1, t + h) - p.elevation(1.1, t - h)) / (2 * h)
    np.testing.assert_allclose(p.orbital_velocity(1.1, 0.0, t)[1], detadt, atol=1e-7)
    np.testing.assert_allclose(p.orbital_velocity(1.1, -0.4, t)[1], 0, atol=1e-15)


def test_second_order_velocity_is_stokes():
    p = WavePaddle({**REGULAR, "waveorder": 2})
    k, d, w, H = p.k, 0.4, p.omega, 0.05
    t, x, z = np.array([0.7, 1.9]), 0.8, -0.15
    th = w * t + 0.3 * math.pi - k * x
    u = H / 2 * w * np.cosh(k * (z + d)) / np.sinh(k * d) * np.cos(th) \
        + 3 / 16 * H * H * w * k * np.cosh(2 * k * (z + d)) / np.sinh(k * d) ** 4 * np.cos(2 * th)
    np.testing.assert_allclose(p.orbital_velocity(x, z, t)[0], u, rtol=1e-12)
    first = WavePaddle(REGULAR)
    assert not np.allclose(first.orbital_velocity(x, z, t)[0], u, rtol=1e-3)


def test_table_columns():
    p = WavePaddle({**REGULAR, "type": "flap", "flapaxis0": [0, 0, 0], "flapaxis1": [0, 1, 0], "variabledraft": 0.0,
                    "ramp": 2.0})
    p.place(0.05)
    names, rows = motion_table(p, {"xpos": 1.05, "zpos": -0.2, "periods": 3, "periodsteps": 13}, 9.0, 0.1)
    assert names == ["time [s]", "stroke [m]", "stroke_vel [m/s]", "angle [deg]", "eta [m]", "u [m/s]", "w [m/s]"]
    t = rows[:, 0]
    np.testing.assert_allclose(rows[:, 1], [p.theory_position(ti)[0] for ti in t])
    np.testing.assert_allclose(rows[:, 3], np.degrees(np.arctan2(rows[:, 1], 0.4)))
    np.testing.assert_allclose(rows[:, 4], p.elevation(1.0, t))      # 1 m in front of the face
    np.testing.assert_allclose(rows[:, 6], p.orbital_velocity(1.0, -0.2, t)[1])
    assert motion_table(p, {}, 2.6, 0.1)[0] == ["time [s]", "stroke [m]", "stroke_vel [m/s]", "angle [deg]", "eta [m]"]


@pytest.mark.parametrize("make", [lambda o: WavePaddle({**REGULAR, "waveorder": o}),
                                  lambda o: SpectrumPaddle({**SPECTRUM, "waveorder": o})], ids=["regular", "irregular"])
def test_a_second_order_pistons_table_carries_its_bound_waves(make):
    """The elevation and velocity columns of a second-order piston are its theory's to second order
    (the bound waves), a first-order one's linear."""
    for order in (1, 2):
        p = make(order)
        names, rows = motion_table(p, {"xpos": 0.8, "zpos": -0.15, "time": 6.0, "timedt": 0.05,
                                       "periods": 4, "periodsteps": 20}, 9.0, 0.1)
        t = rows[:, 0]
        np.testing.assert_allclose(rows[:, names.index("eta [m]")], p.elevation(0.8, t, order=order), atol=1e-15)
        np.testing.assert_allclose(rows[:, names.index("u [m/s]")], p.orbital_velocity(0.8, -0.15, t)[0], atol=1e-15)
    assert not np.allclose(p.elevation(0.8, t, order=2), p.elevation(0.8, t), atol=1e-5)


def test_focused_table_peaks_at_the_focus():
    from test_wave_focused import spec
    p = FocusedPaddle(spec())
    names, rows = motion_table(p, {"time": 30.0, "timedt": 0.001, "xpos": 6.0}, 30.0, 0.1)
    i = int(np.argmax(rows[:, names.index("eta [m]")]))
    assert rows[i, 0] == pytest.approx(p.focus_time, abs=1e-3)
    assert rows[i, names.index("eta [m]")] == pytest.approx(p.crest, rel=1e-5)      # sampled every 1 ms


def run_tank(tmp_path, special, *options):
    """``sphdvi run`` of test_moving's tank with ``special`` (its piston mkbound 10) into tmp_path/out."""
    from run.test_moving import TANK
    case = tmp_path / "CaseMoving_Def.xml"
    case.write_text(TANK.replace("MOTION", '<mvnull id="1" />').replace("SPECIAL", special))
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--threads", "1", "-q", *options])
    assert r.exit_code == 0, r.output
    return out


def test_the_run_writes_the_files_and_overwrite_sets_them_aside(tmp_path):
    special = ('<wavepaddles><piston><mkbound value="10"/><depth value="0.3"/><waveheight value="0.02"/>'
               '<waveperiod value="1.0"/><savemotion xpos="1" zpos="-0.1"/>'
               '<savemotion periods="2" periodsteps="10"/></piston></wavepaddles>')
    out = run_tank(tmp_path, special)
    first = np.genfromtxt(out / "PaddleMotion_mkbound10_1.csv", delimiter=";", skip_header=1)
    assert first.shape == (5, 6)          # TimeMax 0.2 s, TimeOut 0.05 s
    second = (out / "PaddleMotion_mkbound10_2.csv").read_text().splitlines()
    assert second[0] == "time [s];stroke [m];stroke_vel [m/s];eta [m]" and len(second) == 22
    run_tank(tmp_path, special, "--overwrite")
    assert (out / "PaddleMotion_mkbound10_2.csv").is_file()


def test_the_run_writes_the_series_files(tmp_path):
    special = ('<wavepaddles><piston_spectrum><mkbound value="10"/><depth value="0.3"/><spectrum value="jonswap"/>'
               '<waveheight value="0.02"/><waveperiod value="1.0"/><waves value="20"/>'
               '<saveserie timemin="5" timemax="6" timedt="0.1" xpos="0.5"/>'
               '<saveseriewaves timemax="100"/></piston_spectrum></wavepaddles>')
    out = run_tank(tmp_path, special)
    serie = np.genfromtxt(out / "PaddleSerie_mkbound10.csv", delimiter=";", skip_header=1)
    np.testing.assert_allclose(serie[:, 0], 5 + 0.1 * np.arange(11), atol=1e-12)
    waves = (out / "PaddleSerieWaves_mkbound10.csv").read_text().splitlines()
    assert waves[0] == "wave;t_start [s];period [s];height [m]" and len(waves) > 50


def test_serie_lines(tmp_path):
    (d,), reader = paddles(tmp_path, "piston_spectrum", '<saveserie timemin="0" timemax="300" timedt="0.05" xpos="0"/>'
                                                       '<saveseriewaves timemin="10" timemax="1000" xpos="2"/>')
    assert d["saveserie"] == {"timemin": 0.0, "timemax": 300.0, "timedt": 0.05, "xpos": 0.0}
    assert d["saveseriewaves"] == {"timemin": 10.0, "timemax": 1000.0, "xpos": 2.0} and not reader.warnings
    with pytest.raises(CaseError, match="timemax=5 is not after timemin=10") as e:
        paddles(tmp_path, "piston_spectrum", '<saveseriewaves timemin="10" timemax="5"/>')
    assert e.value.element == "saveseriewaves"
    with pytest.raises(CaseError, match="unknown attribute 'timedt' of <saveseriewaves>"):
        paddles(tmp_path, "piston_spectrum", '<saveseriewaves timemax="5" timedt="0.1"/>')


def test_zero_upcrossing_of_a_sine():
    from sphdvi.io.paddle_motion import zero_upcrossing_waves
    t = np.linspace(0.0, 10.0, 100001)
    waves = zero_upcrossing_waves(t, 0.3 * np.sin(2 * np.pi * t / 1.25 + 0.4))
    assert len(waves) == 7
    np.testing.assert_allclose(waves[:, 1], 1.25, rtol=1e-6)
    np.testing.assert_allclose(waves[:, 2], 0.6, rtol=1e-6)


def test_serie_waves_give_the_sea_state():
    """Over 1,000 s the significant height H1/3 of the zero up-crossing waves is within 10 % of the
    case's Hm0 (narrow-band theory: H1/3 ≈ 0.95-1.0 Hm0) and their mean period that of Tz = √(m0/m2)."""
    from sphdvi.io.paddle_motion import serie_waves_table
    p = SpectrumPaddle({**SPECTRUM, "waves": 100})
    names, rows = serie_waves_table(p, {"timemin": 0.0, "timemax": 1000.0, "xpos": 1.0})
    h = np.sort(rows[:, 3])[::-1]
    h13 = h[: len(h) // 3].mean()
    assert 0.9 * 0.04 < h13 < 1.1 * 0.04
    e, f = p.amp ** 2, p.components["f"]
    assert rows[:, 2].mean() == pytest.approx(math.sqrt(np.sum(e) / np.sum(e * f * f)), rel=0.05)


def test_series_repetition_period():
    """<calcserielength>: 40 regular waves over 0.5-3 fp sit at odd multiples of Δf/2, so the series repeats
    every 2/Δf; stretched bins (irrational edges) do not repeat within 1,000 s."""
    from sphdvi import wavespectra as ws
    reg = ws.components("jonswap", 0.04, 1.4, 40, "regular")
    df = reg["df"][0]
    assert ws.repetition_period(reg["f"], 1000.0) == pytest.approx(2 / df, rel=1e-12)
    assert ws.repetition_period(reg["f"], 1.9 / df) is None
    assert ws.repetition_period(ws.components("jonswap", 0.04, 1.4, 40, "stretched")["f"], 1000.0) is None
    assert ws.repetition_period([0.5], 10.0) == 2.0


def test_calcserielength_is_read_and_reported(tmp_path):
    (d,), reader = paddles(tmp_path, "piston_spectrum", '<calcserielength timemax="1000" comment="x"/>')
    assert d["calcserielength"] == 1000.0 and not reader.warnings
    with pytest.raises(CaseError, match="timemax"):
        paddles(tmp_path, "piston_spectrum", '<calcserielength timemax="0"/>')
    from run.test_run import REPO
    text = (REPO / "cases" / "waveflume2d" / "CaseWaveIrregular2D_Def.xml").read_text()
    case = tmp_path / "Serie_Def.xml"
    case.write_text(text.replace('<discretization value="stretched"', '<discretization value="regular"')
                    .replace("<waves value=\"50\" />", '<waves value="50" /><calcserielength timemax="1000"/>'))
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out"), "--dp", "0.04"])
    assert r.exit_code == 0, r.output
    assert "Irregular series (mkbound 10): repeats every 56 s" in r.output

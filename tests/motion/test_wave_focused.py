"""Focused wave groups (<piston_focused>): NewWave amplitudes, the focus in space and time, the
paddle's stroke per wave, the start and end ramps, and the reader's defaults and refusals."""
import math

import numpy as np
import pytest
from lxml import etree

from sphdvi import wavespectra as ws
from sphdvi.case.wavepaddles_xml import read_wavepaddles
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError
from sphdvi.motion import (FocusedPaddle, MotionSet, group_velocity, newwave_crest, piston_height_to_stroke,
                           wave_number)

G = 9.81


def spec(**kw):
    d = {"type": "piston_focused", "mkbound": 10, "depth": 0.5, "waveheight": 0.05, "waveperiod": 1.5,
         "spectrum": "jonswap", "discretization": "regular", "peakcoef": 3.3, "waves": 64, "randomseed": 0,
         "ramptime": 0.0, "xf": 6.0, "fphase": 0.0, "fpretime": 5.0, "fmovtime": 0.0, "fmovramp": 0.0,
         "maxwaveh": {"nwaves": 1000}, "start": 0.0, "duration": 0.0, "gainstroke": 1.0, "pistondir": [1.0, 0, 0]}
    d.update(kw)
    return d


def test_newwave_crest_is_the_most_probable_largest_of_n():
    """√(2 m0 ln N) with m0 = Hs²/16, half the Rayleigh H_max = Hs √(ln N / 2)."""
    assert newwave_crest(0.1, 1000) == pytest.approx(math.sqrt(2 * (0.1 / 4) ** 2 * math.log(1000)), rel=1e-14)
    assert 2 * newwave_crest(0.1, 1000) == pytest.approx(0.1 * math.sqrt(math.log(1000) / 2), rel=1e-14)
    with pytest.raises(ValueError, match="above 1"):
        newwave_crest(0.1, 1)


def test_group_velocity_limits():
    """Deep water c_g = g/(2ω); shallow water √(g d)."""
    w = 2 * math.pi / 0.8
    assert group_velocity(w, wave_number(0.8, 50.0), 50.0) == pytest.approx(G / (2 * w), rel=1e-9)
    k = wave_number(200.0, 0.1)
    assert group_velocity(2 * math.pi / 200.0, k, 0.1) == pytest.approx(math.sqrt(G * 0.1), rel=1e-4)


def test_the_group_focuses_at_xf_and_tf():
    """Every wave's crest meets at (x_f, t_f): η there is Σ a_i = A; anywhere else along the flume
    and at any other time it is lower; with fphase 180 the focus is a trough of −A."""
    p = FocusedPaddle(spec())
    assert p.amp.sum() == pytest.approx(newwave_crest(0.05, 1000), rel=1e-12)
    assert p.elevation_at(6.0, p.focus_time)[0] == pytest.approx(p.crest, rel=1e-12)
    t = np.linspace(0, 2 * p.focus_time, 40001)
    for x in (2.0, 4.0, 5.5, 6.5, 8.0):
        assert p.elevation_at(x, t).max() < 0.99 * p.crest
    eta = p.elevation_at(6.0, t)
    assert abs(t[np.argmax(eta)] - p.focus_time) <= t[1] - t[0]
    trough = FocusedPaddle(spec(fphase=180.0))
    assert trough.elevation_at(6.0, trough.focus_time)[0] == pytest.approx(-trough.crest, rel=1e-12)
    # each wave carries its bin's energy share: a_i ∝ S(f_i) Δf_i
    c = p.components
    np.testing.assert_allclose(p.amp / p.amp.sum(), ws.jonswap(c["f"], 0.05, 1.5) * c["df"]
                               / np.sum(ws.jonswap(c["f"], 0.05, 1.5) * c["df"]), rtol=1e-12)


def test_focus_time_and_distance_from_the_face():
    """t_f = fpretime + (x_f − face)/c_g,min, the slowest wave the highest; place() moves the face."""
    p = FocusedPaddle(spec())
    k_top = wave_number(1 / p.components["f"][-1], 0.5)
    cg = group_velocity(2 * math.pi * p.components["f"][-1], k_top, 0.5)
    assert p.cg_min == pytest.approx(float(cg), rel=1e-12)
    assert p.focus_time == pytest.approx(5.0 + 6.0 / float(cg), rel=1e-12)
    p.place(-0.4)
    assert p.distance == pytest.approx(6.4) and p.focus_time == pytest.approx(5.0 + 6.4 / float(cg), rel=1e-12)
    assert p.elevation_at(6.0, p.focus_time)[0] == pytest.approx(p.crest, rel=1e-12)
    with pytest.raises(ValueError, match="not in front of the piston's face"):
        p.place(6.5)


def test_stroke_is_biesels_per_wave_and_starts_at_rest():
    """X(τ) = Σ S_i/2 [sin(ω_i τ + φ_i) − sin φ_i], S_i = 2 a_i / (H/S)(k_i d); the rate its derivative."""
    p = FocusedPaddle(spec(gainstroke=1.5))
    k = np.array([wave_number(1 / f, 0.5) for f in p.components["f"]])
    half = p.amp / np.array([piston_height_to_stroke(ki, 0.5) for ki in k])
    assert p.amp.sum() == pytest.approx(1.5 * p.crest)
    w = 2 * np.pi * p.components["f"]
    for t in (0.3, 7.7, p.focus_time - 1.0):
        x = np.sum(half * (np.sin(w * t + p.phase) - np.sin(p.phase)))
        v = np.sum(half * w * np.cos(w * t + p.phase))
        assert p.stroke_position(t) == pytest.approx((x, v), rel=1e-12, abs=1e-15)
        num = (p.stroke_position(t + 1e-6)[0] - p.stroke_position(t - 1e-6)[0]) / 2e-6
        assert num == pytest.approx(v, rel=1e-6)
    assert p.stroke_position(0.0) == (0.0, 0.0)


def test_ramps_and_the_end_of_the_motion():
    base = FocusedPaddle(spec(fpretime=1.0))
    ramped = FocusedPaddle(spec(fpretime=1.0, ramptime=2.0))
    free = base.stroke_position(0.5)[0] - base.mean_position()
    assert ramped.mean_position() == 0.0 and ramped.stroke_position(0.5)[0] == pytest.approx(0.25 * free)
    ended = FocusedPaddle(spec(fpretime=1.0, ramptime=2.0, fmovtime=20.0, fmovramp=4.0))
    assert ended.stroke_position(10.0) == pytest.approx(ramped.stroke_position(10.0))
    x17, v17 = ended.stroke_position(17.0)      # 3 s before the end: a quarter of the way down
    assert x17 == pytest.approx(0.75 * ramped.stroke_position(17.0)[0])
    assert v17 == pytest.approx(0.75 * ramped.stroke_position(17.0)[1] - ramped.stroke_position(17.0)[0] / 4.0)
    assert ended.stroke_position(20.0) == (0.0, 0.0) and ended.stroke_position(25.0) == (0.0, 0.0)
    stopped = FocusedPaddle(spec(fpretime=1.0, ramptime=2.0, fmovtime=20.0))     # no final ramp: it stays
    assert stopped.stroke_position(30.0) == (pytest.approx(ramped.stroke_position(20.0)[0]), 0.0)


def test_maxwaveh_time_counts_zero_crossing_periods():
    p = FocusedPaddle(spec(maxwaveh={"time": 3600.0}))
    e = p.components["amp"] ** 2
    tz = math.sqrt(np.sum(e) / np.sum(e * p.components["f"] ** 2))
    assert p.nwaves == pytest.approx(3600.0 / tz, rel=1e-12)
    assert p.crest == pytest.approx(newwave_crest(0.05, 3600.0 / tz), rel=1e-12)


def test_motionset_places_the_face_from_the_particles():
    ms = MotionSet([], [spec()])
    pos = np.array([[-0.3, 0, 0.1], [-0.1, 0, 0.2], [4.0, 0, 0.1]])
    ms.place_paddles(pos, np.array([10, 10, -1]))
    assert ms.paddles[10].face == pytest.approx(-0.1)


def paddles(tmp_path, inner, waveorder=1):
    xml = ('<wavepaddles>\n<piston_focused><mkbound value="10"/><depth value="0.5"/><spectrum value="jonswap"/>'
           f'<waveheight value="0.05"/><waveperiod value="1.5"/><waveorder value="{waveorder}"/>\n{inner}'
           '</piston_focused></wavepaddles>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_wavepaddles(reader, etree.fromstring(xml)), reader


def test_reader_defaults(tmp_path):
    (d,), reader = paddles(tmp_path, '<xf value="6"/>')
    assert (d["discretization"], d["waves"], d["fpretime"], d["fphase"], d["fmovtime"], d["fmovramp"],
            d["maxwaveh"]) == ("regular", 128, 5.0, 0.0, 0.0, 0.0, {"nwaves": 1000})
    assert d["pistondir"] == [1.0, 0.0, 0.0] and not reader.warnings
    (d,), _ = paddles(tmp_path, '<xf value="6"/><maxwaveh time="600"/><discretization value="cosstretched"/>'
                                '<waves value="40"/><fmovtime value="30"/><fmovramp value="2"/>')
    assert (d["maxwaveh"], d["discretization"], d["waves"], d["fmovramp"]) == ({"time": 600.0}, "cosstretched", 40, 2.0)


@pytest.mark.parametrize("inner, expect", [
    ('<maxwaveh nwaves="500"/><maxwaveh time="0"/>', {"nwaves": 500}),     # DualSPHysics's format doc: both
    ('<maxwaveh nwaves="500" time="600"/>', {"time": 600.0}),               # a positive time decides
    ('<maxwaveh time="0"/>', {"nwaves": 1000}),
    ("<maxwaveh/>", {"nwaves": 1000}),
])
def test_maxwaveh_as_dualsphysics_writes_it(tmp_path, inner, expect):
    (d,), reader = paddles(tmp_path, '<xf value="6"/>' + inner)
    assert d["maxwaveh"] == expect and not reader.warnings


@pytest.mark.parametrize("inner, element, match", [
    ("", "piston_focused", "missing <xf>"),
    ('<xf value="6"/><maxwaveh nwaves="1"/>', "maxwaveh", "nwaves=1"),
    ('<xf value="6"/><maxwaveh time="-1"/>', "maxwaveh", "time=-1 is negative"),
    ('<xf value="6"/><fpretime value="-1"/>', "fpretime", "negative"),
    ('<xf value="6"/><fmovramp value="2"/>', "fmovramp", "without <fmovtime>"),
    ('<xf value="6"/><serieini value="2"/>', "serieini", "unknown element <serieini>"),
])
def test_reader_refusals(tmp_path, inner, element, match):
    with pytest.raises(CaseError, match=match) as e:
        paddles(tmp_path, inner)
    assert e.value.element == element


def test_second_order_is_read(tmp_path):
    (d,), reader = paddles(tmp_path, '<xf value="6"/>', waveorder=2)
    assert d["waveorder"] == 2 and FocusedPaddle(d).second_order


def test_gencase_warns_when_the_group_cannot_form(tmp_path):
    """DualSPHysics's format-doc numbers (x_f 12.5 m, T_p 1.5 s, fpretime 0, fmovtime 30 s) in W7's flume
    focus at 31.65 s by sphdvi's rule, after a TimeMax of 30 s: warned; the paddle stopping at 30 s (its
    ramp down from 29 s) is not, its last (fastest) waves having left it at 23.8 s. Stopped at 20 s it is
    warned about too. A focus past the water's end (W7's flume is 6 m long) is warned about."""
    from click.testing import CliRunner

    from run.test_run import REPO
    from sphdvi.cli import main
    text = (REPO / "cases" / "waveflume2d" / "CaseWaveFocused2D_Def.xml").read_text()
    text = (text.replace('<xf value="2"', '<xf value="12.5"').replace('<waveperiod value="1.4"', '<waveperiod value="1.5"')
            .replace('<parameter key="TimeMax" value="8"', '<parameter key="TimeMax" value="30"'))

    def warnings(fmovtime):
        case = tmp_path / "Late_Def.xml"
        case.write_text(text.replace('<fmovtime value="8"', f'<fmovtime value="{fmovtime}"'))
        r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out"), "--dp", "0.05"])
        assert r.exit_code == 0, r.output
        return [line for line in r.output.splitlines() if "warning: <piston_focused>" in line
                or "warning: <xf>" in line]

    found = warnings(30)
    assert len(found) == 2
    (beyond,) = [w for w in found if "beyond the water" in w]
    (late,) = [w for w in found if "focuses at" in w]
    assert "the focus xf=12.5 m lies beyond the water drawn (it ends at 5.9" in beyond    # W7's flume is 6 m long
    assert "the group focuses at t = 31.6" in late and "after the run ends (TimeMax 30 s)" in late
    found = warnings(20)
    assert len(found) == 3
    (stop,) = [w for w in found if "stops moving" in w]
    assert "the paddle stops moving at t = 19 s" in stop and "before the group's last (fastest) waves leave it at 23.79 s" in stop


def test_gencase_prints_the_second_order_crest(tmp_path):
    """W8's case (W7's group at second order): gencase prints the linear crest A and the crest with the
    group's bound waves, a few per cent higher."""
    import re

    from click.testing import CliRunner

    from run.test_run import REPO
    from sphdvi.cli import main
    case = REPO / "cases" / "waveflume2d" / "CaseWaveFocused2ndOrder2D_Def.xml"
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out"), "--dp", "0.04"])
    assert r.exit_code == 0, r.output
    (line,) = [ln for ln in r.output.splitlines() if ln.startswith("Focused group")]
    m = re.search(r"crest ([\d.]+) m \(with its bound waves ([\d.]+) m\) at x = 2 m", line)
    assert m, line
    linear, second = float(m.group(1)), float(m.group(2))
    assert linear == pytest.approx(0.02788, abs=1e-5) and 1.02 < second / linear < 1.08

"""Motion and wave-paddle input: DualSPHysics's motion-file conventions, and every bad input
a case error at gencase (file:line, element, what was expected), never a crash or a hang in the run."""
from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner
from lxml import etree

from sphdvi.case.reader import read_motion
from sphdvi.case.wavepaddles_xml import read_wavepaddles
from sphdvi.case.xmldoc import CaseReader
from sphdvi.cli import main
from sphdvi.errors import CaseError
from sphdvi.motion import (MotionSet, WavePaddle, chain_transform, flap_height_to_stroke,
                           piston_height_to_stroke, wave_number)


def read(tmp_path, body, files=None, begin='<begin mov="1" start="0"/>'):
    """read_motion on one objreal (mkbound 1) whose movements are ``body``; the movement
    element is on line 3 of case.xml."""
    for name, content in (files or {}).items():
        data = content if isinstance(content, bytes) else content.encode()
        (tmp_path / name).write_bytes(data)
    xml = f'<casedef>\n<motion><objreal ref="1">{begin}\n{body}\n</objreal></motion>\n</casedef>'
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_motion(reader, etree.fromstring(xml)), reader


def rectfile(attrs='fields="4" fieldtime="0" fieldx="1" fieldy="2" fieldz="3"', tag="mvrectfile"):
    return f'<{tag} id="1" duration="100"><file name="m.csv" {attrs}/></{tag}>'


DSPH_FILE = "#Time(s);X(m);Y(m);Z(m)\r\n0.0;0.0;0.0;0.0\r\n1.0;0.5;0.1;-0.2\r\n2.0;0.5;0.3;-0.2\r\n"


# -- motion files as DualSPHysics writes them ------------------------------------------
@pytest.mark.parametrize("content", [
    DSPH_FILE,
    "time;x;y;z\n0;0;0;0\n1;0.5;0.1;-0.2\n2;0.5;0.3;-0.2\n",                 # header without '#'
    "0 0 0 0\n1 0.5 0.1 -0.2\n2\t0.5\t0.3\t-0.2\n",                           # spaces and tabs
    "0,0,0,0\n1,0.5,0.1,-0.2\n2,0.5,0.3,-0.2,99\n",                          # commas, an extra column
])
def test_fields_is_the_column_count(tmp_path, content):
    """fields="4" is the number of columns of the file (it was taken for a 5th column index)."""
    (m,), _ = read(tmp_path, rectfile(), {"m.csv": content})
    mv = m["movements"][0]
    assert mv["ncols"] == 4 and mv["fields"] == {"fieldtime": 0, "fieldx": 1, "fieldy": 2, "fieldz": 3}
    x, v = chain_transform(m, 1.5).apply(np.zeros((1, 3)))
    assert x[0] == pytest.approx([0.5, 0.2, -0.2]) and np.all(np.isfinite(v))


def test_columns_in_any_order_and_unused_columns(tmp_path):
    content = "# x; unused; t\n0.0; 7; 0\n1.0; 8; 2\n"
    (m,), _ = read(tmp_path, rectfile('fields="3" fieldtime="2" fieldx="0"'), {"m.csv": content})
    assert chain_transform(m, 1.0).apply(np.zeros((1, 3)))[0][0] == pytest.approx([0.5, 0, 0])


@pytest.mark.parametrize("alias", ["mvfile", "mvpredef"])
def test_dualsphysics_aliases_of_mvrectfile(tmp_path, alias):
    (m,), _ = read(tmp_path, rectfile(tag=alias), {"m.csv": DSPH_FILE})
    assert m["movements"][0]["type"] == "mvrectfile"
    assert chain_transform(m, 1.0).apply(np.zeros((1, 3)))[0][0] == pytest.approx([0.5, 0.1, -0.2])


def test_rotfile_default_and_explicit_columns(tmp_path):
    axis = '<axisp1 x="0" y="0" z="0"/><axisp2 x="0" y="1" z="0"/>'
    body = f'<mvrotfile id="1" duration="100"><file name="a.csv"/>{axis}</mvrotfile>'
    (m,), _ = read(tmp_path, body, {"a.csv": "#time;angle\n0;0\n1;90\n"})
    x = chain_transform(m, 1.0).apply(np.array([[1.0, 0, 0]]))[0]
    # DualSPHysics's sense: +90 degrees about (0,0,0) -> (0,1,0) takes +x to +z
    assert x[0] == pytest.approx([0, 0, 1], abs=1e-12)
    body = f'<mvrotfile id="1" duration="100"><file name="a.csv" fields="3" fieldtime="1" fieldang="2"/>{axis}</mvrotfile>'
    (m,), _ = read(tmp_path, body, {"a.csv": "5;0;0\n5;1;90\n"})
    assert chain_transform(m, 1.0).apply(np.array([[1.0, 0, 0]]))[0][0] == pytest.approx([0, 0, 1], abs=1e-12)


def test_motionset_reads_the_file_again_at_run_time(tmp_path):
    (m,), _ = read(tmp_path, rectfile(), {"m.csv": DSPH_FILE})
    (tmp_path / "m.csv").write_text("0 0 0 0\n")          # changed after gencase
    with pytest.raises(CaseError, match="one data row") as e:
        MotionSet([m]).transform(1, 0.5)
    assert e.value.file == str(tmp_path / "m.csv")


# -- bad <file> attributes and bad files: errors at gencase --------------------------------
@pytest.mark.parametrize("attrs,match", [
    ('fields="4" fieldtime="0" fieldx="4"', r"fieldx=4 is not a column of a file of fields=4 columns"),
    ('fields="2" fieldtime="0" fieldx="1" fieldz="2"', r"fieldz=2 is not a column"),
    ('fields="3" fieldtime="1" fieldx="1"', r"fieldx=1 is the time column"),
    ('fields="1" fieldtime="0"', r"fields='1' is below 2"),
    ('fields="4" fieldtime="-1" fieldx="1"', r"fieldtime='-1' is below 0"),
])
def test_bad_field_attributes(tmp_path, attrs, match):
    with pytest.raises(CaseError, match=match) as e:
        read(tmp_path, rectfile(attrs), {"m.csv": DSPH_FILE})
    assert e.value.element == "file" and e.value.line == 3
    assert str(e.value).startswith(str(tmp_path / "case.xml") + ":3: <file>:")


@pytest.mark.parametrize("content,match,line", [
    ("", "no data rows", None),
    ("#Time;X;Y;Z\n", "no data rows", None),
    ("time x y z\n", "no data rows", None),
    (b"\x00\xff\xfe\x00garbage\n", "not a text file", None),
    ("#t;x;y;z\n0;0;0;0\n", r"one data row \(line 2\)", None),
    ("0;0;0;0\n1;nan;0;0\n2;0;0;0\n", r"column 1 \(fieldx\) is nan", 2),
    ("0;0;0;0\n1;0;0;inf\n", r"column 3 \(fieldz\) is inf", 2),
    ("#h\n1;0;0;0\n0.5;0.1;0;0\n", r"time 0.5 comes before 1 \(line 2\)", 3),
    ("0;0;0;0\n1;0;0;0\n1;0.1;0;0\n0.9;0;0;0\n", r"time 0.9 comes before 1 \(line 3\)", 4),
    ("0;0;0;0\n1;0;0\n", "3 column", 2),
    ("0;0;0;0\n1;abc;0;0\n", "'1;abc;0;0' is not numeric", 2),
])
def test_bad_motion_files(tmp_path, content, match, line):
    with pytest.raises(CaseError, match=match) as e:
        read(tmp_path, rectfile(), {"m.csv": content})
    assert e.value.element == "file" and e.value.line == 3
    data = str(tmp_path / "m.csv") + (f":{line}:" if line else ":")
    assert data in e.value.message


def test_rows_going_back_beyond_the_movements_reach_are_left_out(tmp_path):
    """MoorDynPlus's example 03_WavesMoorings3D plays 30 s of a piston file whose last rows go
    back from 49.575 to 35.48 s: DualSPHysics never reaches them, and sphdvi leaves them out with
    a warning (file:line), at gencase and at run time alike."""
    content = "0;0;0;0\n1;1;0;0\n2;2;0;0\n3;3;0;0\n1.5;9;0;0\n1.6;9;0;0\n"
    body = '<mvrectfile id="1" duration="2"><file name="m.csv" fields="4" fieldx="1"/></mvrectfile>'
    (m,), reader = read(tmp_path, body, {"m.csv": content})
    (w,) = list(reader.warnings)
    assert f"{tmp_path / 'm.csv'}:5: the time goes back after line 4 (3 s)" in w
    assert "from 0 s for 2 s" in w and "left out (2 rows)" in w
    for t, x in ((1.5, 1.5), (2.0, 2.0), (5.0, 2.0)):        # the movement stops after 2 s
        assert chain_transform(m, t).apply(np.zeros((1, 3)))[0][0, 0] == pytest.approx(x)
    assert MotionSet([m]).transform(1, 1.5).d[0] == pytest.approx(1.5)      # the run's reading


@pytest.mark.parametrize("duration,flash", [("3.5", False), ("-3.5", True)])
def test_rows_going_back_within_the_movements_reach_are_an_error(tmp_path, duration, flash):
    """The same file played longer than its rows before the jump back reach (a flash's |duration|
    too): the file is refused, its line named."""
    content = "0;0;0;0\n1;1;0;0\n2;2;0;0\n3;3;0;0\n1.5;9;0;0\n1.6;9;0;0\n"
    body = f'<mvrectfile id="1" duration="{duration}"><file name="m.csv" fields="4" fieldx="1"/></mvrectfile>'
    with pytest.raises(CaseError, match=r"time 1.5 comes before 3 \(line 4\)") as e:
        read(tmp_path, body, {"m.csv": content})
    assert f"{tmp_path / 'm.csv'}:5:" in e.value.message


def test_missing_motion_file(tmp_path):
    with pytest.raises(CaseError, match="file 'm.csv' not found") as e:
        read(tmp_path, rectfile())
    assert e.value.element == "file"


def test_rectfile_without_coordinates_warns(tmp_path):
    _, reader = read(tmp_path, rectfile('fields="2" fieldtime="0"'), {"m.csv": "0 0\n1 1\n"})
    (w,) = list(reader.warnings)
    assert ":3: warning: <file>: none of fieldx, fieldy, fieldz" in w


def test_cli_bad_motion_file_is_exit_2(tmp_path):
    case = tmp_path / "Case_Def.xml"
    case.write_text(CASE.replace("MOV", rectfile()))
    (tmp_path / "m.csv").write_text("#t x y z\n0 0 0 0\n")
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out"), "-q"])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert f"{case}:" in r.output and "<file>:" in r.output and "one data row" in r.output


# -- loops that would never advance time ------------------------------------------------
@pytest.mark.parametrize("body,ids", [
    ('<mvrect id="1" duration="0" next="1"><vel x="1" y="0" z="0"/></mvrect>', "1 -> 1"),
    ('<mvrect id="1" duration="0" next="2"><vel x="1" y="0" z="0"/></mvrect><wait id="2" duration="0" next="1"/>', "1 -> 2 -> 1"),
    ('<wait id="1" duration="1" next="2"/><mvrect id="2" duration="0" next="3"><vel x="1" y="0" z="0"/></mvrect>'
     '<wait id="3" duration="0" next="2"/>', "2 -> 3 -> 2"),
])
def test_zero_duration_loop_is_an_error(tmp_path, body, ids):
    with pytest.raises(CaseError, match=f"movements {ids} loop forever without advancing time") as e:
        read(tmp_path, body)
    assert e.value.line == 3 and e.value.element in ("mvrect", "wait")


@pytest.mark.parametrize("body,x10,v10", [
    ('<mvrect id="1" duration="0.5" next="2"><vel x="1" y="0" z="0"/></mvrect><wait id="2" duration="0" next="1"/>',
     10.0, 1.0),                                                                            # 20 loops of 0.5 m
    ('<mvrect id="1" duration="100" next="1"><vel x="1" y="0" z="0"/></mvrect>', 10.0, 1.0),  # loops every 100 s
    ('<mvrect id="1" duration="0" next="2"><vel x="1" y="0" z="0"/></mvrect><wait id="2" duration="0"/>',
     0.0, 0.0),                                                                             # ends, never moved
])
def test_loops_that_advance_are_accepted(tmp_path, body, x10, v10):
    """Accepted, and walked as DualSPHysics's JMotion walks them: the loop of a 0.5 s move at 1 m/s
    repeated with a zero wait keeps the body going at 1 m/s (x = 10 m at t = 10 s, 10.2 m at 10.2 s),
    as does a 100 s move that loops onto itself; a zero-length move followed by a zero wait leaves
    it where it was."""
    (m,), _ = read(tmp_path, body)
    for t in (10.0, 10.2):
        x, v = chain_transform(m, t).apply(np.zeros((1, 3)))
        assert x[0] == pytest.approx([x10 * t / 10.0, 0, 0], abs=1e-9)
        assert v[0] == pytest.approx([v10, 0, 0], abs=1e-12)


def test_zero_loop_at_run_time_is_a_case_error():
    m = {"ref": 1, "begin": {"mov": 1, "start": 0.0, "finish": None}, "parents": [],
         "movements": [{"type": "wait", "id": 1, "duration": 0.0, "next": 1}]}
    with pytest.raises(CaseError, match="without advancing time"):
        chain_transform(m, 1.0)


def test_begin_finish(tmp_path):
    body = '<mvrect id="1" duration="100"><vel x="1" y="0" z="0"/></mvrect>'
    (m,), _ = read(tmp_path, body, begin='<begin mov="1" start="0.5" finish="-1"/>')
    assert m["begin"]["finish"] is None      # DualSPHysics: -1 = no end
    with pytest.raises(CaseError, match="finish=0.2 comes before start=0.5") as e:
        read(tmp_path, body, begin='<begin mov="1" start="0.5" finish="0.2"/>')
    assert e.value.element == "begin"


# -- degenerate axes ------------------------------------------------------------------
SAME = '<axisp1 x="1" y="2" z="3"/><axisp2 x="1" y="2" z="3"/>'


@pytest.mark.parametrize("body", [
    f'<mvrot id="1" duration="100"><vel ang="10"/>{SAME}</mvrot>',
    f'<mvrotace id="1" duration="100"><ace ang="10"/>{SAME}</mvrotace>',
    f'<mvrotsinu id="1" duration="100"><freq v="1"/><ampl v="10"/>{SAME}</mvrotsinu>',
    f'<mvcir id="1" duration="100"><vel ang="10"/><ref x="2" y="0" z="0"/>{SAME}</mvcir>',
    f'<mvcirace id="1" duration="100"><ace ang="10"/><ref x="2" y="0" z="0"/>{SAME}</mvcirace>',
    f'<mvcirsinu id="1" duration="100"><freq v="1"/><ampl v="10"/><ref x="2" y="0" z="0"/>{SAME}</mvcirsinu>',
    f'<mvrotfile id="1" duration="100"><file name="a.csv"/>{SAME}</mvrotfile>',
])
def test_rotation_axis_of_two_equal_points(tmp_path, body):
    with pytest.raises(CaseError, match="axisp1 and axisp2 are the same point") as e:
        read(tmp_path, body, {"a.csv": "0 0\n1 10\n"})
    assert e.value.element == "axisp2" and e.value.line == 3


def test_unknown_movement_named(tmp_path):
    with pytest.raises(CaseError, match="unknown motion element <mvbogus>") as e:
        read(tmp_path, '<mvbogus id="1" duration="1"/>')
    assert e.value.line == 3


# -- wave paddles ---------------------------------------------------------------------
def paddles(tmp_path, inner, tag="piston"):
    xml = (f'<wavepaddles>\n<{tag}><mkbound value="1"/><depth value="1"/><waveheight value="0.1"/>'
           f'<waveperiod value="1"/>\n{inner}</{tag}></wavepaddles>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_wavepaddles(reader, etree.fromstring(xml)), reader


@pytest.mark.parametrize("tag", ["ramp", "start", "duration"])
def test_negative_paddle_times(tmp_path, tag):
    with pytest.raises(CaseError, match=f"<{tag}> value=-1 is negative") as e:
        paddles(tmp_path, f'<{tag} value="-1"/>')
    assert e.value.element == tag and e.value.line == 3


def test_zero_pistondir_and_equal_flap_axis(tmp_path):
    with pytest.raises(CaseError, match="zero vector") as e:
        paddles(tmp_path, '<pistondir x="0" y="0" z="0"/>')
    assert e.value.element == "pistondir"
    with pytest.raises(CaseError, match="same point") as e:
        paddles(tmp_path, '<flapaxis0 x="0" y="0" z="0"/><flapaxis1 x="0" y="0" z="0"/>', tag="flap")
    assert e.value.element == "flapaxis1"


def test_unimplemented_paddle_options_warn(tmp_path):
    """<usefiledata> is warned about; <savemotion> is read (tests/motion/test_paddle_savemotion.py)."""
    inner = '<savemotion periods="24" periodsteps="20" xpos="2" zpos="-0.15"/>\n<usefiledata value="1"/>'
    (p,), reader = paddles(tmp_path, inner)
    text = "\n".join(reader.warnings)
    assert len(reader.warnings) == 1
    assert "case.xml:4: warning: <usefiledata>:" in text and "not implemented by sphdvi" in text
    assert p["savemotion"][0]["periods"] == 24.0


@pytest.mark.parametrize("period", [1e-3, 1e-5, 1.0, 100.0, 1e4])
def test_paddle_stroke_any_period(tmp_path, period):
    """A very short period (deep water, kd ~ 4e6 at T = 1 ms) overflowed cosh(2kd)."""
    for order in (1, 2):
        p = WavePaddle({"type": "piston", "mkbound": 1, "depth": 1.0, "waveheight": 0.1,
                        "waveperiod": period, "waveorder": order})
        assert math.isfinite(p.stroke) and math.isfinite(p.second)
        assert all(math.isfinite(v) for v in p.stroke_position(0.3 * period))
    f = WavePaddle({"type": "flap", "mkbound": 1, "depth": 1.0, "waveheight": 0.1, "waveperiod": period,
                    "flapaxis0": [0, 0, 0], "flapaxis1": [0, 1, 0]})
    assert math.isfinite(f.stroke)


def test_transfer_functions_deep_and_shallow_limits():
    assert piston_height_to_stroke(1e6, 1.0) == 2.0
    assert flap_height_to_stroke(1e6, 1.0) == pytest.approx(2 * (1 - 1e-6), rel=1e-12)
    # closed forms where cosh/sinh do not overflow
    for kd in (1e-3, 0.3, 1.0, 3.0, 30.0):
        ref_p = 2 * (math.cosh(2 * kd) - 1) / (math.sinh(2 * kd) + 2 * kd)
        ref_f = 4 * math.sinh(kd) / kd * (1 - math.cosh(kd) + kd * math.sinh(kd)) / (math.sinh(2 * kd) + 2 * kd)
        assert piston_height_to_stroke(kd, 1.0) == pytest.approx(ref_p, rel=1e-9)
        assert flap_height_to_stroke(kd, 1.0) == pytest.approx(ref_f, rel=1e-7)
    assert wave_number(1e-3, 1.0) == pytest.approx((2 * math.pi / 1e-3) ** 2 / 9.81, rel=1e-12)


CASE = """<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef>
  <constantsdef><gravity x="0" y="0" z="-9.81"/><rhop0 value="1000"/><hswl value="0" auto="true"/>
    <gamma value="7"/><speedsystem value="0" auto="true"/><coefsound value="20"/>
    <speedsound value="0" auto="true"/><coefh value="1.0"/><cflnumber value="0.2"/></constantsdef>
  <mkconfig boundcount="240" fluidcount="9"/>
  <geometry><definition dp="0.1"><pointmin x="-1" y="0" z="-1"/><pointmax x="4.5" y="0" z="3.5"/></definition>
    <commands><mainlist>
      <setmkfluid mk="0"/><drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0"/><size x="1" y="2" z="2"/></drawbox>
      <setmkbound mk="0"/><drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0"/><size x="4" y="2" z="3"/></drawbox>
      <setmkbound mk="1"/><drawbox><boxfill>solid</boxfill><point x="3" y="-1" z="0.2"/><size x="0.2" y="2" z="1"/></drawbox>
    </mainlist></commands></geometry>
  <motion><objreal ref="1"><begin mov="1" start="0"/>
MOV
  </objreal></motion>
</casedef>
<execution><parameters><parameter key="TimeMax" value="0.01"/><parameter key="TimeOut" value="0.01"/></parameters></execution>
</case>
"""


# -- irregular waves: <piston_spectrum> / <flap_spectrum> ---------------------------------
def spectrum_paddles(tmp_path, inner, tag="piston_spectrum", spectrum='<spectrum value="jonswap"/>'):
    return paddles(tmp_path, spectrum + inner, tag=tag)


def test_spectrum_paddle_read_with_dualsphysics_defaults(tmp_path):
    """As DesignSPHysics writes it: stretched, gamma 3.3, 50 waves by default; seed 0; the
    serieini/ramptime of the case; <fixeddepth value="0"> accepted (also in a regular piston)."""
    (p,), reader = spectrum_paddles(tmp_path, '<fixeddepth value="0"/><serieini value="1.5" autofit="false"/>'
                                    '<ramptime value="2"/><pistondir x="1" y="0" z="0"/>')
    assert list(reader.warnings) == []
    assert (p["type"], p["spectrum"], p["discretization"], p["peakcoef"], p["waves"], p["randomseed"]) == \
        ("piston_spectrum", "jonswap", "stretched", 3.3, 50, 0)
    assert (p["serieini"], p["ramptime"], p["waveorder"]) == (1.5, 2.0, 1)
    sets = MotionSet([], [p])
    assert type(sets.paddles[1]).__name__ == "SpectrumPaddle" and sets.paddles[1].amp.size == 50
    (q,), reader = paddles(tmp_path, '<fixeddepth value="0"/>')
    assert q["type"] == "piston" and list(reader.warnings) == []
    (f,), _ = spectrum_paddles(tmp_path, '<flapaxis0 x="0" y="-1" z="0"/><flapaxis1 x="0" y="1" z="0"/>'
                               '<discretization value="Random"/><waves value="12"/>', tag="flap_spectrum",
                               spectrum='<spectrum value="Pierson-Moskowitz"/>')
    assert (f["spectrum"], f["discretization"], f["waves"]) == ("pierson-moskowitz", "random", 12)


@pytest.mark.parametrize("inner, spectrum, message, element", [
    ("", "", "missing <spectrum>", "piston_spectrum"),
    ("", '<spectrum value="bretschneider"/>', "unknown spectrum 'bretschneider'", "spectrum"),
    ('<discretization value="even"/>', None, "unknown discretization 'even'", "discretization"),
    ('<waves value="0"/>', None, "<waves> value=0", "waves"),
    ('<peakcoef value="0.5"/>', None, "<peakcoef> value=0.5", "peakcoef"),
    ('<waveorder value="3"/>', None, "waveorder 3", "piston_spectrum"),
    ('<serieini value="-1"/>', None, "<serieini> value=-1 is negative", "serieini"),
    ('<ramptime value="-2"/>', None, "<ramptime> value=-2 is negative", "ramptime"),
    ('<ramp value="2"/>', None, "unknown element <ramp> in <piston_spectrum>", "ramp"),
])
def test_bad_spectrum_options_are_case_errors(tmp_path, inner, spectrum, message, element):
    kw = {} if spectrum is None else {"spectrum": spectrum}
    with pytest.raises(CaseError, match=message) as e:
        spectrum_paddles(tmp_path, inner, **kw)
    assert e.value.element == element and e.value.line in (2, 3)


def test_unimplemented_spectrum_options_warn(tmp_path):
    inner = ('<serieini value="0" autofit="true"/>\n<saveserie timemin="0" timemax="100" timedt="0.05"/>\n'
             '<saveseriewaves timemin="0" timemax="100" xpos="2"/>\n<fixeddepth value="0.2"/>\n'
             '<calcserielength timemax="1000"/>')     # _FmtXML_WavePaddles.xml (27-03-2023) lists it
    (d,), reader = spectrum_paddles(tmp_path, inner)
    text = "\n".join(reader.warnings)
    assert len(reader.warnings) == 2          # <saveserie>, <saveseriewaves>, <calcserielength>: read
    for tag, line in (("serieini", 3), ("fixeddepth", 6)):
        assert f"case.xml:{line}: warning: <{tag}>" in text
    assert "autofit is ignored" in text
    assert d["saveserie"]["timemax"] == 100.0 and d["saveseriewaves"]["xpos"] == 2.0
    assert d["calcserielength"] == 1000.0


@pytest.mark.parametrize("inner, expect", [
    ('<depth value="1"/><waveheight value="0.1"/><waveperiod value="2"/>', []),
    ('<depth value="1"/><waveheight value="0.5"/><waveperiod value="1"/>', ["Miche"]),
    ('<depth value="0.1"/><waveheight value="0.08"/><waveperiod value="20"/>', ["McCowan"]),
    ('<depth value="0.3"/><waveheight value="0.05"/><waveperiod value="4"/><waveorder value="2"/>', ["Madsen"]),
    ('<depth value="0.3"/><waveheight value="0.05"/><waveperiod value="4"/>', []),
])
def test_breaking_and_second_order_range_are_warned(tmp_path, inner, expect):
    """DualSPHysics's warnings on the waves asked for: steepness breaking (H/L > 0.142 tanh kd), depth
    breaking (H/d > 0.78), second order past Madsen's Ursell limit (H L²/d³ >= 8π²/3)."""
    xml = f'<wavepaddles>\n<piston><mkbound value="1"/>{inner}</piston></wavepaddles>'
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    read_wavepaddles(reader, etree.fromstring(xml))
    text = "\n".join(reader.warnings)
    assert len(reader.warnings) == len(expect)
    for name in expect:
        assert name in text and "case.xml:2: warning: <piston>" in text


# -- JMotion::ReadXml's rules -----------------------------------------------------------
RECT1 = '<mvrect id="1" duration="1"{}><vel x="1" y="0" z="0"/></mvrect>'


def test_next_zero_is_no_next(tmp_path):
    """next="0" is DualSPHysics's "no next" (JMotionObj::LinkMovs: if(NextId)); it was refused."""
    (m,), _ = read(tmp_path, RECT1.format(' next="0"'))
    assert m["movements"][0]["next"] is None
    assert chain_transform(m, 2.0).d == pytest.approx([1, 0, 0])


@pytest.mark.parametrize("body, begin, match, element", [
    (RECT1.format("").replace('id="1"', 'id="0"'), '<begin mov="0" start="0"/>', "id='0' is below 1", "mvrect"),
    ('<mvrect id="1"><vel x="1" y="0" z="0"/></mvrect>', None, "missing attribute 'duration'", "mvrect"),
    ('<wait id="1" duration="-1" next="2"/>' + RECT1.format("").replace('id="1"', 'id="2"'), None,
     "<wait> with a negative duration", "wait"),
    (RECT1.format(""), '<begin mov="1"/>', "missing attribute 'start'", "begin"),
    (RECT1.format(' anglesunits="Degrees"'), None, "anglesunits='Degrees' is not recognised", "mvrect"),
    ('<mvrot id="1" duration="1" anglesunits="RADIANS"><vel ang="1"/><axisp1 x="0" y="0" z="0"/>'
     '<axisp2 x="0" y="1" z="0"/></mvrot>', None, "anglesunits='RADIANS' is not recognised", "mvrot"),
])
def test_what_dualsphysics_refuses_is_a_case_error(tmp_path, body, begin, match, element):
    """JMotion: movement ids > 0 (MovAdd), duration and <begin start> required (GetAttributeFloat
    without a default), no negative wait (MovAddWait), anglesunits exactly degrees or radians
    (ErrReadAtrib); sphdvi accepted each of them."""
    with pytest.raises(CaseError, match=match) as e:
        read(tmp_path, body, begin=begin or '<begin mov="1" start="0"/>')
    assert e.value.element == element


def test_a_negative_duration_is_read_as_a_flash(tmp_path):
    """duration="-0.5" (refused before; -1 was sphdvi's "forever"): the displacement of 0.5 s at once."""
    (m,), _ = read(tmp_path, '<mvrect id="1" duration="-0.5"><vel x="1" y="0" z="0"/></mvrect>')
    assert chain_transform(m, 0.01).d == pytest.approx([0.5, 0, 0])
    assert chain_transform(m, 10.0).d == pytest.approx([0.5, 0, 0])


def test_mvnull_reads_no_duration_and_no_next(tmp_path):
    """JMotion::ReadXml reads neither duration nor next of an <mvnull>: the chain ends there."""
    (m,), reader = read(tmp_path, '<mvnull id="1"/>')
    assert m["movements"][0]["duration"] == 0.0 and m["movements"][0]["next"] is None


MOTION_2D = ('<casedef>\n<geometry><definition dp="0.1"><pointmin x="0" y="0" z="0"/><pointmax x="1" y="{y}" z="1"/>'
             '</definition></geometry>\n<motion><objreal ref="1"><begin mov="1" start="0"/>\n{body}\n</objreal></motion>\n'
             '</casedef>')


@pytest.mark.parametrize("body, what", [
    ('<mvrect id="1" duration="1"><vel x="0.1" y="0.3" z="0"/></mvrect>', "<vel> y=0.3"),
    ('<mvrectsinu id="1" duration="1"><freq x="1" y="1" z="1"/><ampl x="0" y="0.1" z="0"/></mvrectsinu>', "<ampl> y=0.1"),
    ('<mvrot id="1" duration="1"><vel ang="10"/><axisp1 x="0" y="0" z="0"/><axisp2 x="1" y="0" z="0"/></mvrot>',
     "an axis not along y"),
    ('<mvcir id="1" duration="1"><vel ang="10"/><ref x="1" y="0" z="0"/><axisp1 x="0" y="0" z="0"/>'
     '<axisp2 x="0" y="0" z="1"/></mvcir>', "an axis not along y"),
])
def test_a_2d_motion_out_of_the_plane_is_warned(tmp_path, body, what):
    """2D: DualSPHysics drops a translation's y (JDsMotion::ProcesTime) and keeps y under a matrix
    (MoveMatBound); gencase says so."""
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    read_motion(reader, etree.fromstring(MOTION_2D.format(y=0, body=body)))
    (w,) = list(reader.warnings)
    assert "2D case" in w and what in w and "keep their y" in w and ":4:" in w
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    read_motion(reader, etree.fromstring(MOTION_2D.format(y=1, body=body)))      # 3D: nothing to say
    assert list(reader.warnings) == []

"""Gauge input of <special><gauges> is checked at gencase (sphdvi.case.gauge_spec).

Every class of defect the run used to meet as an internal error (rc 1) or an out-of-memory
is now exit code 2 at ``sphdvi gencase`` (and ``sphdvi run CASE.xml``), with
``file:line: <element>: what; expected what`` and no traceback.
"""
import glob
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.errors import InputError

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
SWL = '<point0 x="0.2" y="0" z="0" />\n<point2 x="0.2" y="0" z="2" />'
VPOINT = '<point x="0.5" y="0" z="0.5" />'
MESH = ('<point x="0.2" y="0" z="0.2" />\n<vec1 x="1" y="0" z="0" />\n<vec2 x="0" y="0" z="1" />\n'
        '<size1 value="0.4" />\n<size2 value="0.4" />')


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def case_text(gauges: str) -> str:
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.1"')
    return re.sub(r"<gauges>.*?</gauges>", lambda m: f"<gauges>\n{gauges}\n</gauges>", text, flags=re.S)


def write_case(tmp_path, gauges: str) -> Path:
    case = tmp_path / "CaseG_Def.xml"
    case.write_text(case_text(gauges))
    return case


def line_of(text: str, marker: str) -> int:
    assert text.count(marker) == 1, marker
    return text[:text.index(marker)].count("\n") + 1


# (id, gauges, marker of the element the error must name, its tag, words of the message)
BAD = [
    # numbers that are not numbers
    ("coefdp_abc", f'<swl name="g">\n<pointdp coefdp="abc" />\n{SWL}\n</swl>', '<pointdp coefdp="abc"', "pointdp",
     "not a number"),
    ("masslimit_abc", f'<swl name="g">\n<masslimit coef="abc" />\n{SWL}\n</swl>', "<masslimit", "masslimit",
     "not a number"),
    ("computetime_abc", f'<velocity name="g">\n<computetime start="abc" end="1" />\n{VPOINT}\n</velocity>',
     "<computetime", "computetime", "not a number"),
    ("outputtime_abc", f'<velocity name="g">\n<outputtime start="abc" />\n{VPOINT}\n</velocity>', "<outputtime",
     "outputtime", "not a number"),
    ("distlimit_abc", '<maxz name="g">\n<point0 x="0.5" y="0" z="0" />\n<distlimit coefdp="abc" />\n</maxz>',
     "<distlimit", "distlimit", "not a number"),
    ("default_abc", f'<default>\n<computedt value="abc" />\n</default>\n<velocity name="g">{VPOINT}</velocity>',
     "<computedt", "computedt", "not a number"),
    ("target_abc", '<force name="g">\n<target mkbound="abc" />\n</force>', "<target", "target", "not a number"),
    # ranges
    ("coefdp_zero", f'<swl name="g">\n<pointdp coefdp="0" />\n{SWL}\n</swl>', "<pointdp", "pointdp",
     "not positive"),
    ("coefdp_neg", f'<swl name="g">\n<pointdp value="-1" />\n{SWL}\n</swl>', "<pointdp", "pointdp",
     "not positive"),
    ("pointdp_noattr", f'<swl name="g">\n<pointdp />\n{SWL}\n</swl>', "<pointdp", "pointdp", "none of value, coefdp"),
    ("pointdp_both", f'<swl name="g">\n<pointdp value="0.1" coefdp="1" />\n{SWL}\n</swl>', "<pointdp", "pointdp",
     "more than one of"),
    ("masslimit_zero", f'<swl name="g">\n<masslimit value="0" />\n{SWL}\n</swl>', "<masslimit", "masslimit",
     "not positive"),
    ("computedt_neg", f'<velocity name="g">\n<computedt value="-1" />\n{VPOINT}\n</velocity>', "<computedt",
     "computedt", "negative"),
    ("computetime_inverted", f'<velocity name="g">\n<computetime start="5" end="1" />\n{VPOINT}\n</velocity>',
     "<computetime", "computetime", "start=5 is after end=1"),
    ("window_inherited", '<default>\n<computetime start="5" />\n</default>\n'
     f'<velocity name="g">\n<computetime end="1" />\n{VPOINT}\n</velocity>', '<computetime end="1"', "computetime",
     "from <default>"),
    ("height_neg", '<maxz name="g">\n<point0 x="0.5" y="0" z="0" />\n<height value="-2" />\n</maxz>', "<height",
     "height", "not positive"),
    ("distlimit_zero", '<maxz name="g">\n<point0 x="0.5" y="0" z="0" />\n<distlimit coefh="0" />\n</maxz>',
     "<distlimit", "distlimit", "not positive"),
    # missing points: nothing to sample
    ("swl_nopoints", '<swl name="g">\n</swl>', '<swl name="g"', "swl", "has no <point0>"),
    ("swl_nopoint2", '<swl name="g">\n<point0 x="0.2" y="0" z="0" />\n</swl>', '<swl name="g"', "swl",
     "has no <point2>"),
    ("swl_same_points", '<swl name="g">\n<point0 x="0.2" y="0" z="0" />\n<point2 x="0.2" y="0" z="0" />\n</swl>',
     "<point2", "point2", "equals <point0>"),
    ("vel_nopoint", '<velocity name="g">\n</velocity>', '<velocity name="g"', "velocity", "has no <point>"),
    ("maxz_nopoint", '<maxz name="g">\n<height value="1" />\n</maxz>', '<maxz name="g"', "maxz", "has no <point0>"),
    ("force_notarget", '<force name="g">\n</force>', '<force name="g"', "force", "has no <target>"),
    ("force_mkfluid", '<force name="g">\n<target mkfluid="0" />\n</force>', "<target", "target",
     "missing attribute 'mkbound'"),
    ("mesh_nopoint", '<mesh name="g">\n</mesh>', '<mesh name="g"', "mesh", "has no <point>"),
    # absurd numbers of sample points
    ("coefdp_tiny", f'<swl name="g">\n<pointdp coefdp="1e-9" />\n{SWL}\n</swl>', "<pointdp", "pointdp",
     "sample points, more than 1,000,000"),
    ("pointdp_1e-300", '<swl name="g">\n<pointdp value="1e-300" />\n<point0 x="0" y="0" z="0" />\n'
     '<point2 x="1e300" y="0" z="0" />\n</swl>', "<pointdp", "pointdp", "more than 1e15 sample points"),
    ("mesh_huge", '<mesh name="g">\n<point x="0" y="0" z="0" />\n<size1 value="1e4" />\n<size3 value="1e4" />\n'
     '</mesh>', '<mesh name="g"', "mesh", "sample points, more than 1,000,000"),
    # mesh geometry and outputs
    ("mesh_size_neg", f'<mesh name="g">\n{MESH}\n<size3 value="-1" />\n</mesh>', "<size3", "size3", "negative"),
    ("mesh_vec_zero", '<mesh name="g">\n<point x="0" y="0" z="0" />\n<vec1 x="0" y="0" z="0" />\n'
     '<size1 value="1" />\n</mesh>', "<vec1", "vec1", "zero vector but <size1> is 1"),
    ("mesh_outputdata", f'<mesh name="g">\n{MESH}\n<outputdata value="vel,foo" />\n</mesh>', "<outputdata",
     "outputdata", "unknown output data 'foo'"),
    ("mesh_outputdata_empty", f'<mesh name="g">\n{MESH}\n<outputdata value=" , " />\n</mesh>', "<outputdata",
     "outputdata", "no output data"),
    ("mesh_outputfmt", f'<mesh name="g">\n{MESH}\n<outputfmt value="bar" />\n</mesh>', "<outputfmt", "outputfmt",
     "not an output format"),
    ("mesh_kclimit", f'<mesh name="g">\n{MESH}\n<kclimit value="abc" />\n</mesh>', "<kclimit", "kclimit",
     "not a number"),
    ("mesh_zsurf_flat", f'<mesh name="g">\n{MESH}\n<outputdata value="zsurf" />\n</mesh>', "<outputdata",
     "outputdata", "zsurf needs a column"),
    ("mesh_dirdat_zero", f'<mesh name="g">\n{MESH}\n<outputdata value="veldir" />\n<dirdat x="0" y="0" z="0" />\n'
     '</mesh>', "<dirdat", "dirdat", "zero vector"),
    ("mesh_unknown_child", f'<mesh name="g">\n{MESH}\n<sise1 value="1" />\n</mesh>', "<sise1", "sise1",
     "unknown element <sise1>"),
    # names become file names
    ("name_slash", f'<velocity name="a/b">{VPOINT}</velocity>', '<velocity name="a/b"', "velocity",
     "contains '/'"),
    ("name_backslash", f'<velocity name="a\\b">{VPOINT}</velocity>', "<velocity name=", "velocity",
     "contains '\\\\'"),
    ("name_dotdot", f'<velocity name="x..y">{VPOINT}</velocity>', "<velocity name=", "velocity", "contains '..'"),
    ("name_windows", f'<velocity name="a:b*">{VPOINT}</velocity>', "<velocity name=", "velocity", "contains '*', ':'"),
    ("name_long", f'<velocity name="{"x" * 300}">{VPOINT}</velocity>', "<velocity name=", "velocity",
     "300 bytes long"),
    ("name_empty", f'<velocity name="">{VPOINT}</velocity>', "<velocity name=", "velocity", "empty gauge name"),
    ("name_twice", f'<velocity name="v">{VPOINT}</velocity>\n<swl name="v">{SWL}</swl>', '<swl name="v"', "swl",
     "used twice"),
]


@pytest.mark.parametrize("gauges,marker,tag,words", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_gauge_is_exit_2_at_gencase(tmp_path, gauges, marker, tag, words):
    case = write_case(tmp_path, gauges)
    line = line_of(case.read_text(), marker)
    r = invoke("gencase", case, "-o", tmp_path / "out", "-q")
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and "internal error" not in r.output
    assert f"{case}:{line}: <{tag}>: " in r.output, r.output
    assert words in r.output and "; expected " in r.output, r.output
    assert not glob.glob(str(tmp_path / "out" / "*.h5"))


def test_bad_gauge_is_exit_2_at_run_case_xml(tmp_path):
    case = write_case(tmp_path, f'<swl name="g">\n<pointdp coefdp="1e-9" />\n{SWL}\n</swl>')
    r = invoke("run", case, "-o", tmp_path / "out", "--tmax", "0.002", "-q")
    assert r.exit_code == 2, r.output
    assert f"{case}:{line_of(case.read_text(), '<pointdp')}: <pointdp>: " in r.output
    assert not (tmp_path / "out" / "run.json").exists() or "completed" not in (tmp_path / "out" / "run.json").read_text()


GOOD = """<default>
<computetime start="0.01" end="0.5" />
<output value="true" />
</default>
<velocity name="V.1-a">
<computetime start="0.02" />
<point x="0.5" y="0" z="0.5" />
</velocity>
<swl name="S1">
<pointdp value="0.05" />
<masslimit coef="0.45" />
<point0 x="0.2" y="0" z="0" />
<point2 x="0.2" y="0" z="2" />
</swl>
<maxz name="M1">
<point0 x="0.5" y="0" z="0" />
<height value="3" />
<distlimit coefh="1.5" />
</maxz>
<force name="F1"><target mkbound="0" /></force>
<mesh name="P1">
<point x="1" y="0" z="0.1" />
<vec1 x="1" y="0" z="0" /><vec2 x="0" y="1" z="0" /><vec3 x="0" y="0" z="1" />
<size1 value="0" /><size2 value="0" /><size3 value="0" />
<outputdata value="rhop" />
</mesh>
<mesh name="Z">
<point x="0.1" y="0" z="0" />
<vec1 x="1" y="0" z="0" /><vec2 x="0" y="0" z="0" /><vec3 x="0" y="0" z="1" />
<size1 value="0.3" /><size3 value="2.5" />
<outputdata value=" Vel , zsurf,vel " /><outputfmt value="csv" /><kclimit value="NONE" />
<masslimit value="2" />
</mesh>"""


def test_valid_gauges_read_typed(tmp_path):
    """Valid input: a size 0 with one node (the Lobovsky pressure probes), a zero vector with no
    size (no extent along it, as in DualSPHysics), windows inheriting from <default>."""
    from sphdvi.case.gencase import build_case
    res = build_case(str(write_case(tmp_path, GOOD)))
    g = res.case.special["gauges"]
    items = {i["name"]: i for i in g["items"]}
    assert g["default"]["computetime"] == {"start": 0.01, "end": 0.5}
    assert items["V.1-a"]["computetime"] == {"start": 0.02, "end": 0.5}      # end from <default>
    assert items["S1"]["pointdp"] == {"value": 0.05} and items["S1"]["masslimit"] == {"coef": 0.45}
    assert items["M1"]["distlimit"] == {"coefh": 1.5} and items["M1"]["height"] == 3.0
    assert items["F1"]["target"] == {"mkbound": 0}
    assert items["P1"]["size1"] == 0.0 and items["P1"]["outputdata"] == {"value": "rhop"}
    assert items["Z"]["outputdata"] == {"value": "vel,zsurf"} and items["Z"]["kclimit"] == {"value": "none"}
    assert items["Z"]["vec2"] == [0.0, 0.0, 0.0]


def test_valid_gauges_run(tmp_path):
    case = write_case(tmp_path, GOOD)
    out = tmp_path / "out"
    r = invoke("run", case, "-o", out, "--tmax", "0.02", "--threads", "1", "-q")
    assert r.exit_code == 0, r.output
    names = sorted(p.name for p in out.glob("Gauges*.csv"))
    assert names == ["GaugesForce_F1.csv", "GaugesMaxZ_M1.csv", "GaugesMesh_P1_Rhop.csv", "GaugesMesh_Z_Vel.csv",
                     "GaugesMesh_Z_Zsurf.csv", "GaugesSWL_S1.csv", "GaugesVel_V.1-a.csv"]
    head = (out / "GaugesMesh_Z_Vel.csv").read_text().splitlines()[0].split(";")
    assert len(head) == 1 + 4 * 3 * 26                       # time; vel of 4 x 26 nodes
    assert len((out / "GaugesMesh_Z_Zsurf.csv").read_text().splitlines()[0].split(";")) == 1 + 4   # 4 columns
    assert len((out / "GaugesMesh_P1_Rhop.csv").read_text().splitlines()[0].split(";")) == 2


def test_run_of_old_case_file_with_invalid_gauge_is_exit_2(tmp_path):
    """A case file written before gencase checked gauges: a clear error at start-up, not rc 1."""
    from sphdvi.io.casefile import read_case_h5
    from sphdvi.measure.gauges import RunGauges
    case = write_case(tmp_path, f'<swl name="g">{SWL}</swl>')
    assert invoke("gencase", case, "-o", tmp_path / "out", "-q").exit_code == 0
    data = read_case_h5(glob.glob(str(tmp_path / "out" / "*.h5"))[0])
    for change, words in ((lambda i: i.update(pointdp={"coefdp": "abc"}), "could not convert"),
                          (lambda i: i.pop("point0"), "point0"),
                          (lambda i: i.update(name="../x"), "contains '/'")):
        item = dict(data["json"]["gauges"]["items"][0], output=True)
        change(item)
        d = {**data, "json": {**data["json"], "gauges": {"default": {}, "items": [item]}}}
        with pytest.raises(InputError, match=words):
            RunGauges(d, data.get("parameters") or {}, str(tmp_path / "run"))


@pytest.mark.parametrize("gauge, outside", [
    ('<velocity name="far">\n<point x="9" y="0" z="0.5" />\n</velocity>', True),
    ('<swl name="far">\n<point0 x="9" y="0" z="0" />\n<point2 x="9" y="0" z="9" />\n</swl>', True),
    ('<maxz name="far">\n<point0 x="9.5" y="0" z="0" />\n<height value="20" />\n</maxz>', True),
    ('<mesh name="far">\n<point x="9.2" y="0" z="0.2" />\n<vec1 x="1" y="0" z="0" />\n<size1 value="40" />\n</mesh>',
     True),
    # lines and meshes reaching into the domain record there: not warned (a swl line from z = 0,
    # below the floor particles at a coarse dp, was)
    ('<swl name="part">\n<point0 x="0.2" y="0" z="-0.01" />\n<point2 x="0.2" y="0" z="9" />\n</swl>', False),
    ('<maxz name="part">\n<point0 x="0.5" y="0" z="0" />\n<height value="20" />\n</maxz>', False),
    ('<mesh name="part">\n<point x="0.2" y="0" z="0.2" />\n<vec1 x="1" y="0" z="0" />\n<size1 value="40" />\n</mesh>',
     False),
    (f'<velocity name="near">\n{VPOINT}\n</velocity>', False),
    # 2D: y is not compared (the particles lie on y = 0)
    ('<velocity name="y2d">\n<point x="0.5" y="3" z="0.5" />\n</velocity>', False),
])
def test_gauge_outside_the_domain_is_warned(tmp_path, gauge, outside):
    """A gauge whose points lie outside the simulation domain records no fluid there: gencase
    says so with the gauge's line (a warning, as DualSPHysics runs such a gauge)."""
    case = write_case(tmp_path, gauge)
    r = invoke("gencase", case, "-o", tmp_path / "out")
    assert r.exit_code == 0, r.output
    warned = [ln for ln in r.output.splitlines() if "outside the simulation domain" in ln]
    if outside:
        assert len(warned) == 1, r.output
        line = gauge.splitlines()[0]
        assert f"{case.name}:{line_of(case.read_text(), line)}:" in warned[0] and "gauge 'far'" in warned[0]
    else:
        assert not warned, r.output


def test_swl_point1_is_warned_and_ignored(tmp_path):
    """DualSPHysics 5.4 ran a case whose swl gauges carry a <point1> (yupengxiang/DualSPHysics F5
    C082S1): read, warned as not used, the gauge the line from point0 to point2."""
    from sphdvi.case.gencase import build_case
    gauge = f'<swl name="S">\n<point1 x="0.2" y="0" z="1" />\n{SWL}\n</swl>'
    case = write_case(tmp_path, gauge)
    res = build_case(str(case))
    item = res.case.special["gauges"]["items"][0]
    assert "point1" not in item and item["point0"] == [0.2, 0.0, 0.0] and item["point2"] == [0.2, 0.0, 2.0]
    line = line_of(case.read_text(), '<point1 x="0.2"')
    assert any(f"{case.name}:{line}: warning: <point1>" in w and "swl gauge 'S': <point1> is not read" in w
               for w in res.warnings), list(res.warnings)

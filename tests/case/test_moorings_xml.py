"""``<special><moorings>`` read as DualSPHysics v5.4 and MoorDynPlus read it (sphdvi.case.moorings_xml):
the dict it gives, its defaults, the order of a line's ends, the ``file=`` and legacy ``<moordyn>``
forms, and each refusal an error naming the file, line and element (exit 2 from ``sphdvi gencase``)."""
import math
import re
from pathlib import Path

import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.moorings_xml import read_moorings
from sphdvi.case.xmldoc import CaseReader, load_xml, strip_disabled
from sphdvi.cli import main
from sphdvi.errors import CaseError, Warnings
from sphdvi.io.casefile import read_case_h5
from sphdvi.simulation import find_case_file

EXAMPLE = Path(__file__).resolve().parents[2] / "cases" / "mooredbox2d" / "CaseMooredBox2D_Def.xml"

# a 2D tank (bed at z = 0, still water at z = 0.5) with a floating box (mkbound 50) at its centre
COMMANDS = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="3" y="2" z="0.5" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" />
                        <size x="3" y="2" z="1" /></drawbox>
                    <setmkbound mk="50" />
                    <drawbox><boxfill>solid</boxfill><point x="1.3500001" y="-1" z="0.4" />
                        <size x="0.2999998" y="2" z="0.2" /></drawbox>"""
FLOATINGS = """
        <floatings><floating mkbound="50" relativeweight="0.5" /></floatings>"""

SOLVER = """<solverOptions>
                        <waterDepth value="0.5" /><freesurface value="0.5" />
                    </solverOptions>"""
BODIES = """<bodies><body ref="50" /></bodies>"""
LINEDEFAULT = """<linedefault>
                            <ea value="2.9e3" /><diameter value="3.656e-3" /><massDenInAir value="0.0607" />
                            <length value="0.6" /><segments value="20" />
                        </linedefault>"""
LINE0 = """<line>
                            <vesselconnection bodyref="50" x="1.35" y="0" z="0.4" />
                            <fixconnection x="0.95" y="0" z="0" />
                        </line>"""
LINE1 = """<line savedata="false">
                            <fixconnection x="2.05" y="0" z="0" M="0.2" V="1e-4" />
                            <vesselconnection bodyref="50" x="1.65" y="0" z="0.4" />
                            <cdn value="2.0" /><segments value="10" /><depth value="0.6" /><outputFlags value="pt" />
                        </line>"""
SAVEDATA = """<savedata><time starTime="0.5" endTime="0" /><tension value="true" /><force /></savedata>"""


CONNECTS = ('<connects><connect conref="1" x="1.1" y="0" z="0.15" M="0.2" V="5e-5">'
            '<coeffini cda="0.01" ca="1" /></connect></connects>')


def library(solver=SOLVER, bodies=BODIES, lines=None, savedata=SAVEDATA, extra=""):
    lines = lines if lines is not None else LINEDEFAULT + LINE0 + LINE1
    return f"""{solver}
                    {bodies}
                    <lines>{lines}</lines>
                    {savedata}{extra}"""


def moorings(lib=None, tag="moordynplus", head="", floatings='<floating mkbound="50" />'):
    lib = library() if lib is None else lib
    return f"""
            <moorings>{head}
                <mooredfloatings>{floatings}</mooredfloatings>
                <{tag}>{lib}</{tag}>
            </moorings>"""


def _case(tmp_path, special, name="CaseMoor_Def.xml", floatings=FLOATINGS):
    text = case_xml(dp="0.02", pointmin=("-0.1", "0", "-0.1"), pointmax=("3.1", "0", "1.1"), commands=COMMANDS,
                    casedef_extra=floatings, special=special,
                    parameters='<parameter key="TimeMax" value="0.1" /><parameter key="TimeOut" value="0.05" />')
    return write_case(tmp_path, text, name)


def _read(tmp_path, special, **kw):
    """The reader's dict (and the warnings) for a case whose <special> is ``special``."""
    path = _case(tmp_path, special, **kw)
    root, _ = load_xml(path)
    strip_disabled(root, path)
    warnings = Warnings()
    reader = CaseReader(path, warnings=warnings)
    reader.root = root
    return read_moorings(reader, root.find("execution/special/moorings")), list(warnings)


def _gencase(tmp_path, special, **kw):
    path = _case(tmp_path, special, **kw)
    out = tmp_path / "g"
    return CliRunner().invoke(main, ["gencase", path, "-o", str(out)]), out


def test_a_full_case_reads_into_the_moorings_dict(tmp_path):
    head = """
                <savevtk_points value="true" /><savecsv_points value="false" />
                <start value="0.2" ramptime="0.5" />"""
    m, warnings = _read(tmp_path, moorings(head=head))
    assert not warnings
    assert (m["savevtk_lines"], m["savevtk_moorings"], m["savecsv_points"], m["savevtk_points"]) == \
        (True, True, False, True)
    assert (m["start"], m["ramptime"], m["floatings"]) == (0.2, 0.5, [50])
    assert m["solver"] == {"waterdepth": 0.5, "freesurface": 0.5, "kbot": 3.0e6, "cbot": 3.0e5, "dtm": 1e-4,
                           "dtm_auto": True, "wavekin": 0, "friction": 0.0, "fricdamp": 200.0,
                           "statdynfricscale": 1.0, "rho": 1000.0, "cdscaleic": 5.0, "dtic": 1.0, "tmaxic": 0.0,
                           "threshic": 0.001}
    assert [(b["ref"], b["depth"]) for b in m["bodies"]] == [(50, None)] and m["bodies"][0]["line"] > 0
    l0, l1 = m["lines"]
    assert (l0["id"], l1["id"]) == (0, 1) and l0["line"] < l1["line"]
    # linedefault's values and MoorDynPlus's defaults
    assert (l0["ea"], l0["diameter"], l0["mass"], l0["length"], l0["segments"]) == (2900.0, 3.656e-3, 0.0607, 0.6, 20)
    assert (l0["ba"], l0["can"], l0["cat"], l0["cdn"], l0["cdt"], l0["breaktension"]) == \
        (-0.8, 1.0, 0.0, 1.6, 0.05, 0.0)
    assert (l0["depth"], l0["outputflags"], l0["savedata"]) == (0.5, "-", True)
    # a line's own values override linedefault's
    assert (l1["cdn"], l1["segments"], l1["depth"], l1["outputflags"], l1["savedata"]) == (2.0, 10, 0.6, "pt", False)
    assert (l1["ea"], l1["length"]) == (2900.0, 0.6)
    # the fixed end is node 0, whatever the order in the file
    assert l0["ends"] == [{"kind": "fixed", "body": None, "pos": [0.95, 0.0, 0.0], "mass": 0.0, "volume": 0.0},
                          {"kind": "vessel", "body": 50, "pos": [1.35, 0.0, 0.4], "mass": 0.0, "volume": 0.0}]
    assert l1["ends"][0] == {"kind": "fixed", "body": None, "pos": [2.05, 0.0, 0.0], "mass": 0.2, "volume": 1e-4}
    assert l1["ends"][1]["kind"] == "vessel"
    assert m["savedata"] == {"start": 0.5, "end": None, "dtout": None, "tension": True, "force": True,
                             "velocity": False, "position": False}


def test_defaults_without_savedata_and_options(tmp_path):
    solver = """<solverOptions><WATERDEPTH value="0.6" /><dtM value="0.001" auto="false" /><rho value="1025" />
                        <tmaxIC value="10" /><frictionCoefficient value="0.3" /><writeUnits value="no" />
                    </solverOptions>"""
    bodies = '<bodies><body ref="50"><depth value="0.55" /></body></bodies>'
    m, _ = _read(tmp_path, moorings(library(solver=solver, bodies=bodies, savedata="")))
    s = m["solver"]
    assert (s["waterdepth"], s["freesurface"], s["dtm"], s["dtm_auto"], s["rho"], s["tmaxic"], s["friction"]) == \
        (0.6, 0.0, 0.001, False, 1025.0, 10.0, 0.3)
    assert (m["savevtk_lines"], m["savevtk_moorings"], m["savecsv_points"], m["savevtk_points"]) == \
        (True, True, True, False)
    assert (m["start"], m["ramptime"], m["savedata"]) == (0.0, 0.0, None)
    # depth: the line's (line 1), else its body's (line 0)
    assert [ln["depth"] for ln in m["lines"]] == [0.55, 0.6]
    assert m["bodies"][0]["depth"] == 0.55


def test_e_gives_ea_and_the_old_output_names(tmp_path):
    lines = LINEDEFAULT.replace('<ea value="2.9e3" />', '<e value="2e9" />') + LINE0.replace("<line>",
                                                                                              '<line output="false">')
    save = '<output><time starTime="0" endTime="5" dtOut="0.1" /><velocity value="false" /><position /></output>'
    m, _ = _read(tmp_path, moorings(library(lines=lines, savedata=save)))
    assert m["lines"][0]["ea"] == pytest.approx(2e9 * math.pi * 3.656e-3 ** 2 / 4)
    assert m["lines"][0]["savedata"] is False
    assert m["savedata"] == {"start": 0.0, "end": 5.0, "dtout": 0.1, "tension": False, "force": False,
                             "velocity": False, "position": True}


@pytest.mark.parametrize("z0, z1, first", [(0.3, 0.4, 0), (0.4, 0.3, 1), (0.4, 0.4, 0)])
def test_of_two_vessel_ends_the_lower_is_node_0(tmp_path, z0, z1, first):
    line = f"""<line><vesselconnection bodyref="50" x="1.35" y="0" z="{z0}" />
                     <vesselconnection bodyref="50" x="1.65" y="0" z="{z1}" /><length value="0.35" /></line>"""
    m, _ = _read(tmp_path, moorings(library(lines=LINEDEFAULT + line)))
    ends = m["lines"][0]["ends"]
    assert [e["pos"][0] for e in ends] == ([1.35, 1.65] if first == 0 else [1.65, 1.35])
    assert all(e["kind"] == "vessel" and e["body"] == 50 for e in ends)


def test_the_file_variant_reads_the_named_file(tmp_path):
    (tmp_path / "moor").mkdir()
    (tmp_path / "moor" / "lines.xml").write_text(f'<?xml version="1.0" ?>\n<moordynplus>{library()}</moordynplus>\n')
    special = moorings(lib="").replace("<moordynplus></moordynplus>", '<moordynplus file="moor/lines.xml" />')
    m, warnings = _read(tmp_path, special)
    assert not warnings
    assert [ln["id"] for ln in m["lines"]] == [0, 1] and m["lines"][1]["cdn"] == 2.0
    # an error in that file names it and its line
    (tmp_path / "moor" / "lines.xml").write_text('<?xml version="1.0" ?>\n<moordynplus>\n'
                                                 + library(solver=SOLVER.replace('"0.5"', '"-1"', 1))
                                                 + "</moordynplus>\n")
    with pytest.raises(CaseError) as exc:
        _read(tmp_path, special)
    assert re.search(r"moor/lines\.xml:\d+: <waterDepth>: .*not positive", str(exc.value))
    # its root must be <moordynplus>
    (tmp_path / "moor" / "lines.xml").write_text('<?xml version="1.0" ?>\n<moorings />\n')
    with pytest.raises(CaseError, match=r"lines\.xml:2: <moorings>: the root element .*expected <moordynplus>"):
        _read(tmp_path, special)
    r, _ = _gencase(tmp_path, special.replace("moor/lines.xml", "moor/none.xml"))
    assert r.exit_code == 2 and "not found" in r.output and "Traceback" not in r.output


def test_the_legacy_moordyn_is_read_with_a_warning(tmp_path):
    m, warnings = _read(tmp_path, moorings(tag="moordyn"))
    assert len(m["lines"]) == 2
    assert any("<moordyn>" in w and "DualSPHysics 5.4 refuses" in w and "read as <moordynplus>" in w
               for w in warnings)


def test_warnings_waves_wavekin_short_line(tmp_path):
    solver = SOLVER.replace("</solverOptions>", '<waveKin value="1" /></solverOptions>')
    lines = LINEDEFAULT.replace('"0.6"', '"0.5"') + LINE0
    m, warnings = _read(tmp_path, moorings(library(solver=solver, lines=lines, extra="<waves />")))
    text = "\n".join(warnings)
    assert "<waves>: <waves> is not read" in text
    assert "waveKin=1: no wave kinematics" in text
    assert "line 0's length 0.5 m is shorter than the distance between its ends" in text and "taut" in text


def test_connects_are_read_with_moordynpluss_end_order(tmp_path):
    """A clump weight (conref 1) between an anchor and the body: two lines, the fixed one with the
    connect at node N, the vessel one with the connect at node 0 (MoorDynPlus's ILine::ConfigLine);
    the ends carry the connect's index and position."""
    lines = (LINEDEFAULT + '<line><connect conref="1" /><fixconnection x="0.95" y="0" z="0" /></line>'
             '<line><vesselconnection bodyref="50" x="1.35" y="0" z="0.4" /><connect conref="1" /></line>')
    m, warnings = _read(tmp_path, moorings(library(extra=CONNECTS, lines=lines)))
    assert not warnings
    assert m["connects"] == [{"conref": 1, "pos": [1.1, 0.0, 0.15], "line": m["connects"][0]["line"], "mass": 0.2,
                              "volume": 5e-5, "cda": 0.01, "ca": 1.0}]
    (a0, a1), (b0, b1) = (ln["ends"] for ln in m["lines"])
    assert (a0["kind"], a1["kind"], b0["kind"], b1["kind"]) == ("fixed", "connect", "connect", "vessel")
    assert a1["connect"] == b0["connect"] == 0 and a1["pos"] == [1.1, 0.0, 0.15]


def test_two_connects_on_one_line_the_lower_is_node_0(tmp_path):
    """fixed -> connect 2 -> connect 1 -> vessel: the middle line has a connect at each end, the lower
    one (conref 2, z 0.1) as node 0 whatever the order they are written in."""
    extra = ('<connects><connect conref="1" x="1.2" y="0" z="0.3" M="0.1" V="0" />'
             '<connect conref="2" x="1.05" y="0" z="0.1" M="0.1" V="0" /></connects>')
    lines = (LINEDEFAULT + '<line><fixconnection x="0.95" y="0" z="0" /><connect conref="2" /></line>'
             '<line><connect conref="1" /><connect conref="2" /></line>'
             '<line><connect conref="1" /><vesselconnection bodyref="50" x="1.35" y="0" z="0.4" /></line>')
    m, _ = _read(tmp_path, moorings(library(extra=extra, lines=lines)))
    ends = [[(e["kind"], e.get("conref")) for e in ln["ends"]] for ln in m["lines"]]
    assert ends == [[("fixed", None), ("connect", 2)], [("connect", 2), ("connect", 1)],
                    [("connect", 1), ("vessel", None)]]
    assert [c["conref"] for c in m["connects"]] == [1, 2]


def test_connect_warnings(tmp_path):
    """M and V absent (0 here, estimated by MoorDynPlus 2025), v2020's <initialCoeffs>, a connect no
    line uses (left out)."""
    extra = ('<connects><connect conref="1" x="1.1" y="0" z="0.15"><initialCoeffs cda="1" ca="1" /></connect>'
             '<connect conref="2" x="1" y="0" z="0.1" M="1" V="0" /></connects>')
    lines = LINEDEFAULT + '<line><connect conref="1" /><fixconnection x="0.95" y="0" z="0" /></line>' + LINE0
    m, warnings = _read(tmp_path, moorings(library(extra=extra, lines=lines)))
    text = "\n".join(map(str, warnings))
    assert "connect conref=1: M and V not given, taken as 0" in text
    assert "<initialCoeffs> is not read, as DualSPHysics 5.4's MoorDynPlus does not read it" in text
    assert "connect conref=2 is used by no line: left out" in text
    assert [c["conref"] for c in m["connects"]] == [1] and m["connects"][0]["cda"] == 0.0


def test_a_line_as_long_as_its_span_is_not_warned_for_a_rounding_error(tmp_path):
    """MoorDynPlus's example 04_ConnectedBoxes: a 0.6 m line between ends 0.6 m apart, whose
    distance computes as 0.6000000000000001, was warned "stretched by 2.22e-14 %"."""
    line = LINE0.replace('x="1.35" y="0" z="0.4"', 'x="0.8" y="0" z="0"').replace('x="0.95"', 'x="0.2"')
    m, warnings = _read(tmp_path, moorings(library(lines=LINEDEFAULT + line)))
    assert len(m["lines"]) == 1 and not [w for w in warnings if "taut" in w]
    m, warnings = _read(tmp_path, moorings(library(lines=LINEDEFAULT + line.replace('x="0.2"', 'x="0.19"'))))
    assert [w for w in warnings if "stretched by 1.67 %" in w]


def test_the_example_case_runs_through_gencase(tmp_path):
    r = CliRunner().invoke(main, ["gencase", str(EXAMPLE), "-o", str(tmp_path / "g")])
    assert r.exit_code == 0, r.output
    # its lines are taut by design (0.55 m between ends 0.566 m apart), as MoorDynPlus warns
    warned = [ln for ln in r.output.splitlines() if "warning" in ln]
    assert len(warned) == 2 and all("it starts taut, stretched by 2.85 %" in ln for ln in warned)
    m = read_case_h5(find_case_file(str(tmp_path / "g")))["json"]["special"]["moorings"]
    assert m["floatings"] == [50] and len(m["lines"]) == 2
    assert [ln["ends"][0]["kind"] for ln in m["lines"]] == ["fixed", "fixed"]
    assert m["savedata"]["tension"] and m["savedata"]["force"]


BAD = [
    # (special, message)
    (moorings(floatings=""), "there are no moored floatings"),
    (moorings(floatings='<floating mkbound="50" /><floating mkbound="50" />'), "floating mkbound=50 is already"),
    (moorings(head="<moordynplus />"), "a second <moordynplus>"),
    (moorings().replace("<mooredfloatings>", "<moordyn /><mooredfloatings>"), "both <moordynplus> and <moordyn>"),
    (moorings().replace("<moordynplus>", "<_x>").replace("</moordynplus>", "</_x>"), "missing <moordynplus>"),
    (moorings(head="<savevtk />"), "unknown element <savevtk> inside <moorings>"),
    (moorings(library(solver="")), "missing child element <solverOptions>"),
    (moorings(library().replace("<lines>", "<_l>").replace("</lines>", "</_l>")), "missing child element <lines>"),
    (moorings(library(extra="<bodys />")), "unknown element <bodys> inside <moordynplus>"),
    (moorings(library(solver="<solverOptions><freesurface value=\"0\" /></solverOptions>")), "missing <waterDepth>"),
    (moorings(library(solver=SOLVER.replace("</s", '<gravity value="9.8" /></s'))), "unknown solver option <gravity>"),
    (moorings(library(solver=SOLVER.replace("</s", '<kBot value="0" /></s'))), "<kBot value=0> is not positive"),
    (moorings(library(solver=SOLVER.replace("</s", '<tmaxIC value="-1" /></s'))), "<tmaxIC value=-1> is negative"),
    (moorings(library(solver=SOLVER.replace("</s", '<cdScaleIC value="0" /></s'))), "<cdScaleIC value=0>"),
    (moorings(library(solver=SOLVER.replace("</s", '<dtM value="0.001" auto="maybe" /></s'))), "is not a boolean"),
    (moorings(library(solver=SOLVER.replace("</s", '<freeSurface value="0.4" /></s'))), "<freeSurface> is given twice"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("<fixconnection", '<connect conref="1"'))),
     "conref=1 is not a <connect> of <connects>"),
    (moorings(library(extra=CONNECTS.replace('conref="1"', 'conref="3"'))
              .replace("<fixconnection", '<connect conref="1"')), "conref=1 is not a <connect> of <connects>"),
    (moorings(library(extra=CONNECTS + '<connects />')), "a second <connects> inside <moordynplus>"),
    (moorings(library(extra=CONNECTS.replace("</connects>", '<connect conref="1" x="0" y="0" z="0" M="1" V="0" />'
                                                            '</connects>'))), "conref=1 is given twice"),
    (moorings(library(extra=CONNECTS.replace("</connects>", "<buoy /></connects>"))),
     "unknown element <buoy> inside <connects>"),
    (moorings(library(extra=CONNECTS.replace('ca="1"', ""))), "missing attribute 'ca'"),
    (moorings(library(extra=CONNECTS, lines=LINEDEFAULT + """<line><connect conref="1" /><connect conref="1" /></line>""")),
     "line 0 hangs both its ends on connect conref=1"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("<fixconnection x=\"0.95\" y=\"0\" z=\"0\" />", ""))),
     "line 0 has 1 connection element(s)"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<fixconnection x="1" y="0" z="0" /></line>'))),
     "line 0 has 3 connection element(s)"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace('bodyref="50"', 'bodyref="7"'))),
     "bodyref=7 is not a <body ref> of <bodies>"),
    (moorings(library(bodies='<bodies><body ref="50" /><body ref="51" /></bodies>')), "body ref=51 is not a moored"),
    (moorings(library(bodies='<bodies><body ref="50" /><body ref="50" /></bodies>')), "body ref=50 is already"),
    (moorings(library(bodies="", lines=LINEDEFAULT)), 'moored floating mkbound=50 has no <body ref="50">'),
    (moorings(library(lines=LINEDEFAULT.replace('<ea value="2.9e3" />', "") + LINE0)), "neither <ea> nor <e>"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<e value="2e9" /></line>'))),
     "has both <ea> and <e>"),
    (moorings(library(lines=LINEDEFAULT.replace('<diameter value="3.656e-3" />', "") + LINE0)),
     "line 0 has no <diameter>"),
    (moorings(library(lines=LINEDEFAULT.replace('<massDenInAir value="0.0607" />', "") + LINE0)),
     "line 0 has no <massDenInAir>"),
    (moorings(library(lines=LINEDEFAULT.replace('<length value="0.6" />', "") + LINE0)), "line 0 has no <length>"),
    (moorings(library(lines=LINEDEFAULT.replace('<segments value="20" />', "") + LINE0)), "line 0 has no <segments>"),
    (moorings(library(lines=LINEDEFAULT.replace('"3.656e-3"', '"0"') + LINE0)), "<diameter value=0> is not positive"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<segments value="0" /></line>'))),
     "value='0' is below 1"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<segments value="2.5" /></line>'))),
     "is not an integer"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<length value="-1" /></line>'))),
     "<length value=-1> is not positive"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<breaktension value="-1" /></line>'))),
     "<breaktension value=-1> is negative"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<outputFlags value="px" /></line>'))),
     "'x' is not an output flag"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<depth value="0" /></line>'))),
     "<depth value=0> is not positive"),
    (moorings(library(lines=LINEDEFAULT.replace("</linedefault>", '<depth value="1" /></linedefault>') + LINE0)),
     "unknown element <depth> inside <linedefault>"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<diametre value="1" /></line>'))),
     "unknown element <diametre> inside <line>"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace("</line>", '<cdn value="1" /><cdn value="2" /></line>'))),
     "<cdn> is given twice"),
    (moorings(library(lines=LINEDEFAULT + LINEDEFAULT + LINE0)), "a second <linedefault>"),
    (moorings(library(lines=LINEDEFAULT)), "no <line> is defined"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace('x="0.95" y="0" z="0"', 'x="0.95" y="0" z="-0.1"'))),
     "line 0's anchor z=-0.1 lies below the seabed"),
    (moorings(library(lines=LINEDEFAULT + LINE0.replace('x="0.95" y="0" z="0"', 'x="0.95" y="0"'))),
     "missing attribute 'z'"),
    (moorings(library(savedata="<savedata><tension /><tension /></savedata>")), "a second <tension>"),
    (moorings(library(savedata="<savedata><strain /></savedata>")), "unknown element <strain> inside <savedata>"),
    (moorings(library(savedata='<savedata><time starTime="2" endTime="1" /></savedata>')), "endTime=1 is before"),
    (moorings(library(savedata='<savedata><time dtOut="0" /></savedata>')), "dtOut='0' is not positive"),
    (moorings(library(savedata="<savedata /><output />")), "both <savedata> and <output>"),
]


@pytest.mark.parametrize("special, message", BAD)
def test_bad_moorings_are_case_errors(tmp_path, special, message):
    with pytest.raises(CaseError) as exc:
        _read(tmp_path, special)
    text = str(exc.value)
    assert message in text
    assert re.match(r".*CaseMoor_Def\.xml:\d+: <[A-Za-z_]+>: ", text)        # file, line, element
    assert "; expected " in text


@pytest.mark.parametrize("special, message", [next(b for b in BAD if b[1] == m) for m in (
    "there are no moored floatings", "line 0 hangs both its ends on connect conref=1",
    "line 0's anchor z=-0.1 lies below the seabed")])
def test_gencase_exits_2_without_a_traceback(tmp_path, special, message):
    r, _ = _gencase(tmp_path, special)
    assert r.exit_code == 2, r.output
    assert message in r.output and "Traceback" not in r.output
    assert re.search(r"CaseMoor_Def\.xml:\d+: <", r.output)


def test_a_moored_floating_must_be_a_floating_body(tmp_path):
    # mkbound 50 is drawn, but fixed: not in <floatings>
    r, _ = _gencase(tmp_path, moorings(), floatings="")
    assert r.exit_code == 2, r.output
    assert "moored floating mkbound 50 is not a floating body" in r.output and "Traceback" not in r.output
    m = re.search(r"CaseMoor_Def\.xml:(\d+): <floating>: ", r.output)
    lines = Path(tmp_path / "CaseMoor_Def.xml").read_text().splitlines()
    assert m and '<floating mkbound="50" />' in lines[int(m.group(1)) - 1]
    assert "in <casedef><floatings>" in r.output


def test_node_outputs_sphdvi_does_not_write_are_warned_about(tmp_path):
    """outputFlags U, D, c, b (wave velocities, hydrodynamic forces, damping, seabed contact) are
    accepted, and warned about: sphdvi writes p, v, t and s."""
    lines = LINEDEFAULT + LINE0.replace("</line>", '<outputFlags value="pDb" /></line>')
    m, warnings = _read(tmp_path, moorings(library(lines=lines)))
    assert m["lines"][0]["outputflags"] == "pDb"
    assert len(warnings) == 1 and "not D, b" in str(warnings[0])


def test_a_line_whose_ends_coincide_is_refused(tmp_path):
    """The nodes start between the two ends: the same point for both leaves every segment of zero
    length (a NaN at the first step)."""
    line = LINE0.replace('<fixconnection x="0.95" y="0" z="0" />', '<fixconnection x="1.35" y="0" z="0.4" />')
    r, _ = _gencase(tmp_path, moorings(library(lines=LINEDEFAULT + line)))
    assert r.exit_code == 2 and "two ends are the same point" in r.output, r.output

"""Fuzz: malformed and hostile case files never give a traceback or write outside OUTDIR.

Each case runs ``sphdvi gencase`` in-process; the exit code must be 0 (accepted)
or 2 (a clear error); 1 would be an internal error. Files may appear only in OUTDIR.
"""
import os

import pytest
from click.testing import CliRunner
from lxml import etree

from casetext import case_xml
from sphdvi.cli import main

BASE = case_xml(dp="0.1", commands="""
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="2" y="-1" z="0.5" /><size x="0.3" y="2" z="0.3" /></drawbox>""",
                casedef_extra='<floatings><floating mkbound="1" rhopbody="800"/></floatings>',
                parameters='<parameter key="TimeMax" value="1"/><parameter key="Visco" value="0.01"/>')


def truncations():
    step = max(1, len(BASE) // 60)
    return [("truncated@%d" % i, BASE[:i]) for i in range(0, len(BASE), step)][:60]


BAD_VALUES = ["abc", "NaN", "nan", "inf", "-inf", "1e999", "", "#1/0", "#Unknown*2", "#sqrt(-1)", "1,5", "0x10"]
TARGETS = [
    ('dp="0.1"', 'dp="{}"'),
    ('<pointmin x="-1"', '<pointmin x="{}"'),
    ('<pointmax x="4.5"', '<pointmax x="{}"'),
    ('<size x="1" y="2" z="2" />', '<size x="{}" y="2" z="2" />'),
    ('<coefh value="1.0" />', '<coefh value="{}" />'),
    ('<rhop0 value="1000" />', '<rhop0 value="{}" />'),
    ('key="TimeMax" value="1"', 'key="TimeMax" value="{}"'),
    ('rhopbody="800"', 'rhopbody="{}"'),
    ('<setmkfluid mk="0" />', '<setmkfluid mk="{}" />'),
]


def wrong_types():
    out = []
    for old, new in TARGETS:
        assert old in BASE, old
        for bad in BAD_VALUES:
            out.append((f"{old[:20]}={bad!r}", BASE.replace(old, new.format(bad), 1)))
    return out


def missing_elements():
    root = etree.fromstring(BASE.encode())
    out = []
    paths = [root.getroottree().getpath(el) for el in root.iter() if el is not root]
    for path in paths:
        r = etree.fromstring(BASE.encode())
        (el,) = r.xpath(path)
        el.getparent().remove(el)
        out.append((f"without {path}", etree.tostring(r).decode()))
    return out[:45]


ABSURD = [
    ("tiny dp", BASE.replace('dp="0.1"', 'dp="1e-9"')),
    ("negative dp", BASE.replace('dp="0.1"', 'dp="-0.1"')),
    ("zero dp", BASE.replace('dp="0.1"', 'dp="0"')),
    ("huge domain", BASE.replace('<pointmax x="4.5"', '<pointmax x="1e12"')),
    ("huge domain 3d", BASE.replace('<pointmax x="4.5" y="0"', '<pointmax x="1e4" y="1e4"')),
    ("inverted domain", BASE.replace('<pointmax x="4.5"', '<pointmax x="-5"')),
    ("huge box", BASE.replace('<size x="1" y="2" z="2" />', '<size x="1e15" y="2" z="1e15" />')),
    ("mk too large", BASE.replace('<setmkbound mk="1" />', '<setmkbound mk="99999" />')),
    ("huge runlist", BASE.replace("<mainlist>", '<list name="a"><runlist name="a"/></list><mainlist><runlist name="a"/>')),
    ("many times", BASE.replace("<mainlist>", '<list name="b"><newvar q="1"/></list><mainlist><runlist name="b" times="1e12"/>')),
    ("long expression", BASE.replace('dp="0.1"', 'dp="#' + "+".join(["0.01"] * 5000) + '"')),
    ("deep expression", BASE.replace('dp="0.1"', 'dp="#' + "(" * 500 + "0.1" + ")" * 500 + '"')),
    ("power bomb", BASE.replace('dp="0.1"', 'dp="#9^9^9^9"')),
]


def _stl_case(path):
    return BASE.replace('<setmkbound mk="1" />', f'<setmkbound mk="2" /><drawfilestl file="{path}"/><setmkbound mk="1" />')


FILES = [
    ("missing stl", _stl_case("nothere.stl")),
    ("stl outside folder", _stl_case("../../../etc/passwd")),
    ("absolute stl", _stl_case("/etc/passwd")),
    ("stl is a folder", _stl_case(".")),
    ("stl bad content", _stl_case("junk.stl")),
    ("missing property file", BASE.replace("</casedef>", '<properties><propertyfile file="nofile.xml" path="m"/></properties></casedef>')),
    ("property file outside", BASE.replace("</casedef>", '<properties><propertyfile file="../x.xml" path="m"/></properties></casedef>')),
    ("shapeout escape", BASE.replace("</mainlist>", '<shapeout file="../../evil"/></mainlist>')),
    ("shapeout absolute", BASE.replace("</mainlist>", '<shapeout file="/tmp/sphdvi_fuzz_evil"/></mainlist>')),
    ("motion file outside", BASE.replace("</casedef>", '<motion><objreal ref="0"><begin mov="1"/><mvrectfile id="1" duration="1">'
                                         '<file name="../../m.csv" fields="4" fieldtime="0" fieldx="1"/></mvrectfile></objreal></motion></casedef>')),
]

HOSTILE = [
    ("empty file", ""),
    ("binary junk", "\x00\x01\x02\xff" * 100),
    ("not xml", "hello world"),
    ("wrong root", "<?xml version='1.0'?><notacase/>"),
    ("billion laughs", '<?xml version="1.0"?><!DOCTYPE case [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
                       '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">'
                       '<!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;"><!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;">]>'
                       '<case><casedef><geometry><definition dp="&f;"/></geometry></casedef></case>'),
    ("external entity", '<?xml version="1.0"?><!DOCTYPE case [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
                        '<case><casedef>&x;</casedef></case>'),
    ("deep nesting", "<case>" + "<a>" * 3000 + "</a>" * 3000 + "</case>"),
    ("huge attribute", BASE.replace('dp="0.1"', 'dp="' + "1" * 200000 + '"')),
    ("two roots", BASE + BASE),
    ("no casedef", "<case><execution/></case>"),
    ("no geometry", "<case><casedef/></case>"),
    ("unknown casedef child", BASE.replace("<casedef>", "<casedef><bogus/>")),
    ("unknown command", BASE.replace("<mainlist>", "<mainlist><drawdragon/>")),
    ("unknown special", BASE.replace("<special>", "<special><bogus/>")),
    ("unknown parameter", BASE.replace("<parameters>", '<parameters><parameter key="Bogus" value="1"/>')),
    ("parameter no value", BASE.replace("<parameters>", '<parameters><parameter key="Visco"/>')),
    ("duplicate floating", BASE.replace("</floatings>", '<floating mkbound="1" rhopbody="700"/></floatings>')),
    ("floating no mass", BASE.replace('rhopbody="800"', "")),
    ("floating bad mk", BASE.replace('mkbound="1" rhopbody', 'mkbound="1-x" rhopbody')),
    ("link to nothing", BASE.replace("<special>", '<special><chrono><link_hinge idbody1="a"><rotpoint x="0"/>'
                                     '<rotvector x="0" y="1"/></link_hinge></chrono>')),
    ("fluid outside domain", BASE.replace("<parameters>", '<parameters><simulationdomain><posmax x="0.5"/></simulationdomain>')),
    ("no particles", case_xml(dp="0.1", commands="")),
    ("utf16", "\ufeff" + BASE),
    ("latin1 bytes", BASE.replace("<case>", "<case>\xe9")),
]

ALL = truncations() + wrong_types() + missing_elements() + ABSURD + FILES + HOSTILE


def test_at_least_200_cases():
    assert len(ALL) >= 200


@pytest.mark.parametrize("name, text", ALL, ids=[n for n, _ in ALL])
def test_fuzz_case(tmp_path, name, text):
    work = tmp_path / "work"
    work.mkdir()
    (work / "junk.stl").write_bytes(b"solid x\n this is not an stl \x00\x01")
    case = work / "Case_Def.xml"
    case.write_text(text, encoding="utf-8", errors="surrogateescape")
    out = work / "out"
    before = {p for p in tmp_path.rglob("*")}
    result = CliRunner().invoke(main, ["gencase", str(case), "-o", str(out), "-q", "--max-nodes", "5000000"])
    assert result.exit_code in (0, 2), f"{name}: exit {result.exit_code}: {result.output}"
    assert "Traceback" not in result.output
    if result.exit_code == 2:
        assert "error:" in result.output
    after = {p for p in tmp_path.rglob("*")}
    new = {p for p in after - before if out not in p.parents and p != out}
    assert not new, f"{name}: files written outside OUTDIR: {new}"
    assert not os.path.exists("/tmp/sphdvi_fuzz_evil")

"""The mk lists other than <chrono>'s, read as the DualSPHysics v5.4 class that reads each (audit
hunt11/r): before, every one went through sphdvi's strict parse_mk_range (an empty item an error).

* ``<special><initialize>`` (JDsInitializeOp_*::ReadXml, Run): ``mkbound``/``mkfluid`` optional,
  none or empty meaning every boundary (fluid); else JRangeFilter; boundnormal_plane loops over
  the list's values, so without one it does nothing;
* ``<accinputs><accinput mkfluid>`` (JDsAccInput::ReadXml): one integer as fun::StrIsIntegerNumber
  reads it (empty: 0), else JRangeFilter, which must give a value ("The mkfluid is invalid.");
* ``<properties><links><link>`` (JCasePropLinks::AddLink, GetProps): every blank dropped, the link
  dropped when its list is then empty, the rest JRangeFilter;
* ``<outputparts><filtermk>`` (JDsOutputPartsOp_Mk::ReadXmlExtra): ``a`` or ``a-b`` cut with
  fun::StrSplitCount/StrSplitValue and read with atoi (``a-`` a, ``-b`` 0-b, empty 0).

Each reads the values DualSPHysics reads, with a warning (file, line, element) where the list was
almost surely mistyped; what DualSPHysics refuses, or would read as another number, is an error.
GenCase's lists (<floatings>, <initials>, <normals>: its reader is not public) keep the strict form."""
import re

import pytest
from casetext import case_xml, write_case

from sphdvi.case.gencase import build_case
from sphdvi.case.mkrange import parse_filtermk, str_is_integer_number
from sphdvi.errors import CaseError

# four fluid blocks (mkfluid 0-3) and three floors (mkbound 0-2): gencase only
COMMANDS = "".join(
    f'<setmkfluid mk="{k}" /><drawbox><boxfill>solid</boxfill><point x="{0.3 * k:g}" y="-1" z="0" />'
    f'<size x="0.2" y="2" z="0.2" /></drawbox>' for k in range(4)) + "".join(
    f'<setmkbound mk="{k}" /><drawbox><boxfill>bottom</boxfill><point x="{1.3 * k:g}" y="-1" z="-0.1" />'
    f'<size x="1.2" y="2" z="0.05" /></drawbox>' for k in range(3))
STEEL = '<property name="steel" Kfric="0.3" Restitution_Coefficient="0.5" Young_Modulus="2e11" PoissonRatio="0.3"/>'
ACC = ('<accinputs><accinput mkfluid="{}"><acccentre x="0" y="0" z="0"/><globalgravity value="true"/>'
       '<acctimes><timevalue time="0" linx="1"/><timevalue time="1" linx="1"/></acctimes></accinput></accinputs>')


def build(tmp_path, **kw):
    tmp_path.mkdir(parents=True, exist_ok=True)
    return build_case(write_case(tmp_path, case_xml(commands=COMMANDS, **kw)), str(tmp_path / "out"))


def list_warnings(r, tag):
    return [w for w in r.warnings if f"<{tag}>" in w]


def one_warning(r, tag, *parts):
    """The one warning about <tag>, holding each of ``parts`` (and the file and line)."""
    (w,) = list_warnings(r, tag)
    assert re.search(rf"Case_Def\.xml:\d+: warning: <{tag}>: ", w), w
    for part in parts:
        assert part in w, w
    return w


# ---------------------------------------------------------------------------- <special><initialize>
def initialize(mkbound, mkfluid):
    return (f'<initialize><boundnormal_set mkbound="{mkbound}"><normal x="0" y="0" z="1"/></boundnormal_set>'
            f'<fluidvelocity mkfluid="{mkfluid}"><direction x="1" y="0" z="0"/><velocity v="1"/></fluidvelocity>'
            '</initialize>')


@pytest.mark.parametrize("text, mkbound, mkfluid, note", [
    ("1,,2", "1-2", [1, 2], "an empty item (two commas in a row, or a leading one) is skipped"),
    ("1, ,2", "0-2", [0, 1, 2], "the blank item ' ' is read as 0"),
    ("1-", "1", [1], "'1-' has no end value: read as 1 alone"),
    (" ", "0", [0], "(blanks only) is read as"),
])
def test_initialize_lists_read_as_jrangefilter(tmp_path, text, mkbound, mkfluid, note):
    """boundnormal_set mkbound and fluidvelocity mkfluid: the values JRangeFilter gives, each list
    warned about (before: an error for "1,,2", "1, ,2" and "1-", and " " meant every particle)."""
    r = build(tmp_path, special=initialize(text, text))
    init = r.case.special["initialize"]
    assert [op["mkbound"] for op in init["normals"]] == [mkbound]
    assert [v["mkfluid"] for v in init["velocity"]] == [mkfluid]
    one_warning(r, "boundnormal_set", f'mkbound="{text}"', note)
    one_warning(r, "fluidvelocity", f'mkfluid="{text}"', note)


@pytest.mark.parametrize("text", ["1-2:1", "0,2,", " 1 - 2 "])
def test_initialize_lists_plain_forms_are_silent(tmp_path, text):
    """A step, a trailing comma (StrSplit ends the list), blanks about the numbers: read, no warning."""
    r = build(tmp_path, special=initialize(text, text))
    assert r.case.special["initialize"]["normals"][0]["mkbound"] in ("1-2", "0,2")
    assert not list_warnings(r, "boundnormal_set") and not list_warnings(r, "fluidvelocity")


def test_initialize_empty_list_is_every_particle(tmp_path):
    """mkbound="" / mkfluid="": GetAttributeStr gives "", which Run reads as ALL; no warning."""
    r = build(tmp_path, special=initialize("", ""))
    init = r.case.special["initialize"]
    assert init["normals"][0]["mkbound"] == "" and init["velocity"][0]["mkfluid"] is None
    assert not list_warnings(r, "boundnormal_set") and not list_warnings(r, "fluidvelocity")


@pytest.mark.parametrize("text, note", [("-2", "'-2' has no start value: it gives nothing"),
                                        ("2-1", "'2-1' ends before it starts: it gives nothing")])
def test_initialize_list_giving_nothing_is_skipped(tmp_path, text, note):
    """A list JRangeFilter gives no value: DualSPHysics runs the operation on no particle; sphdvi
    drops it, with warnings."""
    r = build(tmp_path, special=initialize(text, text))
    assert r.case.special["initialize"] == {"normals": [], "velocity": []}
    for tag, attr in (("boundnormal_set", "mkbound"), ("fluidvelocity", "mkfluid")):
        ws = list_warnings(r, tag)
        assert any(note in w for w in ws), ws
        assert any(f'{attr}="{text}" gives no {attr}: this <{tag}> acts on no particle and is skipped' in w
                   for w in ws), ws


def test_initialize_plane_without_mkbound_does_nothing(tmp_path):
    """boundnormal_plane's Run loops over its list's values: with no mkbound it computes nothing
    (before: an error). A warning; the operation dropped."""
    plane = ('<initialize><boundnormal_plane><point auto="true"/><normal x="0" y="0" z="1"/>'
             '</boundnormal_plane></initialize>')
    r = build(tmp_path, special=plane)
    assert r.case.special["initialize"]["normals"] == []
    one_warning(r, "boundnormal_plane", "no mkbound (or mkbound=\"\")", "so it does nothing")


@pytest.mark.parametrize("text, message", [
    ("a", "mkbound: 'a' in mk list 'a' is not a non-negative integer"),
    ("1 2", "mkbound: '1 2' in mk list '1 2' is not a non-negative integer"),
    ("1.5", "mkbound: '1.5' in mk list '1.5' is not a non-negative integer"),
])
def test_initialize_list_errors(tmp_path, text, message):
    """What atoi would read as another number: a gencase error naming file, line and element."""
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <boundnormal_set>: " + re.escape(message)) as exc:
        build(tmp_path, special=initialize(text, "0"))
    assert exc.value.exit_code == 2


# ---------------------------------------------------------------------------- <accinput mkfluid>
@pytest.mark.parametrize("text, mks, note", [
    ("1,,3", [1, 3], "an empty item (two commas in a row, or a leading one) is skipped"),
    ("1, ,3", [0, 1, 3], "the blank item ' ' is read as 0"),
    ("1-", [1], "'1-' has no end value: read as 1 alone"),
    ("", [0], 'mkfluid="" is read as mkfluid 0'),              # StrIsIntegerNumber(""): atoi gives 0
    (" ", [0], 'mkfluid=" " is read as mkfluid 0'),
    ("1-3:2", [1, 3], None),
    ("1,", [1], None),
    ("+2", [2], None),                                          # one integer: GetAttributeWord
    ("2.0", [2], None),
])
def test_accinput_mkfluid_forms(tmp_path, text, mks, note):
    """<accinput mkfluid>: the mkfluids DualSPHysics imposes the acceleration on (before: an error for
    each list with an empty or blank item, for "1-", "" and "+2")."""
    r = build(tmp_path, special=ACC.format(text))
    assert [a["mkfluid"] for a in r.case.special["accinputs"]] == [mks]
    if note is None:
        assert not list_warnings(r, "accinput")
    else:
        one_warning(r, "accinput", note)


@pytest.mark.parametrize("text, message", [
    ("3-1", 'mkfluid="3-1" gives no mkfluid (DualSPHysics stops: "The mkfluid is invalid.")'),
    ("-3", "mkfluid='-3' is not a 16-bit mk value"),           # an integer: GetAttributeWord refuses < 0
    ("70000", "mkfluid='70000' is not a 16-bit mk value"),
    ("a", "mkfluid: 'a' in mk list 'a' is not a non-negative integer"),
    ("1.5", "mkfluid: '1.5' in mk list '1.5' is not a non-negative integer"),
])
def test_accinput_mkfluid_errors(tmp_path, text, message):
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <accinput>: " + re.escape(message)) as exc:
        build(tmp_path, special=ACC.format(text))
    assert exc.value.exit_code == 2


# ---------------------------------------------------------------------------- <properties><links>
def links(attr, text):
    return f'<properties>{STEEL}<links><link {attr}="{text}" property="steel"/></links></properties>'


@pytest.mark.parametrize("text, mks, note", [
    ("1,,2", [1, 2], "an empty item (two commas in a row, or a leading one) is skipped"),
    ("1, ,2", [1, 2], "an empty item"),            # AddLink drops the blank: an empty item, not 0
    ("1-", [1], "'1-' has no end value: read as 1 alone"),
    ("2-1", [], "'2-1' ends before it starts: it gives nothing"),
    (" 1 - 2 ,", [1, 2], None),
    ("0-2:2", [0, 2], None),
])
def test_link_lists_read_as_jcaseproperties(tmp_path, text, mks, note):
    """<link mkbound>: blanks dropped, then JRangeFilter (before: an error for "1,,2", "1, ,2", "1-"
    and "2-1")."""
    r = build(tmp_path, casedef_extra=links("mkbound", text))
    assert [ln["mkbound"] for ln in r.case.material_links] == [mks]
    if note is None:
        assert not list_warnings(r, "link")
    else:
        one_warning(r, "link", f'mkbound="{text}"', note, "its blanks dropped, then JRangeFilter")


def test_link_global_mk_list(tmp_path):
    """<link mk> (the global mk) read the same way: "1, ,10" is mk 1 and 10 (mkfluid 0, mkbound 0)."""
    r = build(tmp_path, casedef_extra=links("mk", "1, ,10"))
    (ln,) = r.case.material_links
    assert ln["mkfluid"] == [0] and ln["mkbound"] == [0]
    one_warning(r, "link", 'mk="1, ,10"', "an empty item")


@pytest.mark.parametrize("text", ["", "  "])
def test_empty_link_is_dropped(tmp_path, text):
    """A list empty once its blanks go: AddLink drops the link (before: "empty mk list" error)."""
    r = build(tmp_path, casedef_extra=links("mkfluid", text))
    assert r.case.material_links == []
    one_warning(r, "link", "DualSPHysics drops this <link> (JCasePropLinks::AddLink)")


@pytest.mark.parametrize("text, message", [
    ("1 2", 'mkbound="1 2": a blank inside a number'),      # AddLink would read 12
    ("a", "mkbound: 'a' in mk list 'a' is not a non-negative integer"),
])
def test_link_list_errors(tmp_path, text, message):
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <link>: " + re.escape(message)) as exc:
        build(tmp_path, casedef_extra=links("mkbound", text))
    assert exc.value.exit_code == 2


# ---------------------------------------------------------------------------- <outputparts><filtermk>
def filtermk(field, text=None):
    v = "" if text is None else f' v="{text}"'
    return (f'<outputparts preselection="none"><filtermk operation="add"><{field}{v}/></filtermk>'
            '</outputparts>')


@pytest.mark.parametrize("text, lo, hi, note", [
    ("2-", 2, 2, "'2-' has no end value: read as 2 alone"),
    ("-2", 0, 2, "'-2' has no start value: read as 0-2"),
    ("", 0, 0, "the empty value is read as 0"),
    ("2-1", 2, 1, "'2-1' ends before it starts: it selects nothing"),
    (None, 0, 0, "no v: read as 0"),
    (" 1 - 2 ", 1, 2, None),
])
def test_filtermk_forms(tmp_path, text, lo, hi, note):
    """<filtermk><mkbound v>: the range JDsOutputPartsOp_Mk selects (before: an error for each of
    these but the last)."""
    r = build(tmp_path, special=filtermk("mkbound", text))
    (f,) = r.case.special["outputparts"]["filters"]
    assert (f["field"], f["lo"], f["hi"]) == ("mkbound", lo, hi)
    if note is None:
        assert not list_warnings(r, "mkbound")
    else:
        one_warning(r, "mkbound", note, "as DualSPHysics reads it (JDsOutputPartsOp_Mk)")


@pytest.mark.parametrize("text, message", [
    ("1-2-3", "'1-2-3' has more than one '-'"),             # DualSPHysics reads 1-2, dropping -3
    ("1,2", "'1,2' in mk list '1,2' is not a non-negative integer"),     # atoi reads 1
    ("a", "'a' in mk list 'a' is not a non-negative integer"),
])
def test_filtermk_errors(tmp_path, text, message):
    with pytest.raises(CaseError, match=r"<mkfluid>: v='.*' is not an mk value or range \(" + re.escape(message)):
        build(tmp_path, special=filtermk("mkfluid", text))


def test_filtermk_and_integer_parsers():
    """The two DualSPHysics parsers the others rest on: StrSplitCount's pieces, StrIsIntegerNumber."""
    assert parse_filtermk("20-25-")[:2] == (20, 25)            # a trailing '-' makes no piece
    assert parse_filtermk("20- ")[:2] == (20, 0)
    assert [str_is_integer_number(t) for t in ("", " 3 ", "+3", "-3", "3.00", "3.5", "1,2", "1-3")] == \
        [True, True, True, True, True, False, False, False]


# ---------------------------------------------------------------------------- GenCase's lists
@pytest.mark.parametrize("extra, tag", [
    ('<floatings><floating mkbound="1,,2" rhopbody="500"/></floatings>', "floating"),
    ('<initials><velocity mkfluid="0,,1" x="1" y="0" z="0"/></initials>', "velocity"),
    ('<normals><norset mkbound="0,,1"><normal x="0" y="0" z="1"/></norset></normals>', "norset"),
])
def test_gencase_lists_keep_their_errors(tmp_path, extra, tag):
    """GenCase's lists: its reader is not public, so an empty item stays an error (<floating>'s from
    the schema's mk list pattern)."""
    with pytest.raises(CaseError, match=rf"<{tag}>: .*(empty item in mk list|the value) '(0,,1|1,,2)'"):
        build(tmp_path, casedef_extra=extra)

"""<chrono> mkbound lists read as DualSPHysics reads them (audit hunt11/m finding 2).

JChronoObjects::ReadXml and ReadScaleForces pass the attribute to JRangeFilter::Config: the text is cut
at each comma (fun::StrSplit, so a trailing comma ends the list), an empty item is skipped, each number is
read with C's atoi (a blank one is 0), ``a-`` is a alone, ``-b`` and a reversed range give nothing,
``a-b:step`` steps. sphdvi reads the same values and warns where the list was almost surely mistyped;
before, any empty item was an error ("empty item in mk list"). The other lists DualSPHysics reads
(initialize, accinput, links, filtermk) are in test_mk_lists_other.py; GenCase's keep their errors."""
import re

import pytest
from test_chrono_checks import build, chrono_warnings      # tests/case (on the path: conftest)

from sphdvi.case.mkrange import parse_mk_range, parse_range_filter
from sphdvi.errors import CaseError


@pytest.mark.parametrize("text, values, note", [
    ("1,3", [1, 3], None),
    ("0-3,7", [0, 1, 2, 3, 7], None),
    (" 1 - 3 ", [1, 2, 3], None),                   # atoi skips leading blanks and stops at trailing ones
    ("1,", [1], None),                              # StrSplit: a trailing comma ends the list
    ("1-9:2", [1, 3, 5, 7, 9], None),               # AddRangeStep
    ("1-9:", list(range(1, 10)), None),
    ("", [], None),
    ("1,,3", [1, 3], "an empty item"),              # Config skips an empty item
    (",1", [1], "an empty item"),
    ("1, ,3", [0, 1, 3], "the blank item ' ' is read as 0"),   # atoi(" ") = 0
    ("1, ", [0, 1], "the blank item ' ' is read as 0"),
    ("1, -3", [0, 1, 2, 3], "the blank start of ' -3' is read as 0"),
    ("1-", [1], "'1-' has no end value: read as 1 alone"),
    ("-3", [], "'-3' has no start value: it gives nothing"),
    ("3-1", [], "'3-1' ends before it starts: it gives nothing"),
    ("1-9:0", [], "'1-9:0' has a step of 0: it gives nothing"),
    ("1- ", [], "ends before it starts"),           # atoi(" ") = 0 < 1
])
def test_range_filter_forms(text, values, note):
    """Each form read as JRangeFilter::Config reads it, with a note where a typo is likely."""
    got, notes = parse_range_filter(text)
    assert got == values
    if note is None:
        assert notes == []
    else:
        assert any(note in n for n in notes), notes


@pytest.mark.parametrize("text, message", [
    ("a", "'a' in mk list 'a' is not a non-negative integer"),
    ("1.5", "'1.5' in mk list '1.5' is not a non-negative integer"),
    ("1 2", "'1 2' in mk list '1 2' is not a non-negative integer"),
    ("1--3", "'-3' in mk list '1--3' is not a non-negative integer"),
    ("1-:2", "':2' in mk list '1-:2' is not a non-negative integer"),
    ("70000", "mk 70000 is larger than 65535"),
    ("0-99999", "mk 99999 is larger than 65535"),
])
def test_range_filter_errors(text, message):
    """What atoi would read as some other number (or DualSPHysics truncate to 16 bits) is an error."""
    with pytest.raises(ValueError, match=re.escape(message)):
        parse_range_filter(text)


@pytest.mark.parametrize("mkbound, bodies, note", [
    ("1,,2", [("A1", 1), ("A2", 2)], r"an empty item \(two commas in a row, or a leading one\) is skipped"),
    (",1", [("A", 1)], r"an empty item"),
    ("1-", [("A", 1)], r"'1-' has no end value: read as 1 alone"),
])
def test_body_lists_read_as_dualsphysics(tmp_path, mkbound, bodies, note):
    """A <bodyfloating> list with an empty item or an open range: the bodies DualSPHysics makes, and a
    warning naming the file, line, element and the list read (before: an error for the empty item)."""
    r = build(tmp_path, f'<bodyfloating id="A" mkbound="{mkbound}"/>')
    assert [(b["id"], b["mkbound"]) for b in r.case.special["chrono"]["bodies"]] == bodies
    (w,) = chrono_warnings(r)
    assert re.search(rf"Case_Def\.xml:\d+: warning: <bodyfloating>: mkbound=\"{re.escape(mkbound)}\": {note}.*, as "
                     r"DualSPHysics's mk list parser \(JRangeFilter\) reads it, so the list is", w), w


def test_blank_item_is_mkbound_0(tmp_path):
    """mkbound="1, ,2": the blank item is 0 for DualSPHysics (atoi), so the body list is 0, 1, 2; the
    user almost surely did not mean body 0: a warning says so."""
    r = build(tmp_path, '<bodyfixed id="F" mkbound="1, ,2"/>')
    assert [(b["id"], b["mkbound"]) for b in r.case.special["chrono"]["bodies"]] == [("F0", 0), ("F1", 1),
                                                                                     ("F2", 2)]
    (w,) = chrono_warnings(r)
    assert "mkbound=\"1, ,2\": the blank item ' ' is read as 0" in w and "so the list is 0-2" in w


def test_spaces_and_trailing_comma_are_silent(tmp_path):
    """" 1 - 2 ," reads 1 and 2 (atoi skips blanks; the trailing comma ends the list): no warning."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound=" 1 - 2 ,"/>')
    assert [(b["id"], b["mkbound"]) for b in r.case.special["chrono"]["bodies"]] == [("A1", 1), ("A2", 2)]
    assert chrono_warnings(r) == []


@pytest.mark.parametrize("mkbound, note", [("-2", r"'-2' has no start value"), ("2-1", r"'2-1' ends before it starts")])
def test_body_list_giving_nothing_is_skipped(tmp_path, mkbound, note):
    """"-2" or "2-1": JRangeFilter gives no value, so ReadXml makes no body: skipped with warnings, the
    other body kept."""
    r = build(tmp_path, f'<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="{mkbound}"/>')
    assert [b["id"] for b in r.case.special["chrono"]["bodies"]] == ["A"]
    ws = chrono_warnings(r)
    assert len(ws) == 2
    assert any(re.search(note + r": it gives nothing", w) for w in ws), ws
    assert any(f"body 'B' has no mkbound (mkbound=\"{mkbound}\" gives none): it defines no body and is skipped" in w
               for w in ws), ws


def test_link_to_a_body_whose_list_gives_nothing_is_an_error(tmp_path):
    """As for mkbound="": DualSPHysics stops ("idbody1 'B' is not found."), so does sphdvi."""
    with pytest.raises(CaseError, match=r"idbody1='B' names the body of line \d+, whose mkbound list is empty"):
        build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2-1"/>'
                        '<link_spheric idbody1="B"><rotpoint x="0.15" y="0" z="0.5"/></link_spheric>')


@pytest.mark.parametrize("mkbound, message", [
    ("a", r"mkbound: 'a' in mk list 'a' is not a non-negative integer"),
    ("1.5", r"mkbound: '1\.5' in mk list '1\.5' is not a non-negative integer"),
    ("70000", r"mkbound: mk 70000 is larger than 65535"),
])
def test_body_list_errors(tmp_path, mkbound, message):
    """Letters, decimals, a value beyond 16 bits: a gencase error naming the file, line and element."""
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <bodyfloating>: " + message) as exc:
        build(tmp_path, f'<bodyfloating id="A" mkbound="{mkbound}"/>')
    assert exc.value.exit_code == 2


def test_scaleforce_lists(tmp_path):
    """<scaleforce><body mkbound>: JRangeFilter too (ReadScaleForces): "1,,2" is 1 and 2 with a warning;
    "2-1" scales nothing (a warning; the item is dropped)."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2"/>'
                        '<scaleforce><body mkbound="1,,2" x="1" y="1" z="0.5"/>'
                        '<body mkbound="2-1" x="2" y="2" z="2"/></scaleforce>')
    (item,) = r.case.special["chrono"]["scaleforce"]
    assert item["mkbound"] == [1, 2] and item["scale"] == [1.0, 1.0, 0.5]
    ws = chrono_warnings(r)
    assert any('<body>: mkbound="1,,2": an empty item' in w for w in ws), ws
    assert any('<body>: mkbound="2-1" gives no mkbound: this <body> scales nothing' in w for w in ws), ws


def test_other_mk_lists_keep_their_errors(tmp_path):
    """GenCase's lists (here <floating mkbound>, parse_mk_range; its reader is not public) still refuse
    an empty item."""
    with pytest.raises(ValueError, match="empty item in mk list '1,,2'"):
        parse_mk_range("1,,2")

"""<chrono> bodies and links naming nothing, as DualSPHysics's JChronoObjects::ReadXml reads them
(audit hunt10/b finding 2): a body whose mkbound list is empty defines no body (JRangeFilter("")
has no value) and is skipped, with a warning; a link must name bodies that exist ("idbody1 'x' is
not found." stops DualSPHysics: there is no skipping of links), idbody2="NULL" being the ground."""
import re

import pytest
from test_chrono_checks import build, chrono_warnings      # tests/case (on the path: conftest)

from sphdvi.errors import CaseError

SPHERIC = '<link_spheric idbody1="{b1}"{b2}><rotpoint x="0.15" y="0" z="0.5"/></link_spheric>'


def test_body_with_an_empty_mkbound_is_skipped(tmp_path):
    """mkbound="": no body, a warning naming the file, line and element; the case builds, the other
    body and its link are kept (before: an error, "mkbound: empty mk list")."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound=""/>'
                        + SPHERIC.format(b1="A", b2=""))
    chrono = r.case.special["chrono"]
    assert [b["id"] for b in chrono["bodies"]] == ["A"]
    assert [(ln["name"], ln["idbody1"], ln.get("idbody2")) for ln in chrono["links"]] == [("Link_A", "A", None)]
    (w,) = [w for w in chrono_warnings(r) if "empty mkbound" in w]
    assert re.search(r"Case_Def\.xml:\d+: warning: <bodyfloating>: body 'B' has an empty mkbound list: it defines no body "
                     r"and is skipped, as DualSPHysics skips it", w), w


def test_only_bodies_with_empty_mkbounds(tmp_path):
    """Every body skipped: no body and no link, and the warning DualSPHysics's refusal gets."""
    r = build(tmp_path, '<bodyfloating id="B" mkbound=""/>')
    assert r.case.special["chrono"]["bodies"] == [] and r.case.special["chrono"]["links"] == []
    ws = chrono_warnings(r)
    assert any("body 'B' has an empty mkbound list" in w for w in ws)
    assert any("<chrono> defines no body" in w for w in ws)


def test_link_to_a_skipped_body_is_an_error(tmp_path):
    """A link naming the skipped body: DualSPHysics stops ("idbody1 'B' is not found."), so does sphdvi."""
    with pytest.raises(CaseError, match=r"<link_spheric>: idbody1='B' names the body of line \d+, whose mkbound "
                                        r"list is empty: .*\"idbody1 'B' is not found\.\""):
        build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound=""/>'
                        + SPHERIC.format(b1="B", b2=""))


@pytest.mark.parametrize("b1, b2", [("", ""), ("A", ' idbody2=""')])
def test_link_with_an_empty_body_id_is_an_error(tmp_path, b1, b2):
    """idbody1="" or idbody2="": no body has that id, an error in DualSPHysics ("idbody1 '' is not
    found.") and in sphdvi (kept)."""
    which = "idbody1" if not b1 else "idbody2"
    with pytest.raises(CaseError, match=rf"<link_spheric>: {which}='' names no body; expected one of A"):
        build(tmp_path, '<bodyfloating id="A" mkbound="1"/>' + SPHERIC.format(b1=b1, b2=b2))


def test_idbody2_null_is_the_ground(tmp_path):
    """idbody2="NULL" is DualSPHysics's default (GetAttributeStr(.., "idbody2", true, "NULL")): the link
    holds body 1 to the ground, named Link_<id1> (before: "idbody2='NULL' names no body")."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/>' + SPHERIC.format(b1="A", b2=' idbody2="NULL"'))
    (ln,) = r.case.special["chrono"]["links"]
    assert (ln["name"], ln["idbody1"], ln.get("idbody2")) == ("Link_A", "A", None)

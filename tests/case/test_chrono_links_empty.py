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


# the links of two bodies, body 2 left to the ground (audit hunt10/b2 finding 2)
TWO_BODY = {
    "link_linearspring": '<point_fb1 x="0.15" y="0" z="0.33"/><point_fb2 x="0.45" y="0" z="0.33"/>'
                         '<stiffness value="100"/><damping value="1"/><rest_length value="0.3"/>',
    "link_coulombdamping": '<point_fb1 x="0.15" y="0" z="0.33"/><point_fb2 x="0.45" y="0" z="0.33"/>'
                           '<rest_length value="0.3"/><damping value="5"/>',
    "link_pulley": '<rotpoint x="0.15" y="0" z="0.33"/><rotvector x="0" y="1" z="0"/><radius value="0.1"/>'
                   '<radius2 value="0.05"/>',
}
SAYS = {"link_linearspring": r"it stops at the start of the run: \"Link without two bodies reference\.\"",
        "link_coulombdamping": r"it stops at the start of the run: \"Link without two bodies reference\.\"",
        "link_pulley": r"\"Link-Pulley uses two bodies\.\""}


@pytest.mark.parametrize("tag", sorted(TWO_BODY))
@pytest.mark.parametrize("b2, given", [(' idbody2="NULL"', r'idbody2="NULL" \(the ground\)'),
                                       ("", r'no idbody2 \(DualSPHysics reads it as "NULL", the ground\)')])
def test_two_body_link_to_the_ground_is_an_error(tmp_path, tag, b2, given):
    """idbody2="NULL" (or none, which DualSPHysics reads as "NULL") on a spring, a Coulomb damper or a
    pulley: an error saying the ground was given where a second body is needed and what DualSPHysics
    says of it (before: "missing attribute 'idbody2'", misleading when NULL was written)."""
    link = f'<{tag} idbody1="A"{b2}>{TWO_BODY[tag]}</{tag}>'
    with pytest.raises(CaseError, match=rf"<{tag}>: <{tag}> joins two bodies but has {given}, which it cannot take "
                                        rf"\(DualSPHysics: {SAYS[tag]}\); expected idbody2 naming a second body "
                                        r"defined in <chrono> .*: one of A, B"):
        build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfloating id="B" mkbound="2"/>' + link)


@pytest.mark.parametrize("tag", ["link_linearspring", "link_coulombdamping"])
def test_two_body_link_to_a_fixed_body_is_read(tmp_path, tag):
    """The way to hold a spring or damper to the ground: a <bodyfixed> as body 2 (read as before)."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfixed id="floor" mkbound="0"/>'
                        f'<{tag} idbody1="A" idbody2="floor">{TWO_BODY[tag]}</{tag}>')
    (ln,) = r.case.special["chrono"]["links"]
    assert (ln["name"], ln["idbody1"], ln["idbody2"]) == ("Link_A_floor", "A", "floor")


@pytest.mark.parametrize("blank", [" ", "   ", "\t"])
def test_blank_mkbound_is_mkbound_0(tmp_path, blank):
    """mkbound of blanks only: DualSPHysics's JRangeFilter makes it one item, which atoi reads as 0, so
    the body is mkbound 0 (here the floor); sphdvi reads it so too, with a warning naming the file,
    line and element, as it is almost surely a typo (before: an error, "mkbound: empty mk list").
    (A tab in an attribute reaches the parser as a blank: XML attribute-value normalisation.)"""
    r = build(tmp_path, f'<bodyfloating id="A" mkbound="1"/><bodyfixed id="floor" mkbound="{blank}"/>'
                        + SPHERIC.format(b1="A", b2=' idbody2="floor"'))
    chrono = r.case.special["chrono"]
    assert [(b["id"], b["kind"], b["mkbound"]) for b in chrono["bodies"]] == [("A", "floating", 1),
                                                                              ("floor", "fixed", 0)]
    (w,) = [w for w in chrono_warnings(r) if "blanks only" in w]
    assert re.search(r"Case_Def\.xml:\d+: warning: <bodyfixed>: mkbound=\"\s+\" \(blanks only\) is read as mkbound 0, "
                     r"as DualSPHysics reads it", w), w


def test_blank_mkbound_in_scaleforce_is_mkbound_0(tmp_path):
    """The same in <scaleforce><body mkbound=" ">: JRangeFilter there too (ReadScaleForces), so mkbound
    0, which is a <chrono> body here."""
    r = build(tmp_path, '<bodyfloating id="A" mkbound="1"/><bodyfixed id="floor" mkbound="0"/>'
                        '<scaleforce><body mkbound=" " x="1" y="1" z="0.5"/></scaleforce>')
    (item,) = r.case.special["chrono"]["scaleforce"]
    assert item["mkbound"] == [0]
    assert any("blanks only" in w and "<body>" in w for w in chrono_warnings(r))

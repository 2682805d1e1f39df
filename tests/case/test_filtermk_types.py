"""<outputparts><filtermk>: the two ends of a range are particles of one type, as DualSPHysics
v5.4's JDsOutputPartsOp_Mk::ReadXmlExtra requires of their mk blocks ("The values of the mk range
include different types of particles."); sphdvi did not check (audit hunt11/p finding 3). A range
from fluid to boundary, or between a fixed and a floating mkbound, is a CaseError at gencase
(exit 2, file:line, <filtermk>)."""
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.gencase import build_case
from sphdvi.cli import main
from sphdvi.errors import CaseError

# two fluid blocks (mkfluid 0, 1: mk 1, 2), a fixed floor (mkbound 0: mk 10), a floating box
# (mkbound 1: mk 11) and a second fixed block (mkbound 2: mk 12); fluidcount 9
COMMANDS = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.2" y="2" z="0.2" /></drawbox>
                    <setmkfluid mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.3" y="-1" z="0" /><size x="0.2" y="2" z="0.2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom</boxfill><point x="0" y="-1" z="-0.1" /><size x="1.2" y="2" z="0.05" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.7" y="-1" z="0.3" /><size x="0.1" y="2" z="0.1" /></drawbox>
                    <setmkbound mk="2" />
                    <drawbox><boxfill>solid</boxfill><point x="1" y="-1" z="0.3" /><size x="0.1" y="2" z="0.1" /></drawbox>"""
FLOATINGS = '<floatings><floating mkbound="1" rhopbody="500" /></floatings>'


def case_text(field, v):
    special = (f'<outputparts preselection="none"><filtermk operation="add"><{field} v="{v}"/></filtermk>'
               '</outputparts>')
    return case_xml(pointmin=("-0.1", "0", "-0.2"), pointmax=("1.2", "0", "0.6"), commands=COMMANDS, dp="0.05",
                    casedef_extra=FLOATINGS, special=special)


def build(tmp_path, field, v):
    tmp_path.mkdir(parents=True, exist_ok=True)
    return build_case(write_case(tmp_path, case_text(field, v)), str(tmp_path / "out"))


@pytest.mark.parametrize("field, v, what", [
    ("mk", "1-10", "mk 1 is fluid and mk 10 is fixed"),
    ("mk", "2-11", "mk 2 is fluid and mk 11 is floating"),
    ("mk", "11-12", "mk 11 is floating and mk 12 is fixed"),
    ("mkbound", "0-1", "mkbound 0 is fixed and mkbound 1 is floating"),
    ("mkbound", "1-0", "mkbound 1 is floating and mkbound 0 is fixed"),
])
def test_range_across_types_is_an_error(tmp_path, field, v, what):
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <filtermk>: <filtermk> range " + field
                       + r" \d+-\d+ includes different types of particles \(" + what + r"\): DualSPHysics stops"
                       r".*expected a range whose two ends are of one type"):
        build(tmp_path, field, v)


@pytest.mark.parametrize("field, v", [("mk", "1-2"), ("mkfluid", "0-1"), ("mk", "10"), ("mkbound", "0-2"),
                                      ("mk", "10-12"), ("mkbound", "1")])
def test_range_of_one_type_is_read(tmp_path, field, v):
    """Ends of one type pass (mkbound 0-2: both ends fixed, the floating mkbound 1 between them, as
    DualSPHysics checks the ends only)."""
    r = build(tmp_path, field, v)
    (f,) = r.case.special["outputparts"]["filters"]
    assert f["field"] == field


def test_gencase_exits_2(tmp_path):
    case = write_case(tmp_path, case_text("mk", "1-12"))
    res = CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "out")])
    assert res.exit_code == 2 and "includes different types of particles" in res.output


@pytest.mark.parametrize("field, v, mks", [("mkbound", "0-2", {10, 12}), ("mk", "10-12", {10, 12}),
                                           ("mkbound", "1", {11}), ("mk", "1-2", {1, 2})])
def test_a_block_of_another_type_inside_the_range_is_not_selected(tmp_path, field, v, mks):
    """DualSPHysics selects the particle codes between the two ends' mk blocks, all of the ends' type:
    the floating mkbound 1 (mk 11) inside the fixed range mkbound 0-2 is left out (sphdvi took every
    mk of the range)."""
    from sphdvi.output_parts import OutputParts
    r = build(tmp_path, field, v)
    p = r.particles
    sel = OutputParts(r.case.special["outputparts"], r.case.fluidcount).select(p["pos"], p["type"], p["mk"])
    assert set(p["mk"][sel].tolist()) == mks
    assert sel.sum() == sum((p["mk"] == m).sum() for m in mks)

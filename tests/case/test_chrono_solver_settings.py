"""<chrono><solver type maxiter tolerance> (an sphdvi extension: DualSPHysics v5.4's JChronoObjects::
ReadXml reads no <solver>, its Chrono library takes BB under NSC and MINRES under SMC): the names map
to sphdvi's solvers, a substituted method is warned about, an unknown attribute gets the reader's
unknown-attribute warning, and maxiter/tolerance reach the multibody System (audit hunt10/c
findings 1 and 2)."""
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.case.gencase import build_case
from sphdvi.cli import main
from sphdvi.dvi.runner import build_system
from sphdvi.errors import CaseError
from sphdvi.io.casefile import read_case_h5
from sphdvi.mechanism import mechanism_from_case

BODIES = """
                    <setmkbound mk="1" />
                    <drawbox><boxfill>solid</boxfill><point x="0.1" y="-0.1" z="0.3" />
                        <size x="0.1" y="0.2" z="0.1" /></drawbox>"""
FLOATINGS = '<floatings><floating mkbound="1" rhopbody="500" /></floatings>'
HINGE = '<link_hinge idbody1="A"><rotpoint x="0" y="0" z="0.35"/><rotvector x="0" y="1" z="0"/></link_hinge>'


def case_text(solver):
    chrono = f'<chrono><bodyfloating id="A" mkbound="1"/>{HINGE}{solver}</chrono>'
    return case_xml(pointmin=("-0.5", "-0.5", "-0.5"), pointmax=("0.7", "0.5", "0.8"), commands=BODIES,
                    casedef_extra=FLOATINGS, special=chrono, parameters='<parameter key="RigidAlgorithm" value="3" />',
                    dp="0.05")


def build(tmp_path, solver):
    return build_case(write_case(tmp_path, case_text(solver)), str(tmp_path / "out"))


def solver_warnings(r):
    return [w for w in r.warnings if "solver" in w]


def test_solver_settings_are_read(tmp_path):
    r = build(tmp_path, '<solver type="BB" maxiter="2000" tolerance="1e-8"/>')
    assert r.case.special["chrono"]["solver"] == {"type": "bb", "maxiter": 2000, "tolerance": 1e-8}
    assert solver_warnings(r) == []


def test_unknown_solver_attribute_warns(tmp_path):
    """Before: every attribute of <solver> was marked read, so a misspelt one vanished silently."""
    r = build(tmp_path, '<solver type="BB" iterations="2000"/>')
    (w,) = solver_warnings(r)
    assert "unknown attribute 'iterations' ignored" in w
    assert r.case.special["chrono"]["solver"] == {"type": "bb"}


@pytest.mark.parametrize("name, method, replaced", [
    ("MINRES", "direct", "Chrono's MINRES"), ("PMINRES", "direct", "Chrono's projected MINRES"),
    ("SPARSE_LU", "direct", "Chrono's sparse LU"), ("PJACOBI", "psor", "Chrono's projected Jacobi")])
def test_substituted_solver_is_warned_about(tmp_path, name, method, replaced):
    r = build(tmp_path, f'<solver type="{name}"/>')
    assert r.case.special["chrono"]["solver"]["type"] == method
    (w,) = solver_warnings(r)
    assert f'<solver type="{name}">: {replaced}' in w and "is used instead" in w


@pytest.mark.parametrize("name, method", [("bb", "bb"), ("Barzilai_Borwein", "bb"), ("PSOR", "psor"),
                                          ("APGD", "apgd"), ("direct", "direct")])
def test_solver_names(tmp_path, name, method):
    r = build(tmp_path, f'<solver type="{name}"/>')
    assert r.case.special["chrono"]["solver"]["type"] == method and solver_warnings(r) == []


@pytest.mark.parametrize("solver, message", [
    ('<solver type="CG"/>', r"<solver type='CG'> is not a known solver"),
    ('<solver maxiter="0"/>', r"maxiter='0' is below 1"),
    ('<solver tolerance="-1"/>', r"tolerance='-1' is negative")])
def test_bad_solver_settings_are_errors(tmp_path, solver, message):
    with pytest.raises(CaseError, match=r"Case_Def\.xml:\d+: <solver>: " + message):
        build(tmp_path, solver)


def test_solver_settings_reach_the_system(tmp_path):
    case = write_case(tmp_path, case_text('<solver type="MINRES" maxiter="321" tolerance="1e-7"/>'))
    r = CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "out")])
    assert r.exit_code == 0, r.output
    data = read_case_h5(str(next((tmp_path / "out").glob("*.h5"))))
    mech = mechanism_from_case(data)
    assert mech["system"]["solver"] == "direct" and mech["warnings"] == []
    system, _ = build_system(mech["bodies"], mech["links"], mech["materials"], **mech["system"])
    assert (system.solver, system.max_iter, system.tol) == ("direct", 321, 1e-7)


@pytest.mark.parametrize("where", ["collision", "chrono"])
@pytest.mark.parametrize("threads", ["0", "1"])
def test_ompthreads_is_read_in_collision_and_at_chrono_level(tmp_path, where, threads):
    """DualSPHysics v5.x's chrono examples CaseExternalVelocity and CaseBreakingWall put
    <ompthreads> (Chrono's threads: 0 all cores, 1 one) inside <collision>; it was refused there
    (exit 2), and 0 was refused at the chrono level. Read silently, no effect."""
    omp = f'<ompthreads value="{threads}"/>'
    col = ('<collision activate="true"><distancedp value="0.5"/>'
           f'{omp if where == "collision" else ""}</collision>')
    r = build(tmp_path, col + (omp if where == "chrono" else ""))
    assert r.case.special["chrono"]["collision"]["activate"]
    assert not [w for w in r.warnings if "ompthreads" in w]


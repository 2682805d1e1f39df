"""``<special><outputparts>`` (DualSPHysics's JDsOutputParts): the selection rules against
hand-made particle sets, the particle output of a run against the full one, and the case errors."""
import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.vtkhdf import read_step, step_times
from sphdvi.output_parts import OutputParts

from run.test_run import REPO, assert_gencase_error, small_case

COMMON = ["--threads", "1", "-q"]
FLUIDCOUNT = 9


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def flt(kind, operation="add", inverse=False, **kw):
    return dict(kind=kind, operation=operation, inverse=inverse, ftfollow=kw.pop("ftfollow", None), **kw)


def grid():
    """Particles on a 11 x 11 lattice of 0.1 in x-z; the left column boundary (mkbound 3,
    mk 13), the bottom row moving (mkbound 5, mk 15), the rest fluid (mkfluid 0 and 1)."""
    x, z = np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 1, 11), indexing="ij")
    pos = np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])
    ptype = np.full(x.size, 3)
    mk = np.where(pos[:, 0] < 0.5, 1, 2)
    ptype[pos[:, 2] < 0.05] = 1
    mk[pos[:, 2] < 0.05] = 5 + FLUIDCOUNT + 1
    ptype[pos[:, 0] < 0.05] = 0
    mk[pos[:, 0] < 0.05] = 3 + FLUIDCOUNT + 1
    return pos, ptype, mk


def select(filters, preselection="none", centres=None, **kw):
    pos, ptype, mk = grid()
    spec = {"preselection": preselection, "filters": filters, **kw}
    return OutputParts(spec, FLUIDCOUNT).select(pos, ptype, mk, centres), pos, ptype, mk


def test_box_plane_sphere_cylinder():
    sel, pos, _, _ = select([flt("pos", posmin=[0.25, None, None], posmax=[0.55, None, 0.35])])
    assert np.array_equal(sel, (pos[:, 0] >= 0.25) & (pos[:, 0] <= 0.55) & (pos[:, 2] <= 0.35))
    # the side the (unnormalised) vector points to, within 0.3 of the plane x + z = 1.05:
    # the lattice's diagonals x + z = 1.1 ... 1.4
    sel, pos, _, _ = select([flt("plane", point=[1.05, 0, 0], vector=[2, 0, 2], distance=0.3)])
    s = pos[:, 0] + pos[:, 2]
    assert np.array_equal(sel, (s > 1.05) & (s < 1.05 + 0.3 * np.sqrt(2))) and sel.sum() == 10 + 9 + 8 + 7
    sel, pos, _, _ = select([flt("sphere", centre=[0.5, 0, 0.5], radius=0.25)])
    assert np.array_equal(sel, np.linalg.norm(pos - [0.5, 0, 0.5], axis=1) < 0.25) and sel.sum() == 21
    # a slanted cylinder along the diagonal, 0.1 around it, between its end planes: the
    # diagonal from 0.2 to 0.8 (7) and its two neighbours with x + z from 0.3 to 1.7 (8 each)
    sel, pos, _, _ = select([flt("cylinder", point1=[0.14, 0, 0.14], point2=[0.86, 0, 0.86], radius=0.1)])
    along = (s > 0.28) & (s < 1.72)
    off = np.abs(pos[:, 0] - pos[:, 2]) / np.sqrt(2)
    assert np.array_equal(sel, along & (off < 0.1)) and sel.sum() == 7 + 16
    # without <radius> (JDsOutputPartsOp_Cylinder: DBL_MAX) the slab between the end planes
    sel, pos, _, _ = select([flt("cylinder", point1=[0.14, 0, 0.14], point2=[0.86, 0, 0.86], radius=None)])
    assert np.array_equal(sel, along)


def test_operations_inverse_types_mk_and_groups():
    _, pos, ptype, mk = select([])
    fluid = ptype == 3
    # all, then delete the fluid, then add the mkfluid 1 block back
    sel, *_ = select([flt("type", "del", types=["fluid"]), flt("mk", field="mkfluid", lo=1, hi=1)], "all")
    assert np.array_equal(sel, ~fluid | (fluid & (mk == 2)))
    # "bound" is fixed, moving and floating; confirm keeps those also inside the box
    sel, *_ = select([flt("type", types=["bound"]), flt("pos", "confirm", posmin=[None, None, None],
                                                           posmax=[0.35, None, None])])
    assert np.array_equal(sel, ~fluid & (pos[:, 0] < 0.35))
    # inverse: everything outside the sphere; del with inverse keeps only what is inside
    sel, *_ = select([flt("sphere", inverse=True, centre=[0, 0, 0], radius=0.55)])
    inside = np.linalg.norm(pos, axis=1) < 0.55
    assert np.array_equal(sel, ~inside)
    sel, *_ = select([flt("sphere", "del", inverse=True, centre=[0, 0, 0], radius=0.55)], "all")
    assert np.array_equal(sel, inside)
    # mk, mkbound and mkfluid ranges
    sel, *_ = select([flt("mk", field="mkbound", lo=3, hi=5)])
    assert np.array_equal(sel, ~fluid)
    sel, *_ = select([flt("mk", field="mk", lo=14, hi=20)])
    assert np.array_equal(sel, mk == 15)
    # a group (fluid less the left half) deleted from all: the boundary and the fluid's left half
    group = flt("group", "del", preselection="none",
                filters=[flt("type", types=["fluid"]), flt("pos", "del", posmin=[None] * 3, posmax=[0.45, None, None])])
    sel, *_ = select([group], "all")
    assert np.array_equal(sel, ~fluid | (fluid & (pos[:, 0] <= 0.45)))


def test_filters_follow_a_floating_body_and_ignore_keeps_every_nth_output():
    follow = {"mkbound": 7, "centre0": [0.2, 0.0, 0.2]}
    f = flt("sphere", ftfollow=follow, centre=[0.2, 0, 0.2], radius=0.15)
    sel0, pos, _, _ = select([f])
    sel1, *_ = select([f], centres={7: np.array([0.7, 0.0, 0.4])})
    assert sel0.sum() == sel1.sum() == 9
    assert np.array_equal(sel1, np.linalg.norm(pos - [0.7, 0, 0.4], axis=1) <= 0.15)
    box = flt("pos", ftfollow=follow, posmin=[0.15, None, None], posmax=[None, None, 0.15])
    sel, *_ = select([box], centres={7: np.array([0.5, 0.0, 0.5])})     # moved by (0.3, 0, 0.3)
    assert np.array_equal(sel, (pos[:, 0] > 0.45) & (pos[:, 2] < 0.45)) and sel.sum() == 6 * 5
    op = OutputParts({"preselection": "none", "filters": [], "ignore": 3}, FLUIDCOUNT)
    assert [op.applies_to(k) for k in range(7)] == [False, True, True, False, True, True, False]
    assert all(OutputParts({"preselection": "none", "filters": []}, FLUIDCOUNT).applies_to(k) for k in range(4))


OUTPUTPARTS = ('<outputparts preselection="none"><ignore nparts="3"/>'
               '<filtertype operation="add"><type v="fluid"/></filtertype>'
               '<filterpos operation="del"><posmin x="0.3"/></filterpos>'
               '<filtermk operation="add"><mkbound v="0"/></filtermk>'
               '<filterpos operation="confirm"><posmax z="0.5"/></filterpos>'
               '<filtersphere operation="add" active="false"><centre x="0" y="0" z="0"/><radius v="9"/></filtersphere>'
               '</outputparts>')


def with_special(tmp_path, section):
    path = small_case(tmp_path)
    path.write_text(path.read_text().replace("<special>", "<special>" + section, 1))
    return path


def test_a_run_writes_the_selected_particles_of_the_full_output(tmp_path):
    """Fluid with x < 0.3 and the walls, all below z = 0.5; every third output whole; the run
    itself is unchanged (bitwise the full run's particles)."""
    full, part = tmp_path / "full", tmp_path / "part"
    plain = small_case(tmp_path)
    assert invoke(["run", plain, "-o", full, "--tmax", "0.025", "--tout", "0.005"] + COMMON).exit_code == 0
    (tmp_path / "p").mkdir()
    case = with_special(tmp_path / "p", OUTPUTPARTS)
    r = invoke(["run", case, "-o", part, "--tmax", "0.025", "--tout", "0.005"] + COMMON)
    assert r.exit_code == 0, r.output
    times = step_times(str(part / "particles.vtkhdf"))
    assert np.array_equal(times, step_times(str(full / "particles.vtkhdf"))) and len(times) == 6
    log = (part / "run.log").read_text()
    for k in range(6):
        a, b = read_step(str(full / "particles.vtkhdf"), k), read_step(str(part / "particles.vtkhdf"), k)
        if k % 3 == 0:
            keep = np.ones(a["Idp"].size, bool)
            assert f"Part {k:04d}" in log and f"Part {k:04d}" not in [ln[:9] for ln in log.splitlines()
                                                                      if "written=" in ln]
        else:
            x, z = a["points"][:, 0], a["points"][:, 2]
            keep = ((a["Type"] == 3) & (x < 0.3) | (a["Type"] != 3)) & (z <= 0.5)
            assert f"written={int(keep.sum())}" in log
        assert 0 < keep.sum()
        for name in ("Idp", "points", "Vel", "Rhop", "Type", "Mk"):
            np.testing.assert_array_equal(b[name], a[name][keep], err_msg=f"{name} at output {k}")
    from sphdvi.measure.post import RunOutput
    with pytest.warns(UserWarning, match=r"holds only the particles .* \(outputs 0, 3, 6, \.\.\. whole\)"):
        RunOutput(str(part))


@pytest.mark.parametrize("section, message", [
    ('<outputparts preselection="some"/>', "preselection='some' is not recognised"),
    ('<outputparts preselection="all"><filterpos operation="drop"><posmin x="1"/></filterpos></outputparts>',
     "operation='drop' is not recognised"),
    ('<outputparts preselection="all"><filtermk operation="add"><mkfluid v="4"/></filtermk></outputparts>',
     "selects mkfluid 4, which has no particles"),
    ('<outputparts preselection="all"><filtermk operation="add"><mk v="3-x"/></filtermk></outputparts>',
     "is not an mk value or range"),
    ('<outputparts preselection="all"><filtertype operation="add"><type v="fluid,solid"/></filtertype></outputparts>',
     "particle type 'solid'"),
    ('<outputparts preselection="all"><filtersphere operation="add"><ftfollow mkbound="0"/><radius v="1"/>'
     '</filtersphere></outputparts>', "mkbound 0 is not a floating body"),
    ('<outputparts preselection="all"><filterpos operation="add"/></outputparts>', "limits nothing"),
    ('<outputparts preselection="all"><filtercube operation="add"/></outputparts>', "unknown element <filtercube>"),
])
def test_bad_outputparts_is_a_case_error(tmp_path, section, message):
    assert_gencase_error(with_special(tmp_path, section), tmp_path / "g", message)


def test_a_filter_follows_the_floating_body_in_a_run(tmp_path):
    """A sphere of 0.1537 m (no lattice distance) about the floating box's centre (no <centre>: the
    body's), the box launched at 1 m/s: each output holds exactly the particles of the full run within
    its radius of the centre bodies.csv gives at that time."""
    src = REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"
    text = src.read_text().replace('<floating mkbound="5" rhopbody="500" />',
                                   '<floating mkbound="5" rhopbody="500"><linearvelini x="1" y="0" z="0" />'
                                   '</floating>')
    assert "linearvelini" in text
    plain, follow = tmp_path / "CasePlain_Def.xml", tmp_path / "CaseFollow_Def.xml"
    plain.write_text(text)
    section = ('<outputparts preselection="none"><filtersphere operation="add"><ftfollow mkbound="5"/>'
               '<radius v="0.1537"/></filtersphere></outputparts>')
    follow.write_text(text.replace("<special>", "<special>" + section, 1) if "<special>" in text else
                      text.replace("<execution>", "<execution><special>" + section + "</special>", 1))
    common = ["--dp", "0.02", "--tmax", "0.04", "--tout", "0.01", "--threads", "1", "-q", "--set", "FtPause=0"]
    for case, out in ((plain, tmp_path / "a"), (follow, tmp_path / "b")):
        r = invoke(["run", case, "-o", out] + common)
        assert r.exit_code == 0, r.output
    from sphdvi.validation.runs import body_log
    bodies = body_log(str(tmp_path / "b"))
    moved = 0.0
    for k, t in enumerate(step_times(str(tmp_path / "b" / "particles.vtkhdf"))):
        row = bodies[np.isclose(bodies["time"], t, rtol=0, atol=1e-9)][0]
        centre = np.array([row["x"], row["y"], row["z"]])
        if k == 0:
            centre0 = centre
        moved = max(moved, abs(centre[0] - centre0[0]))
        a = read_step(str(tmp_path / "a" / "particles.vtkhdf"), k)
        b = read_step(str(tmp_path / "b" / "particles.vtkhdf"), k)
        keep = np.einsum("ij,ij->i", a["points"] - centre, a["points"] - centre) <= 0.1537 ** 2
        np.testing.assert_array_equal(b["Idp"], a["Idp"][keep], err_msg=f"output {k}")
    assert moved > 0.02            # the box has moved by more than a particle: the sphere went with it

"""<chrono> bodies in runs (audit hunt8/c findings 1, 2, 3, 5, 8): a <floating> the section does
not list moves as a free floating body (DualSPHysics integrates it itself), <scaleforce> scales
the fluid's force on a body, a point-line's stiffness is torsional (the body slides freely), a
stiffness table in a tab-separated file runs, links.csv carries DualSPHysics's link names."""
import csv
from pathlib import Path

import numpy as np
import pytest
from case.casetext import case_xml, write_case      # tests/case (tests/ is on the path: conftest)
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.coupling import FloatingBodies
from sphdvi.io.casefile import read_case_h5
from sphdvi.motion import MotionSet

PENDULUM = (Path(__file__).resolve().parents[2] / "cases" / "pendulum" / "CasePendulum_Def.xml").read_text()
G = 9.81


def tank(z1, z2, chrono):
    """The auditor's p2-p4: a 2D tank 0.6 m wide with 0.2 m of water; boxes 0.1 x 0.06 m of density
    500, mkbound 1 at x 0.1-0.2 and mkbound 2 at x 0.4-0.5, their bottoms at z1 and z2 (0.35: in the
    air, 0.12: floating half in the water)."""
    boxes = "".join(f"""
                    <setmkbound mk="{mk}" />
                    <drawbox><boxfill>solid</boxfill><point x="{x}" y="-1" z="{z}" /><size x="0.1" y="2" z="0.06" /></drawbox>"""
                    for mk, x, z in ((1, 0.1, z1), (2, 0.4, z2)))
    return case_xml(pointmin=("-0.1", "0", "-0.1"), pointmax=("0.7", "0", "0.8"), commands=f"""
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="0.6" y="2" z="0.2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right</boxfill><point x="0" y="-1" z="0" />
                        <size x="0.6" y="2" z="0.6" /></drawbox>{boxes}""",
                    casedef_extra='<floatings><floating mkbound="1" rhopbody="500" />'
                                  '<floating mkbound="2" rhopbody="500" /></floatings>',
                    special=f"<chrono>{chrono}</chrono>",
                    parameters='<parameter key="RigidAlgorithm" value="3" /><parameter key="StepAlgorithm" value="2" />'
                               '<parameter key="Visco" value="0.05" /><parameter key="DensityDT" value="2" />'
                               '<parameter key="TimeMax" value="0.1" /><parameter key="TimeOut" value="0.05" />')


def run(tmp_path, name, text, *args):
    """Run the case ``text``; bodies.csv as {body: structured array}."""
    case = write_case(tmp_path, text, f"{name}.xml")
    out = tmp_path / f"out_{name}"
    r = CliRunner().invoke(main, ["run", case, "-o", str(out), "-q", "--threads", "1", *args])
    assert r.exit_code == 0, r.output
    d = np.genfromtxt(out / "bodies.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    return {str(b): d[d["body"] == b] for b in np.unique(d["body"])}


def falls_freely(rows):
    """z and vz of free fall from rest at the first row (the row times; z to the time
    integration's O(g t dt))."""
    t = rows["time"] - rows["time"][0]
    return (np.allclose(rows["vz"], -G * t, atol=2e-3)
            and np.allclose(rows["z"], rows["z"][0] - 0.5 * G * t ** 2, atol=1e-3))


def test_unlisted_floating_falls_freely(tmp_path):
    """p2: <chrono> lists mkbound 2 only; mkbound 1, also in the air, falls at g as a free body
    (named floating1) beside it. Before, it hung where it was drawn (z 0.39 at 0.1 s)."""
    b = run(tmp_path, "p2", tank(0.35, 0.35, '<bodyfloating id="B" mkbound="2" />'))
    assert sorted(b) == ["B", "floating1"]
    assert falls_freely(b["floating1"]) and falls_freely(b["B"])
    assert b["floating1"]["time"][-1] == pytest.approx(0.1, abs=1e-3)


def test_unlisted_floating_keeps_its_own_loads(tmp_path):
    """p3: the unlisted body 1 floats in the water, the listed body 2 is in the air: body 2 falls at
    g (before it rose on body 1's buoyancy, added to the last body through index -1), body 1 is held
    up by the water (it stood still, frozen)."""
    b = run(tmp_path, "p3", tank(0.12, 0.35, '<bodyfloating id="B" mkbound="2" />'))
    assert falls_freely(b["B"])
    one = b["floating1"]
    assert abs(one["z"][-1] - one["z"][0]) < 0.01 and one["vz"][-1] > -0.3       # far from free fall's -0.98
    assert one["fz"][-1] > -40                                                   # the water bears on it (weight 47 N)


def test_scaleforce_scales_the_fluid_force(tmp_path):
    """p4: body 1 floats in the water with <scaleforce> 0: no fluid force, so it falls as body 2 in
    the air (before it rose, the factor ignored); factor 1 is the run without <scaleforce>."""
    bodies = '<bodyfloating id="A" mkbound="1" /><bodyfloating id="B" mkbound="2" />'
    zero = run(tmp_path, "zero", tank(0.12, 0.35, bodies + '<scaleforce><body mkbound="1" x="0" y="0" z="0" />'
                                                           '</scaleforce>'))
    assert falls_freely(zero["A"]) and falls_freely(zero["B"])
    plain = run(tmp_path, "plain", tank(0.12, 0.35, bodies))
    one = run(tmp_path, "one", tank(0.12, 0.35, bodies + '<scaleforce><body mkbound="1-2" x="1" y="1" z="1" />'
                                                         '</scaleforce>'))
    for name in ("A", "B"):
        for col in ("time", "z", "vz", "fz", "pitch"):
            assert np.array_equal(one[name][col], plain[name][col]), (name, col)
    assert plain["A"]["vz"][-1] > 0        # the buoyancy lifts it (it starts below its draft)


def test_scaleforce_in_3d_warns(tmp_path):
    """DualSPHysics warns that scaleforce is for 2D simulations: the same warning at run start."""
    case = write_case(tmp_path, PENDULUM.replace('</chrono>', '<scaleforce><body mkbound="1" x="0" y="1" z="1"/>'
                                                              '</scaleforce></chrono>'), "CasePendulum_Def.xml")
    r = CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "out")])
    assert r.exit_code == 0, r.output
    data = read_case_h5(str(next((tmp_path / "out").glob("*.h5"))))
    with pytest.warns(UserWarning, match=r"<chrono><scaleforce> should be used only for 2D simulations"):
        fb = FloatingBodies(data, MotionSet([], []), int(data["json"]["mkconfig"]["fluidcount"]))
    assert fb.scale.tolist() == [[0.0, 1.0, 1.0]]


POINTLINE = '''<link_pointline idbody1="pend">
                    <slidingvector x="0" y="0" z="1" />
                    <rotpoint x="0" y="0" z="-1" />
                    <rotvector x="0" y="1" z="0" />
                    <stiffness value="10000" />
                    <damping value="0" />
                </link_pointline>'''


def test_pointline_stiffness_is_torsional(tmp_path):
    """p10: the pendulum's block on a vertical point-line with stiffness 10000: it slides down the
    line in free fall (DualSPHysics: "Torsional stiffness [Nm/rad]"); before, a 10000 N/m spring
    held it about z0 - m g / k."""
    hinge = PENDULUM[PENDULUM.index("<link_hinge"):PENDULUM.index("</link_hinge>") + len("</link_hinge>")]
    b = run(tmp_path, "p10", PENDULUM.replace(hinge, POINTLINE), "--tmax", "0.1", "--tout", "0.02")
    (rows,) = b.values()
    assert rows["z"][0] == pytest.approx(-1.0)
    assert falls_freely(rows)
    assert np.allclose(rows["x"], rows["x"][0])


def test_tab_separated_stiffness_table_runs(tmp_path):
    """p1: the pendulum with <stiffness file="k.txt"/>, k.txt tab-separated: runs as the same
    table with ';' (before: an internal AxisError at run start)."""
    runs = {}
    for name, text in (("tabs", "0\t5\n10\t5\n"), ("semi", "0;5\n10;5\n"), ("inline", None)):
        d = tmp_path / name
        d.mkdir()
        stiff = '<stiffness value="5"/>' if text is None else '<stiffness file="k.txt"/>'
        if text is not None:
            (d / "k.txt").write_text(text)
        runs[name] = run(d, name, PENDULUM.replace('<rotvector x="0" y="1" z="0" />',
                                                   f'<rotvector x="0" y="1" z="0" />{stiff}'), "--tmax", "0.1")
    for name in ("tabs", "semi"):
        assert np.array_equal(runs[name]["pend"]["x"], runs["inline"]["pend"]["x"])


def test_link_names_in_links_csv(tmp_path):
    """p9: the pendulum and two unnamed link_spheric to the ground: links.csv names them as
    DualSPHysics does, Link_pend, Link_pend_2, Link_pend_3 (all Link_pend_ground before)."""
    extra = '<link_spheric idbody1="pend"><rotpoint x="0" y="0" z="0" /></link_spheric>' * 2
    case = write_case(tmp_path, PENDULUM.replace("</link_hinge>", "</link_hinge>" + extra), "p9.xml")
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", case, "-o", str(out), "-q", "--tmax", "0.01"])
    assert r.exit_code == 0, r.output
    with open(out / "links.csv") as fh:
        names = [row["link"] for row in csv.DictReader(fh)]
    assert names[:3] == ["Link_pend", "Link_pend_2", "Link_pend_3"]


def test_table_file_of_an_older_case_file(tmp_path):
    """A case file written before holds {"file": path} for a <stiffness file>: read at run start
    with the JReadDatafile layouts too (it was ';' only, an AxisError otherwise), at least two rows."""
    from sphdvi.errors import CaseError
    from sphdvi.mechanism import _table
    (tmp_path / "k.txt").write_text("# t k\n0\t10\n2\t30\n")
    assert _table({"file": str(tmp_path / "k.txt")}) == [[0.0, 10.0], [2.0, 30.0]]
    (tmp_path / "one.txt").write_text("0 10\n")
    with pytest.raises(CaseError, match=r"one\.txt: stiffness/damping table: fewer than two"):
        _table({"file": str(tmp_path / "one.txt")})


def test_loads_refuse_a_particle_of_no_body(tmp_path):
    """The loads never go to body -1 (numpy's last body, where an unlisted floating's went)."""
    from types import SimpleNamespace
    from sphdvi.sph.state import FluidState
    case = write_case(tmp_path, PENDULUM, "CasePendulum_Def.xml")
    assert CliRunner().invoke(main, ["gencase", case, "-o", str(tmp_path / "out")]).exit_code == 0
    data = read_case_h5(str(next((tmp_path / "out").glob("*.h5"))))
    fb = FloatingBodies(data, MotionSet([], []), int(data["json"]["mkconfig"]["fluidcount"]))
    p = data["particles"]
    state = FluidState(p["pos"].copy(), p["vel"].copy(), p["rhop"].copy(), p["mass"].copy(), p["type"], p["idp"], p["mk"])
    solver = SimpleNamespace(state=state, ace=np.zeros_like(state.pos), time=0.0, normals=None)
    sel = np.flatnonzero(state.ptype == 2)
    body = fb.body_of_idp[state.idp[sel]]
    assert body.min() == 0
    body[3] = -1
    with pytest.raises(RuntimeError, match="belongs to no multibody body"):
        fb.loads(solver, sel, body)

"""cases/bathymetry2d: a bed from a file of points (<drawbathymetry>) through gencase and the solver."""
import shutil
from pathlib import Path

import h5py
import numpy as np
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.vtkhdf import read_step, step_times

CASE_DIR = Path(__file__).resolve().parents[2] / "cases" / "bathymetry2d"
PROFILE = ((0, 0.05), (0.8, 0.05), (1.2, 0.2), (1.6, 0.05), (2, 0.05))   # BarBed.xyz's bed (x, z)
DP = 0.01


def bed(x):
    return np.interp(x, *zip(*PROFILE))


def case_copy(tmp_path, replace_bed_with=None):
    """The case copied into tmp_path; its <drawbathymetry> replaced by another drawing if asked."""
    for f in CASE_DIR.iterdir():
        shutil.copy(f, tmp_path / f.name)
    case = tmp_path / "CaseBathymetry2D_Def.xml"
    if replace_bed_with is not None:
        text = case.read_text()
        a = text.index("<drawbathymetry>\n")
        b = text.index("</drawbathymetry>") + len("</drawbathymetry>")
        case.write_text(text[:a] + replace_bed_with + text[b:])
    return case


def gencase_nodes(tmp_path, name, replace_bed_with=None):
    sub = tmp_path / name
    sub.mkdir()
    case = case_copy(sub, replace_bed_with)
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(sub / "out")])
    assert r.exit_code == 0, r.output
    with h5py.File(sub / "out" / "CaseBathymetry2D.h5") as f:
        pos, kind = f["particles/pos"][:], f["particles/type"][:]
    return {(tuple(np.round(p / DP).astype(int)), int(k)) for p, k in zip(pos, kind)}


def test_bed_from_points_equals_the_same_bed_drawn_otherwise(tmp_path):
    """The resampled points draw the particles a <drawextrude> of the profile draws (3,637)."""
    from_points = gencase_nodes(tmp_path, "points")
    pts = "".join(f'<point x="{x}" y="-0.5" z="{z}"/>' for x, z in PROFILE)
    extruded = gencase_nodes(tmp_path, "extrude", f'<drawextrude closed="false">{pts}'
                             '<extrude x="0" y="1" z="0"/></drawextrude>')
    assert len(from_points) == 3637 and from_points == extruded
    bound = np.array([n for n, k in from_points if k == 0])
    top = {x: bound[(bound[:, 0] == x) & (bound[:, 0] > 0) & (bound[:, 0] < 200), 2].max()
           for x in (30, 100, 120, 140, 190)}
    assert top == {30: 5, 100: 13, 120: 20, 140: 13, 190: 5}    # the bed's top node at x, in dp
    assert (tmp_path / "points" / "out" / "CaseBathymetry2D_Bathymetry_Grid.vtk").is_file()


def test_table_bed_equals_points_bed(tmp_path):
    xs = np.round(np.arange(0, 2.0001, 0.05), 4)
    table = "# BarBed as a table\nY \\ X => Z;" + ";".join(f"{x:g}" for x in xs) + "\n" + "".join(
        f"{y};" + ";".join(f"{bed(x):.4f}" for x in xs) + "\n" for y in (-0.5, 0.5))
    (tmp_path / "BarBed.csv").write_text(table)
    sub = tmp_path / "table"
    sub.mkdir()
    case = case_copy(sub, '<drawfilecsv file="BarBed.csv" mode="bathymetry"/>')
    (sub / "BarBed.csv").write_text(table)
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(sub / "out")])
    assert r.exit_code == 0, r.output
    with h5py.File(sub / "out" / "CaseBathymetry2D.h5") as f:
        table_nodes = {tuple(np.round(p / DP).astype(int)) for p in f["particles/pos"][:]}
    points = {n for n, _ in gencase_nodes(tmp_path, "points")}
    assert table_nodes == points


def test_water_runs_over_the_bar_and_never_through_the_bed(tmp_path):
    """The dam break to t = 0.4 s: no particle excluded, the front past the bar's crest
    (x = 1.2 m; 1.31 m measured), and every fluid particle at least dp/2 above the bed at each
    output (0.84 dp measured: DBC's gap)."""
    case = case_copy(tmp_path)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--tmax", "0.4", "--tout", "0.1", "-q"])
    assert r.exit_code == 0, r.output
    path = str(out / "particles.vtkhdf")
    times = step_times(path)
    assert len(times) == 5
    for k in range(len(times)):
        s = read_step(path, k)
        fluid = s["Type"] == 3
        p = s["points"][fluid]
        assert fluid.sum() == 1666
        assert (p[:, 2] - bed(p[:, 0])).min() > 0.5 * DP
    assert p[:, 0].max() > 1.25


def test_a_bad_bed_file_stops_gencase_with_exit_2(tmp_path):
    case = case_copy(tmp_path)
    lines = (tmp_path / "BarBed.xyz").read_text().splitlines()
    lines[5] = "0.2 -0.5 O.05"          # a letter O for a zero
    (tmp_path / "BarBed.xyz").write_text("\n".join(lines) + "\n")
    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path / "out")])
    assert r.exit_code == 2
    assert "BarBed.xyz:6:" in r.output and "is not numeric" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "out" / "CaseBathymetry2D.h5").exists()

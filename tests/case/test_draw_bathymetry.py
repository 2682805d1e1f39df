"""Bathymetries: <drawfilecsv mode="bathymetry"> and <drawbathymetry> (sphdvi.case.draw.bathymetry)."""
from __future__ import annotations

import numpy as np
import pytest

from sphdvi.case.draw import bathymetry as bathy
from sphdvi.errors import CaseError

from test_draw import draw, nodes

PEN = '<setmkbound mk="0"/>'


def plane(x, y):
    """The bed every exact test draws: z = 2 + x/4 (no y dependence keeps it on whole nodes
    at x = 0, 4, 8)."""
    return 2.0 + 0.25 * np.asarray(x, float) + 0.0 * np.asarray(y, float)


def quadri(x0=0.0, x1=8.0, y0=0.0, y1=8.0):
    """The same plane drawn by <drawquadri> over [x0, x1] x [y0, y1]."""
    pts = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    body = "".join(f'<point x="{x}" y="{y}" z="{plane(x, y)}"/>' for x, y in pts)
    return PEN + f"<drawquadri>{body}</drawquadri>"


def write_table(path, xs, ys, f=plane, sep=";"):
    lines = ["# heights of a bed", sep.join(["Y \\ X => Z"] + [f"{x:g}" for x in xs])]
    for y in ys:
        lines.append(sep.join([f"{y:g}"] + [repr(float(f(x, y))) for x in xs]))
    path.write_text("\n".join(lines) + "\n")


def write_xyz(path, pts, header=True):
    text = ("x y z\n" if header else "") + "\n".join(" ".join(repr(float(v)) for v in p) for p in pts)
    path.write_text(text + "\n")


def scattered_plane(n=60, seed=3, lo=(0, 0), hi=(8, 8)):
    """Random points of the plane in a rectangle, with its four corners."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(lo, hi, (n, 2))
    xy = np.r_[xy, [lo, (hi[0], lo[1]), hi, (lo[0], hi[1])]]
    return np.c_[xy, plane(xy[:, 0], xy[:, 1])]


# ---------------------------------------------------------------- <drawfilecsv mode="bathymetry">
def test_height_table_reads_x_row_y_column_and_heights(tmp_path):
    write_table(tmp_path / "bed.csv", [0, 1, 1.5, 3], [0, 0.5, 2], f=lambda x, y: 10 * x + y)
    xs, ys, z = bathy.read_height_table(str(tmp_path / "bed.csv"))
    assert xs.tolist() == [0, 1, 1.5, 3] and ys.tolist() == [0, 0.5, 2]
    assert np.array_equal(z, 10 * xs[None, :] + ys[:, None])
    tris = bathy.grid_triangles(xs, ys, z)
    assert tris.shape == (2 * 3 * 2, 3, 3)
    # the triangles tile the table's rectangle and pass through its heights
    e1, e2 = tris[:, 1, :2] - tris[:, 0, :2], tris[:, 2, :2] - tris[:, 0, :2]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert area.sum() == pytest.approx(3 * 2)
    assert np.allclose(tris[..., 2], 10 * tris[..., 0] + tris[..., 1])


@pytest.mark.parametrize("sep", [";", ","])
def test_csv_plane_is_drawn_as_the_plane(tmp_path, sep):
    """A table of a plane, unevenly spaced, draws the nodes <drawquadri> draws for that plane."""
    write_table(tmp_path / "bed.csv", [0, 2, 3, 5, 8], [0, 1.5, 4, 8], sep=sep)
    d = draw(tmp_path, PEN + '<drawfilecsv file="bed.csv" mode="bathymetry"/>')
    assert nodes(d) == nodes(draw(tmp_path, quadri())) and len(nodes(d)) == 99
    prim = d.primitives[0]
    assert prim["shape"] == "bathymetry" and prim["params"]["grid"] == [5, 4]
    assert prim["params"]["triangles"] == 2 * 4 * 3


def test_csv_drawmove_drawscale(tmp_path):
    write_table(tmp_path / "bed.csv", [0, 4], [0, 4])
    moved = draw(tmp_path, PEN + '<drawfilecsv file="bed.csv" mode="bathymetry">'
                 '<drawscale x="2" y="2" z="1"/><drawmove x="1" y="0" z="1"/></drawfilecsv>')
    ref = draw(tmp_path, PEN + "<move x=\"1\" y=\"0\" z=\"1\"/>"
               + quadri().replace(PEN, "").replace('x="8"', 'x="8"'))
    # scaled by 2 in x and y: the plane z = 2 + x/4 on [0, 4]^2 becomes z = 2 + x/8 on [0, 8]^2
    expect = {(x, y, z) for x, y, z in nodes(ref)}
    got = nodes(moved)
    assert all(3 <= z <= 4 for _, _, z in got)
    assert {(x, y) for x, y, _ in got} == {(x, y) for x, y, _ in expect}


def test_csv_in_2d_draws_the_profile(tmp_path):
    write_table(tmp_path / "bed.csv", [0, 4, 8], [-1, 1])
    d = draw(tmp_path, PEN + '<drawfilecsv file="bed.csv" mode="bathymetry"/>',
             pmin=(0, 0, 0), pmax=(10, 0, 10))
    ref = draw(tmp_path, quadri(y0=-1, y1=1), pmin=(0, 0, 0), pmax=(10, 0, 10))
    assert nodes(d) == nodes(ref) and {y for _, y, _ in nodes(d)} == {0}
    assert {x for x, _, _ in nodes(d)} == set(range(9))


@pytest.mark.parametrize("text,line,what", [
    ("Y \\ X => Z;0;1\n0;1;2\n1;1\n", 3, "1 height(s) for 2 x values"),
    ("Y \\ X => Z;0;1\n0;1;2\n0;1;2\n", 3, "y = 0 after y = 0"),
    ("Y \\ X => Z;1;0\n0;1;2\n1;1;2\n", 1, "x values do not increase"),
    ("Y \\ X => Z;0;1\n0;1;x\n1;1;2\n", 2, "not a number"),
    ("Y \\ X => Z;0;1\n0;1;2\n", None, "1 row(s) of heights"),
])
def test_csv_table_errors_name_the_line(tmp_path, text, line, what):
    (tmp_path / "bed.csv").write_text(text)
    with pytest.raises(CaseError) as e:
        draw(tmp_path, PEN + '<drawfilecsv file="bed.csv" mode="bathymetry"/>')
    assert what in str(e.value) and e.value.line == line and e.value.file.endswith("bed.csv")


def test_csv_other_mode_refused(tmp_path):
    write_table(tmp_path / "bed.csv", [0, 4], [0, 4])
    with pytest.raises(CaseError, match="mode='mesh' is not recognised"):
        draw(tmp_path, PEN + '<drawfilecsv file="bed.csv" mode="mesh"/>')


# ---------------------------------------------------------------- triangulation and resampling
def test_delaunay_covers_the_hull(tmp_path):
    """2n - 2 - h triangles (h hull points) whose areas add up to the hull's, for random points
    (vtkDelaunay2D with its default offset lost 7 % of this area)."""
    rng = np.random.default_rng(1)
    pts = np.r_[rng.uniform(0, 1, (200, 3)), [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]]
    tri = bathy.delaunay(pts)
    assert len(tri) == 2 * len(pts) - 2 - 4
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    assert area.sum() == pytest.approx(1.0, rel=1e-12)
    assert bathy.hull_area(pts[:, :2]) == pytest.approx(1.0, rel=1e-12)


def test_resample_is_exact_on_a_plane_and_second_order_on_a_smooth_bed():
    """Linear interpolation on the triangulation: a plane to round-off; sin(2x) cos(3y) from
    jittered points at spacing 1/m with error falling as m^-2 (measured: 0.0220, 0.00635,
    0.00171, 0.000456 for m = 10, 20, 40, 80; observed orders 1.79, 1.89, 1.91)."""
    rng = np.random.default_rng(1)
    xs = ys = np.linspace(0, 1, 101)
    X, Y = np.meshgrid(xs, ys)
    errors = []
    for m in (10, 20, 40, 80):
        g = np.linspace(0, 1, m + 1)
        GX, GY = np.meshgrid(g, g)
        jit = rng.uniform(-0.3, 0.3, (2,) + GX.shape) / m
        GX = GX + jit[0] * ((GX > 0) & (GX < 1))
        GY = GY + jit[1] * ((GY > 0) & (GY < 1))
        pts = np.c_[GX.ravel(), GY.ravel(), np.sin(2 * GX.ravel()) * np.cos(3 * GY.ravel())]
        z, outside = bathy.resample(pts, bathy.delaunay(pts), xs, ys)
        assert outside == 0
        errors.append(np.abs(z - np.sin(2 * X) * np.cos(3 * Y)).max())
        if m == 10:
            flat = pts.copy()
            flat[:, 2] = 0.3 + 0.1 * flat[:, 0] - 0.2 * flat[:, 1]
            zp, _ = bathy.resample(flat, bathy.delaunay(flat), xs, ys)
            assert np.abs(zp - (0.3 + 0.1 * X - 0.2 * Y)).max() < 1e-14
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[0] < 0.025 and np.all(orders > 1.7), (errors, orders)


def test_resample_outside_the_hull_takes_the_nearest_height():
    pts = np.array([[0, 0, 1.0], [1, 0, 2.0], [0, 1, 3.0], [1, 1, 4.0]])
    z, outside = bathy.resample(pts, bathy.delaunay(pts), np.array([-1.0, 0.5, 2.0]), np.array([0.0, 0.9]))
    assert outside == 4      # the heights are the plane 1 + x + 2y: linear inside, nearest outside
    assert z[0].tolist() == [1.0, 1.5, 2.0] and z[1] == pytest.approx([3.0, 3.3, 4.0], abs=1e-14)


def test_expand_ramps_and_flat_segments():
    xs, ys, z = [0.0, 1.0], [0.0, 1.0, 2.0], np.array([[1.0, 2.0]] * 3)
    x2, y2, z2 = bathy.expand(xs, ys, z, "xmin", [(2.0, 0.0), (1.0, None)], 0.5)
    assert x2.tolist() == [-3, -2.5, -2, -1.5, -1, -0.5, 0, 1]
    assert z2[0].tolist() == [0, 0, 0, 0.25, 0.5, 0.75, 1, 2]
    x3, y3, z3 = bathy.expand(xs, ys, z, "ymax", [(1.0, 5.0)], 0.4)   # 3 steps of 1/3
    assert y3 == pytest.approx([0, 1, 2, 2 + 1 / 3, 2 + 2 / 3, 3])
    assert z3[-1].tolist() == [5, 5] and z3[3] == pytest.approx([1 + 4 / 3, 2 + 1])


# ---------------------------------------------------------------- <drawbathymetry>
def test_bathymetry_points_on_a_grid_draw_the_plane(tmp_path):
    write_xyz(tmp_path / "bed.xyz", scattered_plane())
    d = draw(tmp_path, PEN + '<drawbathymetry><zpoints file="bed.xyz"/><grid dp="0.5"/></drawbathymetry>')
    assert nodes(d) == nodes(draw(tmp_path, quadri()))
    p = d.primitives[0]["params"]
    assert p["grid"] == [17, 17] and p["points"] == 64 and p["outside"] == 0
    assert p["triangles"] == 2 * 16 * 16


def test_bathymetry_without_grid_draws_the_points_triangulation(tmp_path):
    write_xyz(tmp_path / "bed.xyz", scattered_plane(), header=False)
    d = draw(tmp_path, PEN + '<drawbathymetry><zpoints file="bed.xyz"/></drawbathymetry>')
    assert nodes(d) == nodes(draw(tmp_path, quadri()))
    assert d.primitives[0]["params"]["triangles"] == 2 * 64 - 2 - 4


def test_bathymetry_from_a_vtk_points_file(tmp_path):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(scattered_plane(), deep=True))
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    w = vtk.vtkXMLPolyDataWriter()
    w.SetFileName(str(tmp_path / "bed.vtp"))
    w.SetInputData(pd)
    w.Write()
    d = draw(tmp_path, PEN + '<drawbathymetry><zpoints file="bed.vtp"/><grid dp="1"/></drawbathymetry>')
    assert nodes(d) == nodes(draw(tmp_path, quadri()))


def test_zpoints_transforms_selection_initdomain_finalmove(tmp_path):
    """Points given in other units and place: scaled, rotated, moved, then cut to a rectangle
    (the points beyond it are 100 m high); the grid over <initdomain>; <finalmove> shifts the bed."""
    bed = scattered_plane(100, lo=(0, 0), hi=(8, 16))                   # z = 2 + x/4
    wall = np.c_[np.random.default_rng(5).uniform((8.5, 0), (16, 16), (50, 2)), np.full(50, 100.0)]
    local = np.r_[bed, wall]
    local[:, 2] = 2 * local[:, 2] - 10                        # stored as z' = 2 z - 10
    local[:, :2] = local[:, 1::-1]                            # and as (y, x)
    write_xyz(tmp_path / "bed.xyz", local)
    body = (PEN + '<drawbathymetry><zpoints file="bed.xyz">'
            '<move x="0" y="0" z="5"/><rotate x="0" y="0" z="-90"/><scale x="1" y="1" z="0.5"/>'
            '<selection><point x="-1" y="-17"/><size x="9.2" y="18"/></selection></zpoints>'
            '<grid dp="0.5"><initdomain><point x="0" y="-12"/><size x="8" y="8"/></initdomain>'
            '<finalmove x="0" y="12" z="0"/></grid></drawbathymetry>')
    d = draw(tmp_path, body)
    assert nodes(d) == nodes(draw(tmp_path, quadri()))
    assert d.primitives[0]["params"]["points"] == len(bed) and d.primitives[0]["params"]["outside"] == 0


def test_bathymetry_expands_widen_the_bed(tmp_path):
    write_xyz(tmp_path / "bed.xyz", scattered_plane(lo=(4, 0), hi=(6, 8)))
    d = draw(tmp_path, PEN + '<drawbathymetry><zpoints file="bed.xyz"/><grid dp="0.5">'
             '<expands><xmin size="2"/><xmax size="1" z="3.75" size2="1"/></expands>'
             '</grid></drawbathymetry>')
    # xmin: flat at the edge's height 3 down to x = 2; xmax: the plane goes on to x = 7
    # (z 3.75), then flat to x = 8
    plane_nodes = {n for n in nodes(draw(tmp_path, quadri(4, 7))) if 4 <= n[0] <= 7}
    got = nodes(d)
    assert {n for n in got if 4 <= n[0] <= 7} == plane_nodes
    assert {z for x, _, z in got if x < 4} == {3} and {x for x, _, _ in got} == set(range(2, 9))
    assert {z for x, _, z in got if x == 8} == {4}
    assert d.primitives[0]["params"]["grid"] == [5 + 4 + 2 + 2, 17]


def test_grid_outside_the_points_warns(tmp_path):
    write_xyz(tmp_path / "bed.xyz", scattered_plane(lo=(2, 2), hi=(6, 6)))
    d = draw(tmp_path, PEN + '<drawbathymetry><zpoints file="bed.xyz"/><grid dp="1">'
             '<initdomain><point x="0" y="0"/><size x="8" y="8"/></initdomain></grid></drawbathymetry>')
    assert d.primitives[0]["params"]["outside"] == 81 - 25


def test_grid_file_and_debug_files(tmp_path):
    import vtk
    g = np.arange(0, 9, 2.0)
    X, Y = np.meshgrid(g, g)
    write_xyz(tmp_path / "grid.xyz", np.c_[X.ravel(), Y.ravel(), plane(X.ravel(), Y.ravel())])
    out = tmp_path / "out"
    out.mkdir()
    d = draw(tmp_path, PEN + '<drawbathymetry><grid file="grid.xyz"/>'
             '<savepoints file="true"/><savegrid file="true"/></drawbathymetry>', outdir=str(out))
    assert nodes(d) == nodes(draw(tmp_path, quadri()))
    for name, count in (("case_Bathymetry_Points.vtk", 25), ("case_Bathymetry_Grid.vtk", 32)):
        r = vtk.vtkPolyDataReader()
        r.SetFileName(str(out / name))
        r.Update()
        pd = r.GetOutput()
        n = pd.GetNumberOfPoints() if "Points" in name else pd.GetNumberOfPolys()
        assert n == count


@pytest.mark.parametrize("body,what", [
    ('<zpoints file="bed.xyz"/><grid dp="1"><periodicx rampwidth="0"/></grid>', "<periodicx> is not supported"),
    ('<zpoints file="bed.xyz"/><grid dp="1"><expands><ymax size="-2"/></expands></grid>', "widens a bed only"),
    ('<zpoints file="bed.xyz"/><grid dp="1" file="bed.xyz"/>', "both dp and file"),
    ('<grid dp="1"/>', "no <zpoints file> and no <grid file>"),
    ('<zpoints file="bed.xyz"/><grid/>', "neither dp nor file"),
    ('<zpoints file="bed.xyz"/><grid file="bed.xyz"/>', "<grid file> beside <zpoints>"),
    ('<grid file="bed.xyz"><initdomain><point x="0" y="0"/><size x="1" y="1"/></initdomain></grid>',
     "<initdomain> and <expands> need a grid of spacing dp"),
    ('<zpoints file="missing.xyz"/>', "not found"),
    ('<zpoints file="line.xyz"/>', "lie on one line"),
    ('<zpoints file="bed.xyz"><selection><point x="100" y="0"/><size x="1" y="1"/></selection></zpoints>',
     "0 of the 64 points lie inside the selection"),
])
def test_bathymetry_errors(tmp_path, body, what):
    write_xyz(tmp_path / "bed.xyz", scattered_plane())
    write_xyz(tmp_path / "line.xyz", [(0, 0, 1), (1, 1, 1), (2, 2, 1), (3, 3, 2)])
    with pytest.raises(CaseError) as e:
        draw(tmp_path, PEN + f"<drawbathymetry>{body}</drawbathymetry>")
    assert what in str(e.value) and e.value.line is not None


def test_bad_xyz_line_is_named(tmp_path):
    (tmp_path / "bed.xyz").write_text("0 0 1\n1 0 1\n0 1 x\n")
    with pytest.raises(CaseError) as e:
        draw(tmp_path, PEN + '<drawbathymetry><zpoints file="bed.xyz"/></drawbathymetry>')
    assert e.value.line == 3 and e.value.file.endswith("bed.xyz")

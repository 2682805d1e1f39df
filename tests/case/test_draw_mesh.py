"""GenCase drawing of mesh files (STL, PLY, VTK) and <shapeout>."""
from __future__ import annotations

import os

import numpy as np
import pytest

from sphdvi.errors import CaseError

from test_draw import cube_triangles, draw, lattice_box, nodes


def write_ascii_stl(path, lo=1, hi=5, scale=1.0):
    v, tris = cube_triangles(lo, hi)
    v = np.array(v, dtype=float) * scale
    with open(path, "w") as fh:
        fh.write("solid cube\n")
        for a, b, c in tris:
            fh.write(" facet normal 0 0 0\n  outer loop\n")
            for i in (a, b, c):
                fh.write("   vertex {} {} {}\n".format(*v[i]))
            fh.write("  endloop\n endfacet\n")
        fh.write("endsolid cube\n")


def cube_polydata(lo=1, hi=5):
    import vtk
    v, tris = cube_triangles(lo, hi)
    pts = vtk.vtkPoints()
    for p in v:
        pts.InsertNextPoint(*p)
    cells = vtk.vtkCellArray()
    for t in tris:
        cells.InsertNextCell(3, t)
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    pd.SetPolys(cells)
    return pd


def write_with_vtk(path, writer_name):
    import vtk
    w = getattr(vtk, writer_name)()
    w.SetFileName(str(path))
    w.SetInputData(cube_polydata())
    w.Write()


SURFACE = lattice_box((1, 1, 1), (5, 5, 5)) - lattice_box((2, 2, 2), (4, 4, 4))
FULL = lattice_box((1, 1, 1), (5, 5, 5))


def test_stl_surface_and_autofill(tmp_path):
    write_ascii_stl(tmp_path / "cube.stl")
    d = draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="cube.stl"/>')
    assert nodes(d) == SURFACE
    d = draw(tmp_path, '<setmkbound mk="3"/><drawfilestl file="cube.stl" autofill="true"/>')
    assert nodes(d) == FULL and d.primitives[0]["solid"]
    assert d.primitives[0]["shape"] == "mesh" and d.primitives[0]["params"]["triangles"] == 12


def test_stl_tank_with_fluid_inside(tmp_path):
    write_ascii_stl(tmp_path / "cube.stl")
    d = draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="cube.stl"/>'
             '<setmkfluid mk="0"/><fillvoidpoint x="3" y="3" z="3"/>')
    assert d.count_bound == 98 and d.count_fluid == 27


@pytest.mark.parametrize("name,writer,tag", [("cube.ply", "vtkPLYWriter", "drawfileply"),
                                             ("cube.vtk", "vtkPolyDataWriter", "drawfilevtk"),
                                             ("cube.vtp", "vtkXMLPolyDataWriter", "drawfilevtk"),
                                             ("bin.stl", "vtkSTLWriter", "drawfilestl")])
def test_other_formats(tmp_path, name, writer, tag):
    write_with_vtk(tmp_path / name, writer)
    d = draw(tmp_path, f'<setmkbound mk="0"/><{tag} file="{name}" autofill="true"/>')
    assert nodes(d) == FULL


def test_multiblock_vtm_draws_every_block(tmp_path):
    """A .vtm of two blocks (the cube and the same cube moved by 6 in x) draws both cubes' surfaces."""
    import vtk
    moved = vtk.vtkTransformFilter()
    t = vtk.vtkTransform()
    t.Translate(6, 0, 0)
    moved.SetTransform(t)
    moved.SetInputData(cube_polydata())
    moved.Update()
    mb = vtk.vtkMultiBlockDataSet()
    mb.SetNumberOfBlocks(2)
    mb.SetBlock(0, cube_polydata())
    mb.SetBlock(1, moved.GetOutput())
    w = vtk.vtkXMLMultiBlockDataWriter()
    w.SetFileName(str(tmp_path / "two.vtm"))
    w.SetInputData(mb)
    w.Write()
    d = draw(tmp_path, '<setmkbound mk="0"/><drawfilevtm file="two.vtm"/>', pmax=(14, 10, 10))
    assert nodes(d) == SURFACE | {(x + 6, y, z) for x, y, z in SURFACE}
    assert d.primitives[0]["params"]["triangles"] == 24


def test_drawmove_rotate_scale(tmp_path):
    write_ascii_stl(tmp_path / "unit.stl", lo=0, hi=1)
    body = ('<setmkbound mk="0"/><drawfilestl file="unit.stl" autofill="true">'
            '<drawscale x="2" y="2" z="2"/><drawrotate angx="0" angy="0" angz="90"/>'
            '<drawmove x="5" y="1" z="1"/></drawfilestl>')
    d = draw(tmp_path, body)
    # scaled to [0,2]^3, rotated 90 about z -> x in [-2,0], moved -> x 3..5, y 1..3, z 1..3
    assert nodes(d) == lattice_box((3, 1, 1), (5, 3, 3))


def test_mesh_2d_slice(tmp_path):
    write_ascii_stl(tmp_path / "cube.stl")
    d = draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="cube.stl"/>',
             pmin=(0, 3, 0), pmax=(10, 3, 10))
    assert nodes(d) == {(x, 3, z) for x in range(1, 6) for z in range(1, 6)
                        if x in (1, 5) or z in (1, 5)}


def test_sphere_stl_autofill_matches_analytic(tmp_path):
    import vtk
    src = vtk.vtkSphereSource()
    src.SetRadius(4.0)
    src.SetCenter(10, 10, 10)
    src.SetThetaResolution(64)
    src.SetPhiResolution(64)
    w = vtk.vtkSTLWriter()
    w.SetFileName(str(tmp_path / "s.stl"))
    w.SetInputConnection(src.GetOutputPort())
    w.Write()
    d = draw(tmp_path, '<setmkfluid mk="0"/><drawfilestl file="s.stl" autofill="true"/>',
             pmax=(20, 20, 20))
    got = nodes(d)
    c = np.array(sorted(got)) - 10.0
    r = np.sqrt((c ** 2).sum(axis=1))
    # inside plus the surface layer (within dp/2 of the faceted sphere)
    assert r.max() <= 4.5 + 1e-9
    ball = {(x, y, z) for x in range(21) for y in range(21) for z in range(21)
            if (x - 10) ** 2 + (y - 10) ** 2 + (z - 10) ** 2 <= 3.95 ** 2}
    assert ball <= got


# ---------------------------------------------------------------- mesh errors
def test_mesh_file_outside_case_folder(tmp_path):
    sub = tmp_path / "case"
    sub.mkdir()
    write_ascii_stl(tmp_path / "cube.stl")
    with pytest.raises(CaseError, match="outside the case folder"):
        draw(sub, '<setmkbound mk="0"/><drawfilestl file="../cube.stl"/>')
    with pytest.raises(CaseError, match="outside the case folder"):
        draw(sub, f'<setmkbound mk="0"/><drawfilestl file="{tmp_path / "cube.stl"}"/>')


def test_mesh_file_missing_or_garbage(tmp_path):
    with pytest.raises(CaseError, match="not found"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="nothere.stl"/>')
    (tmp_path / "bad.stl").write_text("this is not an stl file\n")
    with pytest.raises(CaseError, match="cannot read"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="bad.stl"/>')
    (tmp_path / "empty.ply").write_bytes(b"")
    with pytest.raises(CaseError, match="cannot read"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfileply file="empty.ply"/>')
    (tmp_path / "bad.vtk").write_bytes(os.urandom(300))
    with pytest.raises(CaseError, match="cannot read"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfilevtk file="bad.vtk"/>')
    (tmp_path / "x.obj").write_text("v 0 0 0\n")
    with pytest.raises(CaseError, match="extension"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfilevtk file="x.obj"/>')


def test_mesh_unsupported_options(tmp_path):
    write_ascii_stl(tmp_path / "cube.stl")
    with pytest.raises(CaseError, match="not supported"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="cube.stl" advanced="true"/>')
    with pytest.raises(CaseError, match="not supported"):
        draw(tmp_path, '<setmkbound mk="0"/><drawfilestl file="cube.stl">'
                       '<depth depthmin="0.1"/></drawfilestl>')


# ---------------------------------------------------------------- shapeout
def test_shapeout_formats_and_reset(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    body = ('<setmkbound mk="2"/><drawsphere radius="2"><point x="5" y="5" z="5"/></drawsphere>'
            '<shapeout file="first" reset="false"/>'
            + '<drawbox><boxfill>all</boxfill><point x="0" y="0" z="0"/><size x="1" y="1" z="1"/>'
              '</drawbox><shapeout file="both" format="vtp"/><shapeout file="none" format="stl"/>'
            '<shapeout file="first" format="vtu"/>')
    d = draw(tmp_path, body, outdir=str(out))
    names = sorted(os.path.basename(f) for f in d.shape_files)
    assert names == ["case_both.vtp", "case_first.vtk", "case_first.vtu", "case_none.stl"]
    import vtk
    r = vtk.vtkPolyDataReader()
    r.SetFileName(str(out / "case_first.vtk"))
    r.Update()
    sphere_cells = r.GetOutput().GetNumberOfCells()
    assert sphere_cells > 100
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(out / "case_both.vtp"))
    r.Update()
    assert r.GetOutput().GetNumberOfCells() == sphere_cells + 12
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(out / "case_first.vtu"))
    r.Update()
    assert r.GetOutput().GetNumberOfCells() == 0  # reset after "both"
    assert (out / "case_none.stl").read_text().startswith("solid")


def test_shapeout_stays_in_outdir(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    d = draw(tmp_path, '<setmkbound mk="0"/><drawpoint x="1" y="1" z="1"/>'
             '<shapeout file="../../evil"/><shapeout file="/etc/passwd2"/>', outdir=str(out))
    assert sorted(os.listdir(out)) == ["case_evil.vtk", "case_passwd2.vtk"]
    assert all(os.path.dirname(f) == str(out) for f in d.shape_files)
    assert not (tmp_path / "evil.vtk").exists()
    with pytest.raises(CaseError, match="file name"):
        draw(tmp_path, '<shapeout file=".."/>', outdir=str(out))


def test_shapeout_without_outdir_writes_nothing(tmp_path):
    d = draw(tmp_path, '<setmkbound mk="0"/><drawpoint x="1" y="1" z="1"/><shapeout file="s"/>')
    assert d.shape_files == [] and os.listdir(tmp_path) == []


@pytest.mark.parametrize("fill,faces", [("all", 6), ("solid", 6), ("all ^ top", 5),
                                         ("bottom | left | right", 3), ("bottom", 1)])
def test_shapeout_of_a_box_holds_the_faces_drawn(tmp_path, fill, faces):
    """An open tank's shape has no lid: the norgeometry normals of the particles at its rim were
    pulled towards the missing face (DualSPHysics's mdbc/04 CaseDamBreak3D chooses each box's
    faces for its normals geometry: 2,556 rim particles were tilted, 312 on a phantom floor got
    no normal). A solid box keeps its six faces."""
    out = tmp_path / "out"
    out.mkdir()
    d = draw(tmp_path, f'<setmkbound mk="0"/><drawbox><boxfill>{fill}</boxfill><point x="1" y="1" z="1"/>'
             '<size x="4" y="4" z="4"/></drawbox><shapeout file="tank"/>', outdir=str(out))
    tris, _, _ = d.shape_sets["tank"]
    assert len(tris) == 2 * faces
    if fill == "all ^ top":
        assert tris[..., 2].max() == 5.0 and not np.any(np.all(tris[..., 2] == 5.0, axis=1))

"""Writing the drawn shapes (``<shapeout>``) as triangle surfaces: VTK legacy, VTP, VTU or STL.

Written by hand (ASCII) so no vtk import is needed. Each triangle carries the
shape number and its mk (cell data ``ShapeId`` and ``Mk``, ``Fluid`` 0/1).
"""
from __future__ import annotations

import numpy as np

FORMATS = ("vtk", "vtp", "vtu", "stl")


def merge_shapes(shapes):
    """(triangles (T, 3, 3), shape number, mk and fluid flag of each triangle) of the recorded shapes."""
    tris = [np.asarray(s["triangles"], dtype=np.float64).reshape(-1, 3, 3) for s in shapes]
    ids = [np.full(len(t), i, dtype=np.int64) for i, t in enumerate(tris)]
    mks = [np.full(len(t), s["mk"], dtype=np.int64) for s, t in zip(shapes, tris)]
    fl = [np.full(len(t), int(s["fluid"]), dtype=np.int64) for s, t in zip(shapes, tris)]
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(tris), np.concatenate(ids), np.concatenate(mks), np.concatenate(fl)


def _fmt(a) -> str:
    return " ".join(repr(float(v)) if isinstance(v, (float, np.floating)) else str(int(v))
                    for v in np.ravel(a))


def write_shapes(path: str, shapes, fmt: str) -> None:
    """Write the triangles of ``shapes`` (dicts with triangles, mk, fluid) to ``path``."""
    tris, ids, mks, fl = merge_shapes(shapes)
    pts = tris.reshape(-1, 3)
    n = len(tris)
    conn = np.arange(3 * n).reshape(-1, 3)
    with open(path, "w", encoding="ascii") as fh:
        if fmt == "stl":
            fh.write("solid sphdvi_shapes\n")
            for t in tris:
                nrm = np.cross(t[1] - t[0], t[2] - t[0])
                ln = np.linalg.norm(nrm)
                nrm = nrm / ln if ln > 0 else nrm
                fh.write(f"facet normal {_fmt(nrm)}\n outer loop\n")
                for p in t:
                    fh.write(f"  vertex {_fmt(p)}\n")
                fh.write(" endloop\nendfacet\n")
            fh.write("endsolid sphdvi_shapes\n")
            return
        if fmt == "vtk":
            fh.write("# vtk DataFile Version 3.0\nsphdvi shapes\nASCII\nDATASET POLYDATA\n")
            fh.write(f"POINTS {len(pts)} double\n")
            for p in pts:
                fh.write(_fmt(p) + "\n")
            fh.write(f"POLYGONS {n} {4 * n}\n")
            for c in conn:
                fh.write("3 " + _fmt(c) + "\n")
            fh.write(f"CELL_DATA {n}\n")
            for name, arr in (("ShapeId", ids), ("Mk", mks), ("Fluid", fl)):
                fh.write(f"SCALARS {name} int 1\nLOOKUP_TABLE default\n")
                fh.write("\n".join(str(int(v)) for v in arr) + "\n")
            return
        # XML formats
        kind = "PolyData" if fmt == "vtp" else "UnstructuredGrid"
        fh.write(f'<?xml version="1.0"?>\n<VTKFile type="{kind}" version="0.1" '
                 'byte_order="LittleEndian">\n')
        fh.write(f"<{kind}>\n")
        if fmt == "vtp":
            fh.write(f'<Piece NumberOfPoints="{len(pts)}" NumberOfPolys="{n}">\n')
        else:
            fh.write(f'<Piece NumberOfPoints="{len(pts)}" NumberOfCells="{n}">\n')
        fh.write('<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">\n')
        fh.write(_fmt(pts) + "\n</DataArray></Points>\n")
        fh.write("<CellData>\n")
        for name, arr in (("ShapeId", ids), ("Mk", mks), ("Fluid", fl)):
            fh.write(f'<DataArray type="Int32" Name="{name}" format="ascii">\n{_fmt(arr)}\n'
                     "</DataArray>\n")
        fh.write("</CellData>\n")
        tag = "Polys" if fmt == "vtp" else "Cells"
        fh.write(f"<{tag}>\n")
        fh.write(f'<DataArray type="Int64" Name="connectivity" format="ascii">\n{_fmt(conn)}\n'
                 "</DataArray>\n")
        fh.write(f'<DataArray type="Int64" Name="offsets" format="ascii">\n'
                 f"{_fmt(3 * np.arange(1, n + 1))}\n</DataArray>\n")
        if fmt == "vtu":
            fh.write(f'<DataArray type="UInt8" Name="types" format="ascii">\n'
                     f"{_fmt(np.full(n, 5))}\n</DataArray>\n")
        fh.write(f"</{tag}>\n</Piece>\n</{kind}>\n</VTKFile>\n")


def write_points(path: str, pts) -> None:
    """Points (N, 3) as a legacy VTK PolyData of vertices, with their height as ``Z``."""
    pts = np.asarray(pts, dtype=np.float64).reshape(-1, 3)
    n = len(pts)
    with open(path, "w", encoding="ascii") as fh:
        fh.write("# vtk DataFile Version 3.0\nsphdvi points\nASCII\nDATASET POLYDATA\n")
        fh.write(f"POINTS {n} double\n")
        for p in pts:
            fh.write(_fmt(p) + "\n")
        fh.write(f"VERTICES {n} {2 * n}\n")
        for k in range(n):
            fh.write(f"1 {k}\n")
        fh.write(f"POINT_DATA {n}\nSCALARS Z double 1\nLOOKUP_TABLE default\n")
        fh.write("\n".join(repr(float(v)) for v in pts[:, 2]) + "\n")

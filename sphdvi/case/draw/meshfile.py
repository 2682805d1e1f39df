"""Reading triangle meshes (STL, PLY, VTK legacy, VTP, VTU, VTM multiblock) with the vtk package.

vtk is imported inside :func:`read_triangles` only, so importing sphdvi stays fast.
"""
from __future__ import annotations

import os

import numpy as np

MAX_MESH_BYTES = 512 * 1024 * 1024


class MeshError(ValueError):
    """The file could not be read as a triangle mesh; the message says why."""


def _reader_for(path: str, kind: str):
    import vtk
    ext = os.path.splitext(path)[1].lower()
    if kind == "stl":
        return vtk.vtkSTLReader()
    if kind == "ply":
        return vtk.vtkPLYReader()
    if kind == "vtm":
        return vtk.vtkXMLMultiBlockDataReader()
    if ext == ".vtp":
        return vtk.vtkXMLPolyDataReader()
    if ext == ".vtu":
        return vtk.vtkXMLUnstructuredGridReader()
    if ext == ".vtk":
        return vtk.vtkGenericDataObjectReader()
    raise MeshError(f"unknown VTK file extension '{ext}' (expected .vtk, .vtp or .vtu)")


def _read_data(path: str, kind: str):
    """The data set of a mesh file, read by vtk with its messages kept off the terminal."""
    size = os.path.getsize(path)
    if size > MAX_MESH_BYTES:
        raise MeshError(f"file is {size} bytes; at most {MAX_MESH_BYTES}")
    if size == 0:
        raise MeshError("file is empty")
    import vtk
    vtk.vtkObject.GlobalWarningDisplayOff()
    reader = _reader_for(path, kind)
    reader.SetFileName(path)
    previous = vtk.vtkOutputWindow.GetInstance()
    quiet = vtk.vtkFileOutputWindow()  # keep vtk's messages off the terminal
    quiet.SetFileName(os.devnull)
    vtk.vtkOutputWindow.SetInstance(quiet)
    try:
        reader.Update()
    finally:
        vtk.vtkOutputWindow.SetInstance(previous)
    data = reader.GetOutputDataObject(0)
    if data is None:
        raise MeshError("vtk could not read the file")
    return data


def read_points(path: str) -> np.ndarray:
    """Every point (N, 3) of a VTK file (legacy .vtk, .vtp or .vtu), whatever its cells."""
    from vtk.util.numpy_support import vtk_to_numpy
    data = _read_data(path, "vtk")
    pts = data.GetPoints() if hasattr(data, "GetPoints") else None
    if pts is None or pts.GetNumberOfPoints() == 0:
        raise MeshError("no points found (not a VTK data set with points?)")
    out = vtk_to_numpy(pts.GetData()).astype(np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(out)):
        raise MeshError("the file has non-finite coordinates")
    return out


def read_triangles(path: str, kind: str) -> np.ndarray:
    """All triangles of a mesh file as a (T, 3, 3) float64 array (polygons are triangulated)."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    data = _read_data(path, kind)
    # a multiblock file (.vtm): the surfaces of all its blocks together
    geom = vtk.vtkCompositeDataGeometryFilter() if data.IsA("vtkCompositeDataSet") else vtk.vtkGeometryFilter()
    geom.SetInputData(data)
    tri = vtk.vtkTriangleFilter()
    tri.SetInputConnection(geom.GetOutputPort())
    tri.PassVertsOff()
    tri.PassLinesOff()
    tri.Update()
    poly = tri.GetOutput()
    if poly is None or poly.GetNumberOfPolys() == 0 or poly.GetPoints() is None:
        raise MeshError("no triangles found (not a valid mesh file?)")
    pts = vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)
    polys = poly.GetPolys()
    conn = vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64)
    offs = vtk_to_numpy(polys.GetOffsetsArray()).astype(np.int64)
    if not np.all(np.diff(offs) == 3):
        raise MeshError("triangulation failed")
    tris = pts[conn.reshape(-1, 3)]
    if not np.all(np.isfinite(tris)):
        raise MeshError("the mesh has non-finite coordinates")
    return tris

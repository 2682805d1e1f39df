"""A small writer of VTK XML PolyData (``.vtp``) point clouds and ``.pvd`` collections.

Appended raw binary, little-endian, UInt64 headers; readable by every ParaView
(including 5.11, which cannot read VTKHDF PolyData) without the vtk package.
"""
from __future__ import annotations

import numpy as np

from .atomic import atomic_path

_VTK_TYPES = {
    np.dtype("float32"): "Float32", np.dtype("float64"): "Float64",
    np.dtype("int8"): "Int8", np.dtype("uint8"): "UInt8", np.dtype("int16"): "Int16",
    np.dtype("uint16"): "UInt16", np.dtype("int32"): "Int32", np.dtype("uint32"): "UInt32",
    np.dtype("int64"): "Int64", np.dtype("uint64"): "UInt64",
}


def write_vtp_points(path: str, points: np.ndarray, point_data: dict | None = None) -> None:
    """Write points (N,3) with one VTK_VERTEX cell each and the given point arrays."""
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    n = points.shape[0]
    arrays = [("Points", points)]
    blocks = []
    offset = 0
    header = []

    def add(name, data, ncomp):
        nonlocal offset
        data = np.ascontiguousarray(data)
        if data.dtype.byteorder == ">":
            data = data.astype(data.dtype.newbyteorder("<"))
        vtype = _VTK_TYPES[np.dtype(data.dtype.str.lstrip("<>="))]
        raw = data.tobytes()
        blocks.append(np.uint64(len(raw)).tobytes() + raw)
        tag = (f'<DataArray type="{vtype}" Name="{name}" NumberOfComponents="{ncomp}" '
               f'format="appended" offset="{offset}"/>')
        offset += 8 + len(raw)
        return tag

    pd_tags = []
    for name, data in (point_data or {}).items():
        data = np.asarray(data)
        if data.dtype == np.bool_:
            data = data.astype(np.uint8)
        ncomp = 1 if data.ndim == 1 else data.shape[1]
        pd_tags.append(add(name, data, ncomp))
    pts_tag = add("Points", points, 3)
    conn_tag = add("connectivity", np.arange(n, dtype=np.int64), 1)
    off_tag = add("offsets", np.arange(1, n + 1, dtype=np.int64), 1)
    del arrays, header
    xml = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
        '<PolyData>\n'
        f'<Piece NumberOfPoints="{n}" NumberOfVerts="{n}" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="0">\n'
        '<PointData>\n' + "\n".join(pd_tags) + '\n</PointData>\n'
        '<Points>\n' + pts_tag + '\n</Points>\n'
        '<Verts>\n' + conn_tag + '\n' + off_tag + '\n</Verts>\n'
        '</Piece>\n</PolyData>\n'
        '<AppendedData encoding="raw">\n_'
    )
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(xml.encode("ascii"))
            for b in blocks:
                fh.write(b)
            fh.write(b"\n</AppendedData>\n</VTKFile>\n")


def write_pvd(path: str, entries: list[tuple[float, str]]) -> None:
    """A ParaView collection of (time, relative file name)."""
    lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "<Collection>"]
    for t, name in entries:
        lines.append(f'<DataSet timestep="{t:.9g}" part="0" file="{name}"/>')
    lines += ["</Collection>", "</VTKFile>", ""]
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="ascii") as fh:
            fh.write("\n".join(lines))


def write_normals_vtp(path: str, pos: np.ndarray, ptype: np.ndarray, mk: np.ndarray, normals: np.ndarray) -> str:
    """The boundary particles that have an mDBC normal, for ParaView's Glyph filter (as
    DualSPHysics's CfgInit_Normals): ``Normal`` its direction, ``NormalSize`` |N| (the distance to
    the boundary surface; the ghost node lies 2 |N| away), ``Mk``."""
    normals = np.asarray(normals, dtype=np.float64)
    size = np.linalg.norm(normals, axis=1)
    has = (np.asarray(ptype) != 3) & (size > 0)
    write_vtp_points(path, np.asarray(pos)[has], {"Normal": (normals[has] / size[has, None]).astype(np.float32),
                                                  "NormalSize": size[has].astype(np.float32),
                                                  "Mk": np.asarray(mk)[has].astype(np.int32)})
    return path


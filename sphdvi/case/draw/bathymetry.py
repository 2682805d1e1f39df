"""Bathymetries: a sea bed given as heights z(x, y), turned into a triangulated surface.

Two GenCase commands use it (GenCase_CaseTemplate.xml and GenCase_Bathymetry.csv, DualSPHysics
v5.4 doc/xml_format):

``<drawfilecsv file="..." mode="bathymetry">``
    A table of heights: the first row holds the x values after a label (``Y \\ X => Z;0;1;1.5``),
    each further row a y value and the heights z(x_i, y) (:func:`read_height_table`). Each cell
    of the table becomes two triangles (:func:`grid_triangles`).

``<drawbathymetry>``
    Scattered points ``x y z`` (``<zpoints file>``: an XYZ text file or the points of a VTK
    file), triangulated in the plane (Delaunay, :func:`delaunay`) and drawn as they are, or
    resampled on a regular grid of spacing ``<grid dp>`` by linear interpolation on that
    triangulation (:func:`resample`; nodes outside the points' convex hull take the height of
    the nearest point), optionally widened at its sides (``<expands>``, :func:`expand`).

How GenCase itself grids the points is not documented: linear interpolation on the Delaunay
triangulation is sphdvi's rule (exact for a plane, second order in the point spacing for a smooth
bed: :mod:`tests.case.test_draw_bathymetry` measures it).

vtk does the triangulation (vtkDelaunay2D) and finds the nearest points (vtkStaticPointLocator);
it is imported inside the functions that need it. The interpolation is a numba kernel
(:func:`.kernels.interpolate_on_triangles`): vtkProbeFilter missed nodes on the hull's edges.
"""
from __future__ import annotations

import os

import numpy as np

from ...errors import CaseError
from .. import datafiles

MAX_GRID_NODES = 20_000_000
#: share of the points' hull the triangulation may leave uncovered (vtkDelaunay2D drops a few
#: slivers along the hull of large sets: 3e-7 of it for 200,000 random points); the grid nodes
#: there take the nearest point's height
HULL_GAP = 1e-4
SIDES = ("xmin", "xmax", "ymin", "ymax")


class BathymetryError(ValueError):
    """The points or options cannot make a bed; the message says why."""


# ------------------------------------------------------------------ files
def _split_fields(line: str) -> list[str]:
    for sep in (";", ",", "\t"):
        if sep in line:
            return [f.strip() for f in line.split(sep)]
    return line.split()


def _numbers(fields, path, lineno, what):
    try:
        vals = np.array([float(f) for f in fields], dtype=np.float64)
    except ValueError:
        raise CaseError(f"{what}: '{';'.join(fields)[:80]}' holds a field that is not a number",
                        file=path, line=lineno, expected="numbers separated by ';'") from None
    if not np.all(np.isfinite(vals)):
        raise CaseError(f"{what}: a value is not finite", file=path, line=lineno,
                        expected="finite numbers")
    return vals


def read_height_table(path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The table of a ``<drawfilecsv mode="bathymetry">`` file -> (x (nx,), y (ny,), z (ny, nx)).

    Lines starting with ``#`` are comments. The first other line is ``label;x0;x1;...``, each
    further line ``y;z(x0, y);z(x1, y);...``; fields are separated by ``;`` (or ``,`` or tabs).
    x and y must increase strictly and every row must hold one height per x."""
    what = "bathymetry table"
    xs, ys, rows = None, [], []
    try:
        with open(path, encoding="utf-8-sig", errors="replace") as fh:
            for lineno, line in enumerate(fh, 1):
                text = line.strip()
                if not text or text.startswith("#"):
                    continue
                fields = _split_fields(text)
                if fields and fields[-1] == "":
                    fields = fields[:-1]      # a trailing separator (spreadsheets write one)
                if xs is None:
                    xs = _numbers(fields[1:], path, lineno, what)
                    if xs.size < 2:
                        raise CaseError(f"{what}: the first row holds {xs.size} x value(s)",
                                        file=path, line=lineno,
                                        expected="a label and at least two x values: 'Y \\ X => Z;x0;x1;...'")
                    if np.any(np.diff(xs) <= 0):
                        raise CaseError(f"{what}: the x values do not increase", file=path,
                                        line=lineno, expected="strictly increasing x values")
                    continue
                vals = _numbers(fields, path, lineno, what)
                if vals.size != xs.size + 1:
                    raise CaseError(f"{what}: {vals.size - 1} height(s) for {xs.size} x values",
                                    file=path, line=lineno,
                                    expected=f"y and {xs.size} heights separated by ';'")
                if ys and not vals[0] > ys[-1]:
                    raise CaseError(f"{what}: y = {vals[0]:g} after y = {ys[-1]:g}", file=path,
                                    line=lineno, expected="strictly increasing y values")
                ys.append(vals[0])
                rows.append(vals[1:])
    except OSError as exc:
        raise CaseError(f"{what}: cannot read the file ({exc.strerror})", file=path,
                        expected="a readable file") from None
    if xs is None or len(ys) < 2:
        raise CaseError(f"{what}: {len(ys)} row(s) of heights", file=path,
                        expected="a row of x values and at least two rows 'y;z0;z1;...'")
    return xs, np.array(ys), np.array(rows)


def read_points(path: str) -> np.ndarray:
    """The points (N, 3) of an XYZ text file (x y z per line; ``;``, ``,`` or blanks between
    them; ``#`` comments; a header line is skipped) or of a VTK file (``.vtk``, ``.vtp``,
    ``.vtu``: every point of the data set)."""
    ext = os.path.splitext(path)[1].lower()
    if ext in (".vtk", ".vtp", ".vtu"):
        from .meshfile import MeshError, read_points as read_vtk_points
        try:
            return read_vtk_points(path)
        except (MeshError, OSError) as exc:
            raise CaseError(f"bathymetry points: cannot read the file: {exc}", file=path,
                            expected="a VTK file with points") from None
    return datafiles.read_columns(path, 3, "bathymetry points")[:, :3].copy()


# ------------------------------------------------------------------ surfaces
def grid_triangles(xs, ys, z) -> np.ndarray:
    """Two triangles (T, 3, 3) per cell of the grid z[j, i] = z(xs[i], ys[j]), each cell cut
    along its diagonal from (x_i, y_j) to (x_i+1, y_j+1)."""
    xs, ys, z = np.asarray(xs, float), np.asarray(ys, float), np.asarray(z, float)
    X, Y = np.meshgrid(xs, ys)
    p = np.stack([X, Y, z], axis=-1)
    a, b = p[:-1, :-1], p[:-1, 1:]      # (i, j), (i+1, j)
    c, d = p[1:, 1:], p[1:, :-1]        # (i+1, j+1), (i, j+1)
    t1 = np.stack([a, b, c], axis=-2).reshape(-1, 3, 3)
    t2 = np.stack([a, c, d], axis=-2).reshape(-1, 3, 3)
    return np.concatenate([t1, t2])


def _polydata(points):
    """A vtkPolyData of the points (no cells)."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    return pd


def hull_area(xy) -> float:
    """Area of the convex hull of points (N, 2) (Andrew's monotone chain)."""
    pts = np.unique(np.asarray(xy, dtype=np.float64), axis=0)
    if len(pts) < 3:
        return 0.0

    def half(seq):
        chain = []
        for q in seq:
            while len(chain) >= 2 and ((chain[-1][0] - chain[-2][0]) * (q[1] - chain[-2][1])
                                       - (chain[-1][1] - chain[-2][1]) * (q[0] - chain[-2][0])) <= 0:
                chain.pop()
            chain.append(q)
        return chain[:-1]

    hull = np.array(half(pts) + half(pts[::-1]))
    x, y = hull[:, 0], hull[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _triangle_areas(xy, tri) -> np.ndarray:
    a, b, c = xy[tri[:, 0]], xy[tri[:, 1]], xy[tri[:, 2]]
    return 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def morton_order(xy) -> np.ndarray:
    """The order of points (N, 2) along a Morton (Z-order) curve on a 2^16 grid over their extent."""
    xy = np.asarray(xy, dtype=np.float64)
    lo = xy.min(axis=0)
    span = float((xy.max(axis=0) - lo).max()) or 1.0
    q = np.clip(((xy - lo) / span * 65535.0).astype(np.int64), 0, 65535).astype(np.uint64)

    def spread(v):
        for shift, mask in ((8, 0x00FF00FF), (4, 0x0F0F0F0F), (2, 0x33333333), (1, 0x55555555)):
            v = (v | (v << np.uint64(shift))) & np.uint64(mask)
        return v

    return np.argsort(spread(q[:, 0]) | (spread(q[:, 1]) << np.uint64(1)), kind="stable")


def delaunay(points) -> np.ndarray:
    """The Delaunay triangulation of the points' (x, y) -> vertex indices (T, 3) (vtkDelaunay2D;
    points closer than 1e-9 of the data's extent count as one).

    vtkDelaunay2D starts from a bounding triangulation ``Offset`` times the data's size and may
    lose triangles along the convex hull when it is small (with the default 1, 7 % of the area of
    200 random points in a square); the offset grows until the triangles cover the hull, or
    all but ``HULL_GAP`` of it (slivers along the hull of large sets). The
    points go in along a Morton curve: vtkDelaunay2D walks from the last triangle to the next
    point, and in the file's order (random here) 200,000 points took 86 s against 0.5 s."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    points = np.asarray(points, dtype=np.float64)
    if len(points) < 3:
        raise BathymetryError(f"{len(points)} point(s): a bed needs at least 3")
    flat = points.copy()
    flat[:, 2] = 0.0
    target = hull_area(points[:, :2])
    if not target > 0:
        raise BathymetryError("the points lie on one line in (x, y): they span no area")
    order = morton_order(points[:, :2])
    source = _polydata(flat[order])
    best, covered = None, -1.0
    for offset in (1e3, 1e4, 1e5):
        d = vtk.vtkDelaunay2D()
        d.SetInputData(source)
        d.SetTolerance(1e-9)
        d.SetOffset(offset)
        d.Update()
        polys = d.GetOutput().GetPolys()
        # vtkDelaunay2D keeps the input points in order: back to the indices of ``points``
        tri = order[vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64).reshape(-1, 3)]
        area = float(_triangle_areas(points[:, :2], tri).sum())
        if area > covered:
            best, covered = tri, area
        if abs(covered - target) <= 1e-9 * target:
            break
    if covered < (1.0 - HULL_GAP) * target:
        raise BathymetryError(f"the Delaunay triangulation covers {covered:.6g} of the points' hull "
                              f"area {target:.6g} (nearly coincident or collinear points?)")
    return best


def resample(points, triangles, xs, ys) -> tuple[np.ndarray, int]:
    """Heights z[j, i] at (xs[i], ys[j]) (both increasing) by linear interpolation on the
    triangulation of the points; a node outside it takes the height of the nearest point in
    (x, y) (vtkStaticPointLocator). Returns (z, number of nodes outside)."""
    from . import kernels
    points = np.asarray(points, dtype=np.float64)
    xs = np.ascontiguousarray(xs, dtype=np.float64)
    ys = np.ascontiguousarray(ys, dtype=np.float64)
    z = np.zeros((len(ys), len(xs)))
    found = np.zeros(z.shape, dtype=np.bool_)
    kernels.interpolate_on_triangles(np.ascontiguousarray(points[:, 0]), np.ascontiguousarray(points[:, 1]),
                                     np.ascontiguousarray(points[:, 2]),
                                     np.ascontiguousarray(triangles, dtype=np.int64), xs, ys, z, found)
    outside = np.argwhere(~found)
    if len(outside):
        import vtk
        flat = points.copy()
        flat[:, 2] = 0.0
        loc = vtk.vtkStaticPointLocator()
        loc.SetDataSet(_polydata(flat))
        loc.BuildLocator()
        for j, i in outside:
            z[j, i] = points[loc.FindClosestPoint(xs[i], ys[j], 0.0), 2]
    return z, int(len(outside))


def grid_axis(lo: float, size: float, dp: float) -> np.ndarray:
    """Nodes lo, lo + dp, ... up to lo + size (the last one at most dp/1e6 beyond)."""
    if not dp > 0:
        raise BathymetryError(f"grid dp = {dp:g}: expected a spacing > 0")
    n = int(np.floor(size / dp * (1 + 1e-12) + 1e-6)) + 1
    check_grid_size(n, 1)
    return lo + dp * np.arange(max(n, 1))


def expand(xs, ys, z, side: str, segments, dp: float):
    """The grid widened at one side (xmin, xmax, ymin, ymax) by ramps: each segment
    (length, height or None) adds nodes at most dp apart over its length, the heights going
    linearly from the edge's profile to the given height (kept flat where it is None); the next
    segment starts from where the last ended."""
    xs, ys, z = np.asarray(xs, float), np.asarray(ys, float), np.asarray(z, float)
    along_x = side in ("xmin", "xmax")
    outward = -1.0 if side in ("xmin", "ymin") else 1.0
    axis = xs if along_x else ys
    # profile at the edge, as a 1-D array over the other axis
    edge = (z[:, 0] if side == "xmin" else z[:, -1]) if along_x else (z[0] if side == "ymin" else z[-1])
    start = axis[0] if outward < 0 else axis[-1]
    coords, profiles = [], []
    for length, height in segments:
        if not length > 0:
            raise BathymetryError(f"<{side}> size = {length:g}: expected a length > 0")
        n = max(1, int(np.ceil(length / dp - 1e-9)))
        target = edge if height is None else np.full_like(edge, float(height))
        for k in range(1, n + 1):
            f = k / n
            coords.append(start + outward * length * f)
            profiles.append(edge + (target - edge) * f)
        start += outward * length
        edge = target
    coords = np.array(coords)
    block = np.array(profiles)                  # (n, other)
    if outward < 0:
        coords, block = coords[::-1], block[::-1]
    if along_x:
        block = block.T                          # (ny, n)
        if outward < 0:
            return np.r_[coords, xs], ys, np.hstack([block, z])
        return np.r_[xs, coords], ys, np.hstack([z, block])
    if outward < 0:
        return xs, np.r_[coords, ys], np.vstack([block, z])
    return xs, np.r_[ys, coords], np.vstack([z, block])


def check_grid_size(nx: int, ny: int) -> None:
    if nx * ny > MAX_GRID_NODES:
        raise BathymetryError(f"the grid has {nx} x {ny} nodes: at most {MAX_GRID_NODES}")

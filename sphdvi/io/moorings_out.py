"""The mooring lines' output files (DualSPHysics's names and columns, ``;``-separated as its):

* ``moordynplus_data/MoorDynPlus_tension.csv``, ``_force.csv``, ``_velocity.csv``,
  ``_position.csv`` (MoorDynPlus's ``<savedata>``: ``<tension>``, ``<force>``, ``<velocity>``,
  ``<position>``): ``time [s];dt [s]`` then, per line with ``savedata``, its anchor's and fairlead's
  value (``Anchor_L0 [N];Fairlead_L0 [N]``; vectors ``Anchor.x_L0 [N]`` ...), at ``<time starTime
  endTime dtOut>`` (dtOut: TimeOut);
* ``moordynplus_data/Line_<id>_pos.csv``, ``_vel.csv``, ``_tension.csv``, ``_strain.csv`` (a line's
  ``outputFlags`` p, v, t, s: its nodes' positions and velocities, its segments' tensions EA·strain
  (no compression) and strains), at the same times;
* ``FtForcePoints_ft<ffff>_pt<pp>.csv`` (``<savecsv_points>``): per fairlead (``ffff`` its floating's
  place among the case's floatings, ``pp`` its place among all the fairleads: :func:`force_point_files`),
  ``Part;Time [s];PosX [m];...;ForceX [N];...;VelX [m/s];...`` at every output (the force as the body
  feels it through the next step, after the start ramp);
* ``MooringsVtk/MooringsLines_<nnnn>.vtk`` (``<savevtk_lines>``) and ``MooringsVtk/Moorings_<nnnn>.vtk``
  (``<savevtk_moorings>``): at every output, a legacy VTK polydata (written by vtk) with one polyline
  per line through its nodes, and a vertex (MooringsLines) or a sphere (Moorings) at each node, the
  cell array ``Line`` (the line's id), as DualSPHysics writes them (:func:`write_lines_vtk`);
* ``MooringsVtk/FtForcesPoints_<nnnn>.vtk`` (``<savevtk_points>``): the fairleads with ``FtId``,
  ``Vel`` and ``Force`` (:func:`write_points_vtk`).

Numbers are written with 9 significant digits (MoorDynPlus writes six decimals). A resume cuts
each file back to the restart time, atomically; rows are appended at each output.
"""
from __future__ import annotations

import os

import numpy as np

from .atomic import append_text, write_text_atomic

FOLDER = "moordynplus_data"
KINDS = ("tension", "force", "velocity", "position")
UNITS = {"tension": "N", "force": "N", "velocity": "m/s", "position": "m"}
LINE_FLAGS = {"p": ("pos", "pos_{i}.{a} [m]", 3), "v": ("vel", "vel_{i}.{a} [m/s]", 3),
              "t": ("tension", "tension_{i} [N]", 1), "s": ("strain", "St_{i} [-]", 1)}
POINTS_HEADER = ("Part;Time [s];PosX [m];PosY [m];PosZ [m];ForceX [N];ForceY [N];ForceZ [N];"
                 "VelX [m/s];VelY [m/s];VelZ [m/s]")


def _fmt(values) -> str:
    return ";".join(f"{v:.9g}" for v in np.ravel(values))


def force_point_files(lines: list, moored: list, floatings: list) -> list:
    """(file name, line, end) of each fairlead's FtForcePoints file, as DualSPHysics names them
    (JDsFtForcePoints::SaveCsvPoints: ``FtForcePoints_ft%04d_pt%02u.csv`` of the point's floating id
    and the point's index among all the points): the points of the moored floatings in mkbound order,
    each body's in the order of its lines; a floating's id is its place among all the case's
    floatings (``floatings``) in mkbound order."""
    return [(f"FtForcePoints_ft{ft:04d}_pt{i:02d}.csv", k, e)
            for i, (ft, k, e) in enumerate(fairleads(lines, moored, floatings))]


def fairleads(lines: list, moored: list, floatings: list) -> list:
    """(floating id, line, end) of each fairlead in DualSPHysics's order of force points
    (:func:`force_point_files`)."""
    ftid = {mkb: i for i, mkb in enumerate(sorted(int(m) for m in floatings))}
    out = []
    for mkb in sorted(int(m) for m in moored):
        for k, ln in enumerate(lines):
            for e, end in enumerate(ln["ends"]):
                if end["kind"] == "vessel" and int(end["body"]) == mkb:
                    out.append((ftid[mkb], k, e))
    return out


def _rows_until(path: str, t: float | None, column: int) -> list:
    """The data rows of ``path`` whose time (in ``column``) is at most ``t`` (all when t is None)."""
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        lines = fh.readlines()[1:]
    if t is None:
        return lines
    keep = []
    for line in lines:
        try:
            if float(line.split(";")[column]) <= t * (1 + 1e-12) + 1e-12:
                keep.append(line)
        except (ValueError, IndexError):
            break
    return keep


class MooringLog:
    """The files of this module (its docstring) for the lines of a :class:`~sphdvi.moorings.system.Moorings`."""

    def __init__(self, outdir: str, moorings, floatings: list, tout: float, resume_time: float | None = None):
        """``floatings``: the mkbounds of every floating body of the case (the FtForcePoints files'
        ``ft`` is a body's place among them, in mkbound order)."""
        self.m = moorings
        self.folder = os.path.join(outdir, FOLDER)
        spec = moorings.spec
        self.files = {}          # path -> (header, column of the time, rows pending)
        save = spec.get("savedata")
        self.kinds = [k for k in KINDS if save and save.get(k)]
        self.lines = [k for k, ln in enumerate(spec["lines"]) if ln.get("savedata", True)]
        self.flags = {k: [f for f in ln.get("outputflags", "-") if f in LINE_FLAGS]
                      for k, ln in enumerate(spec["lines"])} if save else {}
        if save:
            self.t_start = float(save.get("start") or 0.0)
            end = save.get("end")
            self.t_end = float(end) if end else float("inf")
            self.dtout = float(save.get("dtout") or tout)
            self.next = self.t_start
            for kind in self.kinds:
                head = ["time [s]", "dt [s]"]
                for k in self.lines:
                    for where in ("Anchor", "Fairlead"):
                        head += ([f"{where}_L{k} [{UNITS[kind]}]"] if kind == "tension" else
                                 [f"{where}.{a}_L{k} [{UNITS[kind]}]" for a in "xyz"])
                self._open(os.path.join(outdir, FOLDER, f"MoorDynPlus_{kind}.csv"), ";".join(head), 0, resume_time)
            for k, flags in self.flags.items():
                n = int(spec["lines"][k]["segments"])
                for f in flags:
                    name, col, dim = LINE_FLAGS[f]
                    count = n + 1 if f in "pv" else n
                    cols = [col.format(i=i, a=a) for i in range(count) for a in ("xyz" if dim == 3 else "-")]
                    self._open(os.path.join(outdir, FOLDER, f"Line_{spec['lines'][k]['id']}_{name}.csv"),
                               "time [s];" + ";".join(c.replace(".-", "") for c in cols), 0, resume_time)
        self.vtk = {key: spec.get(key, default) for key, default in
                    (("savevtk_lines", True), ("savevtk_moorings", True), ("savevtk_points", False))}
        self.vtk_folder = os.path.join(outdir, "MooringsVtk") if any(self.vtk.values()) else None
        if self.vtk_folder is not None:
            os.makedirs(self.vtk_folder, exist_ok=True)
        self.fairleads = fairleads(spec["lines"], spec["floatings"], floatings)
        self.points = []         # (path, line, end) of each fairlead
        if spec.get("savecsv_points", True):
            for name, k, e in force_point_files(spec["lines"], spec["floatings"], floatings):
                path = os.path.join(outdir, name)
                self._open(path, POINTS_HEADER, 1, resume_time)
                self.points.append((path, k, e))
        if save and resume_time is not None and moorings.log_next is not None:
            self.next = moorings.log_next        # the schedule of the run that wrote the checkpoint

    def _open(self, path: str, header: str, column: int, resume_time: float | None) -> None:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        rows = _rows_until(path, resume_time, column) if resume_time is not None else []
        write_text_atomic(path, header + "\n" + "".join(rows))
        self.files[path] = []

    def after_step(self, t: float) -> None:
        """The MoorDynPlus rows due at ``t`` (``<savedata>``'s times: one ``dtOut`` further after each
        row, as MoorDynPlus), kept until the next output; the ``dt`` column is the lines' sub-step."""
        if not self.kinds and not any(self.flags.values()):
            return
        if not (self.t_start <= t <= self.t_end) or t < self.next * (1 - 1e-12) - 1e-12:
            return
        self.next += self.dtout
        m = self.m
        m.log_next = self.next
        dt_m = m.substep
        ends = (m.first, m.last)
        values = {"tension": m.end_tensions(), "force": m.fairlead_forces(),
                  "velocity": np.stack([m.vel[e] for e in ends], axis=1),
                  "position": np.stack([m.pos[e] for e in ends], axis=1)}
        head = f"{t:.9g};{dt_m:.9g};"
        for kind in self.kinds:
            path = os.path.join(self.folder, f"MoorDynPlus_{kind}.csv")
            self.files[path].append(head + _fmt(values[kind][self.lines]) + "\n")
        for k, flags in self.flags.items():
            a, b = m.first[k], m.last[k]
            seg_len = m.work["seg_len"][a:b]
            strain = seg_len / m.prm[k, 0] - 1.0
            data = {"pos": m.pos[a:b + 1], "vel": m.vel[a:b + 1], "strain": strain,
                    "tension": m.prm[k, 1] * np.maximum(strain, 0.0)}       # |T_i| = EA strain, as MoorDynPlus
            for f in flags:
                name = LINE_FLAGS[f][0]
                path = os.path.join(self.folder, f"Line_{m.lines[k]['id']}_{name}.csv")
                self.files[path].append(f"{t:.9g};" + _fmt(data[name]) + "\n")

    def record_part(self, part: int, t: float) -> None:
        """The FtForcePoints rows and the lines' VTK file of output ``part`` at ``t``; then every
        pending row to its file."""
        m = self.m
        if self.vtk["savevtk_lines"]:
            write_lines_vtk(os.path.join(self.vtk_folder, f"MooringsLines_{part:04d}.vtk"), m)
        if self.vtk["savevtk_moorings"]:
            write_lines_vtk(os.path.join(self.vtk_folder, f"Moorings_{part:04d}.vtk"), m, spheres=True)
        if self.points or self.vtk["savevtk_points"]:
            force = m.fairlead_forces() * m.ramp          # as the body feels it (the ramp of the step)
            nodes = [m.first[k] if e == 0 else m.last[k] for _, k, e in self.fairleads]
            for path, k, e in self.points:
                node = m.first[k] if e == 0 else m.last[k]
                self.files[path].append(f"{part};{t:.9g};{_fmt(m.pos[node])};{_fmt(force[k, e])};{_fmt(m.vel[node])}\n")
            if self.vtk["savevtk_points"]:
                write_points_vtk(os.path.join(self.vtk_folder, f"FtForcesPoints_{part:04d}.vtk"),
                                 [ft for ft, _, _ in self.fairleads], m.pos[nodes], m.vel[nodes],
                                 np.array([force[k, e] for _, k, e in self.fairleads]).reshape(-1, 3))
        for path, rows in self.files.items():
            if rows:
                append_text(path, "".join(rows))
                rows.clear()


def write_lines_vtk(path: str, moorings, spheres: bool = False) -> None:
    """The lines as DualSPHysics's JDsMooredFloatings::SaveVtkMoorings draws them, a legacy VTK
    polydata file written by vtk (atomically): one polyline per line through its nodes, and either
    a vertex at each node (``MooringsLines_<nnnn>.vtk``) or, with ``spheres``, a sphere of 16
    sides at each node whose radius is a tenth of the line's first segment (``Moorings_<nnnn>.vtk``);
    the cell array ``Line`` holds each cell's line id."""
    pos = np.asarray(moorings.pos, dtype=np.float64)
    first = np.asarray(moorings.first, dtype=np.int64)
    last = np.asarray(moorings.last, dtype=np.int64)
    ids = np.array([int(ln["id"]) for ln in moorings.lines], dtype=np.int32)
    counts = last - first + 1
    node_line = np.repeat(ids, counts)
    nodes = np.concatenate([np.arange(a, b + 1) for a, b in zip(first, last)])
    lines = (np.r_[0, np.cumsum(counts)], nodes)
    if not spheres:
        verts = (np.arange(len(nodes) + 1), nodes)
        data = _polydata(pos, verts=verts, lines=lines, cell_line=np.r_[node_line, ids])
    else:
        unit, tri = _unit_sphere()
        radius = np.repeat(np.linalg.norm(pos[first + 1] - pos[first], axis=1) / 10.0, counts)
        ball = (pos[nodes, None, :] + radius[:, None, None] * unit[None]).reshape(-1, 3)
        base = len(pos) + len(unit) * np.arange(len(nodes))
        conn = (tri[None, :, :] + base[:, None, None]).ravel()
        polys = (3 * np.arange(len(nodes) * len(tri) + 1), conn)
        data = _polydata(np.vstack([pos, ball]), lines=lines, polys=polys,
                         cell_line=np.r_[ids, np.repeat(node_line, len(tri))])
    _write_polydata(path, data)


def write_points_vtk(path: str, ftid, pos, vel, force) -> None:
    """``MooringsVtk/FtForcesPoints_<nnnn>.vtk`` (``<savevtk_points>``), as DualSPHysics's
    JDsFtForcePoints::SaveVtkPoints: a vertex at each fairlead with the point arrays ``FtId`` (its
    floating's place among the case's floatings), ``Vel`` and ``Force`` (as in the CSV files)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    n = len(ftid)
    data = _polydata(np.asarray(pos, float).reshape(n, 3), verts=(np.arange(n + 1), np.arange(n)))
    for name, values in (("FtId", np.asarray(ftid, np.int32)), ("Vel", np.asarray(vel, np.float32).reshape(n, 3)),
                         ("Force", np.asarray(force, np.float32).reshape(n, 3))):
        arr = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
        arr.SetName(name)
        data.GetPointData().AddArray(arr)
    _write_polydata(path, data)


_SPHERE: list = []


def _unit_sphere() -> tuple:
    """(points, triangles) of a unit sphere of 16 sides (vtkSphereSource), built once."""
    if not _SPHERE:
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkFiltersSources import vtkSphereSource
        src = vtkSphereSource()
        src.SetRadius(1.0)
        src.SetThetaResolution(16)
        src.SetPhiResolution(16)
        src.Update()
        out = src.GetOutput()
        pts = vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)
        cells = out.GetPolys()
        conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)
        _SPHERE.extend([pts, conn.reshape(-1, 3)])
    return _SPHERE[0], _SPHERE[1]


def _cells(offsets, connectivity):
    from vtkmodules.util.numpy_support import numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonDataModel import vtkCellArray
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.ascontiguousarray(offsets, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(np.ascontiguousarray(connectivity, dtype=np.int64), deep=True))
    return cells


def _polydata(points, verts=None, lines=None, polys=None, cell_line=None):
    """A vtkPolyData of ``points`` (float32, as DualSPHysics writes) and cells given as (offsets,
    connectivity); ``cell_line``: the cell array ``Line``, in VTK's cell order (verts, lines, polys)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    pts = vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float32), deep=True))
    data = vtkPolyData()
    data.SetPoints(pts)
    if verts is not None:
        data.SetVerts(_cells(*verts))
    if lines is not None:
        data.SetLines(_cells(*lines))
    if polys is not None:
        data.SetPolys(_cells(*polys))
    if cell_line is not None:
        arr = numpy_to_vtk(np.ascontiguousarray(cell_line, dtype=np.int32), deep=True)
        arr.SetName("Line")
        data.GetCellData().AddArray(arr)
    return data


def _write_polydata(path: str, data) -> None:
    from vtkmodules.vtkIOLegacy import vtkPolyDataWriter
    from .atomic import atomic_path
    with atomic_path(path) as tmp:
        w = vtkPolyDataWriter()
        w.SetFileName(tmp)
        w.SetInputData(data)
        w.SetFileTypeToBinary()
        if not w.Write():
            raise OSError(f"cannot write {path}")

"""Temporal VTKHDF PolyData particle files (one file per run), written with h5py.

Layout (``../shared/design/conventions.md`` §3.4, verified against vtkHDFReader 9.7):
points of all steps are concatenated; each step is one partition of N_s vertices;
the vertex topology 0..Nmax-1 is stored once and reused by every step (CellOffsets
= 0), which is valid because live particles are compacted first.

Crash safety: a step's arrays are appended first, then the ``Steps`` metadata
that makes them visible, then the file is flushed. Rows written after the last
complete step are ignored and cut on the next append (see :meth:`truncate_to`).

Readers during the run: the writer opens the file without HDF5's file lock (h5py
``locking=False``), so ParaView, h5py, ``sphdvi measure`` and ``sphdvi export`` can open it
while the run goes on, as DualSPHysics users open the Part files of a running job; a reader
opening it after an output's flush sees every step up to that output.  One that opens it while
an output is being written may find it inconsistent: :func:`open_particles` then says so (exit
2, read again).  Two runs writing one file are stopped by OUT's run lock instead
(:func:`sphdvi.io.runfolder.run_lock`).
"""
from __future__ import annotations

import contextlib
import os

import numpy as np

from ..errors import InputError, SphdviError, h5_reason

TOPOLOGIES = ("Vertices", "Lines", "Polygons", "Strips")
_LAYOUT = ("VTKHDF/Points", "VTKHDF/NumberOfPoints", "VTKHDF/PointData", "VTKHDF/Steps/Values",
           "VTKHDF/Steps/PointOffsets", "VTKHDF/Steps/PointDataOffsets")


def _bad_file(path: str, exc: BaseException) -> InputError:
    reason = h5_reason(exc)
    running = _writing_run(path)
    if running:
        return InputError(f"{path} could not be read ({reason}) while the run writing it ({running}) was in the "
                          "middle of an output: the steps written before are intact; read it again (a reader that "
                          "opens it between two outputs sees every step written so far)")
    if "unable to lock file" in reason or getattr(exc, "errno", None) == 11:
        return InputError(f"{path} is locked by another program that holds it open for writing (HDF5 file locking; "
                          "a sphdvi run does not lock it, an older sphdvi did): read it once that program has ended "
                          "(a stopped run goes on with --resume)")
    return InputError(f"{path} is not a readable particle file ({reason}; truncated or corrupt?)")


def _writing_run(path: str) -> str | None:
    """'pid N on HOST' of the run that holds the run lock of the particle file's folder, if any."""
    from .runfolder import run_lock_holder
    try:
        return run_lock_holder(os.path.dirname(os.path.abspath(path)))
    except OSError:
        return None


def _check_layout(f, path: str) -> None:
    missing = [name for name in _LAYOUT if name not in f]
    if missing or "NSteps" not in f["VTKHDF/Steps"].attrs:
        raise InputError(f"{path} is not a particle file of sphdvi run: no {(missing or ['Steps NSteps'])[0]}")


def require_point_arrays(f, path: str, names) -> None:
    """InputError naming the first of the point arrays ``names`` that the open particle file
    ``f`` lacks (its PointData dataset or its Steps/PointDataOffsets entry): a damaged file."""
    root = f["VTKHDF"]
    for name in names:
        for group in ("PointData", "Steps/PointDataOffsets"):
            if name not in root[group]:
                raise InputError(f"{path} lacks VTKHDF/{group}/{name} (not a particle file of a sphdvi run, or "
                                 "damaged)")


@contextlib.contextmanager
def open_particles(path: str):
    """``path`` opened for reading, its layout checked: a corrupt or truncated file, or an
    HDF5 file that is not a particle file, is an InputError naming it (exit code 2), also
    when a read inside the ``with`` block fails."""
    import h5py
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise _bad_file(path, exc) from None
    try:
        try:
            _check_layout(f, path)
        except InputError as exc:
            if _writing_run(path):          # a new file whose layout is being written
                raise _bad_file(path, exc) from None
            raise
        yield f
    except (OSError, KeyError) as exc:
        raise _bad_file(path, exc) from None
    except (ValueError, IndexError, RuntimeError) as exc:
        # an inconsistent view of a file an output is being written into (sizes past NSteps, ...)
        if isinstance(exc, SphdviError) or not _writing_run(path):
            raise
        raise _bad_file(path, exc) from None
    finally:
        f.close()


class VTKHDFParticleWriter:
    """Append particle snapshots to ``path`` (created, or opened for appending)."""

    def __init__(self, path: str, point_arrays: dict[str, tuple[np.dtype, int]], append: bool = False,
                 points_per_step: int | None = None):
        import h5py
        self.path = path
        self.arrays = dict(point_arrays)
        self.points_per_step = points_per_step      # sizes the point arrays' chunks of a new file
        mode = "a" if append else "w"
        try:
            # no HDF5 file lock: readers (ParaView, measure, export) may open it during the run; OUT's run
            # lock (io.runfolder.run_lock) keeps a second run out
            self.f = h5py.File(path, mode, locking=False)
        except OSError as exc:
            if not append:
                raise
            raise InputError(f"--resume: {path} is not a readable particle file ({h5_reason(exc)}; truncated or "
                             "corrupt?): the run cannot go on appending to it; move it away to resume into a new "
                             "one, or run without --resume") from None
        if not append or "VTKHDF" not in self.f:
            self._create()
        else:
            try:
                _check_layout(self.f, path)
            except InputError as exc:
                self.f.close()
                raise InputError(f"--resume: {exc}") from None
        self.root = self.f["VTKHDF"]
        self._bind()

    def _bind(self):
        """Keep the datasets an append writes (an h5py group look-up per dataset and output cost
        more than the writes: ~6 ms an output)."""
        root = self.root
        steps = root["Steps"]
        self._steps = steps
        self._points = root["Points"]
        self._nop = root["NumberOfPoints"]
        self._vconn = root["Vertices"]["Connectivity"]
        self._pdata = [(name, dtype, root["PointData"][name]) for name, (dtype, _) in self.arrays.items()]
        self._counts = [(topo == "Vertices", root[topo]["NumberOfCells"], root[topo]["NumberOfConnectivityIds"])
                        for topo in TOPOLOGIES]
        self._meta = {name: steps[name] for name in ("Values", "PartOffsets", "NumberOfParts", "PointOffsets",
                                                     "CellOffsets", "ConnectivityIdOffsets")}
        self._pdo = [steps["PointDataOffsets"][name] for name in self.arrays]

    # -- layout -----------------------------------------------------------------------
    def _create(self):
        import h5py
        root = self.f.create_group("VTKHDF")
        root.attrs["Version"] = np.array([2, 2], dtype=np.int64)
        t = "PolyData"
        root.attrs.create("Type", np.bytes_(t), dtype=h5py.string_dtype("ascii", len(t)))
        # chunks (HDF5 allocates whole ones): up to 2^16 values for the arrays of points, fewer
        # when a step holds fewer points; 2^10 rows for the arrays of one row per step (2^16 each
        # before: a 1-step file of 1,501 particles took 14.3 MB)
        point_cap = 1 << 16
        if self.points_per_step:
            point_cap = min(point_cap, max(1 << 10, 1 << int(np.ceil(np.log2(max(1, self.points_per_step))))))
        step_rows = 1 << 10

        def grow(group, name, shape, dtype, per_step=False):
            maxshape = (None,) + tuple(shape[1:])
            ncomp = max(1, int(np.prod(shape[1:])))
            rows = step_rows if per_step else max(1, min(point_cap, (1 << 16) // ncomp))
            group.create_dataset(name, shape=shape, maxshape=maxshape, dtype=dtype, chunks=(rows,) + tuple(shape[1:]))

        grow(root, "NumberOfPoints", (0,), np.int64, per_step=True)
        grow(root, "Points", (0, 3), np.float64)
        for topo in TOPOLOGIES:
            g = root.create_group(topo)
            grow(g, "NumberOfCells", (0,), np.int64, per_step=True)
            grow(g, "NumberOfConnectivityIds", (0,), np.int64, per_step=True)
            grow(g, "Offsets", (1,), np.int64, per_step=topo != "Vertices")
            grow(g, "Connectivity", (0,), np.int64, per_step=topo != "Vertices")
        pd = root.create_group("PointData")
        for name, (dtype, ncomp) in self.arrays.items():
            grow(pd, name, (0,) if ncomp == 1 else (0, ncomp), dtype)
        steps = root.create_group("Steps")
        steps.attrs["NSteps"] = np.int64(0)
        for name in ("Values",):
            grow(steps, name, (0,), np.float64, per_step=True)
        for name in ("PartOffsets", "NumberOfParts", "PointOffsets"):
            grow(steps, name, (0,), np.int64, per_step=True)
        grow(steps, "CellOffsets", (0, 4), np.int64, per_step=True)
        grow(steps, "ConnectivityIdOffsets", (0, 4), np.int64, per_step=True)
        pdo = steps.create_group("PointDataOffsets")
        for name in self.arrays:
            grow(pdo, name, (0,), np.int64, per_step=True)
        self.f.flush()

    # -- state ------------------------------------------------------------------------
    @property
    def nsteps(self) -> int:
        return int(self.root["Steps"].attrs["NSteps"])

    def times(self) -> np.ndarray:
        return self.root["Steps/Values"][: self.nsteps]

    def truncate_to(self, nsteps: int) -> None:
        """Keep the first ``nsteps`` steps and cut every array after them."""
        root = self.root
        steps = root["Steps"]
        nsteps = min(nsteps, int(steps.attrs["NSteps"]))
        npts = int(steps["PointOffsets"][nsteps - 1] + root["NumberOfPoints"][nsteps - 1]) if nsteps else 0
        for name in ("Values", "PartOffsets", "NumberOfParts", "PointOffsets", "CellOffsets",
                     "ConnectivityIdOffsets"):
            steps[name].resize(nsteps, axis=0)
        for name in self.arrays:
            steps["PointDataOffsets"][name].resize(nsteps, axis=0)
            root["PointData"][name].resize(npts, axis=0)
        root["NumberOfPoints"].resize(nsteps, axis=0)
        root["Points"].resize(npts, axis=0)
        for topo in TOPOLOGIES:
            root[topo]["NumberOfCells"].resize(nsteps, axis=0)
            root[topo]["NumberOfConnectivityIds"].resize(nsteps, axis=0)
        steps.attrs["NSteps"] = np.int64(nsteps)
        self.f.flush()

    # -- append -----------------------------------------------------------------------
    def append(self, time: float, points: np.ndarray, point_data: dict[str, np.ndarray]) -> None:
        """Write one step: ``points`` (N,3) of live particles and their arrays, then the step's
        rows of the Steps metadata, then NSteps (what makes the step visible), then a flush."""
        root = self.root
        steps = self._steps
        s = int(steps.attrs["NSteps"])
        if self._nop.id.shape[0] != s:             # leftovers of an interrupted append
            self.truncate_to(s)
        n = int(points.shape[0])
        start = int(self._points.id.shape[0])
        self._extend(self._points, np.asarray(points, dtype=np.float64))
        for name, dtype, ds in self._pdata:
            self._extend(ds, np.asarray(point_data[name], dtype=dtype))
        if self._vconn.id.shape[0] < n:                # topology 0..n-1 stored once, grown on demand
            vert = root["Vertices"]
            old = vert["Connectivity"].shape[0]
            vert["Connectivity"].resize(n, axis=0)
            vert["Connectivity"][old:] = np.arange(old, n, dtype=np.int64)
            vert["Offsets"].resize(n + 1, axis=0)
            vert["Offsets"][old + 1:] = np.arange(old + 1, n + 1, dtype=np.int64)
        none, count = np.zeros(1, np.int64), np.array([n], np.int64)
        for is_vert, cells, ids in self._counts:
            self._extend(cells, count if is_vert else none)
            self._extend(ids, count if is_vert else none)
        self._extend(self._nop, count)
        meta = self._meta
        self._extend(meta["Values"], np.array([time], np.float64))
        self._extend(meta["PartOffsets"], np.array([s], np.int64))
        self._extend(meta["NumberOfParts"], np.ones(1, np.int64))
        first = np.array([start], np.int64)
        self._extend(meta["PointOffsets"], first)
        self._extend(meta["CellOffsets"], np.zeros((1, 4), np.int64))
        self._extend(meta["ConnectivityIdOffsets"], np.zeros((1, 4), np.int64))
        for ds in self._pdo:
            self._extend(ds, first)
        steps.attrs["NSteps"] = np.int64(s + 1)
        self.f.flush()

    @staticmethod
    def _extend(ds, data):
        """Append ``data``'s rows to the chunked dataset ``ds`` (h5py's low-level calls: the
        high-level resize and slice assignment cost ~0.2 ms each in Python)."""
        from h5py import h5s
        data = np.ascontiguousarray(data)
        old = ds.id.shape[0]
        ds.id.set_extent((old + data.shape[0],) + data.shape[1:])
        if data.shape[0] == 0:
            return
        fspace = ds.id.get_space()
        fspace.select_hyperslab((old,) + (0,) * (data.ndim - 1), data.shape)
        ds.id.write(h5s.create_simple(data.shape), fspace, data)

    def close(self):
        if self.f:
            self.f.flush()
            self.f.close()
            self.f = None


def read_step(path: str, step: int) -> dict:
    """Read one step of a particle VTKHDF file: time, points and point arrays."""
    with open_particles(path) as f:
        root = f["VTKHDF"]
        steps = root["Steps"]
        nsteps = int(steps.attrs["NSteps"])
        if not -nsteps <= step < nsteps:
            raise IndexError(f"step {step} of {nsteps}")
        step %= nsteps
        off = int(steps["PointOffsets"][step])
        n = int(root["NumberOfPoints"][step])
        out = {"time": float(steps["Values"][step]), "points": root["Points"][off:off + n]}
        require_point_arrays(f, path, list(root["PointData"]))
        for name in root["PointData"]:
            o = int(steps["PointDataOffsets"][name][step])
            out[name] = root["PointData"][name][o:o + n]
        return out


def step_times(path: str) -> np.ndarray:
    with open_particles(path) as f:
        steps = f["VTKHDF"]["Steps"]
        return steps["Values"][: int(steps.attrs["NSteps"])]

"""``sphdvi export OUT --isosurface``: the free surface at every output time (IsoSurface tool).

At each output time the kernel sum ``sum_b m_b/rho_b W(x - x_b)`` of the
fluid particles (1 inside the fluid, 1/2 at a flat surface) is evaluated on a
regular grid (spacing dp/2 by default, the grid covering the fluid plus 2h)
by the gather loop of :mod:`.core`, and contoured at the surface threshold
(0.5 in 3D, 0.4 in 2D) with vtk's contour filter (marching cubes in 3D,
marching squares in the x-z plane in 2D).  Written as OUT/<subdir>/Iso_XXXX.vtp
plus OUT/<subdir>/isosurface.pvd (ParaView reads the series with time).
"""
from __future__ import annotations

import os

import numpy as np

from ..errors import InputError
from ..io.atomic import make_folder


# the isosurface's grid at most: 5e7 nodes take ~3 GB with their positions and sums
MAX_GRID_NODES = 50_000_000


def kernel_sum_grid(grid, spec, spacing):
    """(origin, dims, values) of the kernel sum on a grid covering the fluid plus 2h."""
    from .core import kernel_sum
    lo = grid.pos.min(axis=0) - 2.0 * spec.h
    hi = grid.pos.max(axis=0) + 2.0 * spec.h
    dims = np.floor((hi - lo) / spacing).astype(np.int64) + 1
    if spec.is2d:
        lo[1] = grid.pos[0, 1]
        dims[1] = 1
    nodes = float(np.prod(dims.astype(np.float64)))
    if nodes > MAX_GRID_NODES:
        # the spacing that gives MAX_GRID_NODES nodes over the same box
        box = np.where(dims > 1, hi - lo, 1.0)
        need = (float(np.prod(box[dims > 1])) / MAX_GRID_NODES) ** (1.0 / max(1, int((dims > 1).sum())))
        raise InputError(f"--iso-spacing {spacing:g}: {nodes:.3g} grid nodes over the fluid "
                         f"({' x '.join(f'{e:.3g}' for e, n in zip(hi - lo, dims) if n > 1)} m); at most "
                         f"{MAX_GRID_NODES:.0e}: expected a spacing >= {need:.3g} m (the default is dp/2, "
                         f"{0.5 * spec.dp:g} m)")
    axes = [lo[k] + spacing * np.arange(dims[k]) for k in range(3)]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")      # x fastest (VTK order)
    nodes = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    return lo, dims, kernel_sum(grid, nodes)


def contour(origin, dims, spacing, values, level):
    """vtkPolyData of the level set of ``values`` on the image (x fastest)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkFiltersCore import vtkContourFilter
    img = vtkImageData()
    img.SetOrigin(*[float(v) for v in origin])
    img.SetSpacing(spacing, spacing, spacing)
    img.SetDimensions(*[int(v) for v in dims])
    arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float64), deep=1)
    arr.SetName("KernelSum")
    img.GetPointData().SetScalars(arr)
    f = vtkContourFilter()
    f.SetInputData(img)
    f.SetValue(0, float(level))
    f.ComputeNormalsOn()
    f.Update()
    return f.GetOutput()


def export_isosurface(outdir: str, subdir: str = "iso", spacing: float | None = None,
                      threshold: float | None = None, first: int = 0, last: int | None = None) -> list:
    """Write the free surface of every output time; returns the written files (.pvd last)."""
    try:
        from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    except ImportError:
        raise InputError("--isosurface needs the vtk package (pip install vtk)") from None
    from ..io.vtkxml import write_pvd
    from .post import RunOutput
    run = RunOutput(outdir)
    spec = run.spec
    spacing = 0.5 * spec.dp if spacing is None else float(spacing)
    if not spacing > 0:
        raise InputError("isosurface spacing must be positive")
    level = spec.surface_threshold if threshold is None else float(threshold)
    from ..io.export import export_dir
    dest = export_dir(outdir, subdir or "iso")      # as `export --dir`: relative to OUTDIR, absolute as given
    make_folder(dest, "--dir")
    files, entries = [], []
    for snap in run.snapshots(arrays=("Rhop",), first=first, last=last):
        from .core import ParticleGrid, FLUID
        fl = snap.ptype == FLUID
        grid = ParticleGrid(snap.pos[fl], spec, {"vol": snap.mass[fl] / snap.rhop[fl]})
        name = f"Iso_{snap.part:04d}.vtp"
        path = os.path.join(dest, name)
        if grid.n:
            origin, dims, values = kernel_sum_grid(grid, spec, spacing)
            poly = contour(origin, dims, spacing, values, level)
        else:
            from vtkmodules.vtkCommonDataModel import vtkPolyData
            poly = vtkPolyData()
        w = vtkXMLPolyDataWriter()
        w.SetFileName(path + ".tmp")
        w.SetInputData(poly)
        w.SetDataModeToAppended()
        if not w.Write():
            raise OSError(f"cannot write {path}")
        os.replace(path + ".tmp", path)
        files.append(path)
        entries.append((snap.time, name))
    if first == 0 and last is None:          # the whole run: parts of a longer earlier one go
        from ..io.export import remove_stale_parts
        remove_stale_parts(dest, "isosurface.pvd", files)
    pvd = os.path.join(dest, "isosurface.pvd")
    write_pvd(pvd, entries)
    return files + [pvd]

"""Shared measurement operations on one particle snapshot (arrays in, arrays out).

The run-time gauges (:mod:`sphdvi.measure.gauges`) and the post-processing
commands (:mod:`sphdvi.measure.post`) both call these functions, so the same
point at the same time gives the same value to round-off (the snapshot file
stores Vel, Rhop and Press in float32).

* :class:`KernelSpec`: kernel kind, h, dp, 2D/3D and viscosity of a case;
* :class:`ParticleGrid`: particles counting-sorted into cells of size 2h;
* :func:`interpolate`: Shepard (or first-order MLS) kernel interpolation at points;
* :func:`surface_along_lines`: free surface by the kernel-sum threshold along lines;
* :func:`fluid_forces`: SPH force of the fluid on target particles.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..case.gauge_spec import line_samples
from ..sph import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from . import _kernels as K

FLUID = 3
DEFAULT_KCLIMIT = 0.5


@dataclass(frozen=True)
class KernelSpec:
    """What the gather loops need to know about a case."""

    kind: int          # 1 cubic spline, 2 Wendland
    h: float
    dp: float
    is2d: bool
    cs0: float = 0.0
    rhop0: float = 1000.0
    b: float = 0.0
    gamma: float = 7.0
    visco_kind: int = 1
    visco_bound: float = 0.0     # Visco x ViscoBoundFactor (fluid-boundary pairs)
    massfluid: float = 0.0
    laminar_eta: float = 0.1     # ViscoLaminarEta: eta/h of the laminar term
    visco_table: tuple = ()      # ViscoTime: ((time, Visco x ViscoBoundFactor), ...) or ()

    def visco_bound_at(self, t: float | None) -> float:
        """Visco x ViscoBoundFactor at time ``t`` (ViscoTime: linear, end values outside)."""
        if not self.visco_table or t is None:
            return self.visco_bound
        times, values = zip(*self.visco_table)
        return float(np.interp(t, times, values))

    @property
    def alpha(self) -> float:
        return K.kernel_alpha(self.kind, self.h, self.is2d)

    @property
    def wdp_inv(self) -> float:
        """1/W(dp) of the cubic kernel (tensile correction), 0 for Wendland; W(dp) taken
        at q = 2/3 whatever dp/h, as DualSPHysics (FunSphKernel.h GetKernelCubic_Ctes)
        and the solver."""
        if self.kind != 1:
            return 0.0
        return 1.0 / K.kernel_w(1, 1.0 / 1.5, K.kernel_alpha(1, self.h, self.is2d))

    @property
    def surface_threshold(self) -> float:
        """Kernel-sum threshold of the free surface: 0.4 in 2D, 0.5 in 3D (MeasureTool)."""
        return 0.4 if self.is2d else 0.5

    @classmethod
    def from_case(cls, data: dict, params: dict | None = None) -> "KernelSpec":
        """From a case file read by ``read_case_h5`` (``params`` overrides its parameters)."""
        c = data["constants"]
        p = dict(data.get("parameters") or {})
        p.update(params or {})
        gamma = float(c.get("gamma") or 7.0)
        cs0 = float(c.get("cs0") or 0.0)
        rhop0 = float(c.get("rhop0") or 1000.0)
        b = float(c.get("b") or cs0 * cs0 * rhop0 / gamma)
        factor = float(p.get("ViscoBoundFactor", 1.0) or 1.0)
        visco = float(p.get("Visco", 0.01) or 0.0) * factor
        table = ()
        if str(p.get("ViscoTime") or "").strip():
            from ..case.datafiles import read_visco_table
            table = tuple((float(t), float(v) * factor) for t, v in read_visco_table(str(p["ViscoTime"])))
        return cls(kind=int(p.get("Kernel", 2) or 2), h=float(c["h"]), dp=float(c["dp"]),
                   is2d=bool(c["is2d"]), cs0=cs0, rhop0=rhop0, b=b, gamma=gamma,
                   visco_kind=int(p.get("ViscoTreatment", 1) or 1), visco_bound=visco,
                   massfluid=float(c.get("massfluid") or 0.0),
                   laminar_eta=float(p.get("ViscoLaminarEta", 0.1)), visco_table=table)

    def tait_pressure(self, rhop):
        """Tait's equation of state p = B((rho/rho0)^gamma - 1)."""
        return self.b * ((np.asarray(rhop, np.float64) / self.rhop0) ** self.gamma - 1.0)


class ParticleGrid:
    """Particles counting-sorted into cells of size 2h (x fastest; 2D uses x-z).

    ``arrays`` (name -> per-particle array) are stored sorted, as contiguous
    float64, next to the sorted positions ``pos``.
    """

    def __init__(self, pos, spec: KernelSpec, arrays: dict | None = None):
        pos = np.ascontiguousarray(pos, dtype=np.float64).reshape(-1, 3)
        self.spec = spec
        self.n = pos.shape[0]
        self.cellsize = 2.0 * spec.h
        self.inv_cs = 1.0 / self.cellsize
        if self.n:
            lo, hi = K.bounding_box(pos)
        else:
            lo = hi = np.zeros(3)
        self.pmin = np.ascontiguousarray(lo, dtype=np.float64)
        shape = np.floor((hi - lo) * self.inv_cs).astype(np.int64) + 1
        if spec.is2d:
            shape[1] = 1
        self.shape = tuple(int(v) for v in shape)
        ncx, ncy, ncz = self.shape
        self.cell_start = np.zeros(ncx * ncy * ncz + 1, np.int64)
        self.order = np.empty(self.n, np.int64)
        if self.n:
            K.sort_into_cells(pos, self.pmin, self.inv_cs, ncx, ncy, ncz, spec.is2d, self.order,
                              self.cell_start)
        self.pos = np.ascontiguousarray(pos[self.order])
        self.arrays = {}
        for name, a in (arrays or {}).items():
            self.arrays[name] = np.ascontiguousarray(np.asarray(a)[self.order], dtype=np.float64)

    def geometry(self):
        """(cell_start, pmin, inv_cs, ncx, ncy, ncz, is2d): the grid arguments of the loops."""
        ncx, ncy, ncz = self.shape
        return self.cell_start, self.pmin, self.inv_cs, ncx, ncy, ncz, self.spec.is2d

    def field(self, names) -> np.ndarray:
        """Sorted arrays stacked as columns (N, k)."""
        cols = []
        for name in names:
            a = self.arrays[name]
            cols.append(a.reshape(self.n, -1))
        if not cols:
            return np.zeros((self.n, 0))
        return np.ascontiguousarray(np.concatenate(cols, axis=1))


def fluid_grid(pos, vel, rhop, mass, press, ptype, spec: KernelSpec, periodicity=None) -> ParticleGrid:
    """Grid of the fluid particles (``ptype == 3``) with vel, rhop, press, mass and
    volume m/rho: the input of interpolation, surfaces and forces.

    With a :class:`~sphdvi.sph.periodic.Periodicity`, the fluid particles within 2h of a
    periodic end get their ghost copies across it, so that a point near the end has its
    whole kernel support (DualSPHysics's gauges search the cell division, which holds
    the periodic copies)."""
    sel = np.flatnonzero(np.asarray(ptype) == FLUID)
    fpos = np.asarray(pos, np.float64)[sel]
    if periodicity is not None and sel.size:
        src, disp = periodicity.ghosts(fpos, 2.0 * spec.h)
        sel = np.concatenate([sel, sel[src]])
        fpos = np.concatenate([fpos, fpos[src] + disp])
    rho = np.asarray(rhop, np.float64)[sel]
    m = np.asarray(mass, np.float64)[sel]
    return ParticleGrid(fpos, spec, {
        "vel": np.asarray(vel, np.float64)[sel], "rhop": rho,
        "press": np.asarray(press, np.float64)[sel], "mass": m, "vol": m / rho})


def as_points(points) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(points, np.float64).reshape(-1, 3))


def interpolate(grid: ParticleGrid, points, names=("vel", "rhop", "press"), order: int = 0,
                kclimit: float | None = DEFAULT_KCLIMIT):
    """Kernel interpolation of the named arrays at ``points`` (P, 3).

    Returns ``(values (P, k), ksum (P,))``; ``ksum = sum_b m_b/rho_b W_pb``.
    Points with ``ksum < kclimit`` get NaN values (MeasureTool's kclimit).
    """
    pts = as_points(points)
    fields = grid.field(names)
    out = np.empty((pts.shape[0], fields.shape[1]))
    ksum = np.zeros(pts.shape[0])
    if grid.n == 0:
        out[:] = np.nan
        return out, ksum
    s = grid.spec
    K.interpolate_points(pts, grid.pos, grid.arrays["vol"], fields, *grid.geometry(), s.kind, s.h,
                         s.alpha, int(order), out, ksum)
    if kclimit is not None:
        out[ksum < kclimit] = np.nan
    return out, ksum


def kernel_sum(grid: ParticleGrid, points) -> np.ndarray:
    """sum_b m_b/rho_b W at the points (about 1 inside the fluid, 0.5 at a flat surface)."""
    _, ksum = interpolate(grid, points, names=(), kclimit=None)
    return ksum


def surface_along_lines(grid: ParticleGrid, p0, p1, step: float, threshold: float):
    """Free surface along the segments p0[i] -> p1[i] (MeasureTool -elevation, gauge swl).

    Samples every ``step``; the surface is the first point where the kernel sum
    drops below ``threshold`` after having reached it, linearly interpolated
    between samples.  Returns (L, 3) positions, NaN where the line meets no fluid.
    """
    p0 = as_points(p0)
    p1 = as_points(p1)
    seg = p1 - p0
    length = np.sqrt((seg * seg).sum(axis=1))
    ns = int(line_samples(float(length.max(initial=0.0)), step))
    s = np.linspace(0.0, 1.0, ns)
    samples = (p0[:, None, :] + s[None, :, None] * seg[:, None, :]).reshape(-1, 3)
    ks = kernel_sum(grid, samples)
    frac = np.empty(p0.shape[0])
    K.first_drop_below(ks, ns, float(threshold), frac)
    out = p0 + (frac / (ns - 1))[:, None] * seg
    out[frac < 0] = np.nan
    return out


def fluid_forces(grid: ParticleGrid, tpos, tvel, trhop, tpress, tmass, spec: KernelSpec,
                 viscosity: bool = True, t: float | None = None) -> np.ndarray:
    """Per-particle force (T, 3) of the fluid on the target particles (boundary or
    floating): pressure, tensile correction (cubic) and viscous terms of the
    momentum equation, see :func:`_kernels.fluid_force`. Per metre of width in 2D.
    ``t``: the time, for the viscosity of a ViscoTime case."""
    tpos = as_points(tpos)
    out = np.zeros((tpos.shape[0], 3))
    if grid.n == 0 or tpos.shape[0] == 0:
        return out
    f8 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    K.fluid_force(tpos, f8(tvel).reshape(-1, 3), f8(trhop), f8(tpress), f8(tmass), grid.pos,
                  grid.arrays["vel"].reshape(-1, 3), grid.arrays["rhop"], grid.arrays["press"],
                  grid.arrays["mass"], *grid.geometry(), spec.kind, spec.h, spec.alpha,
                  spec.visco_kind if viscosity else 0, spec.visco_bound_at(t), spec.cs0, spec.wdp_inv,
                  (spec.laminar_eta * spec.h) ** 2, out)
    return out


def force_and_moment(pos, forces, centre=None, axis=None):
    """Total force and moment about ``centre`` (default: mean of ``pos``); with
    ``axis`` (unit vector) the moment is projected on the axis through centre.
    Serial sums (reproducible)."""
    pos = np.asarray(pos, np.float64).reshape(-1, 3)
    forces = np.asarray(forces, np.float64).reshape(-1, 3)
    if pos.shape[0] == 0:
        return np.zeros(3), np.zeros(3)
    c = pos.mean(axis=0) if centre is None else np.asarray(centre, np.float64)
    f = forces.sum(axis=0)
    m = np.cross(pos - c, forces).sum(axis=0)
    if axis is not None:
        e = np.asarray(axis, np.float64)
        e = e / np.linalg.norm(e)
        m = (m @ e) * e
    return f, m


def nearest_particle_distance(points, pos, spec: KernelSpec, rmax: float) -> np.ndarray:
    """Distance from each point to the nearest of ``pos`` (capped at ``rmax`` <= 2h)."""
    pts = as_points(points)
    out = np.full(pts.shape[0], float(rmax))
    pos = as_points(pos)
    if pos.shape[0] == 0:
        return out
    g = ParticleGrid(pos, spec)
    K.nearest_distance(pts, g.pos, *g.geometry(), float(rmax), out)
    return out

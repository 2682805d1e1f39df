"""Post-processing of a run folder (``sphdvi measure``): points, elevation, forces, bodies.

Each function reads OUT/particles.vtkhdf step by step (only the arrays it
needs, the file kept open) and the gencase file OUT/<casename>.h5 (kernel,
h, dp, masses by Idp, parameters), and returns a :class:`~.tables.Table`.
"""
from __future__ import annotations

import json
import math
import os
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from . import core
from .tables import Table

UNITS = {"vel": "m/s", "rhop": "kg/m^3", "press": "Pa", "mass": "kg", "vol": "m^3", "kcorr": "-"}
UNITS_2D = {"mass": "kg/m", "vol": "m^2"}      # a 2D particle is a prism 1 m deep
VARS = ("vel", "rhop", "press")


# ---------------------------------------------------------------------------------
# reading a run folder
# ---------------------------------------------------------------------------------
@dataclass
class Snapshot:
    """One output time of particles.vtkhdf (arrays in file order)."""

    part: int
    time: float
    pos: np.ndarray
    vel: np.ndarray | None
    rhop: np.ndarray | None
    press: np.ndarray | None
    ptype: np.ndarray
    idp: np.ndarray
    mk: np.ndarray | None
    mass: np.ndarray


def case_periodicity(data: dict, params: dict):
    """The run's :class:`~sphdvi.sph.periodic.Periodicity` (None without periodic axes): measurements
    near a periodic end see the fluid's periodic copies, as the run's interaction does."""
    from ..simulation import periodic_axes, periodic_params
    from ..sph.periodic import Periodicity
    c = data["constants"]
    axes = periodic_axes(data, params)
    if not axes:
        return None
    return Periodicity(axes, np.asarray(data["particles"]["pos"], float), float(c["dp"]),
                       periodic_params(data, params))


class RunOutput:
    """A run folder: the case file, its kernel spec and the particle snapshots."""

    def __init__(self, outdir: str):
        from ..io.casefile import read_case_h5
        from ..simulation import find_case_file
        if not os.path.isdir(outdir):
            raise InputError(f"{outdir}: not a folder")
        self.outdir = outdir
        self.case_file = find_case_file(outdir)
        self.data = read_case_h5(self.case_file)
        self.params = dict(self.data["parameters"])
        run_json = os.path.join(outdir, "run.json")
        if os.path.exists(run_json):
            try:
                with open(run_json) as fh:
                    self.params.update(json.load(fh).get("parameters") or {})
            except (json.JSONDecodeError, OSError):
                pass
        self.spec = core.KernelSpec.from_case(self.data, self.params)
        self.periodicity = case_periodicity(self.data, self.params)
        p = self.data["particles"]
        idp = np.asarray(p["idp"], np.int64)
        self.mass_by_idp = np.zeros(int(idp.max(initial=-1)) + 1)
        self.fluidcount = int((self.data["json"].get("mkconfig") or {}).get("fluidcount", 0))
        self.mass_by_idp[idp] = self._run_masses(p)
        self.vtk_path = os.path.join(outdir, "particles.vtkhdf")
        selection = (self.data["json"].get("special") or {}).get("outputparts")
        if selection:
            every = int(selection.get("ignore") or 0)
            warnings.warn(f"{self.vtk_path} holds only the particles the case's <special><outputparts> selects"
                          + (f" (outputs 0, {every}, {2 * every}, ... whole)" if every > 0 else "")
                          + ": what is measured from it sees those alone")

    def _masses(self, idp: np.ndarray) -> np.ndarray:
        """The masses of the particles ``idp``: those of the case's, and for the ids a run created
        past them (the buffers of inlet/outlet zones, fluid) the fluid mass rho0 dp^d."""
        if idp.size and int(idp.max()) >= self.mass_by_idp.size:
            grown = np.full(int(idp.max()) + 1, float(self.data["constants"]["massfluid"]))
            grown[:self.mass_by_idp.size] = self.mass_by_idp
            self.mass_by_idp = grown
        return self.mass_by_idp[idp]

    def _run_masses(self, p) -> np.ndarray:
        """The particle masses the run used: the case's, but rho0 dp^d for the floating
        particles mDBC corrects (:func:`sphdvi.case.normals.mdbc_floating_mask`: of the case's
        own normals, those that have one; computed ones reach every floating particle)."""
        from ..case.normals import mdbc_floating_mask
        from ..coupling import body_labels
        mass = np.array(p["mass"], float)
        try:
            mask = mdbc_floating_mask(p["type"], body_labels(p["mk"], self.fluidcount), self.params,
                                      self.data.get("normals"))
        except ValueError:
            return mass         # a bad MdbcMkbound: the run refused it
        mass[mask] = float(self.data["constants"]["massbound"])
        return mass

    @property
    def has_particles(self) -> bool:
        return os.path.exists(self.vtk_path)

    def times(self) -> np.ndarray:
        from ..io.vtkhdf import step_times
        self._require_particles()
        return step_times(self.vtk_path)

    def _require_particles(self):
        if not self.has_particles:
            raise InputError(f"{self.vtk_path} not found: run 'sphdvi run {self.outdir}' first")

    def snapshots(self, arrays=("Vel", "Rhop", "Press", "Mk"), first=0, last=None, every=1):
        """Yield :class:`Snapshot` objects for steps first..last (inclusive); a range with no
        output time in it, or an unreadable particle file (one without Idp, Type or one of
        ``arrays`` but Press, which Rhop gives), is an InputError."""
        from ..io.vtkhdf import open_particles, require_point_arrays
        self._require_particles()
        with open_particles(self.vtk_path) as f:
            require_point_arrays(f, self.vtk_path, ["Idp", "Type"] + [a for a in arrays if a != "Press"])
            root = f["VTKHDF"]
            steps = root["Steps"]
            nsteps = int(steps.attrs["NSteps"])
            values = steps["Values"][:nsteps]
            offs = steps["PointOffsets"][:nsteps]
            counts = root["NumberOfPoints"][:nsteps]
            pd = root["PointData"]
            for k in output_range(nsteps, first, last, every, self.vtk_path):
                o, n = int(offs[k]), int(counts[k])

                def read(name):
                    if name not in pd or name not in steps["PointDataOffsets"]:
                        return None
                    d = steps["PointDataOffsets"][name][k]
                    return pd[name][int(d):int(d) + n]

                idp = read("Idp").astype(np.int64)
                yield Snapshot(
                    part=k, time=float(values[k]), pos=root["Points"][o:o + n],
                    vel=read("Vel") if "Vel" in arrays else None,
                    rhop=read("Rhop") if "Rhop" in arrays else None,
                    press=read("Press") if "Press" in arrays else None,
                    ptype=read("Type"), idp=idp, mk=read("Mk") if "Mk" in arrays else None,
                    mass=self._masses(idp))

    def fluid_grid(self, snap: Snapshot) -> core.ParticleGrid:
        press = snap.press if snap.press is not None else self.spec.tait_pressure(snap.rhop)
        return core.fluid_grid(snap.pos, snap.vel, snap.rhop, snap.mass, press, snap.ptype, self.spec,
                               self.periodicity)

    def domain_z(self):
        d = self.data.get("domain") or {}
        lo, hi = d.get("posmin"), d.get("posmax")
        return (float(lo[2]), float(hi[2])) if lo is not None and hi is not None else (None, None)


def output_range(n: int, first=0, last=None, every=1, source: str = "the run") -> range:
    """The output indices ``first..last`` (inclusive, ``last`` at most n - 1) every ``every``;
    InputError when none is left (``--first`` past the last output, ``--last`` before it)."""
    first = int(first or 0)
    if n == 0:
        raise InputError(f"{source} has no output time")
    if first > n - 1:
        raise InputError(f"--first {first}: {source} has {n} output times, numbered 0 to {n - 1}")
    stop = n - 1 if last is None else min(int(last), n - 1)
    if stop < first:
        raise InputError(f"--last {last} is before --first {first}: no output time to measure")
    return range(first, stop + 1, max(1, int(every)))


# ---------------------------------------------------------------------------------
# parsing of point lists
# ---------------------------------------------------------------------------------
def parse_points(text: str, is2d: bool | None = None, ncoord: int = 3) -> np.ndarray:
    """Points from ``"x,y,z;x,y,z"`` or a file (one point a line, separators , ; or
    spaces, ``#`` comments; MeasureTool ``POINTS`` / ``POINTSLIST`` / ``POINTSENDLIST``
    blocks too, as DualSPHysics's doc/help/FilePointsTemplate.txt lays them out).

    ``ncoord=2`` accepts ``x[,y]`` per point (elevation). ``is2d``: the case's dimension
    when known: in 3D (False) a point of 2 numbers (``ncoord=2``: of 1) is refused, in 2D or
    unknown (None) it is x,z (x). Raises ValueError.
    """
    if os.path.isfile(text):
        with open(text, encoding="utf-8") as fh:
            return _points_from_lines(fh.read().splitlines(), ncoord, source=text, is2d=is2d)
    if os.path.isdir(text):
        raise ValueError(f"{text} is a folder; expected a points file or a list of numbers")
    if _looks_like_a_file_name(text):
        raise ValueError(f"{text}: file not found (and not a list of numbers)")
    items = [s for s in text.replace("\n", ";").split(";") if s.strip()]
    if not items:
        raise ValueError("no points given")
    return _points_from_lines(items, ncoord, source=None, is2d=is2d)


def _looks_like_a_file_name(text: str) -> bool:
    """Not numbers but a path: one word with a path separator or a letter that cannot be
    part of a number (e, E and the words inf/nan can)."""
    t = text.strip()
    if not t or "," in t or ";" in t or " " in t:
        return False
    if "/" in t or os.sep in t:
        return True
    try:
        float(t)
        return False
    except ValueError:
        return any(ch.isalpha() for ch in t)


def _numbers(line: str):
    return [float(v) for v in line.replace(",", " ").replace(";", " ").replace(":", " ").split()]


# points a points file may define at most (a POINTSLIST count of 1e8 ran out of time and memory)
MAX_POINTS = 1_000_000
_BLOCK_ROWS = {"POINTSLIST": ("begin", "step", "count"), "POINTSENDLIST": ("begin", "step", "end")}


def _points_from_lines(lines, ncoord, source, is2d=None):
    """The points of a points file's lines (or of the command line's items): plain rows, and
    the three-row ``POINTSLIST`` / ``POINTSENDLIST`` blocks expanded; ValueError naming the
    file and line of a bad row."""
    pts = []
    mode = None
    block = []                       # the rows of the current list block: (where, text, numbers)
    for no, raw in enumerate(lines, 1):
        line = raw.split("#", 1)[0].strip()
        if not line or line.startswith("//"):
            continue
        where = f"{source}:{no}: " if source else ""
        word = line.split()[0].upper()
        if word in _TRANSFORMS:
            raise ValueError(_transform_refusal(where, raw.strip(), word))
        if word in ("POINTS", "POINTSLIST", "POINTSENDLIST"):
            _check_block_complete(mode, block)
            mode, block = word, []
            continue
        try:
            vals = _numbers(line)
        except ValueError:
            raise ValueError(f"{where}'{raw.strip()}' is not a list of numbers") from None
        if mode in _BLOCK_ROWS:
            if len(vals) != 3:
                raise ValueError(f"{where}'{raw.strip()}': expected 3 numbers in a {mode} "
                                 f"({' / '.join(_BLOCK_ROWS[mode])} rows)")
            block.append((where, raw.strip(), vals))
            if len(block) == 3:
                new = _pointslist(block) if mode == "POINTSLIST" else _pointsendlist(block)
                if len(pts) + len(new) > MAX_POINTS:
                    raise ValueError(f"{where}the points so far and this {mode} make {len(pts) + len(new):,} points; "
                                     f"at most {MAX_POINTS:,}")
                pts.extend(new)
                block = []
            continue
        pts.append(_plain_point(vals, ncoord, where, raw.strip(), source, is2d))
    _check_block_complete(mode, block)
    if not pts:
        raise ValueError("no points given")
    arr = np.asarray(pts, np.float64)
    if not np.isfinite(arr).all():
        raise ValueError("point coordinates must be finite")
    return arr


# MeasureTool's transformation lines (doc/help/FilePointsTemplate.txt): not read, see below
_TRANSFORMS = ("MOVE", "ROTATEAXIS", "SCALE")


def _transform_refusal(where, text, word):
    """The error for a MOVE / ROTATEAXIS / SCALE line. DualSPHysics's FilePointsTemplate.txt gives
    their syntax and one line, "Use_transformation_options_between_POINTS_and_after_POINTSLIST_or_
    POINTSENDLIST", but not which points they move (those after the line or before it), whether
    they add up or a block resets them, their order of composition nor the rotation's sense, and
    MeasureTool's source is not public: rather than guess, they are refused."""
    return (f"{where}'{text}': MeasureTool's transformation lines (MOVE, ROTATEAXIS, SCALE) are not read by "
            f"sphdvi ({word} here): DualSPHysics documents their syntax but not which points they move (those "
            "after the line or before it), whether they add up or what resets them, nor their order; write the "
            "points out already transformed, as x y z rows or POINTSLIST / POINTSENDLIST blocks (or transform "
            "them outside sphdvi), and remove the line")


def _plain_point(vals, ncoord, where, text, source, is2d):
    """One point row as x, y, z: ``x,z`` in 2D (``x`` for an elevation's ``x[,y]``), refused
    in a 3D case (``is2d`` False), where that shorthand would put the point at y = 0."""
    if ncoord == 2:
        # a MeasureTool points file has x y z lines (z unused: the whole vertical is
        # sampled); given on the command line, a third number is a mistake
        if len(vals) not in ((1, 2, 3) if source else (1, 2)):
            raise ValueError(f"{where}'{text}': expected x or x,y (the elevation is found along the "
                             "whole vertical at each x,y: no z)")
        if len(vals) == 1 and is2d is False:
            raise ValueError(f"{where}'{text}': the case is 3D: expected x,y")
        return [vals[0], vals[1] if len(vals) > 1 else 0.0, 0.0]
    if len(vals) == 2:                  # 2D shorthand x,z
        if is2d is False:
            raise ValueError(f"{where}'{text}': the case is 3D: expected x,y,z (x,z is for 2D cases)")
        vals = [vals[0], 0.0, vals[1]]
    if len(vals) != 3:
        raise ValueError(f"{where}'{text}': expected 3 coordinates x,y,z")
    return vals


def _check_block_complete(mode, block):
    """A POINTSLIST / POINTSENDLIST block cut short (by the end or the next keyword)."""
    if block:
        where, text, _ = block[-1]
        raise ValueError(f"{where}'{text}': the {mode} ends after {len(block)} row(s); expected 3 rows "
                         f"({' / '.join(_BLOCK_ROWS[mode])})")


def _check_block_finite(block, mode):
    for where, text, vals in block:
        if not all(math.isfinite(v) for v in vals):
            raise ValueError(f"{where}'{text}': the {mode} numbers must be finite")


def _grid_points(begin, step, counts, where, mode):
    """begin + (i, j, k) * step for i < counts[0], j < counts[1], k < counts[2] (z varying
    fastest), refused beyond :data:`MAX_POINTS`."""
    total = math.prod(counts)
    if total > MAX_POINTS:
        raise ValueError(f"{where}the {mode} makes {' x '.join(f'{c:,}' for c in counts)} = {total:,} points; at most "
                         f"{MAX_POINTS:,}")
    grid = np.stack(np.meshgrid(*(np.arange(k) for k in counts), indexing="ij"), -1).reshape(-1, 3)
    return (np.asarray(begin, float) + grid * np.asarray(step, float)).tolist()


def _pointslist(block):
    """MeasureTool POINTSLIST: rows 'BeginX BeginY BeginZ', 'StepX StepY StepZ',
    'CountX CountY CountZ' (counts: positive whole numbers)."""
    _check_block_finite(block, "POINTSLIST")
    (_, _, begin), (_, _, step), (where, text, count) = block
    if any(c < 1 or c != int(c) for c in count):
        raise ValueError(f"{where}'{text}': POINTSLIST counts must be whole numbers >= 1 (CountX CountY CountZ)")
    return _grid_points(begin, step, [int(c) for c in count], where, "POINTSLIST")


def _pointsendlist(block):
    """MeasureTool POINTSENDLIST: rows 'BeginX BeginY BeginZ', 'StepX StepY StepZ',
    'EndX EndY EndZ': along each axis begin, begin + step, ... up to end (a step of 0: the
    begin value alone), e.g. x 0..4 by 0.1 = 41 points."""
    _check_block_finite(block, "POINTSENDLIST")
    (_, _, begin), (swhere, stext, step), (where, text, end) = block
    counts = []
    for axis, b, s, e in zip("XYZ", begin, step, end):
        if s == 0:
            counts.append(1)
            continue
        q = (e - b) / s
        if q < -1e-9:
            raise ValueError(f"{swhere}'{stext}': Step{axis} {s:g} goes away from End{axis} {e:g} "
                             f"(Begin{axis} {b:g}); expected a step towards the end point, or 0")
        n = math.floor(q + 1e-6) + 1          # an end within a millionth of a step is kept (rounding)
        if n > MAX_POINTS:
            raise ValueError(f"{where}the POINTSENDLIST makes {n:,} points along {axis} (Begin{axis} {b:g} to "
                             f"End{axis} {e:g} by {s:g}); at most {MAX_POINTS:,}")
        counts.append(n)
    return _grid_points(begin, step, counts, where, "POINTSENDLIST")


# ---------------------------------------------------------------------------------
# measure points
# ---------------------------------------------------------------------------------
def _component_names(var: str, is2d: bool):
    if var == "vel":
        return ["velx", "vely", "velz"]
    return [var]


def tracked_motion(run: RunOutput, mks, mkbound=False):
    """A function snapshot -> (R, t), the rigid motion since the case's start of the boundary
    or floating particles with mk (or mkbound) in ``mks`` (Kabsch fit of their positions to
    their initial ones, by Idp): MeasureTool's ``-trackmk``, points that move with a tank.
    With periodic boundaries the run wraps a set that crosses a periodic end particle by particle,
    so each particle is first taken at its periodic image nearest where the motion so far puts it
    (:func:`unwrap_near`): at the first snapshot measured, the set's start moved as its particle
    nearest the initial centroid moved (any travel, any size of set, while the rotation moves no
    particle half a period away from that translation), then the previous fit (any motion of less
    than half a period between two outputs); :func:`tracked_points` brings the points back into the
    periodic box. Snapshots are to be given in time order."""
    p = run.data["particles"]
    first = Snapshot(part=0, time=0.0, pos=np.asarray(p["pos"], float), vel=None, rhop=None, press=None,
                     ptype=np.asarray(p["type"]), idp=np.asarray(p["idp"], np.int64), mk=np.asarray(p["mk"]),
                     mass=np.asarray(p["mass"], float))
    sel = target_mask(first, mks, run.fluidcount, mkbound)
    kind = "mkbound" if mkbound else "mk"
    if np.count_nonzero(sel) < 3:
        raise InputError(f"--track{kind} {','.join(str(m) for m in mks)}: the case has "
                         f"{np.count_nonzero(sel)} boundary or floating particles with that {kind}; "
                         "expected a rigid set of at least 3 (see the Mk column of particles.vtkhdf)")
    ref_pos = np.zeros((int(first.idp.max()) + 1, 3))
    ref_pos[first.idp[sel]] = first.pos[sel]
    is2d = run.spec.is2d
    per = run.periodicity
    anchor = int(first.idp[sel][np.argmin(np.linalg.norm(first.pos[sel] - first.pos[sel].mean(axis=0), axis=1))])
    last = []                   # the previous fit (R, t), with periodic boundaries

    def motion(snap: Snapshot):
        cur = target_mask(snap, mks, run.fluidcount, mkbound)
        ref, pos = ref_pos[snap.idp[cur]], np.asarray(snap.pos[cur], float)
        if per is None:
            return rigid_fit(ref, pos, is2d)
        if last:
            guess = ref @ last[0][0].T + last[0][1]
        else:
            k = np.flatnonzero(snap.idp[cur] == anchor)
            a = int(k[0]) if k.size else 0
            guess = ref + (pos[a] - ref[a])
        fit = rigid_fit(ref, unwrap_near(pos, guess, per), is2d)
        last[:] = [fit]
        return fit
    return motion


def tracked_points(start, R, t, per=None):
    """The points ``start`` (at the case's start) carried by the rigid motion (R, t) of
    :func:`tracked_motion`; with periodic boundaries (``per``) brought into the periodic box, where
    the run keeps the fluid: along each periodic axis k in turn, minus the whole periods S_k they
    are past its low end (JSphCpu::UpdatePos's wrap, increments included, repeated for a motion of
    more than one period)."""
    points = start @ R.T + t
    if per is not None:
        for k in per.axes:
            n = np.floor((points[:, k] - per.lo[k]) / per.length[k])
            if n.any():
                points -= n[:, None] * per.shift[k]
    return points


def measure_points(run: RunOutput, points, variables=VARS, kclimit=core.DEFAULT_KCLIMIT, order=0,
                   wall_factor=1.5, first=0, last=None, every=1, track=None):
    """Kernel interpolation of ``variables`` at ``points`` at every output time.

    ``track``: (mks, mkbound) of a rigid set of boundary or floating particles the points
    move with (their positions are then those at the case's start; :func:`tracked_motion`).
    Returns (table, near_wall) where ``near_wall`` lists (point index, min
    distance, first time) of points closer than ``wall_factor`` h to a
    boundary particle at some output time.
    """
    points = core.as_points(points)
    motion = tracked_motion(run, *track) if track is not None else None
    variables = list(variables)
    for v in variables:
        if v not in UNITS:
            raise InputError(f"unknown variable '{v}'; expected some of {', '.join(UNITS)}")
    spec = run.spec
    names, units, positions = [], [], []
    for v in variables:
        for i in range(points.shape[0]):
            for comp in _component_names(v, spec.is2d):
                names.append(f"{comp}_{i}")
                units.append(UNITS_2D.get(v, UNITS[v]) if spec.is2d else UNITS[v])
                positions.append(points[i])
    times, parts, rows = [], [], []
    near: dict = {}
    rwall = wall_factor * spec.h
    start = points
    for snap in run.snapshots(first=first, last=last, every=every):
        grid = run.fluid_grid(snap)
        if motion is not None:
            R, t = motion(snap)
            points = tracked_points(start, R, t, run.periodicity)
        fields = [v for v in variables if v != "kcorr"]
        vals, ksum = core.interpolate(grid, points, fields, order=order, kclimit=kclimit)
        # column order: variable, point, component
        row, col = [], 0
        for v in variables:
            if v == "kcorr":        # the kernel sum itself (MeasureTool's kcorr): ~1 in the water
                row.append(ksum)
                continue
            ncomp = 3 if v == "vel" else 1
            row.append(vals[:, col:col + ncomp].reshape(-1))
            col += ncomp
        rows.append(np.concatenate(row) if row else np.zeros(0))
        times.append(snap.time)
        parts.append(snap.part)
        bound = snap.pos[snap.ptype != core.FLUID]
        if wall_factor > 0 and bound.shape[0]:
            d = core.nearest_particle_distance(points, bound, spec, min(rwall, 2.0 * spec.h))
            for i in np.flatnonzero(d < rwall):
                if int(i) not in near:
                    near[int(i)] = (float(d[i]), snap.time)
                else:
                    near[int(i)] = (min(near[int(i)][0], float(d[i])), near[int(i)][1])
    table = Table(np.asarray(times), names, units, np.asarray(rows).reshape(len(rows), len(names)),
                  np.asarray(parts, np.int64), np.asarray(positions).reshape(-1, 3), title="points")
    near_wall = [(i, d, t) for i, (d, t) in sorted(near.items())]
    return table, near_wall


# ---------------------------------------------------------------------------------
# measure elevation
# ---------------------------------------------------------------------------------
def elevation_step(grid: core.ParticleGrid, bound_pos, xy, zlo, zhi, spec, threshold, dz):
    """Free-surface elevation and water depth at the (x, y) positions of one snapshot.

    Elevation: first drop of the kernel sum below ``threshold`` going up the
    vertical from ``zlo`` (MeasureTool -elevation).  Bottom: the top of the
    boundary below the water's lowest particle there (highest boundary particle within dp
    horizontally) plus dp/2, its half spacing (the wall face).  Below the lowest water, not
    below the surface: at a side wall the wall's own particles reach up to the surface
    (the depth there read 6 mm, then negative, in water 0.5 m deep).
    """
    from . import _kernels as K
    xy = np.asarray(xy, np.float64).reshape(-1, 3)
    p0 = xy.copy()
    p1 = xy.copy()
    p0[:, 2] = zlo
    p1[:, 2] = zhi
    surf = core.surface_along_lines(grid, p0, p1, dz, threshold)[:, 2]
    bottom = np.full(xy.shape[0], np.nan)
    if bound_pos.shape[0]:
        zlim = np.where(np.isfinite(surf), surf, zhi)
        if grid.n:
            lowest = np.empty(xy.shape[0])
            K.column_lowest(xy, np.ascontiguousarray(grid.pos, dtype=np.float64), spec.dp * 1.0001, spec.is2d, lowest)
            zlim = np.where(np.isfinite(lowest), np.minimum(zlim, lowest), zlim)
        K.column_top_below(xy, np.ascontiguousarray(zlim, dtype=np.float64),
                           np.ascontiguousarray(bound_pos, dtype=np.float64), 0.5 * spec.dp * 1.0001 + 1e-12,
                           spec.is2d, bottom)
        if np.isnan(bottom).any():     # no column exactly below: widen to dp
            wide = np.empty_like(bottom)
            K.column_top_below(xy, np.ascontiguousarray(zlim, dtype=np.float64),
                               np.ascontiguousarray(bound_pos, dtype=np.float64), spec.dp * 1.0001,
                               spec.is2d, wide)
            bottom = np.where(np.isnan(bottom), wide, bottom)
        bottom = bottom + 0.5 * spec.dp
    return surf, bottom


# samples along one vertical of `measure elevation` at most (--dz 1e-9 ran out of memory)
MAX_LINE_SAMPLES = 1_000_000


def measure_elevation(run: RunOutput, xy, threshold=None, dz=None, first=0, last=None, every=1):
    """Free-surface elevation and water depth at each (x, y) at every output time."""
    spec = run.spec
    xy = np.asarray(xy, np.float64).reshape(-1, 3).copy()
    if spec.is2d:
        xy[:, 1] = float(run.data["constants"].get("posy2d") or 0.0)
    threshold = spec.surface_threshold if threshold is None else float(threshold)
    dz = 0.25 * spec.dp if dz is None else float(dz)
    names, units, positions = [], [], []
    for i in range(xy.shape[0]):
        names += [f"elevation_{i}", f"depth_{i}"]
        units += ["m", "m"]
        positions += [xy[i], xy[i]]
    times, parts, rows = [], [], []
    for snap in run.snapshots(arrays=("Rhop",), first=first, last=last, every=every):
        fl = snap.ptype == core.FLUID
        grid = core.ParticleGrid(snap.pos[fl], spec, {"vol": snap.mass[fl] / snap.rhop[fl]})
        bound = snap.pos[~fl]
        if grid.n:
            zlo = min(float(snap.pos[:, 2].min()), float(grid.pos[:, 2].min())) - 2 * spec.h
            zhi = float(grid.pos[:, 2].max()) + 2 * spec.h
        else:
            zlo, zhi = 0.0, 1.0
        if (zhi - zlo) / dz > MAX_LINE_SAMPLES:
            raise InputError(f"--dz {dz:g}: {(zhi - zlo) / dz:.3g} samples along each vertical ({zhi - zlo:.3g} m, "
                             f"the fluid's height and 2h either side); at most {MAX_LINE_SAMPLES:.0e}: expected "
                             f"--dz >= {(zhi - zlo) / MAX_LINE_SAMPLES:.3g} m (the default is dp/4, "
                             f"{0.25 * spec.dp:g} m)")
        surf, bottom = elevation_step(grid, bound, xy, zlo, zhi, spec, threshold, dz)
        rows.append(np.column_stack([surf, surf - bottom]).reshape(-1))
        times.append(snap.time)
        parts.append(snap.part)
    return Table(np.asarray(times), names, units, np.asarray(rows).reshape(len(rows), len(names)),
                 np.asarray(parts, np.int64), np.asarray(positions).reshape(-1, 3), title="elevation")


# ---------------------------------------------------------------------------------
# measure forces
# ---------------------------------------------------------------------------------
def parse_mk_list(text: str):
    """``"11,12"`` or ``"11-14"`` -> [11, 12, ...]; raises ValueError."""
    out = []
    for part in str(text).replace(";", ",").split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if "-" in part[1:]:
                a, b = part.split("-", 1)
                lo, hi = int(a), int(b)
                if hi < lo:
                    raise ValueError(f"empty mk range '{part}'")
                out.extend(range(lo, hi + 1))
            else:
                out.append(int(part))
        except ValueError as exc:
            if "empty mk range" in str(exc):
                raise
            raise ValueError(f"'{part}' is not an mk; expected mk numbers or ranges like 11,12 or 11-14") from None
    if not out:
        raise ValueError("no mk given")
    return out


def force_units(is2d):
    return ("N/m", "N*m/m") if is2d else ("N", "N*m")


def target_mask(snap: Snapshot, mks, fluidcount=0, mkbound=False):
    """Non-fluid particles whose mk (global, or mkbound when ``mkbound``) is in ``mks``."""
    mk = snap.mk.astype(np.int64)
    if mkbound:
        mk = mk - fluidcount - 1
    return np.isin(mk, np.asarray(mks, np.int64)) & (snap.ptype != core.FLUID)


def step_force(run: RunOutput, snap: Snapshot, sel, grid=None, centre=None, axis=None, viscosity=True,
               arm_pos=None):
    """Total fluid force and moment on the particles ``sel`` of one snapshot; ``arm_pos``: the
    positions the lever arms start from (default the particles', e.g. a body made whole across a
    periodic end by :func:`unwrap_rigid`)."""
    spec = run.spec
    grid = grid or run.fluid_grid(snap)
    press = snap.press if snap.press is not None else spec.tait_pressure(snap.rhop)
    f = core.fluid_forces(grid, snap.pos[sel], snap.vel[sel], snap.rhop[sel], press[sel], snap.mass[sel],
                          spec, viscosity=viscosity, t=snap.time)
    return core.force_and_moment(snap.pos[sel] if arm_pos is None else arm_pos, f, centre=centre, axis=axis)


def measure_forces(run: RunOutput, mks, mkbound=False, point=None, axis=None, viscosity=True,
                   first=0, last=None, every=1):
    """Fluid force and moment on the particles of ``mks`` (ComputeForces).

    Moment about ``point`` (default: the mean position of the selected
    particles at each time); with ``axis`` = (p1, p2) the moment about the
    axis through p1 and p2, as a vector along it."""
    ax = None
    if axis is not None:
        p1, p2 = np.asarray(axis[0], float), np.asarray(axis[1], float)
        if np.linalg.norm(p2 - p1) == 0:
            raise InputError("--axis: the two points are equal")
        point, ax = p1, p2 - p1
    fu, mu = force_units(run.spec.is2d)
    names = ["fx", "fy", "fz", "mx", "my", "mz"]
    units = [fu] * 3 + [mu] * 3
    times, parts, rows = [], [], []
    found = False
    for snap in run.snapshots(first=first, last=last, every=every):
        sel = np.flatnonzero(target_mask(snap, mks, run.fluidcount, mkbound))
        found = found or sel.size > 0
        f, m = step_force(run, snap, sel, centre=point, axis=ax, viscosity=viscosity)
        rows.append(np.concatenate([f, m]))
        times.append(snap.time)
        parts.append(snap.part)
    if not found:
        kind = "mkbound" if mkbound else "mk"
        raise InputError(f"no boundary or floating particles with {kind} {','.join(map(str, mks))} in "
                         f"{run.vtk_path}")
    return Table(np.asarray(times), names, units, np.asarray(rows).reshape(len(rows), 6),
                 np.asarray(parts, np.int64), title="forces")


# ---------------------------------------------------------------------------------
# measure bodies
# ---------------------------------------------------------------------------------
BODY_COLUMNS = (("cx", "m"), ("cy", "m"), ("cz", "m"), ("surge", "m"), ("sway", "m"), ("heave", "m"),
                ("roll", "deg"), ("pitch", "deg"), ("yaw", "deg"), ("vx", "m/s"), ("vy", "m/s"),
                ("vz", "m/s"), ("wx", "rad/s"), ("wy", "rad/s"), ("wz", "rad/s"),
                ("ffx", "F"), ("ffy", "F"), ("ffz", "F"), ("ftx", "M"), ("fty", "M"), ("ftz", "M"),
                ("cfx", "F"), ("cfy", "F"), ("cfz", "F"), ("ctx", "M"), ("cty", "M"), ("ctz", "M"))
LINK_COLUMNS = (("fx", "F"), ("fy", "F"), ("fz", "F"), ("tx", "M"), ("ty", "M"), ("tz", "M"))


def rotation_to_euler_deg(R):
    """Roll, pitch, yaw [deg] of R = Rz(yaw) Ry(pitch) Rx(roll) (the convention of bodies.csv)."""
    roll = math.atan2(R[2, 1], R[2, 2])
    pitch = math.asin(max(-1.0, min(1.0, -R[2, 0])))
    yaw = math.atan2(R[1, 0], R[0, 0])
    return np.degrees([roll, pitch, yaw])


def rigid_fit(ref, cur, is2d=False):
    """Rotation R and translation t minimising |R ref + t - cur| (Kabsch 1976, SVD);
    in 2D the rotation is about y only."""
    mr, mc = ref.mean(axis=0), cur.mean(axis=0)
    a, b = ref - mr, cur - mc
    if is2d:
        # rotation about y in the x-z plane: angle from the 2D cross/dot sums
        s = np.sum(a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2])
        c = np.sum(a[:, 0] * b[:, 0] + a[:, 2] * b[:, 2])
        th = math.atan2(s, c)
        R = np.array([[math.cos(th), 0.0, math.sin(th)], [0.0, 1.0, 0.0], [-math.sin(th), 0.0, math.cos(th)]])
    else:
        u, _, vt = np.linalg.svd(a.T @ b)
        d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
        R = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return R, mc - R @ mr


def unwrap_rigid(pos, anchor: int, per):
    """The positions ``pos`` of a rigid body's particles as one piece when the run's periodic
    boundaries (``per``, None: none) have wrapped part of it to the other end: each particle's
    offset from the ``anchor`` particle taken as its shortest periodic image (the minimum image
    DualSPHysics's FtPeriodicDist takes for the particle-to-centre distance). Exact while every
    particle lies within half a period of the anchor along each periodic axis."""
    pos = np.asarray(pos, float)
    if per is None or pos.shape[0] == 0:
        return pos
    d = pos - pos[anchor]
    per.min_image(d)
    return pos[anchor] + d


def unwrap_near(pos, guess, per):
    """Each position of ``pos`` moved by whole periods (``per``: the run's periodicity, increments
    included) to its image nearest ``guess`` (the same particle's expected position): a rigid set
    the run wrapped particle by particle made whole again, as :func:`unwrap_rigid` but about a
    guess of each particle's place rather than one particle (so also for a set longer than half a
    period, e.g. the floor of a periodic channel). A position already nearest is returned as it is."""
    d0 = np.asarray(pos, float) - guess
    d = per.min_image(d0.copy())
    return np.asarray(pos, float) + (d - d0)


def rigid_velocity(pos, vel, centre, is2d=False):
    """Linear velocity of ``centre`` and angular velocity w of a rigid set of particles
    (least squares of v_i = V + w x (x_i - c))."""
    m = pos.mean(axis=0)
    r = pos - m
    vm = vel.mean(axis=0)
    L = np.cross(r, vel - vm).sum(axis=0)
    inertia = (r * r).sum() * np.eye(3) - r.T @ r
    if is2d:
        w = np.array([0.0, L[1] / inertia[1, 1] if inertia[1, 1] > 0 else 0.0, 0.0])
    else:
        w = np.linalg.lstsq(inertia, L, rcond=None)[0]
    return vm + np.cross(w, np.asarray(centre) - m), w


def _body_table_columns(names, is2d, links=()):
    fu, mu = force_units(is2d)
    unit = {"F": fu, "M": mu}
    cols, units = [], []
    for nm in names:
        for c, u in BODY_COLUMNS:
            cols.append(f"{nm}_{c}")
            units.append(unit.get(u, u))
    for ln in links:
        for c, u in LINK_COLUMNS:
            cols.append(f"{ln}_{c}")
            units.append(unit.get(u, u))
    return cols, units


BODY_LOG_COLUMNS = ("time", "body", "x", "y", "z", "roll", "pitch", "yaw", "vx", "vy", "vz", "wx", "wy", "wz",
                    "cfx", "cfy", "cfz", "ctx", "cty", "ctz")
LINK_LOG_COLUMNS = ("time", "link", "fx", "fy", "fz", "tx", "ty", "tz")


def _read_body_logs(outdir: str):
    """Rows (dicts) of a run's bodies.csv and links.csv (no links.csv: none), their numbers
    as floats; a file without the columns measure reads, or with a value that is not a
    number, is an InputError naming it (a damaged or foreign file)."""
    rows = _read_log(os.path.join(outdir, "bodies.csv"), BODY_LOG_COLUMNS)
    lpath = os.path.join(outdir, "links.csv")
    links = _read_log(lpath, LINK_LOG_COLUMNS) if os.path.exists(lpath) else []
    return rows, links


def _read_log(path: str, columns) -> list:
    """The rows of a run's body or link log ``path`` with ``columns`` (the second a name, the
    others numbers)."""
    import csv
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            missing = [c for c in columns if c not in (reader.fieldnames or [])]
            if missing:
                raise InputError(f"{path} is not a readable {os.path.basename(path)} of a sphdvi run (damaged?): no "
                                 f"column {', '.join(missing[:3])}{', ...' if len(missing) > 3 else ''}; expected "
                                 f"the columns {','.join(columns)}")
            rows = []
            for r in reader:
                try:
                    rows.append({c: (r[c] if k == 1 else float(r[c])) for k, c in enumerate(columns)})
                except (TypeError, ValueError):
                    raise InputError(f"{path}:{reader.line_num}: not a readable {os.path.basename(path)} row "
                                     f"(damaged?): expected numbers in {','.join(columns[:1] + columns[2:])}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path} cannot be read ({exc.__class__.__name__}: {exc})") from None
    return rows


def _time_index(times, t, rel=1e-8):
    """Index of ``t`` in the sorted ``times`` (written with 9 digits), or None."""
    i = int(np.searchsorted(times, t))
    for k in (i - 1, i):
        if 0 <= k < len(times) and abs(times[k] - t) <= rel * max(1.0, abs(t)):
            return k
    return None


def with_logged_contacts(table: Table, outdir: str, data: dict, is2d: bool) -> Table:
    """Fill the contact force and torque of the floating bodies, and add the link
    forces, from the bodies.csv / links.csv an SPH run wrote at its output times
    (the snapshots hold particles only)."""
    from ..mechanism import mechanism_from_case
    rows, links = _read_body_logs(outdir)
    mech = mechanism_from_case(data)
    name_of = {int(mkb): b["name"] for mkb, b in zip(mech["mkbounds"], mech["bodies"])}
    mkbounds = [int(v) for v in data["bodies"]["mkbound"]]
    block_of = {name_of[m]: b for b, m in enumerate(mkbounds) if m in name_of}     # body name -> table block
    lnames = list(dict.fromkeys(r["link"] for r in links))
    cols, units = _body_table_columns([f"mkbound{m}" for m in mkbounds], is2d, lnames)
    out = np.full((table.time.size, len(cols)), np.nan)
    out[:, :table.data.shape[1]] = table.data
    nb = len(BODY_COLUMNS)
    contact = ("cfx", "cfy", "cfz", "ctx", "cty", "ctz")
    for r in rows:
        k = _time_index(table.time, float(r["time"]))
        b = block_of.get(r["body"])
        if k is not None and b is not None:
            out[k, (b + 1) * nb - 6:(b + 1) * nb] = [float(r[c]) for c in contact]
    base = len(mkbounds) * nb
    for r in links:
        k = _time_index(table.time, float(r["time"]))
        if k is not None:
            l = lnames.index(r["link"])
            out[k, base + 6 * l: base + 6 * (l + 1)] = [float(r[c]) for c in ("fx", "fy", "fz", "tx", "ty", "tz")]
    return Table(table.time, cols, units, out, table.part, title=table.title)


def bodies_from_csv(outdir: str, is2d: bool, first=0, last=None, every=1) -> Table:
    """The body table from bodies.csv / links.csv of a body-only run (no fluid:
    the fluid force is zero); ``first``, ``last``, ``every`` index its row times."""
    rows, links = _read_body_logs(outdir)
    names = list(dict.fromkeys(r["body"] for r in rows))
    lnames = list(dict.fromkeys(r["link"] for r in links))
    times = sorted({float(r["time"]) for r in rows})
    keep = set(times[k] for k in output_range(len(times), first, last, every,
                                              os.path.join(outdir, "bodies.csv")))
    times = [t for t in times if t in keep]
    origin = {}                       # each body's first centre (t = 0): surge, sway, heave from it
    for r in rows:
        origin.setdefault(r["body"], np.array([float(r[k]) for k in ("x", "y", "z")]))
    rows = [r for r in rows if float(r["time"]) in keep]
    tindex = {t: i for i, t in enumerate(times)}
    cols, units = _body_table_columns(names, is2d, lnames)
    data = np.full((len(times), len(cols)), np.nan)
    nb = len(BODY_COLUMNS)
    for r in rows:
        i = tindex[float(r["time"])]
        b = names.index(r["body"])
        c = np.array([float(r[k]) for k in ("x", "y", "z")])
        vals = np.concatenate([c, c - origin[r["body"]], [float(r[k]) for k in ("roll", "pitch", "yaw")],
                               [float(r[k]) for k in ("vx", "vy", "vz", "wx", "wy", "wz")], np.zeros(6),
                               [float(r[k]) for k in ("cfx", "cfy", "cfz", "ctx", "cty", "ctz")]])
        data[i, b * nb:(b + 1) * nb] = vals
    base = len(names) * nb
    for r in links:
        t = float(r["time"])
        if t not in tindex:
            continue
        l = lnames.index(r["link"])
        data[tindex[t], base + 6 * l: base + 6 * (l + 1)] = [float(r[k]) for k in
                                                              ("fx", "fy", "fz", "tx", "ty", "tz")]
    return Table(np.asarray(times), cols, units, data, title="bodies")


def bodies_from_snapshots(run: RunOutput, first=0, last=None, every=1) -> Table:
    """Body motion of the floating bodies from the particle snapshots (rigid fit of
    each body's particles to their initial positions), and the fluid force and
    torque about the centre recomputed from the fluid (contact forces: left empty
    here; :func:`with_logged_contacts` fills them from the run's bodies.csv). With periodic
    boundaries a body across a periodic end is first made whole about its particle nearest the
    centre (:func:`unwrap_rigid`), and its centre is given in the periodic box, as bodies.csv and
    DualSPHysics's floating outputs give it (surge, sway, heave: that centre minus the initial one)."""
    data = run.data
    bodies = data.get("bodies") or {}
    if "mk" not in bodies or len(bodies["mk"]) == 0:
        raise InputError(f"{run.outdir}: the case has no floating bodies and no bodies.csv")
    is2d = run.spec.is2d
    mks = [int(v) for v in bodies["mk"]]
    names = [f"mkbound{int(v)}" for v in bodies["mkbound"]]
    centre0 = np.asarray(bodies["center"], float).reshape(-1, 3)
    p = data["particles"]
    per = run.periodicity
    ref, anchor = {}, {}
    for b, mk in enumerate(mks):
        sel = np.flatnonzero((p["mk"] == mk) & (p["type"] != core.FLUID))
        o = np.argsort(p["idp"][sel])
        ref[b] = (p["idp"][sel][o], p["pos"][sel][o])
        # the particle nearest the centre: the body is made whole about it (unwrap_rigid)
        anchor[b] = int(ref[b][0][np.argmin(np.linalg.norm(ref[b][1] - centre0[b], axis=1))]) if sel.size else -1
    cols, units = _body_table_columns(names, is2d)
    nb = len(BODY_COLUMNS)
    times, parts, rows = [], [], []
    for snap in run.snapshots(first=first, last=last, every=every):
        grid = run.fluid_grid(snap)
        row = np.full(len(cols), np.nan)
        for b, mk in enumerate(mks):
            sel = np.flatnonzero((snap.mk == mk) & (snap.ptype != core.FLUID))
            if sel.size == 0:
                continue
            sel = sel[np.argsort(snap.idp[sel])]
            ridp, rpos = ref[b]
            keep = np.isin(ridp, snap.idp[sel])
            k = np.flatnonzero(snap.idp[sel] == anchor[b])
            pos = unwrap_rigid(snap.pos[sel], int(k[0]) if k.size else 0, per)
            R, t = rigid_fit(rpos[keep], pos, is2d)
            c = R @ centre0[b] + t
            v, w = rigid_velocity(pos, snap.vel[sel].astype(float), c, is2d)
            f, m = step_force(run, snap, sel, grid=grid, centre=c, arm_pos=pos)
            if per is not None:             # the centre in the periodic box, as bodies.csv (FtUpdateFloatings)
                c = c[None, :].copy()
                per.wrap(c)
                c = c[0]
            row[b * nb:(b + 1) * nb] = np.concatenate([c, c - centre0[b], rotation_to_euler_deg(R), v, w, f, m,
                                                       np.full(6, np.nan)])
        rows.append(row)
        times.append(snap.time)
        parts.append(snap.part)
    return Table(np.asarray(times), cols, units, np.asarray(rows).reshape(len(rows), len(cols)),
                 np.asarray(parts, np.int64), title="bodies")


def measure_bodies(outdir: str, first=0, last=None, every=1) -> Table:
    """Per body: centre, surge/sway/heave, roll/pitch/yaw, velocities, fluid force and
    torque, contact force and torque, and link forces (FloatingInfo)."""
    from ..io.casefile import read_case_h5
    from ..simulation import find_case_file
    data = read_case_h5(find_case_file(outdir))
    logged = os.path.exists(os.path.join(outdir, "bodies.csv"))
    if logged and not os.path.exists(os.path.join(outdir, "particles.vtkhdf")):
        # a body-only run: no particle snapshots, the logs are the whole record
        return bodies_from_csv(outdir, bool(data["constants"]["is2d"]), first=first, last=last, every=every)
    table = bodies_from_snapshots(RunOutput(outdir), first=first, last=last, every=every)
    if logged:
        table = with_logged_contacts(table, outdir, data, bool(data["constants"]["is2d"]))
    return table

"""Run-time gauges of ``<special><gauges>`` (DualSPHysics ``JDsGaugeItem``), case-format.md §2.12.

Types and outputs (``;``-separated, first column ``time [s]``, in OUT):

* ``velocity`` -> ``GaugesVel_<name>.csv``: ``time;velx;vely;velz;posx;posy;posz``,
  kernel interpolation at ``point``, Shepard-normalised where the kernel sum is at
  least 0.5 and 0 below (DualSPHysics's JGaugeVelocity writes the raw sum
  sum_b V_b W u_b everywhere, which reads low by the kernel sum near a surface:
  24 % at a dam-break front);
* ``swl`` -> ``GaugesSWL_<name>.csv``: ``time;swlx;swly;swlz;pos0x..pos2z``, free
  surface along ``point0`` -> ``point2`` sampled every ``pointdp`` (``value`` [m] or
  ``coefdp``, default 0.5 dp) where the kernel sum drops below ``masslimit``
  (``coef``, default 0.5 in 3D / 0.4 in 2D; ``value`` [kg] is divided by massfluid);
  ``point0`` on a dry line, ``point2`` on one that never leaves the water (JGaugeSwl);
* ``maxz`` -> ``GaugesMaxZ_<name>.csv``: ``time;zmax;posx;posy;posz`` (pos = ``point0``),
  the highest fluid particle within ``distlimit`` (``value`` [m], ``coefdp`` or
  ``coefh``, default 1.5 dp) horizontally of ``point0`` and up to ``height`` above it;
  ``point0``'s z when there is none (DualSPHysics writes the domain's lowest z);
* ``force`` -> ``GaugesForce_<name>.csv``: ``time;force;forcex;forcey;forcez``, the
  fluid force on the particles of ``<target mkbound>`` (per metre in 2D): pressure
  and viscous terms with the case's kernel (DualSPHysics's JGaugeForce: the pressure
  term alone, Wendland, fixed and moving targets only; sphdvi also takes floating
  ones);
* ``mesh`` -> one file per ``outputdata`` item, ``GaugesMesh_<name>_Vel.csv``,
  ``_VelDir``, ``_Rhop``, ``_Zsurf`` (DualSPHysics's names), columns ``v(i:j:k)``
  (``.x .y .z`` for Vel): nodes ``point + i d1 e1 + j d2 e2 + k d3 e3`` (e = unit
  ``vec1..3``; ``<sizeK length distpt>`` gives the extent and the spacing dK, the
  older ``<sizeK value>`` the extent with spacing dp); veldir is the velocity along
  ``dirdat`` (default 1,0,0), zsurf the free surface along ``vec3`` for each (i, j)
  column (the column's base when dry, its top when it never leaves the water);
  kernel correction as JGaugeMesh: Shepard where the kernel sum >= ``kclimit``
  (default 0.5), ``kcdummy`` (default 0) below it, the raw sums with ``kcdummy``
  ``none`` below it or with ``kclimit`` ``none`` everywhere.

As DualSPHysics's JGaugeSystem, a gauge writes its file only with ``<output
value="true"/>`` (on it or in ``<default>``; gencase warns about one without), and
then a row every ``outputdt`` (default TimeOut); sphdvi computes it only then, at
``computedt``.

Gauge input is checked at gencase (:mod:`sphdvi.case.gauge_spec`), so the items
read here are valid; a case file written before those checks that still holds
an invalid gauge stops the run at start-up with exit code 2.

Each gauge is computed at ``t = 0`` and then at the first step reaching each
multiple of ``computedt`` (default TimeOut; 0 = every step) inside
``computetime start end``; rows are kept every ``outputdt`` (default TimeOut)
inside ``outputtime``.  The new rows are
appended at every output (part) of the run, before its checkpoint, and at the end,
in one write each (the cost of an output does not grow with the rows written
before), as DualSPHysics's JSph::SaveData calls JGaugeSystem::SaveResults; a new run
starts each file anew (header only), a resume cuts it back to the restart time,
atomically.  The two schedules of each gauge (next compute, next kept row: JGaugeItem's
ComputeNext and OutputNext) travel in the checkpoint (:meth:`RunGauges.get_state`), so
that a resumed run keeps the rows an uninterrupted one keeps.  The interpolation,
surface and force code is that of ``sphdvi measure`` (:mod:`.core`).
"""
from __future__ import annotations

import json
import math
import os

import numpy as np

from ..case.gauge_spec import SWL_DEFAULT_COEFDP, mesh_axis, mesh_length, name_problem, zsurf_step
from ..errors import InputError
from ..io.atomic import append_text, complete_lines, write_text_atomic
from . import core

EPS_REL = 1e-12


def _num(d, key, default=None):
    """A number from a raw attribute dict (``{"value": "0.1"}``) or a plain value."""
    v = d.get(key, default) if isinstance(d, dict) else d
    if v is None or (isinstance(v, str) and v.strip().lower() in ("", "none")):
        return default
    return float(v)


class Schedule:
    """Times k*dt (dt = 0: every call) inside [start, end]."""

    def __init__(self, dt, start=0.0, end=math.inf):
        self.dt = float(dt)
        self.start = float(start)
        self.end = float(end)
        self.k = 0

    def eps(self):
        return EPS_REL * max(1.0, self.dt)

    def due(self, t):
        e = self.eps()
        if t < self.start - e or t > self.end + e:
            return False
        if self.dt <= 0:
            return True
        if t >= self.k * self.dt - e:
            self.k = max(self.k + 1, int(math.floor(t / self.dt + 1e-9)) + 1)
            return True
        return False

    def skip_to(self, t):
        """After a resume at time t from a checkpoint without the gauge schedules (an older
        sphdvi's): the next due time is the first multiple after t."""
        if self.dt > 0:
            self.k = int(math.floor(t / self.dt + 1e-9)) + 1


class StateView:
    """One particle state (solver order or case order) and its lazily built fluid grid."""

    def __init__(self, time, pos, vel, rhop, mass, press, ptype, mk, spec, periodicity=None):
        self.time = float(time)
        self.pos, self.vel, self.rhop, self.mass = pos, vel, rhop, mass
        self.press, self.ptype, self.mk = press, ptype, mk
        self.spec = spec
        self.periodicity = periodicity
        self._grid = None

    @property
    def grid(self) -> core.ParticleGrid:
        if self._grid is None:
            self._grid = core.fluid_grid(self.pos, self.vel, self.rhop, self.mass, self.press, self.ptype,
                                         self.spec, self.periodicity)
        return self._grid


def kernel_corrected(values, ksum, kclimit, kcdummy):
    """Kernel-interpolated ``values`` (Shepard-normalised, (P, k)) as DualSPHysics's JGaugeMesh
    writes them: normalised where ``ksum >= kclimit``, ``kcdummy`` below it, the raw sums
    ``values * ksum`` below it when ``kcdummy`` is None, and everywhere when ``kclimit`` is None."""
    raw = np.where(ksum[:, None] > 0, values * ksum[:, None], 0.0)
    if kclimit is None:
        return raw
    below = ksum < kclimit
    out = np.array(values, dtype=np.float64)
    out[below] = raw[below] if kcdummy is None else kcdummy
    return out


# ---------------------------------------------------------------------------------
# gauge kinds
# ---------------------------------------------------------------------------------
class Gauge:
    prefix = ""
    header: tuple = ()

    def __init__(self, item, spec, data):
        self.name = item["name"]
        self.item = item
        self.spec = spec

    def compute(self, view: StateView) -> list:
        raise NotImplementedError

    def filename(self):
        return f"Gauges{self.prefix}_{self.name}.csv"

    def files(self) -> list:
        """[(file name, header columns)]: the row of :meth:`compute` is these files' columns in turn."""
        return [(self.filename(), tuple(self.header))]


class VelocityGauge(Gauge):
    prefix = "Vel"
    header = ("velx [m/s]", "vely [m/s]", "velz [m/s]", "posx [m]", "posy [m]", "posz [m]")

    def __init__(self, item, spec, data):
        super().__init__(item, spec, data)
        self.point = np.asarray(item["point"], float).reshape(1, 3)

    def compute(self, view):
        vel, ksum = core.interpolate(view.grid, self.point, ("vel",), kclimit=None)
        vel = kernel_corrected(vel, ksum, core.DEFAULT_KCLIMIT, 0.0)
        return list(vel[0]) + list(self.point[0])


class SwlGauge(Gauge):
    prefix = "SWL"
    header = ("swlx [m]", "swly [m]", "swlz [m]", "pos0x [m]", "pos0y [m]", "pos0z [m]",
              "pos2x [m]", "pos2y [m]", "pos2z [m]")

    def __init__(self, item, spec, data):
        super().__init__(item, spec, data)
        self.p0 = np.asarray(item["point0"], float).reshape(1, 3)
        self.p2 = np.asarray(item["point2"], float).reshape(1, 3)
        pdp = item.get("pointdp") or {}
        self.step = _num(pdp, "value") or (_num(pdp, "coefdp", SWL_DEFAULT_COEFDP) * spec.dp)
        ml = item.get("masslimit") or {}
        if _num(ml, "value") is not None and spec.massfluid > 0:
            self.limit = _num(ml, "value") / spec.massfluid
        else:
            self.limit = _num(ml, "coef", spec.surface_threshold)

    def compute(self, view):
        s = core.surface_along_lines(view.grid, self.p0, self.p2, self.step, self.limit)
        s = np.where(np.isnan(s), self.p0, s)            # a dry line: its bottom point (JGaugeSwl)
        return list(s[0]) + list(self.p0[0]) + list(self.p2[0])


class MaxZGauge(Gauge):
    """JGaugeMaxZ: the highest fluid particle within ``distlimit`` (horizontal distance) of the
    vertical line from ``point0`` up ``height``.  sphdvi's window is strict, point0.z <= z <=
    point0.z + height, and ``distlimit`` defaults to 1.5 dp; DualSPHysics searches whole cells
    (GetInteractionCellsMaxZ: ceil(distlimit/Scell) cells below point0's cell to as many above
    the cell of point0.z + height), so it also counts fluid up to a cell or more beyond either
    end, and requires ``<distlimit>``.  They differ only where the water comes within a cell
    of the window's ends."""
    prefix = "MaxZ"
    header = ("zmax [m]", "posx [m]", "posy [m]", "posz [m]")

    def __init__(self, item, spec, data):
        super().__init__(item, spec, data)
        self.p0 = np.asarray(item["point0"], float).reshape(1, 3)
        self.height = float(item.get("height", math.inf))
        dl = item.get("distlimit") or {}
        self.radius = (_num(dl, "value") or (_num(dl, "coefh") or 0.0) * spec.h
                       or _num(dl, "coefdp", 1.5) * spec.dp)

    def compute(self, view):
        from . import _kernels as K
        fl = view.ptype == core.FLUID
        out = np.empty(1)
        idx = np.empty(1, np.int64)
        K.column_max_z(self.p0, np.array([self.p0[0, 2] + self.height]),
                       np.ascontiguousarray(view.pos[fl], dtype=np.float64), self.radius, self.spec.is2d, out, idx)
        zmax = out[0] if idx[0] >= 0 else self.p0[0, 2]
        return [zmax, self.p0[0, 0], self.p0[0, 1], self.p0[0, 2]]


class ForceGauge(Gauge):
    prefix = "Force"

    def __init__(self, item, spec, data):
        super().__init__(item, spec, data)
        tgt = item.get("target") or {}
        self.mkbound = int(float(tgt.get("mkbound")))
        fluidcount = int((data["json"].get("mkconfig") or {}).get("fluidcount", 0))
        self.mk = self.mkbound + fluidcount + 1
        u = "N/m" if spec.is2d else "N"
        self.header = (f"force [{u}]", f"forcex [{u}]", f"forcey [{u}]", f"forcez [{u}]")

    def compute(self, view):
        sel = np.flatnonzero((view.mk == self.mk) & (view.ptype != core.FLUID))
        f = core.fluid_forces(view.grid, view.pos[sel], view.vel[sel], view.rhop[sel], view.press[sel],
                              view.mass[sel], self.spec, t=view.time)
        total, _ = core.force_and_moment(view.pos[sel], f)
        return [float(np.sqrt(total @ total))] + list(total)


class MeshGauge(Gauge):
    prefix = "Mesh"
    FILE_KEYS = {"vel": "Vel", "veldir": "VelDir", "rhop": "Rhop", "zsurf": "Zsurf"}

    def __init__(self, item, spec, data):
        super().__init__(item, spec, data)
        self.origin = np.asarray(item.get("point", [0, 0, 0]), float)
        axes, counts, steps = [], [], []
        for k in (1, 2, 3):
            v = np.asarray(item.get(f"vec{k}", [1.0 * (k == 1), 1.0 * (k == 2), 1.0 * (k == 3)]), float)
            nv = np.linalg.norm(v)
            axes.append(v / nv if nv > 0 else np.zeros(3))
            n, d = mesh_axis(item.get(f"size{k}"), spec.dp) if nv > 0 else (1, 0.0)
            counts.append(int(n))
            steps.append(d)
        self.axes, self.counts = axes, counts
        # node (i, j, k) -> row i + j n1 + k n1 n2 (DualSPHysics's order, i fastest)
        kk, jj, ii = np.meshgrid(*(np.arange(c) for c in counts[::-1]), indexing="ij")
        self.nodes = np.ascontiguousarray((self.origin + ii[..., None] * steps[0] * axes[0]
                                           + jj[..., None] * steps[1] * axes[1]
                                           + kk[..., None] * steps[2] * axes[2]).reshape(-1, 3))
        outd = (item.get("outputdata") or {}).get("value") or "vel,rhop"
        self.outputs = list(dict.fromkeys(s.strip().lower() for s in outd.split(",") if s.strip()))
        bad = [s for s in self.outputs if s not in self.FILE_KEYS]
        if bad:
            raise ValueError(f"mesh gauge '{self.name}': unknown outputdata {bad}; expected vel, veldir, rhop, zsurf")
        kc = (item.get("kclimit") or {}).get("value")
        self.kclimit = None if (kc is not None and str(kc).strip().upper() == "NONE") else _num(
            item.get("kclimit") or {}, "value", core.DEFAULT_KCLIMIT)
        kd = (item.get("kcdummy") or {}).get("value")
        self.kcdummy = None if (kd is not None and str(kd).strip().upper() == "NONE") else _num(
            item.get("kcdummy") or {}, "value", 0.0)
        self.dirdat = np.asarray(item.get("dirdat", [1, 0, 0]), float)
        ml = item.get("masslimit") or {}
        if _num(ml, "value") is not None and spec.massfluid > 0:
            self.limit = _num(ml, "value") / spec.massfluid
        else:
            self.limit = _num(ml, "coef", spec.surface_threshold)
        jj, ii = np.meshgrid(np.arange(counts[1]), np.arange(counts[0]), indexing="ij")
        self.col0 = np.ascontiguousarray((self.origin + ii[..., None] * steps[0] * axes[0]
                                          + jj[..., None] * steps[1] * axes[1]).reshape(-1, 3))
        self.col1 = self.col0 + mesh_length(item.get("size3")) * axes[2]
        self.zstep = zsurf_step(item.get("size3"), spec.dp)
        labels = [f"{i}:{j}:{k}" for k in range(counts[2]) for j in range(counts[1]) for i in range(counts[0])]
        cols12 = [f"{i}:{j}" for j in range(counts[1]) for i in range(counts[0])]
        self.parts = []
        for o in self.outputs:
            if o == "vel":
                head = tuple(f"v({n}).{c} [m/s]" for n in labels for c in "xyz")
            elif o == "veldir":
                head = tuple(f"v({n}) [m/s]" for n in labels)
            elif o == "rhop":
                head = tuple(f"v({n}) [kg/m^3]" for n in labels)
            else:
                head = tuple(f"v({n}) [m]" for n in cols12)
            self.parts.append((f"Gauges{self.prefix}_{self.name}_{self.FILE_KEYS[o]}.csv", head))

    def files(self):
        return list(self.parts)

    def compute(self, view):
        vals, ksum = core.interpolate(view.grid, self.nodes, ("vel", "rhop"), kclimit=None)
        vals = kernel_corrected(vals, ksum, self.kclimit, self.kcdummy)
        row = []
        for o in self.outputs:
            if o == "vel":
                row += list(vals[:, :3].reshape(-1))
            elif o == "veldir":
                d = self.dirdat / (np.linalg.norm(self.dirdat) or 1.0)
                row += list(vals[:, :3] @ d)
            elif o == "rhop":
                row += list(vals[:, 3])
            else:
                s = core.surface_along_lines(view.grid, self.col0, self.col1, self.zstep, self.limit)
                s = np.where(np.isnan(s), self.col0, s)        # a dry column: its base (JGaugeMesh)
                row += list(s @ self.axes[2])
        return row


GAUGE_TYPES = {"velocity": VelocityGauge, "swl": SwlGauge, "maxz": MaxZGauge, "force": ForceGauge,
               "mesh": MeshGauge}


# ---------------------------------------------------------------------------------
# the run-time driver
# ---------------------------------------------------------------------------------
class _Slot:
    """A gauge with its schedules, its files and the rows not yet written."""

    def __init__(self, gauge, compute, output, outdir):
        self.gauge, self.compute, self.output = gauge, compute, output
        self.files = [(os.path.join(outdir, name), header) for name, header in gauge.files()]
        self.rows: list = []

    @staticmethod
    def header(columns) -> str:
        return "time [s];" + ";".join(columns) + "\n"

    def pending(self):
        """(path, header, text of the new rows) of each of the gauge's files."""
        out, start = [], 1
        for path, columns in self.files:
            stop = start + len(columns)
            text = "".join(";".join([f"{r[0]:.15g}"] + [_fmt(v) for v in r[start:stop]]) + "\n"
                           for r in self.rows)
            out.append((path, self.header(columns), text))
            start = stop
        return out


def _fmt(v) -> str:
    v = float(v)
    return "" if not math.isfinite(v) else f"{v:.9g}"


def _lines_up_to(path, tmax):
    """The complete data lines of a gauge file with time <= tmax (for a resume)."""
    out = []
    for line in complete_lines(path)[1:]:
        head = line.split(";", 1)[0].strip()
        if head and float(head) <= tmax:
            out.append(line + "\n")
    return out


class RunGauges:
    """Computes the case's gauges during a run at their ``computedt`` (see the module doc)."""

    def __init__(self, data, params, outdir, resume=False, time=0.0, periodicity=None, state=None):
        self.spec = core.KernelSpec.from_case(data, params)
        self.outdir = outdir
        self.periodicity = periodicity
        gauges = data["json"].get("gauges") or {}
        default = gauges.get("default") or {}
        self.tout = float(params.get("TimeOut") or 0.0) or 0.01
        self.slots = []
        for raw in gauges.get("items") or []:
            item = {**default, **raw}
            if item.get("output", False) is not True:
                continue            # DualSPHysics's default: no file; nothing else reads it here
            try:
                problem = name_problem(str(item["name"]))
                if problem:
                    raise ValueError(problem)
                gauge = GAUGE_TYPES[item["type"]](item, self.spec, data)
                cdt = item.get("computedt")
                ct = item.get("computetime") or {}
                compute = Schedule(self.tout if cdt is None else float(cdt), _num(ct, "start", 0.0),
                                   _num(ct, "end", math.inf))
                ot = item.get("outputtime") or {}
                odt = item.get("outputdt")
                output = Schedule(self.tout if odt is None else float(odt), _num(ot, "start", 0.0),
                                  _num(ot, "end", math.inf))
            except (KeyError, ValueError, TypeError, ZeroDivisionError, OverflowError) as exc:
                # only a case file written before gencase checked the gauges gets here
                raise InputError(f"gauge '{item.get('name')}' (case file line {item.get('line')}) is invalid: "
                                 f"{type(exc).__name__}: {exc}; run 'sphdvi gencase' again to see what is "
                                 "wrong with it") from None
            self.slots.append(_Slot(gauge, compute, output, outdir))
        if resume:
            for s in self.slots:
                # the rows up to the restart time stay; anything later (or torn) is cut
                for path, columns in s.files:
                    kept = _lines_up_to(path, time + EPS_REL * max(1.0, time))
                    write_text_atomic(path, s.header(columns) + "".join(kept))
            self.set_state(state, time)
        else:
            for s in self.slots:
                # a new run starts its files anew (an earlier run's rows must not stay above)
                for path, columns in s.files:
                    write_text_atomic(path, s.header(columns))
            p = data["particles"]
            view = StateView(0.0, p["pos"], p["vel"], p["rhop"], p["mass"], self.spec.tait_pressure(p["rhop"]),
                             p["type"], p["mk"], self.spec, periodicity)
            self._measure(view)
            self.flush()

    def _measure(self, view):
        for s in self.slots:
            if s.compute.due(view.time):
                row = s.gauge.compute(view)
                if s.output.due(view.time):
                    s.rows.append([view.time] + [float(v) for v in row])

    def after_step(self, solver):
        """Called after every time step with the SPH solver."""
        t = float(solver.time)
        if not any(s.compute.dt <= 0 or t >= s.compute.k * s.compute.dt - s.compute.eps() for s in self.slots):
            return
        st = solver.state
        view = StateView(t, st.pos, st.vel, st.rhop, st.mass, solver.press, st.ptype, st.mk, self.spec,
                         self.periodicity)
        self._measure(view)

    def get_state(self) -> dict:
        """The schedules of each gauge (its file name -> [compute k, output k]; JGaugeItem's
        ComputeNext and OutputNext), for the checkpoint.  The output schedule only moves when a
        computed row is kept, so it is not a function of the time."""
        return {s.gauge.filename(): [s.compute.k, s.output.k] for s in self.slots}

    def set_state(self, state, time):
        """Restore :meth:`get_state` (a dict, or its JSON) on resume; a gauge the checkpoint has
        no state for (an older sphdvi's) goes on from the first multiples after ``time``."""
        saved = (json.loads(state) if isinstance(state, (str, bytes)) else state) or {}
        for s in self.slots:
            ks = saved.get(s.gauge.filename())
            if ks is None:
                s.compute.skip_to(time)
                s.output.skip_to(time)
            else:
                s.compute.k, s.output.k = int(ks[0]), int(ks[1])

    def flush(self):
        """Append the new rows to the CSV files (header first when a file is new)."""
        for s in self.slots:
            if s.rows:
                for path, header, text in s.pending():
                    if not os.path.exists(path):
                        write_text_atomic(path, header)
                    append_text(path, text)
                s.rows = []

    def close(self):
        """Flush the CSV files."""
        self.flush()

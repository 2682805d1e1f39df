"""Body-only runs: a System from plain structures, the fixed-step output schedule, the
rows of ``bodies.csv`` and ``links.csv`` (as text lines and as arrays).  Nothing here writes
a file: ``sphdvi run`` (:mod:`sphdvi.simulation`) does the I/O.

Inputs are plain Python structures so that a case-file reader can feed them:

* ``bodies``: list of dicts with keys ``name``, ``mass``, ``inertia`` (3 or 3x3,
  about the centre, body frame), ``pos`` (centre), ``quat`` (w,x,y,z), ``vel``,
  ``omega`` (world), ``kind`` ("floating" | "fixed" | "moving"),
  ``translation_dof``, ``rotation_dof``, ``imposed_velocity`` (6 values, None =
  free, or callable t -> 6 values), ``motion`` (callable t -> (v, ω)),
  ``force``, ``torque`` (constant external loads, world) and ``shapes``: a list
  of dicts passed to :meth:`System.add_shape` (``shape``, ``size``, ``pos``,
  ``quat``, ``material``, ``points``, ``radius``, ``local``).  A shape dict
  with ``shape="plane"`` takes ``point`` and ``normal`` (world).
* ``links``: list of dicts with ``kind`` (see :meth:`System.add_link`),
  ``body1``, ``body2`` (names or indices; None/-1 = ground) and the keyword
  arguments of the link.
* ``materials``: list of dicts for :meth:`System.add_material`.
"""
import math

import numpy as np

from ._math import quat_to_euler_deg
from .system import System

BODIES_HEADER = ("time,body,x,y,z,qw,qx,qy,qz,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,"
                 "fx,fy,fz,tx,ty,tz,cfx,cfy,cfz,ctx,cty,ctz,ffx,ffy,ffz,ftx,fty,ftz")
LINKS_HEADER = "time,link,fx,fy,fz,tx,ty,tz"

_BODY_KEYS = ("mass", "inertia", "pos", "quat", "vel", "omega", "kind", "translation_dof",
              "rotation_dof", "motion", "imposed_velocity", "force", "torque", "external_load")


def build_system(bodies, links=(), materials=(), **system_kw):
    """Create a :class:`System` from plain dicts; returns (system, body names)."""
    s = System(**system_kw)
    for m in materials or ():
        s.add_material(**m)
    names = {}
    for i, bd in enumerate(bodies):
        kw = {k: bd[k] for k in _BODY_KEYS if k in bd and bd[k] is not None}
        name = str(bd.get("name", f"body{i}"))
        idx = s.add_body(name=name, **kw)
        names[name] = idx
        for sh in bd.get("shapes", ()):
            sh = dict(sh)
            if sh.get("shape") == "plane":
                s.add_plane(sh.get("point", (0, 0, 0)), sh.get("normal", (0, 0, 1)), body=idx,
                            material=sh.get("material"))
            else:
                s.add_shape(idx, **sh)

    def body_index(v):
        if v is None:
            return -1
        if isinstance(v, str):
            return names[v]
        return int(v)

    for ln in links or ():
        ln = dict(ln)
        kind = ln.pop("kind")
        b1 = body_index(ln.pop("body1", None))
        b2 = body_index(ln.pop("body2", None))
        s.add_link(kind, b1, b2, **ln)
    return s, list(names)


class StepSchedule:
    """The fixed-step schedule of a body-only run: ``nsteps`` steps of ``dt``, an output at the first
    step that reaches each output time and at the last step, the next output time being the first
    one after that step's time (DualSPHysics's ``TimeStep >= TimePartNext`` and
    ``GetNextTime(TimeStep)``, as an SPH run's loop); ``output_times``: an
    :class:`~sphdvi.output_schedule.OutputSchedule` of uneven output times (``<special><timeout>``)
    instead of one every ``tout``.  With TimeOutExtra (``tout_extra``; None: none, 0: every step)
    a row at the first step reaching each multiple of it after the previous row (TimeOutExtraUpdate)."""

    def __init__(self, tmax, tout, dt, tout_extra=None, output_times=None):
        from ..output_schedule import OutputSchedule
        self.dt = float(dt)
        # the steps that reach TimeMax, as an SPH run's (one that ends between two steps takes the
        # next: round() stopped --tmax 1.0125 at 1.012 with dt 1e-3)
        n = tmax / dt
        self.nsteps = int(math.ceil(n - 1e-9 * max(1.0, n)))
        sched = output_times if output_times is not None else OutputSchedule.every(float(tout))
        tol = 1e-9 * max(1.0, sched.smallest)
        self.steps = self._reaching(sched.after(0.0), lambda t: sched.first_after(t, tol))
        self.every_step = tout_extra is not None and float(tout_extra) <= 0.0
        self.extra = None
        if tout_extra is not None and not self.every_step:
            te = float(tout_extra)
            self.extra = self._reaching(te, lambda t: (math.floor(t / te * (1 + 1e-12)) + 1) * te)

    def _reaching(self, t, following):
        """The steps at which the times t, following(step time), ... are first reached."""
        steps = set()
        while True:
            k = max(1, int(math.ceil(t / self.dt - 1e-9 * max(1.0, t / self.dt))))
            if k > self.nsteps:
                return steps
            steps.add(k)
            t = following(k * self.dt)

    def is_output(self, k):
        """Step ``k`` (1-based) ends at an output time."""
        return k in self.steps or k == self.nsteps

    def is_row(self, k):
        """Step ``k`` ends at an output or a TimeOutExtra time."""
        return self.is_output(k) or self.every_step or (self.extra is not None and k in self.extra)


# the columns of bodies.csv after time and body, and of links.csv after time and link
BODY_FIELDS = ("pos", "quat", "euler", "vel", "omega", "force", "torque", "contact_force", "contact_torque",
               "fluid_force", "fluid_torque")
LINK_FIELDS = ("link_force", "link_torque")
RECORD_FIELDS = BODY_FIELDS + LINK_FIELDS


def body_record(s):
    """The arrays of one bodies.csv/links.csv row block: per body ``pos``, ``quat`` (w x y z),
    ``euler`` (roll, pitch, yaw in degrees), ``vel``, ``omega`` (world), ``force``, ``torque``
    (total, about the centre), ``contact_force``, ``contact_torque``, ``fluid_force``,
    ``fluid_torque`` (the fluid's load of the last step, as DualSPHysics's FloatingInfo gives it;
    0 without fluid); per link ``link_force``, ``link_torque`` (reaction on body 1).  Copies."""
    return {"pos": s.pos.copy(), "quat": s.quat.copy(), "euler": quat_to_euler_deg(s.quat),
            "vel": s.vel.copy(), "omega": s.omega_world, "force": s.total_force.copy(),
            "torque": s.total_torque.copy(), "contact_force": s.contact_force.copy(),
            "contact_torque": s.contact_torque.copy(), "fluid_force": s.fluid_force.copy(),
            "fluid_torque": s.fluid_torque.copy(), "link_force": s.link_force.copy(),
            "link_torque": s.link_torque.copy()}


def csv_time(t: float) -> str:
    """The time column of bodies.csv and links.csv (9 significant digits)."""
    return f"{t:.9g}"


def _csv_lines(t, names, record, fields):
    return [f"{csv_time(t)},{nm}," + ",".join(f"{v:.9g}" for v in np.concatenate([record[f][i] for f in fields]))
            + "\n" for i, nm in enumerate(names)]


def csv_rows(s, names):
    """The bodies.csv and links.csv rows (two lists of lines) of the System's current state."""
    record = body_record(s)
    return (_csv_lines(s.time, names, record, BODY_FIELDS),
            _csv_lines(s.time, [rec["name"] for rec in s.links], record, LINK_FIELDS))


class BodyHistory:
    """What :func:`run_bodies` returns: ``system`` (at the end), ``names`` (bodies),
    ``link_names``, ``time`` (nrec,) and one array per :data:`RECORD_FIELDS` entry, shaped
    (nrec, nbodies, 3|4) or (nrec, nlinks, 3), at the same times as the rows of bodies.csv."""

    def __init__(self, system, names, time, records):
        self.system = system
        self.names = list(names)
        self.link_names = [rec["name"] for rec in system.links]
        self.time = np.asarray(time, float)
        for field in RECORD_FIELDS:
            setattr(self, field, np.stack([r[field] for r in records]))


def run_bodies(bodies, links=(), tmax=1.0, tout=0.01, dt=1e-3, materials=(), forces=None,
               tout_extra=None, **system_kw):
    """Run a body-only simulation in memory and return a :class:`BodyHistory`: the state at
    every output time, t = 0 included (and with ``tout_extra``, DualSPHysics's TimeOutExtra,
    at its multiples in between, 0 meaning every step): the rows ``sphdvi run`` writes to
    bodies.csv and links.csv.  ``forces``: optional callable (system) -> (F, T) arrays
    (nb, 3) applied each step.  Extra keywords go to :class:`System` (gravity, solver,
    max_iter, tol, recovery_speed, envelope, contactmethod, ...).  Writes no file (the
    files of a body-only run are written by ``sphdvi run``, :mod:`sphdvi.simulation`)."""
    s, names = build_system(bodies, links, materials, **system_kw)
    if not s._packed:
        s._pack()
    schedule = StepSchedule(tmax, tout, dt, tout_extra)
    times, records = [s.time], [body_record(s)]
    for k in range(1, schedule.nsteps + 1):
        F = T = None
        if forces is not None:
            F, T = forces(s)
        s.step(dt, F, T)
        if schedule.is_row(k):
            times.append(s.time)
            records.append(body_record(s))
    return BodyHistory(s, names, times, records)

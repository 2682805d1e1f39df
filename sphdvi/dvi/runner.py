"""Body-only simulation runner writing ``bodies.csv`` and ``links.csv``.

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
import os

import numpy as np

from ._math import quat_to_euler_deg
from .system import System

BODIES_HEADER = ("time,body,x,y,z,qw,qx,qy,qz,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,"
                 "fx,fy,fz,tx,ty,tz,cfx,cfy,cfz,ctx,cty,ctz")
LINKS_HEADER = "time,link,fx,fy,fz,tx,ty,tz"

_BODY_KEYS = ("mass", "inertia", "pos", "quat", "vel", "omega", "kind", "translation_dof",
              "rotation_dof", "motion", "imposed_velocity", "force", "torque")


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


def _write_atomic(path, header, rows, fmt="%.9g"):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(header + "\n")
        for r in rows:
            f.write(r)
    os.replace(tmp, path)


def _body_lines(s, names):
    t = s.time
    eul = quat_to_euler_deg(s.quat)
    w = s.omega_world
    out = []
    for i, nm in enumerate(names):
        vals = np.concatenate([s.pos[i], s.quat[i], eul[i], s.vel[i], w[i], s.total_force[i],
                               s.total_torque[i], s.contact_force[i], s.contact_torque[i]])
        out.append(f"{t:.9g},{nm}," + ",".join(f"{v:.9g}" for v in vals) + "\n")
    return out


def _link_lines(s):
    t = s.time
    out = []
    for l, rec in enumerate(s.links):
        vals = np.concatenate([s.link_force[l], s.link_torque[l]])
        out.append(f"{t:.9g},{rec['name']}," + ",".join(f"{v:.9g}" for v in vals) + "\n")
    return out


def run_bodies(bodies, links=(), out_dir=".", tmax=1.0, tout=0.01, dt=1e-3, materials=(),
               forces=None, flush_every=200, tout_extra=None, **system_kw):
    """Run a body-only simulation and write ``out_dir/bodies.csv`` and
    ``out_dir/links.csv`` (one row per body/link per output time, including
    t = 0; with ``tout_extra`` (DualSPHysics's TimeOutExtra) also at its
    multiples in between, 0 meaning every step).  ``forces``: optional
    callable (system) -> (F, T) arrays (nb, 3)
    applied each step.  Extra keywords go to :class:`System` (gravity,
    solver, max_iter, tol, recovery_speed, envelope, contactmethod, ...).
    Returns the system at the end."""
    os.makedirs(out_dir, exist_ok=True)
    s, names = build_system(bodies, links, materials, **system_kw)
    if not s._packed:
        s._pack()
    nb_path = os.path.join(out_dir, "bodies.csv")
    nl_path = os.path.join(out_dir, "links.csv")
    brows = _body_lines(s, names)
    lrows = _link_lines(s)
    nsteps = int(round(tmax / dt))
    every = max(1, int(round(tout / dt)))
    extra = every if tout_extra is None else max(1, int(round(tout_extra / dt)))
    nout = 0
    for k in range(1, nsteps + 1):
        F = T = None
        if forces is not None:
            F, T = forces(s)
        s.step(dt, F, T)
        if k % every == 0 or k % extra == 0 or k == nsteps:
            brows += _body_lines(s, names)
            lrows += _link_lines(s)
            nout += 1
            if nout % flush_every == 0:
                _write_atomic(nb_path, BODIES_HEADER, brows)
                _write_atomic(nl_path, LINKS_HEADER, lrows)
    _write_atomic(nb_path, BODIES_HEADER, brows)
    _write_atomic(nl_path, LINKS_HEADER, lrows)
    return s

"""Coupling of the fluid with the solids that move its boundary particles.

Two kinds, as in DualSPHysics:

* :class:`ImposedMotions`: boundary particles of type 1 follow the rigid motion of
  their mk (``<motion>``, wave paddles), evaluated at each step end (JSph's
  ``CalcMotion`` / ``MoveLinBound`` / ``MoveMatBound``);
* :class:`FloatingBodies`: floating particles (type 2) move with rigid bodies that
  the multibody engine (``sphdvi.dvi``, the Chrono NSC DVI) integrates, driven by
  the force and moment the fluid exerts on the bodies' particles,
  F = sum m_k a_k and T = sum (r_k - R) x m_k a_k (DualSPHysics's ``FtPartsSumAce``
  and ``FtComputeAceVel``, Canelas et al. 2018; a floating particle's a_k has no
  gravity: the multibody system adds m g to each body); the particles then take the
  body's rigid-body motion, v_k = V + Omega x (r_k - R) (``FtPartsUpdate``), their
  positions by the exact rigid transform of their body-frame offsets rather than by
  dt times their old velocity.

The fluid side is the solver's arrays; nothing here writes files.
"""
from __future__ import annotations

import numpy as np


def quat_matrix(q) -> np.ndarray:
    """Rotation matrix of the unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def body_labels(mk: np.ndarray, fluidcount: int) -> np.ndarray:
    """GenCase's mkbound of boundary and floating particles (mk - fluidcount - 1)."""
    return mk.astype(np.int64) - fluidcount - 1


class ImposedMotions:
    """Boundary particles moved by their mk's imposed motion: each moving particle at
    ``motion(t)`` applied to its initial position (by idp), its velocity the motion's;
    mDBC normals turn with it."""

    def __init__(self, motions, pos0: np.ndarray, fluidcount: int, normals0: np.ndarray | None = None):
        self.motions = motions
        self.pos0 = pos0                    # initial positions, indexed by idp
        self.fluidcount = fluidcount
        self.normals0 = normals0            # initial mDBC normals, indexed by idp

    def apply(self, solver, t: float) -> None:
        """Place the moving particles (type 1) at time ``t``."""
        s = solver.state
        sel = np.flatnonzero(s.ptype == 1)
        label = body_labels(s.mk[sel], self.fluidcount)
        for mkb in np.unique(label):
            rows = sel[label == mkb]
            rig = self.motions.transform(int(mkb), t)
            x, v = rig.apply(self.pos0[s.idp[rows]])
            s.pos[rows] = x
            s.vel[rows] = v
            if self.normals0 is not None:
                solver.normals[rows] = self.normals0[s.idp[rows]] @ rig.R.T


class FloatingBodies:
    """The floating bodies of a case: a multibody System (``system``, its bodies named
    ``names``) and, per body, its particles' idp and body-frame offsets.

    ``ftpause``: DualSPHysics's FtPause, the time during which the bodies stay frozen
    (their clock runs; the fluid still acts on their particles, which do not move)."""

    def __init__(self, data: dict, motions, fluidcount: int, normals0: np.ndarray | None = None,
                 ftpause: float = 0.0):
        from .dvi.runner import build_system
        from .mechanism import mechanism_from_case
        mech = mechanism_from_case(data, motions)
        self.system, self.names = build_system(mech["bodies"], mech["links"], mech["materials"],
                                               **mech["system"])
        self.mkbounds = [int(m) for m in mech["mkbounds"]]
        self.is2d = bool(data["constants"]["is2d"])
        self.normals0 = normals0
        self.ftpause = float(ftpause)
        p = data["particles"]
        label = body_labels(p["mk"], fluidcount)
        self.particles = []         # per body: idp (sorted) of its particles, body-frame offsets
        for i, mkb in enumerate(mech["mkbounds"]):
            idp = p["idp"][(p["type"] != 3) & (label == mkb)]
            local = (p["pos"][idp] - self.system.pos[i]) @ quat_matrix(self.system.quat[i])
            self.particles.append((idp, local))
        self.R0 = [quat_matrix(q) for q in self.system.quat]
        self.body_of_idp = np.full(p["idp"].size, -1, np.int64)
        for i, (idp, _) in enumerate(self.particles):
            self.body_of_idp[idp] = i

    def loads(self, solver, sel: np.ndarray, body: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Force and moment about each body's centre of the accelerations of its particles
        (``sel``: rows of the floating particles, ``body``: their body): the fluid's alone
        (gravity is the multibody system's), in 2D restricted to the x-z plane."""
        s = solver.state
        nb = self.system.nb
        f = s.mass[sel, None] * solver.ace[sel]
        F = np.zeros((nb, 3))
        T = np.zeros((nb, 3))
        np.add.at(F, body, f)
        np.add.at(T, body, np.cross(s.pos[sel] - self.system.pos[body], f))
        if self.is2d:
            F[:, 1] = 0.0
            T[:, 0] = T[:, 2] = 0.0
        return F, T

    def step(self, solver, dt: float) -> None:
        """Advance the bodies by ``dt`` under this step's loads and carry their particles
        (``solver.ace`` holds this step's accelerations; a floating particle's has no gravity)."""
        s = solver.state
        sel = np.flatnonzero(s.ptype == 2)
        body = self.body_of_idp[s.idp[sel]]
        F, T = self.loads(solver, sel, body)
        if solver.time <= self.ftpause:
            self.system.time = solver.time     # frozen bodies (FtPause): the clock still runs
            return
        self.system.step(dt, F, T)
        self.carry_particles(solver, sel, body)

    def carry_particles(self, solver, sel: np.ndarray, body: np.ndarray) -> None:
        """Rigid-body position and velocity of each floating particle (and its mDBC normal)."""
        s = solver.state
        sys_ = self.system
        pos, quat, vel, omega = sys_.pos, sys_.quat, sys_.vel, sys_.omega_world
        for i, (idp, local) in enumerate(self.particles):
            rows = sel[body == i]
            if rows.size == 0:
                continue
            R = quat_matrix(quat[i])
            x = pos[i] + local[np.searchsorted(idp, s.idp[rows])] @ R.T
            s.pos[rows] = x
            s.vel[rows] = vel[i] + np.cross(omega[i], x - pos[i])
            if self.normals0 is not None:
                solver.normals[rows] = self.normals0[s.idp[rows]] @ (R @ self.R0[i].T).T

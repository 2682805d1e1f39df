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
  dt times their old velocity.  With Symplectic, as DualSPHysics's ComputeStep_Sym, the
  bodies first go to the half step under the predictor's loads (their particles there for
  the corrector's interaction; the multibody state then put back) and then by the whole step
  from the step's start under the corrector's loads (:meth:`FloatingBodies.predict`,
  :meth:`FloatingBodies.step`); mDBC normals turn with the body at the half step too
  (DualSPHysics keeps them at t^n until the corrector's update).  With periodic boundaries the particles are kept in
  the periodic box while the body's centre is not wrapped: r_k - R is taken as its
  shortest periodic image (DualSPHysics's FtPeriodicDist).

The fluid side is the solver's arrays; nothing here writes files.
"""
from __future__ import annotations

import warnings

import numpy as np

from .sph import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit

from .errors import DivergenceError
from .sph.clock import time_reached


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

    def apply(self, solver, t: float, dt: float | None = None) -> None:
        """Place the moving particles (type 1) at time ``t``, the end of a step of ``dt``.

        Their velocity is the step's displacement over dt, as DualSPHysics's MoveLinBound (the
        translation over dt, JMotionList::Sp_Movedt) and MoveMatBound ((new - old position)/dt):
        not the motion's velocity at t (they differ by O(dt), and in the step where a movement
        ends or flashes).  In 2D the particles keep their y (DualSPHysics's JDsMotion::ProcesTime
        zeroes a translation's y, MoveMatBound keeps y under a matrix).  Without ``dt`` (a placement
        outside the time loop) the velocity is the motion's at t."""
        s = solver.state
        sel = np.flatnonzero(s.ptype == 1)
        label = body_labels(s.mk[sel], self.fluidcount)
        flat = bool(getattr(solver, "is2d", False))
        per = getattr(solver, "periodicity", None)
        for mkb in np.unique(label):
            rows = sel[label == mkb]
            rig = self.motions.transform(int(mkb), t)
            x0 = self.pos0[s.idp[rows]]
            x, v = rig.apply(x0)
            if flat:
                x[:, 1] = x0[:, 1]
                v[:, 1] = 0.0
            if dt:
                step = x - s.pos[rows]
                if per is not None:
                    per.min_image(step)      # a particle the periodic box wrapped in between
                v = step / dt
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
        self.scale = np.asarray(mech.get("scaleforce", np.ones((len(self.mkbounds), 3))), float)
        if not self.is2d and np.any(self.scale != 1.0):
            warnings.warn("<chrono><scaleforce> should be used only for 2D simulations (as DualSPHysics warns); "
                          "this case is 3D")
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
        self.local_of_idp = np.zeros((p["idp"].size, 3))     # body-frame offset of each floating idp
        for i, (idp, local) in enumerate(self.particles):
            self.body_of_idp[idp] = i
            self.local_of_idp[idp] = local
        self._R0 = np.array(self.R0).reshape(-1, 3, 3)
        self._sel = np.empty(p["idp"].size, np.int64)     # rows and bodies of the floating particles,
        self._body = np.empty(p["idp"].size, np.int64)    # refilled each call (the solver reorders)

    def rows(self, solver):
        """(rows of the floating particles in the solver's order, their body): views of work
        arrays that the next call overwrites."""
        s = solver.state
        if self._sel.size < s.n:
            self._sel = np.empty(s.n, np.int64)
            self._body = np.empty(s.n, np.int64)
        k = _floating_rows(s.ptype, s.idp, self.body_of_idp, self._sel, self._body)
        return self._sel[:k], self._body[:k]

    def loads(self, solver, sel: np.ndarray, body: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Force and moment about each body's centre of the accelerations of its particles
        (``sel``: rows of the floating particles, ``body``: their body): the fluid's alone
        (gravity is the multibody system's), in 2D restricted to the x-z plane.

        ``<scaleforce>`` (DualSPHysics's JChBody::SetScaleForce, per body and axis) multiplies
        the fluid's force. Confirmed from DualSPHysics's public source: the factors are read per
        mkbound (ranges) and handed to its Chrono library with the body, with a warning in 3D.
        Not confirmed (the library's source is closed): whether the moment is scaled too and
        whether the gravity part of the acceleration DualSPHysics sends is; sphdvi scales the
        fluid's force only (the moment, gravity and ``<linearforce>`` are not scaled)."""
        s = solver.state
        nb = self.system.nb
        F = np.zeros((nb, 3))
        T = np.zeros((nb, 3))
        # the body's particles are wrapped at the periodic ends, its centre is not: the lever
        # arm is the shortest periodic image (DualSPHysics's FtPeriodicDist)
        bad = _sum_loads(sel, body, s.mass, solver.ace, s.pos, self.system.pos,
                         *_periodic_args(getattr(solver, "periodicity", None)), F, T)
        if bad >= 0:
            raise RuntimeError(f"floating particle idp {int(s.idp[sel[bad]])} belongs to no multibody body")
        if self.is2d:
            F[:, 1] = 0.0
            T[:, 0] = T[:, 2] = 0.0
        F *= self.scale
        return F, T

    def paused(self, t_start: float) -> bool:
        """FtPause holds the bodies in a step that starts before it (DualSPHysics's RunFloating:
        ``ftpaused = TimeStep < FtPause``, TimeStep the step's start time; to round-off)."""
        return not time_reached(t_start, self.ftpause)

    def step(self, solver, dt: float) -> None:
        """Advance the bodies by ``dt`` under this step's loads and carry their particles
        (``solver.ace`` holds this step's accelerations; a floating particle's has no gravity;
        ``solver.time`` is the step's end).  With Symplectic the step starts again from the
        state :meth:`predict` left the bodies in, the one at the step's start."""
        sel, body = self.rows(solver)
        F, T = self.loads(solver, sel, body)
        if self.paused(solver.time - dt):
            self.system.time = solver.time     # frozen bodies (FtPause): the clock still runs
            self.hold(F, T)
            return
        self.system.step(dt, F, T)
        self.carry_particles(solver, sel, body)
        self.check_in_domain(solver, sel, body)

    def predict(self, solver, dt_half: float) -> None:
        """Symplectic predictor (DualSPHysics's ComputeStep_Sym: RunFloating(dt/2, predictor)):
        the bodies advance by ``dt_half`` under the predictor's loads and carry their particles
        there, for the corrector's interaction; the multibody state is then put back
        (System.get_state / set_state), so that :meth:`step` advances from the step's start
        with the corrector's loads.  ``solver.time`` is the step's start."""
        if self.paused(solver.time):
            return
        sel, body = self.rows(solver)
        F, T = self.loads(solver, sel, body)
        saved = self.system.get_state()
        self.system.step(dt_half, F, T)
        self.carry_particles(solver, sel, body)
        self.system.set_state(saved)

    def hold(self, F: np.ndarray, T: np.ndarray) -> None:
        """During FtPause, the loads on each held floating body for bodies.csv: its weight plus
        the fluid's force (``F``) as total_force, the fluid's moment (``T``, the torque columns),
        as DualSPHysics keeps computing them for its output while paused."""
        from .dvi.system import FLOATING
        sys_ = self.system
        fl = (sys_.kind == FLOATING)[:, None]
        sys_.total_force = np.where(fl, F + sys_.mass[:, None] * sys_.gravity[None, :], sys_.total_force)
        sys_.total_torque = np.where(fl, T, sys_.total_torque)

    def check_in_domain(self, solver, sel: np.ndarray, body: np.ndarray) -> None:
        """Stop the run (DivergenceError, exit 3) when a floating particle has left the simulation
        domain, naming the body, the time and the position: DualSPHysics excludes such a
        particle and aborts (JSph::AbortBoundOut, "Fixed, moving or floating particles were
        excluded")."""
        dom = getattr(solver, "_domain", None)
        if dom is None or sel.size == 0:
            return
        k = _first_outside(solver.state.pos, sel, dom[0], dom[1])
        if k < 0:
            return
        pos = solver.state.pos[sel]
        out = np.any((pos < dom[0]) | (pos > dom[1]), axis=1)
        i = int(body[k])
        nout = int(np.count_nonzero(out & (body == i)))
        fmt = lambda v: "(" + ", ".join(f"{float(x):.5g}" for x in v) + ")"     # noqa: E731
        raise DivergenceError(
            f"t={solver.time:.6g} s, step {solver.nstep}: floating body mkbound {self.mkbounds[i]} "
            f"('{self.names[i]}', centre {fmt(self.system.pos[i])}) left the simulation domain: its particle "
            f"{int(solver.state.idp[sel[k]])} is at {fmt(pos[k])}, outside {fmt(dom[0])} - {fmt(dom[1])} "
            f"({nout} of its particles out); DualSPHysics stops too (\"Fixed, moving or floating particles "
            f"were excluded\"); check the body's loads and contacts (RigidAlgorithm 1: the walls hold it through "
            f"the SPH terms; 0: it meets no wall) or enlarge the domain")

    def carry_particles(self, solver, sel: np.ndarray, body: np.ndarray) -> None:
        """Rigid-body position and velocity of each floating particle (and its mDBC normal), in
        the periodic box (as the fluid) with periodic boundaries: one compiled loop."""
        s = solver.state
        sys_ = self.system
        normals = self.normals0 is not None
        _carry(sel, body, s.idp, self.local_of_idp, sys_.pos, sys_.quat, sys_.vel, sys_.omega_world,
               *_periodic_args(getattr(solver, "periodicity", None)), s.pos, s.vel, normals,
               self.normals0 if normals else _NO_NORMALS, self._R0, solver.normals if normals else _NO_NORMALS)


# ---------------------------------------------------------------------------------
# compiled per-step bookkeeping of the floating particles
# ---------------------------------------------------------------------------------
_NO_NORMALS = np.zeros((0, 3))
_NO_AXES = (np.zeros(0, np.int64), np.zeros(3), np.zeros(3), np.zeros((3, 3)))


def _periodic_args(per) -> tuple:
    """(axes, lo, length, shift) of a Periodicity for the kernels (no axes without one)."""
    if per is None:
        return _NO_AXES
    return np.asarray(per.axes, np.int64), per.lo, per.length, per.shift


@njit(cache=True)
def _floating_rows(ptype, idp, body_of_idp, sel, body) -> int:
    """Rows of the floating particles (type 2) in order and their body; returns their number."""
    k = 0
    for i in range(ptype.shape[0]):
        if ptype[i] == 2:
            sel[k] = i
            body[k] = body_of_idp[idp[i]]
            k += 1
    return k


@njit(cache=True)
def _min_image(r, axes, length, shift):
    """Periodicity.min_image of one separation (DualSPHysics's FtPeriodicDist), in place."""
    for a in range(axes.shape[0]):
        k = axes[a]
        n = np.rint(r[k] / length[k])
        if n != 0.0:
            for j in range(3):
                r[j] -= n * shift[k, j]


@njit(cache=True)
def _sum_loads(sel, body, mass, ace, pos, centre, axes, lo, length, shift, F, T) -> int:
    """F += m_k a_k and T += (r_k - R) x m_k a_k per body, in the particles' order
    (DualSPHysics's FtPartsSumAce); returns the first index of ``sel`` without a body, or -1."""
    for j in range(sel.shape[0]):
        if body[j] < 0:
            return j
    arm = np.empty(3)
    for j in range(sel.shape[0]):
        i = sel[j]
        b = body[j]
        fx, fy, fz = mass[i] * ace[i, 0], mass[i] * ace[i, 1], mass[i] * ace[i, 2]
        F[b, 0] += fx
        F[b, 1] += fy
        F[b, 2] += fz
        for c in range(3):
            arm[c] = pos[i, c] - centre[b, c]
        _min_image(arm, axes, length, shift)
        T[b, 0] += arm[1] * fz - arm[2] * fy
        T[b, 1] += arm[2] * fx - arm[0] * fz
        T[b, 2] += arm[0] * fy - arm[1] * fx
    return -1


@njit(cache=True)
def _quat_matrix(q, R):
    """quat_matrix into R."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    R[0, 0], R[0, 1], R[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
    R[1, 0], R[1, 1], R[1, 2] = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    R[2, 0], R[2, 1], R[2, 2] = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)


@njit(cache=True)
def _carry(sel, body, idp, local_of_idp, bpos, quat, bvel, omega, axes, lo, length, shift, pos, vel,
           normals_on, normals0, R0, normals):
    """Each floating particle at its body's rigid transform of its body-frame offset, its velocity
    V + Omega x (r - R) (DualSPHysics's FtPartsUpdate), then wrapped into the periodic box as
    JSphCpu::UpdatePos; its mDBC normal turned by R R0^T."""
    nb = bpos.shape[0]
    R = np.empty((nb, 3, 3))
    M = np.empty((nb, 3, 3))
    for b in range(nb):
        _quat_matrix(quat[b], R[b])
        for r in range(3):
            for c in range(3):
                M[b, r, c] = R[b, r, 0] * R0[b, c, 0] + R[b, r, 1] * R0[b, c, 1] + R[b, r, 2] * R0[b, c, 2]
    x = np.empty(3)
    for j in range(sel.shape[0]):
        i = sel[j]
        b = body[j]
        loc = local_of_idp[idp[i]]
        for r in range(3):
            x[r] = bpos[b, r] + (loc[0] * R[b, r, 0] + loc[1] * R[b, r, 1] + loc[2] * R[b, r, 2])
        dx, dy, dz = x[0] - bpos[b, 0], x[1] - bpos[b, 1], x[2] - bpos[b, 2]
        vel[i, 0] = bvel[b, 0] + (omega[b, 1] * dz - omega[b, 2] * dy)
        vel[i, 1] = bvel[b, 1] + (omega[b, 2] * dx - omega[b, 0] * dz)
        vel[i, 2] = bvel[b, 2] + (omega[b, 0] * dy - omega[b, 1] * dx)
        for a in range(axes.shape[0]):
            k = axes[a]
            below = x[k] < lo[k]
            above = x[k] >= lo[k] + length[k]
            if below:
                for c in range(3):
                    x[c] += shift[k, c]
            if above:
                for c in range(3):
                    x[c] -= shift[k, c]
        for c in range(3):
            pos[i, c] = x[c]
        if normals_on:
            n0 = normals0[idp[i]]
            for r in range(3):
                normals[i, r] = n0[0] * M[b, r, 0] + n0[1] * M[b, r, 1] + n0[2] * M[b, r, 2]


@njit(cache=True)
def _first_outside(pos, sel, lo, hi) -> int:
    """The first index of ``sel`` whose particle is outside [lo, hi], or -1."""
    for j in range(sel.shape[0]):
        i = sel[j]
        for c in range(3):
            if pos[i, c] < lo[c] or pos[i, c] > hi[c]:
                return j
    return -1


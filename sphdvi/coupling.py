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
  the periodic box and so is a free body's centre after each whole step (DualSPHysics's FtUpdateFloatings:
  ``center = UpdatePeriodicPos(fcenter)``); r_k - R is taken as its shortest periodic image
  (DualSPHysics's FtPeriodicDist).  A body with links or a collision shape is integrated, as
  DualSPHysics's Chrono integrates it, without the periodic conditions: its crossing a periodic
  boundary stops the run (InputError, exit 2) rather than let its contacts and links act on the
  wrong image (:meth:`FloatingBodies.wrap_centres`).

The fluid side is the solver's arrays; nothing here writes files.
"""
from __future__ import annotations

import warnings

import numpy as np

from .sph import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit

from .errors import DivergenceError, InputError
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


_NO_BOX = (np.full(3, -np.inf), np.full(3, np.inf))


@njit(cache=True)
def place_moving(ptype, idp, pos, vel, normals, slot, group, active, x, y0, nrm, V, W, c, dt, flat,
                 paxes, plen, pshift, lo, hi):
    """Put each moving particle (type 1, its slot by idp) of an ``active`` mkbound at ``x`` (its
    motion applied to its initial position; in 2D its y kept, ``y0``'s) with the velocity
    (new − old position)/dt - DualSPHysics's MoveLinBound/MoveMatBound - the step taken as its
    shortest periodic image along ``paxes`` (Periodicity.min_image); ``dt`` 0: the motion's
    velocity V + W × (x − c) of its mkbound.  Turned mDBC normals ``nrm`` where ``normals`` has
    rows.  Returns the number of moving rows found (all the slots when the map is current) and
    the first row it placed outside the box [lo, hi] (the simulation domain), or -1."""
    found = 0
    first_out = -1
    has_normals = normals.shape[0] == pos.shape[0]
    step = np.empty(3)
    for r in range(ptype.shape[0]):
        if ptype[r] != 1:
            continue
        k = slot[idp[r]]
        if k < 0:
            continue
        found += 1
        g = group[k]
        if not active[g]:
            continue
        p0 = x[k, 0]
        p1 = x[k, 1]
        p2 = x[k, 2]
        if dt > 0.0:
            if flat:
                p1 = y0[k, 1]
            step[0] = p0 - pos[r, 0]
            step[1] = p1 - pos[r, 1]
            step[2] = p2 - pos[r, 2]
            _min_image(step, paxes, plen, pshift)   # a particle the periodic box wrapped in between
            v0 = step[0] / dt
            v1 = step[1] / dt
            v2 = step[2] / dt
        else:
            t0 = p0 - c[g, 0]
            t1 = p1 - c[g, 1]
            t2 = p2 - c[g, 2]
            v0 = V[g, 0] + (W[g, 1] * t2 - W[g, 2] * t1)
            v1 = V[g, 1] + (W[g, 2] * t0 - W[g, 0] * t2)
            v2 = V[g, 2] + (W[g, 0] * t1 - W[g, 1] * t0)
            if flat:
                p1 = y0[k, 1]
                v1 = 0.0
        if first_out < 0 and (p0 < lo[0] or p0 > hi[0] or p1 < lo[1] or p1 > hi[1] or p2 < lo[2] or p2 > hi[2]):
            first_out = r
        pos[r, 0] = p0
        pos[r, 1] = p1
        pos[r, 2] = p2
        vel[r, 0] = v0
        vel[r, 1] = v1
        vel[r, 2] = v2
        if has_normals:
            normals[r, 0] = nrm[k, 0]
            normals[r, 1] = nrm[k, 1]
            normals[r, 2] = nrm[k, 2]
    return found, first_out


class ImposedMotions:
    """Boundary particles moved by their mk's imposed motion: each moving particle at
    ``motion(t)`` applied to its initial position (by idp), its velocity the motion's;
    mDBC normals turn with it.

    The moving particles are grouped once by mkbound in idp order (``_build``): each step
    turns each mkbound's initial positions (and normals) as a block and :func:`place_moving`
    writes them to the rows where the solver's cell order has put them (by idp).  An mkbound
    placed twice in a row at the same R and d (at rest: before its motion starts, after it
    ends, a null movement) is left as it is from then on, its particles already there with zero
    velocity (not with periodic boundaries, whose wrap moves them, nor in a placement without dt)."""

    def __init__(self, motions, pos0: np.ndarray, fluidcount: int, normals0: np.ndarray | None = None,
                 skip_mkbounds=()):
        self.motions = motions
        self.skip_mkbounds = np.asarray(list(skip_mkbounds), np.int64)   # moved otherwise (flexible structures)
        self.pos0 = pos0                    # initial positions, indexed by idp
        self.fluidcount = fluidcount
        self.normals0 = normals0            # initial mDBC normals, indexed by idp
        self._slot = None                   # the moving particles' slot by idp (built at the first call)
        self._batch = None                  # the compiled pass's plans (sphdvi.motion_batch, _build)
        self.first_outside = -1             # the first moving row placed outside the domain (apply), or -1

    def _build(self, s) -> None:
        """Group the moving particles by mkbound, in idp order: slot of each idp, mkbound of each
        slot, their initial positions (and normals) by mkbound, and the work arrays."""
        sel = np.flatnonzero(s.ptype == 1)
        if self.skip_mkbounds.size:
            sel = sel[~np.isin(body_labels(s.mk[sel], self.fluidcount), self.skip_mkbounds)]
        idp = s.idp[sel].astype(np.int64)
        label = body_labels(s.mk[sel], self.fluidcount)
        order = np.lexsort((idp, label))
        idp, label = idp[order], label[order]
        mkbs, starts = np.unique(label, return_index=True)
        self.mkbounds = [int(m) for m in mkbs]
        self._bounds = list(zip(starts.tolist(), np.append(starts[1:], idp.size).tolist()))
        self._slot = np.full(max(self.pos0.shape[0], int(idp.max(initial=-1)) + 1), -1, np.int64)
        self._slot[idp] = np.arange(idp.size)
        self._count = idp.size
        self._group = np.repeat(np.arange(mkbs.size), np.diff(np.append(starts, idp.size)))
        self._x0 = [self.pos0[idp[a:b]] for a, b in self._bounds]
        self._y0 = self.pos0[idp]                   # (their y, kept in 2D)
        self._x0all = self._y0 + 0.0                # (x0 @ I: a zero's sign as the product's)
        self._x = np.empty((idp.size, 3))
        self._vwc = np.zeros((3, mkbs.size, 3))
        self._active = np.ones(mkbs.size, np.bool_)
        self._last = [None] * mkbs.size             # the placement each mkbound was last put at
        self._rest = [False] * mkbs.size            # ... and left at rest there
        # the same as bits of (R, d) for those the compiled pass may place (MotionBatch.eligible)
        self._last_R = np.zeros((mkbs.size, 9), np.int64)
        self._last_d = np.zeros((mkbs.size, 3), np.int64)
        self._has_last = np.zeros(mkbs.size, np.bool_)
        self._rest_fast = np.zeros(mkbs.size, np.bool_)
        self._first = np.asarray([a for a, _ in self._bounds], np.int64)
        self._end = np.asarray([b for _, b in self._bounds], np.int64)
        # the translations evaluated in one compiled pass (sphdvi.motion_batch), the rest by their walk
        from .motion_batch import MotionBatch
        if self._batch is not None:
            self._batch.sync()                      # grouped again: the walks go on from where it left them
        self._batch = (MotionBatch(self.motions, self.mkbounds)
                       if getattr(self.motions, "_walks", None) is not None else None)
        if self._batch is not None and not any(self._batch.eligible):
            self._batch = None                      # (wave paddles, rotations: one by one)
        if self.normals0 is not None:
            self._n0 = [self.normals0[idp[a:b]] for a, b in self._bounds]
            self._n0all = self.normals0[idp] + 0.0
            self._n = np.empty((idp.size, 3))
        else:
            self._n = np.zeros((0, 3))

    def apply(self, solver, t: float, dt: float | None = None) -> None:
        """Place the moving particles (type 1) at time ``t``, the end of a step of ``dt``.

        Their velocity is the step's displacement over dt, as DualSPHysics's MoveLinBound (the
        translation over dt, JMotionList::Sp_Movedt) and MoveMatBound ((new - old position)/dt):
        not the motion's velocity at t (they differ by O(dt), and in the step where a movement
        ends or flashes).  In 2D the particles keep their y (DualSPHysics's JDsMotion::ProcesTime
        zeroes a translation's y, MoveMatBound keeps y under a matrix).  Without ``dt`` (a placement
        outside the time loop) the velocity is the motion's at t."""
        s = solver.state
        if self._slot is None:
            self._build(s)
        per = getattr(solver, "periodicity", None)
        normals = solver.normals if self.normals0 is not None else self._n
        flat = bool(getattr(solver, "is2d", False))
        dom = getattr(solver, "_domain", None)
        box = _NO_BOX if dom is None else (np.asarray(dom[0], float), np.asarray(dom[1], float))
        found, self.first_outside = self._place(s, t, dt, per, normals, flat, box)
        if found != self._count:
            self._build(s)                          # the moving particles changed: group them again
            _, self.first_outside = self._place(s, t, dt, per, normals, flat, box)

    def _still(self, g: int, rig, dt, still_test: bool) -> bool:
        """The at-rest test of an mkbound the compiled pass may place (its last placement kept as
        bits, :func:`sphdvi.motion_batch.place_translations`'s): False when it is left where it is."""
        same = (self._has_last[g] and rig.R.tobytes() == self._last_R[g].tobytes()
                and rig.d.tobytes() == self._last_d[g].tobytes())
        if still_test and same:
            if self._rest_fast[g]:
                return False
            self._rest_fast[g] = True
        else:
            self._rest_fast[g] = False
        self._has_last[g] = bool(dt)
        if dt:
            self._last_R[g] = np.ascontiguousarray(rig.R).reshape(-1).view(np.int64)
            self._last_d[g] = rig.d.view(np.int64)
        return True

    def _place(self, s, t: float, dt, per, normals, flat: bool, box) -> tuple[int, int]:
        """Evaluate each mkbound's motion at t (skipping those at rest) and place its particles;
        (rows found, the first row placed outside ``box`` or -1: a wall at rest did not move).
        The translations a compiled pass covers (:class:`sphdvi.motion_batch.MotionBatch`) are
        placed in one compiled pass too; the others one by one."""
        from .motion_batch import _EYE_BITS, place_translations
        active = self._active
        batch = self._batch
        still_test = bool(dt) and per is None
        if batch is not None:
            others = batch.evaluate(t).tolist()
            place_translations(batch.fast, bool(dt), still_test, batch.d, batch.V, batch.d_bits, _EYE_BITS,
                               self._last_R, self._last_d, self._has_last, self._rest_fast, active,
                               self._first, self._end, self._x0all, self._x, self._n0all if self.normals0
                               is not None else self._x0all, self._n, self.normals0 is not None, self._vwc)
        else:
            others = range(len(self.mkbounds))
        for g in others:
            if batch is not None and batch.eligible[g]:
                rig = batch.transform(g, t)
                if not self._still(g, rig, dt, still_test):
                    active[g] = False
                    continue
            else:
                rig = self.motions.transform(self.mkbounds[g], t)
                key = (rig.R.tobytes(), rig.d.tobytes())
                if still_test and key == self._last[g]:
                    if self._rest[g]:               # placed there at rest already
                        active[g] = False
                        continue
                    self._rest[g] = True            # placed again where it was: at rest from now on
                else:
                    self._rest[g] = False
                self._last[g] = key if dt else None
            active[g] = True
            a, b = self._bounds[g]
            if rig.rot:
                np.matmul(self._x0[g], rig.R.T, out=self._x[a:b])
                self._x[a:b] += rig.d
                if self.normals0 is not None:
                    np.matmul(self._n0[g], rig.R.T, out=self._n[a:b])
            else:
                np.add(self._x0all[a:b], rig.d, out=self._x[a:b])
                if self.normals0 is not None:
                    self._n[a:b] = self._n0all[a:b]
            if not dt:
                self._vwc[0, g], self._vwc[1, g], self._vwc[2, g] = rig.V, rig.W, rig.c
        if not active.any():
            return self._count, -1
        paxes, _lo, plen, pshift = _periodic_args(per)
        return place_moving(s.ptype, s.idp, s.pos, s.vel, normals, self._slot, self._group, active,
                            self._x, self._y0, self._n, self._vwc[0], self._vwc[1], self._vwc[2],
                            float(dt) if dt else 0.0, flat,
                            paxes, plen, pshift, box[0], box[1])


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
        from .bodychecks import BodyWatch       # finite states, joints, embedded contacts (sphdvi.bodychecks)
        self.watch = BodyWatch(self.system, self.names, self.mkbounds, mech["sizes"], mech["dp"])
        for line in mech["warnings"]:
            warnings.warn(line)
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
        self._free_rows, self._tied_rows = _periodic_roles(self.system)
        self._held = None           # the solver of a step held by FtPause whose loads are not computed yet
        self._saved = None          # the multibody state the Symplectic predictor puts back (kept arrays)
        self._sel = np.empty(p["idp"].size, np.int64)     # rows and bodies of the floating particles,
        self._body = np.empty(p["idp"].size, np.int64)    # refilled each call (the solver reorders)
        self.moorings = self._moorings(data)

    def _moorings(self, data: dict):
        """``<special><moorings>`` (sphdvi.moorings): the lines on the moored floating bodies, or None."""
        spec = (data["json"].get("special") or {}).get("moorings")
        if not spec:
            return None
        from .moorings.system import Moorings
        index = {mkb: i for i, mkb in enumerate(self.mkbounds)}
        missing = [m for m in spec["floatings"] if int(m) not in index]
        if missing:
            raise InputError(f"<moorings><mooredfloatings>: mkbound {missing[0]} is not a floating body of the case "
                             "(expected the mkbound of a <floating>)")
        g = abs(float(np.asarray(data["constants"]["gravity"], float)[2]))    # |g_z|, as DualSPHysics
        return Moorings(spec, g, index, self.system.pos.copy(), self.system.quat.copy())

    def _with_moorings(self, F: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The fluid's loads plus the mooring lines' (held from the last step; in 2D in the x-z plane)."""
        if self.moorings is None:
            return F, T
        mF, mT = self.moorings.loads()
        F, T = F + mF, T + mT
        if self.is2d:
            F[:, 1] = 0.0
            T[:, 0] = T[:, 2] = 0.0
        return F, T

    def _step_moorings(self, t0: float, dt: float) -> None:
        if self.moorings is not None:
            self.moorings.step(t0, dt, self.system.pos, self.system.quat)

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
        # the body's particles and its centre are wrapped at the periodic ends each on its own
        # (a body across an end has both): the lever arm is the shortest periodic image
        # (DualSPHysics's FtPeriodicDist)
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
        state :meth:`predict` left the bodies in, the one at the step's start.  During FtPause
        the bodies stay where they are and their loads wait for a bodies.csv row
        (:meth:`held_loads`)."""
        if self.paused(solver.time - dt):
            self.system.time = solver.time     # frozen bodies (FtPause): the clock still runs
            self._held = solver
            self._step_moorings(solver.time - dt, dt)      # the lines settle on the held bodies
            return
        self._held = None
        sel, body = self.rows(solver)
        F, T = self.loads(solver, sel, body)
        self.system.fluid_force, self.system.fluid_torque = F, T    # bodies.csv ffx.. ftz (fresh arrays)
        self.system.advance(dt, *self._with_moorings(F, T))
        self._step_moorings(solver.time - dt, dt)
        self.watch.after_step(getattr(solver, "nstep", 0))     # a NaN body: stopped before the fluid sees it
        self.carry_particles(solver, sel, body)
        self.wrap_centres(solver)
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
        self._saved = saved = self.system.get_state(self._saved)    # into the last step's copy
        self.system.advance(dt_half, *self._with_moorings(F, T))
        self.watch.check_finite(getattr(solver, "nstep", 0) + 1)     # the step under way
        self.carry_particles(solver, sel, body)
        self.system.set_state(saved)

    def held_loads(self) -> None:
        """During FtPause, the loads of the last step on the held bodies (fluid_force,
        fluid_torque, :meth:`hold`), computed only when a bodies.csv row is written (BodyLog's
        ``prepare``, at outputs and TimeOutExtra), the only place they are read: the solver's
        accelerations and the frozen particles are still those of the step's end then.  As
        DualSPHysics's JSphCpuSingle::RunFloating, which sums them while paused only when a Part
        or a TimeOutExtra row is due (``if(!ftpaused || saveftvalues)``)."""
        solver, self._held = self._held, None
        if solver is None:
            return
        sel, body = self.rows(solver)
        F, T = self.loads(solver, sel, body)
        self.system.fluid_force, self.system.fluid_torque = F, T
        self.hold(F, T)

    def hold(self, F: np.ndarray, T: np.ndarray) -> None:
        """During FtPause, the loads on each held floating body for bodies.csv: its weight plus
        the fluid's force (``F``) as total_force, the fluid's moment (``T``, the torque columns),
        as DualSPHysics keeps computing them for its output while paused."""
        from .dvi.system import FLOATING
        sys_ = self.system
        fl = (sys_.kind == FLOATING)[:, None]
        sys_.total_force = np.where(fl, F + sys_.mass[:, None] * sys_.gravity[None, :], sys_.total_force)
        sys_.total_torque = np.where(fl, T, sys_.total_torque)

    def wrap_centres(self, solver) -> None:
        """With periodic boundaries, bring the centre of each free floating body that left the
        periodic box back in (as the fluid's particles: + S_k below it, - S_k at or above its high
        end), as DualSPHysics's FtUpdateFloatings stores ``UpdatePeriodicPos(fcenter)`` after each
        whole step; only its position moves (velocity, rotation and loads are unchanged: the lever
        arms are minimum images).  A floating body with links or a collision shape (DualSPHysics
        integrates it in Chrono, which knows nothing of the periodic box: its links and contacts
        would act on the unwrapped body) is not wrapped: its centre leaving the box is an
        InputError (exit 2)."""
        per = getattr(solver, "periodicity", None)
        if per is None:
            return
        pos = self.system.pos
        if self._free_rows.size:
            centres = pos[self._free_rows]
            per.wrap(centres)
            pos[self._free_rows] = centres
        for i in self._tied_rows:
            for k in per.axes:
                x, lo, hi = float(pos[i, k]), float(per.lo[k]), float(per.lo[k] + per.length[k])
                if lo <= x < hi:
                    continue
                what = _tied_reason(self.system, i)
                raise InputError(
                    f"t={solver.time:.6g} s: floating body mkbound {self.mkbounds[i]} ('{self.names[i]}') crossed the "
                    f"periodic boundary along {'xyz'[k]} (centre {'xyz'[k]} = {x:.6g} m, periodic box [{lo:.6g}, "
                    f"{hi:.6g}) m) but it has {what}: those are not periodic (DualSPHysics integrates such a body in "
                    f"Chrono, without the periodic conditions), so its contacts and links would act on the wrong "
                    f"image; expected a <chrono> body with links or a modelfile to stay inside the periodic box "
                    f"(or a floating without <chrono> links and collisions to cross it)")

    def check_radius(self, per, ignore: bool = False) -> None:
        """DualSPHysics's JSph::CalcFloatingRadius at the start of a periodic run: a floating body's
        radius is 1.2 times the largest distance of its particles from its centre, and a periodic
        length (the period L_k, |PeriXinc.x| ...) not above the largest radius stops the run
        (InputError, exit 2), or with ``ignore`` (the FtIgnoreRadius parameter) is warned about, as
        DualSPHysics does: such a body can meet its own periodic image."""
        if per is None or not self.particles:
            return
        from .dvi.system import FLOATING
        radius = {i: FLOATING_OVERRADIUS * float(np.sqrt((local * local).sum(axis=1).max(initial=0.0)))
                  for i, (_, local) in enumerate(self.particles) if int(self.system.kind[i]) == FLOATING}
        if not radius:
            return
        i = max(radius, key=radius.get)
        for k in per.axes:
            length = float(per.length[k])
            if length > radius[i]:
                continue
            text = (f"floating body mkbound {self.mkbounds[i]} ('{self.names[i]}'): its radius, {radius[i]:.6g} m "
                    f"({FLOATING_OVERRADIUS:g} x the largest distance of its particles from its centre, as "
                    f"DualSPHysics's CalcFloatingRadius), is not below the periodic length along {'xyz'[k]}, "
                    f"{length:.6g} m: the body can meet its own periodic image (DualSPHysics: \"The floating body "
                    f"radius ({radius[i]:g} [m]) is too large for periodic distance in {'XYZ'[k]} ({length:g} [m])\")")
            if ignore:
                warnings.warn(text + "; run on as FtIgnoreRadius asks")
            else:
                raise InputError(text + "; expected a periodic length above the body's radius (a longer periodic "
                                        "domain or a smaller body), or FtIgnoreRadius=1 in <parameters> to run on "
                                        "with a warning")

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
# DualSPHysics's CalcFloatingRadius: a floating body's radius is this times its particles' largest
# distance from its centre ("overradius")
FLOATING_OVERRADIUS = 1.2


def _periodic_roles(system) -> tuple[np.ndarray, np.ndarray]:
    """(free, tied) floating bodies of a multibody system: a tied one has a collision shape or a
    link (kept unwrapped, as DualSPHysics's Chrono bodies), a free one neither (its centre is
    wrapped into the periodic box, as DualSPHysics's own floating update)."""
    from .dvi.system import FLOATING
    tied = np.zeros(system.nb, np.bool_)
    tied[np.asarray(system.sh_body, np.int64)] = True
    for rec in system.links:
        for b in (rec.get("b1"), rec.get("b2")):
            if b is not None and int(b) >= 0:
                tied[int(b)] = True
    floating = np.asarray(system.kind) == FLOATING
    return np.flatnonzero(floating & ~tied), np.flatnonzero(floating & tied)


def _tied_reason(system, i: int) -> str:
    """What ties body ``i`` to the non-periodic multibody world: its links' names, a collision shape."""
    links = [rec["name"] for rec in system.links if i in (rec.get("b1"), rec.get("b2"))]
    parts = [f"link{'s' if len(links) > 1 else ''} " + ", ".join(f"'{n}'" for n in links)] if links else []
    if np.any(np.asarray(system.sh_body) == i):
        parts.append("a collision shape (<chrono> collision with a modelfile)")
    return " and ".join(parts)


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


"""Checks of the multibody state during a run, body-only or coupled to SPH, and the start-up
warnings on the bodies.

* a non-finite body state (position, orientation, velocity, angular velocity) stops the run
  (DivergenceError, exit 3) naming the body (and its mkbound), the time, its last finite state
  and the likely cause, the body with a non-finite or absurd imposed load first (DSPHChronoLib
  checks the bodies' data for NaN too, fdsch::CheckForNaNs, and DualSPHysics stops);
* a rigid joint whose position violation stays above JOINT_BREAK_FRACTION of the smaller body's
  size (at least dp), or whose locked rotations are off by more than JOINT_BREAK_ANGLE (a hinge's
  axes apart, a hinge turned over in its bearing), for JOINT_BREAK_STEPS steps without shrinking has
  come apart: the run stops (exit 3) naming the link, its bodies, the violation and what to try;
* in a body-only run a body's particle outside the case's domain stops it (exit 3), as a floating
  particle leaving the domain stops an SPH run (DualSPHysics's AbortBoundOut);
* a contact deeper than EMBED_ENVELOPES collision envelopes whose depth has not shrunk over a window of
  EMBED_STEPS steps and EMBED_RECOVERY_TIMES the time the recovery speed needs to remove it is warned
  about once per pair of bodies (it does not recover);
* a heavy body resting on a light one (their contact normal within 60 deg of up, carrying half the
  heavier's weight) whose mass ratio exceeds what the chosen solver handles (CONTACT_RATIO_LIMIT) is
  warned about once per pair (:meth:`BodyWatch.check_contact_ratio`; the limits were measured for
  that case: a light body on a heavy one, or bodies that never touch, the solvers hold);
* at start (:func:`startup_warnings`): a moment of inertia below INERTIA_FRACTION of m·L² (a unit
  slip).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .errors import DivergenceError

# a rigid joint has come apart when its position violation stays above this fraction of the
# smaller of its bodies' sizes (at least dp) for JOINT_BREAK_STEPS steps in a row without shrinking
# (a drawn joint point off by more than that is pulled back at the recovery speed, 0.6 m/s, and
# shrinks; a chain flying apart grows)
JOINT_BREAK_FRACTION = 0.1
JOINT_BREAK_STEPS = 10
# ... and when the angle of its locked rotations (:func:`_mate_angles`: a hinge's axes z1, z2 apart, a
# fixed joint's relative rotation) stays above JOINT_BREAK_ANGLE rad for JOINT_BREAK_STEPS steps without
# shrinking (a hinge turned over inside its bearing, z1 = -z2, satisfies its two dot-product rows)
JOINT_BREAK_ANGLE = 0.1
# a contact gap below -EMBED_ENVELOPES x the collision envelope (distancedp dp, DualSPHysics's "allowed
# collision overlap") that has not shrunk by EMBED_SHRINK of its depth over a window of at least
# EMBED_STEPS steps and EMBED_RECOVERY_TIMES the time the recovery speed (0.6 m/s) needs to remove that
# depth: embedded, not recovering (a 2 cm overlap recovers in 33 ms, 330 steps at h = 1e-4 s; a cube
# driven into a one-layer plate in one step stays at 1.8 envelopes)
EMBED_ENVELOPES = 1.5
EMBED_STEPS = 50
EMBED_RECOVERY_TIMES = 3.0
EMBED_SHRINK = 0.1
# a principal moment of inertia below this fraction of m L^2 (L the body's size) is warned about
INERTIA_FRACTION = 1e-6
# the largest mass ratio between two colliding bodies each solver holds at its default 100
# iterations (a light box under a heavy one on a plane, offset 1 cm or turned 10 deg, h = 1e-3 s,
# 1 s, held = gap error < 1 mm: measured 2026-11-27; PSOR 300 / 1e3 fails, APGD 300 / 1e3,
# BB 1e3 / 3e3 (1e8 only on a bit-exactly symmetric stack); direct holds 1e8 (its interior point))
CONTACT_RATIO_LIMIT = {"psor": 300.0, "apgd": 300.0, "bb": 1e3}
# an imposed force above this many times the body's weight (a torque: times weight x size) is absurd
ABSURD_LOAD = 1e6


def _fmt(v) -> str:
    return "(" + ", ".join(f"{float(x):.5g}" for x in v) + ")"


def body_sizes(points: list, dp: float) -> np.ndarray:
    """Each body's size: the largest side of its particles' bounding box plus dp (a body of one
    particle: dp)."""
    return np.array([float(np.ptp(np.asarray(p, float), axis=0).max(initial=0.0)) + dp if len(p) else dp
                     for p in points])


def solver_hint(line: str) -> str:
    """The multibody solver's not-converged warning with the remedy the case file offers."""
    if line.startswith("multibody solver not converged"):
        return (line + "; in the case file: <chrono><solver maxiter=\"1000\"/> (more iterations) or "
                "<solver type=\"direct\"/> (joint chains), or a smaller DtFixed")
    return line


class BodyWatch:
    """The run-time checks of a System's bodies (see the module's docstring). ``names``: the
    bodies' names; ``mkbounds``: their mkbounds (None: not named); ``sizes``: their sizes (m);
    ``dp``: the case's dp; ``points``/``domain``: each body's particles (world, at the start, with
    the System at its start pose) and the simulation domain (posmin, posmax[, where each limit came
    from]), for the domain check
    of a body-only run."""

    def __init__(self, system, names, mkbounds=None, sizes=None, dp: float = 0.0, points=None, domain=None):
        self.s = system
        self.names = list(names)
        self.mkbounds = list(mkbounds) if mkbounds is not None else None
        self.dp = float(dp)
        self.sizes = (np.asarray(sizes, float) if sizes is not None else np.full(system.nb, np.inf))
        self._last = None           # (time, pos, vel, omega_b) of the last finite state (when _seen)
        self._joint_run = {}        # mate -> violations of the steps in a row above its limit
        self._angle_run = {}        # mate -> locked-rotation angles of the steps in a row above JOINT_BREAK_ANGLE
        self._limits = None         # each mate's violation limit (_joint_limit)
        self._embed_run = {}        # (body a, body b) -> [steps in a row embedded, window: steps, start time, depth]
        self._embed_warned = set()
        self._ratio_warned = set()  # (light, heavy) pairs warned about (check_contact_ratio)
        self._ratio_possible = None  # two floating bodies' mass ratio beyond the solver's limit
        self.domain = None
        self._seen = False          # a state was checked: _last holds one
        if np.isfinite(system.pos).all() and np.isfinite(system.vel).all():
            self._last = (float(system.time), system.pos.copy(), system.vel.copy(), system.omega_b.copy())
            self._seen = True
        self.domain_note = ""       # where the domain's limits came from (domain[2], optional)
        if domain is not None and points is not None:
            self.domain = (np.asarray(domain[0], float), np.asarray(domain[1], float))
            self.domain_note = str(domain[2]) if len(domain) > 2 else ""
            from .dvi._math import np_quat_to_mat
            self.local = [(np.asarray(p, float) - system.pos[i]) @ np_quat_to_mat(system.quat[i])
                          for i, p in enumerate(points)]
            self.radius = np.array([float(np.sqrt((p * p).sum(axis=1).max(initial=0.0))) for p in self.local])

    def label(self, i: int) -> str:
        """'name' (mkbound N) of body i."""
        mk = f" (mkbound {self.mkbounds[i]})" if self.mkbounds is not None else ""
        return f"'{self.names[i]}'{mk}"

    # -- every step ------------------------------------------------------------------
    def after_step(self, step: int) -> None:
        """The checks of one step: finite state, joints, domain, embedded contacts, a heavy body
        resting on a light one beyond the solver's mass ratio."""
        self.check_finite(step)
        self.check_joints(step)
        if self.domain is not None:
            self.check_domain(step)
        self.check_embedded()
        self.check_contact_ratio()

    def check_finite(self, step: int) -> None:
        """Raise DivergenceError at a non-finite body state (see :meth:`_diverged`); otherwise
        remember the state as the last finite one."""
        s = self.s
        if self._last is None or self._last[1].shape != s.pos.shape:
            self._last = (0.0, np.zeros_like(s.pos), np.zeros_like(s.vel), np.zeros_like(s.omega_b))
        if _finite_keep(s.pos, s.quat, s.vel, s.omega_b, self._last[1], self._last[2], self._last[3]):
            self._last = (float(s.time),) + self._last[1:]
            self._seen = True
            return
        raise DivergenceError(self._diverged(step))

    def _load_size(self, i: int) -> tuple[float, float]:
        """(|force|/weight, |torque|/(weight x size)) of body i's imposed load."""
        s = self.s
        w = float(s.mass[i]) * max(float(np.linalg.norm(s.gravity)), 1.0)
        L = float(self.sizes[i]) if np.isfinite(self.sizes[i]) else 1.0
        return (float(np.abs(s.f_ext[i]).max()) / w, float(np.abs(s.t_ext[i]).max()) / (w * L))

    def _load_note(self) -> str:
        """'; body 'b' (mkbound 2) has an absurd imposed load (...)' for the bodies whose imposed load
        is not finite or above ABSURD_LOAD times their weight (the likely cause of a blow-up)."""
        s = self.s
        bad = [i for i in range(s.nb) if not (np.isfinite(s.f_ext[i]).all() and np.isfinite(s.t_ext[i]).all())
               or max(self._load_size(i)) > ABSURD_LOAD]
        return "".join(f"; body {self.label(i)} has an absurd imposed load (force {_fmt(s.f_ext[i])} N, torque "
                       f"{_fmt(s.t_ext[i])} N m at t={s.time:.6g} s, for {float(s.mass[i]):.6g} kg)" for i in bad)

    def _diverged(self, step: int) -> str:
        """The message of a non-finite state: the body whose imposed load is non-finite or absurd,
        else one with an imposed load, else the one that moved fastest at the last finite state."""
        s = self.s
        parts = (("position", s.pos), ("orientation", s.quat), ("velocity", s.vel), ("angular velocity", s.omega_b))
        bad = {what: ~np.isfinite(a).all(axis=1) for what, a in parts}
        badrows = np.flatnonzero(np.any(list(bad.values()), axis=0))
        loaded = {i for i, _ in s._load_fn} | {i for i in range(s.nb)
                                               if np.any(s.f_ext[i] != 0) or np.any(s.t_ext[i] != 0)}
        finite_load = {i: np.isfinite(s.f_ext[i]).all() and np.isfinite(s.t_ext[i]).all() for i in range(s.nb)}
        speed = np.zeros(s.nb)
        if self._seen:
            _, _, v0, w0 = self._last
            L = np.where(np.isfinite(self.sizes), self.sizes, 1.0)
            speed = np.linalg.norm(v0, axis=1) + np.linalg.norm(w0, axis=1) * L

        def rank(i):
            return (not finite_load[i], finite_load[i] and max(self._load_size(i)) > ABSURD_LOAD, i in loaded, speed[i])
        suspects = [i for i in range(s.nb) if not finite_load[i]] or list(badrows)
        i = max(suspects, key=rank)
        what = ", ".join(w for w in bad if bad[w][i]) or "state"
        others = [self.names[k] for k in badrows if k != i]
        more = (f" (and {len(others)} other bod{'y' if len(others) == 1 else 'ies'}: {', '.join(others)})"
                if others else "")
        where = f" at {_fmt(s.pos[i])}" if np.isfinite(s.pos[i]).all() else ""
        last = ""
        if self._seen:
            t0, p0, v0, _ = self._last
            last = f"; its last finite state (t={t0:.6g} s): position {_fmt(p0[i])} m, velocity {_fmt(v0[i])} m/s"
        tables = ("its <linearforce>/<angularforce> tables" if any(k == i for k, _ in s._load_fn)
                  else "its imposed force/torque")
        force, torque = s.total_force[i], s.total_torque[i]
        loads = f"force {_fmt(force)} N, torque {_fmt(torque)} N m"
        imposed = f"force {_fmt(s.f_ext[i])} N, torque {_fmt(s.t_ext[i])} N m"
        if not finite_load[i]:
            cause = f"its imposed load is not finite ({imposed} at t={s.time:.6g} s): check {tables}"
        elif max(self._load_size(i)) > ABSURD_LOAD:
            cause = (f"its imposed load is absurdly large for its mass ({float(s.mass[i]):.6g} kg) and size "
                     f"({imposed}, more than {ABSURD_LOAD:g} x its weight): check {tables}")
        elif not (np.isfinite(force).all() and np.isfinite(torque).all()):
            cause = f"the forces on it are not finite ({loads}): the multibody solution blew up"
        elif max(np.abs(force).max(), np.abs(torque).max()) > 1e100:
            cause = f"the load on it is absurdly large ({loads})"
        else:
            cause = f"the multibody solution blew up ({loads})"
        if i in loaded and finite_load[i] and max(self._load_size(i)) <= ABSURD_LOAD:
            cause += f"; it has an imposed load ({imposed})"
        return (f"t={s.time:.6g} s, step {step}: body {self.label(i)}{where} has a non-finite {what} (NaN or inf)"
                f"{more}{last}; cause: {cause}; try a smaller DtFixed, or check the masses, inertias, loads and links")

    def joint_violations(self) -> np.ndarray:
        """Each mate's (joint's) position violation now: the length of P1 - P2 along its locked
        translations (m; :func:`_mate_gaps`)."""
        s = self.s
        if not s._packed:
            s._pack()
        out = np.empty(s.m_b1.shape[0])
        _mate_gaps(s.pos, s.quat, s.m_b1, s.m_b2, s.m_p1, s.m_p2, s.m_T2, s.m_mask, out)
        return out

    def joint_angles(self) -> np.ndarray:
        """Each mate's (joint's) locked-rotation error now, rad (:func:`_mate_angles`)."""
        s = self.s
        if not s._packed:
            s._pack()
        out = np.empty(s.m_b1.shape[0])
        _mate_angles(s.quat, s.m_b1, s.m_b2, s.m_Q1, s.m_Q2, s.m_mask, out)
        return out

    def check_joints(self, step: int) -> None:
        """Raise DivergenceError when a rigid joint has come apart (see the module's docstring): its
        position violation or the angle of its locked rotations stays above its limit for
        JOINT_BREAK_STEPS steps without shrinking."""
        s = self.s
        if not s._mates:
            return
        viol = self.joint_violations()
        if self._limits is None or self._limits.shape != viol.shape:
            self._limits = np.array([self._joint_limit(m) for m in range(viol.size)])
        self._check_runs(step, self._joint_run, viol, self._limits, "position")
        self._check_runs(step, self._angle_run, self.joint_angles(), np.full(viol.size, JOINT_BREAK_ANGLE),
                         "rotation")

    def _check_runs(self, step: int, runs: dict, viol: np.ndarray, limits: np.ndarray, what: str) -> None:
        """Track the steps in a row each mate's ``viol`` stays above its limit; raise DivergenceError
        after JOINT_BREAK_STEPS of them without shrinking."""
        over = viol > limits      # NaN is check_finite's
        if not runs and not over.any():
            return
        for m in list(runs):
            if not over[m]:
                del runs[m]
        for m in np.flatnonzero(over):
            run = runs.setdefault(int(m), [])
            run.append(float(viol[m]))
            if len(run) >= JOINT_BREAK_STEPS and run[-1] >= run[0]:
                raise DivergenceError(self._joint_message(int(m), step, run, float(limits[m]), what))

    def _joint_limit(self, m: int) -> float:
        s = self.s
        sizes = [self.sizes[b] for b in (s.m_b1[m], s.m_b2[m]) if b >= 0]
        return max(JOINT_BREAK_FRACTION * min(sizes), self.dp) if sizes else np.inf

    def _joint_message(self, m: int, step: int, run: list, limit: float, what: str = "position") -> str:
        s = self.s
        lid = int(s.m_lid[m])
        link = s.links[lid]["name"] if lid < len(s.links) else f"link {lid}"
        b1, b2 = int(s.m_b1[m]), int(s.m_b2[m])
        bodies = f"{self.label(b1)} and " + (self.label(b2) if b2 >= 0 else "the ground")
        linked = {int(b) for b in np.concatenate([s.m_b1, s.m_b2]) if b >= 0 and s.inv_mass[b] > 0}
        masses = [float(s.mass[b]) for b in linked]
        ratio = max(masses) / min(masses) if masses and min(masses) > 0 else 1.0
        h = float(s._prev_h or 0.0)
        rec = float(s.recovery_speed)
        if what == "position":
            off = (f"its position violation is {run[-1]:.3g} m (above {limit:.3g} m, {JOINT_BREAK_FRACTION:g} of "
                   f"the smaller body's size or dp, for {len(run)} steps and not shrinking; {run[0]:.3g} m "
                   f"{len(run) - 1} steps before)")
        else:
            off = (f"its locked rotation is off by {run[-1]:.3g} rad ({math.degrees(run[-1]):.3g} deg; above "
                   f"{limit:.3g} rad for {len(run)} steps and not shrinking; {run[0]:.3g} rad {len(run) - 1} steps "
                   f"before{'; the joint has turned over' if run[-1] > math.pi / 2 else ''})")
        return (f"t={s.time:.6g} s, step {step}: the joint '{link}' between {bodies} has come apart: {off}; "
                f"solver '{s.solver}' ({s.max_iter} iterations at most, residual {s.last_residual:.3g} m/s after "
                f"{s.last_iterations}), mass ratio of the jointed bodies {ratio:.3g}, step {h:.3g} s"
                f"{self._load_note()}; likely causes: a mass ratio the iterative solver does not resolve in its "
                f"iterations, a step too long for the motion (the joints are pulled back at {rec:g} m/s at most, "
                f"{rec * h:.3g} m a step), or an absurd load or inertia; try {self._remedy()}a smaller DtFixed")

    def _remedy(self) -> str:
        """What the case file can change: the direct solver (exact for joint chains), more iterations."""
        s = self.s
        out = "" if s.solver == "direct" else "<chrono><solver type=\"direct\"/> (exact for joint chains, also those "
        if s.solver != "direct":
            out += ("with contacts), " if getattr(s, "exact_joints", True)
                    else "with contacts; or drop exactjoints=\"false\": joint-only chains are then exact), ")
        if s.solver != "direct" and s.max_iter < 1000:
            out += "<solver maxiter=\"1000\"/>, "
        return out + ("or " if out else "")

    def check_domain(self, step: int) -> None:
        """Raise DivergenceError when a body's particle has left the simulation domain (a body-only
        run; the SPH run's own check is coupling.FloatingBodies.check_in_domain): the centre plus
        the body's radius first, its particles where that reaches out."""
        s = self.s
        lo, hi = self.domain
        reach = (s.pos - self.radius[:, None] < lo) | (s.pos + self.radius[:, None] > hi)
        from .dvi.system import FLOATING
        for i in np.flatnonzero(reach.any(axis=1) & (s.kind == FLOATING)):
            from .dvi._math import np_quat_to_mat
            pts = s.pos[i] + self.local[i] @ np_quat_to_mat(s.quat[i]).T
            out = np.any((pts < lo) | (pts > hi), axis=1)
            if not out.any():
                continue
            k = int(np.flatnonzero(out)[0])
            raise DivergenceError(
                f"t={s.time:.6g} s, step {step}: body {self.label(i)} (centre {_fmt(s.pos[i])}) left the simulation "
                f"domain: its particle at {_fmt(pts[k])} is outside {_fmt(lo)} - {_fmt(hi)} ({int(out.sum())} of its "
                f"particles out{'; the domain: ' + self.domain_note if self.domain_note else ''})"
                f"{self._load_note()}; DualSPHysics stops too (\"Fixed, moving or floating particles "
                f"were excluded\"); "
                f"check the body's loads, links and contacts (a body faster than a wall's thickness per step "
                f"passes through it: a smaller DtFixed), or enlarge the domain (<simulationdomain>)")

    def check_embedded(self) -> None:
        """Warn once per pair of bodies whose contact has stayed deeper than EMBED_ENVELOPES
        collision envelopes without recovering (a body driven through a thin wall in one step stays
        stuck in it): its worst depth has not shrunk by EMBED_SHRINK over a window of at least
        EMBED_STEPS steps and EMBED_RECOVERY_TIMES x depth / recovery speed (a time, so that a deep
        contact recovering at the recovery speed at a small step is not reported)."""
        s = self.s
        nc = int(getattr(s, "n_contacts", 0) or 0)
        c = getattr(s, "_c", None)
        if nc == 0 or c is None:
            if self._embed_run:
                self._embed_run.clear()
            return
        depth = EMBED_ENVELOPES * float(s.envelope)
        gap = c["gap"][:nc]
        deep = gap < -depth
        worst = {}
        if deep.any():
            for a, b, g in zip(c["a"][:nc][deep], c["b"][:nc][deep], gap[deep]):
                p = (min(int(a), int(b)), max(int(a), int(b)))
                worst[p] = max(worst.get(p, 0.0), -float(g))
        for p in list(self._embed_run):
            if p not in worst:
                del self._embed_run[p]
        t = float(s.time)
        vrec = float(s.recovery_speed)
        for p, d in worst.items():
            run = self._embed_run.setdefault(p, [0, 0, t, d])
            run[0] += 1
            run[1] += 1
            n, nw, t0, d0 = run
            need = EMBED_RECOVERY_TIMES * d0 / vrec if vrec > 0 else 0.0
            if nw < EMBED_STEPS or t - t0 < need * (1 - 1e-9) or p in self._embed_warned:
                continue
            if d < (1 - EMBED_SHRINK) * d0:             # shrinking: a new window from here
                run[1:] = [0, t, d]
                continue
            self._embed_warned.add(p)
            a, b = p
            who = " and ".join(self.label(k) if k >= 0 else "the ground" for k in (a, b))
            line = (f"bodies {who} have been embedded in each other for {n} steps at t={t:.6g} s: contact "
                    f"penetration {d:.3g} m (more than {depth:.3g} m, {EMBED_ENVELOPES:g} collision envelopes; "
                    f"{d0:.3g} m {t - t0:.3g} s before, in which the recovery speed, {vrec:g} m/s, removes it "
                    f"{(t - t0) * vrec / d0 if d0 > 0 else 0:.3g} times over); "
                    f"it does not recover (a body driven through a thin wall in one step stays in it): "
                    f"use a smaller DtFixed or thicker walls")
            s.say(line)


    def check_contact_ratio(self) -> None:
        """Warn once per pair of floating bodies whose mass ratio is above what the solver holds
        (CONTACT_RATIO_LIMIT) when the heavier rests on the lighter: their contact normal, from the
        lighter to the heavier, within 60 deg of up (against gravity) and carrying at least half the
        heavier's weight.  A light body on a heavy one, or bodies that never touch, the solvers hold."""
        s = self.s
        limit = CONTACT_RATIO_LIMIT.get(str(s.solver).lower())
        nc = int(getattr(s, "n_contacts", 0) or 0)
        if limit is None or nc == 0 or str(getattr(s, "contactmethod", "nsc")).lower() == "smc":
            return
        from .dvi.system import FLOATING
        if self._ratio_possible is None:            # (the masses do not change in a run)
            m = s.mass[(s.kind == FLOATING) & (s.mass > 0)]
            self._ratio_possible = m.size >= 2 and float(m.max() / m.min()) > limit
        if not self._ratio_possible:
            return
        c, crow = getattr(s, "_c", None), getattr(s, "_c_row", None)
        g = float(np.linalg.norm(s.gravity))
        if c is None or crow is None or crow.shape[0] < nc or g == 0.0:
            return
        a, b = c["a"][:nc], c["b"][:nc]
        both = (a >= 0) & (b >= 0)
        if not both.any():
            return
        ia, ib = a[both].astype(np.int64), b[both].astype(np.int64)
        ma, mb = s.mass[ia], s.mass[ib]
        heavy_b = mb > ma
        ratio = np.where(heavy_b, mb / np.maximum(ma, 1e-300), ma / np.maximum(mb, 1e-300))
        sel = (ratio > limit) & (s.kind[ia] == FLOATING) & (s.kind[ib] == FLOATING)
        if not sel.any():
            return
        up = -np.asarray(s.gravity, float) / g
        n = c["n"][:nc][both]                           # from a to b
        n_up = np.where(heavy_b, 1.0, -1.0) * (n @ up)  # from the lighter to the heavier, along up
        force = s.r_gamma[crow[both]] / float(s._prev_h or 1.0)
        pairs = {}
        for k in np.flatnonzero(sel & (n_up > 0.5)):
            light, heavy = (int(ia[k]), int(ib[k])) if heavy_b[k] else (int(ib[k]), int(ia[k]))
            pairs[(light, heavy)] = pairs.get((light, heavy), 0.0) + float(force[k])
        for (light, heavy), f in pairs.items():
            weight = float(s.mass[heavy]) * g
            if f < 0.5 * weight or (light, heavy) in self._ratio_warned:
                continue
            self._ratio_warned.add((light, heavy))
            line = (f"body {self.label(heavy)} ({float(s.mass[heavy]):.6g} kg) rests on body {self.label(light)} "
                    f"({float(s.mass[light]):.6g} kg) at t={s.time:.6g} s (contact force {f:.3g} N, its weight "
                    f"{weight:.3g} N): mass ratio {float(s.mass[heavy] / s.mass[light]):.3g}, above the "
                    f"{limit:.3g} that the '{s.solver}' solver resolves (a light body under a heavy one is crushed "
                    f"or launched); the direct solver (<solver type=\"direct\"/>) holds 1e8")
            s.say(line)


@njit(cache=True)
def _finite_keep(pos, quat, vel, omb, kpos, kvel, komb) -> bool:
    """True when every body's position, orientation, velocity and angular velocity are finite, and
    then the state copied into kpos, kvel, komb (the last finite state)."""
    for a in (pos, vel, omb):
        for v in a.ravel():
            if not math.isfinite(v):
                return False
    for v in quat.ravel():
        if not math.isfinite(v):
            return False
    kpos[:] = pos
    kvel[:] = vel
    komb[:] = omb
    return True


@njit(cache=True)
def _quat_mat(q):
    """The rotation matrix of the unit quaternion (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@njit(cache=True)
def _mate_gaps(pos, quat, b1, b2, p1, p2, T2, mask, out):
    """Per mate, |P1 - P2| along its locked translations, the axes of frame 2 (the position error of
    rows.build_mate_rows' translational rows, C = e_k . (P1 - P2)); a body index < 0 is the ground."""
    for m in range(b1.shape[0]):
        P1 = p1[m].copy()
        if b1[m] >= 0:
            P1 = pos[b1[m]] + _quat_mat(quat[b1[m]]) @ p1[m]
        R2 = np.eye(3)
        P2 = p2[m].copy()
        if b2[m] >= 0:
            R2 = _quat_mat(quat[b2[m]])
            P2 = pos[b2[m]] + R2 @ p2[m]
        E = R2 @ T2[m]
        d = P1 - P2
        acc = 0.0
        for k in range(3):
            if mask[m, k] != 0:
                c = E[0, k] * d[0] + E[1, k] * d[1] + E[2, k] * d[2]
                acc += c * c
        out[m] = np.sqrt(acc)


@njit(cache=True)
def _mate_angles(quat, b1, b2, Q1, Q2, mask, out):
    """Per mate, the angle (rad) by which its locked rotations are off (rows.build_mate_rows): with one
    free rotation f the angle between the free axes f1 and f2 (a hinge turned over, f1 = -f2, is pi,
    though its two rows ``f1 . o2`` are 0 there); all three locked: the relative rotation angle of
    frame 1 in frame 2; one locked (a dot-1 row ``C = sin(error)``, whose zero set is the joint's
    motion): asin|C|; none locked: 0.  A body index < 0 is the ground."""
    for m in range(b1.shape[0]):
        R1 = np.eye(3)
        R2 = np.eye(3)
        if b1[m] >= 0:
            R1 = _quat_mat(quat[b1[m]])
        if b2[m] >= 0:
            R2 = _quat_mat(quat[b2[m]])
        A = R1 @ Q1[m]
        B = R2 @ Q2[m]
        nfree = 0
        f = 0
        for k in range(3):
            if mask[m, 3 + k] == 0:
                nfree += 1
                f = k
        if nfree == 0:
            Rrel = B.T @ A
            c = 0.5 * (Rrel[0, 0] + Rrel[1, 1] + Rrel[2, 2] - 1.0)
            ax = Rrel[2, 1] - Rrel[1, 2]
            ay = Rrel[0, 2] - Rrel[2, 0]
            az = Rrel[1, 0] - Rrel[0, 1]
            out[m] = math.atan2(0.5 * math.sqrt(ax * ax + ay * ay + az * az), c)
        elif nfree == 1:
            u = A[:, f]
            v = B[:, f]
            cx = u[1] * v[2] - u[2] * v[1]
            cy = u[2] * v[0] - u[0] * v[2]
            cz = u[0] * v[1] - u[1] * v[0]
            out[m] = math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), u[0] * v[0] + u[1] * v[1] + u[2] * v[2])
        elif nfree == 2:
            a = 0
            for k in range(3):
                if mask[m, 3 + k] != 0:
                    a = k
            u = A[:, (a + 1) % 3]
            v = B[:, (a + 2) % 3]
            out[m] = math.asin(min(1.0, abs(u[0] * v[0] + u[1] * v[1] + u[2] * v[2])))
        else:
            out[m] = 0.0


def startup_warnings(bodies: list, sizes, mkbounds, solver: str, is2d: bool) -> list[str]:
    """The start-up warnings on the bodies of a case (``bodies``: mechanism_from_case's dicts):
    a moment of inertia about a free axis below INERTIA_FRACTION of m L² (L the body's size; a unit
    slip such as g mm² for kg m²: a torque then spins the body at ω ~ T h / I and its links break).
    ``solver`` is kept for the callers: the contact mass ratio is checked at run time, where a heavy
    body rests on a light one (:meth:`BodyWatch.check_contact_ratio`)."""
    out = []
    for i, bd in enumerate(bodies):
        if bd.get("kind") != "floating":
            continue
        I = np.asarray(bd["inertia"], float)
        I = np.diag(I) if I.ndim == 1 else I
        m, L = float(bd["mass"]), float(sizes[i])
        ref = m * L * L
        top = float(np.abs(np.diag(I)).max())
        free = [k for k in range(3) if bd.get("rotation_dof", (1, 1, 1))[k] and not (is2d and k != 1)]
        for k in free:
            moment = float(I[k, k])
            if top > 0 and moment > 1e-12 * top and moment < INERTIA_FRACTION * ref:
                out.append(f"floating body '{bd['name']}' (mkbound {mkbounds[i]}): its moment of inertia about "
                           f"{'xyz'[k]}, {moment:.3g} kg m2, is below {INERTIA_FRACTION:g} of m L2 ({m:.6g} kg x "
                           f"({L:.3g} m)2 = {ref:.3g} kg m2): a unit slip (g mm2 for kg m2?); a torque spins such a "
                           f"body at w ~ T dt / I and its links break")
                break
    return out

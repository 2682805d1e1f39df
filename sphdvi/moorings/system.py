"""The mooring lines of a case (``<special><moorings>``, DualSPHysics's MoorDynPlus) and their
coupling to the floating bodies they hold: :class:`Moorings`.

Set-up (MoorDynPlus's): each line's nodes are placed on its quasi-static elastic catenary between
its anchor and fairlead (:func:`sphdvi.moorings.catenary.elastic_catenary`; on a straight line
where no catenary exists), at rest; with ``tmaxIC`` > 0 the lines then relax with their bodies
held (drag × ``cdScaleIC``) in spans of ``dtIC`` until every fairlead's force changes by at most
``threshIC`` (relative) over two spans.

Coupling (DualSPHysics's): after each SPH step the lines advance over that step
(:func:`sphdvi.moorings.lines.advance_lines`, in sub-steps of at most dtM) with each fairlead on the
straight path from its body's pose at the step's start to the one at its end; the force of each
fairlead node then acts on its body, with its moment about the body's centre, through the next
step (both halves of a Symplectic step), multiplied by the start ramp of ``<start value
ramptime>``. A broken line (``breaktension``) pulls no more (MoorDynPlus leaves the last force
before the break on the body).

The state (nodes, broken lines, the held loads) goes into restart.h5 through
:meth:`get_state`/:meth:`set_state`.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from ..dvi._math import np_quat_to_mat
from . import lines as L


def start_ramp(t: float, start: float, ramptime: float) -> float:
    """``<start value ramptime>``: 0 before ``start``, ((t − start)/ramptime)² over the ramp, then 1
    (MoorDynPlus's factor on the force given to the bodies)."""
    if t >= start + ramptime:
        return 1.0
    if t < start or ramptime <= 0:
        return 0.0
    return ((t - start) / ramptime) ** 2


def initial_nodes(anchor, fairlead, length: float, segments: int, ea: float, w: float) -> np.ndarray:
    """The nodes 0..N of a line at rest on its elastic catenary (MoorDynPlus's initial shape), in the
    vertical plane through its ends, with a frictionless seabed at the anchor's height whatever the
    bed's own height (as MoorDynPlus places them); on the straight segment between them when the
    catenary has no solution (a line too long for that bed, a fairlead below its anchor, or ``w`` ≤ 0:
    a line that floats)."""
    from .catenary import elastic_catenary
    anchor, fairlead = np.asarray(anchor, float), np.asarray(fairlead, float)
    s = np.linspace(0.0, length, segments + 1)
    d = fairlead - anchor
    xf = math.hypot(d[0], d[1])
    straight = anchor + np.outer(s / length, d)
    if w <= 0:
        return straight
    try:
        sol = elastic_catenary(xf, d[2], length, ea, w, seabed=True, s=s)
    except (ValueError, RuntimeError, ZeroDivisionError, FloatingPointError):
        return straight
    x, z = np.asarray(sol["x"], float), np.asarray(sol["z"], float)
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(z))):
        return straight
    horizontal = d[:2] / xf if xf > 0 else np.zeros(2)
    nodes = np.empty((segments + 1, 3))
    nodes[:, 0] = anchor[0] + x * horizontal[0]
    nodes[:, 1] = anchor[1] + x * horizontal[1]
    nodes[:, 2] = anchor[2] + z
    nodes[0], nodes[-1] = anchor, fairlead
    return nodes


class Moorings:
    """The lines of a ``<moorings>`` spec (:mod:`sphdvi.case.moorings_xml`) on the bodies of a
    multibody system: ``body_index`` maps a moored floating's mkbound to its body, ``centre`` and
    ``quat`` are the bodies' poses at t = 0 (the vessel connections are world points at t = 0)."""

    def __init__(self, spec: dict, g: float, body_index: dict, centre: np.ndarray, quat: np.ndarray):
        self.spec = spec
        sol = spec["solver"]
        self.lines = spec["lines"]
        self.start, self.ramptime = float(spec.get("start", 0.0)), float(spec.get("ramptime", 0.0))
        self.rho_w, self.g = float(sol["rho"]), float(g)
        nl = len(self.lines)
        counts = [int(ln["segments"]) + 1 for ln in self.lines]
        self.first = np.cumsum([0] + counts[:-1]).astype(np.int64)
        self.last = (self.first + np.array(counts) - 1).astype(np.int64)
        nn = int(sum(counts))
        self.pos = np.zeros((nn, 3))
        self.vel = np.zeros((nn, 3))
        self.prm = np.zeros((nl, L.NPRM))
        self.end_kind = np.zeros((nl, 2), np.int64)
        self.end_body = np.full((nl, 2), -1, np.int64)
        self.end_local = np.zeros((nl, 2, 3))           # a vessel end in its body's frame
        self.end_extra = np.zeros((nl, 2))              # (V ρ_w − M) g of its connection, upwards
        self.end_p0 = np.zeros((nl, 2, 3))
        self.end_v = np.zeros((nl, 2, 3))
        self.broken = np.zeros(nl, np.bool_)
        self.end_conn = np.full((nl, 2), -1, np.int64)
        connects = spec.get("connects") or []
        self.cpos = np.array([c["pos"] for c in connects], float).reshape(-1, 3)
        self.cvel = np.zeros_like(self.cpos)
        self.cprm = np.array([[c["mass"], c["volume"], c["cda"], c["ca"]] for c in connects], float).reshape(-1, L.NCPRM)
        self.cwork = L.empty_connect_work(len(connects))
        self.glob = np.array([self.rho_w, self.g, sol["kbot"], sol["cbot"], sol["friction"], sol["fricdamp"],
                              sol["statdynfricscale"], sol["freesurface"], 1.0])
        self.nbodies = int(centre.shape[0])
        dtm = float(sol["dtm"])
        for k, ln in enumerate(self.lines):
            dia, mass = float(ln["diameter"]), float(ln["mass"])
            area = math.pi * dia * dia / 4.0
            seg = float(ln["length"]) / int(ln["segments"])
            ea = float(ln["ea"])
            zbed = float(sol["freesurface"]) - float(ln["depth"])
            self.prm[k] = [seg, ea, L.damping_coefficient(float(ln["ba"]), seg, ea, mass), dia, area, mass / area,
                           ln["can"], ln["cat"], ln["cdn"], ln["cdt"], zbed, ln["breaktension"]]
            if sol.get("dtm_auto", True):
                dtm = min(dtm, L.auto_time_step(float(ln["length"]), int(ln["segments"]), ea, mass / area,
                                                self.rho_w, area))
            for e, end in enumerate(ln["ends"]):
                if end["kind"] == "connect":
                    self.end_kind[k, e] = L.CONNECT
                    self.end_conn[k, e] = int(end["connect"])
                    self.end_p0[k, e] = self.cpos[int(end["connect"])]
                    continue
                p = np.asarray(end["pos"], float)
                self.end_p0[k, e] = p
                self.end_extra[k, e] = (float(end.get("volume", 0.0)) * self.rho_w - float(end.get("mass", 0.0))) * g
                if end["kind"] == "vessel":
                    b = body_index[int(end["body"])]
                    self.end_kind[k, e] = L.VESSEL
                    self.end_body[k, e] = b
                    self.end_local[k, e] = np_quat_to_mat(quat[b]).T @ (p - centre[b])
            anchor, fairlead = self.end_p0[k, 0], self.end_p0[k, 1]
            w = (mass / area - self.rho_w) * area * self.g
            nodes = initial_nodes(anchor, fairlead, float(ln["length"]), int(ln["segments"]), ea, w)
            self.pos[self.first[k]:self.last[k] + 1] = nodes
        self.dtm = dtm
        ves = np.nonzero(self.end_kind == L.VESSEL)
        self._ves = ves                                   # (line, end) of each vessel connection
        self._ves_body = self.end_body[ves]
        self._ves_node = np.where(ves[1] == 0, self.first[ves[0]], self.last[ves[0]])
        self._ves_local = self.end_local[ves]
        self._ves_lift = self.end_extra[ves]
        self._ves_pos = np.zeros((self._ves_body.size, 3))
        self.work = L.empty_work(nn)
        self.F = np.zeros((self.nbodies, 3))        # the loads on the bodies through the next step
        self.T = np.zeros((self.nbodies, 3))
        self.time = 0.0
        self.ramp = start_ramp(0.0, self.start, self.ramptime)    # the factor of the loads held (F, T)
        self.substep = self.dtm                 # the last coupling step's sub-step (MoorDynPlus's dt column)
        self.log_next = None                    # the next MoorDynPlus row time (sphdvi.io.moorings_out)
        self.broke_warned = np.zeros(nl, np.bool_)
        self._evaluate(0.0)
        self._warn_breaks(0.0)
        self._check_finite(0.0)
        self.relax_spans = 0
        if float(sol.get("tmaxic", 0.0)) > 0:
            self.relax_spans = self.relax(float(sol["tmaxic"]), float(sol["dtic"]), float(sol["cdscaleic"]),
                                          float(sol["threshic"]))
        self.F, self.T = self._body_loads(centre, ramp=self.ramp)

    # ---- the kernels' calls ----

    def _advance(self, t0: float, dt: float) -> None:
        nsub = max(1, int(math.ceil(dt / self.dtm - 1e-9)))
        self.substep = dt / nsub
        w = self.work
        L.advance_lines(t0, dt, nsub, self.pos, self.vel, self.first, self.last, self.end_kind, self.end_p0,
                        self.end_v, self.prm, self.glob, self.broken, w["fnet"], w["acc"], w["seg_t"], w["seg_len"],
                        w["pos_h"], w["vel_h"], self.end_conn, self.cpos, self.cvel, self.cprm,
                        self.cwork)
        self._warn_breaks(t0 + dt)
        self._check_finite(t0 + dt)

    def _check_finite(self, t: float) -> None:
        """A node or force that is not finite stops the run (exit 3), naming the line (MoorDynPlus
        stops on a NaN in its state too)."""
        from ..errors import DivergenceError
        cbad = ~(np.isfinite(self.cpos).all(axis=1) & np.isfinite(self.cvel).all(axis=1))
        if cbad.any():
            c = int(np.flatnonzero(cbad)[0])
            raise DivergenceError(f"<moorings> connect conref={self.spec['connects'][c]['conref']} is not finite at "
                                  f"t = {t:.6g} s (sub-step {self.substep:.3g} s; a smaller dtM, or dtM auto, may "
                                  "hold it)")
        bad = ~(np.isfinite(self.pos).all(axis=1) & np.isfinite(self.vel).all(axis=1)
                & np.isfinite(self.work["fnet"]).all(axis=1))
        if not bad.any():
            return
        j = int(np.flatnonzero(bad)[0])
        k = int(np.searchsorted(self.last, j))
        raise DivergenceError(f"<moorings> line {self.lines[k]['id']}: node {j - int(self.first[k])} is not finite "
                              f"at t = {t:.6g} s (sub-step {self.substep:.3g} s; a smaller dtM, or dtM auto, may "
                              "hold it)")

    def _evaluate(self, t: float) -> None:
        """Eq. (3) at the nodes as they are (the ends where ``end_p0`` says)."""
        w = self.work
        self.end_v[:] = 0.0
        L.advance_lines(t, 0.0, 0, self.pos, self.vel, self.first, self.last, self.end_kind, self.end_p0,
                        self.end_v, self.prm, self.glob, self.broken, w["fnet"], w["acc"], w["seg_t"], w["seg_len"],
                        w["pos_h"], w["vel_h"], self.end_conn, self.cpos, self.cvel, self.cprm,
                        self.cwork)

    def _warn_breaks(self, t: float) -> None:
        for k in np.flatnonzero(self.broken & ~self.broke_warned):
            self.broke_warned[k] = True
            warnings.warn(f"<moorings> line {self.lines[k]['id']} reached its breaktension "
                          f"{self.lines[k]['breaktension']:g} N at t = {t:.6g} s and is broken: it no longer "
                          "pulls on its body")

    def fairlead_forces(self) -> np.ndarray:
        """(lines, 2, 3): the force of each line on its two ends' connections (0 for a broken line):
        the end node's eq. (3) plus the connection's (V ρ_w − M) g upwards."""
        f = np.empty((len(self.lines), 2, 3))
        f[:, 0] = self.work["fnet"][self.first]
        f[:, 1] = self.work["fnet"][self.last]
        f[:, :, 2] += self.end_extra
        f[self.broken] = 0.0
        return f

    def end_tensions(self) -> np.ndarray:
        """(lines, 2): |T + Td| of each line's first and last segment (0 for a broken line)."""
        seg_t = self.work["seg_t"]
        out = np.column_stack([seg_t[self.first], seg_t[self.last - 1]])
        out[self.broken] = 0.0
        return out

    def _body_loads(self, centre: np.ndarray, ramp: float) -> tuple[np.ndarray, np.ndarray]:
        """Each body's sum of its fairleads' forces (× ``ramp``) and their moments about ``centre``."""
        F = np.zeros((self.nbodies, 3))
        T = np.zeros((self.nbodies, 3))
        L.body_loads(self.pos, self.work["fnet"], self._ves_node, self._ves_body, self._ves_lift,
                     self.broken[self._ves[0]], centre, ramp, F, T)
        return F, T

    # ---- coupling ----

    def vessel_points(self, centre: np.ndarray, quat: np.ndarray) -> np.ndarray:
        """(lines, 2, 3): the world position of each end, a vessel end carried by its body's pose."""
        p = self.end_p0.copy()
        L.vessel_positions(centre, quat, self._ves_body, self._ves_local, self._ves_pos)
        p[self._ves] = self._ves_pos
        return p

    def step(self, t0: float, dt: float, centre: np.ndarray, quat: np.ndarray) -> None:
        """Advance the lines from t0 over dt, each fairlead from where the last step left it to where
        its body (``centre``, ``quat`` at t0 + dt) carries it now; hold their loads for the next step."""
        if dt <= 0:
            return
        target = self.vessel_points(centre, quat)
        self.end_v[:] = (target - self.end_p0) / dt
        self._advance(t0, dt)
        self.end_p0[:] = target
        self.end_v[:] = 0.0
        self.time = t0 + dt
        self.ramp = start_ramp(t0, self.start, self.ramptime)     # MoorDynPlus's framp(t_n)
        self.F, self.T = self._body_loads(centre, ramp=self.ramp)

    def loads(self) -> tuple[np.ndarray, np.ndarray]:
        """The force and moment (about each body's centre) the lines put on the bodies this step."""
        return self.F, self.T

    def relax(self, tmax: float, span: float, cdscale: float, thresh: float) -> int:
        """MoorDynPlus's dynamic relaxation before t = 0: the bodies held, the drag × ``cdscale``, in
        spans of ``span`` until every fairlead force changed by at most ``thresh`` (relative) since
        each of the two spans before (from the third span on), or ``tmax``. Returns the spans run."""
        self.glob[L.G_CDSCALE] = cdscale
        history = []
        n = max(1, int(round(tmax / span)))
        try:
            for k in range(n):
                self.end_v[:] = 0.0
                self._advance(k * span, span)
                tension = np.linalg.norm(self.fairlead_forces(), axis=2)[self.end_kind == L.VESSEL]
                history.append(tension)
                # (without a vessel connection the test passes at once, as MoorDynPlus's DoDynamicRelaxIC)
                if k > 2 and all(
                        np.all(np.abs(tension / np.where(h != 0, h, np.inf) - 1) <= thresh) for h in history[-3:-1]):
                    return k + 1
            return n
        finally:
            self.glob[L.G_CDSCALE] = 1.0

    # ---- restart ----

    STATE_ARRAYS = ("pos", "vel", "broken", "end_p0", "F", "T", "broke_warned", "cpos", "cvel")
    STATE_WORK = ("fnet", "seg_t", "seg_len")           # the forces of the last evaluation, for outputs
    STATE_SCALARS = ("time", "ramp", "substep")

    def get_state(self) -> dict:
        """Everything that evolves (copies): nodes, broken lines, fairleads, held loads, the last
        evaluation's forces, and the next MoorDynPlus row time (NaN: none yet)."""
        st = {key: getattr(self, key).copy() for key in self.STATE_ARRAYS}
        st.update({key: self.work[key].copy() for key in self.STATE_WORK})
        st.update({key: float(getattr(self, key)) for key in self.STATE_SCALARS})
        st["log_next"] = math.nan if self.log_next is None else float(self.log_next)
        return st

    def set_state(self, st: dict) -> None:
        """Restore a :meth:`get_state` (copied in)."""
        for key in self.STATE_ARRAYS:
            if key not in st and getattr(self, key).size == 0:
                continue                 # a restart.h5 written before connects existed, of a case without them
            getattr(self, key)[...] = np.asarray(st[key])
        for key in self.STATE_WORK:
            self.work[key][...] = np.asarray(st[key])
        for key in self.STATE_SCALARS:
            setattr(self, key, float(st[key]))
        nxt = float(st["log_next"])
        self.log_next = None if math.isnan(nxt) else nxt

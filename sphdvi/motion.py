"""Imposed motion of boundary objects: DualSPHysics ``<motion>`` chains and wave paddles.

Each moving mkbound gets, at time t, a rigid transform x = R x0 + d of its
initial particle positions and a velocity field v(x) = V + Ω × (x − c).
Positions are always placed by the exact transform (no accumulated drift).

Movements (DualSPHysics ``JMotion``; times τ measured from the start of the movement):

* ``wait``, ``mvnull``: no motion;
* ``mvrect``: d = v τ;  ``mvrectace``: d = v0 τ + a τ²/2 (v0 defaults to the previous movement's
  final speed, 0 after one that is not rectilinear, as DualSPHysics);
* ``mvrot``: rotation by ω τ about the axis through p1 and p2, in DualSPHysics's sense (a
  positive angle turns right-handed about p2→p1: :func:`_rotational`); ``mvrotace``: ω0 τ + α τ²/2;
* ``mvcir``: the object translates along the circle that ``ref`` describes when rotated about the axis;
* ``mvrectsinu``: d = A [sin(2π f τ + φ) − sin φ] per component (φ defaults to the phase a
  previous sinusoidal movement of the chain reached, 0 after any other);
  ``mvrotsinu``: angle A [sin(2π f τ + φ) − sin φ]; ``mvcirsinu`` likewise on a circle;
* ``mvrectfile`` (alias ``mvfile``, ``mvpredef``)/``mvrotfile``: positions or angles
  interpolated linearly from a file of ``fields`` columns, its first row played at the movement's
  start and the displacement measured from it, the velocity the slope of the rows' segment (0
  outside the file's times); ``fieldtime``, ``fieldx``... are 0-based column indices
  (DualSPHysics's JMotionDataFile);
* ``mvpathfile``: an ``mvrectfile``'s positions and an ``mvrotadvfile``'s angles from one file, the
  centre travelling with the path (``movecenter``, the default) or staying put
  (:func:`_from_path_file`, sphdvi's reading as for ``mvrotadvfile``);
* ``mvrotadvfile``: three Euler angles from a file (``fieldang1``-``3``; ``axes`` such as XYZ,
  ``intrinsic`` or about the fixed axes, each turn right-handed), the object turned about
  ``center`` to the orientation they give relative to the file's first row's
  (:func:`_from_euler_file`; DualSPHysics applies the angles step by step and does not publish how:
  this is sphdvi's reading, exact whatever the step).

A movement ends after ``duration`` and continues with ``next``; the chain starts at
``begin start`` and stops at ``finish``. A negative duration is DualSPHysics's "flash"
(JMotionMovActive's Flash, JMotion::MovAddTeleport): the displacement |duration| seconds of the
movement would make, applied at once at its start, taking no time. A circular movement keeps the
point its ``ref`` reached (JMotion::AxisAdd's own Ref axis, moved by every step): entered again
through ``next`` it goes on round the circle. Movements of enclosing ``<obj>`` elements are
applied after the object's own. The walk along a chain is kept between evaluations
(:class:`_Walk`), so that a loop costs the same per step at any time.

Wave paddles (regular waves, Biesel transfer functions, Dean & Dalrymple 1991 §6):
piston H/S = 2 (cosh 2kd − 1)/(sinh 2kd + 2kd); flap H/S = 4 sinh kd/kd ·
(1 − cosh kd + kd sinh kd)/(sinh 2kd + 2kd) hinged at the bottom, from linear wavemaker
theory with its hinge ``variabledraft`` below it (:func:`flap_height_to_stroke`); second-order
piston term of Madsen (1971). A linear ramp r over ``ramp`` periods starts the motion from rest,
X = r S/2 sin(ωτ + φ); without a ramp X = S/2 [sin(ωτ + φ) − sin φ] starts it without a jump.
"""
from __future__ import annotations

import math
import warnings

import numpy as np


_EYE = np.eye(3)
_EYE.flags.writeable = False
_ZERO = np.zeros(3)
_ZERO.flags.writeable = False
_SKEW: dict = {}        # axis bytes -> (its cross-product matrix [k]x, [k]x²), built once per axis


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit axis (Rodrigues), I + sin θ [k]x + (1 − cos θ) [k]x²."""
    key = axis.tobytes()
    skew = _SKEW.get(key)
    if skew is None:
        k = axis / np.linalg.norm(axis)
        kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        skew = _SKEW.setdefault(key, (kx, kx @ kx))
    kx, kx2 = skew
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx2


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b of two 3-vectors in plain float arithmetic: np.cross's products and differences in
    its order (the same bits), without its per-call overhead."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


class Rigid:
    """x ↦ R x + d, with the velocity field v(x) = V + Ω × (x − c) at the current time.

    ``rot``: R may differ from the identity (False for a translation: R is I, Ω is 0);
    ``ident``: the identity at rest, ``Rigid()``.  The arrays are never changed in place (a
    composition shares them)."""

    __slots__ = ("R", "d", "V", "W", "c", "rot", "ident")

    def __init__(self, R=None, d=None, V=None, W=None, c=None, rot=None):
        self.R = _EYE if R is None else R
        self.d = _ZERO if d is None else d
        self.V = _ZERO if V is None else V
        self.W = _ZERO if W is None else W
        self.c = _ZERO if c is None else c
        self.rot = (R is not None or W is not None) if rot is None else rot
        self.ident = R is None and d is None and V is None and W is None and c is None

    def then(self, other: "Rigid") -> "Rigid":
        """Apply ``self`` first, then ``other`` (velocities combine as frames in motion).

        The identity and translations skip the products with R = I and the Ω × r of Ω = 0
        (the same values, up to the sign of a zero)."""
        if other.ident:
            return self
        # velocity of a point x = T_other(y), y moving with self: v = R_o v_self(y) + v_other(x)
        # expressed as V' + W' × (x − c'), with c' = T_other(c_self)
        if self.ident:
            if not other.rot:
                return Rigid(other.R, other.d, other.V, other.W, other.d, rot=False)
            return Rigid(other.R, other.d, other.V + _cross(other.W, other.d - other.c), other.W, other.d,
                         rot=True)
        if other.rot:
            Ro = other.R
            R = Ro @ self.R
            d = Ro @ self.d + other.d
            c = Ro @ self.c + other.d
            W = Ro @ self.W + other.W
            V = Ro @ self.V + other.V + _cross(other.W, c - other.c)
            return Rigid(R, d, V, W, c, rot=True)
        return Rigid(self.R, self.d + other.d, self.V + other.V, self.W, self.c + other.d, rot=self.rot)

    def apply(self, x0: np.ndarray):
        """Positions and velocities of points with initial positions x0."""
        x = x0 @ self.R.T + self.d
        v = self.V + np.cross(self.W, x - self.c)
        return x, v


def _angle_units(m) -> float:
    return math.pi / 180.0 if m.get("anglesunits", "degrees") == "degrees" else 1.0


def _segment(m: dict, tau: float, state: dict) -> Rigid:
    """Transform and velocity of one movement ``tau`` seconds after it started.

    ``state`` carries what DualSPHysics's active movement carries into the next one of the chain
    (JMotionMovActive::NextMov) at the end of this one: the linear speed of a rectilinear movement
    (``v``), the angular speed of a rotation or circular one (``w``), the advanced phases of a
    sinusoidal one (``phase3``: mvrectsinu; ``phase``: mvrotsinu, mvcirsinu); every other one is
    zero there (a mvrectace without <velini> after a rotation starts from rest, not from the last
    rectilinear speed; a mvrectsinu without <phase> after another goes on from its phase)."""
    kind = m["type"]
    carried = {"v": _ZERO, "w": 0.0, "phase3": _ZERO, "phase": 0.0}
    if kind in ("wait", "mvnull"):
        state.update(carried)
        return Rigid()
    if kind in ("mvrect", "mvrectace"):
        v0, a = _rect_params(m, state)
        d = v0 * tau + 0.5 * a * tau * tau
        v = v0 + a * tau
        state.update(carried, v=v)
        return Rigid(d=d, V=v)
    if kind in ("mvrot", "mvrotace", "mvcir", "mvcirace"):
        u = _angle_units(m)
        if kind in ("mvrot", "mvcir"):
            w0, al = m["vel"] * u, 0.0
        else:
            w0 = m["velini"] * u if "velini" in m else state.get("w", 0.0)
            al = m["ace"] * u
        angle = w0 * tau + 0.5 * al * tau * tau
        w = w0 + al * tau
        state.update(carried, w=w)
        return _rotational(m, angle, w, circular=kind.startswith("mvcir"), state=state)
    if kind == "mvrectsinu":
        f, A, ph = _rectsinu_params(m, state)
        arg = 2 * math.pi * f * tau + ph
        d = A * (np.sin(arg) - np.sin(ph))
        state.update(carried, phase3=np.where(A != 0.0, arg, ph))     # DualSPHysics advances moving axes only
        return Rigid(d=d, V=A * 2 * math.pi * f * np.cos(arg))
    if kind in ("mvrotsinu", "mvcirsinu"):
        u = _angle_units(m)
        f, A = m["freq"], m["ampl"] * u
        ph = m["phase"] * u if "phase" in m else state.get("phase", 0.0)
        arg = 2 * math.pi * f * tau + ph
        angle = A * (math.sin(arg) - math.sin(ph))
        w = A * 2 * math.pi * f * math.cos(arg)
        state.update(carried, phase=arg)
        return _rotational(m, angle, w, circular=kind == "mvcirsinu", state=state)
    if kind in ("mvrectfile", "mvrotfile"):
        state.update(carried)
        return _from_file(m, tau)
    if kind == "mvrotadvfile":
        state.update(carried)
        return _from_euler_file(m, tau)
    if kind == "mvpathfile":
        state.update(carried)
        return _from_path_file(m, tau)
    raise ValueError(f"unsupported movement {kind}")


def _rect_params(m: dict, state: dict) -> tuple:
    """(v0, a) of an ``mvrect`` (a = 0) or ``mvrectace`` (v0 the previous movement's speed without
    <velini>): d = v0 τ + a τ²/2."""
    if m["type"] == "mvrect":
        return np.asarray(m["vel"], float), np.zeros(3)
    v0 = np.asarray(m["velini"], float) if "velini" in m else state.get("v", np.zeros(3))
    return v0, np.asarray(m["ace"], float)


def _rectsinu_params(m: dict, state: dict) -> tuple:
    """(f, A, φ) of an ``mvrectsinu`` (φ the phase a previous sinusoidal movement reached without
    <phase>): d = A [sin(2π f τ + φ) − sin φ]."""
    f, A = np.asarray(m["freq"], float), np.asarray(m["ampl"], float)
    ph = (np.asarray(m["phase"], float) * _angle_units(m) if "phase" in m
          else np.asarray(state.get("phase3", np.zeros(3)), float))
    return f, A, ph


def _rotational(m, angle, w, circular, state=None) -> Rigid:
    """A rotation by ``angle`` (rate ``w``) about the axis through axisp1 and axisp2, in
    DualSPHysics's sense: its JMatrix4::MatrixRot(ang, p1, p2), which JMotionPos::Rotate applies,
    turns by −ang in the right-hand sense about p1 → p2 (MatrixRotY(ang), the right-hand
    rotation about +y, is MatrixRot(ang, 0, (0, −1, 0)) there); so a positive angle turns
    right-handed about p2 → p1.  (The SPHERIC Test 10 roll record, a positive angle about
    (0, −1, 0) → (0, 1, 0), then throws the water at the left wall when the experiment's
    sensor there records the impacts.)

    A circular movement translates the object by the turn of its reference point, which starts
    where the movement's last pass left it (``state["refs"]``, by movement id; the XML ``ref`` on
    the first pass): DualSPHysics's JMotionObj::ProcesTime turns the movement's own Ref axis and
    stores it back every step, so a circular movement looped by ``next`` closes its circle.  The
    moved point is stored in a new ``state["refs"]`` (the caller's copies are not changed)."""
    p1, p2, axis = _of_movement(m, "axis", _axis)
    R = _rotation(axis, angle)
    if not circular:
        return Rigid(R=R, d=p1 - R @ p1, W=w * axis, c=p1)
    refs = state.get("refs", {}) if state is not None else {}
    ref = refs.get(m.get("id"), np.asarray(m["ref"], float))
    moved = R @ (ref - p1) + p1
    if state is not None:
        state["refs"] = {**refs, m.get("id"): moved}
    vel = np.cross(w * axis, moved - p1)
    return Rigid(d=moved - ref, V=vel)


def _axis(m) -> tuple:
    """(p1, p2, unit vector p2 → p1) of a rotation's axisp1 and axisp2."""
    p1, p2 = np.asarray(m["axisp1"], float), np.asarray(m["axisp2"], float)
    return p1, p2, _unit(p1 - p2, f"{m['type']} id={m.get('id')}: axisp1 and axisp2")


_OF_MOVEMENT: dict = {}     # (what, id(movement)) -> (movement, value): what a movement's XML fixes


def _of_movement(m: dict, what: str, make):
    """``make(m)``, made once per movement (its XML does not change during a run)."""
    entry = _OF_MOVEMENT.get((what, id(m)))
    if entry is None or entry[0] is not m:
        entry = _OF_MOVEMENT[(what, id(m))] = (m, make(m))
    return entry[1]


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    """v / |v|; a zero (or non-finite) vector is an error of the case."""
    n = float(np.linalg.norm(v))
    if not (n > 0 and math.isfinite(n)):
        from .errors import CaseError
        raise CaseError(f"{what}: no direction (zero length)",
                        expected="two distinct points or a non-zero vector")
    return v / n


_FILE_CACHE: dict = {}


def file_columns(m) -> tuple[int, dict]:
    """(number of columns, {fieldtime/fieldx/...: 0-based column}) of a file movement."""
    from .case.datafiles import motion_file_columns
    given = {k: int(v) for k, v in m.get("fields", {}).items() if k != "fields"}
    return motion_file_columns(m["type"], given, m.get("ncols"))


def _load_table(m):
    """(table, {field: its column in the table}) of a file movement, read once per file (looked up
    once per movement)."""
    return _of_movement(m, "table", _read_table)


def _read_table(m):
    """(:class:`sphdvi.tables.TimeTable` of the file's used columns, {field: column}) of a file
    movement, from the file's cache (the columns contiguous, read once: a look-up does not copy them)."""
    ncols, cols = file_columns(m)
    key = (m["file"], ncols, tuple(sorted(cols.items())), m.get("reach"))
    if key not in _FILE_CACHE:
        from .case.datafiles import read_motion_table
        from .tables import TimeTable
        data = read_motion_table(m["file"], ncols, cols, f"<{m['type']}> file", m.get("reach"))
        names = [name for name in cols if name != "fieldtime"]
        table = TimeTable(data[:, cols["fieldtime"]], data[:, [cols[name] for name in names]])
        _FILE_CACHE[key] = (table, {name: k for k, name in enumerate(names)})
    return _FILE_CACHE[key]


def _file_values(table, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """Each file column's displacement from its first row and its rate ``tau`` seconds into the
    movement, as DualSPHysics's JMotionMovActive::DfGetNewPos/DfGetNewAng with JMotionObj::ProcesTime:
    the file's first row plays at the movement's start (its time looked up is τ + t_0), the
    value is interpolated linearly between rows and held at the last row; the rate is the step's
    displacement over dt there: the slope of the row segment that holds τ, 0 before the first
    row and from the last row on.  A repeated time is a step: the row found is the last of the
    repeated ones, so the segment is never of zero length (DfGetNewPos steps over it alike; at
    the repeated time itself it holds the first row's value, this look-up the last's).  One
    look-up in the table (its kept row) gives both."""
    t, cols = table.times, table.columns
    tf = tau + t[0]
    value = table.at(tf) - cols[:, 0]
    i = table.last
    if i < 0 or i >= t.size - 1:
        return value, np.zeros(cols.shape[0])
    return value, (cols[:, i + 1] - cols[:, i]) / (t[i + 1] - t[i])


def _from_file(m, tau) -> Rigid:
    """The transform of an ``mvrectfile`` (displacement per axis given in the file) or an
    ``mvrotfile`` (angle about its axis) ``tau`` seconds after it started (:func:`_file_values`)."""
    table, fields = _load_table(m)
    value, rate = _file_values(table, tau)
    if m["type"] == "mvrectfile":
        d = np.zeros(3)
        v = np.zeros(3)
        for k, name in enumerate(("fieldx", "fieldy", "fieldz")):
            if name in fields:
                d[k], v[k] = value[fields[name]], rate[fields[name]]
        return Rigid(d=d, V=v)
    units = _angle_units(m)
    c = fields["fieldang"]
    return _rotational(m, float(value[c]) * units, float(rate[c]) * units, circular=False)


_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}


def euler_turns(angles, axes: str, intrinsic: bool) -> list:
    """The three elementary turns of Euler angles, as (axis index, angle) in the order their
    matrices multiply, R = R_1 R_2 R_3 (each R_k right-handed about a coordinate axis, as
    DualSPHysics's JMatrix4 MatrixRotX/Y/Z): intrinsic ``axes`` "XYZ" with angles (a, b, c) is
    Rx(a) Ry(b) Rz(c) (each turn about the axes the earlier ones left); extrinsic (about the
    fixed axes, the first angle's turn applied first) Rz(c) Ry(b) Rx(a)."""
    turns = [(_AXIS_INDEX[a], float(x)) for a, x in zip(axes, angles)]
    return turns if intrinsic else turns[::-1]


def euler_matrix(angles, axes: str, intrinsic: bool) -> np.ndarray:
    """The rotation matrix of three Euler angles [rad] (:func:`euler_turns`)."""
    R = np.eye(3)
    for i, a in euler_turns(angles, axes, intrinsic):
        R = R @ _rotation(_EYE[i], a)
    return R


def euler_rate(angles, rates, axes: str, intrinsic: bool) -> np.ndarray:
    """The angular velocity ω (fixed axes) of Euler angles changing at ``rates``: with
    R = R_1 R_2 R_3, Ṙ Rᵀ = [ω]ₓ for ω = ȧ_1 e_1 + R_1 ȧ_2 e_2 + R_1 R_2 ȧ_3 e_3."""
    w = np.zeros(3)
    R = np.eye(3)
    for (i, a), (_, r) in zip(euler_turns(angles, axes, intrinsic), euler_turns(rates, axes, intrinsic)):
        w += r * R[:, i]
        R = R @ _rotation(_EYE[i], a)
    return w


def _from_euler_file(m, tau) -> Rigid:
    """An ``mvrotadvfile`` ``tau`` seconds after it started: the orientation its file's Euler angles
    give (each angle interpolated linearly, :func:`_file_values`), relative to its first row's, about
    ``center``: x = c + R(τ) R(0)ᵀ (x0 − c); an angle without a column stays 0."""
    table, fields = _load_table(m)
    value, rate = _file_values(table, tau)
    R, W = _euler_turn(m, table, fields, value, rate)
    c = np.asarray(m.get("center", (0.0, 0.0, 0.0)), float)
    return Rigid(R=R, d=c - R @ c, W=W, c=c)


def _euler_turn(m, table, fields, value, rate) -> tuple[np.ndarray, np.ndarray]:
    """(R(τ) R(0)ᵀ, Ω) of a file movement's Euler angles (``fieldang1``-``3``; one without a column
    stays 0) at the look-up ``value``, ``rate`` of :func:`_file_values`."""
    from .case.datafiles import EULER_FIELDS
    units = _angle_units(m)
    first, a, w = np.zeros(3), np.zeros(3), np.zeros(3)
    for k, name in enumerate(EULER_FIELDS):
        if name in fields:
            j = fields[name]
            first[k] = table.columns[j, 0] * units
            a[k], w[k] = first[k] + value[j] * units, rate[j] * units
    axes, intrinsic = m["axes"], bool(m["intrinsic"])
    R0 = _of_movement(m, "euler0", lambda _: euler_matrix(first, axes, intrinsic))
    return euler_matrix(a, axes, intrinsic) @ R0.T, euler_rate(a, w, axes, intrinsic)


def _from_path_file(m, tau) -> Rigid:
    """An ``mvpathfile`` ``tau`` seconds after it started: the displacement d of its file's
    positions from their first row (as ``mvrectfile``) and the turn R of its Euler angles from
    their first row's (as ``mvrotadvfile``) about ``center``.  With ``movecenter`` (the default) the
    centre travels along the path: x = c + d + R (x0 − c), v = ḋ + Ω × (x − (c + d)); without it
    the centre stays where it is and the travelled object turns about it:
    x = c + R (x0 + d − c), v = R ḋ + Ω × (x − c).  sphdvi's reading: DualSPHysics does not publish
    how it applies the file (column missing: 0)."""
    table, fields = _load_table(m)
    value, rate = _file_values(table, tau)
    d, dv = np.zeros(3), np.zeros(3)
    for k, name in enumerate(("fieldx", "fieldy", "fieldz")):
        if name in fields:
            d[k], dv[k] = value[fields[name]], rate[fields[name]]
    R, W = _euler_turn(m, table, fields, value, rate)
    c = np.asarray(m.get("center", (0.0, 0.0, 0.0)), float)
    if m.get("movecenter", True):
        return Rigid(R=R, d=c + d - R @ c, V=dv, W=W, c=c + d)
    return Rigid(R=R, d=c + R @ (d - c), V=R @ dv, W=W, c=c)


def chain_transform(chain: dict, t: float, walks: dict | None = None) -> Rigid:
    """Accumulated transform of an object's movements at time t: each of its events (``<begin>``,
    DualSPHysics's JMotionEvent) runs its own chain (:class:`_Walk`), and their transforms
    compose in order of their start (the reader admits several events only where that is
    DualSPHysics's motion: times that do not overlap, or overlapping translations).  ``walks``
    keeps each event's walk between calls (:class:`MotionSet`'s); without it the chains are walked
    from their start.  An event starts from the reference points of circular movements where the
    events before it left them (DualSPHysics's movements, and their Ref axes, belong to the object)."""
    events = chain.get("events") or ([chain["begin"]] if chain.get("begin") else [])
    walks = {} if walks is None else walks
    total = Rigid()
    refs: dict = {}
    for k, begin in sorted(enumerate(events), key=lambda e: e[1]["start"]):
        key = (id(chain), k)
        walk = walks.get(key) or walks.setdefault(key, _Walk(chain, begin))
        total = total.then(walk.at(t, refs))
        refs = walk.refs()
    return total


def _event_transform(chain: dict, begin: dict, t: float) -> Rigid:
    """Transform of the chain of movements that the event ``begin`` starts, at time t, walked from
    its start (:class:`_Walk`)."""
    return _Walk(chain, begin).at(t)


def _static(r: Rigid) -> Rigid:
    """The placement of ``r`` without its velocity (a movement that is over)."""
    if r.ident:
        return r
    return Rigid(r.R, r.d, c=r.c, rot=r.rot)


class _Walk:
    """Where the chain of movements of one event (``begin``: mov, start, finish) stands: the movement
    under way, its start ``t0``, the transform of the movements done before it and what they carried
    into it (:func:`_segment`'s ``state``, with the circular movements' reference points) -
    DualSPHysics's JMotionMovActive, advanced by JMotionObj::ProcesTime and NextMov.

    :meth:`at` goes on from there (a loop of movements costs the same per step at any time); for a
    time before the movement under way (a multibody substep, a predictor) it goes back to the last
    of the recent movement starts before that time, or to the event's start.  The walk is a
    function of t alone (the same sums in the same order whether it is walked at once or step by
    step), so a resumed run places the particles bitwise as the run it continues.  A movement of
    negative duration is a flash (JMotionMovActive::Flash): the displacement of |duration| seconds
    of it applied once t has passed its start, taking no time (the next movement starts then)."""

    MAX_MOVES = 1_000_000       # movements walked in one evaluation: a loop of vanishing durations
    HISTORY = 16                # recent movement starts kept to go back to

    def __init__(self, chain: dict, begin: dict):
        self.chain = chain
        self.movs = {m["id"]: m for m in chain["movements"]}
        self.start, self.finish = begin["start"], begin.get("finish")
        self.first = self.movs.get(begin["mov"])
        self.begun = False
        self.initial = None             # the walk at the event's start (set when it begins)
        self.history: list = []
        self._restore((self.first, self.start, Rigid(), {}, 0))

    def _snapshot(self) -> tuple:
        return (self.current, self.t0, self.done, self.state, self.stalled)

    def _restore(self, snap: tuple) -> None:
        self.current, self.t0, self.done, self.state, self.stalled = snap
        self.state = dict(self.state)
        self.seen = self.t0             # the latest t_end walked to
        self.final = None               # (transform, state, set by the finish) once the walk is over

    def refs(self) -> dict:
        """The reference points of the circular movements as the walk leaves them."""
        state = self.final[1] if self.final is not None else self.state
        return state.get("refs", {})

    def _t_end(self, t: float) -> float:
        return t if self.finish is None else min(t, self.finish)

    def _go_back(self, t: float, t_end: float) -> None:
        """Go back to a movement start before ``t_end`` where the walk stands after it (a time
        before the movement under way, or before the finish that ended the walk)."""
        if self.final is not None and self.final[2]:
            if t >= self.finish:
                return
        elif t_end >= self.seen or t_end > self.t0:
            return
        while self.history and not t_end > self.history[-1][1]:
            self.history.pop()
        self._restore(self.history[-1] if self.history else self.initial)

    def at(self, t: float, refs: dict | None = None) -> Rigid:
        """The event's transform at time t (at rest before its start, static after its chain or its
        ``finish`` is over); ``refs``: the circular movements' reference points where the object's
        earlier events leave them, taken when this event begins."""
        if t <= self.start:
            return Rigid()
        if not self.begun:
            self.begun = True
            self.state = {"refs": dict(refs)} if refs else {}
            self.initial = self._snapshot()
            self.state = dict(self.state)   # the snapshot keeps its own
        t_end = self._t_end(t)
        self._go_back(t, t_end)
        self.seen = max(self.seen, t_end)
        if self.final is not None:
            return self.final[0]
        over = self.finish is not None and t >= self.finish
        for _ in range(self.MAX_MOVES):
            cur = self.current
            if cur is None:
                self.final = (_static(self.done), self.state, False)
                return self.final[0]
            dur = cur["duration"]
            if dur < 0:                 # flash: applied once t has passed its start
                if t_end <= self.t0:
                    if over:
                        self.final = (_static(self.done), self.state, True)
                    return _static(self.done)
                self._advance(_segment(cur, -dur, self.state), self.t0, dur)
                continue
            t1 = self.t0 + dur
            if t_end < t1:
                state = dict(self.state)
                total = self.done.then(_segment(cur, t_end - self.t0, state))
                if over:
                    self.final = (_static(total), state, True)
                    return self.final[0]
                return total
            self._advance(_segment(cur, dur, self.state), t1, dur)
        raise self._error(f"more than a million movements before t={t:g} s (a loop of very short durations)",
                          "loops of movements lasting a reasonable time")

    def _advance(self, seg: Rigid, t1: float, dur: float) -> None:
        """Movement ``current`` done (its whole transform ``seg``): on to its next at t1."""
        self.done = self.done.then(_static(seg))
        self.t0 = t1
        self.stalled = self.stalled + 1 if dur <= 0 else 0
        if self.stalled > len(self.movs):
            raise self._error("the movements loop through next= without advancing time (their durations "
                              "add up to 0)", "a positive duration in every loop of movements")
        nxt = self.current.get("next")
        self.current = self.movs.get(nxt) if nxt is not None else None
        self.history.append(self._snapshot())
        del self.history[:-self.HISTORY]
        self.state = dict(self.state)   # the snapshot keeps its own

    def _error(self, what: str, expected: str):
        from .errors import CaseError
        return CaseError(f"motion of mkbound {self.chain.get('ref', '?')}: {what}", expected=expected)


def motion_transform(motion: dict, t: float, walks: dict | None = None) -> Rigid:
    """Transform of one ``objreal`` including its parent ``<obj>`` chains."""
    total = chain_transform(motion, t, walks)
    for parent in reversed(motion.get("parents", [])):
        total = total.then(chain_transform(parent, t, walks))
    return total


# ---------------------------------------------------------------------------
# wave paddles
# ---------------------------------------------------------------------------
def wave_number(period: float, depth: float, g: float = 9.81) -> float:
    """k from ω² = g k tanh(k d) (Newton iterations; k → ω²/g in deep water, ω/√(g d) in shallow)."""
    if not (period > 0 and depth > 0 and g > 0 and math.isfinite(period) and math.isfinite(depth)):
        raise ValueError(f"wave period {period} s and depth {depth} m must be positive and finite")
    omega = 2 * math.pi / period
    k = max(omega * omega / g, omega / math.sqrt(g * depth))
    for _ in range(100):
        t = math.tanh(k * depth)
        f = g * k * t - omega * omega
        df = g * t + g * k * depth * (1 - t * t)
        dk = f / df
        k -= dk
        if abs(dk) < 1e-15 * k:
            break
    return k


# The transfer functions are written with q = exp(-kd) so that they hold without overflow
# from shallow water to the deep-water limits (piston H/S -> 2, flap H/S -> 2 (1 - 1/kd)).
def piston_height_to_stroke(k: float, d: float) -> float:
    """Biesel transfer function of a piston: H/S = 2 (cosh 2kd − 1)/(sinh 2kd + 2kd)."""
    x = k * d
    e = math.exp(-2 * x)
    return 2 * math.expm1(-2 * x) ** 2 / (-math.expm1(-4 * x) + 4 * x * e)


def flap_height_to_stroke(k: float, d: float, draft: float = 0.0) -> float:
    """Transfer function H/S (S the stroke at the free surface) of a flap hinged ``draft`` below
    the bottom (DualSPHysics's ``<variabledraft>``: < 0 above it), from linear wavemaker theory
    (Dean & Dalrymple 1991 §6.2): H/S = 4 sinh kd/(sinh 2kd + 2kd) · k ∫ X(z)/S cosh k(d+z) dz over
    the water column, X(z)/S = (z + D)/D above the hinge (D = d + draft its depth) and 0 below it:

        H/S = 4 sinh kd/(sinh 2kd + 2kd) · [sinh kd − (cosh kd − cosh k u_b)/(k D)],  u_b = max(0, −draft),

    Biesel's 4 sinh kd/kd · (1 − cosh kd + kd sinh kd)/(sinh 2kd + 2kd) for a hinge at the bottom.
    Written with q = exp(−kd), the brackets' cosh kd − cosh k u_b = expm1(k u_b − kd) expm1(−k u_b − kd)/(2q),
    so that it holds without overflow in deep water."""
    depth = d + draft
    if not depth > 0:
        raise ValueError(f"the flap's hinge ({draft:g} m below the bottom) must lie below the still water "
                         f"(depth {d:g} m)")
    x = k * d
    xb = k * max(0.0, -draft)
    a = -math.expm1(-2 * x)          # 1 - q²
    b2 = math.expm1(xb - x) * math.expm1(-xb - x)
    return 2 * a * (a - b2 / (k * depth)) / (-math.expm1(-4 * x) + 4 * x * math.exp(-2 * x))


def _coth_over_sinh2(x: float) -> float:
    """cosh x / sinh³ x without overflow: 4 q² (1 + q²)/(1 − q²)³, q = exp(−x)."""
    q2 = math.exp(-2 * x)
    return 4 * q2 * (1 + q2) / (-math.expm1(-2 * x)) ** 3


class _Paddle:
    """What regular and irregular wave paddles share: a piston moves its particles along
    ``pistondir``; a flap turns them about the axis flapaxis0 → flapaxis1 by atan(X / hinge depth),
    X the stroke at the still-water level; the clock starts at ``start`` and stops after
    ``duration`` (0: never), where the paddle stays; a linear ramp over ``ramp_time`` seconds."""

    def _set_geometry(self, spec: dict) -> None:
        self.spec = spec
        self.kind = "piston" if spec["type"].startswith("piston") else "flap"
        self.start = spec.get("start", 0.0)
        self.duration = spec.get("duration", 0.0)
        self.gain = spec.get("gainstroke", 1.0)
        mk = spec.get("mkbound")
        if self.kind == "piston":
            direction = np.asarray(spec.get("pistondir", [1, 0, 0]), float)
            self.direction = _unit(direction, f"piston mkbound={mk}: <pistondir>")
        else:
            self.hinge_depth = spec["depth"] + spec.get("variabledraft", 0.0)
            p0, p1 = np.asarray(spec["flapaxis0"], float), np.asarray(spec["flapaxis1"], float)
            self.p0, self.axis = p0, _unit(p1 - p0, f"flap mkbound={mk}: <flapaxis0> and <flapaxis1>")

    def _height_to_stroke(self, k: float, d: float) -> float:
        """Biesel's H/S of this paddle for the wave number k in depth d (a flap's with its hinge
        ``variabledraft`` below the bottom)."""
        if self.kind == "piston":
            return piston_height_to_stroke(k, d)
        return flap_height_to_stroke(k, d, self.spec.get("variabledraft", 0.0))

    def _clock(self, t: float) -> tuple[float, bool]:
        """(τ, moving): the time since ``start`` held within [0, duration], and whether the
        paddle is moving at t."""
        tau = t - self.start
        if tau <= 0:
            return 0.0, False
        if self.duration > 0 and tau > self.duration:
            return self.duration, False
        return tau, True

    def _ramp(self, tau):
        if self.ramp_time <= 0 or tau >= self.ramp_time:
            return 1.0, 0.0
        return tau / self.ramp_time, 1.0 / self.ramp_time

    absorber = None     # a sphdvi.wave_absorption.PistonAbsorber when the piston absorbs (AWAS)
    face = 0.0          # the paddle's front face at rest, a coordinate along :attr:`heading` (:meth:`place`)

    @property
    def heading(self) -> np.ndarray:
        """The direction its waves run: a piston's ``pistondir``; +x for a flap."""
        return self.direction if self.kind == "piston" else _EYE[0]

    def place(self, face: float, check: bool = True) -> None:
        """Where the paddle's front face is at rest (a coordinate along :attr:`heading`), from which
        the distances of ``<savemotion xpos>`` are counted."""
        self.face = float(face)

    def place_on(self, positions: np.ndarray) -> None:
        """:meth:`place` the face at the largest coordinate along :attr:`heading` of the paddle's
        particles at rest (``positions``, none: left where it is)."""
        if len(positions):
            self.place(float((np.asarray(positions) @ self.heading).max()))

    def orbital_velocity(self, x: float, z: float, t):
        """The theory's (u along the heading, w up) at a distance ``x`` in front of the paddle and ``z``
        below the still water (negative), without the ramp and the evanescent modes."""
        raise NotImplementedError(f"no orbital velocity for a {self.spec['type']} paddle")

    def mean_position(self) -> float:
        """The theory's mean displacement once the ramp is over (m), about which the paddle moves."""
        return 0.0

    def drift_position(self, t: float) -> float:
        """The part of the theory's displacement at t that is a deliberate slow drift, not motion about
        :meth:`mean_position` (m): none here; a second-order irregular piston's subharmonic stroke."""
        return 0.0

    def theory_position(self, t: float):
        """The wave theory's paddle displacement at the free surface and its rate (m, m/s)."""
        tau, moving = self._clock(t)
        if tau == 0.0:
            return 0.0, 0.0
        x, v = self._series(tau)
        r, dr = self._ramp(tau)
        return r * x, (r * v + dr * x) if moving else 0.0

    def stroke_position(self, t: float):
        """Paddle displacement at the free surface and its rate (m, m/s): the theory's, plus the
        absorber's correction where the piston absorbs."""
        x, v = self.theory_position(t)
        if self.absorber is not None:
            x += self.absorber.offset
            v += self.absorber.velocity
        return x, v

    def target_elevation(self, x: float, t: float, order: int = 1) -> float:
        """The free-surface elevation the paddle means to make at a distance ``x`` in front of it at
        time t (:meth:`elevation` with the ramp; 0 before ``start`` and after ``duration``): the
        target of an absorbing piston."""
        tau, moving = self._clock(t)
        if not moving:
            return 0.0
        return self._ramp(tau)[0] * float(np.asarray(self.elevation(x, t, order)).reshape(-1)[0])

    def transform(self, t: float) -> Rigid:
        x, v = self.stroke_position(t)
        if self.kind == "piston":
            return Rigid(d=x * self.direction, V=v * self.direction)
        angle = math.atan2(x, self.hinge_depth)
        w = v * self.hinge_depth / (self.hinge_depth ** 2 + x * x)
        R = _rotation(self.axis, angle)
        return Rigid(R=R, d=self.p0 - R @ self.p0, W=w * self.axis, c=self.p0)


class WavePaddle(_Paddle):
    """Regular waves from a piston (displacement along ``pistondir``) or flap (rotation about
    its axis): ``<piston>``/``<flap>``; the ramp lasts ``ramp`` periods."""

    def __init__(self, spec: dict, g: float = 9.81):
        self._set_geometry(spec)
        d, H, T = spec["depth"], spec["waveheight"], spec["waveperiod"]
        self.omega = 2 * math.pi / T
        self.k = wave_number(T, d, g)
        self.height, self.depth = H, d
        self.phase = spec.get("phase", 0.0) * math.pi
        self.ramp_time = spec.get("ramp", 0.0) * T
        self.shift = self.ramp_time <= 0      # no ramp: the series starts from its value at τ = 0
        m1 = self._height_to_stroke(self.k, d)
        self.stroke = H / m1 * self.gain
        self.second = 0.0
        if spec.get("waveorder", 1) == 2:
            if self.kind == "piston":
                kd = self.k * d
                self.second = (H * H / (32 * d)) * (3 * _coth_over_sinh2(kd) - 2 / m1) * self.gain
            else:
                # DualSPHysics generates second-order waves with pistons only (Madsen 1971)
                warnings.warn("flap mkbound=%s: waveorder=2 is implemented for pistons only; "
                              "the flap moves with first-order theory" % spec.get("mkbound"))

    def elevation(self, x, t, order: int = 1) -> np.ndarray:
        """The progressive wave η(x, t) = H/2 cos θ, θ = ω τ + φ − k x, at a distance ``x`` in front of
        the paddle, without the ramp and the local evanescent modes (in phase with the paddle's
        velocity at x = 0); ``order`` 2 adds Stokes's second-order bound harmonic
        (π H²/8L) cosh kd (2 + cosh 2kd)/sinh³ kd cos 2θ (Dean & Dalrymple 1991 §11). H is the height
        the stroke makes: ``waveheight`` times ``gainstroke``, as the irregular paddle's."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        theta = self.omega * (t - self.start) + self.phase - self.k * float(x)
        H = self.height * self.gain
        eta = 0.5 * H * np.cos(theta)
        if order == 2:
            kd = self.k * self.depth
            eta = eta + (H * H * self.k / 16.0) * (2.0 + math.cosh(2 * kd)) * _coth_over_sinh2(kd) * np.cos(2 * theta)
        return eta

    def orbital_velocity(self, x: float, z: float, t):
        """(u, w) of the progressive wave of :meth:`elevation` at a distance ``x`` and ``z`` below the still
        water: a ω cosh k(z+d)/sinh kd cos θ, −a ω sinh k(z+d)/sinh kd sin θ (a = H/2), with ``order`` 2's
        Stokes term (3/16) H² ω k cosh 2k(z+d)/sinh⁴ kd cos 2θ (Dean & Dalrymple 1991 §11) when the
        paddle generates second order."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        theta = self.omega * (t - self.start) + self.phase - self.k * float(x)
        H = self.height * self.gain
        ch, sh = _depth_ratios(self.k, float(z), self.depth)
        u = 0.5 * H * self.omega * ch * np.cos(theta)
        w = -0.5 * H * self.omega * sh * np.sin(theta)
        if self.second:
            ch2, sh2 = _depth_ratios(2 * self.k, float(z), self.depth)
            # cosh 2k(z+d)/sinh⁴ kd = [cosh 2k(z+d)/sinh 2kd] · 2 coth kd/sinh² kd
            amp2 = 0.1875 * H * H * self.omega * self.k * 2.0 * _coth_over_sinh2(self.k * self.depth)
            u = u + amp2 * ch2 * np.cos(2 * theta)
            w = w - amp2 * sh2 * np.sin(2 * theta)
        return u, w

    def stroke_amplitude(self) -> float:
        """The theoretical stroke's amplitude S/2 (m)."""
        return 0.5 * self.stroke

    def max_acceleration(self) -> float:
        """The peak acceleration of the theoretical stroke, (S/2) ω² + 4 ω² |second-order term| (m/s²)."""
        return (0.5 * self.stroke + 4.0 * abs(self.second)) * self.omega ** 2

    def mean_position(self) -> float:
        """The theory's mean displacement once the ramp is over (m): 0 with a ramp, which starts the
        paddle from rest; without one −(S/2 sin φ + X2 sin 2φ), the series less its start value."""
        if not self.shift:
            return 0.0
        return -(0.5 * self.stroke * math.sin(self.phase) + self.second * math.sin(2 * self.phase))

    def _series(self, tau: float):
        """S/2 sin(ω τ + φ) + X2 sin 2(ω τ + φ) (φ ``phase`` π, X2 the second-order amplitude), plus
        :meth:`mean_position` (without a ramp the paddle starts where it is drawn, not with a jump)."""
        a = self.omega * tau + self.phase
        x = 0.5 * self.stroke * math.sin(a) + self.second * math.sin(2 * a) + self.mean_position()
        v = 0.5 * self.stroke * self.omega * math.cos(a) + self.second * 2 * self.omega * math.cos(2 * a)
        return x, v


class SpectrumPaddle(_Paddle):
    """Irregular long-crested waves from a piston or flap (``<piston_spectrum>``/``<flap_spectrum>``):
    the sea state's N linear waves (:func:`sphdvi.wavespectra.components`: amplitude
    a_i, frequency f_i, phase φ_i) each made by Biesel's stroke S_i = 2 a_i / (H/S)(k_i d), so that
    X(τ) = r(τ) [Σ S_i/2 sin(ω_i (τ + t0) + φ_i) + X2⁺(τ + t0) − X_0] + D(τ) (times ``gainstroke``),
    t0 = ``serieini``, r a linear ramp over ``ramptime`` seconds; X_0 the bracket's value at τ = 0
    without a ramp (the paddle starts where it is drawn), 0 with one (it starts from rest and moves
    about its rest position). On a piston with ``waveorder`` 2 only, X2⁺ is the superharmonic
    stroke and D the subharmonic drift, started from rest, that make the waves' bound sum- and
    difference-frequency waves without free ones (:mod:`sphdvi.wave_second_order`). The waves it
    makes at a distance x from the paddle are :meth:`elevation`."""

    def __init__(self, spec: dict, g: float = 9.81):
        comp = self._set_waves(spec, g)
        self._set_amplitudes(comp["amp"] * self.gain)
        self.phase = comp["phase"]
        self.t0 = spec.get("serieini", 0.0)
        self.ramp_time = spec.get("ramptime", 0.0)
        self._set_second_order(spec, g)
        self._set_start()

    def _set_waves(self, spec: dict, g: float) -> dict:
        """The paddle's geometry and the sea state's waves (:func:`sphdvi.wavespectra.components`):
        their frequencies ω_i and wave numbers k_i; returns the components."""
        from .wavespectra import components
        self._set_geometry(spec)
        comp = components(spec["spectrum"], spec["waveheight"], spec["waveperiod"], int(spec["waves"]),
                          spec["discretization"], spec["peakcoef"], int(spec["randomseed"]))
        self.components = comp
        self.omega = 2 * np.pi * comp["f"]
        self.k = np.array([wave_number(1.0 / f, spec["depth"], g) for f in comp["f"]])
        return comp

    def _set_amplitudes(self, amp: np.ndarray) -> None:
        """The waves' amplitudes a_i and Biesel's half strokes S_i/2 = a_i / (H/S)(k_i d) that make them."""
        d = self.spec["depth"]
        self.amp = amp
        self.height_to_stroke = np.array([self._height_to_stroke(k, d) for k in self.k])
        self.half_stroke = amp / self.height_to_stroke

    def _set_second_order(self, spec: dict, g: float) -> None:
        """``waveorder`` 2 on a piston: the stroke adds the second-order term that makes the waves'
        bound sum- and difference-frequency waves and no free ones
        (:class:`sphdvi.wave_second_order.SecondOrderSea`); ``gainstroke`` scales it with the rest of
        the stroke, as the regular piston's."""
        self.g = g
        self._sea = None
        self.second_order = spec.get("waveorder", 1) == 2 and self.kind == "piston"
        if self.second_order:
            self._sea = self._second_order_sea(with_paddle=True)

    def _set_start(self) -> None:
        """Once the phases are known: without a ramp the oscillating series is shifted by its start
        value so that the paddle starts from where it is drawn; with one (r(0) = 0) it moves about its
        rest position. A second-order piston's subharmonic drift starts from rest
        (:class:`sphdvi.wave_second_order.SubharmonicStroke`)."""
        self.offset = self._series_from_rest(0.0)[0] if self.ramp_time <= 0 else 0.0
        if self.second_order:
            from .wave_second_order import SubharmonicStroke
            a0 = self.complex_amplitudes() * np.exp(1j * self.omega * self.t0)
            self._drift = SubharmonicStroke(self._sea.paddle_diff / self.gain, a0, self.omega, self.ramp_time)

    def _second_order_sea(self, with_paddle: bool = False):
        """The sea's second-order kernels (built once; the paddle's with ``with_paddle``)."""
        if self._sea is None:
            from .wave_second_order import SecondOrderSea
            self._sea = SecondOrderSea(self.omega, self.spec["depth"],
                                       self.height_to_stroke if with_paddle else None, self.g)
        return self._sea

    def complex_amplitudes(self) -> np.ndarray:
        """A_n = a_n e^{iφ_n}: η1 = Re Σ A_n e^{i(ω_n (τ + t0) − k_n x)}."""
        return self.amp * np.exp(1j * self.phase)

    def mean_position(self) -> float:
        """The theory's mean displacement once the ramp is over (m): −(the series' value at serieini)
        without a ramp, 0 with one."""
        return -self.offset

    def _series_from_rest(self, tau: float):
        """The oscillating stroke: Σ S_i/2 sin(ω_i (τ + t0) + φ_i), plus on a second-order piston its
        superharmonic stroke, and its rate."""
        a = self.omega * (tau + self.t0) + self.phase
        x = float(np.dot(self.half_stroke, np.sin(a)))
        v = float(np.dot(self.half_stroke * self.omega, np.cos(a)))
        if self.second_order:
            x2, v2 = self._sea.superharmonic_stroke(self.complex_amplitudes(), tau + self.t0)
            x, v = x + float(x2) / self.gain, v + float(v2) / self.gain
        return x, v

    def _end_ramp(self, tau):
        """A ramp that brings the paddle back to rest at its end, and its rate: none here."""
        return 1.0, 0.0

    def theory_position(self, t: float):
        """The oscillating stroke under the ramps (:meth:`_Paddle.theory_position`), plus on a
        second-order piston its subharmonic drift from rest (under the end ramp)."""
        x, v = _Paddle.theory_position(self, t)
        if not self.second_order:
            return x, v
        tau, moving = self._clock(t)
        s, ds = self._drift_under_end_ramp(tau)
        return x + s, (v + ds) if moving else 0.0

    def _drift_under_end_ramp(self, tau: float):
        """A second-order piston's subharmonic drift D(τ) and its rate, under the end ramp (0 at τ = 0)."""
        if tau <= 0.0:
            return 0.0, 0.0
        s, ds = self._drift(tau)
        e, de = self._end_ramp(tau)
        return e * s, e * ds + de * s

    def drift_position(self, t: float) -> float:
        """A second-order piston's subharmonic drift at t."""
        if not self.second_order:
            return 0.0
        return self._drift_under_end_ramp(self._clock(t)[0])[0]

    def _series(self, tau: float):
        x, v = self._series_from_rest(tau)
        return x - self.offset, v

    def stroke_amplitude(self) -> float:
        """The stroke's significant amplitude 2σ, σ² = Σ (S_i/2)²/2 (as Hs/2 = 2σ of the elevation) (m)."""
        return 2.0 * math.sqrt(0.5 * float(np.sum(self.half_stroke ** 2)))

    def max_acceleration(self) -> float:
        """A bound on the stroke's acceleration, Σ (S_i/2) ω_i², plus on a second-order piston
        ½ Σ |G±_ij| a_i a_j (ω_i ± ω_j)² of its second-order term (m/s²)."""
        bound = float(np.sum(self.half_stroke * self.omega ** 2))
        if self.second_order:
            sea, a = self._sea, np.outer(self.amp, self.amp)
            w = self.omega
            bound += 0.5 * float(np.sum(np.abs(sea.paddle_sum) * a * np.add.outer(w, w) ** 2)
                                 + np.sum(np.abs(sea.paddle_diff) * a * np.subtract.outer(w, w) ** 2)) / self.gain
        return bound

    def elevation(self, x, t, order: int = 1) -> np.ndarray:
        """The linear progressive wave η(x, t) = Σ a_i cos(ω_i (τ + t0) + φ_i − k_i x) at a distance
        ``x`` [m] in front of the paddle (along its stroke), without the ramp and the local
        evanescent modes: what the paddle makes once the ramp is over and the waves have arrived;
        ``order`` 2 adds the waves' bound sum- and difference-frequency waves (Dean & Sharma 1981:
        :meth:`sphdvi.wave_second_order.SecondOrderSea.elevation`), as the regular paddle adds Stokes's."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tau = t - self.start
        a = np.outer(tau + self.t0, self.omega) + self.phase - self.k * float(x)
        eta = np.cos(a) @ self.amp
        if order == 2:
            eta = eta + self._second_order_sea().elevation(self.complex_amplitudes(), float(x), tau + self.t0)
        return eta

    def orbital_velocity(self, x: float, z: float, t):
        """(u, w) of the linear waves of :meth:`elevation` at a distance ``x`` and ``z`` below the still
        water: Σ a_i ω_i cosh k_i(z+d)/sinh k_i d cos θ_i, −Σ a_i ω_i sinh k_i(z+d)/sinh k_i d sin θ_i;
        a second-order piston's adds the bound waves' flow."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        a = np.outer(t - self.start + self.t0, self.omega) + self.phase - self.k * float(x)
        ch, sh = _depth_ratios(self.k, float(z), self.spec["depth"])
        u, w = np.cos(a) @ (self.amp * self.omega * ch), -(np.sin(a) @ (self.amp * self.omega * sh))
        if self.second_order:
            u2, w2 = self._sea.velocity(self.complex_amplitudes(), float(x), float(z), t - self.start + self.t0)
            u, w = u + u2, w + w2
        return u, w


def _depth_ratios(k, z: float, d: float):
    """cosh k(z+d)/sinh kd and sinh k(z+d)/sinh kd for z in [−d, 0], without overflow in deep water."""
    k = np.asarray(k, dtype=float)
    e = np.exp(k * z)                        # the deep-water decay, both ratios' limit
    q = np.exp(-2.0 * k * (z + d))
    r = 1.0 / (-np.expm1(-2.0 * k * d))
    return e * (1.0 + q) * r, e * (1.0 - q) * r


def group_velocity(omega, k, depth: float):
    """Linear waves' group velocity c_g = (ω/k)/2 · (1 + 2kd / sinh 2kd) (Dean & Dalrymple 1991 §4)."""
    omega, k = np.asarray(omega, float), np.asarray(k, float)
    kd2 = 2.0 * k * depth
    with np.errstate(over="ignore"):
        ratio = np.where(kd2 < 700.0, kd2 / np.sinh(np.minimum(kd2, 700.0)), 0.0)
    return 0.5 * omega / k * (1.0 + ratio)


def newwave_crest(hs: float, nwaves: float) -> float:
    """The crest of a NewWave group (Tromans, Anaturk & Hagemeijer 1991): the most probable largest
    crest of ``nwaves`` waves of a narrow-band sea of spectral height Hs, √(2 m0 ln N) with
    m0 = Hs²/16, i.e. Hs √(ln N / 8) (half the Rayleigh H_max = Hs √(ln N / 2))."""
    if not nwaves > 1:
        raise ValueError(f"the number of waves of the sea state must be above 1 (got {nwaves:g})")
    return hs * math.sqrt(math.log(nwaves) / 8.0)


class FocusedPaddle(SpectrumPaddle):
    """A focused wave group from a piston (``<piston_focused>``) (NewWave, Tromans et al. 1991;
    ``waveorder`` 2 adds the group's second-order stroke, as :class:`SpectrumPaddle`'s): the sea state's N linear waves (:func:`sphdvi.wavespectra.components`: the
    spectrum, its discretisation, ``waves``, ``peakcoef``) take amplitudes a_i = A E_i / Σ E_j (E_i the
    energy of wave i's bin, S(f_i) Δf_i) and phases that put every crest at the focus together:
    η(x, τ) = Σ a_i cos(ω_i (τ − t_f) − k_i (x − x_f) + φ_f), A = :func:`newwave_crest` of
    ``waveheight`` (Hs) over ``maxwaveh nwaves`` waves (1000), or over ``maxwaveh time`` / Tz
    waves (Tz = √(m0/m2) of the components), φ_f = ``fphase`` (degrees; 0: a crest, 180: a
    trough). Each wave is made by Biesel's stroke, as :class:`SpectrumPaddle` (``gainstroke`` scales
    it).

    x_f is ``xf``, a coordinate along ``pistondir``; the distance to the focus is counted from the
    piston's front face at rest (:meth:`place`, the run's start; 0 until then). The focus time
    t_f = ``fpretime`` + (x_f − face) / c_g,min after ``start``: the extra time, plus the time the
    slowest group (the highest frequency's) takes to reach the focus, so that every wave has
    left the paddle before the group forms. (DualSPHysics's own rule for t_f is not published;
    this is sphdvi's.) A linear ramp over ``ramptime`` starts the motion from rest; ``fmovtime``
    (seconds after ``start``, 0: never) stops the paddle, the motion ramped down to the piston's
    rest position over the ``fmovramp`` seconds before it (0: it stops where it is)."""

    def __init__(self, spec: dict, g: float = 9.81):
        comp = self._set_waves(spec, g)
        energy = comp["amp"] ** 2
        maxwaveh = spec.get("maxwaveh") or {"nwaves": 1000}
        if "time" in maxwaveh:
            m0, m2 = float(np.sum(energy)), float(np.sum(energy * comp["f"] ** 2))
            self.nwaves = float(maxwaveh["time"]) / math.sqrt(m0 / m2)
        else:
            self.nwaves = float(maxwaveh["nwaves"])
        self.crest = newwave_crest(spec["waveheight"], self.nwaves)
        self._set_amplitudes(self.crest * energy / float(np.sum(energy)) * self.gain)
        cg = group_velocity(self.omega, self.k, spec["depth"])
        self.cg_min, self.cg_max = float(np.min(cg)), float(np.max(cg))
        self.xf = float(spec["xf"])
        self.fphase = math.radians(spec.get("fphase", 0.0))
        self.pretime = spec.get("fpretime", 5.0)
        self.t0 = 0.0
        self.ramp_time = spec.get("ramptime", 0.0)
        self.fmovtime = spec.get("fmovtime", 0.0)
        self.fmovramp = min(spec.get("fmovramp", 0.0), self.fmovtime) if self.fmovtime > 0 else 0.0
        if self.fmovtime > 0:
            self.duration = self.fmovtime if self.duration <= 0 else min(self.duration, self.fmovtime)
        self._set_second_order(spec, g)
        self.place(0.0, check=False)

    def place(self, face: float, check: bool = True) -> None:
        """Count the distance to the focus from ``face``, the piston's front face along ``pistondir``
        at rest: sets the focus distance, the focus time and the waves' phases (ValueError with
        ``check``: the focus is not in front of the face)."""
        self.face = float(face)
        self.distance = self.xf - self.face
        if check and not self.distance > 0:
            raise ValueError(f"the focus xf={self.xf:g} m is not in front of the piston's face at {self.face:g} m "
                             f"along its direction")
        self.focus_time = self.pretime + self.distance / self.cg_min
        self.phase = self.k * self.distance - self.omega * self.focus_time + self.fphase
        self._set_start()

    def _end_ramp(self, tau):
        """The end ramp (``fmovramp`` before ``fmovtime``) and its rate."""
        if self.fmovramp > 0 and tau > self.fmovtime - self.fmovramp:
            e = max(0.0, (self.fmovtime - tau) / self.fmovramp)
            return e, (-1.0 / self.fmovramp if e > 0 else 0.0)
        return 1.0, 0.0

    def _ramp(self, tau):
        """The start ramp (``ramptime``) times the end ramp, and its rate."""
        r, dr = SpectrumPaddle._ramp(self, tau)
        e, de = self._end_ramp(tau)
        return r * e, dr * e + r * de

    def elevation_at(self, x: float, t, order: int | None = None) -> np.ndarray:
        """η at the coordinate ``x`` along ``pistondir`` (the focus is at x = ``xf``), without the ramps,
        to ``order`` (the paddle's ``waveorder`` by default: a second-order group's with its bound waves)."""
        return self.elevation(float(x) - self.face, t, self.spec.get("waveorder", 1) if order is None else order)

    def focus_crest(self, order: int | None = None) -> float:
        """The crest at the focus: A at first order; at second order the largest of :meth:`elevation_at`
        there within half a peak period of the focus time (sampled every Tp/2000)."""
        order = self.spec.get("waveorder", 1) if order is None else order
        if order == 1:
            return self.crest
        tp = float(self.spec["waveperiod"])
        t = self.start + self.focus_time + np.linspace(-0.5, 0.5, 2001) * tp
        return float(np.max(self.elevation_at(self.xf, t, order)))


SOLITARY_THEORIES = {1: "Rayleigh", 2: "Boussinesq", 3: "KdV"}
GORING_THETA = 3.8        # Goring (1978): the motion spans tanh θ from -0.999 to 0.999


def solitary_wave(theory: int, H: float, h: float, g: float = 9.81) -> tuple[float, float]:
    """(κ, c) of the solitary wave η = H sech²(κ (x − c t)) in depth h: Rayleigh (Serre 1953)
    κ = √(3H / (4h²(h + H))), c = √(g(h + H)); Boussinesq (Goring 1978) κ = √(3H/4h³),
    c = √(g(h + H)); KdV κ = √(3H/4h³), c = √(gh) (1 + H/2h)."""
    if theory == 1:
        return math.sqrt(3 * H / (4 * h * h * (h + H))), math.sqrt(g * (h + H))
    if theory == 2:
        return math.sqrt(3 * H / (4 * h ** 3)), math.sqrt(g * (h + H))
    if theory == 3:
        return math.sqrt(3 * H / (4 * h ** 3)), math.sqrt(g * h) * (1 + H / (2 * h))
    raise ValueError(f"solitary-wave theory {theory} (expected 1, 2 or 3)")


class _SolitaryStroke:
    """One solitary wave from a piston (Goring 1978): the piston moves with the wave's
    depth-averaged velocity, dX/dt = c η/(h + η) at X. With η = H sech²θ, θ = κ(c t − X) − θ_e,
    dX/dθ = η/(κh), so X(θ) = (H/κh)(tanh θ + tanh θ_e), t(θ) = (θ + θ_e + κ X(θ))/(κ c): exact for
    each theory's κ and c. θ runs from −θ_e to θ_e, θ_e chosen so that the motion lasts
    ``durationcoef`` times Goring's T = 2(3.8 + H/h)/(κc); t(θ) is inverted by Newton's method."""

    def __init__(self, theory: int, H: float, h: float, durationcoef: float, start: float, g: float):
        self.H, self.h, self.start = H, h, start
        self.kappa, self.c = solitary_wave(theory, H, h, g)
        self.duration = durationcoef * 2 * (GORING_THETA + H / h) / (self.kappa * self.c)
        target, e = 0.5 * self.kappa * self.c * self.duration, GORING_THETA
        for _ in range(50):             # θ_e + (H/h) tanh θ_e = κ c T / 2
            step = (e + H / h * math.tanh(e) - target) / (1 + H / h / math.cosh(e) ** 2)
            e -= step
            if abs(step) < 1e-14 * max(1.0, e):
                break
        self.theta_e = e
        self.amp = H / (self.kappa * h)
        self.stroke = self.amp * 2 * math.tanh(e)

    def _theta(self, tau: float) -> float:
        """θ at the time τ since this wave's start (Newton on κcτ = θ + θ_e + κX(θ))."""
        target = self.kappa * self.c * tau - self.theta_e - self.kappa * self.amp * math.tanh(self.theta_e)
        th = min(max(target, -self.theta_e), self.theta_e)
        r = self.H / self.h
        for _ in range(60):
            step = (th + r * math.tanh(th) - target) / (1 + r / math.cosh(th) ** 2)
            th -= step
            if abs(step) < 1e-15 * max(1.0, abs(th)):
                break
        return th

    def position(self, t: float) -> tuple[float, float]:
        """Displacement and velocity of the piston at time t (0 before the start, the stroke after)."""
        tau = t - self.start
        if tau <= 0:
            return 0.0, 0.0
        if tau >= self.duration:
            return self.stroke, 0.0
        th = self._theta(tau)
        eta = self.H / math.cosh(th) ** 2
        return self.amp * (math.tanh(th) + math.tanh(self.theta_e)), self.c * eta / (self.h + eta)

    def crest(self) -> tuple[float, float]:
        """Where (from the piston's rest position) and when the crest leaves the piston (θ = 0)."""
        x = self.amp * math.tanh(self.theta_e)
        return x, self.start + (self.theta_e + self.kappa * x) / (self.kappa * self.c)


class SolitaryPaddle(_Paddle):
    """Solitary waves from a piston (``<piston_solitary>``): ``waves`` strokes of
    :class:`_SolitaryStroke`, each starting ``startcoef`` times the previous one's duration
    after it; their displacements add up.  Theories 1 Rayleigh, 2 Boussinesq (Goring's, the
    default), 3 KdV (:func:`solitary_wave`)."""

    def __init__(self, spec: dict, g: float = 9.81):
        self._set_geometry(spec)
        self.g = g
        self.ramp_time = 0.0
        self.duration = 0.0                 # each stroke stops by itself
        self.depth = spec["depth"]
        self.strokes = []
        start = 0.0
        for w in spec["solitary"]:
            if self.strokes:
                start += w["startcoef"] * self.strokes[-1].duration
            self.strokes.append(_SolitaryStroke(int(spec.get("theory", 2)), w["waveheight"], self.depth,
                                                w["durationcoef"], start, g))

    def _series(self, tau: float):
        x = v = 0.0
        for s in self.strokes:
            dx, dv = s.position(tau)
            x, v = x + dx, v + dv
        return x, v

    def elevation(self, x, t, order: int = 1) -> np.ndarray:
        """The solitary waves' η(x, t) = Σ H sech²(κ(x − x_c − c(τ − τ_c))) at a distance ``x`` in
        front of the piston's rest position, each crest leaving the piston at x_c, τ_c
        (:meth:`_SolitaryStroke.crest`); no interaction between the waves."""
        tau = np.atleast_1d(np.asarray(t, dtype=float)) - self.start
        eta = np.zeros_like(tau)
        for s in self.strokes:
            xc, tc = s.crest()
            eta += s.H / np.cosh(s.kappa * (float(x) - xc - s.c * (tau - tc))) ** 2
        return eta


def make_paddle(spec: dict, g: float = 9.81) -> _Paddle:
    """The paddle of a ``<wavepaddles>`` entry."""
    if spec["type"] == "piston_solitary":
        return SolitaryPaddle(spec, g)
    if spec["type"] == "piston_focused":
        return FocusedPaddle(spec, g)
    return SpectrumPaddle(spec, g) if spec["type"].endswith("_spectrum") else WavePaddle(spec, g)


class MotionSet:
    """All imposed motions of a case: ``transforms(t)`` → {mkbound: Rigid}."""

    def __init__(self, motions: list, wavepaddles: list | None = None, g: float = 9.81):
        self.motions = {m["ref"]: m for m in motions}
        self._walks: dict = {}          # each event's walk along its chain (chain_transform)
        self.paddles = {p["mkbound"]: make_paddle(p, g) for p in (wavepaddles or [])}

    @property
    def mkbounds(self):
        return sorted(set(self.motions) | set(self.paddles))

    def place_paddles(self, pos: np.ndarray, labels: np.ndarray) -> None:
        """Tell each paddle where its front face is at rest (a focused piston counts its focus from it,
        every paddle its ``<savemotion xpos>``): the largest coordinate along its :attr:`heading` of
        its particles (``labels``: each particle's mkbound, -1 for fluid)."""
        for mkb, paddle in self.paddles.items():
            paddle.place_on(pos[labels == mkb])

    def place_paddles_from_particles(self, p: dict, fluidcount: int) -> None:
        """:meth:`place_paddles` from a particle set (``pos``, ``type``, ``mk``: GenCase's global mk,
        the boundary labels mk − fluidcount − 1)."""
        from .coupling import body_labels
        self.place_paddles(p["pos"], np.where(p["type"] != 3, body_labels(p["mk"], fluidcount), -1))

    def transform(self, mkbound: int, t: float) -> Rigid:
        base = motion_transform(self.motions[mkbound], t, self._walks) if mkbound in self.motions else Rigid()
        if mkbound in self.paddles:
            base = base.then(self.paddles[mkbound].transform(t))
        return base

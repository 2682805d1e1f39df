"""The multibody system: bodies, shapes, materials, links and the time step.

One call to :meth:`System.step` performs one Anitescu–Tasora step
(Chrono's EULER_IMPLICIT_LINEARIZED):

1. free velocity  ``v_free = v + h M⁻¹ (f_ext + m g − ω×Jω)``;
2. collision detection at the current pose, contact rows, joint rows,
   spring-damper rows (springs, joint stiffness/damping: implicit compliance
   rows, or fixed explicit impulses where that is stable), boxed rows
   (Coulomb dampers), motor and imposed-velocity rows;
3. one CCP solve (PSOR, APGD or BB) for the impulses γ, warm started;
4. ``v⁺ = v_free + M⁻¹ Dᵀ γ``, then ``x += h v⁺``, ``q ← q ⊗ exp(h ω⁺_body)``.
"""

import warnings

import numpy as np

from . import collision as col
from . import rows as rw
from ._math import (body_rotations, frame_from_axis, integrate_bodies, np_mat_to_quat,
                    np_quat_to_mat)
from ._kernels import (apply_dof_masks, copy_state, gather_warm, prepare_live_rows, scatter_warm,
                       step_end, step_free, step_start)
from .solvers import (SOLVER_ALIASES, SOLVER_NAMES, max_abs_diff, prepare_rows, row_residuals,
                      scatter_impulses, sliding_speeds, solve_ccp, solve_direct, solve_iterative)

FLOATING = 0
FIXED = 1
MOVING = 2
_BODY_KINDS = {"floating": FLOATING, "free": FLOATING, "fixed": FIXED, "moving": MOVING}

# consecutive steps with the solver's residual above System.residual_warning before it warns
RESIDUAL_WARN_STEPS = 10
# a change of the sliding term below this many times the solver's residual ends the sliding
# passes (System._solve_rows): it is the unconverged solve's noise, not sliding
SLIDING_RES_FACTOR = 2.0

_MATE_MASKS = {
    # (tx, ty, tz, rx, ry, rz) constrained = 1; the free axis of a joint is z
    "fixed": (1, 1, 1, 1, 1, 1),
    "lock": (1, 1, 1, 1, 1, 1),
    "spherical": (1, 1, 1, 0, 0, 0),
    "spheric": (1, 1, 1, 0, 0, 0),
    "hinge": (1, 1, 1, 1, 1, 0),
    "revolute": (1, 1, 1, 1, 1, 0),
    "slider": (1, 1, 0, 1, 1, 1),
    "prismatic": (1, 1, 0, 1, 1, 1),
    "cylindrical": (1, 1, 0, 1, 1, 0),
    "hingedslider": (1, 1, 0, 1, 1, 0),
    "pointline": (1, 1, 0, 0, 0, 0),
    "pointplane": (0, 0, 1, 0, 0, 0),
    "planar": (0, 0, 1, 1, 1, 0),
}


_SPRING_SCHEMES = {"auto": rw.SPRING_AUTO, "implicit": rw.SPRING_IMPLICIT,
                   "explicit": rw.SPRING_EXPLICIT}


def _as_table(v):
    """A constant, a callable f(t) or a table [[t, value], ...] -> callable or float."""
    if v is None:
        return 0.0
    if callable(v):
        return v
    a = np.asarray(v, dtype=np.float64)
    if a.ndim == 0:
        return float(a)
    from ..tables import TimeTable              # contiguous columns, a kept row: O(1) per step
    return TimeTable.of_rows(a.reshape(-1, 2)).value


def _eval(v, t):
    return v(t) if callable(v) else v


ZERO_INERTIA = 1e-12    # principal moments below this fraction of the largest count as none


def free_inverse_inertia(I, R, rotation_dof, name="body"):
    """The body-frame inverse of the inertia tensor ``I`` of a floating body, inverted on the
    rotations it has inertia for only (a pseudo-inverse): a principal moment below
    ZERO_INERTIA of the largest (a 2D body's I_xx, I_zz; a body whose particles lie on a line)
    gives no rotation about its axis, i.e. that rotation is locked (DualSPHysics inverts the
    tensor as given, JSphCpuSingle::FtCalcForces, and a singular one is unusable there).  A
    locked axis (``rotation_dof``, world axes at the orientation ``R``) needs no moment; a free
    one is warned about (the reader refuses a zero moment given in <inertia> about a free axis)."""
    lam, V = np.linalg.eigh(np.asarray(I, dtype=np.float64))
    top = float(lam.max())
    zero = lam <= ZERO_INERTIA * top if top > 0 else np.ones(3, bool)
    if not zero.any():
        return np.linalg.inv(I)
    inv = (V * np.where(zero, 0.0, 1.0 / np.where(zero, 1.0, lam))) @ V.T
    free = np.asarray(rotation_dof, float)
    for k in np.flatnonzero(zero):
        axis = np.asarray(R, float) @ V[:, k]
        if np.any(np.abs(axis) * free > 1e-6):
            warnings.warn(f"floating body {name} has no moment of inertia about the axis "
                          f"({', '.join(f'{x:.3g}' for x in axis)}) (principal moment {lam[k]:.3g}, "
                          f"below {ZERO_INERTIA:g} of the largest, {top:.3g}): its rotation about that axis is "
                          "locked")
    return inv


class System:
    """A rigid multibody system (no fluid).

    Parameters
    ----------
    gravity : 3 floats (world).
    solver : "psor" | "apgd" | "bb" (iterative, matrix-free) or "direct"
        (bilateral rows eliminated by a dense Cholesky factorisation, the
        remaining contact rows by a dense projected gradient; for small,
        stiff or badly scaled mechanisms).
    max_iter, tol : iteration limit and residual tolerance (m/s, see
        :mod:`sphdvi.dvi.solvers`).
    exact_joints : with psor, apgd or bb, solve the islands that hold only joints (and the
        compliance rows of springs, dampers and motors: a linear system) exactly, by the
        Cholesky factorisation of ``direct``, and only the islands with contacts or bounded rows
        iteratively (:func:`sphdvi.dvi.solvers.solve_iterative`); False: every row iterative.
    omega : PSOR relaxation.
    recovery_speed : max penetration/violation recovery speed (m/s).
    envelope : collision envelope (m): contacts are created for gaps below it.
    min_bounce_speed : restitution applies only where the rebound speed e·|v_n| exceeds it
        (m/s; Chrono's ChSystem default 0.15, compared as ChContactNSC does).
    sliding_passes : CCP solves per step at most for the sliding correction (0: none, the
        plain convexified CCP of Chrono NSC, whose sliding contacts lift off at μ‖v_t‖/(1+μ²)):
        each contact's normal row gets ``+ μ‖v_t‖`` (De Saxcé; Chrono::Multicore's Build_s),
        ``v_t`` first the smaller of the warm start's prediction and the pre-step value,
        then the previous pass's solution (warm-started re-solve) until it changes by less
        than ``sliding_tol`` (m/s) or twice the solver's residual (:meth:`_solve_rows`).
    residual_warning : a solver residual (m/s) above this for RESIDUAL_WARN_STEPS steps in a
        row (an unconverged or infeasible problem: imposed velocities driving into a wall,
        conflicting joints) is warned about once per such episode (``take_warnings``).
    contactmethod : "nsc" (complementarity) or "smc" (penalty, Hertz/Hooke).
    smc_model : "hertz" or "hooke".
    position_projection : after each step, project the positions back onto
        the rigid joint constraints (minimum mass-weighted displacement,
        Chrono's EULER_IMPLICIT_PROJECTED idea; one extra solve).  Removes
        the O(h²v²/L) drift of the velocity-level stabilisation.

    After a step, ``link_force``/``link_torque`` (nlinks, 3) hold each link's reaction on body
    1 in the world frame, the torque about the link point on body 1 (a spring's or damper's
    element force on body 1, its preload included): the opposite sign of Chrono's
    ChLink::GetReaction2 (the wrench on body 2, in link frame 2) and of the ADAMS Rforce that
    Chrono's joint tests compare it with (audit g: Revolute_Case01 at t = 0.96 s, ADAMS
    (−9.110, 0, −25.679), sphdvi (9.094, 0, 25.693)).  links.csv writes them as they are.
    """

    def __init__(self, gravity=(0.0, 0.0, -9.81), solver="bb", max_iter=100, tol=1e-10,
                 omega=1.0, recovery_speed=0.6, envelope=0.002, min_bounce_speed=0.15,
                 contactmethod="nsc", smc_model="hertz", position_projection=False,
                 spring_integration="auto", sliding_passes=4, sliding_tol=1e-4,
                 residual_warning=0.1, exact_joints=True):
        self.gravity = np.asarray(gravity, dtype=np.float64)
        key = str(solver).lower().replace("_", "").replace("-", "")
        if key not in SOLVER_ALIASES:
            raise ValueError(f"unknown solver {solver!r}; use psor, apgd, bb or direct")
        self.solver = SOLVER_ALIASES[key]
        self.max_iter = int(max_iter)
        self.tol = float(tol)
        self.exact_joints = bool(exact_joints)
        self.omega = float(omega)
        self.recovery_speed = float(recovery_speed)
        self.envelope = float(envelope)
        self.min_bounce_speed = float(min_bounce_speed)
        self.sliding_passes = int(sliding_passes)
        self.sliding_tol = float(sliding_tol)
        self.residual_warning = float(residual_warning)
        self.pending_warnings = []      # lines for run.log (take_warnings)
        self.defer_warnings = False     # True: only queued (a run loop logs and prints them)
        self._res_high = 0              # consecutive steps with the residual above residual_warning
        self._res_warned = False
        self._preload_links = []        # (link, force on body 1, torque about its centre) of preload-only springs
        if isinstance(contactmethod, (int, np.integer)):  # DualSPHysics: 0 = NSC, 1 = SMC
            contactmethod = ("nsc", "smc")[int(contactmethod)]
        self.contactmethod = str(contactmethod)
        self.smc_model = smc_model
        self.position_projection = bool(position_projection)
        key = str(spring_integration).lower()
        if key not in _SPRING_SCHEMES:
            raise ValueError(f"unknown spring_integration {spring_integration!r}; "
                             "use auto, implicit or explicit")
        self.spring_integration = key
        self.time = 0.0
        self.last_iterations = 0
        self.last_residual = 0.0
        self.n_contacts = 0
        # bodies
        self.names = []
        self.kind = np.zeros(0, np.int32)
        self.mass = np.zeros(0)
        self.inv_mass = np.zeros(0)
        self.I_b = np.zeros((0, 3, 3))
        self.inv_I_b = np.zeros((0, 3, 3))
        self.pos = np.zeros((0, 3))
        self.quat = np.zeros((0, 4))
        self.vel = np.zeros((0, 3))
        self.omega_b = np.zeros((0, 3))
        self.f_ext = np.zeros((0, 3))
        self.t_ext = np.zeros((0, 3))
        self.dof_mask = np.zeros((0, 6))
        self.imposed = np.zeros((0, 6))
        self._motion = []
        self._imposed_fn = []
        self._load_fn = []          # (body, t -> (force, torque)) of time-dependent external loads
        # materials (index 0 = default)
        self.mat_names = ["default"]
        self.mat_mu = np.array([0.3])
        self.mat_e = np.array([0.0])
        self.mat_E = np.array([1e7])
        self.mat_nu = np.array([0.3])
        # shapes
        self.sh_body = np.zeros(0, np.int32)
        self.sh_type = np.zeros(0, np.int32)
        self.sh_pos = np.zeros((0, 3))
        self.sh_R = np.zeros((0, 3, 3))
        self.sh_dims = np.zeros((0, 3))
        self.sh_mat = np.zeros(0, np.int32)
        self.sh_rad = np.zeros(0)
        self.samp_off = np.zeros(0, np.int32)
        self.samp_cnt = np.zeros(0, np.int32)
        self.samp_rad = np.zeros(0)
        self.samp_pts = np.zeros((0, 3))
        self.samp_nrm = np.zeros((0, 4))     # cloud particles: outward normal, flag (col.cloud_surface)
        self.pl_off = np.zeros(0, np.int32)
        self.pl_cnt = np.zeros(0, np.int32)
        self.planes = np.zeros((0, 4))
        self.cg_meta = np.zeros((0, 8))
        self.cg_start = np.zeros(0, np.int64)
        self.edges = np.zeros((0, 2), np.int32)
        self.ed_off = np.zeros(0, np.int32)
        self.ed_cnt = np.zeros(0, np.int32)
        self.ed_rep = np.zeros(0, np.int32)     # per edge: first parallel edge (_edge_classes)
        # face polygons of box/hull planes (per plane of ``planes``): vertex indices (local to
        # the shape) counter-clockwise about the outward normal, and the shape-local edge index
        # of each polygon edge (fv[k] → fv[k+1]; -1: not in the edge list)
        self.fv_off = np.zeros(0, np.int32)
        self.fv_cnt = np.zeros(0, np.int32)
        self.fv_idx = np.zeros(0, np.int32)
        self.fv_edge = np.zeros(0, np.int32)
        # links
        self.links = []          # python records, index = link id
        self._mates = []
        self._springs = []
        self._dampers = []
        self._pulleys = []
        self._packed = False
        # warm start and results
        self._prev_keys = np.zeros(0, np.int64)
        self._prev_g3 = np.zeros((0, 3))
        self._prev_link_gamma = np.zeros(0)
        self._prev_h = None
        self._cap_rows = 0
        self._w_vpred = np.zeros((0, 6))    # sliding correction: velocities the warm start predicts
        self._cap_contacts = 256
        self._cap_pairs = 1024
        self._work_shape = None         # (bodies, links, shapes) the step's work arrays are sized for
        self.contact_force = np.zeros((0, 3))
        self.contact_torque = np.zeros((0, 3))
        self.fluid_force = np.zeros((0, 3))     # the fluid's load of the last step (set by the coupling)
        self.fluid_torque = np.zeros((0, 3))
        self.total_force = np.zeros((0, 3))
        self.total_torque = np.zeros((0, 3))
        self.link_force = np.zeros((0, 3))
        self.link_torque = np.zeros((0, 3))

    # ------------------------------------------------------------- bodies
    @property
    def nb(self):
        return self.mass.shape[0]

    def add_body(self, mass=1.0, inertia=(1.0, 1.0, 1.0), pos=(0, 0, 0), quat=(1, 0, 0, 0),
                 vel=(0, 0, 0), omega=(0, 0, 0), kind="floating", translation_dof=(1, 1, 1),
                 rotation_dof=(1, 1, 1), motion=None, imposed_velocity=None, name=None,
                 force=(0, 0, 0), torque=(0, 0, 0), external_load=None):
        """Add a rigid body and return its index.

        inertia: principal values (3,) or a full tensor (3, 3) about the centre
        of mass, in the body frame.  pos/quat: centre of mass and orientation
        (w, x, y, z).  vel, omega: initial velocities (world frame).
        kind: "floating", "fixed" or "moving" (kinematic: velocities from
        ``motion(t) -> (v_world, omega_world)`` or kept constant).
        translation_dof/rotation_dof: 1 = free, 0 = locked (world axes).
        imposed_velocity: 6 values (v, ω world), None/NaN = free component;
        or a callable t -> 6 values.  force/torque: constant external load
        (world; torque about the centre); external_load: a callable t -> (force,
        torque) replacing them at each step's end time (DualSPHysics's
        <linearforce>/<angularforce> tables)."""
        k = _BODY_KINDS[kind] if isinstance(kind, str) else int(kind)
        if k == FIXED and (np.any(np.asarray(vel, float) != 0) or np.any(np.asarray(omega, float) != 0)):
            raise ValueError(f"body {name if name is not None else self.nb}: a fixed body cannot have a "
                             f"velocity (vel={tuple(vel)}, omega={tuple(omega)}); use kind='moving' "
                             "for a body that moves on its own")
        I = np.asarray(inertia, dtype=np.float64)
        if I.ndim == 1:
            I = np.diag(I)
        q = np.asarray(quat, dtype=np.float64)
        q = q / np.linalg.norm(q)
        R = np_quat_to_mat(q)
        dyn = k == FLOATING
        self.kind = np.append(self.kind, np.int32(k)).astype(np.int32)
        self.mass = np.append(self.mass, float(mass))
        self.inv_mass = np.append(self.inv_mass, 1.0 / mass if dyn and mass > 0 else 0.0)
        self.I_b = np.concatenate([self.I_b, I[None]])
        inv_I = (free_inverse_inertia(I, R, rotation_dof, name if name is not None else f"body{self.nb}")
                 if dyn else np.zeros((3, 3)))
        self.inv_I_b = np.concatenate([self.inv_I_b, inv_I[None]])
        self.pos = np.vstack([self.pos, np.asarray(pos, float)[None]])
        self.quat = np.vstack([self.quat, q[None]])
        mask = np.concatenate([np.asarray(translation_dof, float), np.asarray(rotation_dof, float)])
        v = np.asarray(vel, float) * (mask[:3] if dyn else 1.0)
        w = np.asarray(omega, float) * (mask[3:] if dyn else 1.0)
        self.vel = np.vstack([self.vel, v[None]])
        self.omega_b = np.vstack([self.omega_b, (R.T @ w)[None]])
        self.f_ext = np.vstack([self.f_ext, np.asarray(force, float)[None]])
        self.t_ext = np.vstack([self.t_ext, np.asarray(torque, float)[None]])
        self.dof_mask = np.vstack([self.dof_mask, mask[None]])
        imp = np.full(6, np.nan)
        fn = None
        if callable(imposed_velocity):
            fn = imposed_velocity
        elif imposed_velocity is not None:
            imp = np.array([np.nan if c is None else float(c) for c in imposed_velocity])
        self.imposed = np.vstack([self.imposed, imp[None]])
        self._imposed_fn.append(fn)
        if external_load is not None:
            self._load_fn.append((self.nb - 1, external_load))
        self._motion.append(motion)
        self._packed = False
        self.names.append(name if name is not None else f"body{self.nb - 1}")
        for a in ("contact_force", "contact_torque", "fluid_force", "fluid_torque"):
            setattr(self, a, np.vstack([getattr(self, a), np.zeros((1, 3))]))
        # before the first step the total load is the applied one
        f0 = np.asarray(force, float) + (float(mass) * self.gravity if dyn else 0.0)
        self.total_force = np.vstack([self.total_force, f0[None]])
        self.total_torque = np.vstack([self.total_torque, np.asarray(torque, float)[None]])
        return self.nb - 1

    def set_external_load(self, body, force=None, torque=None):
        """Set the persistent external force/torque (world; torque about centre)."""
        if force is not None:
            self.f_ext[body] = force
        if torque is not None:
            self.t_ext[body] = torque

    # ---------------------------------------------------------- materials
    def add_material(self, name=None, friction=0.3, restitution=0.0, young=1e7, poisson=0.3):
        """Add a contact material; returns its index.  Pair rule: the friction
        and the restitution of a contact are the minimum of the two values;
        SMC combines Young's moduli and Poisson ratios into E*."""
        self.mat_names.append(name or f"mat{len(self.mat_names)}")
        self.mat_mu = np.append(self.mat_mu, float(friction))
        self.mat_e = np.append(self.mat_e, float(restitution))
        self.mat_E = np.append(self.mat_E, float(young))
        self.mat_nu = np.append(self.mat_nu, float(poisson))
        return len(self.mat_names) - 1

    def material_index(self, m):
        if m is None:
            return 0
        if isinstance(m, str):
            return self.mat_names.index(m)
        return int(m)

    # -------------------------------------------------------------- shapes
    def add_shape(self, body, shape, size=(0, 0, 0), pos=(0, 0, 0), quat=(1, 0, 0, 0),
                  material=None, points=None, radius=0.0, local=True, plane_normal=None):
        """Attach a collision shape to ``body`` (-1: the world).

        shape: "sphere" (size=(r,)), "box" (size = half extents), "capsule"
        (r, half length along local z), "cylinder" (r, half length along z),
        "plane" (solid below local z = 0; use :meth:`add_plane`), "hull"
        (``points`` = vertices of a mesh, convex hull taken), "cloud"
        (``points`` = sphere centres, ``radius``; collided as their smooth
        surface, :func:`collision.cloud_surface`; ``plane_normal``: the plane of
        a 2-D case).  pos/quat: shape pose in the body frame (``local=True``)
        or in the world frame."""
        t = col.SHAPE_NAMES[shape] if isinstance(shape, str) else int(shape)
        size = np.atleast_1d(np.asarray(size, float)).ravel()[:3]
        dims = np.zeros(3)
        dims[: len(size)] = size
        q = np.asarray(quat, float)
        Rl = np_quat_to_mat(q / np.linalg.norm(q))
        p = np.asarray(pos, float)
        if not local and body >= 0:
            Rb = np_quat_to_mat(self.quat[body])
            p = Rb.T @ (p - self.pos[body])
            Rl = Rb.T @ Rl
        samples = np.zeros((0, 3))
        srad = 0.0
        planes = np.zeros((0, 4))
        edges = np.zeros((0, 2), np.int64)
        if t == col.SPHERE:
            samples = np.zeros((1, 3))
            srad = dims[0]
            crad = dims[0]
        elif t == col.BOX:
            s = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
            samples = s * dims
            crad = float(dims.min())
            # vertex index = 4a + 2b + c (a, b, c = coordinate > 0); edges flip one bit
            edges = np.array([(v, v | bit) for v in range(8) for bit in (1, 2, 4) if not v & bit])
            planes = np.array([[sg * (k == 0), sg * (k == 1), sg * (k == 2), -dims[k]]
                               for k in range(3) for sg in (1.0, -1.0)], float)
        elif t == col.CAPSULE:
            samples = np.array([[0, 0, -dims[1]], [0, 0, 0], [0, 0, dims[1]]], float)
            srad = dims[0]
            crad = dims[0]
        elif t == col.CYLINDER:
            a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
            ring = np.column_stack([dims[0] * np.cos(a), dims[0] * np.sin(a), np.zeros_like(a)])
            samples = np.vstack([ring + [0, 0, -dims[1]], ring + [0, 0, dims[1]]])
            crad = dims[0]
        elif t == col.PLANE:
            crad = 1e6
        elif t == col.HULL:
            from scipy.spatial import ConvexHull, QhullError
            pts = np.asarray(points, float).reshape(-1, 3)
            try:
                hull = ConvexHull(pts)
            except QhullError:
                who = self.names[body] if 0 <= body < self.nb else "the world"
                raise ValueError(
                    f"hull shape {self.sh_type.shape[0]} of body {body} ({who!r}): its {len(pts)} "
                    f"points are coplanar or collinear (or fewer than 4): a hull needs points "
                    f"that span a 3-D solid (a thin plate is a box with a small half extent)") from None
            samples = pts[hull.vertices]
            planes = self._merge_facets(hull.equations)
            edges = self._hull_edges(hull)
            crad = 0.5 * float(np.min(samples.max(0) - samples.min(0)))
        elif t == col.CLOUD:
            dims[0] = radius if radius > 0 else dims[0]
            samples, snrm, dims[1] = col.cloud_surface(points, dims[0], plane_normal)
            srad = dims[0]
            crad = dims[0]
            samples, meta, starts = self._cloud_grid(np.hstack([samples, snrm]), dims[0])
            samples, snrm = samples[:, :3].copy(), samples[:, 3:].copy()
        else:
            raise ValueError(f"unknown shape {shape!r}")
        self.sh_body = np.append(self.sh_body, np.int32(body)).astype(np.int32)
        self.sh_type = np.append(self.sh_type, np.int32(t)).astype(np.int32)
        self.sh_pos = np.vstack([self.sh_pos, p[None]])
        self.sh_R = np.concatenate([self.sh_R, Rl[None]])
        self.sh_dims = np.vstack([self.sh_dims, dims[None]])
        self.sh_mat = np.append(self.sh_mat, np.int32(self.material_index(material))).astype(np.int32)
        self.sh_rad = np.append(self.sh_rad, crad)
        self.samp_off = np.append(self.samp_off, np.int32(self.samp_pts.shape[0])).astype(np.int32)
        self.samp_cnt = np.append(self.samp_cnt, np.int32(samples.shape[0])).astype(np.int32)
        self.samp_rad = np.append(self.samp_rad, srad)
        self.samp_pts = np.vstack([self.samp_pts, samples])
        self.samp_nrm = np.vstack([self.samp_nrm, snrm if t == col.CLOUD else np.zeros((samples.shape[0], 4))])
        self.pl_off = np.append(self.pl_off, np.int32(self.planes.shape[0])).astype(np.int32)
        self.pl_cnt = np.append(self.pl_cnt, np.int32(planes.shape[0])).astype(np.int32)
        self.planes = np.vstack([self.planes, planes])
        if t == col.CLOUD:
            meta[7] = self.cg_start.shape[0]
            self.cg_start = np.concatenate([self.cg_start, starts])
        else:
            meta = np.zeros(8)
        self.cg_meta = np.vstack([self.cg_meta, meta[None]])
        self.ed_off = np.append(self.ed_off, np.int32(self.edges.shape[0])).astype(np.int32)
        self.ed_cnt = np.append(self.ed_cnt, np.int32(edges.shape[0])).astype(np.int32)
        self.edges = np.vstack([self.edges, np.asarray(edges, np.int32).reshape(-1, 2)])
        self.ed_rep = np.append(self.ed_rep, self._edge_classes(samples, edges)).astype(np.int32)
        for f_idx, f_edge in self._face_polygons(samples, planes, edges):
            self.fv_off = np.append(self.fv_off, np.int32(self.fv_idx.shape[0])).astype(np.int32)
            self.fv_cnt = np.append(self.fv_cnt, np.int32(len(f_idx))).astype(np.int32)
            self.fv_idx = np.append(self.fv_idx, np.asarray(f_idx, np.int32)).astype(np.int32)
            self.fv_edge = np.append(self.fv_edge, np.asarray(f_edge, np.int32)).astype(np.int32)
        return self.sh_type.shape[0] - 1

    @staticmethod
    def _edge_classes(verts, edges):
        """Per edge of a box or hull: the index of the first edge parallel to it (its own
        index if none), so that the separating-axis test tries each pair of edge directions
        once (collision._polytope_sat)."""
        edges = np.asarray(edges, np.int64).reshape(-1, 2)
        d = verts[edges[:, 1]] - verts[edges[:, 0]] if edges.shape[0] else np.zeros((0, 3))
        rep = np.arange(edges.shape[0], dtype=np.int32)
        ln = np.linalg.norm(d, axis=1)
        for k in range(1, edges.shape[0]):
            par = np.linalg.norm(np.cross(d[:k], d[k]), axis=1) <= 1e-12 * ln[:k] * ln[k]
            par &= rep[:k] == np.arange(k)
            if par.any():
                rep[k] = int(np.argmax(par))
        return rep

    @staticmethod
    def _face_polygons(verts, planes, edges):
        """Per facet plane (n, d) of a box or hull: the vertices on it (|n·v + d| small),
        ordered counter-clockwise about n (by angle about their centroid), and the index in
        ``edges`` of each polygon edge (-1 where it is none: a vertex on an edge's line)."""
        out = []
        if planes.shape[0] == 0:
            return out
        ext = float(np.ptp(verts, axis=0).max()) if verts.shape[0] else 1.0
        emap = {(int(min(a, b)), int(max(a, b))): k for k, (a, b) in enumerate(np.asarray(edges))}
        for pl in planes:
            n = pl[:3]
            on = np.nonzero(np.abs(verts @ n + pl[3]) < 1e-7 * max(ext, 1e-300))[0]
            c = verts[on].mean(axis=0)
            u = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
            u /= np.linalg.norm(u)
            w = np.cross(n, u)
            d = verts[on] - c
            f_idx = on[np.argsort(np.arctan2(d @ w, d @ u), kind="stable")]
            f_edge = [emap.get((int(min(a, b)), int(max(a, b))), -1)
                      for a, b in zip(f_idx, np.roll(f_idx, -1))]
            out.append((f_idx, f_edge))
        return out

    @staticmethod
    def _hull_edges(hull):
        """Edges of a convex hull (indices into hull.vertices order), without
        the diagonals of coplanar (merged) facets."""
        remap = {int(v): i for i, v in enumerate(hull.vertices)}
        eq = hull.equations
        out = set()
        for si, simp in enumerate(hull.simplices):
            for m in range(3):
                nb = hull.neighbors[si, m]
                if 1.0 - float(eq[si, :3] @ eq[nb, :3]) < 1e-9:
                    continue  # shared by coplanar triangles: not a real edge
                a, b = (int(simp[k]) for k in range(3) if k != m)
                out.add((min(remap[a], remap[b]), max(remap[a], remap[b])))
        return np.array(sorted(out), np.int64).reshape(-1, 2)

    @staticmethod
    def _cloud_grid(pts, r):
        """Body-frame cell grid of a sphere cloud (cell = 2r): points sorted by
        cell, meta = (origin xyz, cell size, nx, ny, nz, base), cell starts.
        Columns past the third (per-point data) are sorted along."""
        cs = max(2.0 * r, 1e-12)
        org = pts[:, :3].min(axis=0) - 1e-9
        ijk = np.floor((pts[:, :3] - org) / cs).astype(np.int64)
        nxyz = ijk.max(axis=0) + 1
        cid = (ijk[:, 0] * nxyz[1] + ijk[:, 1]) * nxyz[2] + ijk[:, 2]
        order = np.argsort(cid, kind="stable")
        ncell = int(np.prod(nxyz))
        starts = np.searchsorted(cid[order], np.arange(ncell + 1)).astype(np.int64)
        meta = np.array([org[0], org[1], org[2], cs, nxyz[0], nxyz[1], nxyz[2], 0.0])
        return pts[order], meta, starts

    @staticmethod
    def _merge_facets(eq):
        out = []
        for e in eq:
            if not any(np.allclose(e, o, atol=1e-9) for o in out):
                out.append(e)
        return np.array(out)

    def add_sphere(self, body, radius, **kw):
        return self.add_shape(body, "sphere", (radius,), **kw)

    def add_box(self, body, half_extents, **kw):
        return self.add_shape(body, "box", half_extents, **kw)

    def add_capsule(self, body, radius, half_length, **kw):
        return self.add_shape(body, "capsule", (radius, half_length), **kw)

    def add_cylinder(self, body, radius, half_length, **kw):
        return self.add_shape(body, "cylinder", (radius, half_length), **kw)

    def add_hull(self, body, vertices, **kw):
        return self.add_shape(body, "hull", points=vertices, **kw)

    def add_cloud(self, body, points, radius, **kw):
        return self.add_shape(body, "cloud", points=points, radius=radius, **kw)

    def add_plane(self, point=(0, 0, 0), normal=(0, 0, 1), body=-1, material=None):
        """Half-space (solid on the side opposite to ``normal``), world frame."""
        F = frame_from_axis(normal)
        q = np_mat_to_quat(F)
        return self.add_shape(body, "plane", pos=point, quat=q, material=material, local=False) \
            if body >= 0 else self.add_shape(-1, "plane", pos=point, quat=q, material=material)

    # --------------------------------------------------------------- links
    def _body_pose(self, i):
        if i < 0:
            return np.zeros(3), np.eye(3)
        return self.pos[i].copy(), np_quat_to_mat(self.quat[i])

    def add_link(self, kind, body1, body2=-1, **kw):
        """Add a link between body1 and body2 (-1 = ground); returns the link id.

        kind: "fixed", "spherical", "hinge"/"revolute", "slider"/"prismatic",
        "cylindrical"/"hingedslider", "pointline", "pointplane", "planar",
        "generic" (keyword ``mask`` = 6 flags tx ty tz rx ry rz), "spring"
        (TSDA), "coulombdamper", "pulley".  See :meth:`add_mate`,
        :meth:`add_spring`, :meth:`add_coulomb_damper`, :meth:`add_pulley`."""
        k = kind.lower().replace("link_", "").replace("_", "")
        if k in ("spring", "tsda", "linearspring"):
            return self.add_spring(body1, body2, **kw)
        if k in ("coulombdamper", "coulombdamping"):
            return self.add_coulomb_damper(body1, body2, **kw)
        if k == "pulley":
            return self.add_pulley(body1, body2, **kw)
        if k == "generic":
            mask = kw.pop("mask")
            return self.add_mate(body1, body2, mask=mask, **kw)
        return self.add_mate(body1, body2, mask=_MATE_MASKS[k], kind=k, **kw)

    def add_mate(self, body1, body2=-1, point=(0, 0, 0), axis=(0, 0, 1), mask=(1, 1, 1, 1, 1, 1),
                 point2=None, frame=None, rot_axis=None, rot_axis2=None, stiffness=0.0,
                 damping=0.0, rest=0.0, motor=None, motor_dof=None, motor_target=0.0,
                 kind="generic", name=None):
        """Generic joint between frame 1 on body1 and frame 2 on body2.

        point: world position of the joint (both markers coincide unless
        ``point2`` is given); axis: world z axis of the joint frame (hinge
        axis, slider direction, point-line line); frame: full world frame (3x3,
        columns) instead of ``axis``.  mask: constrained DOFs (tx, ty, tz, rx,
        ry, rz) in the joint frame.  For "pointline" the rotations are free
        unless ``rot_axis`` (DualSPHysics ``rotvector``: only rotation about it
        allowed) and optionally ``rot_axis2`` (``rotvector2``: a second free
        rotation axis) are given.
        stiffness/damping: on the free DOFs (spring-damper rows, implicit or
        explicit as ``spring_integration`` says); a
        constant, a table [[t, v], ...] or a callable f(t) for all free DOFs,
        or a dict {dof: value} (dof 0..5 or "tx".."rz"); rest: rest
        coordinate(s) (scalar for all free DOFs, or 6 values).
        Coordinates are frame-1-in-frame-2 (rotation angles, unwrapped on
        single-axis joints).  motor: "angle"/"position" or "speed" applied to
        ``motor_dof`` (default: rotation z for hinges, translation z for
        sliders) with ``motor_target`` a constant, table or callable f(t)."""
        F = np.asarray(frame, float) if frame is not None else frame_from_axis(axis)
        Frot = F
        mask = [int(m) for m in mask]
        if kind == "pointline" and rot_axis is not None:
            if rot_axis2 is None:
                Frot = frame_from_axis(rot_axis)
                mask[3:] = [1, 1, 0]
            else:
                Frot = frame_from_axis(rot_axis, hint=rot_axis2)
                mask[3:] = [0, 1, 0]  # free about rotvector (z) and rotvector2 (x)
        P = np.asarray(point, float)
        P2 = np.asarray(point2, float) if point2 is not None else P
        x1, R1 = self._body_pose(body1)
        x2, R2 = self._body_pose(body2)
        lid = len(self.links)
        stiff = self._per_dof(stiffness)
        damp = self._per_dof(damping)
        restv = np.zeros(6) + (np.asarray(rest, float) if np.ndim(rest) else 0.0)
        if np.ndim(rest) == 0 and rest != 0.0:
            for k in range(6):
                if mask[k] == 0:
                    restv[k] = rest
        mmode = np.zeros(6, np.int32)
        mtarget = [0.0] * 6
        if motor is not None:
            if motor_dof is None:
                motor_dof = 5 if mask[5] == 0 else 2
            mmode[motor_dof] = rw.MOTOR_POSITION if motor in ("angle", "position") else rw.MOTOR_SPEED
            mtarget[motor_dof] = _as_table(motor_target)
        rec = dict(type="mate", kind=kind, lid=lid, b1=body1, b2=body2,
                   p1=R1.T @ (P - x1), p2=R2.T @ (P2 - x2), T1=R1.T @ F, T2=R2.T @ F,
                   Q1=R1.T @ Frot, Q2=R2.T @ Frot, mask=np.array(mask, np.int8),
                   k=stiff, c=damp, rest=restv, mmode=mmode, mtarget=mtarget,
                   name=name or f"{kind}{lid}")
        self._add_link_record(rec)
        self._mates.append(rec)
        self._packed = False
        return lid

    def _add_link_record(self, rec):
        self.links.append(rec)
        self.link_force = np.zeros((len(self.links), 3))
        self.link_torque = np.zeros((len(self.links), 3))

    _DOF_NAMES = {"tx": 0, "ty": 1, "tz": 2, "rx": 3, "ry": 4, "rz": 5}

    @classmethod
    def _per_dof(cls, v):
        """A value for all free DOFs, or a dict {dof: value} with dof an index
        0..5 or a name tx, ty, tz, rx, ry, rz (joint frame)."""
        if isinstance(v, dict):
            out = [0.0] * 6
            for k, x in v.items():
                out[cls._DOF_NAMES.get(k, k) if isinstance(k, str) else int(k)] = _as_table(x)
            return out
        t = _as_table(v)
        return [t] * 6

    def add_spring(self, body1, body2=-1, point1=(0, 0, 0), point2=(0, 0, 0), stiffness=0.0,
                   damping=0.0, rest_length=None, preload=0.0, name=None):
        """Linear spring-damper (TSDA) between world points point1 (on body1)
        and point2 (on body2): F = f0 − k(l − l0) − c l̇ along the line,
        positive pushing the bodies apart.  Implicit (compliance row) where
        it is stiff for the step, explicit where that is stable with margin
        (``System(spring_integration=...)``: auto, implicit or explicit).
        k and c may be constants, tables [[t, v], ...] or callables."""
        P1 = np.asarray(point1, float)
        P2 = np.asarray(point2, float)
        x1, R1 = self._body_pose(body1)
        x2, R2 = self._body_pose(body2)
        l0 = float(np.linalg.norm(P1 - P2)) if rest_length is None else float(rest_length)
        lid = len(self.links)
        rec = dict(type="spring", lid=lid, b1=body1, b2=body2, p1=R1.T @ (P1 - x1),
                   p2=R2.T @ (P2 - x2), k=_as_table(stiffness), c=_as_table(damping),
                   l0=l0, f0=float(preload), name=name or f"spring{lid}")
        self._add_link_record(rec)
        self._springs.append(rec)
        self._packed = False
        return lid

    def add_coulomb_damper(self, body1, body2=-1, point1=(0, 0, 0), point2=(0, 0, 0),
                           force=0.0, name=None):
        """Coulomb damper: a friction force of constant magnitude ``force``
        opposing the relative speed along point1–point2 (boxed row)."""
        P1 = np.asarray(point1, float)
        P2 = np.asarray(point2, float)
        x1, R1 = self._body_pose(body1)
        x2, R2 = self._body_pose(body2)
        lid = len(self.links)
        rec = dict(type="coulomb", lid=lid, b1=body1, b2=body2, p1=R1.T @ (P1 - x1),
                   p2=R2.T @ (P2 - x2), F=float(force), name=name or f"coulombdamper{lid}")
        self._add_link_record(rec)
        self._dampers.append(rec)
        self._packed = False
        return lid

    def add_pulley(self, body1, body2, axis=(0, 0, 1), axis2=None, radius=1.0, radius2=1.0,
                   name=None):
        """Pulley/belt: r1 ω1·a1 = r2 ω2·a2 (world axes at creation)."""
        a1 = np.asarray(axis, float) / np.linalg.norm(axis)
        a2 = a1 if axis2 is None else np.asarray(axis2, float) / np.linalg.norm(axis2)
        _, R1 = self._body_pose(body1)
        _, R2 = self._body_pose(body2)
        lid = len(self.links)
        rec = dict(type="pulley", lid=lid, b1=body1, b2=body2, a1=R1.T @ a1, a2=R2.T @ a2,
                   r1=float(radius), r2=float(radius2), name=name or f"pulley{lid}")
        self._add_link_record(rec)
        self._pulleys.append(rec)
        self._packed = False
        return lid

    # ------------------------------------------------------------- packing
    def _pack(self):
        M = self._mates
        nm = len(M)
        self.m_b1 = np.array([m["b1"] for m in M], np.int32)
        self.m_b2 = np.array([m["b2"] for m in M], np.int32)
        self.m_p1 = np.array([m["p1"] for m in M], float).reshape(nm, 3)
        self.m_p2 = np.array([m["p2"] for m in M], float).reshape(nm, 3)
        self.m_T1 = np.array([m["T1"] for m in M], float).reshape(nm, 3, 3)
        self.m_T2 = np.array([m["T2"] for m in M], float).reshape(nm, 3, 3)
        self.m_Q1 = np.array([m["Q1"] for m in M], float).reshape(nm, 3, 3)
        self.m_Q2 = np.array([m["Q2"] for m in M], float).reshape(nm, 3, 3)
        self.m_mask = np.array([m["mask"] for m in M], np.int8).reshape(nm, 6)
        self.m_k = np.zeros((nm, 6))
        self.m_c = np.zeros((nm, 6))
        self.m_rest = np.array([m["rest"] for m in M], float).reshape(nm, 6)
        self.m_mmode = np.array([m["mmode"] for m in M], np.int32).reshape(nm, 6)
        self.m_mval = np.zeros((nm, 6))
        self.m_mdval = np.zeros((nm, 6))
        if not hasattr(self, "m_angle") or self.m_angle.shape[0] != nm:
            self.m_angle = np.zeros((nm, 3))
        self.m_lid = np.array([m["lid"] for m in M], np.int32)
        self.m_P1w = np.zeros((nm, 3))
        self._mate_timedep = [(i, k) for i, m in enumerate(M) for k in range(6)
                              if callable(m["k"][k]) or callable(m["c"][k])]
        for i, m in enumerate(M):
            for k in range(6):
                self.m_k[i, k] = 0.0 if callable(m["k"][k]) else m["k"][k]
                self.m_c[i, k] = 0.0 if callable(m["c"][k]) else m["c"][k]
        self._motors = [(i, k) for i, m in enumerate(M) for k in range(6) if m["mmode"][k] != 0]
        S = self._springs
        ns = len(S)
        self.s_b1 = np.array([s["b1"] for s in S], np.int32)
        self.s_b2 = np.array([s["b2"] for s in S], np.int32)
        self.s_p1 = np.array([s["p1"] for s in S], float).reshape(ns, 3)
        self.s_p2 = np.array([s["p2"] for s in S], float).reshape(ns, 3)
        self.s_k = np.array([0.0 if callable(s["k"]) else s["k"] for s in S], float)
        self.s_c = np.array([0.0 if callable(s["c"]) else s["c"] for s in S], float)
        self.s_l0 = np.array([s["l0"] for s in S], float)
        self.s_f0 = np.array([s["f0"] for s in S], float)
        self.s_lid = np.array([s["lid"] for s in S], np.int32)
        self.s_P1w = np.zeros((ns, 3))
        self.s_len = np.zeros(ns)
        D = self._dampers
        nd = len(D)
        self.d_b1 = np.array([s["b1"] for s in D], np.int32)
        self.d_b2 = np.array([s["b2"] for s in D], np.int32)
        self.d_p1 = np.array([s["p1"] for s in D], float).reshape(nd, 3)
        self.d_p2 = np.array([s["p2"] for s in D], float).reshape(nd, 3)
        self.d_F = np.array([s["F"] for s in D], float)
        self.d_lid = np.array([s["lid"] for s in D], np.int32)
        self.d_P1w = np.zeros((nd, 3))
        P = self._pulleys
        npu = len(P)
        self.p_b1 = np.array([s["b1"] for s in P], np.int32)
        self.p_b2 = np.array([s["b2"] for s in P], np.int32)
        self.p_a1 = np.array([s["a1"] for s in P], float).reshape(npu, 3)
        self.p_a2 = np.array([s["a2"] for s in P], float).reshape(npu, 3)
        self.p_r1 = np.array([s["r1"] for s in P], float)
        self.p_r2 = np.array([s["r2"] for s in P], float)
        self.p_lid = np.array([s["lid"] for s in P], np.int32)
        self.p_P1w = np.zeros((npu, 3))
        self.link_force = np.zeros((len(self.links), 3))
        self.link_torque = np.zeros((len(self.links), 3))
        self._link_P1w = np.zeros((len(self.links), 3))
        self._link_b1 = np.array([l["b1"] for l in self.links], np.int64)
        self._imposed_fn_idx = [i for i, f in enumerate(self._imposed_fn) if f is not None]
        self._motion_idx = [i for i, f in enumerate(self._motion) if f is not None]
        # what the step has to do (only what the scene has runs)
        self._spring_fn = [j for j, s in enumerate(S) if callable(s["k"]) or callable(s["c"])]
        self._time_dependent = bool(self._load_fn or self._mate_timedep or self._motors or self._spring_fn)
        self._static_imposed = not np.isnan(self.imposed).all()
        self._preload_springs = [s for s in S if s["f0"] != 0]
        self._link_rows_max = 6 * nm + ns + nd + npu + 6 * self.nb
        self._p1w_parts = [(a, l) for a, l in ((self.m_P1w, self.m_lid), (self.s_P1w, self.s_lid),
                                                (self.d_P1w, self.d_lid), (self.p_P1w, self.p_lid))
                           if l.shape[0]]
        if len(self._p1w_parts) == 1 and np.array_equal(self._p1w_parts[0][1], np.arange(len(self.links))):
            self._link_P1w = self._p1w_parts[0][0]      # one link type, in link order: its own array
            self._p1w_parts = []
        self._packed = True

    def _update_time_dependent(self, t_next):
        for i, load in self._load_fn:
            force, torque = load(t_next)
            self.f_ext[i] = force
            self.t_ext[i] = torque
        M = self._mates
        for i, k in self._mate_timedep:
            self.m_k[i, k] = _eval(M[i]["k"][k], t_next)
            self.m_c[i, k] = _eval(M[i]["c"][k], t_next)
        h = t_next - self.time
        for i, k in self._motors:
            target = M[i]["mtarget"][k]
            if self.m_mmode[i, k] == rw.MOTOR_POSITION:
                # error against the target now, the target's rate over the step apart
                # (ChLinkMotorRotationAngle: C clamped by the recovery speed, Ct unclamped)
                now = _eval(target, self.time)
                self.m_mval[i, k] = now
                self.m_mdval[i, k] = (_eval(target, t_next) - now) / h if h > 0 else 0.0
            else:
                self.m_mval[i, k] = _eval(target, t_next)
        for j in self._spring_fn:
            s = self._springs[j]
            if callable(s["k"]):
                self.s_k[j] = s["k"](t_next)
            if callable(s["c"]):
                self.s_c[j] = s["c"](t_next)

    # -------------------------------------------------------------- rows
    def _ensure_rows(self, n):
        if n <= self._cap_rows:
            return
        cap = max(int(n * 1.5), 64)
        self._cap_rows = cap
        self.r_a = np.zeros(cap, np.int32)
        self.r_b = np.zeros(cap, np.int32)
        self.r_J = np.zeros((cap, 12))
        self.r_MiJ = np.zeros((cap, 12))
        self.r_bias = np.zeros(cap)
        self.r_E = np.zeros(cap)
        self.r_kind = np.zeros(cap, np.int8)
        self.r_lo = np.zeros(cap)
        self.r_hi = np.zeros(cap)
        self.r_mu = np.zeros(cap)
        self.r_link = np.zeros(cap, np.int32)
        self.r_C = np.zeros(cap)
        self.r_g = np.zeros(cap)
        self.r_gamma = np.zeros(cap)
        # work arrays of the sliding correction (_solve_rows): bias without it, s, s_new
        self.r_bias0 = np.zeros(cap)
        self.r_slide = np.zeros(cap)
        self.r_slide2 = np.zeros(cap)

    def _row_args(self):
        return (self.r_a, self.r_b, self.r_J, self.r_bias, self.r_E, self.r_kind, self.r_lo,
                self.r_hi, self.r_mu, self.r_link, self.r_C)

    def _build_link_rows(self, h, R, vel6=None, invm3=None, invI=None):
        """Joint, spring, damper, pulley and imposed-velocity rows.  vel6 and
        the DOF-masked inverse masses serve the explicit spring-damper rows
        (:func:`rows._soft_row`); without them every spring is implicit.  Only the builders of
        the link types the system has are called (a lone free body: none)."""
        scheme = _SPRING_SCHEMES[self.spring_integration]
        if vel6 is None:
            nb = self.nb
            scheme = rw.SPRING_IMPLICIT
            vel6 = np.zeros((nb, 6))
            invm3 = np.zeros((nb, 3))
            invI = np.zeros((nb, 3, 3))
        nr = 0
        if self.m_b1.shape[0]:
            nr = rw.build_mate_rows(nr, h, self.recovery_speed, self.pos, R, self.m_b1, self.m_b2,
                                    self.m_p1, self.m_p2, self.m_T1, self.m_T2, self.m_Q1, self.m_Q2,
                                    self.m_mask, self.m_k, self.m_c, self.m_rest, self.m_mmode,
                                    self.m_mval, self.m_mdval, self.m_angle, self.m_lid, self.m_P1w,
                                    scheme, vel6, invm3, invI, *self._row_args())
        if self.s_b1.shape[0]:
            nr = rw.build_spring_rows(nr, h, self.pos, R, self.s_b1, self.s_b2, self.s_p1, self.s_p2,
                                      self.s_k, self.s_c, self.s_l0, self.s_f0, self.s_lid,
                                      self.s_P1w, self.s_len, scheme, vel6, invm3, invI,
                                      *self._row_args())
        if self.d_b1.shape[0]:
            nr = rw.build_coulomb_rows(nr, h, self.pos, R, self.d_b1, self.d_b2, self.d_p1,
                                       self.d_p2, self.d_F, self.d_lid, self.d_P1w, *self._row_args())
        if self.p_b1.shape[0]:
            nr = rw.build_pulley_rows(nr, self.pos, R, self.p_b1, self.p_b2, self.p_a1, self.p_a2,
                                      self.p_r1, self.p_r2, self.p_lid, self.p_P1w, *self._row_args())
        if self._imposed_fn_idx or (self._static_imposed and not np.isnan(self._imposed_now).all()):
            nr = rw.build_imposed_rows(nr, R, self._imposed_now, *self._row_args())
        return nr

    def _max_link_rows(self):
        return 6 * len(self._mates) + len(self._springs) + len(self._dampers) + \
            len(self._pulleys) + 6 * self.nb

    # ---------------------------------------------------------- collisions
    def _collide(self, R):
        ns = self.sh_type.shape[0]
        self.n_contacts = 0
        if ns < 2:
            return 0
        self._work()
        w_pos, w_R, lo, hi = self._w_shapes          # work arrays kept on the System
        col.shape_world_poses(self.sh_body, self.sh_pos, self.sh_R, self.pos, R, w_pos, w_R)
        col.shape_aabbs(self.sh_type, self.sh_dims, self.samp_off, self.samp_cnt, self.samp_pts,
                        self.samp_rad, w_pos, w_R, self.envelope, lo, hi)
        active = self._w_active
        while True:
            if self._w_pairs.shape[0] != self._cap_pairs:
                self._w_pairs = np.empty((self._cap_pairs, 2), np.int64)
            pairs = self._w_pairs
            npair = col.broad_phase(lo, hi, self.sh_body, self.sh_type, active, pairs, w_pos, w_R,
                                    self.envelope)
            if npair <= self._cap_pairs:
                break
            self._cap_pairs = int(npair * 1.5)
        while True:
            cap = self._cap_contacts
            if self._w_c is None or self._w_c["a"].shape[0] != cap:
                self._w_c = dict(a=np.empty(cap, np.int32), b=np.empty(cap, np.int32),
                                 sa=np.empty(cap, np.int32), sb=np.empty(cap, np.int32),
                                 pt=np.empty((cap, 3)), n=np.empty((cap, 3)), gap=np.empty(cap),
                                 key=np.empty(cap, np.int64))
                # per contact: friction, restitution, first row, warm start (System.advance)
                self._w_cmu, self._w_ce = np.empty(cap), np.empty(cap)
                self._w_crow, self._w_g3 = np.empty(cap, np.int64), np.zeros((cap, 3))
            c = self._w_c
            nc = col.narrow_phase(npair, pairs, self.envelope, self.sh_body, self.sh_type,
                                  self.sh_dims, self.samp_off, self.samp_cnt, self.samp_pts,
                                  self.samp_rad, self.pl_off, self.pl_cnt, self.planes,
                                  self.cg_meta, self.cg_start, self.edges, self.ed_off,
                                  self.ed_cnt, w_pos, w_R, lo, hi, c["a"], c["b"], c["sa"], c["sb"], c["pt"],
                                  c["n"], c["gap"], c["key"], self.samp_nrm, self.fv_off,
                                  self.fv_cnt, self.fv_idx, self.fv_edge, self.ed_rep)
            if nc <= cap:
                break
            self._cap_contacts = int(nc * 1.5)
        self._c = c
        self.n_contacts = nc
        return nc

    def compile_contact_kernels(self):
        """Compile (or load from numba's cache) the kernels that only a contact calls: the pair
        materials, the contact rows, their warm start and the SMC forces.  Called on zero
        contacts (the argument types are those of :meth:`step`), so that a first contact later in
        a run compiles nothing inside the time loop.  Meant for a warm-up's copy: it may allocate
        the System's row arrays, and moves nothing."""
        if self.sh_type.shape[0] < 2:
            return
        if not self._packed:
            self._pack()
        nb, nc = self.nb, 0
        c = dict(a=np.empty(1, np.int32), b=np.empty(1, np.int32), sa=np.empty(1, np.int32),
                 sb=np.empty(1, np.int32), pt=np.empty((1, 3)), n=np.empty((1, 3)),
                 gap=np.empty(1), key=np.empty(1, np.int64))
        R = body_rotations(self.quat)
        if self.contactmethod.lower() == "smc":
            col.smc_forces(nc, c["a"], c["b"], c["sa"], c["sb"], c["pt"], c["n"], c["gap"],
                           self.sh_mat, self.sh_rad, self.mat_mu, self.mat_e, self.mat_E,
                           self.mat_nu, self.pos, R, self.vel, self.omega_b, self.inv_mass,
                           np.zeros((nb, 3)), np.zeros((nb, 3)), True)
            return
        c_mu, c_e, c_row = np.empty(nc), np.empty(nc), np.empty(nc, np.int64)
        col.contact_materials(nc, c["sa"], c["sb"], self.sh_mat, self.mat_mu, self.mat_e, c_mu, c_e)
        self._ensure_rows(self._max_link_rows())
        rw.build_contact_rows(0, 1.0, self.recovery_speed, self.min_bounce_speed, self.pos, R,
                              np.zeros((nb, 6)), nc, c["a"], c["b"], c["pt"], c["n"], c["gap"],
                              c_mu, c_e, c_row, *self._row_args())
        col.match_warm_start(nc, c["key"], np.zeros(0, np.int64), np.zeros((0, 3)),
                             np.zeros((nc, 3)))
        invm3, invI = apply_dof_masks(self.inv_mass, self.inv_I_b, self.dof_mask, R)
        prepare_live_rows(0, self.r_a, self.r_b, self.r_J, self.r_E, self.r_kind, invm3, invI,
                          self.r_MiJ, self.r_g, self.r_bias, self.r_gamma)
        scatter_warm(self.r_gamma, c_row, c_mu, np.zeros((0, 3)))
        gather_warm(self.r_gamma, c_row, c_mu, np.zeros((0, 3)))

    # ---------------------------------------------------------------- step
    def step(self, dt, forces=None, torques=None):
        """Advance the system by ``dt``.

        forces, torques: optional (nb, 3) world-frame external loads for this
        step only (torque about each body's centre), added to gravity and the
        persistent loads — this is how a fluid solver drives the bodies.
        Returns (pos, quat, vel, omega_world) views/arrays after the step
        (:meth:`advance` is the step without them)."""
        self.advance(dt, forces, torques)
        return self.pos, self.quat, self.vel, self.omega_world

    def _work(self):
        """The step's work arrays, kept on the System and sized again only when the bodies,
        links or shapes change (as the row arrays, :meth:`_ensure_rows`): the step allocates
        (almost) nothing.  ``contact_force`` ... ``link_torque`` are written in place from step to
        step (read them, or copy them to keep them)."""
        nb, nl, ns = self.nb, len(self.links), self.sh_type.shape[0]
        if self._work_shape == (nb, nl, ns):
            return
        self._work_shape = (nb, nl, ns)
        z = np.zeros
        self._w_R = z((nb, 3, 3))
        self._applied_F, self._applied_T = z((nb, 3)), z((nb, 3))
        self._smc_f, self._smc_t = z((nb, 3)), z((nb, 3))
        self._w_invm3, self._w_invI = z((nb, 3)), z((nb, 3, 3))
        self._w_vel6, self._w_vfree, self._w_vout = z((nb, 6)), z((nb, 6)), z((nb, 6))
        self._w_imp = z((nb, 6))
        # (bf, bt: zero at each step's start, step_end zeroes them after use)
        self._w_cf, self._w_ct, self._w_bf, self._w_bt = z((nb, 3)), z((nb, 3)), z((nb, 3)), z((nb, 3))
        self._w_lf, self._w_ltc = z((nl, 3)), z((nl, 3))
        self._w_out = [z((nb, 3)) for _ in range(4)] + [z((nl, 3)) for _ in range(2)]
        self._w_none = z((0, 3))
        self._w_shapes = (z((ns, 3)), z((ns, 3, 3)), z((ns, 3)), z((ns, 3)))
        self._w_active = self.kind == FLOATING
        self._w_pairs = np.empty((0, 2), np.int64)
        self._w_c = None

    def advance(self, dt, forces=None, torques=None):
        """:meth:`step` without its return value (a coupling's call: nothing allocated for it).

        Only what the scene has runs: no collision pass without two shapes, no row building
        without links, contacts or imposed velocities (a free body: v = v_free), no Python
        loop over time-dependent values, moving bodies or spring preloads it lacks."""
        h = float(dt)
        nb = self.nb
        if not self._packed:
            self._pack()
        self._work()
        t_next = self.time + h
        if self._time_dependent:
            self._update_time_dependent(t_next)
        R = self._w_R
        F = self._applied_F
        T = self._applied_T
        step_start(self.quat, self.f_ext, self.t_ext,
                   self._w_none if forces is None else np.ascontiguousarray(forces, np.float64).reshape(nb, 3),
                   self._w_none if torques is None else np.ascontiguousarray(torques, np.float64).reshape(nb, 3),
                   self.mass, self.gravity, self.kind, R, F, T)
        # imposed velocities (rows) and moving bodies (kinematic)
        if self._imposed_fn_idx:
            imp = self._w_imp
            imp[:] = self.imposed
            for i in self._imposed_fn_idx:
                imp[i] = [np.nan if c is None else c for c in self._imposed_fn[i](t_next)]
            self._imposed_now = imp
        else:
            self._imposed_now = self.imposed
        for i in self._motion_idx:
            if self.kind[i] == MOVING:
                v, w = self._motion[i](t_next)
                self.vel[i] = v
                self.omega_b[i] = R[i].T @ np.asarray(w, float)
        # explicit preloads of springs without stiffness/damping
        if self._preload_springs:
            self._spring_preloads(R, F, T)
        elif self._preload_links:
            self._preload_links = []
        nc = self._collide(R)
        smc = self.contactmethod.lower() == "smc"
        if smc and nc > 0:
            self._smc_f[:] = 0.0
            self._smc_t[:] = 0.0
            c = self._c
            col.smc_forces(nc, c["a"], c["b"], c["sa"], c["sb"], c["pt"], c["n"], c["gap"],
                           self.sh_mat, self.sh_rad, self.mat_mu, self.mat_e, self.mat_E,
                           self.mat_nu, self.pos, R, self.vel, self.omega_b, self.inv_mass,
                           self._smc_f, self._smc_t, self.smc_model.lower() != "hooke")
            F += self._smc_f
            T += self._smc_t
            self._smc_on = True
        elif getattr(self, "_smc_on", False):
            self._smc_f[:] = 0.0
            self._smc_t[:] = 0.0
            self._smc_on = False
        invm3, invI = self._w_invm3, self._w_invI
        vel6, vfree, vout = self._w_vel6, self._w_vfree, self._w_vout
        step_free(h, self.kind, self.inv_mass, self.inv_I_b, self.dof_mask, R, self.I_b, self.vel,
                  self.omega_b, F, T, invm3, invI, vel6, vfree)
        # rows
        ncr = 0 if smc else nc
        self._ensure_rows(self._link_rows_max + 3 * ncr)
        nl_rows = self._build_link_rows(h, R, vel6, invm3, invI) \
            if self.links or self._imposed_fn_idx or self._static_imposed else 0
        g = self.r_gamma
        g[:] = 0.0
        # warm start: impulses of the last step, rescaled to this step (γ = h·force)
        ws = 1.0 if self._prev_h is None else h / self._prev_h
        if self._prev_link_gamma.shape[0] == nl_rows:
            np.multiply(self._prev_link_gamma, ws, out=g[:nl_rows])
        nr = nl_rows
        if ncr > 0:
            c = self._c
            c_mu = self._w_cmu[:nc]
            c_e = self._w_ce[:nc]
            col.contact_materials(nc, c["sa"], c["sb"], self.sh_mat, self.mat_mu, self.mat_e,
                                  c_mu, c_e)
            c_row = self._w_crow[:nc]
            nr = rw.build_contact_rows(nr, h, self.recovery_speed, self.min_bounce_speed,
                                       self.pos, R, vel6, nc, c["a"], c["b"], c["pt"], c["n"],
                                       c["gap"], c_mu, c_e, c_row, *self._row_args())
            g3 = self._w_g3[:nc]
            g3[:] = 0.0
            col.match_warm_start(nc, c["key"], self._prev_keys, self._prev_g3, g3)
            if ws != 1.0:
                g3 *= ws
            scatter_warm(g, c_row, c_mu, g3)
            self._c_row = c_row
            self._c_mu = c_mu
        if nr:                          # (rows that cannot act, no dynamic body: no bias, no warm start)
            prepare_live_rows(nr, self.r_a, self.r_b, self.r_J, self.r_E, self.r_kind, invm3, invI,
                              self.r_MiJ, self.r_g, self.r_bias, g)
        if not nr:                      # no link, no contact: v = v_free (what the solvers return)
            vout[:] = vfree
            it, res = 0, 0.0
        else:
            it, res = self._solve_rows(nr, nb, g, vel6, vfree, vout, ncr > 0 and bool((c_mu > 0).any()))
        self.last_iterations = int(it)
        self.last_residual = float(res)
        self.n_rows = nr
        self._check_residual(nr, g, vout, h)
        # warm-start caches
        if self._prev_link_gamma.shape[0] == nl_rows:
            self._prev_link_gamma[:] = g[:nl_rows]
        else:
            self._prev_link_gamma = g[:nl_rows].copy()
        self._prev_h = h
        if ncr > 0:
            keys = self._c["key"][:nc]
            order = np.argsort(keys)
            g3 = self._w_g3[:nc]
            gather_warm(g, self._c_row, self._c_mu, g3)
            self._prev_keys = keys[order]       # (new arrays: the cache that get_state copies)
            self._prev_g3 = g3[order]
        elif self._prev_keys.shape[0]:
            self._prev_keys = np.zeros(0, np.int64)
            self._prev_g3 = np.zeros((0, 3))
        # reactions, then the state update
        self._accumulate(nr, h, R)
        self.time = t_next
        if self.position_projection and self._mates:
            self._project_positions(invm3, invI)

    def _solve_once(self, nr, nb, g, vfree, vout):
        """One CCP solve of the rows (warm start and result in ``g``, v⁺ in ``vout``)."""
        if self.solver.lower() == "direct":
            return solve_direct(nr, nb, self.r_a, self.r_b, self.r_J, self.r_MiJ, self.r_bias,
                                self.r_E, self.r_kind, self.r_mu, self.r_lo, self.r_hi,
                                self.r_g, g, vfree, vout, self.max_iter, self.tol, owner=self)
        return solve_iterative(SOLVER_NAMES[self.solver.lower()], nr, nb, self.r_a, self.r_b,
                               self.r_J, self.r_MiJ, self.r_bias, self.r_E, self.r_kind,
                               self.r_mu, self.r_lo, self.r_hi, self.r_g, g, vfree, vout,
                               self.max_iter, self.tol, self.omega, owner=self,
                               exact_joints=self.exact_joints)

    def _solve_rows(self, nr, nb, g, vel6, vfree, vout, friction):
        """The step's CCP with the sliding correction (De Saxcé's fixed point) on frictional
        contacts.

        The convexified CCP makes a sliding contact separate at ``u_n = μ‖u_t‖``: a box resting
        on a plane and pushed at v_t leaves it at μ v_t/(1 + μ²) whatever h (hop (0.4 v_t)²/2g
        at μ = 0.5).  Each normal row therefore gets ``b_n + s``, ``s = μ‖u_t⁺‖`` (Chrono::
        Multicore's SLIDING mode, ChConstraintRigidRigid::Build_s; ContactBench's De Saxcé
        correction): with the exact ``s`` a sliding contact keeps ``J_n v⁺ + b_n = 0`` and the
        solution is Coulomb's (non-associated) law; where the contact sticks (u_t = 0) nothing
        changes.  ``s`` is first the smaller of two guesses of μ‖u_t⁺‖: at the velocities the
        warm start predicts, ``v_free + M⁻¹ Dᵀ γ_warm`` (Multicore's ``v_new = M_invk + M_invD γ``:
        in steady sliding γ_warm already holds the friction, so that guess is right to O(Δγ)),
        and at the pre-step velocities (right to O(h) wherever the warm start is poor: in a
        resting pile solved by 50 PSOR sweeps the first guess reads tangential speeds of 5 cm/s
        where the solution has 3 mm/s, and took 3 solves a step where this takes 1).  A guess
        too large lets the normal row approach at the excess, one too small lifts; while the
        solution's ``μ‖u_t⁺‖`` differs from ``s`` by more than ``sliding_tol`` and
        SLIDING_RES_FACTOR times the solver's residual (an unconverged solve's u_t is no better:
        in a resting pile solved by BB with 100 iterations Δs ≈ 1.1–1.6 × residual, and each
        further pass chased that noise at the cost of a whole solve), the CCP is solved again with it,
        warm started (a convex problem each time; for one contact the map contracts by
        μ²/(1+μ²)), at most ``sliding_passes`` solves in all.  A residual error Δs leaves a
        normal speed Δs, i.e. a hop of Δs²/2g."""
        if self.sliding_passes <= 0 or not friction:
            return self._solve_once(nr, nb, g, vfree, vout)
        args = (nr, self.r_a, self.r_b, self.r_J, self.r_kind, self.r_mu, self.r_g)
        # work arrays kept on the System (rows: _ensure_rows; bodies: here), no allocation
        if self._w_vpred.shape[0] != nb:
            self._w_vpred = np.empty((nb, 6))
        vpred = self._w_vpred
        b0 = self.r_bias0[:nr]
        b0[:] = self.r_bias[:nr]
        s = self.r_slide[:nr]
        s_new = self.r_slide2[:nr]
        vpred[:] = vfree
        scatter_impulses(nr, self.r_a, self.r_b, self.r_MiJ, g, vpred)
        sliding_speeds(*args, vpred, s)
        sliding_speeds(*args, vel6, s_new)
        np.minimum(s, s_new, out=s)
        its = 0
        for _ in range(self.sliding_passes):
            np.add(b0, s, out=self.r_bias[:nr])
            it, res = self._solve_once(nr, nb, g, vfree, vout)
            its += it
            sliding_speeds(*args, vout, s_new)
            if max_abs_diff(nr, s_new, s) <= max(self.sliding_tol, SLIDING_RES_FACTOR * res):
                break
            s, s_new = s_new, s
        return its, res

    def _check_residual(self, nr, g, vout, h):
        """Warn (once per episode) when the solver's residual has stayed above
        ``residual_warning`` for RESIDUAL_WARN_STEPS steps: the forces are then not a solution
        (1e7–1e14 N against a wall that an imposed velocity drives a body into).  The line names
        the time, the residual and the bodies of the worst rows; it is queued for run.log
        (:meth:`take_warnings`) and, unless ``defer_warnings``, warned about at once."""
        if self.last_residual <= self.residual_warning or not nr:
            self._res_high = 0
            self._res_warned = False
            return
        self._res_high += 1
        if self._res_high < RESIDUAL_WARN_STEPS or self._res_warned:
            return
        self._res_warned = True
        rr = np.empty(nr)
        row_residuals(nr, self.r_a, self.r_b, self.r_J, self.r_bias, self.r_E, self.r_kind,
                      self.r_mu, self.r_lo, self.r_hi, self.r_g, g, vout, rr)
        worst = np.argsort(rr)[::-1][:8]
        bodies = []
        for k in worst:
            if rr[k] <= self.residual_warning:
                break
            for i in (self.r_a[k], self.r_b[k]):
                name = self.names[i] if i >= 0 else "ground"
                if name not in bodies:
                    bodies.append(name)
        f = np.abs(g[:nr]).max() / h
        line = (f"multibody solver not converged at t={self.time + h:.6g} s for "
                f"{self._res_high} steps: residual {self.last_residual:.3g} m/s (above "
                f"{self.residual_warning:g}) after {self.last_iterations} iterations, largest "
                f"row force {f:.3g} N; bodies {', '.join(bodies) or '?'}: the constraints conflict "
                "(an imposed velocity into a wall or a joint, redundant or contradicting links) or "
                "the solver needs more iterations; the forces are not a solution")
        self.say(line)

    def say(self, line: str) -> None:
        """A warning of the multibody run: kept for run.log (:meth:`take_warnings`) and, unless a
        run defers them, raised now as a UserWarning."""
        self.pending_warnings.append(line)
        if not self.defer_warnings:
            warnings.warn(line)

    def take_warnings(self):
        """The warning lines of the steps since the last call (for run.log)."""
        lines, self.pending_warnings = self.pending_warnings, []
        return lines

    def _project_positions(self, invm3, invI):
        """Solve  D M⁻¹ Dᵀ λ = −C  on the rigid joint rows at the new pose and
        move the bodies by Δ = M⁻¹ Dᵀ λ (linear world, rotation vector body)."""
        nb = self.nb
        R = body_rotations(self.quat)
        saved_imp = self._imposed_now
        self._imposed_now = np.full((nb, 6), np.nan)
        ang = self.m_angle.copy()
        nr = self._build_link_rows(1.0, R)
        self.m_angle[:] = ang
        self._imposed_now = saved_imp
        rigid = np.nonzero(np.isfinite(self.r_C[:nr]))[0]
        if rigid.size == 0:
            return
        ra = self.r_a[rigid].copy()
        rb = self.r_b[rigid].copy()
        J = self.r_J[rigid].copy()
        C = self.r_C[rigid].copy()
        n = rigid.size
        E = np.zeros(n)
        kind = np.zeros(n, np.int8)
        MiJ = np.zeros((n, 12))
        gd = np.zeros(n)
        invm3, invI = apply_dof_masks(self.inv_mass, self.inv_I_b, self.dof_mask, R)
        prepare_rows(n, ra, rb, J, E, kind, invm3, invI, MiJ, gd)
        lam = np.zeros(n)
        z6 = np.zeros((nb, 6))
        d = np.empty((nb, 6))
        big = np.full(n, 1e300)
        if self.solver.lower() == "direct":
            solve_direct(n, nb, ra, rb, J, MiJ, C, E, kind, E, -big, big, gd, lam, z6, d,
                         self.max_iter, self.tol)
        else:
            solve_ccp(SOLVER_NAMES[self.solver.lower()], n, nb, ra, rb, J, MiJ, C, E, kind, E,
                      -big, big, gd, lam, z6, d, max(self.max_iter, 100), self.tol, self.omega)
        integrate_bodies(self.pos, self.quat, d[:, :3].copy(), d[:, 3:].copy(), self.kind, 1.0)

    def _spring_preloads(self, R, F, T):
        """Preloads of springs without stiffness and damping (no row carries them): applied as
        explicit forces, and kept for the springs' link_force (force on body 1) and link torque
        (the torque about body 1's centre, so that about the link point it is 0)."""
        self._preload_links = []
        for s in self._springs:
            if _eval(s["k"], self.time) > 0 or _eval(s["c"], self.time) > 0 or s["f0"] == 0:
                continue
            x1, R1 = (self.pos[s["b1"]], R[s["b1"]]) if s["b1"] >= 0 else (np.zeros(3), np.eye(3))
            x2, R2 = (self.pos[s["b2"]], R[s["b2"]]) if s["b2"] >= 0 else (np.zeros(3), np.eye(3))
            P1 = x1 + R1 @ s["p1"]
            P2 = x2 + R2 @ s["p2"]
            d = P1 - P2
            n = d / max(np.linalg.norm(d), 1e-300)
            f = s["f0"] * n
            self._preload_links.append((s["lid"], f, np.cross(P1 - x1, f)))
            if s["b1"] >= 0:
                F[s["b1"]] += f
                T[s["b1"]] += np.cross(P1 - x1, f)
            if s["b2"] >= 0:
                F[s["b2"]] -= f
                T[s["b2"]] -= np.cross(P2 - x2, f)

    def _accumulate(self, nr, h, R):
        """The step's reactions into the kept arrays (contact, total and link loads,
        :func:`rows.accumulate_row_forces`), then v⁺ and the move (:func:`_kernels.step_end`)."""
        cf, ct, bf, bt, lf, ltc = (self._w_cf, self._w_ct, self._w_bf, self._w_bt, self._w_lf,
                                   self._w_ltc)
        rw.accumulate_row_forces(nr, self.r_a, self.r_b, self.r_J, self.r_gamma, 1.0 / h, R,
                                 self.r_link, lf.shape[0], cf, ct, lf, ltc, self.nb, bf, bt)
        for lid, f, tc in self._preload_links:
            lf[lid] += f
            ltc[lid] += tc
        # link torque about the link point on body 1
        P1w = self._link_P1w
        for arr, lids in self._p1w_parts:
            P1w[lids] = arr
        out = self._w_out
        self.contact_force, self.contact_torque, self.total_force, self.total_torque = out[:4]
        self.link_force, self.link_torque = out[4], out[5]
        out[4][:] = lf
        step_end(h, cf, ct, self._smc_f, self._smc_t, self._applied_F, self._applied_T, bf, bt,
                 out[0], out[1], out[2], out[3], lf, ltc, P1w, self._link_b1, out[5], self._w_vout,
                 self.pos, self.quat, self.vel, self.omega_b, self.kind)

    # ------------------------------------------------------------ state
    def _bodies_like(self, st):
        """Whether the state ``st``'s poses and velocities are float64 arrays of this System's
        shapes (copy_state's arrays: a compiled copy checks no bounds)."""
        for key in ("pos", "quat", "vel", "omega_b"):
            a, b = st.get(key), getattr(self, key)
            if not isinstance(a, np.ndarray) or a.shape != b.shape or a.dtype != np.float64:
                return False
        return True

    def get_state(self, out=None):
        """A copy of the dynamic state (poses, velocities, time, joint angle
        counters, warm-start caches): for predictor–corrector couplings.  ``out``: a state an
        earlier call returned, refilled in place where its arrays have the sizes (a coupling's
        kept copy: nothing allocated) and returned."""
        angle = getattr(self, "m_angle", None)
        if out is None or not self._bodies_like(out) or ("m_angle" in out) != (angle is not None):
            st = dict(pos=self.pos.copy(), quat=self.quat.copy(), vel=self.vel.copy(),
                      omega_b=self.omega_b.copy(), time=self.time,
                      prev_keys=self._prev_keys.copy(), prev_g3=self._prev_g3.copy(),
                      prev_link_gamma=self._prev_link_gamma.copy(), prev_h=self._prev_h)
            if angle is not None:
                st["m_angle"] = angle.copy()
            return st
        copy_state(self.pos, self.quat, self.vel, self.omega_b, out["pos"], out["quat"], out["vel"],
                   out["omega_b"])
        for key, a in (("prev_keys", self._prev_keys), ("prev_g3", self._prev_g3),
                       ("prev_link_gamma", self._prev_link_gamma), ("m_angle", angle)):
            if a is None:
                continue
            if out[key].shape == a.shape:
                if a.size:
                    out[key][...] = a
            else:
                out[key] = a.copy()
        out["time"] = self.time
        out["prev_h"] = self._prev_h
        return out

    def set_state(self, st):
        """Restore a state returned by :meth:`get_state` (copied: ``st`` stays the caller's)."""
        if self._bodies_like(st):
            copy_state(st["pos"], st["quat"], st["vel"], st["omega_b"], self.pos, self.quat, self.vel,
                       self.omega_b)
        else:                           # another layout (a checkpoint of other bodies): numpy's error
            self.pos[:] = st["pos"]
            self.quat[:] = st["quat"]
            self.vel[:] = st["vel"]
            self.omega_b[:] = st["omega_b"]
        self.time = st["time"]
        for key in ("prev_keys", "prev_g3", "prev_link_gamma"):
            a, b = getattr(self, "_" + key), st[key]
            if a.shape == b.shape and a is not b:
                if a.size:
                    a[...] = b
            else:
                setattr(self, "_" + key, b.copy())
        self._prev_h = st["prev_h"]
        if "m_angle" in st and hasattr(self, "m_angle"):
            self.m_angle[:] = st["m_angle"]

    # ------------------------------------------------------------ accessors
    def body_index(self, name):
        """Index of the body called ``name``."""
        return self.names.index(name)

    def link_index(self, name):
        """Id of the link called ``name``."""
        for i, rec in enumerate(self.links):
            if rec["name"] == name:
                return i
        raise KeyError(name)

    @property
    def omega_world(self):
        R = body_rotations(self.quat)
        return np.einsum("nij,nj->ni", R, self.omega_b)

    def set_velocity(self, body, vel=None, omega=None):
        """Set a body's linear and/or angular velocity (world frame); a fixed body's stays 0
        (a non-zero one is refused)."""
        if self.kind[body] == FIXED and any(v is not None and np.any(np.asarray(v, float) != 0)
                                            for v in (vel, omega)):
            raise ValueError(f"body {self.names[body]} is fixed: it cannot be given a velocity")
        if vel is not None:
            self.vel[body] = vel
        if omega is not None:
            self.omega_b[body] = np_quat_to_mat(self.quat[body]).T @ np.asarray(omega, float)

    def kinetic_energy(self):
        wb = self.omega_b
        lin = 0.5 * self.mass * np.einsum("ni,ni->n", self.vel, self.vel)
        rot = 0.5 * np.einsum("ni,nij,nj->n", wb, self.I_b, wb)
        e = (lin + rot) * (self.kind == FLOATING)
        return float(e.sum())

    def potential_energy(self):
        e = -self.mass * (self.pos @ self.gravity) * (self.kind == FLOATING)
        return float(e.sum())

    def angular_momentum_world(self, body):
        R = np_quat_to_mat(self.quat[body])
        return R @ (self.I_b[body] @ self.omega_b[body])

    def constraint_violation(self):
        """Max |C| over the rigid (position-level) joint rows at the current pose."""
        if not self._packed:
            self._pack()
        R = body_rotations(self.quat)
        self._imposed_now = np.full((self.nb, 6), np.nan)
        self._ensure_rows(self._max_link_rows())
        ang = self.m_angle.copy()
        nr = self._build_link_rows(1.0, R)
        self.m_angle[:] = ang
        C = self.r_C[:nr]
        C = C[np.isfinite(C)]
        return float(np.abs(C).max()) if C.size else 0.0


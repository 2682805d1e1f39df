"""sphdvi.dvi — a Chrono-NSC-style rigid multibody engine (no SPH inside).

Importing this sub-package imports numba; ``import sphdvi`` does not.

Quick use::

    from sphdvi.dvi import System
    s = System(gravity=(0, 0, -9.81), solver="bb", max_iter=100)
    b = s.add_body(mass=1.0, inertia=(0.1, 0.1, 0.1), pos=(0, 0, 1))
    s.add_box(b, (0.1, 0.1, 0.1))
    s.add_plane((0, 0, 0), (0, 0, 1))
    s.add_link("hinge", b, -1, point=(0, 0, 2), axis=(0, 1, 0))
    for _ in range(1000):
        s.step(1e-3, forces=None, torques=None)   # optional (nb,3) world loads

Method
------
One Anitescu–Tasora step per call (Chrono's EULER_IMPLICIT_LINEARIZED): a
velocity-level cone complementarity problem for the impulses of all joint,
contact, motor and force-element rows, solved with implicit Schur-complement
products (N = D M⁻¹ Dᵀ is never formed) and warm started; positions then move
with the new velocities (x += h v, q ← q ⊗ exp(h ω_body)).  Stabilisation:
``b = clamp(C/h, ±recovery_speed)`` for joints, ``max(Φ/h, −recovery_speed)``
for contacts.  Link stiffness/damping, springs (TSDA) and joint stiffness are
implicit compliance rows ``E = 1/(h(hk + c))`` (stable for k = 1e8 at
h = 1e-3); Coulomb dampers are boxed rows.

Public API
----------
``System(gravity=(0,0,-9.81), solver="bb", max_iter=100, tol=1e-10, omega=1.0,
recovery_speed=0.6, envelope=0.002, min_bounce_speed=0.15, contactmethod="nsc",
smc_model="hertz", position_projection=False, spring_integration="auto", sliding_passes=4,
sliding_tol=1e-4, residual_warning=0.1)``

* solver: "psor" (projected Gauss–Seidel), "apgd" (Nesterov, adaptive step,
  restart), "bb" (Barzilai–Borwein spectral projected gradient, non-monotone;
  DualSPHysics's default), "direct" (joint rows eliminated by a dense
  Cholesky factorisation, contacts by a dense projected gradient; for small,
  stiff or badly scaled mechanisms; "minres" is an alias).  ``tol`` is a
  velocity residual (m/s, see :mod:`sphdvi.dvi.solvers`).
* contactmethod: "nsc" (complementarity: Coulomb cone, Newton restitution
  where the rebound speed e·|v_n| exceeds ``min_bounce_speed``, Chrono's 0.15 m/s
  default) or "smc" (penalty: Hertz or Hooke with Young's modulus, Poisson ratio,
  restitution); DualSPHysics's 0/1 are accepted.
* envelope: contacts are created for gaps below it.
* sliding_passes, sliding_tol: the convexified CCP alone (Chrono NSC's) makes a
  sliding contact separate at a *speed* μ‖v_t‖/(1 + μ²) whatever h (a box at rest on
  a plane given v0 hops (0.4 v0)²/2g at μ = 0.5; in steady sliding it rides h·μ·v_t
  above the surface); each normal row therefore gets + μ‖v_t⁺‖ (De Saxcé's
  correction, Chrono::Multicore's SLIDING mode), v_t⁺ predicted from the warm start
  and refined by warm-started re-solves until it changes by less than sliding_tol
  m/s (at most sliding_passes solves; 0 = the plain CCP).  A sliding box stays on
  the plane (lift < 1e-6 m).
* residual_warning: a solver residual above it (m/s) for 10 steps in a row is
  warned about once per episode (``take_warnings()``; run.log in a CLI run).
* position_projection: project positions onto the joint constraints after
  each step (drift-free closed loops).

Bodies, materials, shapes:

* ``add_body(mass, inertia, pos, quat=(1,0,0,0), vel, omega, kind="floating"|"fixed"|"moving",
  translation_dof=(1,1,1), rotation_dof=(1,1,1), motion=None, imposed_velocity=None,
  name=None, force=(0,0,0), torque=(0,0,0)) -> int``.  inertia: principal
  values or a 3x3 tensor about the centre (body frame); velocities world;
  ``motion(t) -> (v, ω_world)`` for moving bodies; ``imposed_velocity``: 6
  values (v, ω world) with None/NaN = free, or a callable of t.
* ``add_material(name, friction=0.3, restitution=0.0, young=1e7, poisson=0.3) -> int``.
  Pair rule (Chrono's default composition): friction = min(μ1, μ2),
  restitution = min(e1, e2); SMC: E* = 1/((1−ν1²)/E1 + (1−ν2²)/E2).
* ``add_shape(body, shape, size, pos, quat, material, points, radius, local=True) -> int``
  with shape "sphere" (r), "box" (half extents), "capsule" (r, half length,
  axis z), "cylinder" (r, half length, axis z), "plane", "hull" (convex hull of
  ``points``), "cloud" (a body's particles: ``points`` + ``radius``, r = dp/2; its
  flat faces collide as their tangent planes dp/2 in front of the surface particles,
  edges, corners and curved parts as spheres: ``collision.cloud_surface``;
  ``plane_normal`` for a 2D cloud).  Shortcuts: ``add_sphere``, ``add_box``,
  ``add_capsule``, ``add_cylinder``, ``add_hull``, ``add_cloud``,
  ``add_plane(point, normal, body=-1, material)``.

Links (body index -1 = the ground; points and axes in world coordinates at
creation):

* ``add_link(kind, body1, body2=-1, **kw) -> link id`` with kind in
  "fixed", "spherical"/"spheric", "hinge"/"revolute", "slider"/"prismatic",
  "cylindrical"/"hingedslider", "pointline" (``rot_axis`` = DualSPHysics
  rotvector, ``rot_axis2`` = rotvector2), "pointplane", "planar", "generic"
  (``mask`` = 6 flags tx ty tz rx ry rz constrained), "spring"/"linearspring"
  (TSDA), "coulombdamper", "pulley".
* ``add_mate(body1, body2, point, axis, mask, stiffness, damping, rest, motor=None|"angle"|"speed",
  motor_dof, motor_target, ...)``: the free axis of a joint is the z axis of
  its frame (``axis``).  stiffness/damping/motor_target: constant, table
  [[t, v], ...] or callable f(t).
* ``add_spring(body1, body2, point1, point2, stiffness, damping, rest_length, preload)``
* ``add_coulomb_damper(body1, body2, point1, point2, force)``
* ``add_pulley(body1, body2, axis, axis2, radius, radius2)``

Stepping and state:

* ``step(dt, forces=None, torques=None) -> (pos, quat, vel, omega_world)``;
  forces/torques: (nb, 3) world-frame loads for this step (torque about each
  centre), added to gravity and the persistent loads — the fluid coupling;
  ``advance(dt, forces=None, torques=None)``: the same step without the return
  value (the coupling's call).  The step's work arrays are kept on the System (sized
  again when bodies, links or shapes are added): a step allocates almost nothing.
* ``pos`` (nb,3), ``quat`` (nb,4, w x y z), ``vel`` (nb,3), ``omega_world``
  (nb,3), ``omega_b`` (body frame), ``time``.
* Last step: ``total_force``/``total_torque`` (all loads incl. gravity,
  contacts and joint reactions, world, about the centre), ``contact_force``/
  ``contact_torque`` (contact part), ``link_force``/``link_torque`` (nlinks,3):
  reaction on body 1 in the world frame, torque about the link point on body
  1 (for springs/dampers the element force on body 1, a preload included).  The
  opposite sign of Chrono's ChLink::GetReaction2 (and of the ADAMS Rforce its joint
  tests compare with: the wrench on body 2) and in the world frame, not link frame 2:
  to compare with DSPH+Chrono's ChronoLink_forces.csv or ADAMS, negate it and rotate.
  These arrays are written in place by the next step: copy them to keep them.
* ``last_iterations`` (all passes), ``last_residual``, ``n_contacts``, ``n_rows``,
  ``take_warnings()``,
  ``constraint_violation()``, ``kinetic_energy()``, ``potential_energy()``,
  ``set_velocity(body, vel, omega)``, ``set_external_load(body, force, torque)``,
  ``get_state(out=None)``/``set_state(st)`` (predictor–corrector couplings; ``out``: an
  earlier state refilled in place),
  ``body_index(name)``, ``link_index(name)``.

Body-only runs:

* ``run_bodies(bodies, links=(), tmax, tout, dt=1e-3, materials=(), forces=None, tout_extra=None,
  **system_kw) -> BodyHistory`` steps a System built from plain dicts in memory and returns
  its state at every output time (``time``, ``pos``, ``quat``, ``euler`` — degrees,
  roll-pitch-yaw with R = Rz(yaw) Ry(pitch) Rx(roll) —, ``vel``, ``omega``, ``force``,
  ``torque``, ``contact_force``, ``contact_torque``, ``link_force``, ``link_torque``, and
  ``system`` at the end); it writes no file.  ``sphdvi run`` on a case with bodies and no
  fluid writes them as ``bodies.csv`` (header :data:`BODIES_HEADER`) and ``links.csv``
  (:data:`LINKS_HEADER`).  ``build_system(bodies, links, materials, **system_kw)`` builds
  the System from the same plain dicts (see :mod:`sphdvi.dvi.runner`).
"""
from .runner import BODIES_HEADER, LINKS_HEADER, build_system, run_bodies  # noqa: F401
from .system import System  # noqa: F401

MultibodySystem = System

__all__ = ["System", "MultibodySystem", "run_bodies", "build_system", "BODIES_HEADER",
           "LINKS_HEADER"]

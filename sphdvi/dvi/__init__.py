"""sphdvi.dvi — a Chrono-NSC-style rigid multibody engine (no SPH inside).

Quick use::

    from sphdvi.dvi import System
    s = System(gravity=(0, 0, -9.81), solver="psor", max_iter=100)
    b = s.add_body(mass=1.0, inertia=(0.1, 0.1, 0.1), pos=(0, 0, 1))
    s.add_box(b, (0.1, 0.1, 0.1))
    s.add_plane((0, 0, 0), (0, 0, 1))
    s.add_link("hinge", b, -1, point=(0, 0, 2), axis=(0, 1, 0))
    for _ in range(1000):
        s.step(1e-3, forces=None, torques=None)   # (nb,3) world loads per step

Public API
----------
System(gravity, solver="psor"|"apgd"|"bb", max_iter, tol, omega, recovery_speed=0.6,
       envelope, min_bounce_speed, contactmethod="nsc"|"smc", smc_model="hertz"|"hooke")
  .add_body(mass, inertia, pos, quat, vel, omega, kind="floating"|"fixed"|"moving",
            translation_dof, rotation_dof, motion, imposed_velocity, name, force, torque) -> int
  .add_material(name, friction, restitution, young, poisson) -> int
  .add_shape(body, shape, size, pos, quat, material, points, radius, local) -> int
  .add_sphere/add_box/add_capsule/add_cylinder/add_hull/add_cloud/add_plane
  .add_link(kind, body1, body2=-1, **kw) -> link id
  .add_mate / add_spring / add_coulomb_damper / add_pulley
  .step(dt, forces=None, torques=None) -> (pos, quat, vel, omega_world)
  .pos, .quat (w,x,y,z), .vel, .omega_world, .omega_b
  .total_force/.total_torque, .contact_force/.contact_torque   (nb,3), last step
  .link_force/.link_torque   (nlinks,3): reaction on body 1, world frame,
                             torque about the link point on body 1
  .last_iterations, .last_residual, .n_contacts, .constraint_violation()
run_bodies(bodies, links, out_dir, tmax, tout, dt=1e-3, ...)  -> writes bodies.csv, links.csv

Body index -1 means the ground (world).  All quantities SI, world frame unless
stated.  Contact material pair rule: friction = min(μ1, μ2), restitution =
min(e1, e2) (Chrono's default composition).
"""
from .system import System  # noqa: F401
from .runner import run_bodies, BODIES_HEADER, LINKS_HEADER  # noqa: F401

MultibodySystem = System

__all__ = ["System", "MultibodySystem", "run_bodies", "BODIES_HEADER", "LINKS_HEADER"]

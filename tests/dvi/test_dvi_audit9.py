"""Audit 9 (g) of the multibody engine: unconverged solves are warned about, the angle motor's
tracking error is clamped by the recovery speed, fixed bodies never move, a preload-only spring
reports its force, min_bounce_speed is Chrono's."""
import math
import warnings

import numpy as np
import pytest

from sphdvi.dvi import System

G = 9.81


def imposed_into_wall(solver="bb", **kw):
    """Audit g's p10_imposed.py: a box with an imposed vx = 1 m/s (other components free) on a
    floor, driven into a wall at x = 0.3 m (its face reaches it at t = 0.2 s): no solution
    exists (then bb/apgd/psor: residual 0.8–1.0 m/s, contact forces 1e7 N; direct 1.6 m/s and
    the box pushed through the wall)."""
    s = System(gravity=(0, 0, -G), solver=solver, **kw)
    b = s.add_body(mass=1.0, inertia=(0.0067,) * 3, pos=(0, 0, 0.1),
                   imposed_velocity=(1.0, None, None, None, None, None), name="pusher")
    s.add_box(b, (0.1,) * 3)
    s.add_plane((0, 0, 0), (0, 0, 1))
    s.add_plane((0.3, 0, 0), (-1, 0, 0))
    return s, b


def test_unconverged_solve_is_warned_once_per_episode():
    """The box reaches the wall at t = 0.2 s; from then on the solver's residual stays ~0.8 m/s
    with 1e7 N forces: one warning (time, residual, the body) after RESIDUAL_WARN_STEPS steps,
    none before the wall, none repeated while the episode lasts; the line is queued for run.log."""
    from sphdvi.dvi.system import RESIDUAL_WARN_STEPS
    s, b = imposed_into_wall()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(195):
            s.step(1e-3)
    assert s.take_warnings() == []
    with pytest.warns(UserWarning, match="multibody solver not converged") as rec:
        for _ in range(300):
            s.step(1e-3)
    assert len(rec) == 1
    msg = str(rec[0].message)
    assert "pusher" in msg and "ground" in msg
    t = float(msg.split("at t=")[1].split(" s")[0])
    assert 0.2 < t < 0.2 + (RESIDUAL_WARN_STEPS + 5) * 1e-3
    assert s.last_residual > s.residual_warning
    assert s.take_warnings() == [msg]
    assert s.take_warnings() == []


def test_deferred_warnings_are_only_queued():
    """A run loop sets defer_warnings and logs take_warnings() itself (run.log and stderr)."""
    s, b = imposed_into_wall(solver="psor")
    s.defer_warnings = True
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(300):
            s.step(1e-3)
    lines = s.take_warnings()
    assert len(lines) == 1 and "pusher" in lines[0]


def test_converged_contacts_do_not_warn():
    s = System(gravity=(0, 0, -G), solver="psor", max_iter=50)
    s.add_plane()
    b = s.add_body(1.0, (0.0067,) * 3, pos=(0, 0, 0.12), vel=(1.0, 0, 0))
    s.add_box(b, (0.1,) * 3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(300):
            s.step(1e-3)
    assert s.take_warnings() == []


def hinge_with_angle_motor(target, vrec=0.6):
    s = System(gravity=(0, 0, 0), solver="bb", max_iter=100, tol=1e-12, recovery_speed=vrec)
    b = s.add_body(1.0, (0.1, 0.1, 0.1), pos=(0.5, 0, 0))
    lid = s.add_mate(b, -1, point=(0, 0, 0), axis=(0, 0, 1), mask=(1, 1, 1, 1, 1, 0),
                     motor="angle", motor_target=target)
    return s, b, lid


def test_angle_motor_started_off_target_turns_at_the_recovery_speed():
    """Target 1 rad from angle 0 (audit g p11: ω = 1000 rad/s in the first step): the motor turns
    at the recovery speed 0.6 rad/s (ChLinkMateGeneric's clamp) and then holds the target."""
    s, b, lid = hinge_with_angle_motor(1.0)
    w = []
    for _ in range(2500):
        s.step(1e-3)
        w.append(s.omega_world[b, 2])
    w = np.array(w)
    assert np.abs(w).max() <= 0.6 + 1e-9
    np.testing.assert_allclose(w[:1000], 0.6, rtol=1e-9)
    ang = math.atan2(s.pos[b, 1], s.pos[b, 0])
    assert abs(ang - 1.0) < 1e-9
    assert abs(w[-1]) < 1e-9


def test_angle_motor_on_target_follows_a_fast_target_exactly():
    """A target moving at 3 rad/s (above the recovery speed) from the body's angle: the rate term
    is not clamped, the angle follows q*(t) at every step."""
    s, b, lid = hinge_with_angle_motor(lambda t: 3.0 * t)
    for k in range(1, 501):
        s.step(1e-3)
        ang = 2.0 * math.atan2(s.quat[b, 3], s.quat[b, 0])      # the body's turn about z
        assert abs(ang - 3.0 * k * 1e-3) < 1e-9
    assert abs(s.omega_world[b, 2] - 3.0) < 1e-9


def test_fixed_body_refuses_a_velocity_and_never_moves():
    """audit g p12: a fixed body given vel/omega moved 1 m and turned 57° in 1 s."""
    s = System()
    with pytest.raises(ValueError, match="fixed body cannot have a velocity"):
        s.add_body(mass=1.0, kind="fixed", vel=(1, 0, 0), omega=(0, 0, 1))
    f = s.add_body(mass=1.0, pos=(0.5, 0, 0), kind="fixed")
    with pytest.raises(ValueError, match="is fixed"):
        s.set_velocity(f, vel=(1, 0, 0))
    s.set_velocity(f, vel=(0, 0, 0))
    s.vel[f] = (1.0, 0, 0)            # even set behind the API's back
    s.omega_b[f] = (0, 0, 1.0)
    for _ in range(100):
        s.step(1e-2)
    np.testing.assert_array_equal(s.pos[f], (0.5, 0, 0))
    np.testing.assert_array_equal(s.quat[f], (1, 0, 0, 0))


def test_moving_body_still_moves():
    s = System(gravity=(0, 0, 0))
    m = s.add_body(mass=1.0, kind="moving", vel=(1, 0, 0))
    for _ in range(100):
        s.step(1e-2)
    assert abs(s.pos[m, 0] - 1.0) < 1e-12


def test_preload_only_spring_reports_its_force():
    """audit g p14: preload 2 N with k = c = 0 pushed the body (vz = −2e-3) but link_force was 0.
    Now the force on body 1 (away from point 2), with no torque about the link point, the same
    as a spring whose (tiny) stiffness puts the preload into a row."""
    forces = []
    for k in (0.0, 1e-9):
        s = System(gravity=(0, 0, 0))
        b = s.add_body(mass=1.0, pos=(0, 0, -1.0))
        l = s.add_spring(b, -1, point1=(0.1, 0, -1), point2=(0.1, 0, 0), preload=2.0, stiffness=k)
        s.step(1e-3)
        assert abs(s.vel[b, 2] + 2e-3) < 1e-9
        forces.append(s.link_force[l].copy())
        np.testing.assert_allclose(s.link_torque[l], 0.0, atol=1e-12)
    np.testing.assert_allclose(forces[0], (0, 0, -2.0), atol=1e-12)
    np.testing.assert_allclose(forces[0], forces[1], atol=1e-9)


def test_min_bounce_speed_default_is_chronos():
    """Chrono's ChSystem default 0.15 m/s, compared with the rebound speed e·|v_n|: with e = 0.5 a
    ball bouncing at 0.28 m/s (rebound 0.14) stops, at 0.32 m/s (rebound 0.16) bounces."""
    assert System().min_bounce_speed == 0.15
    ups = []
    for v in (0.28, 0.32):
        s = System(gravity=(0, 0, 0), solver="bb", tol=1e-12)
        m = s.add_material("m", friction=0.0, restitution=0.5)
        s.add_plane(material=m)
        b = s.add_body(1.0, (0.004,) * 3, pos=(0, 0, 0.1 + 0.5 * v * 1e-3), vel=(0, 0, -v))
        s.add_sphere(b, 0.1, material=m)
        for _ in range(3):
            s.step(1e-3)
        ups.append(s.vel[b, 2])
    assert abs(ups[0]) < 1e-9
    assert abs(ups[1] - 0.16) < 1e-9


def test_unconverged_warning_reaches_run_log(tmp_path, monkeypatch):
    """A body-only `sphdvi run` logs the System's warning in run.log ("WARNING: ...") and, unless
    -q, on stderr as a UserWarning (here forced: every residual counts as too large)."""
    from pathlib import Path

    from click.testing import CliRunner

    import sphdvi.dvi.system as dsys
    from sphdvi.cli import main
    case = Path(__file__).resolve().parents[2] / "cases" / "pendulum" / "CasePendulum_Def.xml"
    init = dsys.System.__init__

    def forced(self, *a, **kw):
        init(self, *a, **kw)
        self.residual_warning = -1.0
    monkeypatch.setattr(dsys.System, "__init__", forced)
    for quiet in (True, False):
        out = tmp_path / f"out{quiet}"
        args = ["run", str(case), "-o", str(out), "--tmax", "0.05", "--tout", "0.01"] + (["-q"] if quiet else [])
        with warnings.catch_warnings(record=True) as rec:
            warnings.simplefilter("always")
            r = CliRunner().invoke(main, args)
        assert r.exit_code == 0, r.output
        log = (out / "run.log").read_text()
        assert log.count("WARNING: multibody solver not converged") == 1
        ours = [w for w in rec if "multibody solver not converged" in str(w.message)]
        assert len(ours) == (0 if quiet else 1)

"""Chains of movements as DualSPHysics's JMotionObj::ProcesTime runs them: a circular movement
entered again keeps its moved reference point (a looped mvcir closes its circle), a negative
duration is a flash (the displacement of |duration| seconds at once), and the walk along a looping
chain is kept between evaluations (constant cost per step, bitwise the walk from the start)."""
import math

import numpy as np
import pytest

import sphdvi.motion as motion
from sphdvi.motion import MotionSet, chain_transform

AXZ = {"axisp1": [0, 0, 0], "axisp2": [0, 0, 1], "anglesunits": "degrees"}
POINT = np.array([[2.0, 0.5, 0.3]])


def chain(movs, *events):
    events = [dict(mov=1, start=0.0, finish=None, **e) if "mov" not in e else dict(dict(finish=None), **e)
              for e in (events or ({},))]
    return {"ref": 1, "movements": movs, "begin": events[0], "events": events, "parents": []}


def stepped(c, times):
    """MotionSet's (incremental) transforms at each of ``times`` in turn."""
    ms = MotionSet([c])
    return [ms.transform(1, t) for t in times]


def test_looped_mvcir_closes_its_circle():
    """mvcir 180 deg/s for 0.5 s, next=itself, ref (1,0,0) about z: four passes of 90 degrees are a
    full turn (DualSPHysics: back home at t = 2; each pass restarting from the XML ref made the
    object drift 1.41 m per pass, (-2, -3.5, 0.3) at t = 2)."""
    c = chain([dict(type="mvcir", id=1, duration=0.5, next=1, vel=180.0, ref=[1, 0, 0], **AXZ)])
    expect = {1.0: [0.0, 0.5, 0.3], 2.0: [2.0, 0.5, 0.3]}
    for t, x in expect.items():
        assert chain_transform(c, t).apply(POINT)[0][0] == pytest.approx(x, abs=1e-12)
    times = np.arange(1, 2001) * 1e-3
    for t, r in zip(times, stepped(c, times)):
        if round(t, 9) in expect:
            assert r.apply(POINT)[0][0] == pytest.approx(expect[round(t, 9)], abs=1e-12)


def test_looped_mvcirsinu_oscillates_about_home():
    """mvcirsinu 90 deg amplitude, 1 Hz, 0.25 s per pass, next=itself (the phase carried): back at
    the start every half period, as DualSPHysics (it drifted by -2 m in x every 0.5 s)."""
    c = chain([dict(type="mvcirsinu", id=1, duration=0.25, next=1, freq=1.0, ampl=90.0, ref=[1, 0, 0], **AXZ)])
    for t in (0.5, 1.0, 1.5, 2.0):
        assert chain_transform(c, t).apply(POINT)[0][0] == pytest.approx(POINT[0], abs=1e-12)
    # a quarter period in, the ref point has turned by the full amplitude (right-handed about -z)
    assert chain_transform(c, 0.25).d == pytest.approx(np.array([0, -1, 0]) - [1, 0, 0], abs=1e-12)


def test_a_later_event_goes_on_from_the_moved_reference():
    """The circular movement's reference point belongs to the object (JMotion::AxisAdd): a second
    <begin> of the same mvcir goes on round the circle from where the first left it."""
    c = chain([dict(type="mvcir", id=1, duration=0.5, next=None, vel=180.0, ref=[1, 0, 0], **AXZ)],
              dict(mov=1, start=0.0, finish=None), dict(mov=1, start=1.0, finish=None))
    assert chain_transform(c, 1.6).d == pytest.approx([-2, 0, 0], abs=1e-12)      # half a turn in all
    times = np.arange(1, 1601) * 1e-3
    assert stepped(c, times)[-1].d == pytest.approx([-2, 0, 0], abs=1e-12)


def test_two_circular_movements_each_start_from_their_own_ref():
    """Two different circular movements with the same ref in a chain: each has its own Ref axis."""
    c = chain([dict(type="mvcir", id=1, duration=0.5, next=2, vel=180.0, ref=[1, 0, 0], **AXZ),
               dict(type="mvcir", id=2, duration=0.5, next=None, vel=180.0, ref=[1, 0, 0], **AXZ)])
    one = chain_transform(chain([dict(c["movements"][0], next=None)]), 0.5).d
    assert chain_transform(c, 1.0).d == pytest.approx(2 * one, abs=1e-12)


def test_negative_duration_is_a_flash():
    """mvrect of duration -0.5 at 1 m/s: a jump of 0.5 m once t has passed the event's start, no
    time taken (the next movement starts then), as JMotionMovActive's Flash / MovAddTeleport."""
    c = chain([dict(type="mvrect", id=1, duration=-0.5, next=2, vel=[1, 0, 0]),
               dict(type="mvrect", id=2, duration=1.0, next=None, vel=[0, 0, 1])], dict(mov=1, start=0.2))
    assert chain_transform(c, 0.2).d == pytest.approx([0, 0, 0])
    assert chain_transform(c, 0.2 + 1e-9).d == pytest.approx([0.5, 0, 1e-9], abs=1e-15)
    assert chain_transform(c, 0.7).d == pytest.approx([0.5, 0, 0.5], abs=1e-12)
    assert chain_transform(c, 5.0).d == pytest.approx([0.5, 0, 1.0], abs=1e-12)
    assert not chain_transform(c, 5.0).V.any()


def test_a_flash_carries_its_speed_into_the_next_movement():
    """A mvrectace flash of |duration| 1 s from rest at 1 m/s^2 jumps 0.5 m and leaves 1 m/s to a
    following mvrectace without <velini> (NextMov carries Vel), which goes on at 1 m/s."""
    c = chain([dict(type="mvrectace", id=1, duration=-1.0, next=2, ace=[1, 0, 0], velini=[0, 0, 0]),
               dict(type="mvrectace", id=2, duration=10.0, next=None, ace=[0, 0, 0])])
    assert chain_transform(c, 1.0).d == pytest.approx([1.5, 0, 0], abs=1e-12)


def test_a_flash_at_the_end_of_the_chain_waits_for_its_start():
    """A flash after a 1 s movement happens once t has passed 1 s (DualSPHysics applies it in
    the step after the one that ends exactly at its start)."""
    c = chain([dict(type="mvrect", id=1, duration=1.0, next=2, vel=[1, 0, 0]),
               dict(type="mvrect", id=2, duration=-2.0, next=None, vel=[0, 0, 1])])
    assert chain_transform(c, 1.0).d == pytest.approx([1, 0, 0], abs=1e-12)
    assert chain_transform(c, 1.0 + 1e-9).d == pytest.approx([1, 0, 2], abs=1e-12)
    r = stepped(c, [0.5, 1.0, 1.001, 3.0])
    assert np.array([x.d for x in r]) == pytest.approx(np.array([[0.5, 0, 0], [1, 0, 0], [1, 0, 2], [1, 0, 2]]),
                                                        abs=1e-12)


LOOP = [dict(type="mvrect", id=1, duration=0.05, next=2, vel=[0.2, 0, 0]),
        dict(type="mvrotsinu", id=2, duration=0.03, next=3, freq=2.0, ampl=5.0, phase=30.0, **AXZ),
        dict(type="mvcir", id=3, duration=0.02, next=1, vel=90.0, ref=[1, 0, 0], **AXZ)]


def test_the_walk_is_kept_between_steps(monkeypatch):
    """A looping chain evaluated step by step costs a few movements per step late in the run (it
    walked every pass since the start before: ~600 movements at t = 20 s here)."""
    c = chain([dict(m) for m in LOOP])
    ms = MotionSet([c])
    t, dt = 0.0, 2.1e-3
    while t < 20.0:
        t += dt
        ms.transform(1, t)
    calls = []
    real = motion._segment
    monkeypatch.setattr(motion, "_segment", lambda *a: calls.append(1) or real(*a))
    ms.transform(1, t + dt)
    assert len(calls) <= 3


def test_the_kept_walk_is_bitwise_the_walk_from_the_start():
    """Positions step by step equal, bit for bit, those of a walk from the start at the same t (a
    resumed run rebuilds the walk from its time alone); going back in time starts it again."""
    c = chain([dict(m) for m in LOOP], dict(mov=1, start=0.013))
    ms = MotionSet([c])
    rng = np.random.default_rng(3)
    t = 0.0
    checks = 0
    for k in range(3000):
        t += float(rng.uniform(2e-4, 9e-4))
        r = ms.transform(1, t)
        if k % 499 == 0:
            fresh = MotionSet([c]).transform(1, t)
            assert np.array_equal(r.R, fresh.R) and np.array_equal(r.d, fresh.d)
            assert np.array_equal(r.d, chain_transform(c, t).d)
            checks += 1
    back = ms.transform(1, 1.234)
    assert np.array_equal(back.d, chain_transform(c, 1.234).d) and checks == 7
    assert math.isfinite(float(back.d[0]))


def test_a_time_before_the_movement_under_way_goes_back_a_little(monkeypatch):
    """A multibody substep or a predictor asks for a time inside the step just done: the walk goes
    back to the last movement start before it (not to the event's start), and gives the walk from
    the start's answer bit for bit, before and after a movement switch and a flash."""
    movs = [dict(m) for m in LOOP] + [dict(type="mvrect", id=4, duration=-0.01, next=1, vel=[0, 0, 1])]
    movs[2]["next"] = 4
    c = chain(movs)
    ms = MotionSet([c])
    t, dt = 0.0, 1.7e-3
    while t < 2.0:
        t += dt
        ms.transform(1, t)
    calls = []
    real = motion._segment
    monkeypatch.setattr(motion, "_segment", lambda *a: calls.append(1) or real(*a))
    for k in range(120):          # two passes of the loop: every switch, the flash
        t += dt
        for tk in (t - 0.75 * dt, t - 0.5 * dt, t):
            r, fresh = ms.transform(1, tk), chain_transform(c, tk)
            assert np.array_equal(r.d, fresh.d) and np.array_equal(r.R, fresh.R)
    calls.clear()
    for k in range(50):
        t += dt
        ms.transform(1, t - 0.5 * dt)
        ms.transform(1, t)
    assert len(calls) <= 50 * 2 * 3

"""Imposed motions and wave paddles against closed forms."""
import math

import numpy as np
import pytest

from sphdvi.motion import (MotionSet, WavePaddle, chain_transform, flap_height_to_stroke,
                           piston_height_to_stroke, wave_number)


def chain(movs, start=0.0, finish=None):
    return {"ref": 0, "movements": movs, "begin": {"mov": movs[0]["id"], "start": start, "finish": finish},
            "parents": []}


def rect(i, dur, vel, nxt=None):
    return {"type": "mvrect", "id": i, "duration": dur, "next": nxt, "vel": vel}


def test_rect_chain_with_next_and_start():
    c = chain([rect(1, 0.5, [1, 0, 0], 2), rect(2, 0.5, [-1, 0, 0], 1)], start=0.1)
    x0 = np.zeros((1, 3))
    for t, xe, ve in ((0.05, 0, 0), (0.35, 0.25, 1), (0.55, 0.45, 1), (0.85, 0.25, -1), (1.35, 0.25, 1)):
        x, v = chain_transform(c, t).apply(x0)
        assert x[0, 0] == pytest.approx(xe, abs=1e-12) and v[0, 0] == pytest.approx(ve if t > 0.1 else 0)


def test_finish_stops_motion():
    c = chain([rect(1, 100.0, [2, 0, 0])], start=0.0, finish=1.0)
    x, v = chain_transform(c, 3.0).apply(np.zeros((1, 3)))
    assert x[0, 0] == pytest.approx(2.0) and v[0, 0] == 0


def test_rectace_continues_speed():
    movs = [rect(1, 1.0, [1, 0, 0], 2), {"type": "mvrectace", "id": 2, "duration": 1.0, "next": None,
                                          "ace": [2, 0, 0]}]
    x, v = chain_transform(chain(movs), 1.5).apply(np.zeros((1, 3)))
    assert x[0, 0] == pytest.approx(1.0 + 0.5 + 0.5 * 2 * 0.25) and v[0, 0] == pytest.approx(2.0)


def test_what_a_movement_carries_into_the_next_is_dualsphysics_s():
    """As JMotionMovActive::NextMov: a mvrectace without <velini> takes the previous movement's
    final speed only when that one is rectilinear (after a rotation it starts from rest: it took
    the last rectilinear speed before); a mvrectsinu without <phase> goes on from the phase the
    previous mvrectsinu reached (it restarted at 0, the velocity jumping), so that two halves of
    a sinusoid chained are the whole one."""
    rot = {"type": "mvrot", "id": 2, "duration": 1.0, "next": 3, "vel": 10.0, "anglesunits": "degrees",
           "axisp1": [0, 0, 0], "axisp2": [0, 1, 0]}
    ace = {"type": "mvrectace", "id": 3, "duration": 1.0, "next": None, "ace": [0, 0, 0]}
    before = chain_transform(chain([rect(1, 1.0, [1, 0, 0], 2), rot, ace]), 2.0).apply(np.zeros((1, 3)))[0]
    after = chain_transform(chain([rect(1, 1.0, [1, 0, 0], 2), rot, ace]), 3.0).apply(np.zeros((1, 3)))
    assert after[0] == pytest.approx(before, abs=1e-12) and after[1] == pytest.approx(np.zeros((1, 3)), abs=1e-12)
    sinu = {"type": "mvrectsinu", "freq": [1, 0, 0], "ampl": [0.1, 0, 0], "anglesunits": "degrees"}
    halves = chain([dict(sinu, id=1, duration=0.3, next=2), dict(sinu, id=2, duration=100.0, next=None)])
    whole = chain([dict(sinu, id=1, duration=100.0, next=None)])
    for t in (0.2, 0.45, 0.8):
        xh, vh = chain_transform(halves, t).apply(np.zeros((1, 3)))
        xw, vw = chain_transform(whole, t).apply(np.zeros((1, 3)))
        assert xh == pytest.approx(xw, abs=1e-12) and vh == pytest.approx(vw, abs=1e-12)
        assert xw[0, 0] == pytest.approx(0.1 * math.sin(2 * math.pi * t), abs=1e-12)


def test_rotation_quarter_turn_about_axis():
    m = {"type": "mvrot", "id": 1, "duration": 100.0, "next": None, "vel": 90.0, "anglesunits": "degrees",
         "axisp1": [1, 0, 0], "axisp2": [1, 1, 0]}
    x, v = chain_transform(chain([m]), 1.0).apply(np.array([[2.0, 0, 0]]))
    # DualSPHysics's sense (JMatrix4::MatrixRot): +90 degrees about the axis (1,0,0) -> (1,1,0)
    # is the right-hand quarter turn about -y, which takes (2,0,0) to (1,0,1)
    assert x[0] == pytest.approx([1, 0, 1], abs=1e-12)
    assert v[0] == pytest.approx(np.cross([0, -math.pi / 2, 0], x[0] - [1, 0, 0]))


def test_rotation_sense_is_dualsphysics_matrixrot():
    """DualSPHysics's JMatrix4::MatrixRot(ang, p1, p2), written out as its code composes it
    (move p1 to the origin, turn the axis onto z, rotate with rz = [[c, s], [-s, c]], undo), for
    a few axes: mvrot gives the same matrix."""
    def matrixrot(ang, p1, p2):
        rad = math.radians(ang)
        v = np.subtract(p2, p1, dtype=float)
        L, L1 = np.linalg.norm(v), math.hypot(v[1], v[2])
        rx, rxm1, ry, rym1, rz = (np.eye(3) for _ in range(5))
        if L1 == 0:
            rx[1:, 1:] = [[0, 1], [-1, 0]]
            rxm1[1:, 1:] = [[0, -1], [1, 0]]
        else:
            rx[1:, 1:] = [[v[2] / L1, v[1] / L1], [-v[1] / L1, v[2] / L1]]
            rxm1[1:, 1:] = [[v[2] / L1, -v[1] / L1], [v[1] / L1, v[2] / L1]]
        ry[0, 0], ry[0, 2], ry[2, 0], ry[2, 2] = L1 / L, v[0] / L, -v[0] / L, L1 / L
        rym1[0, 0], rym1[0, 2], rym1[2, 0], rym1[2, 2] = L1 / L, -v[0] / L, v[0] / L, L1 / L
        rz[:2, :2] = [[math.cos(rad), math.sin(rad)], [-math.sin(rad), math.cos(rad)]]
        return rx @ ry @ rz @ rym1 @ rxm1
    for p2 in ([0, 1, 0], [0, -1, 0], [1, 0, 0], [0, 0, 1], [0.3, 0.5, 0.8]):
        m = {"type": "mvrot", "id": 1, "duration": 100.0, "next": None, "vel": 30.0, "anglesunits": "degrees",
             "axisp1": [0, 0, 0], "axisp2": p2}
        assert chain_transform(chain([m]), 1.0).R == pytest.approx(matrixrot(30.0, [0, 0, 0], p2), abs=1e-12)


def test_sinusoid_velocity_is_derivative():
    m = {"type": "mvrectsinu", "id": 1, "duration": 100.0, "next": None, "freq": [1.5, 0, 0], "ampl": [0.1, 0, 0],
         "phase": [30, 0, 0], "anglesunits": "degrees"}
    c = chain([m])
    t, h = 0.37, 1e-6
    xp = chain_transform(c, t + h).apply(np.zeros((1, 3)))[0][0, 0]
    xm = chain_transform(c, t - h).apply(np.zeros((1, 3)))[0][0, 0]
    v = chain_transform(c, t).apply(np.zeros((1, 3)))[1][0, 0]
    assert v == pytest.approx((xp - xm) / (2 * h), rel=1e-6)
    assert chain_transform(c, 0.0 + 1e-12).apply(np.zeros((1, 3)))[0][0, 0] == pytest.approx(0, abs=1e-9)


def test_parent_hierarchy():
    child = chain([rect(1, 100.0, [0, 0, 1])])
    child["parents"] = [chain([rect(1, 100.0, [1, 0, 0])])]
    ms = MotionSet([child])
    x, v = ms.transform(0, 2.0).apply(np.zeros((1, 3)))
    assert x[0] == pytest.approx([2, 0, 2]) and v[0] == pytest.approx([1, 0, 1])


def test_transfer_functions_limits():
    """Deep water: piston H/S → 2, flap H/S → 2(kd−1)/kd; shallow water: piston H/S → kd."""
    assert piston_height_to_stroke(50.0, 1.0) == pytest.approx(2.0, rel=1e-6)
    assert flap_height_to_stroke(50.0, 1.0) == pytest.approx(2 * 49 / 50, rel=1e-9)
    assert piston_height_to_stroke(1e-3, 1.0) == pytest.approx(1e-3, rel=1e-3)
    k = wave_number(1.2, 0.4)
    assert (2 * math.pi / 1.2) ** 2 == pytest.approx(9.81 * k * math.tanh(0.4 * k), rel=1e-12)


def test_piston_stroke_and_ramp():
    spec = {"type": "piston", "mkbound": 10, "depth": 0.4, "waveheight": 0.1, "waveperiod": 1.2, "ramp": 1,
            "phase": 0.0, "pistondir": [1, 0, 0]}
    p = WavePaddle(spec)
    S = 0.1 / piston_height_to_stroke(wave_number(1.2, 0.4), 0.4)
    xs = [p.stroke_position(t)[0] for t in np.linspace(1.2, 2.4, 2001)]
    assert max(xs) == pytest.approx(S / 2, rel=1e-5) and min(xs) == pytest.approx(-S / 2, rel=1e-5)
    assert abs(p.stroke_position(0.3)[0]) < S / 2 * 0.3 / 1.2 + 1e-12


def test_flap_rotates_about_hinge():
    spec = {"type": "flap", "mkbound": 11, "depth": 1.0, "waveheight": 0.1, "waveperiod": 2.0, "ramp": 0,
            "flapaxis0": [0, 0, 0], "flapaxis1": [0, 1, 0], "variabledraft": 0.0}
    p = WavePaddle(spec)
    T = p.transform(0.5)
    hinge = T.apply(np.array([[0.0, 0.0, 0.0]]))[0][0]
    assert hinge == pytest.approx([0, 0, 0], abs=1e-12)
    top = T.apply(np.array([[0.0, 0.0, 1.0]]))[0][0]
    assert top[0] == pytest.approx(p.stroke_position(0.5)[0] / math.hypot(1, p.stroke_position(0.5)[0]), rel=1e-9)


def test_flap_second_order_warns_and_runs_first_order():
    """DualSPHysics generates second-order waves with pistons only: a flap
    asking waveorder 2 is told so and moves as the first-order flap."""
    spec = {"type": "flap", "mkbound": 11, "depth": 1.0, "waveheight": 0.1, "waveperiod": 2.0, "ramp": 0,
            "flapaxis0": [0, 0, 0], "flapaxis1": [0, 1, 0], "variabledraft": 0.0}
    first = WavePaddle(spec)
    with pytest.warns(UserWarning, match="pistons only"):
        second = WavePaddle({**spec, "waveorder": 2})
    for t in (0.3, 0.7, 1.9):
        assert second.stroke_position(t) == first.stroke_position(t)

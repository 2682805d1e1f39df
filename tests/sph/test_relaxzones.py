"""Relaxation zones (sphdvi.sph.relaxzones): the weight, the target velocity against the wave theory of
the paddles (an independent implementation) and against the Stokes drift's mass transport, the step's
factor, the clock, and the uniform zone's turned box."""
import math

import numpy as np
import pytest

from sphdvi.motion import SpectrumPaddle, WavePaddle, wave_number
from sphdvi.sph.relaxzones import UniformZone, WaveZone, relaxation_zones, weight
from sphdvi.sph.state import FLUID, FluidState

H, T, D = 0.03, 1.2, 0.3


def regular(**kw):
    spec = {"type": "rzwaves_regular", "waveheight": H, "waveperiod": T, "depth": D, "swl": D, "center": [1.0, 0, 0],
            "width": 1.0, "waveorder": 1, "phase": 0.0, "ramp": 0.0, "start": 0.0, "duration": 0.0, "coefdt": 0.0,
            "psi": 0.9, "beta": 1.0, "coefdir": [1.0, 0.0, 1.0], "driftcorrection": 0.0}
    spec.update(kw)
    return spec


def spectrum(**kw):
    spec = regular(type="rzwaves_spectrum", waveheight=0.04, waveperiod=1.4, spectrum="jonswap", waves=30,
                   discretization="stretched", peakcoef=3.3, randomseed=5, serieini=0.0, ramptime=0.0)
    del spec["phase"], spec["ramp"]
    spec.update(kw)
    return spec


def column(x, zs, vel=None, ptype=FLUID):
    """Fluid particles at x and heights zs (m above the bottom, z = 0), velocity ``vel``."""
    pos = np.column_stack([np.full(len(zs), x), np.zeros(len(zs)), zs])
    v = np.zeros((len(zs), 3)) if vel is None else np.tile(np.asarray(vel, float), (len(zs), 1))
    return FluidState(pos, v, mass=1.0, ptype=np.full(len(zs), ptype))


def target_velocity(zone, pos, t):
    """v_T of a wave zone at ``pos`` in numpy, with cosh and sinh (the kernel uses exponentials):
    (u, 0, w), the drift c cosh K(z+d)/(2 sinh² (K d/2)) subtracted."""
    amp_w, wk, theta0, drift_c, drift_k = zone.components(zone.clock(t) or 0.0)
    x, z, d = pos[:, 0] - zone.centre[0], pos[:, 2] - zone.swl, zone.depth
    out = np.zeros((len(x), 3))
    for a, k, t0 in zip(amp_w, wk, theta0):
        out[:, 0] += a * np.cosh(k * (z + d)) / np.sinh(k * d) * np.cos(t0 - k * x)
        out[:, 2] -= a * np.sinh(k * (z + d)) / np.sinh(k * d) * np.sin(t0 - k * x)
    for c, kk in zip(drift_c, drift_k):
        out[:, 0] -= c * np.cosh(kk * (z + d)) / (2.0 * np.sinh(0.5 * kk * d) ** 2)
    return out


ZS = np.linspace(0.005, 0.33, 12)       # through the depth, and above the still water (a crest)


def test_the_weight_is_one_at_the_centre_and_zero_at_the_edges():
    s = np.linspace(-1, 1, 201)
    f = weight(s)
    assert f[100] == pytest.approx(1.0, abs=1e-14) and abs(f[0]) < 1e-14 and abs(f[-1]) < 1e-14
    assert np.allclose(f, f[::-1], atol=1e-14) and np.all(np.diff(f[100:]) < 0)
    # DualSPHysics's (psi 0.9, beta 1): (tanh 1.4 − tanh 0.4 − f_sub)/f_div at s = 0.5
    fsub = math.tanh(1.9) - math.tanh(0.1)
    assert weight(0.5) == pytest.approx((math.tanh(1.4) - math.tanh(-0.4) - fsub) / (2 * math.tanh(0.9) - fsub))


@pytest.mark.parametrize("order", [1, 2])
def test_the_centre_takes_the_regular_waves_orbital_velocity(order):
    zone = WaveZone(regular(waveorder=order), 1)
    paddle = WavePaddle({"type": "piston", "depth": D, "waveheight": H, "waveperiod": T, "waveorder": order})
    for t in (0.37, 1.9):
        st = column(1.0, ZS, vel=[0.3, 0.1, -0.2])
        zone.apply(st, t, 1e-4)             # coefdt 0: the whole target at the centre
        for i, z in enumerate(ZS):
            u, w = paddle.orbital_velocity(0.0, z - D, t)
            assert st.vel[i, 0] == pytest.approx(float(u[0]), rel=1e-12, abs=1e-14)
            assert st.vel[i, 2] == pytest.approx(float(w[0]), rel=1e-12, abs=1e-14)
        assert np.all(st.vel[:, 1] == 0.1)   # y is left
    if order == 2:      # the bound harmonic is there: order 2 differs from order 1 by it
        a, b = column(1.0, ZS), column(1.0, ZS)
        zone.apply(a, 0.37, 1e-4)
        WaveZone(regular(), 1).apply(b, 0.37, 1e-4)
        assert np.abs(a.vel - b.vel).max() > 1e-4


def test_the_centre_takes_the_seas_orbital_velocity():
    spec = spectrum()
    zone = WaveZone(spec, 1)
    paddle = SpectrumPaddle({**spec, "type": "piston_spectrum", "waveorder": 1})
    st = column(1.0, ZS)
    zone.apply(st, 3.3, 1e-4)
    for i, z in enumerate(ZS):
        u, w = paddle.orbital_velocity(0.0, z - D, 3.3)
        assert st.vel[i, 0] == pytest.approx(float(u[0]), rel=1e-10, abs=1e-14)
        assert st.vel[i, 2] == pytest.approx(float(w[0]), rel=1e-10, abs=1e-14)


def test_across_the_zone_the_weight_blends_target_and_own_velocity():
    zone = WaveZone(regular(), 1)
    v0 = np.array([0.2, 0.0, -0.1])
    for x in (0.55, 0.8, 1.25, 1.5):
        st = column(x, ZS, vel=v0)
        target = target_velocity(zone, st.pos, 0.9)
        zone.apply(st, 0.9, 1e-4)
        f = weight((x - 1.0) / 0.5)
        assert np.allclose(st.vel[:, 0], f * target[:, 0] + (1 - f) * v0[0], rtol=1e-12, atol=1e-15)
        assert np.allclose(st.vel[:, 2], f * target[:, 2] + (1 - f) * v0[2], rtol=1e-12, atol=1e-15)
    for x in (0.49, 1.51):          # outside the zone
        st = column(x, ZS, vel=v0)
        zone.apply(st, 0.9, 1e-4)
        assert np.all(st.vel == v0)
    st = column(1.0, ZS, vel=v0, ptype=2)    # a floating body's particles are not relaxed
    zone.apply(st, 0.9, 1e-4)
    assert np.all(st.vel == v0)


def test_the_step_factor_is_coefdt_dt_held_at_one_and_scaled_by_coefdir():
    v0 = np.array([0.2, 0.0, -0.1])
    for coefdt, dt, factor in ((1000.0, 1e-4, 0.1), (1000.0, 5e-3, 1.0), (0.0, 1e-4, 1.0)):
        zone = WaveZone(regular(coefdt=coefdt, coefdir=[0.5, 0.0, 0.25]), 1)
        st = column(1.0, ZS, vel=v0)
        target = target_velocity(zone, st.pos, 0.9)
        zone.apply(st, 0.9, dt)
        assert np.allclose(st.vel[:, 0], 0.5 * factor * target[:, 0] + (1 - 0.5 * factor) * v0[0], rtol=1e-12)
        assert np.allclose(st.vel[:, 2], 0.25 * factor * target[:, 2] + (1 - 0.25 * factor) * v0[2], rtol=1e-12)


def test_the_zone_acts_between_start_and_start_plus_duration_with_its_ramp():
    zone = WaveZone(regular(start=1.0, duration=2.0, ramp=2.0), 1)      # ramp: 2 periods = 2.4 s
    v0 = [0.2, 0.0, -0.1]
    for t in (0.99, 3.01):
        st = column(1.0, ZS, vel=v0)
        zone.apply(st, t, 1e-4)
        assert np.all(st.vel == v0)
    full = WaveZone(regular(start=1.0), 1)
    a, b = column(1.0, ZS), column(1.0, ZS)
    zone.apply(a, 2.2, 1e-4)               # τ = 1.2 s: half the ramp
    full.apply(b, 2.2, 1e-4)
    assert np.allclose(a.vel, 0.5 * b.vel, rtol=1e-12, atol=1e-16)


def test_the_drift_correction_removes_the_stokes_mass_transport():
    """Σ over a column of the subtracted drift, integrated over the depth, is the linear wave's mass
    transport a² ω / (2 tanh kd) (= E/(ρ c), Dean & Dalrymple 1991 §7); under the ramp it takes r²."""
    zs = np.linspace(0.0, D, 3001)
    a, b = column(1.0, zs), column(1.0, zs)
    WaveZone(regular(driftcorrection=1.0), 1).apply(a, 0.9, 1e-4)
    WaveZone(regular(), 1).apply(b, 0.9, 1e-4)
    drift = b.vel[:, 0] - a.vel[:, 0]
    transport = np.sum(0.5 * (drift[1:] + drift[:-1]) * np.diff(zs))
    k, omega = wave_number(T, D), 2 * math.pi / T
    assert transport == pytest.approx((H / 2) ** 2 * omega / (2 * math.tanh(k * D)), rel=1e-6)
    assert np.all(drift > 0) and drift[-1] > drift[0]          # largest at the surface
    c = column(1.0, zs)
    WaveZone(regular(driftcorrection=0.5, ramp=2.0), 1).apply(c, 0.6, 1e-4)     # r = 0.25
    d = column(1.0, zs)
    WaveZone(regular(ramp=2.0), 1).apply(d, 0.6, 1e-4)
    assert np.allclose(d.vel[:, 0] - c.vel[:, 0], 0.5 * 0.25 ** 2 * drift, rtol=1e-9)


def test_a_seas_drift_is_the_sum_of_its_waves():
    zs = np.linspace(0.0, D, 2001)
    spec = spectrum()
    a, b = column(1.0, zs), column(1.0, zs)
    WaveZone({**spec, "driftcorrection": 1.0}, 1).apply(a, 2.0, 1e-4)
    zone = WaveZone(spec, 1)
    zone.apply(b, 2.0, 1e-4)
    drift = b.vel[:, 0] - a.vel[:, 0]
    transport = np.sum(0.5 * (drift[1:] + drift[:-1]) * np.diff(zs))
    expect = float(np.sum(zone.amp ** 2 * zone.omega / (2 * np.tanh(zone.k * D))))
    assert transport == pytest.approx(expect, rel=1e-5)


def test_a_uniform_zone_relaxes_its_turned_box_towards_its_velocity():
    spec = {"type": "rzwaves_uniform", "start": 0.0, "duration": 0.0, "coefdt": 0.0, "psi": 0.9, "beta": 1.0,
            "domainbox": {"point": [0.0, -0.5, 0.0], "size": [1.0, 1.0, 0.2], "direction": [1.0, 0.0, 0.0],
                          "rotation": {"angle": math.radians(30.0), "p1": [0.0, 0.0, 0.0], "p2": [0.0, 1.0, 0.0]}},
            "velocitytimes": [[0.0, 0.0], [2.0, 0.5]]}
    zone = relaxation_zones([spec])[0]
    assert isinstance(zone, UniformZone)
    # a right-handed turn of 30° about +y takes +x to (cos 30°, 0, −sin 30°)
    d = np.array([math.cos(math.radians(30)), 0.0, -math.sin(math.radians(30))])
    assert zone.normal == pytest.approx(d)
    rng = np.random.default_rng(1)
    pos = rng.uniform([-0.2, -0.1, -0.7], [1.2, 0.1, 0.4], (1000, 3))
    v0 = rng.normal(size=(1000, 3))
    st = FluidState(pos, v0, mass=1.0)
    zone.apply(st, 1.0, 1e-4)                      # V(1 s) = 0.25 m/s
    local = np.column_stack([pos @ d, pos[:, 1] + 0.5, pos @ np.array([math.sin(math.radians(30)), 0,
                                                                       math.cos(math.radians(30))])])
    inside = np.all((local > 0) & (local < [1.0, 1.0, 0.2]), axis=1)
    assert 60 < inside.sum() < 900
    f = weight((local[:, 0] - 0.5) / 0.5)[:, None]
    expect = np.where(inside[:, None], f * 0.25 * d + (1 - f) * v0, v0)
    assert np.allclose(st.vel, expect, rtol=1e-12, atol=1e-14)


def test_deep_below_a_short_wave_the_target_is_still_water_not_nan():
    """k z < −745: e^{kz} underflows; the kernel leaves the component out (both its terms are below
    e^{−kd}) instead of dividing by zero."""
    zone = WaveZone(regular(waveheight=0.01, waveperiod=0.2, depth=10.0, swl=10.0, driftcorrection=1.0), 1)
    assert zone.k[0] * 9.0 > 745
    st = column(1.0, np.array([0.5, 5.0, 9.99]), vel=[0.1, 0.0, 0.1])
    zone.apply(st, 0.3, 1e-4)
    assert np.all(np.isfinite(st.vel))
    assert np.all(st.vel[0] == 0.0)                 # 9.5 m below the surface: still water, fully imposed
    assert abs(st.vel[2, 0]) > 1e-3                 # at the surface the wave moves the water

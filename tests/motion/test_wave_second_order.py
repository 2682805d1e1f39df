"""Second-order irregular waves (sphdvi.wave_second_order) against the closed forms they must reduce
to: Stokes's second-order wave and Madsen's (1971) second-order piston for one wave, Longuet-Higgins &
Stewart's deep-water pair interactions and their set-down under a narrow wave group; and the
irregular pistons (<piston_spectrum>, <piston_focused> with waveorder 2) that use them."""
import math

import numpy as np
import pytest

from sphdvi.motion import (FocusedPaddle, SpectrumPaddle, WavePaddle, _coth_over_sinh2, group_velocity,
                           piston_height_to_stroke, wave_number)
from sphdvi.wave_second_order import SecondOrderSea, depth_mean, symmetric, wave_numbers

G = 9.81
SEAS = [(1.0, 0.5), (2.0, 0.4), (1.2, 3.0), (4.0, 0.5), (0.5, 50.0)]      # (period s, depth m): kh 0.36 - 800


def one_wave(period, depth):
    k = wave_number(period, depth)
    return SecondOrderSea([2 * math.pi / period], depth, [piston_height_to_stroke(k, depth)]), k


def test_wave_numbers_solve_the_dispersion_relation():
    w = np.array([0.3, 2.0, 9.0, 40.0])
    k = wave_numbers(w, 0.7)
    np.testing.assert_allclose(G * k * np.tanh(k * 0.7), w * w, rtol=1e-13)
    assert k[1] == pytest.approx(wave_number(2 * math.pi / 2.0, 0.7), rel=1e-14)


def test_depth_mean():
    p, h = 3.0, 0.4
    z = np.linspace(-h, 0, 200001)
    f = np.cosh(p * (z + h)) / np.cosh(p * h)
    assert float(depth_mean(p, h)) == pytest.approx(np.trapezoid(f, z) / h, rel=1e-9)
    assert float(depth_mean(-p, h)) == float(depth_mean(p, h))
    assert float(depth_mean(0.0, h)) == 1.0 and float(depth_mean(1e4, 1.0)) == pytest.approx(1e-4)


@pytest.mark.parametrize("period, depth", SEAS)
def test_one_wave_is_stokes_and_madsen(period, depth):
    """One wave a cos θ: the bound wave (k a²/4) cosh kh (2 + cosh 2kh)/sinh³ kh cos 2θ (Stokes), the
    piston's second-order stroke (H²/32h)(3 cosh kh/sinh³ kh − 2/m1) sin 2θ with H = 2a, m1 Biesel's
    H/S, against the stroke a/m1 sin θ (Madsen 1971; DualSPHysics's regular piston)."""
    sea, k = one_wave(period, depth)
    kh = k * depth
    # ½ Re[G a² e^{2iθ}]: G = 2 × the coefficient of cos 2θ (η2), and −2i × that of sin 2θ (X2), per a²
    stokes = k / 4 * (2 + math.cosh(2 * kh)) * _coth_over_sinh2(kh) if kh < 300 else k / 2
    assert sea.eta_sum[0, 0] == pytest.approx(2 * stokes, rel=1e-12)
    m1 = piston_height_to_stroke(k, depth)
    madsen = 4 / (32 * depth) * (3 * _coth_over_sinh2(kh) - 2 / m1)
    assert sea.paddle_sum[0, 0] == pytest.approx(-2j * madsen, rel=1e-12)
    assert sea.eta_diff[0, 0] == 0 and sea.paddle_diff[0, 0] == 0        # the mean level and stroke are kept


def test_deep_water_pairs_are_longuet_higgins_and_stewart():
    """In deep water two waves' bound waves are ½ a1 a2 [(k1 + k2) cos(θ1 + θ2) − |k1 − k2| cos(θ1 − θ2)]
    (Longuet-Higgins & Stewart 1960): the symmetric kernels' off-diagonal entries ½(k1 + k2), −½|k1 − k2|."""
    sea = SecondOrderSea([2 * math.pi / 0.5, 2 * math.pi / 0.35], 100.0)
    k1, k2 = sea.k
    assert sea.eta_sum[0, 1] == pytest.approx(0.5 * (k1 + k2), rel=1e-12)
    assert sea.eta_diff[0, 1] == pytest.approx(-0.5 * abs(k1 - k2), rel=1e-12)
    assert sea.eta_sum[0, 1] == sea.eta_sum[1, 0] and sea.eta_diff[0, 1] == np.conj(sea.eta_diff[1, 0])


@pytest.mark.parametrize("period, depth", [(1.0, 0.5), (2.0, 0.4), (3.0, 0.5)])
def test_narrow_group_set_down(period, depth):
    """Two waves a hair apart beat as a group whose bound long wave is the set-down under it,
    −g a1 a2 (2 cg/c − ½)/(g h − cg²) cos(θ1 − θ2) (Longuet-Higgins & Stewart 1964, radiation stress)."""
    w = 2 * math.pi / period
    k = wave_number(period, depth)
    c, cg = w / k, float(group_velocity(w, k, depth))
    setdown = -G * (2 * cg / c - 0.5) / (G * depth - cg * cg)
    for dw in (1e-3, 1e-4):
        sea = SecondOrderSea([w, w * (1 + dw)], depth)
        assert sea.eta_diff[0, 1].real == pytest.approx(setdown, rel=5 * dw)


@pytest.mark.parametrize("period, depth", [(1.0, 0.5), (1.4, 0.4), (3.0, 0.5), (1.0, 3.0)])
def test_narrow_group_paddle_delivers_the_set_downs_flux(period, depth):
    """Under a narrow group the bound long wave is the set-down η̄ travelling at c_g, whose volume flux
    is c_g η̄ (the current under it, (c_g η̄ − M)/h, plus the short waves' transport M = g a1 a2/c
    cos(θ1 − θ2)); the subharmonic stroke must deliver it, h Ẋ2 = c_g η̄, or a free long wave carries
    the difference. X2 = Re[G⁻_12 z1 z̄2], θ1 − θ2 of frequency −Δω: G⁻_12 = i c_g η̄/(h Δω) per a1 a2."""
    w = 2 * math.pi / period
    k = wave_number(period, depth)
    c, cg = w / k, float(group_velocity(w, k, depth))
    setdown = -G * (2 * cg / c - 0.5) / (G * depth - cg * cg)
    for dw in (1e-3, 1e-4):
        ws = np.array([w, w * (1 + dw)])
        sea = SecondOrderSea(ws, depth, [piston_height_to_stroke(kk, depth) for kk in wave_numbers(ws, depth)])
        assert sea.paddle_diff[0, 1] / (1j * cg * setdown / (depth * w * dw)) == pytest.approx(1.0, abs=2 * dw)
        # the current under the group: the depth mean of the bound flow's u, Re[K_12 z1 z̄2]
        u_kernel = sea.pot_diff * (-1j * sea.k_diff) * depth_mean(sea.k_diff, depth)
        current = symmetric(np.zeros_like(u_kernel), u_kernel)[1][0, 1]
        assert current.real == pytest.approx((cg * setdown - G / c) / depth, rel=5 * dw)
        assert abs(current.imag) < 1e-9 * abs(current)


def test_the_bound_flow_is_a_potential_flow_with_the_bound_waves_surface():
    """∂u2/∂x + ∂w2/∂z = 0, w2 = 0 at the bottom, and for one wave Stokes's
    u2 = (3/16) H² ω k cosh 2k(z+h)/sinh⁴ kh cos 2θ."""
    depth = 0.4
    sea = SecondOrderSea(2 * np.pi / np.array([1.3, 1.0, 0.8]), depth)
    amp = np.array([0.01, 0.006, 0.004]) * np.exp(1j * np.array([0.3, 2.0, -1.0]))
    t, e = np.linspace(0.0, 3.0, 7), 1e-5
    for x, z in ((0.3, -0.1), (1.7, -0.33)):
        dudx = (sea.velocity(amp, x + e, z, t)[0] - sea.velocity(amp, x - e, z, t)[0]) / (2 * e)
        dwdz = (sea.velocity(amp, x, z + e, t)[1] - sea.velocity(amp, x, z - e, t)[1]) / (2 * e)
        np.testing.assert_allclose(dudx + dwdz, 0.0, atol=1e-8)
    np.testing.assert_allclose(sea.velocity(amp, 0.5, -depth, t)[1], 0.0, atol=1e-15)
    one = SecondOrderSea([2 * math.pi / 1.3], depth)
    k, w, H, z = one.k[0], 2 * math.pi / 1.3, 0.05, -0.15
    theta = w * t + 0.3 - k * 0.8
    u2 = 3 / 16 * H * H * w * k * np.cosh(2 * k * (z + depth)) / np.sinh(k * depth) ** 4 * np.cos(2 * theta)
    np.testing.assert_allclose(one.velocity([H / 2 * np.exp(0.3j)], 0.8, z, t)[0], u2, rtol=1e-12)


SPECTRUM = {"type": "piston_spectrum", "mkbound": 10, "depth": 0.4, "waveheight": 0.05, "waveperiod": 1.4,
            "spectrum": "jonswap", "discretization": "stretched", "peakcoef": 3.3, "waves": 40, "randomseed": 2,
            "ramptime": 0.0, "serieini": 0.0, "start": 0.0, "duration": 0.0, "gainstroke": 1.0,
            "pistondir": [1.0, 0, 0], "waveorder": 2}


def test_a_one_wave_spectrum_moves_as_the_regular_second_order_piston():
    p = SpectrumPaddle({**SPECTRUM, "waves": 1})
    f, a, phase = p.components["f"][0], p.amp[0], p.phase[0]
    reg = WavePaddle({"type": "piston", "mkbound": 10, "depth": 0.4, "waveheight": 2 * a, "waveperiod": 1 / f,
                      "waveorder": 2, "start": 0.0, "duration": 0.0, "gainstroke": 1.0, "phase": phase / math.pi,
                      "ramp": 0.0, "pistondir": [1.0, 0, 0]})
    assert reg.second != 0
    for t in (0.0, 0.37, 1.9, 5.2):
        np.testing.assert_allclose(p.theory_position(t), reg.theory_position(t), rtol=1e-12, atol=1e-15)
        assert float(p.elevation(0.9, t, order=2)[0]) == pytest.approx(float(reg.elevation(0.9, t, order=2)[0]),
                                                                       rel=1e-12)
    np.testing.assert_allclose(p.orbital_velocity(0.9, -0.1, [1.0, 2.0]), reg.orbital_velocity(0.9, -0.1, [1.0, 2.0]),
                               rtol=1e-12)


def test_second_order_stroke_and_its_rate():
    """The second-order piston adds X2 to the first-order stroke; the rate is X's derivative; the
    first-order paddle of the same sea does not; gainstroke scales the whole stroke."""
    second, first = SpectrumPaddle(SPECTRUM), SpectrumPaddle({**SPECTRUM, "waveorder": 1})
    assert second.second_order and not first.second_order
    t = np.linspace(0.5, 20.0, 40)
    x2 = np.array([second.theory_position(ti)[0] for ti in t])
    x1 = np.array([first.theory_position(ti)[0] for ti in t])
    assert np.std(x2 - x1) > 0.01 * np.std(x1)
    e = 1e-6
    for ti in t[:8]:
        fd = (second.theory_position(ti + e)[0] - second.theory_position(ti - e)[0]) / (2 * e)
        assert second.theory_position(ti)[1] == pytest.approx(fd, rel=1e-6, abs=1e-9)
    assert second.theory_position(0.0) == (0.0, 0.0)
    assert second.mean_position() == pytest.approx(-second._series_from_rest(0.0)[0])
    gained = SpectrumPaddle({**SPECTRUM, "gainstroke": 1.5})
    for ti in t[:5]:
        assert gained.theory_position(ti)[0] == pytest.approx(1.5 * second.theory_position(ti)[0], rel=1e-12)
    acc = second.max_acceleration()
    samples = np.array([second.theory_position(ti)[1] for ti in np.arange(1.0, 30.0, 0.002)])
    assert np.max(np.abs(np.diff(samples))) / 0.002 < acc


def test_flap_spectrum_keeps_first_order_and_the_bound_waves_are_the_elevations_second_order():
    flap = SpectrumPaddle({**SPECTRUM, "type": "flap_spectrum", "flapaxis0": [0, 0, 0], "flapaxis1": [0, 1, 0],
                           "variabledraft": 0.0})
    assert not flap.second_order
    t = np.linspace(1.0, 9.0, 50)
    bound = flap.elevation(1.0, t, order=2) - flap.elevation(1.0, t)
    sea = SecondOrderSea(flap.omega, 0.4)
    np.testing.assert_allclose(bound, sea.elevation(flap.complex_amplitudes(), 1.0, t), rtol=1e-12, atol=1e-15)
    assert np.max(np.abs(bound)) > 0.02 * np.max(np.abs(flap.elevation(1.0, t)))


def test_second_order_focused_group_crest_is_higher_and_troughs_shallower():
    spec = {"type": "piston_focused", "mkbound": 10, "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.4,
            "spectrum": "jonswap", "discretization": "cosstretched", "peakcoef": 3.3, "waves": 64, "randomseed": 0,
            "ramptime": 1.0, "start": 0.0, "duration": 0.0, "gainstroke": 1.0, "pistondir": [1.0, 0, 0],
            "waveorder": 2, "xf": 2.0}
    p = FocusedPaddle(spec)
    assert p.second_order
    t = np.linspace(p.focus_time - 2, p.focus_time + 2, 4001)
    lin, nl = p.elevation(2.0, t), p.elevation(2.0, t, order=2)
    assert np.max(lin) == pytest.approx(p.crest, rel=1e-3)
    assert np.max(nl) > 1.02 * np.max(lin) and np.min(nl) > np.min(lin)


def test_the_subharmonic_drift_starts_from_rest_under_the_ramp():
    """S_r(τ) = ∫_0^τ r(s)² Ṡ(s) ds (r the linear start ramp over T): checked by quadrature of its own
    rate, continuous at T, S(τ) − S(0) without a ramp; the ramped paddle's rate is its stroke's derivative."""
    from sphdvi.wave_second_order import SubharmonicStroke
    p = SpectrumPaddle({**SPECTRUM, "ramptime": 2.0})
    a0 = p.complex_amplitudes()
    ramped = SubharmonicStroke(p._sea.paddle_diff, a0, p.omega, 2.0)
    free = SubharmonicStroke(p._sea.paddle_diff, a0, p.omega, 0.0)
    assert ramped(0.0) == (0.0, 0.0) and free(0.0)[0] == 0.0
    s = np.linspace(0.0, 5.0, 50001)
    r2 = np.minimum(s / 2.0, 1.0) ** 2
    rate = np.array([free(si)[1] for si in s])                 # Ṡ (the free stroke's rate is the series')
    quad = np.concatenate([[0.0], np.cumsum(0.5 * (r2[1:] * rate[1:] + r2[:-1] * rate[:-1]) * np.diff(s))])
    for i in (7000, 20000, 20001, 35000, 50000):
        value, rate_i = ramped(s[i])
        assert value == pytest.approx(quad[i], abs=1e-7 * np.max(np.abs(quad)))     # the trapezoids' error
        assert rate_i == pytest.approx(r2[i] * rate[i], rel=1e-12, abs=1e-15)
    assert abs(quad[-1]) > 1e-5                                 # a drift of some tenths of a millimetre
    e = 1e-6
    for ti in (0.3, 1.9, 2.0001, 4.2):
        fd = (p.theory_position(ti + e)[0] - p.theory_position(ti - e)[0]) / (2 * e)
        assert p.theory_position(ti)[1] == pytest.approx(fd, rel=1e-6, abs=1e-9)

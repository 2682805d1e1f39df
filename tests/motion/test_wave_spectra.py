"""Irregular waves (<piston_spectrum>/<flap_spectrum>): the spectra against their integrals, the
discretisations, the paddle's stroke series against Biesel's transfer function per wave."""
import math

import numpy as np
import pytest

from sphdvi import wavespectra as ws
from sphdvi.motion import SpectrumPaddle, flap_height_to_stroke, piston_height_to_stroke, wave_number

F = np.linspace(1e-3, 30.0, 600001)


def test_pierson_moskowitz_holds_hs_squared_over_16_and_peaks_at_fp():
    s = ws.pierson_moskowitz(F, 0.1, 2.0)
    assert np.trapezoid(s, F) == pytest.approx(0.1 ** 2 / 16, rel=1e-5)
    assert F[np.argmax(s)] == pytest.approx(0.5, abs=1e-4)


@pytest.mark.parametrize("gamma, ratio", [(1.0, 1.0456), (3.3, 1.0336), (7.0, 1.0279)])
def test_jonswap_is_godas_form(gamma, ratio):
    """Goda's β_J: the spectrum's own 4 √m0 is 1.03-1.05 times his Hs (= H1/3); γ = 1 is the
    Pierson-Moskowitz shape times β_J(1)/(5/16); the peak sits at fp and rises with γ."""
    s = ws.jonswap(F, 0.1, 2.0, gamma)
    assert 4 * math.sqrt(np.trapezoid(s, F)) / 0.1 == pytest.approx(ratio, abs=2e-4)
    assert F[np.argmax(s)] == pytest.approx(0.5, abs=1e-4)
    if gamma == 1.0:
        beta = 0.0624 / (0.230 + 0.0336 - 0.185 / 2.9) * 1.094
        np.testing.assert_allclose(s, ws.pierson_moskowitz(F, 0.1, 2.0) * beta / (5 / 16), rtol=1e-12, atol=1e-300)
    else:
        assert s.max() > 2 * ws.jonswap(F, 0.1, 2.0, 1.0).max()


@pytest.mark.parametrize("how", ws.DISCRETISATIONS)
@pytest.mark.parametrize("kind", ws.SPECTRA)
def test_components_make_the_case_height_in_the_band(kind, how):
    c = ws.components(kind, 0.04, 1.4, 50, how, 3.3, seed=2)
    fmin, fmax = c["band"]
    assert (fmin, fmax) == pytest.approx((0.5 / 1.4, 3.0 / 1.4))
    assert ws.spectral_height(c["amp"]) == pytest.approx(0.04, rel=1e-12)
    assert c["f"].size == 50 and np.all(np.diff(c["f"]) > 0) and fmin <= c["f"][0] and c["f"][-1] <= fmax
    assert c["df"].sum() == pytest.approx(fmax - fmin, rel=1e-12)
    assert np.all((c["phase"] >= 0) & (c["phase"] < 2 * np.pi))
    # the band holds 98.5 % (PM) and 99 % (JONSWAP) of the energy: the scaling makes up the tails,
    # and for JONSWAP takes Goda's spectrum (4 sqrt(m0) = 1.034 Hs) to Hm0 = Hs
    assert (1.0 < c["scale"] < 1.02) if kind == "pierson-moskowitz" else (0.94 < c["scale"] < 0.99)
    again = ws.components(kind, 0.04, 1.4, 50, how, 3.3, seed=2)
    other = ws.components(kind, 0.04, 1.4, 50, how, 3.3, seed=3)
    assert np.array_equal(again["phase"], c["phase"]) and np.array_equal(again["f"], c["f"])
    assert not np.array_equal(other["phase"], c["phase"])


def test_each_discretisation_as_documented():
    fp = 1 / 1.4
    reg = ws.components("jonswap", 0.04, 1.4, 40, "regular")
    assert np.allclose(reg["df"], reg["df"][0]) and np.allclose(np.diff(reg["f"]), reg["df"][0])
    # a_i = sqrt(2 S(f_i) df) times one scale
    np.testing.assert_allclose(reg["amp"], reg["scale"] * np.sqrt(2 * ws.jonswap(reg["f"], 0.04, 1.4) * reg["df"]))
    rnd = ws.components("jonswap", 0.04, 1.4, 40, "random", seed=5)
    edges = reg["band"][0] + reg["df"][0] * np.arange(41)
    assert np.all((rnd["f"] >= edges[:-1]) & (rnd["f"] <= edges[1:])) and not np.allclose(rnd["f"], reg["f"])
    st = ws.components("jonswap", 0.04, 1.4, 40, "stretched")
    assert np.allclose(st["amp"], st["amp"][0], rtol=1e-6)                  # equal energy per wave
    near = np.argmin(np.abs(st["f"] - fp))
    assert st["df"][near] < 0.3 * st["df"][-1] and st["df"][near] < 0.3 * st["df"][0]   # crowded at the peak
    cos = ws.components("jonswap", 0.04, 1.4, 40, "cosstretched")
    edges = np.concatenate([[cos["band"][0]], cos["band"][0] + np.cumsum(cos["df"])])
    assert np.isclose(edges, fp).any()                                      # a bin edge at fp
    k = int(np.argmin(np.abs(edges - fp)))
    assert cos["df"][k - 1] < cos["df"][0] / 5 and cos["df"][k] < cos["df"][-1] / 5


def test_bad_options_are_refused():
    with pytest.raises(ValueError, match="unknown spectrum"):
        ws.spectrum("bretschneider", F, 1, 1)
    with pytest.raises(ValueError, match="unknown discretization"):
        ws.components("jonswap", 0.04, 1.4, 10, "even")
    with pytest.raises(ValueError, match="at least 1"):
        ws.components("jonswap", 0.04, 1.4, 0)


def spec(kind="piston_spectrum", **kw):
    d = {"type": kind, "mkbound": 10, "depth": 0.3, "waveheight": 0.04, "waveperiod": 1.4, "spectrum": "jonswap",
         "discretization": "stretched", "peakcoef": 3.3, "waves": 30, "randomseed": 2, "ramptime": 0.0,
         "serieini": 0.0, "start": 0.0, "duration": 0.0, "gainstroke": 1.0, "pistondir": [1.0, 0, 0]}
    if kind.startswith("flap"):
        d.pop("pistondir")
        d.update(flapaxis0=[0, -1, 0], flapaxis1=[0, 1, 0])
    d.update(kw)
    return d


@pytest.mark.parametrize("kind, transfer", [("piston_spectrum", piston_height_to_stroke),
                                            ("flap_spectrum", flap_height_to_stroke)])
def test_stroke_is_bieseis_per_wave(kind, transfer):
    """X(τ) = Σ S_i/2 [sin(ω_i τ + φ_i) − sin φ_i], S_i = 2 a_i/(H/S)(k_i d); the rate is its derivative."""
    p = SpectrumPaddle(spec(kind))
    c = p.components
    k = np.array([wave_number(1 / f, 0.3) for f in c["f"]])
    half = c["amp"] / np.array([transfer(ki, 0.3) for ki in k])
    for t in (0.37, 1.9, 7.25):
        w = 2 * np.pi * c["f"]
        x = np.sum(half * (np.sin(w * t + c["phase"]) - np.sin(c["phase"])))
        v = np.sum(half * w * np.cos(w * t + c["phase"]))
        assert p.stroke_position(t) == pytest.approx((x, v), rel=1e-12, abs=1e-15)
        h = 1e-6
        num = (p.stroke_position(t + h)[0] - p.stroke_position(t - h)[0]) / (2 * h)
        assert num == pytest.approx(v, rel=1e-6)
    assert p.stroke_position(0.0) == (0.0, 0.0)


def test_ramp_gain_serieini_start_and_duration():
    base = SpectrumPaddle(spec())
    ramped = SpectrumPaddle(spec(ramptime=2.0))     # from rest about the rest position: not shifted
    free = base.stroke_position(0.5)[0] - base.mean_position()
    assert base.mean_position() != 0 and ramped.mean_position() == 0
    assert ramped.stroke_position(0.5)[0] == pytest.approx(0.25 * free)
    assert ramped.stroke_position(3.0) == pytest.approx((base.stroke_position(3.0)[0] - base.mean_position(),
                                                         base.stroke_position(3.0)[1]))
    double = SpectrumPaddle(spec(gainstroke=2.0))
    assert double.stroke_position(1.3)[0] == pytest.approx(2 * base.stroke_position(1.3)[0])
    later = SpectrumPaddle(spec(serieini=5.0))                  # the series from its 5th second, from rest
    assert later.stroke_position(1.0)[0] == pytest.approx(base.stroke_position(6.0)[0] - base.stroke_position(5.0)[0])
    delayed = SpectrumPaddle(spec(start=1.0, duration=2.0))
    assert delayed.stroke_position(0.8) == (0.0, 0.0)
    assert delayed.stroke_position(2.5)[0] == pytest.approx(base.stroke_position(1.5)[0])
    held = delayed.stroke_position(4.0)                         # after the duration: it stays, at rest
    assert held == (pytest.approx(base.stroke_position(2.0)[0]), 0.0)


def test_elevation_is_the_sum_of_the_progressive_waves():
    p = SpectrumPaddle(spec())
    c = p.components
    t = np.array([3.0, 4.5])
    k = np.array([wave_number(1 / f, 0.3) for f in c["f"]])
    expect = [np.sum(c["amp"] * np.cos(2 * np.pi * c["f"] * ti + c["phase"] - k * 1.2)) for ti in t]
    np.testing.assert_allclose(p.elevation(1.2, t), expect, rtol=1e-12)
    # its mean square over a long record is m0 = (Hs/4)^2 (40 regular waves: the band starts at 8 df,
    # the waves are odd multiples of df/2, and over 1/df their squares average to a half, their products to 0)
    reg = SpectrumPaddle(spec(discretization="regular", waves=40))
    period = 1 / reg.components["df"][0]
    tt = np.linspace(0, period, 20001)[:-1]
    assert math.sqrt(np.mean(reg.elevation(0.6, tt) ** 2)) == pytest.approx(0.04 / 4, rel=1e-9)

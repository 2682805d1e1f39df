"""Wave paddles: the flap's transfer function with its hinge off the bottom (``<variabledraft>``),
the paddle's mean position with and without a ramp, and the spectrum options refused at gencase."""
from __future__ import annotations

import math

import numpy as np
import pytest
from lxml import etree
from scipy.integrate import quad

from sphdvi.case.wavepaddles_xml import read_wavepaddles
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError
from sphdvi.motion import SpectrumPaddle, WavePaddle, flap_height_to_stroke, wave_number
from sphdvi.wavespectra import components


def paddles(tmp_path, inner, tag="flap"):
    xml = (f'<wavepaddles>\n<{tag}><mkbound value="1"/><depth value="0.3"/><waveheight value="0.03"/>'
           f'<waveperiod value="1.2"/>\n{inner}</{tag}></wavepaddles>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_wavepaddles(reader, etree.fromstring(xml)), reader


def wavemaker_quadrature(k, d, draft):
    """Linear wavemaker theory by quadrature: H/S = 4 sinh kd/(sinh 2kd + 2kd) · k ∫ X(z)/S cosh k(d+z) dz,
    X/S = (z + D)/D above the hinge at depth D = d + draft, 0 below it."""
    D = d + draft
    lo = max(-d, -D)
    integral = quad(lambda z: (z + D) / D * math.cosh(k * (d + z)), lo, 0.0, epsabs=0, epsrel=1e-13)[0]
    kd = k * d
    return 4 * math.sinh(kd) / (math.sinh(2 * kd) + 2 * kd) * k * integral


@pytest.mark.parametrize("period, depth", [(1.2, 0.3), (2.0, 0.4), (0.6, 1.0), (5.0, 0.3)])
@pytest.mark.parametrize("draft_of_d", [-0.6, -0.3, 0.0, 0.1, 0.3, 2.0])
def test_flap_transfer_function_is_linear_wavemaker_theory(period, depth, draft_of_d):
    k = wave_number(period, depth)
    draft = draft_of_d * depth
    assert flap_height_to_stroke(k, depth, draft) == pytest.approx(wavemaker_quadrature(k, depth, draft), rel=1e-11)


def test_flap_hinged_at_the_bottom_is_biesel_s():
    for kd in (0.05, 0.5, 1.065, 3.0, 20.0):
        biesel = 4 * math.sinh(kd) / kd * (1 - math.cosh(kd) + kd * math.sinh(kd)) / (math.sinh(2 * kd) + 2 * kd)
        assert flap_height_to_stroke(kd, 1.0, 0.0) == pytest.approx(biesel, rel=1e-12)
        assert flap_height_to_stroke(kd, 1.0) == flap_height_to_stroke(kd, 1.0, 0.0)
    # a hinge far below the bottom tends to a piston, one near the surface moves hardly any water
    k = wave_number(1.2, 0.3)
    piston = 2 * (math.cosh(2 * k * 0.3) - 1) / (math.sinh(2 * k * 0.3) + 2 * k * 0.3)
    assert flap_height_to_stroke(k, 0.3, 1e4) == pytest.approx(piston, rel=1e-4)
    assert flap_height_to_stroke(k, 0.3, -0.2999) < 1e-3
    assert flap_height_to_stroke(1e4, 1.0, 0.5) == pytest.approx(2.0, rel=1e-3)     # deep water, no overflow


@pytest.mark.parametrize("draft", [-0.09, 0.0, 0.03, 0.09])
def test_flaps_make_the_height_asked_whatever_their_draft(tmp_path, draft):
    """The stroke of regular and irregular flaps from the transfer function of their own hinge; the angle
    turns the surface point by the stroke (atan(X / hinge depth))."""
    axes = '<flapaxis0 x="0" y="-1" z="0"/><flapaxis1 x="0" y="1" z="0"/>'
    (p,), _ = paddles(tmp_path, f'<variabledraft value="{draft}"/>{axes}')
    paddle = WavePaddle(p)
    k = wave_number(1.2, 0.3)
    assert paddle.stroke * wavemaker_quadrature(k, 0.3, draft) == pytest.approx(0.03, rel=1e-10)
    assert paddle.hinge_depth == pytest.approx(0.3 + draft)
    (s,), _ = paddles(tmp_path, f'<spectrum value="jonswap"/><waves value="8"/><variabledraft value="{draft}"/>'
                      + axes, tag="flap_spectrum")
    sp = SpectrumPaddle(s)
    expect = [a / wavemaker_quadrature(ki, 0.3, draft) for a, ki in zip(sp.amp, sp.k)]
    assert sp.half_stroke == pytest.approx(expect, rel=1e-10)


def test_a_hinge_above_the_water_is_a_case_error(tmp_path):
    axes = '<flapaxis0 x="0" y="-1" z="0"/><flapaxis1 x="0" y="1" z="0"/>'
    with pytest.raises(CaseError, match="variabledraft.*at or above the still water") as e:
        paddles(tmp_path, f'<variabledraft value="-0.3"/>{axes}')
    assert e.value.element == "variabledraft" and e.value.line == 3


def test_one_cosstretched_wave_is_a_case_error(tmp_path):
    """Its bins narrow towards fp from both sides: one wave made a division by zero (period NaN)."""
    with pytest.raises(CaseError, match="waves> value=1 with the cosstretched") as e:
        paddles(tmp_path, '<spectrum value="jonswap"/><discretization value="cosstretched"/><waves value="1"/>',
                tag="piston_spectrum")
    assert e.value.element == "waves" and e.value.line == 3
    with pytest.raises(ValueError, match="at least 2 waves"):
        components("jonswap", 0.04, 1.4, 1, "cosstretched")
    assert np.all(np.isfinite(components("jonswap", 0.04, 1.4, 2, "cosstretched")["f"]))


REGULAR = {"type": "piston", "mkbound": 1, "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.2, "waveorder": 1}


@pytest.mark.parametrize("order", [1, 2])
def test_a_ramped_regular_paddle_moves_about_its_rest_position(order):
    """With a ramp (r(0) = 0 already starts it from rest) X = r(τ) (S/2 sin(ωτ + φ) + X2 sin 2(ωτ + φ));
    without one the series less its start value (no jump), about −S/2 sin φ − X2 sin 2φ."""
    ramped = WavePaddle({**REGULAR, "phase": 0.5, "ramp": 2.0, "waveorder": order})
    w, T = ramped.omega, 1.2
    for t in (0.3, 1.7, 2.4, 5.1, 9.95):
        r = min(1.0, t / (2 * T))
        a = w * t + 0.5 * math.pi
        x = 0.5 * ramped.stroke * math.sin(a) + ramped.second * math.sin(2 * a)
        assert ramped.stroke_position(t)[0] == pytest.approx(r * x, abs=1e-15)
    assert ramped.mean_position() == 0.0
    tt = np.linspace(2 * T, 12 * T, 20001)[:-1]
    assert np.mean([ramped.stroke_position(t)[0] for t in tt]) == pytest.approx(0.0, abs=1e-6)
    free = WavePaddle({**REGULAR, "phase": 0.5, "ramp": 0.0, "waveorder": order})
    assert free.stroke_position(1e-9)[0] == pytest.approx(0.0, abs=1e-9)
    assert free.mean_position() == pytest.approx(-0.5 * free.stroke - free.second * math.sin(math.pi))
    assert np.mean([free.stroke_position(t)[0] for t in tt]) == pytest.approx(free.mean_position(), abs=1e-6)


def test_a_ramped_spectrum_paddle_is_not_shifted():
    spec = {"type": "piston_spectrum", "mkbound": 1, "depth": 0.3, "waveheight": 0.04, "waveperiod": 1.4,
            "spectrum": "jonswap", "waves": 50, "discretization": "stretched", "peakcoef": 3.3, "randomseed": 0,
            "serieini": 0.0, "start": 0.0, "duration": 0.0, "gainstroke": 1.0}
    ramped = SpectrumPaddle({**spec, "ramptime": 2.0})
    free = SpectrumPaddle({**spec, "ramptime": 0.0})
    series = lambda p, t: float(np.dot(p.half_stroke, np.sin(p.omega * t + p.phase)))     # noqa: E731
    assert ramped.offset == 0.0 and ramped.mean_position() == 0.0
    for t in (0.5, 1.0, 3.0, 17.3):
        assert ramped.stroke_position(t)[0] == pytest.approx(min(1.0, t / 2.0) * series(ramped, t), abs=1e-15)
    assert free.mean_position() == pytest.approx(-series(free, 0.0)) and abs(free.mean_position()) > 1e-3
    assert free.stroke_position(1e-9)[0] == pytest.approx(0.0, abs=1e-9)

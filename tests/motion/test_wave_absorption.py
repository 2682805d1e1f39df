"""Active wave absorption at a piston (``<awas_zsurf>``, DualSPHysics's AWAS): the case input, the
correction law u_r = sqrt(g/d)(η_target − η_measured) and its safeguards (drift correction,
acceleration limit), the in-loop free-surface gauge, and the linear-theory reflection."""
from __future__ import annotations

import math

import numpy as np
import pytest
from lxml import etree

from sphdvi.case.wavepaddles_xml import read_wavepaddles
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError
from sphdvi.motion import SpectrumPaddle, WavePaddle, piston_height_to_stroke, wave_number
from sphdvi.wave_absorption import PistonAbsorber, linear_reflection

G = 9.81
AWAS = ('<awas_zsurf><swl value="0.3"/><gaugey value="0"/>{}</awas_zsurf>')


def paddles(tmp_path, inner, tag="piston", extra=""):
    ramp = '<ramp value="2"/>' if tag in ("piston", "flap") else ""
    xml = (f'<wavepaddles>\n<{tag}><mkbound value="1"/><depth value="0.3"/><waveheight value="0.03"/>'
           f'<waveperiod value="1.2"/>{ramp}{extra}\n{inner}</{tag}></wavepaddles>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_wavepaddles(reader, etree.fromstring(xml)), reader


# -- the case input ----------------------------------------------------------------------------
def test_defaults_are_dualsphysics(tmp_path):
    (p,), reader = paddles(tmp_path, AWAS.format(""))
    a = p["awas"]
    assert a["startawas"] == pytest.approx(2.4)            # the end of the 2-period ramp
    assert a["elevation"] == 2 and a["gaugedp"] == 0.1 and a["limitace"] == 2.0
    assert a["gaugex"] == {"unit": "dp", "value": 5.0}
    assert a["correction"] == {"coefstroke": 0.0, "coefperiod": 0.0, "powerfunc": 1.0}
    assert "coefmasslimit" not in a and not reader.warnings


def test_every_option_read(tmp_path):
    inner = ('<startawas value="3"/><elevation value="1"/><gaugex valueh="2"/><gaugezmin value="0.1"/>'
             '<gaugezmax value="0.5"/><gaugedp value="0.25"/><coefmasslimit value="0.45"/><limitace value="0"/>'
             '<correction coefstroke="1.8" coefperiod="1" powerfunc="3"/><savedata value="1"/>')
    (p,), reader = paddles(tmp_path, AWAS.format(inner))
    a = p["awas"]
    assert (a["startawas"], a["elevation"], a["gaugezmin"], a["gaugezmax"], a["gaugedp"], a["coefmasslimit"],
            a["limitace"]) == (3.0, 1, 0.1, 0.5, 0.25, 0.45, 0.0)
    assert a["gaugex"] == {"unit": "h", "value": 2.0}
    assert a["correction"] == {"coefstroke": 1.8, "coefperiod": 1.0, "powerfunc": 3.0}
    assert len(reader.warnings) == 1 and "<savedata>" in "\n".join(reader.warnings)


@pytest.mark.parametrize("inner, match, element", [
    ('<startawas value="1"/>', "before the end of the ramp", "startawas"),
    ('<elevation value="3"/>', "elevation", "elevation"),
    ('<gaugex value="0.1" valuedp="5"/>', "exactly one of", "gaugex"),
    ('<gaugedp value="0"/>', "gaugedp > 0", "gaugedp"),
    ('<gaugezmin value="0.5"/><gaugezmax value="0.1"/>', "not above", "gaugezmax"),
    ('<limitace value="-1"/>', "limitace", "limitace"),
    ('<correction coefstroke="0.5" coefperiod="1"/>', "coefstroke >= 1", "correction"),
    ('<correction coefstroke="2" coefperiod="0"/>', "coefperiod > 0", "correction"),
    ('<correction powerfunc="0.5"/>', "powerfunc >= 1", "correction"),
    ('<gaugez value="1"/>', "unknown element", "gaugez"),
])
def test_bad_options_are_case_errors(tmp_path, inner, match, element):
    with pytest.raises(CaseError, match=match) as e:
        paddles(tmp_path, AWAS.format(inner))
    assert e.value.element == element


def test_required_swl_and_pistons_along_x_only(tmp_path):
    with pytest.raises(CaseError, match="missing <swl>"):
        paddles(tmp_path, '<awas_zsurf><gaugey value="0"/></awas_zsurf>')
    with pytest.raises(CaseError, match="along \\+x"):
        paddles(tmp_path, AWAS.format(""), extra='<pistondir x="0" y="1" z="0"/>')
    with pytest.raises(CaseError, match="pistons only") as e:
        paddles(tmp_path, AWAS.format(""), tag="flap",
                extra='<flapaxis0 x="0" y="0" z="0"/><flapaxis1 x="0" y="1" z="0"/>')
    assert e.value.element == "awas_zsurf"


def test_irregular_piston_absorbs_after_its_ramptime(tmp_path):
    (p,), _ = paddles(tmp_path, AWAS.format(""), tag="piston_spectrum",
                      extra='<spectrum value="jonswap"/><ramptime value="3"/>')
    assert p["awas"]["startawas"] == 3.0


# -- the correction law ------------------------------------------------------------------------
class _Gauge:
    """A stand-in for the surface gauge (the absorber's law is tested on its own)."""


def absorber(opts=None, spec=None):
    spec = {"type": "piston", "mkbound": 10, "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.2, "ramp": 0,
            "waveorder": 1, **(spec or {})}
    o = {"startawas": 0.0, "swl": 0.3, "elevation": 1, "gaugey": 0.0, **(opts or {})}
    return PistonAbsorber(WavePaddle(spec), o, g=G, dp=0.01, h=0.017, is2d=True, face_x=0.0, zlim=(0.0, 1.0))


def drive(a, surface, t_end, dt=1e-3):
    """Steps of dt up to t_end, the gauge reading surface(t, target) (an absolute z)."""
    t = 0.0
    out = []
    while t < t_end - 1e-12:
        t_new = t + dt
        target = a.paddle.target_elevation(a.gauge_dx, t_new, a.order)
        a.update(t_new, dt, surface(t_new, target))
        out.append((t_new, a.offset, a.velocity, a.paddle.stroke_position(t_new)[0]))
        t = t_new
    return np.array(out)


def test_the_target_met_leaves_the_theoretical_stroke():
    a = absorber()
    rec = drive(a, lambda t, target: 0.3 + target, 2.4)
    assert np.abs(rec[:, 1]).max() < 1e-16                  # the gauge's z less swl rounds
    assert rec[-1, 3] == pytest.approx(a.paddle.theory_position(rec[-1, 0])[0], abs=1e-16)


def test_a_level_error_moves_the_piston_at_the_absorption_velocity():
    """The surface 5 mm above the target: the piston recedes at sqrt(g/d) · 5 mm, from the first step
    that starts after startawas (the trapezoidal rule: half a step's worth less on that step)."""
    a = absorber({"limitace": 0.0})
    dt = 1e-3
    rec = drive(a, lambda t, target: 0.3 + target + 0.005, 1.0, dt)
    u = -math.sqrt(G / 0.3) * 0.005
    assert rec[-1, 2] == pytest.approx(u, rel=1e-12)
    assert rec[-1, 1] == pytest.approx(u * (rec[-1, 0] - 1.5 * dt), rel=1e-9)
    assert a.eta == pytest.approx(a.target + 0.005)


def test_no_correction_before_startawas_or_without_a_surface():
    a = absorber({"startawas": 0.5})
    rec = drive(a, lambda t, target: 0.3 + target + 0.005, 0.5)
    assert np.abs(rec[:, 1]).max() == 0.0
    b = absorber()
    rec = drive(b, lambda t, target: math.nan, 0.5)
    assert np.abs(rec[:, 1]).max() == 0.0


def test_drift_correction_brings_the_piston_back():
    """A steady error drives the piston off; past coefstroke amplitudes it is brought back by that
    much over coefperiod periods, along 1 − (1 − τ/T_c)^p."""
    opts = {"limitace": 0.0, "correction": {"coefstroke": 1.5, "coefperiod": 1.0, "powerfunc": 3.0}}
    a = absorber(opts)
    b = absorber({"limitace": 0.0})
    surface = lambda t, target: 0.3 + target + 0.01    # noqa: E731
    dt = 1e-3
    ra = drive(a, surface, 3.0, dt)
    rb = drive(b, surface, 3.0, dt)
    limit = 1.5 * a.paddle.stroke_amplitude()
    assert a.corr_limit == pytest.approx(limit) and a.corr_time == pytest.approx(1.2)
    diff = ra[:, 1] - rb[:, 1]
    started = np.flatnonzero(np.abs(diff) > 0)[0]
    assert abs(rb[started, 3]) > limit >= abs(rb[started - 1, 3])
    t0 = ra[started, 0] - dt           # the correction runs from the start of the step that found the drift
    tau = ra[started:, 0] - t0
    first = tau <= 1.2 + 1e-9         # the first correction (the steady error starts a second one after it)
    expect = limit * (1 - (1 - tau[first] / 1.2) ** 3)
    assert np.allclose(diff[started:][first], expect * np.sign(-rb[started, 3]), atol=1e-12, rtol=0)
    assert abs(diff[-1]) > 1.5 * limit


@pytest.mark.parametrize("phase, ramp", [(0.5, 0.0), (1.5, 0.0), (0.5, 2.0), (0.25, 0.0)])
def test_drift_is_measured_from_the_theory_s_mean_position(phase, ramp):
    """A surface that meets the target leaves nothing to absorb, so no drift correction: the piston's
    distance is measured from where the theory centres it (−S/2 sin φ without a ramp: it swings over
    [−S, 0] for φ = π/2, past 1.8 S/2 from its rest position), not from the rest position."""
    corr = {"coefstroke": 1.8, "coefperiod": 1.0, "powerfunc": 3.0}
    a = absorber({"correction": corr, "startawas": 2.4}, {"phase": phase, "ramp": ramp})
    rec = drive(a, lambda t, target: 0.3 + target, 12.0)
    assert math.isnan(a.corr_start) and np.abs(rec[:, 1]).max() < 1e-15
    assert np.abs(rec[:, 3] - a.paddle.mean_position()).max() <= a.paddle.stroke_amplitude() * (1 + 1e-12)
    assert a.paddle.mean_position() == pytest.approx(0.0 if ramp else -a.paddle.stroke_amplitude() *
                                                     math.sin(phase * math.pi), abs=1e-15)


@pytest.mark.parametrize("order", [1, 2])
def test_irregular_drift_is_measured_from_the_series_mean(order):
    """An unramped irregular series starts from its value at serieini and so swings about −that value;
    a surface that is the target (to second order on a second-order piston, its bound waves
    included) leaves the piston on its theory."""
    spec = {"type": "piston_spectrum", "mkbound": 10, "depth": 0.3, "waveheight": 0.04, "waveperiod": 1.4,
            "spectrum": "jonswap", "waves": 50, "discretization": "stretched", "peakcoef": 3.3, "randomseed": 0,
            "serieini": 0.0, "ramptime": 0.0, "start": 0.0, "duration": 0.0, "gainstroke": 1.0, "waveorder": order}
    o = {"startawas": 0.0, "swl": 0.3, "elevation": order, "gaugey": 0.0,
         "correction": {"coefstroke": 1.8, "coefperiod": 1.0, "powerfunc": 3.0}}
    a = PistonAbsorber(SpectrumPaddle(spec), o, g=G, dp=0.01, h=0.017, is2d=True, face_x=0.0, zlim=(0.0, 1.0))
    assert abs(a.paddle.mean_position()) > 0.5 * a.paddle.stroke_amplitude()
    rec = drive(a, lambda t, target: 0.3 + target, 40.0, dt=2e-3)
    assert math.isnan(a.corr_start) and np.abs(rec[:, 1]).max() < 1e-15


def test_acceleration_limit_holds_the_velocity_change_per_step():
    """A sudden 2 cm jump of the surface: the piston's mean velocity changes by at most
    limitace · (S/2) ω² · dt per step, and it is otherwise untouched."""
    dt = 1e-3
    a = absorber({"limitace": 2.0})
    free = absorber({"limitace": 0.0})
    jump = lambda t, target: 0.3 + target + (0.02 if t > 0.5 else 0.0)    # noqa: E731
    ra, rf = drive(a, jump, 0.8, dt), drive(free, jump, 0.8, dt)
    v = np.diff(ra[:, 3]) / dt
    amax = 2.0 * a.paddle.max_acceleration()
    assert np.abs(np.diff(v)).max() <= amax * dt * (1 + 1e-9)
    assert np.abs(np.diff(np.diff(rf[:, 3]) / dt)).max() > 10 * amax * dt
    before = ra[:, 0] < 0.5
    assert np.array_equal(ra[before], rf[before])


def test_state_round_trip_continues_exactly():
    surface = lambda t, target: 0.3 + target + 0.004 * math.sin(7 * t)    # noqa: E731
    opts = {"correction": {"coefstroke": 1.2, "coefperiod": 0.5, "powerfunc": 2.0}}
    a = absorber(opts)
    drive(a, surface, 0.7)
    b = absorber(opts)
    b.set_state(a.get_state())
    t, dt = 0.7, 1e-3
    for _ in range(300):
        t += dt
        target = a.paddle.target_elevation(a.gauge_dx, t, 1)
        a.update(t, dt, surface(t, target))
        b.update(t, dt, surface(t, target))
    assert a.get_state() == b.get_state()


# -- linear theory -----------------------------------------------------------------------------
def test_linear_reflection_shallow_and_intermediate_depth():
    """R = (1 − G)/(1 + G): 0 in shallow water (H/S = kd, ω = k sqrt(g d)); −6.4 % for W1's kd 1.065."""
    for kd in (1e-3, 0.01):
        d = 1.0
        k = kd / d
        omega = math.sqrt(G * k * math.tanh(kd))
        assert abs(linear_reflection(piston_height_to_stroke(k, d), omega, G, d)) < 1e-4
    k = wave_number(1.2, 0.3)
    r = linear_reflection(piston_height_to_stroke(k, 0.3), 2 * math.pi / 1.2, G, 0.3)
    assert r == pytest.approx(-0.064, abs=0.001)


def test_regular_target_elevation_first_and_second_order():
    p = WavePaddle({"type": "piston", "mkbound": 1, "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.2,
                    "ramp": 1, "waveorder": 1})
    t = np.linspace(0.0, 6.0, 601)
    eta1 = p.elevation(0.1, t)
    assert np.allclose(eta1, 0.015 * np.cos(p.omega * t - p.k * 0.1))
    # the paddle's velocity is in phase with the wave it makes (x = 0)
    v = np.array([p.theory_position(tt)[1] for tt in t[t > 1.2]])
    assert np.corrcoef(v, p.elevation(0.0, t[t > 1.2]))[0, 1] > 0.999
    kd = p.k * 0.3
    a2 = (0.03 ** 2 * p.k / 16) * math.cosh(kd) * (2 + math.cosh(2 * kd)) / math.sinh(kd) ** 3
    assert np.allclose(p.elevation(0.1, t, 2) - eta1, a2 * np.cos(2 * (p.omega * t - p.k * 0.1)))
    assert p.target_elevation(0.1, 0.6, 1) == pytest.approx(0.5 * p.elevation(0.1, 0.6)[0])   # half-way up the ramp
    assert p.target_elevation(0.1, 0.0) == 0.0


# -- the in-loop gauge -------------------------------------------------------------------------
@pytest.mark.parametrize("is2d", [True, False])
def test_surface_gauge_matches_the_swl_gauge(is2d):
    """The in-loop gauge finds the surface where the measurement tool's swl gauge does, on a
    lattice with a wavy top."""
    from sphdvi.measure import core
    from sphdvi.sph.state import FluidState
    from sphdvi.sph.surface_gauge import VerticalSurfaceGauge
    dp, h = 0.01, 0.012
    xs = np.arange(0.0, 0.4, dp)
    ys = np.array([0.0]) if is2d else np.arange(0.0, 0.1, dp)
    pts = []
    for x in xs:
        top = 0.2 + 0.03 * math.sin(8 * x)
        for y in ys:
            for z in np.arange(0.0, top, dp):
                pts.append((x, y, z))
    pos = np.array(pts)
    n = len(pos)
    vol = dp ** (2 if is2d else 3)
    rhop = np.full(n, 1000.0)
    mass = rhop * vol
    ptype = np.full(n, 3, np.uint8)
    state = FluidState(pos, np.zeros((n, 3)), rhop, mass, ptype, np.arange(n), np.ones(n, np.int64), rhop0=1000.0)
    threshold = 0.4 if is2d else 0.5
    gauge = VerticalSurfaceGauge(0.05, 0.4, 0.25 * dp, threshold, 2, h, is2d)
    spec = core.KernelSpec(kind=2, h=h, dp=dp, is2d=is2d, cs0=10.0, rhop0=1000.0, b=1.0, gamma=7.0)
    grid = core.fluid_grid(pos, np.zeros((n, 3)), rhop, mass, np.zeros(n), ptype, spec)
    for x in (0.13, 0.205, 0.3):
        z = gauge.level(state, x, 0.05)
        ref = core.surface_along_lines(grid, [[x, 0.05, 0.05]], [[x, 0.05, 0.05 + (gauge.nsample - 1) * gauge.dz]],
                                       gauge.dz, threshold)[0, 2]
        assert z == pytest.approx(ref, abs=1e-9)
        assert abs(z - (0.2 + 0.03 * math.sin(8 * x))) < 1.5 * dp
    assert math.isnan(gauge.level(state, 2.0, 0.05))


def test_piston_reflection_with_its_gauge_in_front():
    """The full linear result reduces to (1 − G)/(1 + G) with the gauge at the piston less the
    evanescent modes' share, and to (1 − G e^{iθ})/(1 + G e^{−iθ}) far from them; W5's flume: |R|
    0.20 with the gauge 5 dp = 0.1 m out at dp 0.02, 0.13 at dp 0.01."""
    from sphdvi.wave_absorption import evanescent_wavenumbers, piston_reflection
    d, T = 0.3, 1.2
    k, om = wave_number(T, d), 2 * math.pi / T
    km = evanescent_wavenumbers(om, d, G, 5)
    assert np.allclose(om * om, -G * km * np.tan(km * d), rtol=1e-9)
    gain = piston_height_to_stroke(k, d) * math.sqrt(G / d) / om
    far = 2.0 * d                                   # the evanescent modes nearly gone (e^{-k_1 x} ~ 1e-2)
    th = k * far
    expect = (1 - gain * np.exp(1j * th)) / (1 + gain * np.exp(-1j * th))
    assert abs(piston_reflection(k, d, om, G, far) - expect) < 1e-2 * abs(expect)
    assert abs(piston_reflection(k, d, om, G, 0.1)) == pytest.approx(0.20, abs=0.005)
    assert abs(piston_reflection(k, d, om, G, 0.05)) == pytest.approx(0.13, abs=0.005)
    # shallow water, the gauge at the piston: nothing comes back
    dd = 0.01
    kk = wave_number(20.0, dd)
    assert abs(piston_reflection(kk, dd, 2 * math.pi / 20.0, G, 1e-6)) < 0.01


def test_target_is_the_wave_the_stroke_makes_gain_included():
    """gainstroke scales the stroke and the wave it makes alike (regular and irregular paddles), so
    that an absorber does not work against the gain."""
    base = {"type": "piston", "mkbound": 1, "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.2, "ramp": 0}
    p1, p2 = WavePaddle(base), WavePaddle({**base, "gainstroke": 1.3})
    assert p2.stroke == pytest.approx(1.3 * p1.stroke)
    assert np.allclose(p2.elevation(0.1, [0.3, 0.7]), 1.3 * p1.elevation(0.1, [0.3, 0.7]))
    from sphdvi.motion import SpectrumPaddle
    sbase = {"type": "piston_spectrum", "mkbound": 1, "depth": 0.3, "waveheight": 0.03, "waveperiod": 1.2,
             "spectrum": "jonswap", "discretization": "stretched", "peakcoef": 3.3, "waves": 10, "randomseed": 1}
    s1, s2 = SpectrumPaddle(sbase), SpectrumPaddle({**sbase, "gainstroke": 1.3})
    assert np.allclose(s2.half_stroke, 1.3 * s1.half_stroke)
    assert np.allclose(s2.elevation(0.1, [0.3, 0.7]), 1.3 * s1.elevation(0.1, [0.3, 0.7]))

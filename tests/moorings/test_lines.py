"""The lumped-mass mooring line (sphdvi.moorings.lines, sphdvi.moorings.system) against closed forms:
the elastic catenary at rest, the vibration of a node between two taut segments (axial: its mass on
two springs EA/l; transverse: the tension's stiffness and the added mass), the seabed's spring,
the break tension and the start ramp."""
import math

import numpy as np
import pytest

from sphdvi.moorings.catenary import elastic_catenary
from sphdvi.moorings.system import Moorings, start_ramp

G = 9.81
EA, DIA, MASS = 2.9e3, 3.656e-3, 0.0607          # DualSPHysics's moored-box example line
AREA = math.pi * DIA ** 2 / 4


def spec(length=0.6, segments=20, anchor=(0.0, 0.0, 0.0), fairlead=(0.4, 0.0, 0.35), fairlead_kind="vessel",
         depth=0.5, freesurface=0.5, **line):
    ln = {"id": 0, "ea": EA, "diameter": DIA, "mass": MASS, "ba": -0.8, "can": 1.0, "cat": 0.0, "cdn": 1.6,
          "cdt": 0.05, "breaktension": 0.0, "length": length, "segments": segments, "depth": depth,
          "outputflags": "-", "savedata": True,
          "ends": [{"kind": "fixed", "body": None, "pos": list(anchor)},
                   {"kind": fairlead_kind, "body": 50 if fairlead_kind == "vessel" else None, "pos": list(fairlead)}]}
    ln.update(line)
    return {"floatings": [50], "start": 0.0, "ramptime": 0.0,
            "solver": {"waterdepth": depth, "freesurface": freesurface, "kbot": 3e6, "cbot": 3e5, "dtm": 1e-4,
                       "dtm_auto": True, "friction": 0.0, "fricdamp": 200.0, "statdynfricscale": 1.0, "rho": 1000.0,
                       "cdscaleic": 5.0, "dtic": 0.5, "tmaxic": 0.0, "threshic": 0.001},
            "lines": [ln], "savedata": None}


BODY = np.array([[0.5, 0.0, 0.4]]), np.array([[1.0, 0.0, 0.0, 0.0]])


def moorings(sp, g=G):
    return Moorings(sp, g, {50: 0}, *BODY)


def wet_weight(rho_w=1000.0):
    return (MASS - rho_w * AREA) * G


def hold(m, seconds, dt=1e-4):
    for k in range(int(round(seconds / dt))):
        m.step(k * dt, dt, *BODY)


def test_a_taut_line_placed_on_its_catenary_stays_there():
    """L = 0.45 m between points 0.53 m apart (stretched 18 %): the nodes start on the elastic
    catenary (HF = 395.3 N, VF = 346.0 N) and the dynamics keep them there: the fairlead node's
    force is (−HF, −VF) to 1e-9 after 0.2 s (measured 4e-11)."""
    m = moorings(spec(length=0.45))
    cat = elastic_catenary(0.4, 0.35, 0.45, EA, wet_weight(), seabed=True)
    assert cat["regime"] == "hanging"
    hold(m, 0.2)
    f = m.fairlead_forces()[0, 1]
    assert f[0] == pytest.approx(-cat["HF"], rel=1e-9) and f[2] == pytest.approx(-cat["VF"], rel=1e-9)
    assert f[1] == 0.0


def test_a_slack_line_settles_on_the_catenary_with_its_touchdown():
    """L = 0.6 m: 0.13 m of it on the seabed. The nodes start on the catenary with the bed at their
    height; the bed's spring (kBot D l per node) lets them sink by w/(kBot D) = 4.49e-5 m while they
    settle. After 1 s the fairlead force is the catenary's within 0.5 % (measured +0.064 % in HF,
    +0.049 % in VF), and a node on the bed carries its wet weight on the spring (within 0.7 %)."""
    m = moorings(spec(length=0.6))
    w = wet_weight()
    cat = elastic_catenary(0.4, 0.35, 0.6, EA, w, seabed=True)
    assert cat["regime"] == "touchdown" and cat["lb"] == pytest.approx(0.130, abs=0.001)
    hold(m, 1.0)
    f = m.fairlead_forces()[0, 1]
    assert f[0] == pytest.approx(-cat["HF"], rel=5e-3) and f[2] == pytest.approx(-cat["VF"], rel=5e-3)
    on_bed = m.pos[1:4, 2]
    assert np.allclose(on_bed, -w / (3e6 * DIA), rtol=0.01)


def test_the_relaxation_before_t0_reaches_the_catenary():
    """tmaxIC 3 s in spans of dtIC 0.5 s (drag × cdScaleIC 5): it stops once the fairlead force has
    changed by less than threshIC = 1e-3 over two spans, before tmaxIC, at the catenary within 0.5 %
    (measured +0.16 % in HF, +0.04 % in VF)."""
    sp = spec(length=0.6)
    sp["solver"].update(tmaxic=3.0)
    m = moorings(sp)
    cat = elastic_catenary(0.4, 0.35, 0.6, EA, wet_weight(), seabed=True)
    f = m.fairlead_forces()[0, 1]
    assert f[0] == pytest.approx(-cat["HF"], rel=5e-3) and f[2] == pytest.approx(-cat["VF"], rel=5e-3)
    assert 3 < m.relax_spans < 6
    assert m.glob[-1] == 1.0            # the drag back to its own


def _middle_node_period(sp, disp, g=0.0, seconds=0.05):
    """The period of the middle node (two segments, both ends held) released from ``disp``."""
    m = moorings(sp, g=g)
    m.pos[1] += disp
    axis = np.flatnonzero(disp)[0]
    t, x = [], []
    dt = 2e-6
    for k in range(int(round(seconds / dt))):
        m.step(k * dt, dt, *BODY)
        t.append((k + 1) * dt)
        x.append(m.pos[1, axis] - (m.pos[0, axis] + m.pos[2, axis]) / 2)
    t, x = np.array(t), np.array(x)
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    return float(np.mean(np.diff(crossings))), m


def test_a_node_between_two_taut_segments_vibrates_at_the_closed_form_frequencies():
    """No gravity, no drag, no internal damping; two segments (l = 0.2 m) stretched 1 % between
    fixed ends. Along the line the middle node (mass ρ A l, no tangential added mass, Cat = 0) sits
    between two springs EA/l: ω² = 2 EA/(l ρ A l). Across it the tension T0 = 0.01 EA is the spring,
    2 T0/ℓ0, and the water adds Can ρ_w A l: ω² = 2 T0/(ℓ0 (ρ + Can ρ_w) A l). The RK2 periods match
    to 1e-4 and 1e-3 (measured −1.6e-6, −6e-8; a node mass counted twice gave √2 too long)."""
    length, stretch = 0.4, 1.01
    sp = spec(length=length, segments=2, fairlead=(length * stretch, 0.0, 0.0), fairlead_kind="fixed",
              ba=0.0, cdn=0.0, cdt=0.0, depth=5.0, freesurface=1.0)
    l = length / 2
    m_node = MASS * l
    axial = 2 * math.pi / math.sqrt(2 * EA / l / m_node)
    period, _ = _middle_node_period(sp, np.array([1e-5, 0.0, 0.0]), seconds=6 * axial)
    assert period == pytest.approx(axial, rel=1e-4)
    t0, l0 = EA * (stretch - 1), l * stretch
    transverse = 2 * math.pi / math.sqrt(2 * t0 / l0 / (m_node + 1.0 * 1000.0 * AREA * l))
    period, _ = _middle_node_period(sp, np.array([0.0, 0.0, 1e-5]), seconds=4 * transverse)
    assert period == pytest.approx(transverse, rel=1e-3)
    # out of the water (the free surface below the line): no added mass
    sp["solver"]["freesurface"] = -1.0
    dry = 2 * math.pi / math.sqrt(2 * t0 / l0 / m_node)
    period, _ = _middle_node_period(sp, np.array([0.0, 0.0, 1e-5]), seconds=4 * dry)
    assert period == pytest.approx(dry, rel=1e-3)


def test_a_line_breaks_at_its_break_tension_and_pulls_no_more():
    """The taut line (395 N at the fairlead) with breaktension 300 N breaks at once: a warning, its
    forces on the body are zero from then on."""
    with pytest.warns(UserWarning, match="breaktension 300 N"):
        m = moorings(spec(length=0.45, breaktension=300.0))
        hold(m, 1e-3)
    assert m.broken[0]
    assert np.all(m.fairlead_forces() == 0.0)
    F, T = m.loads()
    assert np.all(F == 0.0) and np.all(T == 0.0)


def test_the_start_ramp():
    """<start value ramptime>: 0 before start, ((t − start)/ramptime)² over the ramp, 1 after."""
    assert start_ramp(0.5, 1.0, 2.0) == 0.0
    assert start_ramp(2.0, 1.0, 2.0) == pytest.approx(0.25)
    assert start_ramp(3.0, 1.0, 2.0) == 1.0
    assert start_ramp(0.5, 1.0, 0.0) == 0.0 and start_ramp(1.0, 1.0, 0.0) == 1.0


def test_the_load_on_the_body_is_the_fairlead_force_and_its_moment():
    """The body's load is the fairlead node's force, its moment (p − c) × F about the body's centre."""
    m = moorings(spec(length=0.45))
    F, T = m.loads()
    f = m.fairlead_forces()[0, 1]
    assert np.allclose(F[0], f)
    assert np.allclose(T[0], np.cross(np.array([0.4, 0.0, 0.35]) - BODY[0][0], f))


def test_the_state_round_trips_exactly():
    """get_state/set_state (restart.h5): a copy put into fresh lines gives the same state back, and
    both advance to the same nodes bit for bit."""
    m = moorings(spec(length=0.6))
    hold(m, 0.01)
    st = m.get_state()
    other = moorings(spec(length=0.6))
    other.set_state(st)
    back = other.get_state()
    for key in st:
        assert np.array_equal(np.asarray(st[key]), np.asarray(back[key]), equal_nan=True), key
    for mm in (m, other):
        mm.step(0.01, 1e-4, *BODY)
    assert np.array_equal(m.pos, other.pos) and np.array_equal(m.F, other.F)

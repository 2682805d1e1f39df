"""Free connection nodes (MoorDynPlus's ``<connects>``: sphdvi.moorings.lines.connect_accelerations):
a line split in two at a massless connect moves as the whole line (the connect is then just one of
its nodes), and a clump weight hung between two anchors settles where its lines' tension holds its
wet weight (the closed form of two straight elastic lines)."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from sphdvi.moorings.system import Moorings

G = 9.81
EA, DIA = 2.9e3, 3.656e-3
AREA = math.pi * DIA ** 2 / 4
SOLVER = {"waterdepth": 2.0, "freesurface": 2.0, "kbot": 3e6, "cbot": 3e5, "dtm": 1e-4, "dtm_auto": True,
          "friction": 0.0, "fricdamp": 200.0, "statdynfricscale": 1.0, "rho": 1000.0, "cdscaleic": 5.0, "dtic": 0.5,
          "tmaxic": 0.0, "threshic": 0.001}
BODY = np.array([[0.5, 0.0, 0.4]]), np.array([[1.0, 0.0, 0.0, 0.0]])


def line(k, length, segments, ends, mass=0.0607, **kw):
    d = {"id": k, "ea": EA, "diameter": DIA, "mass": mass, "ba": -0.8, "can": 1.0, "cat": 1.0, "cdn": 0.0,
         "cdt": 0.0, "breaktension": 0.0, "length": length, "segments": segments, "depth": 2.0,
         "outputflags": "-", "savedata": True, "ends": ends}
    d.update(kw)
    return d


def spec(lines, connects=()):
    return {"floatings": [50], "start": 0.0, "ramptime": 0.0, "solver": dict(SOLVER), "lines": list(lines),
            "connects": list(connects), "savedata": None}


def connect(pos, mass=0.0, volume=0.0, cda=0.0, ca=0.0):
    return {"conref": 0, "pos": list(pos), "mass": mass, "volume": volume, "cda": cda, "ca": ca}


FIXED = {"kind": "fixed", "body": None, "pos": [0.0, 0.0, 1.0]}
VESSEL = {"kind": "vessel", "body": 50, "pos": [0.5, 0.0, 0.4]}
CON = {"kind": "connect", "connect": 0}


def test_a_line_split_at_a_massless_connect_moves_as_the_whole_line():
    """Isotropic added mass and no drag (Can = Cat, Cdn = Cdt = 0), so a node's mass and force do not
    depend on its tangent: a 20-segment line from an anchor to a body, and the same line as two of
    10 segments joined at a connect (M = V = 0) placed where the whole line's node 10 starts. The body
    swings the fairlead for 0.3 s: every node, the connect and the fairlead force agree to 1e-9."""
    whole = Moorings(spec([line(0, 1.0, 20, [FIXED, VESSEL])]), G, {50: 0}, *BODY)
    mid = whole.pos[10].copy()
    split = Moorings(spec([line(0, 0.5, 10, [FIXED, CON]), line(1, 0.5, 10, [CON, VESSEL])], [connect(mid)]),
                     G, {50: 0}, *BODY)
    split.pos[:11] = whole.pos[:11]               # the same start (each half's own catenary differs)
    split.pos[11:] = whole.pos[10:]
    dt = 2e-4
    for k in range(1500):
        t = k * dt
        centre = BODY[0] + np.array([[0.05 * math.sin(6 * t), 0.0, 0.03 * (1 - math.cos(6 * t))]])
        whole.step(t, dt, centre, BODY[1])
        split.step(t, dt, centre, BODY[1])
    np.testing.assert_allclose(split.cpos[0], whole.pos[10], atol=1e-9)
    np.testing.assert_allclose(split.pos[:11], whole.pos[:11], atol=1e-9)
    np.testing.assert_allclose(split.pos[11:], whole.pos[10:], atol=1e-9)
    np.testing.assert_allclose(split.fairlead_forces()[1, 1], whole.fairlead_forces()[0, 1], rtol=1e-9, atol=1e-9)
    assert abs(whole.pos[10, 0] - mid[0]) > 0.01       # the node did move


def test_a_clump_weight_between_two_anchors_stays_where_the_tension_holds_it():
    """Two neutrally buoyant lines (no wet weight: straight) of L = 0.5 m from anchors 0.8 m apart to a
    connect of M = 2 kg, V = 5e-4 m³ (wet weight 14.7 N), CdA 0.05 m², Ca 1, placed where
    2 EA (ℓ/L − 1) z/ℓ = (M − ρ V) g with ℓ = √(0.4² + z²) (z = 0.3035 m below the anchors): it stays
    there for 2 s within 1e-9 m, and each anchor carries the tension EA (ℓ/L − 1) along its line.
    Placed 2 cm higher it falls, and oscillates about that point (mean over 1.5-4 s within 2 mm)."""
    rho_line = 1000.0 * AREA                       # kg/m: as dense as the water
    a = {"kind": "fixed", "body": None, "pos": [-0.4, 0.0, 1.0]}
    b = {"kind": "fixed", "body": None, "pos": [0.4, 0.0, 1.0]}
    wet = (2.0 - 1000.0 * 5e-4) * G
    z = brentq(lambda z: 2 * EA * (math.hypot(0.4, z) / 0.5 - 1) * z / math.hypot(0.4, z) - wet, 0.3, 0.5)

    def clump(height):
        sp = spec([line(0, 0.5, 10, [a, CON], mass=rho_line), line(1, 0.5, 10, [b, CON], mass=rho_line)],
                  [connect([0.0, 0.0, height], mass=2.0, volume=5e-4, cda=0.05, ca=1.0)])
        return Moorings(sp, G, {50: 0}, *BODY)
    m = clump(1.0 - z)
    dt = 1e-3
    for k in range(2000):
        m.step(k * dt, dt, *BODY)
    assert m.cpos[0] == pytest.approx([0.0, 0.0, 1.0 - z], abs=1e-9)
    ell = math.hypot(0.4, z)
    tension = EA * (ell / 0.5 - 1)
    f_anchor = m.fairlead_forces()[0, 0]           # the line's pull on its anchor, towards the connect
    assert f_anchor == pytest.approx([tension * 0.4 / ell, 0.0, -tension * z / ell], rel=1e-7)
    m = clump(1.02 - z)
    heights = []
    for k in range(4000):
        m.step(k * dt, dt, *BODY)
        heights.append(m.cpos[0, 2])
    assert np.min(heights) < 1.0 - z - 0.005                 # it fell through the balance point
    assert np.mean(heights[1500:]) == pytest.approx(1.0 - z, abs=2e-3)


def test_connect_state_round_trip_and_a_non_finite_connect_stops_the_run():
    from sphdvi.errors import DivergenceError
    sp = spec([line(0, 0.5, 10, [FIXED, CON]), line(1, 0.5, 10, [CON, VESSEL])], [connect([0.2, 0.0, 0.6], mass=0.1)])
    m = Moorings(sp, G, {50: 0}, *BODY)
    for k in range(20):
        m.step(k * 1e-3, 1e-3, *BODY)
    st = m.get_state()
    m2 = Moorings(sp, G, {50: 0}, *BODY)
    m2.set_state(st)
    for mm in (m, m2):
        mm.step(0.02, 1e-3, *BODY)
    assert np.array_equal(m.cpos, m2.cpos) and np.array_equal(m.pos, m2.pos)
    m.cvel[0, 2] = np.nan
    with pytest.raises(DivergenceError, match="connect conref=0 is not finite"):
        m.step(0.021, 1e-3, *BODY)


def test_a_sinker_between_anchor_and_fairlead_rests_where_two_catenaries_meet():
    """A leg from an anchor to a held fairlead (0.9 m across, 0.5 m up) in two lines of 0.6 m (10
    segments) joined at a sinker (M = 50 g, V = 2e-5 m³: wet weight 0.29 N). At rest the sinker is where
    the two elastic catenaries (sphdvi.moorings.catenary, hanging free) meet with the same horizontal
    tension and a vertical jump of its wet weight: (0.5841, −0.0087) m, the fairlead pulled with
    (0.357, 0.732) N. The relaxation before t = 0 (tmaxIC 10 s, drag × 5; the sinker's CdA is not
    scaled, as MoorDynPlus) brings the sinker within 0.1 mm (measured 2.6e-5 m) and the fairlead
    force within 0.2 % (measured 0.055 %)."""
    from scipy.optimize import fsolve

    from sphdvi.moorings.catenary import elastic_catenary
    w = (0.0607 - 1000.0 * AREA) * G
    wc = (0.05 - 1000.0 * 2e-5) * G
    xf, zf, length = 0.9, 0.5, 0.6

    def balance(p):
        a = elastic_catenary(p[0], p[1], length, EA, w, seabed=False)
        b = elastic_catenary(xf - p[0], zf - p[1], length, EA, w, seabed=False)
        return [b["HA"] - a["HF"], b["VA"] - a["VF"] - wc]
    xc, zc = fsolve(balance, [0.45, 0.0], xtol=1e-13)
    fair = elastic_catenary(xf - xc, zf - zc, length, EA, w, seabed=False)
    assert (xc, zc) == pytest.approx((0.5841, -0.0087), abs=1e-4)
    drag = {"cdn": 1.6, "cdt": 0.05, "can": 1.0, "cat": 0.0, "depth": 3.0}
    anchor = {"kind": "fixed", "body": None, "pos": [0.0, 0.0, 0.0]}
    vessel = {"kind": "vessel", "body": 50, "pos": [xf, 0.0, zf]}
    sp = spec([line(0, length, 10, [anchor, CON], **drag), line(1, length, 10, [CON, vessel], **drag)],
              [connect([0.45, 0.0, 0.05], mass=0.05, volume=2e-5, cda=0.002, ca=1.0)])
    sp["solver"].update(waterdepth=3.0, freesurface=2.0, tmaxic=10.0, dtic=0.5, cdscaleic=5.0, threshic=1e-7)
    m = Moorings(sp, G, {50: 0}, np.array([[xf, 0.0, zf]]), np.array([[1.0, 0.0, 0.0, 0.0]]))
    assert m.cpos[0] == pytest.approx([xc, 0.0, zc], abs=1e-4)
    f = m.fairlead_forces()[1, 1]
    assert -f[0] == pytest.approx(fair["HF"], rel=2e-3) and -f[2] == pytest.approx(fair["VF"], rel=2e-3)


def test_a_relaxation_without_vessel_lines_stops_after_four_spans():
    """MoorDynPlus's DoDynamicRelaxIC tests the vessel fairleads' tensions only: with none (two anchors
    and a clump weight) the test passes at its first check, after the fourth span of dtIC, not at tmaxIC."""
    a = {"kind": "fixed", "body": None, "pos": [-0.4, 0.0, 1.0]}
    b = {"kind": "fixed", "body": None, "pos": [0.4, 0.0, 1.0]}
    sp = spec([line(0, 0.5, 10, [a, CON]), line(1, 0.5, 10, [b, CON])], [connect([0.0, 0.0, 0.7], mass=0.2)])
    sp["solver"].update(tmaxic=5.0, dtic=0.1)
    m = Moorings(sp, G, {50: 0}, *BODY)
    assert m.relax_spans == 4

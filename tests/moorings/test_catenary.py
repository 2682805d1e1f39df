"""The quasi-static elastic catenary (sphdvi.moorings.catenary): its equations, its limits and the
force balance of its profiles."""

import math

import numpy as np
import pytest

from sphdvi.moorings.catenary import elastic_catenary


def equations(HF, VF, L, EA, w, regime):
    """(xf, zf) from the Jonkman (2007) / Irvine (1981) equations, written out independently."""
    if regime == "hanging":
        VA = VF - w * L
        x = (HF / w) * (math.asinh(VF / HF) - math.asinh(VA / HF)) + HF * L / EA
        z = (HF / w) * (math.sqrt(1 + (VF / HF) ** 2) - math.sqrt(1 + (VA / HF) ** 2)) + (
            VF * L - w * L * L / 2
        ) / EA
    else:
        LB = L - VF / w
        x = LB + (HF / w) * math.asinh(VF / HF) + HF * L / EA
        z = (HF / w) * (math.sqrt(1 + (VF / HF) ** 2) - 1) + VF**2 / (2 * EA * w)
    return x, z


def bisect(f, a, b, n=200):
    fa = f(a)
    for _ in range(n):
        m = 0.5 * (a + b)
        fm = f(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


# (xf, zf, L, EA, w, seabed, expected regime)
CASES = [
    (100.0, 50.0, 100.0, 1e5, 10.0, True, "hanging"),  # taut, stretched ~1 %
    (100.0, 50.0, 140.0, 1e8, 10.0, True, "touchdown"),  # slack, 86 m on the bed
    (100.0, -50.0, 140.0, 1e6, 10.0, False, "hanging"),  # free, dipping below the anchor
]


@pytest.mark.parametrize("xf, zf, L, EA, w, seabed, regime", CASES)
def test_solution_satisfies_equations_and_profile_ends_at_fairlead(
    xf, zf, L, EA, w, seabed, regime
):
    r = elastic_catenary(xf, zf, L, EA, w, seabed=seabed, s=np.linspace(0.0, L, 101))
    assert r["regime"] == regime
    x, z = equations(r["HF"], r["VF"], L, EA, w, regime)
    scale = max(abs(xf), abs(zf))
    assert abs(x - xf) <= 1e-9 * scale and abs(z - zf) <= 1e-9 * scale
    assert abs(r["x"][-1] - xf) <= 1e-9 * scale and abs(r["z"][-1] - zf) <= 1e-9 * scale
    assert r["x"][0] == 0.0 and r["z"][0] == 0.0
    assert r["HA"] == r["HF"]
    if regime == "touchdown":
        assert r["VA"] == 0.0 and r["lb"] == pytest.approx(L - r["VF"] / w, rel=1e-14)
    else:
        assert r["VA"] == pytest.approx(r["VF"] - w * L, rel=1e-14) and r["lb"] == 0.0


def test_inextensible_symmetric_limit_matches_classical_catenary():
    xf, L, w, EA = 80.0, 100.0, 2.0, 1e12
    r = elastic_catenary(xf, 0.0, L, EA, w, seabed=False)
    # classical catenary between points at one height: L = (2 H/w) sinh(w xf/(2 H))
    H = bisect(lambda H: (2 * H / w) * math.sinh(w * xf / (2 * H)) - L, 1.0, 1e4)
    assert r["HF"] == pytest.approx(H, rel=1e-8)
    assert r["VF"] == pytest.approx(w * L / 2, rel=1e-8)
    assert r["VA"] == pytest.approx(-w * L / 2, rel=1e-8)


@pytest.mark.parametrize(
    "xf, zf, L, EA, w, seabed",
    [(90.0, 40.0, 95.0, 1e5, 10.0, False), (180.0, 40.0, 190.0, 2e4, 10.0, True)],
)
def test_stretched_length_is_L_plus_integral_of_tension(xf, zf, L, EA, w, seabed):
    """The profile's length is L + ∫T ds/EA (each element stretched by T/EA), and the vertical
    forces balance: VF - VA = w × (suspended length)."""
    n = 200_001
    s = np.linspace(0.0, L, n)
    if seabed:
        # put a node exactly at the touchdown point so the kink is not cut by a chord
        lb = elastic_catenary(xf, zf, L, EA, w, seabed=seabed)["lb"]
        s = np.unique(np.concatenate([s, [lb]]))
    r = elastic_catenary(xf, zf, L, EA, w, seabed=seabed, s=s)
    stretched = np.sum(np.hypot(np.diff(r["x"]), np.diff(r["z"])))
    t = r["tension"]
    stretch = np.sum(0.5 * (t[1:] + t[:-1]) * np.diff(s)) / EA
    assert stretch > 0.01 * L  # a taut, really stretched line
    assert abs(stretched - (L + stretch)) <= 1e-9 * L
    if seabed:
        assert r["regime"] == "touchdown" and 0.0 < r["lb"] < L
        assert r["VF"] == pytest.approx(w * (L - r["lb"]), rel=1e-12)
    else:
        assert r["regime"] == "hanging"
        assert r["VF"] - r["VA"] == pytest.approx(w * L, rel=1e-12)


def test_touchdown_tangent_and_vertical_balance():
    xf, zf, L, EA, w = 100.0, 50.0, 140.0, 1e6, 10.0
    r = elastic_catenary(xf, zf, L, EA, w)
    HF, VF, lb = r["HF"], r["VF"], r["lb"]
    assert r["regime"] == "touchdown" and 0.0 < lb < L
    # the suspended part's weight is carried at the fairlead
    assert VF == pytest.approx(w * (L - lb), rel=1e-12)
    # the line leaves the bed tangentially: one-sided slope at LB → 0, shrinking ∝ δ
    slopes = []
    for d in (1e-3, 1e-4, 1e-5):
        p = elastic_catenary(xf, zf, L, EA, w, s=[lb, lb + d])
        slopes.append((p["z"][1] - p["z"][0]) / (p["x"][1] - p["x"][0]))
    # w δ/(2 HF) for a parabola leaving the bed: slope at δ/2 along the line
    for d, sl in zip((1e-3, 1e-4, 1e-5), slopes):
        assert sl == pytest.approx(w * d / (2 * HF), rel=1e-3)
    # on the bed the line is flat, and the profile's tangent is the tension's direction, V/H
    sb = np.linspace(0.0, lb, 11)
    assert np.all(elastic_catenary(xf, zf, L, EA, w, s=sb)["z"] == 0.0)
    for si in (lb + 5.0, lb + 20.0, L - 1.0):
        p = elastic_catenary(xf, zf, L, EA, w, s=[si - 1e-4, si + 1e-4])
        slope = (p["z"][1] - p["z"][0]) / (p["x"][1] - p["x"][0])
        assert slope == pytest.approx(w * (si - lb) / HF, rel=1e-7)


def test_continuous_across_regime_boundary():
    zf, L, EA, w = 50.0, 140.0, 1e5, 10.0
    # the boundary: VF = w L exactly, VA = 0; solve zf for HF, then xf
    def zf_of(H):
        return (H / w) * (math.sqrt(1 + (w * L / H) ** 2) - 1) + w * L * L / (2 * EA) - zf

    H = bisect(zf_of, 1e-3, 1e7)
    xb = (H / w) * math.asinh(w * L / H) + H * L / EA
    xs = xb * (1.0 + 1e-8 * np.arange(-50, 51))
    sols = [elastic_catenary(x, zf, L, EA, w) for x in xs]
    regimes = [r["regime"] for r in sols]
    assert regimes[0] == "touchdown" and regimes[-1] == "hanging"
    k = regimes.index("hanging")
    assert set(regimes[:k]) == {"touchdown"} and set(regimes[k:]) == {"hanging"}
    HF = np.array([r["HF"] for r in sols])
    VF = np.array([r["VF"] for r in sols])
    assert np.max(np.abs(np.diff(HF)) / HF[1:]) <= 1e-6
    assert np.max(np.abs(np.diff(VF)) / VF[1:]) <= 1e-6
    # and the jump at the switch is no larger than the step next to it
    assert abs(HF[k] - HF[k - 1]) <= 3.0 * abs(HF[k + 1] - HF[k])
    assert HF[k] == pytest.approx(H, rel=1e-6) and VF[k] == pytest.approx(w * L, rel=1e-6)


def test_errors():
    # too long to lie on the seabed without doubling back (the limit itself included)
    xf, zf, EA, w = 100.0, 50.0, 1e5, 10.0
    lmax = xf - EA / w + math.sqrt((EA / w) ** 2 + 2 * zf * EA / w)
    elastic_catenary(xf, zf, lmax * (1 - 1e-6), EA, w)  # just shorter: solvable
    for L in (lmax, 1.01 * lmax, 300.0):
        with pytest.raises(ValueError, match="doubling back"):
            elastic_catenary(xf, zf, L, EA, w)
    elastic_catenary(xf, zf, 300.0, EA, w, seabed=False)  # free: fine
    with pytest.raises(ValueError, match="w must be > 0"):
        elastic_catenary(xf, zf, 120.0, EA, 0.0)
    with pytest.raises(ValueError, match="w must be > 0"):
        elastic_catenary(xf, zf, 120.0, EA, -1.0)
    for L in (0.0, -5.0):
        with pytest.raises(ValueError, match="length must be > 0"):
            elastic_catenary(xf, zf, L, EA, w)
    for ea in (0.0, -1e5, math.nan):
        with pytest.raises(ValueError, match="EA must be > 0"):
            elastic_catenary(xf, zf, 120.0, ea, w)
    with pytest.raises(ValueError, match="xf"):
        elastic_catenary(-1.0, zf, 120.0, EA, w)
    with pytest.raises(ValueError, match="below the seabed"):
        elastic_catenary(xf, -1.0, 120.0, EA, w)
    with pytest.raises(ValueError, match="inextensible"):
        elastic_catenary(xf, zf, 100.0, math.inf, w)
    with pytest.raises(ValueError, match=r"\[0, L\]"):
        elastic_catenary(xf, zf, 120.0, EA, w, s=[0.0, 121.0])


def test_vertical_and_flat_limits():
    """xf → 0 tends to the straight vertical line (HF = 0); zf = 0 on the bed is a stretched
    bar."""
    L, EA, w = 150.0, 1e5, 10.0
    for zf, seabed in ((50.0, False), (-160.0, False), (155.0, True)):
        r0 = elastic_catenary(0.0, zf, L, EA, w, seabed=seabed, s=[L])
        r1 = elastic_catenary(1e-6, zf, L, EA, w, seabed=seabed, s=[L])
        assert r0["HF"] == 0.0 and r0["z"][0] == pytest.approx(zf, rel=1e-12)
        assert r1["VF"] == pytest.approx(r0["VF"], rel=1e-6)
    r = elastic_catenary(200.0, 0.0, L, EA, w, s=[0.0, L])
    assert r["regime"] == "touchdown" and r["lb"] == L and r["VF"] == 0.0
    assert r["HF"] == pytest.approx(EA * (200.0 / L - 1.0), rel=1e-12)
    assert r["x"][1] == pytest.approx(200.0, rel=1e-12)


def test_laboratory_line():
    """A line of DualSPHysics's moored floating box scale: EA = 2.9e3 N, D = 3.656 mm,
    0.0607 kg/m in water of 1000 kg/m^3 (w = 0.49248 N/m), fairlead 0.4 m horizontally from
    and 0.35 m above the anchor, seabed at the anchor. Measured:

    L = 0.45 m: hanging (taut, stretched 18 %), HF = 395.305 N, VF = 346.003 N (VA = 345.781 N)
    L = 0.60 m: touchdown, HF = 0.069024 N, VF = 0.231305 N, 0.13033 m on the bed
    """
    g, rho, D, m, EA = 9.81, 1000.0, 3.656e-3, 0.0607, 2.9e3
    w = (m - rho * math.pi * D * D / 4) * g
    assert w == pytest.approx(0.492483, rel=1e-6)
    xf, zf = 0.4, 0.35
    r = elastic_catenary(xf, zf, 0.45, EA, w, s=np.linspace(0, 0.45, 51))
    assert r["regime"] == "hanging"
    assert r["HF"] == pytest.approx(395.305, rel=1e-5)
    assert r["VF"] == pytest.approx(346.003, rel=1e-5)
    # taut: the tension is close to a straight weightless bar's, EA (D/L - 1)
    assert r["tension"][-1] == pytest.approx(EA * (math.hypot(xf, zf) / 0.45 - 1), rel=1e-3)
    r = elastic_catenary(xf, zf, 0.6, EA, w, s=np.linspace(0, 0.6, 51))
    assert r["regime"] == "touchdown"
    assert r["HF"] == pytest.approx(0.069024, rel=1e-4)
    assert r["VF"] == pytest.approx(0.231305, rel=1e-5)
    assert r["lb"] == pytest.approx(0.13033, rel=1e-4)
    assert r["x"][-1] == pytest.approx(xf, rel=1e-9)
    assert r["z"][-1] == pytest.approx(zf, rel=1e-9)

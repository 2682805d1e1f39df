"""The quasi-static elastic catenary of a mooring line (Irvine 1981, "Cable Structures", ch. 1-2;
Jonkman 2007, NREL/TP-500-41958, Appendix: the quasi-static line of FAST). It is the model
DualSPHysics's MoorDynPlus uses to place a line's nodes at t = 0, before the lumped-mass dynamics
(sphdvi.moorings.lines) takes over.

A cable of unstretched length L, axial stiffness EA and weight per unit length in water w hangs in
a vertical plane from its anchor at (0, 0) to its fairlead at (xf, zf). With HF, VF the horizontal
and vertical components of the tension at the fairlead (the force the line pulls the fairlead with
is (-HF, -VF) in the plane, taking x from anchor to fairlead) and s the unstretched arc length from
the anchor, the tension is T(s) = sqrt(HF^2 + V(s)^2), V growing by w per unit s; each element
stretches by (1 + T/EA), so dx/ds = HF/T + HF/EA and dz/ds = V/T + V/EA. Integrating:

* hanging (no seabed, or a seabed that the line does not touch: VA = VF - w L >= 0)

      xf = (HF/w)[asinh(VF/HF) - asinh(VA/HF)] + HF L/EA
      zf = (HF/w)[sqrt(1 + (VF/HF)^2) - sqrt(1 + (VA/HF)^2)] + (VF L - w L^2/2)/EA

* touchdown (seabed at the anchor's height, VF < w L; the length LB = L - VF/w lies on the bed,
  frictionless, CB = 0, so it carries HF)

      xf = LB + (HF/w) asinh(VF/HF) + HF L/EA
      zf = (HF/w)[sqrt(1 + (VF/HF)^2) - 1] + VF^2/(2 EA w)

The two sets agree, with their first derivatives, at VF = w L, so Newton's method on (HF, VF)
with the analytic Jacobian crosses the regime boundary smoothly. The equations are solved in
dimensionless form (lengths / L, forces / (w L), e = w L/EA) with the differences of square roots
written without cancellation: sqrt(H^2 + a^2) - sqrt(H^2 + b^2) = (a - b)(a + b)/(Ta + Tb).

The node profiles at unstretched arc length s (the same integrals stopped at s) are

* hanging, Vs = VA + w s:
      x = (HF/w)[asinh(Vs/HF) - asinh(VA/HF)] + HF s/EA
      z = (HF/w)[sqrt(1 + (Vs/HF)^2) - sqrt(1 + (VA/HF)^2)] + (s/EA)(VA + w s/2)
* touchdown: s <= LB: x = s (1 + HF/EA), z = 0; s > LB, Vs = w (s - LB):
      x = LB + (HF/w) asinh(Vs/HF) + HF s/EA
      z = (HF/w)[sqrt(1 + (Vs/HF)^2) - 1] + Vs^2/(2 EA w)

with the effective tension T = sqrt(HF^2 + Vs^2) (HF on the bed).
"""

import math

import numpy as np

__all__ = ["elastic_catenary"]

_MAX_ITER = 500


def _h_asinh(h, a, b=0.0):
    """h [asinh(a/h) - asinh(b/h)], with its limit 0 at h = 0 (a vertical line).

    For a, b of one sign the difference is taken as one asinh,
    asinh(a/h) - asinh(b/h) = asinh((a - b)(a + b)/(a Tb + b Ta)), T = sqrt(h^2 + .^2), which
    keeps its accuracy for a taut line (h >> |a|, |b|) and a nearly vertical one (h << |a|, |b|).
    """
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    if h == 0.0:
        return np.zeros(a.shape) if a.ndim else 0.0
    same = a * b > 0.0
    den = a * np.hypot(h, b) + b * np.hypot(h, a)
    one = np.arcsinh(np.divide((a - b) * (a + b), den, out=np.zeros(a.shape), where=same))
    out = h * np.where(same, one, np.arcsinh(a / h) - np.arcsinh(b / h))
    return out if out.ndim else float(out)


def _hyp_diff(h, a, b):
    """sqrt(h^2 + a^2) - sqrt(h^2 + b^2) without cancellation (0 where both are 0)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    den = np.hypot(h, a) + np.hypot(h, b)
    num = (a - b) * (a + b)
    out = np.divide(num, den, out=np.zeros(np.broadcast(a, b).shape), where=den > 0.0)
    return out if out.ndim else float(out)


def _residual(h, v, X, Z, e, seabed):
    """Dimensionless residual (x, z) and its Jacobian in (h, v) = (HF, VF)/(w L)."""
    tf = math.hypot(h, v)
    if seabed and v < 1.0:
        # touchdown: 1 - v of the line on the bed
        ash = math.asinh(v / h)
        fx = 1.0 - v + h * ash + h * e - X
        fz = v * v / (tf + h) + 0.5 * e * v * v - Z
        jac = np.array(
            [
                [ash - v / tf + e, -v * v / (tf * (tf + h))],
                [-v * v / (tf * (tf + h)), v / tf + e * v],
            ]
        )
        return np.array([fx, fz]), jac, "touchdown"
    va = v - 1.0
    ta = math.hypot(h, va)
    hash_ = _h_asinh(h, v, va)
    ash = hash_ / h
    fx = hash_ + h * e - X
    fz = (2.0 * v - 1.0) / (tf + ta) + e * (v - 0.5) - Z
    cross = -h * (2.0 * v - 1.0) / (tf * ta * (tf + ta))  # h/tf - h/ta
    jac = np.array(
        [
            [ash - (v / tf - va / ta) + e, cross],
            [cross, v / tf - va / ta + e],
        ]
    )
    return np.array([fx, fz]), jac, "hanging"


def _initial_guess(X, Z, e):
    """Jonkman's (2007) start, plus a stretch-based one for a taut elastic line."""
    D = math.hypot(X, Z)
    if D >= 1.0:
        lam = 0.2
    else:
        lam = math.sqrt(3.0 * ((1.0 - Z * Z) / (X * X) - 1.0)) if X > 1e-6 else 1e6
        lam = min(lam, 1e6)
    h = abs(X / (2.0 * lam))
    v = 0.5 * (Z / math.tanh(lam) + 1.0)
    if D > 1.0 and e > 0.0:
        t = (D - 1.0) / e  # tension of a straight, weightless line stretched to D
        if t * X / D > h:
            h, v = t * X / D, t * Z / D + 0.5
    return max(h, 1e-300), v


def _solve(X, Z, e, seabed, tol):
    h, v = _initial_guess(X, Z, e)
    if seabed and v <= 0.0:
        v = min(0.5, Z)
    F, J, regime = _residual(h, v, X, Z, e, seabed)
    for _ in range(_MAX_ITER):
        res = float(np.max(np.abs(F)))
        if res <= tol:
            return h, v, regime
        try:
            dh, dv = np.linalg.solve(J, -F)
        except np.linalg.LinAlgError:
            dh, dv = np.linalg.lstsq(J, -F, rcond=None)[0]
        if not (math.isfinite(dh) and math.isfinite(dv)):
            break
        # damp: HF stays > 0 (at least a tenth of its value), VF > 0 with a seabed
        alpha = 1.0
        if h + dh <= 0.1 * h:
            alpha = min(alpha, 0.9 * h / -dh)
        if seabed and v + dv <= 0.1 * v:
            alpha = min(alpha, 0.9 * v / -dv)
        phi = float(F @ F)
        while True:
            hn, vn = h + alpha * dh, v + alpha * dv
            Fn, Jn, rn = _residual(hn, vn, X, Z, e, seabed)
            if float(Fn @ Fn) <= (1.0 - 1e-4 * alpha) * phi or alpha < 1e-12:
                break
            alpha *= 0.5
        step = max(abs(hn - h) / max(h, 1e-300), abs(vn - v) / max(abs(v), 1.0))
        h, v, F, J, regime = hn, vn, Fn, Jn, rn
        if step <= 4.0 * np.finfo(float).eps:
            break  # at round-off
    res = float(np.max(np.abs(F)))
    if res <= max(tol, 1e-10):
        return h, v, regime
    raise RuntimeError(
        f"elastic_catenary: Newton's method did not converge (residual {res:.3e} of L "
        f"at HF/(wL) = {h:.6g}, VF/(wL) = {v:.6g})"
    )


def _vertical(Z, e, seabed):
    """xf = 0: the line hangs straight down from the fairlead (HF = 0); v = VF/(w L)."""
    if Z >= 1.0 + 0.5 * e:  # taut all along
        if e == 0.0:
            raise ValueError(
                "elastic_catenary: an inextensible vertical line "
                + ("cannot reach the fairlead" if Z > 1.0 else "has an indeterminate tension")
            )
        return 0.5 + (Z - 1.0) / e
    if seabed:  # unreachable: the doubling-back check comes first
        raise ValueError("elastic_catenary: the vertical line would pile up on the seabed")
    if Z <= -1.0 - 0.5 * e:  # fairlead below the anchor, pulled down by the taut line
        if e == 0.0:
            raise ValueError(
                "elastic_catenary: an inextensible vertical line "
                + ("cannot reach the fairlead" if Z < -1.0 else "has an indeterminate tension")
            )
        return 0.5 + (Z + 1.0) / e
    return 0.5 + Z / (2.0 + e)  # folded: down from the anchor and up to the fairlead


def _profile(sig, h, v, regime, lb, e):
    """Dimensionless x, z, T at sig = s/L."""
    if regime == "hanging":
        va = v - 1.0
        vs = va + sig
        x = _h_asinh(h, vs, va) + h * e * sig
        z = _hyp_diff(h, vs, va) + e * sig * (va + 0.5 * sig)
        return x, z, np.hypot(h, vs)
    vs = np.maximum(sig - lb, 0.0)
    bed = sig <= lb
    x = np.where(bed, sig * (1.0 + h * e), lb + _h_asinh(h, vs) + h * e * sig)
    z = np.where(bed, 0.0, _hyp_diff(h, vs, 0.0 * vs) + 0.5 * e * vs * vs)
    return x, z, np.hypot(h, vs)


def elastic_catenary(xf, zf, length, ea, w, seabed=True, tol=1e-12, s=None):
    """Static equilibrium of an elastic cable from an anchor at (0, 0) to a fairlead at (xf, zf).

    length: unstretched length L (m); ea: axial stiffness EA (N; math.inf for an inextensible
    line); w: weight per unit length in water (N/m, > 0); seabed: a frictionless seabed at the
    anchor's height (the line may lie on it), else the line hangs freely (also below the anchor);
    tol: the largest residual of the two equations, as a fraction of L; s: optional unstretched
    arc lengths from the anchor (0..L) at which to return the profile.

    Returns a dict: HF, VF (fairlead tension components, N), HA, VA (at the anchor; VA = 0 on
    the bed), regime ("hanging" or "touchdown"), lb (length lying on the seabed, m) and, with s,
    x, z (positions relative to the anchor, m) and tension (effective tension, N) at s.
    Raises ValueError for invalid input or a configuration with no solution (a line that would
    have to double back on the seabed, an inextensible line shorter than the span, a fairlead
    below the seabed), RuntimeError if Newton's method fails to converge.
    """
    xf, zf, L, EA, w = float(xf), float(zf), float(length), float(ea), float(w)
    if not (math.isfinite(xf) and xf >= 0.0):
        raise ValueError(f"elastic_catenary: xf must be finite and >= 0, got {xf}")
    if not math.isfinite(zf):
        raise ValueError(f"elastic_catenary: zf must be finite, got {zf}")
    if not (math.isfinite(L) and L > 0.0):
        raise ValueError(f"elastic_catenary: the unstretched length must be > 0, got {L}")
    if not EA > 0.0:  # also rejects nan
        raise ValueError(f"elastic_catenary: EA must be > 0, got {EA}")
    if not (math.isfinite(w) and w > 0.0):
        raise ValueError(f"elastic_catenary: the wet weight per length w must be > 0, got {w}")
    if not tol > 0.0:
        raise ValueError(f"elastic_catenary: tol must be > 0, got {tol}")
    seabed = bool(seabed)
    X, Z, e = xf / L, zf / L, w * L / EA
    if seabed and Z < 0.0:
        raise ValueError(f"elastic_catenary: the fairlead (zf = {zf}) is below the seabed")
    if seabed:
        # longest line that still reaches the fairlead with HF > 0: as HF -> 0 a vertical part
        # u rises from the bed, zf = u + w u^2/(2 EA); anything longer doubles back on the bed
        u = 2.0 * Z / (1.0 + math.sqrt(1.0 + 2.0 * Z * e))
        if 1.0 >= X + u:
            lmax = xf + u * L
            raise ValueError(
                f"elastic_catenary: the line (L = {L}) is too long to lie on the seabed without "
                f"doubling back; it must be shorter than xf - EA/w + sqrt((EA/w)^2 + 2 zf EA/w) "
                f"= {lmax}"
            )
    if e == 0.0 and math.hypot(X, Z) >= 1.0 and X > 0.0:
        raise ValueError(
            f"elastic_catenary: an inextensible line (L = {L}) cannot span the distance "
            f"{math.hypot(xf, zf)} to the fairlead"
        )

    if X == 0.0:
        h, v = 0.0, _vertical(Z, e, seabed)
        regime = "hanging"
    elif seabed and Z == 0.0:
        h, v, regime = (X - 1.0) / e, 0.0, "touchdown"  # all on the bed, stretched
    else:
        h, v, regime = _solve(X, Z, e, seabed, float(tol))
    lb = 1.0 - v if regime == "touchdown" else 0.0
    wl = w * L
    out = {
        "HF": float(h * wl),
        "VF": float(v * wl),
        "HA": float(h * wl),
        "VA": 0.0 if regime == "touchdown" else float((v - 1.0) * wl),
        "regime": regime,
        "lb": float(lb * L),
    }
    if s is not None:
        sa = np.asarray(s, dtype=float)
        if not np.all(np.isfinite(sa)) or np.any(sa < 0.0) or np.any(sa > L):
            raise ValueError("elastic_catenary: the arc lengths s must lie in [0, L]")
        x, z, t = _profile(sa / L, h, v, regime, lb, e)
        out["x"] = np.asarray(x) * L
        out["z"] = np.asarray(z) * L
        out["tension"] = np.asarray(t) * wl
    return out

"""The wave maker against first-order wavemaker theory (``cases/waveflume2d``): a piston (W1) or
a flap hinged at the bottom (W2) makes regular waves H = 0.03 m, T = 1.2 s in d = 0.3 m.  From
the run-time gauges WG1-WG3 (x = 0.3, 0.6, 0.9 m), over the last two periods: the first harmonic's complex amplitude at each gauge,
split by least squares into an incident and a reflected wave of the linear wave number
(Mansard & Funke 1980, three gauges); the incident height against H.  ``paddle_stroke`` measures
the paddle's stroke at the still-water level on its particles, so that a height error is not a
wrong stroke (Biesel's transfer function) in disguise."""
from __future__ import annotations

import math

import numpy as np

from .runs import gauge_table

H = 0.03                   # target wave height [m]
PERIOD = 1.2               # s
DEPTH = 0.3                # m
GAUGES = {"WG1": 0.3, "WG2": 0.6, "WG3": 0.9}
WINDOW = 2                 # periods, at the end of the run
STILL_BEFORE = 0.1         # s: the gauges read the still water before the first wave reaches WG1


def first_harmonic(t: np.ndarray, eta: np.ndarray, omega: float) -> complex:
    """Complex amplitude A of η ≈ c + Re(A e^{iωt}) (+ the second harmonic), least squares."""
    basis = np.column_stack([np.ones(t.size), np.cos(omega * t), np.sin(omega * t),
                             np.cos(2 * omega * t), np.sin(2 * omega * t)])
    c = np.linalg.lstsq(basis, eta, rcond=None)[0]
    return complex(c[1], -c[2])


def incident_reflected(x: np.ndarray, amp: np.ndarray, k: float) -> tuple[complex, complex]:
    """(incident, reflected) complex amplitudes with amp(x) = A_i e^{−ikx} + A_r e^{ikx}."""
    m = np.column_stack([np.exp(-1j * k * x), np.exp(1j * k * x)])
    a = np.linalg.lstsq(m, amp, rcond=None)[0]
    return complex(a[0]), complex(a[1])


def fitted_wavenumber(x: np.ndarray, amp: np.ndarray, k0: float) -> float:
    """The wave number k within ±30 % of ``k0`` for which amp(x) = A_i e^{−ikx} + A_r e^{ikx} fits
    the gauges' complex amplitudes best (least squares; steps of 1e-4 k0): the wave's own k."""
    ks = k0 * np.linspace(0.7, 1.3, 6001)
    resid = []
    for k in ks:
        m = np.column_stack([np.exp(-1j * k * x), np.exp(1j * k * x)])
        a = np.linalg.lstsq(m, amp, rcond=None)[0]
        resid.append(np.linalg.norm(m @ a - amp))
    return float(ks[int(np.argmin(resid))])


def wave_errors(outdir: str) -> dict:
    """Incident height relative to H, the reflection coefficient, the height of the first
    harmonic at each gauge (relative to H); ``celerity``: the phase speed ω/k of the wave the
    gauges see (k from :func:`fitted_wavenumber`) over linear theory's, minus 1, and
    ``reflection_fitted_k`` the reflection coefficient with that k (the split with the theory's k
    takes a phase-speed error for reflection).  ``celerity_still_depth``: the same phase speed against
    linear theory's in the depth the gauges read in the still water (before the first wave arrives,
    from the bottom wall's particle centres at z = 0 to the kernel-sum surface, which stands above
    the top fluid particles), ``still_depth``."""
    from ..motion import wave_number
    k = wave_number(PERIOD, DEPTH)
    omega = 2 * math.pi / PERIOD
    xs, amps, out, still = [], [], {}, []
    for name, x in GAUGES.items():
        g = gauge_table(outdir, "SWL", name)
        t, eta = g[:, 0], g[:, 3]
        still.append(float(np.mean(eta[t <= STILL_BEFORE])))
        sel = t >= t[-1] - WINDOW * PERIOD - 1e-9
        a = first_harmonic(t[sel], eta[sel], omega)
        xs.append(x)
        amps.append(a)
        out[f"H_{name}"] = 2 * abs(a) / H - 1.0
    inc, ref = incident_reflected(np.asarray(xs), np.asarray(amps), k)
    out["H_incident"] = 2 * abs(inc) / H - 1.0
    out["reflection"] = abs(ref) / abs(inc)
    k_wave = fitted_wavenumber(np.asarray(xs), np.asarray(amps), k)
    out["celerity"] = k / k_wave - 1.0
    out["still_depth"] = float(np.mean(still))
    out["celerity_still_depth"] = wave_number(PERIOD, out["still_depth"]) / k_wave - 1.0
    inc, ref = incident_reflected(np.asarray(xs), np.asarray(amps), k_wave)
    out["reflection_fitted_k"] = abs(ref) / abs(inc)
    return out


def paddle_stroke(outdir: str, kind: str, mkbound: int = 10) -> float:
    """Stroke S (peak to peak, at the still-water level z = DEPTH) of the paddle ``mkbound`` over
    the last two periods of the saved steps, from its rigid motion fitted to its particles
    (:func:`sphdvi.measure.post.tracked_motion`): the x displacement (``kind`` "piston"), or the
    rotation θ about a hinge on the bottom (z = 0), S = 2 DEPTH tan|θ| ("flap")."""
    from ..measure.post import RunOutput, tracked_motion
    run = RunOutput(str(outdir))
    motion = tracked_motion(run, [mkbound], mkbound=True)
    times = run.times()
    first = int(np.searchsorted(times, times[-1] - WINDOW * PERIOD - 1e-9))
    t, x = [], []
    for snap in run.snapshots(arrays=("Mk",), first=first):
        R, d = motion(snap)
        t.append(snap.time)
        x.append(d[0] if kind == "piston" else math.atan2(R[0, 2], R[0, 0]))
    amp = abs(first_harmonic(np.asarray(t), np.asarray(x), 2 * math.pi / PERIOD))
    return 2 * amp if kind == "piston" else 2 * DEPTH * math.tan(amp)


# ---- W4: irregular waves (cases/waveflume2d/CaseWaveIrregular2D_Def.xml) ----
IRREGULAR_GAUGES = {"WG1": 0.6, "WG2": 1.2, "WG3": 1.8}
IRREGULAR_FROM = 6.0       # s: the 2 s ramp is over and its first waves have passed WG3
STILL_UNTIL = 0.2          # s: the gauges' still-water reading, before the first waves arrive


def irregular_errors(outdir: str) -> dict:
    """W4: at each gauge, over t ≥ IRREGULAR_FROM, the SPH surface elevation (the gauge's level less
    its mean over t ≤ STILL_UNTIL) against the linear sum of the paddle's waves at the gauge
    (:meth:`sphdvi.motion.SpectrumPaddle.elevation`; W9, the sea generated to second order, against
    the waves with their bound waves), scored as W3 scores its probes
    (:func:`sphdvi.validation.flapwaves.probe_scores`): ``<g>_corr``, ``<g>_rms`` (rms ratio − 1),
    ``<g>_lag`` (the best shift, s; positive: the SPH wave is late), ``<g>_corr_lag`` ...;
    ``corr_min``, ``rms_max`` (largest |<g>_rms|)."""
    from ..motion import SpectrumPaddle
    from .flapwaves import gauge_elevation, probe_scores
    from .runs import case_data
    spec = next(p for p in case_data(outdir)["json"]["special"]["wavepaddles"] if p["type"].endswith("_spectrum"))
    paddle = SpectrumPaddle(spec)
    out: dict = {}
    for name, x in IRREGULAR_GAUGES.items():
        t, eta = gauge_elevation(outdir, name, STILL_UNTIL)
        t_pred = t[t >= IRREGULAR_FROM]
        s = probe_scores(t, eta, t_pred, paddle.elevation(x, t_pred, order=spec.get("waveorder", 1)))
        out.update({f"{name}_{k}": v for k, v in s.items()})
    out["corr_min"] = min(out[f"{n}_corr"] for n in IRREGULAR_GAUGES)
    out["rms_max"] = max(abs(out[f"{n}_rms"]) for n in IRREGULAR_GAUGES)
    return out


AWAS_BEFORE = 5.4          # s: the end of the window (2 periods) before the wall's wave reaches WG3
AWAS_WINDOWS = 4           # windows of two periods, a period apart, at the end of the run


def _split(outdir: str, t_end: float, k: float) -> tuple[complex, complex]:
    """(incident, reflected) first-harmonic amplitudes at x = 0 over the two periods up to ``t_end``."""
    omega = 2 * math.pi / PERIOD
    xs, amps = [], []
    for name, x in GAUGES.items():
        g = gauge_table(outdir, "SWL", name)
        sel = (g[:, 0] >= t_end - WINDOW * PERIOD - 1e-9) & (g[:, 0] <= t_end + 1e-9)
        xs.append(x)
        amps.append(first_harmonic(g[sel, 0], g[sel, 3], omega))
    return incident_reflected(np.asarray(xs), np.asarray(amps), k)


def awas_gauge_distance(outdir: str) -> float | None:
    """How far in front of the piston its absorber's gauge stands (m), from the case (None: no
    absorbing piston)."""
    from ..wave_absorption import gauge_distance
    from .runs import case_data
    data = case_data(outdir)
    c = data["constants"]
    for p in data["json"]["special"].get("wavepaddles", []):
        if p.get("awas"):
            return gauge_distance(p["awas"], float(c["dp"]), float(c["h"]))
    return None


def absorption_errors(outdir: str, gauge_x: float | None = None) -> dict:
    """W5, the flume closed by a wall with an absorbing piston (``CaseWaveAwas2D_Def.xml``): the wave
    leaving the paddle before the wall's wave has come back (A0, ``H_before``) and over the last
    periods (``H_incident``, relative to H), the wave coming back (``H_returning``), and the paddle's
    reflection R = (A − A0)/B of the returning wave B (``reflection``: the mean |R| of the last
    AWAS_WINDOWS windows, ``reflection_spread`` their range) against linear theory's
    (:func:`sphdvi.wave_absorption.piston_reflection`, the gauge ``gauge_x`` in front of the piston:
    ``reflection_theory``). A piston that does not absorb reflects R = 1. ``gauge_x`` defaults to the case's."""
    from ..motion import wave_number
    from ..wave_absorption import piston_reflection
    k = wave_number(PERIOD, DEPTH)
    t_last = gauge_table(outdir, "SWL", "WG1")[-1, 0]
    a0, _ = _split(outdir, AWAS_BEFORE, k)
    refl, inc, ret = [], [], []
    for i in range(AWAS_WINDOWS):
        a, b = _split(outdir, t_last - i * PERIOD, k)
        refl.append(abs((a - a0) / b))
        inc.append(2 * abs(a) / H - 1.0)
        ret.append(2 * abs(b) / H)
    out = {"H_before": 2 * abs(a0) / H - 1.0, "H_incident": inc[0], "H_incident_max": max(inc, key=abs),
           "H_returning": ret[0], "reflection": float(np.mean(refl)),
           "reflection_spread": float(max(refl) - min(refl))}
    gauge_x = awas_gauge_distance(outdir) if gauge_x is None else gauge_x
    if gauge_x is not None:
        out["reflection_theory"] = abs(piston_reflection(k, DEPTH, 2 * math.pi / PERIOD, 9.81, gauge_x))
    return out

"""S7: linear standing wave (sloshing mode 1) in a 2D tank.

The free surface starts at η(x) = a cos(k x), k = π/L, at rest; linear theory gives the
period T = 2π/ω with ω² = g k tanh(k d). The period is read from the horizontal
centre of mass of the fluid, which oscillates with the mode.

The case file ``cases/standingwave2d/CaseStandingWave2D_Def.xml`` is the same tank drawn by
gencase; :func:`case_periods` reads a run of it. Its walls' surfaces lie dp/2 in front of
their first particle layer, so the water fills L_eff = L − dp and its mean depth is the
fluid area over L_eff: theory is evaluated for that geometry.
"""
from __future__ import annotations

import math

import numpy as np

from .runs import gauge_table


def linear_period(length: float, depth: float, g: float = 9.81, mode: int = 1) -> float:
    k = mode * math.pi / length
    return 2 * math.pi / math.sqrt(g * k * math.tanh(k * depth))


def period_from_signal(t, x, centre: float | None = None) -> tuple[float, float]:
    """Mean period from up-crossings of y = x − centre (with hysteresis: the signal must swing
    below −30 % of its amplitude between two crossings, so noise does not count), and the
    relative amplitude loss per period, 1 − exp(−λ T), λ fitted to log |y| at the signal's
    extrema (maxima and minima alike, those beyond 30 % of its amplitude).

    ``centre`` is the signal's equilibrium where it is known (the tank's middle for the
    centre of mass); else the mean of x, which is biased over a record of a few decaying
    periods that does not end on a whole period, and that bias shifts the crossings and the
    extrema alternately."""
    t, y = np.asarray(t, float), np.asarray(x, float)
    y = y - (y.mean() if centre is None else centre)
    amp = np.abs(y).max()
    if amp == 0:
        return float("nan"), float("nan")
    armed, cross = False, []
    for i in range(1, y.size):
        if y[i] < -0.3 * amp:
            armed = True
        if armed and y[i - 1] < 0 <= y[i]:
            cross.append(t[i - 1] - y[i - 1] * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))
            armed = False
    period = float(np.mean(np.diff(cross))) if len(cross) >= 2 else float("nan")
    inner = np.arange(1, y.size - 1)
    ext = inner[((y[inner] - y[inner - 1]) * (y[inner + 1] - y[inner]) <= 0) & (np.abs(y[inner]) > 0.3 * amp)
                & (np.abs(y[inner]) >= np.abs(y[inner - 1])) & (np.abs(y[inner]) >= np.abs(y[inner + 1]))]
    decay = float("nan")
    if ext.size >= 3 and np.isfinite(period):
        rate = np.polyfit(t[ext], np.log(np.abs(y[ext])), 1)[0]
        decay = float(1.0 - np.exp(rate * period))
    return period, decay


def case_periods(outdir: str, length: float = 1.0, gauge: str = "Left") -> dict:
    """Periods of a run of the S7 case file: from the horizontal centre of mass of the fluid
    at every output (``period_com``) and from the run-time elevation gauge ``gauge``
    (``period_gauge``), beside linear theory for the effective tank (``period_theory``;
    ``length_eff`` = L − dp, ``depth_eff`` = fluid area / L_eff) and the amplitude loss per
    period of the centre-of-mass signal (``decay``)."""
    import os

    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data

    case = case_data(outdir)
    dp = float(case["constants"]["dp"])
    g = -float(case["constants"]["gravity"][2])
    nfluid = int(np.count_nonzero(case["particles"]["type"] == 3))
    path = os.path.join(outdir, "particles.vtkhdf")
    times = step_times(path)
    xc = np.empty(times.size)
    for k in range(times.size):
        s = read_step(path, k)
        xc[k] = s["points"][s["Type"] == 3, 0].mean()
    length_eff = length - dp
    depth_eff = nfluid * dp * dp / length_eff
    period_com, decay = period_from_signal(times, xc, centre=0.5 * length)
    gauge_csv = gauge_table(outdir, "SWL", gauge)
    period_gauge, _ = period_from_signal(gauge_csv[:, 0], gauge_csv[:, 3])
    return {"period_theory": linear_period(length_eff, depth_eff, g), "period_com": period_com,
            "period_gauge": period_gauge, "decay": decay, "length_eff": length_eff, "depth_eff": depth_eff,
            "dp": dp}


def viscous_decay_per_period(length: float, depth: float, nu: float, g: float = 9.81,
                             no_slip_walls: bool = True) -> dict:
    """Linear-theory amplitude loss per period of sloshing mode 1 in a 2D tank of viscosity ν.

    Bulk dissipation of the potential flow decays the amplitude at 2νk² (Lamb 1932 §348);
    no-slip walls add Stokes layers, each dissipating (ρ/2)√(νω/2)|U|² per unit area and
    time (time-averaged, U the amplitude of the potential-flow slip velocity). With
    φ ∝ cos(kx) cosh k(z + d), the bottom carries |U| = Ak|sin kx| and each end wall
    |U| = Ak sinh k(z + d), Ak = aω/sinh kd; the standing wave holds E = ρ g a² L/4 per unit
    width, and the amplitude decays at P/(2E). Returns the loss per period 1 − e^(−γT) of the
    bulk, the walls (bottom and both end walls) and both together."""
    k = math.pi / length
    omega = 2 * math.pi / linear_period(length, depth, g)
    period = 2 * math.pi / omega
    gamma_bulk = 2 * nu * k * k
    gamma_walls = 0.0
    if no_slip_walls:
        stokes = math.sqrt(nu * omega / 2)
        ak2 = (omega / math.sinh(k * depth)) ** 2                     # (A k / a)^2
        area = length / 2 + 2 * (math.sinh(2 * k * depth) - 2 * k * depth) / (4 * k)
        power = 0.5 * stokes * ak2 * area                             # / (rho a^2)
        gamma_walls = power / (2 * g * length / 4)
    loss = lambda gam: 1.0 - math.exp(-gam * period)                  # noqa: E731
    return {"bulk": loss(gamma_bulk), "walls": loss(gamma_walls), "total": loss(gamma_bulk + gamma_walls)}

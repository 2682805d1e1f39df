"""Wave spectra for irregular long-crested waves (DualSPHysics ``<piston_spectrum>``/``<flap_spectrum>``).

Variance spectra S(f) [m²/Hz] in terms of the significant wave height Hs and the peak period
Tp = 1/fp (Goda 2000, "Random seas and design of maritime structures", §2.3):

* Pierson–Moskowitz (Bretschneider–Mitsuyasu form): S(f) = 5/16 Hs² fp⁴ f⁻⁵ exp(−5/4 (fp/f)⁴),
  whose integral over 0 < f < ∞ is Hs²/16 exactly;
* JONSWAP (Goda 1988): S(f) = β_J Hs² Tp⁻⁴ f⁻⁵ exp(−5/4 (Tp f)⁻⁴) γ^exp(−(Tp f − 1)²/(2σ²)),
  β_J = 0.0624/(0.230 + 0.0336 γ − 0.185/(1.9 + γ)) · (1.094 − 0.01915 ln γ), σ = 0.07 for
  f ≤ fp and 0.09 above. Goda's Hs is the height of the highest third of the waves, H1/3; the
  spectrum's own height 4 √m0 comes out 1.046 / 1.034 / 1.028 Hs for γ = 1 / 3.3 / 7.

:func:`components` splits the band FBAND·fp into N linear waves of amplitude a_i = √(2 S(f_i) Δf_i)
and seeded random phases, scaled so that the set's spectral height Hm0 = 4 √(Σ a_i²/2) is the
case's ``waveheight`` exactly (the shape from S, the height from the case).
The discretisations keep DualSPHysics's names; their definitions here are sphdvi's own (a
sphdvi series is the same sea state as DualSPHysics's, not the same realisation):

* ``regular``: N equal bins, each wave at its bin's centre;
* ``random``: N equal bins, each wave at a random frequency within its bin;
* ``stretched``: N bins of equal energy (edges at equal steps of the cumulative spectrum), so the
  waves crowd about the peak and all carry the same amplitude; each at its bin's energy centroid;
* ``cosstretched``: the bins below and above fp (their counts in proportion to the two bands'
  widths, at least one each: N ≥ 2) narrow towards fp along a quarter cosine; each wave at its
  bin's centre.
"""
from __future__ import annotations

import math

import numpy as np

SPECTRA = ("jonswap", "pierson-moskowitz")
DISCRETISATIONS = ("regular", "random", "stretched", "cosstretched")
#: the band the waves are drawn from, in units of the peak frequency: below 0.5 fp both spectra
#: hold < 1e-8 of the energy, above 3 fp about 1.5 % (Pierson–Moskowitz) and 1 % (JONSWAP, γ 3.3)
FBAND = (0.5, 3.0)


def pierson_moskowitz(f, hs: float, tp: float) -> np.ndarray:
    """S(f) [m²/Hz] of the Pierson–Moskowitz (Bretschneider) spectrum of Hs and Tp."""
    f = np.asarray(f, dtype=float)
    fp = 1.0 / tp
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        s = 5.0 / 16.0 * hs * hs * fp ** 4 * f ** -5.0 * np.exp(-1.25 * (fp / f) ** 4)
    return np.where(f > 0, s, 0.0)


def jonswap(f, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """S(f) [m²/Hz] of the JONSWAP spectrum of Hs, Tp and the peak enhancement γ (Goda 1988)."""
    f = np.asarray(f, dtype=float)
    beta = 0.0624 / (0.230 + 0.0336 * gamma - 0.185 / (1.9 + gamma)) * (1.094 - 0.01915 * math.log(gamma))
    sigma = np.where(f * tp <= 1.0, 0.07, 0.09)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        s = (beta * hs * hs * tp ** -4.0 * f ** -5.0 * np.exp(-1.25 * (tp * f) ** -4.0)
             * gamma ** np.exp(-((tp * f - 1.0) ** 2) / (2.0 * sigma * sigma)))
    return np.where(f > 0, s, 0.0)


def spectrum(kind: str, f, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """S(f) of ``kind`` (one of :data:`SPECTRA`)."""
    if kind == "jonswap":
        return jonswap(f, hs, tp, gamma)
    if kind == "pierson-moskowitz":
        return pierson_moskowitz(f, hs, tp)
    raise ValueError(f"unknown spectrum {kind!r}; expected one of {', '.join(SPECTRA)}")


def _fine_grid(fmin: float, fmax: float, s) -> tuple[np.ndarray, np.ndarray]:
    """A fine frequency grid over [fmin, fmax] and the cumulative integral of S on it."""
    f = np.linspace(fmin, fmax, 20001)
    return f, _cumulative(f, s(f))


def _cumulative(f: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The running trapezoidal integral of y over f, from 0 at f[0]."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(f))])


def _edges(how: str, n: int, fmin: float, fp: float, fmax: float, s) -> np.ndarray:
    """The n + 1 bin edges of a discretisation."""
    if how in ("regular", "random"):
        return np.linspace(fmin, fmax, n + 1)
    if how == "stretched":
        f, cum = _fine_grid(fmin, fmax, s)
        edges = np.interp(np.linspace(0.0, cum[-1], n + 1), cum, f)
        edges[0], edges[-1] = fmin, fmax
        return edges
    if how == "cosstretched":
        if n < 2:
            raise ValueError(f"the cosstretched discretization needs at least 2 waves, one on each side of fp "
                             f"(got {n})")
        n_lo = min(n - 1, max(1, round(n * (fp - fmin) / (fmax - fmin))))
        n_hi = n - n_lo
        lo = fp - (fp - fmin) * (1.0 - np.cos(0.5 * np.pi * np.arange(n_lo, -1, -1) / n_lo))
        hi = fp + (fmax - fp) * (1.0 - np.cos(0.5 * np.pi * np.arange(1, n_hi + 1) / n_hi))
        return np.concatenate([lo, hi])
    raise ValueError(f"unknown discretization {how!r}; expected one of {', '.join(DISCRETISATIONS)}")


def components(kind: str, hs: float, tp: float, n: int, discretization: str = "stretched",
               gamma: float = 3.3, seed: int = 0) -> dict:
    """The N linear waves of an irregular sea state: ``f`` [Hz], ``df`` (bin widths), ``amp``
    (a_i [m], scaled so that 4 √(Σ a_i²/2) = Hs) and ``phase`` [rad] (uniform on [0, 2π), from a
    numpy PCG64 generator seeded with ``seed``; the ``random`` discretisation draws its
    frequencies from the same generator first), ``scale``: the factor applied to √(2 S Δf)."""
    if n < 1:
        raise ValueError(f"the number of waves must be at least 1 (got {n})")
    if not (hs > 0 and tp > 0):
        raise ValueError(f"Hs ({hs}) and Tp ({tp}) must be positive")
    fp = 1.0 / tp
    fmin, fmax = FBAND[0] * fp, FBAND[1] * fp

    def s(f):
        return spectrum(kind, f, hs, tp, gamma)

    rng = np.random.Generator(np.random.PCG64(int(seed)))
    edges = _edges(discretization, n, fmin, fp, fmax, s)
    df = np.diff(edges)
    if discretization == "stretched":
        # each bin's energy from the integral of S, its wave at the bin's energy centroid
        fine, cum = _fine_grid(fmin, fmax, s)
        moment = _cumulative(fine, fine * s(fine))
        energy = np.diff(np.interp(edges, fine, cum))
        f = np.diff(np.interp(edges, fine, moment)) / energy
        raw = np.sqrt(2.0 * energy)
    else:
        f = edges[:-1] + rng.random(n) * df if discretization == "random" else 0.5 * (edges[1:] + edges[:-1])
        raw = np.sqrt(2.0 * s(f) * df)
    phase = 2.0 * np.pi * rng.random(n)
    scale = hs / spectral_height(raw)
    return {"f": f, "df": df, "amp": raw * scale, "phase": phase, "scale": scale, "band": (fmin, fmax)}


def spectral_height(amp) -> float:
    """Hm0 = 4 √m0 of a set of linear waves of amplitudes ``amp`` (m0 = Σ a²/2)."""
    amp = np.asarray(amp, dtype=float)
    return 4.0 * math.sqrt(0.5 * float(np.sum(amp * amp)))


def repetition_period(f, tmax: float, rtol: float = 1e-9) -> float | None:
    """The shortest T <= ``tmax`` after which waves of frequencies ``f`` all repeat (every f_i T a whole
    number, to ``rtol`` of a cycle), or None: their sum (the series) does not repeat within ``tmax``.
    T is a multiple of 1/(f_1 − f_0), so those are the candidates."""
    f = np.sort(np.asarray(f, dtype=float))
    if f.size == 1:
        return float(1.0 / f[0]) if 1.0 / f[0] <= tmax else None
    base = 1.0 / (f[1] - f[0])
    for m in range(1, int(tmax / base + 1e-9) + 1):
        cycles = f * (m * base)
        if np.all(np.abs(cycles - np.round(cycles)) <= rtol * np.maximum(1.0, cycles)):
            return float(m * base)
    return None


"""Relaxation zones (DualSPHysics ``<special><relaxationzones>``, JRelaxZones; Altomare et al. 2018,
"Improved relaxation zone method in SPH-based model for coastal engineering applications", Applied
Ocean Research 81, 15-33): waves made, and waves coming back absorbed, by relaxing the fluid's
velocity towards a target velocity inside a zone.

At the end of every step (after the damping zones, as DualSPHysics's ComputeStep_Ver/_Sym call
RunRelaxZone after RunDamping), each fluid particle inside a zone gets

    v ← F v_T + (1 − F) v,      F = f(s) · c · min(1, coefdt · dt)   (c · 1 with coefdt 0)

per component, v_T the target velocity, s ∈ [−1, 1] the particle's place across the zone (its
distance from the zone's centre over half its width), c the component's coefficient and

    f(s) = [tanh((s + ψ)β) − tanh((s − ψ)β) − f_sub] / f_div,
    f_sub = tanh((1 + ψ)β) − tanh((1 − ψ)β),   f_div = tanh(ψβ) − tanh(−ψβ) − f_sub,

1 at the centre and 0 at the edges (DualSPHysics's kernels, JRelaxZone_ker.cu).  coefdt · dt is held
at 1, so that a long step does not overshoot the target (DualSPHysics does not hold it).

* Wave zones (``<rzwaves_regular>``, ``<rzwaves_spectrum>``): the zone is |x − x_c| ≤ width/2 over the
  whole depth; v_T is the orbital velocity (u, w) of the waves, which run along +x from the zone's
  centre: Σ a_i ω_i [cosh k_i(z+d), −sinh k_i(z+d)]/sinh k_i d · [cos θ_i, sin θ_i], θ_i = ω_i (τ + t0) +
  φ_i − k_i (x − x_c), z measured from ``swl``, τ the time since ``start`` (:mod:`sphdvi.motion`'s
  wave theory: a regular zone is the regular paddle's wave, with Stokes's second-order term at
  ``waveorder`` 2; a spectrum zone the irregular paddle's linear sea).  A linear ramp over ``ramp``
  periods (``ramptime`` seconds) multiplies it.  ``driftcorrection`` c_d subtracts c_d times the
  waves' Stokes drift, Σ a_i² ω_i k_i cosh 2k_i(z+d) / (2 sinh² k_i d) (Dean & Dalrymple 1991 §7),
  from u, so that the zone does not pump mass into a closed flume; under the ramp the drift, of the
  waves' height squared, takes the ramp squared.  ``coefdir`` gives c for x and z (y is left).
  DualSPHysics's drift correction is a single term of the peak wave, blended by a count of the
  zone's particles; sphdvi's is the sea's own drift.
* A uniform zone (``<rzwaves_uniform>``): the particles strictly inside its box (``<point>``, ``<size>``,
  turned by ``<rotateaxis>``), s their distance from the plane through the box's centre normal to
  ``<direction>`` over half the box's extent along it; v_T = V(t) · direction (all three components,
  c = 1).

Only fluid particles are relaxed (not floating bodies' or walls').  The zones hold no state: a
resumed run relaxes as an uninterrupted one.
"""
from __future__ import annotations

import math

import numpy as np

from . import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit, prange

from .state import FLUID


def weight_constants(psi: float, beta: float) -> tuple[float, float]:
    """(f_sub, f_div) of the weight f(s) for ``<function psi beta>`` (module docstring)."""
    fsub = math.tanh((1 + psi) * beta) - math.tanh((1 - psi) * beta)
    fdiv = math.tanh(psi * beta) - math.tanh(-psi * beta) - fsub
    return fsub, fdiv


def weight(s, psi: float = 0.9, beta: float = 1.0):
    """f(s) of the module docstring (numpy): 1 at s = 0, 0 at s = ±1."""
    fsub, fdiv = weight_constants(psi, beta)
    s = np.asarray(s, float)
    return (np.tanh((s + psi) * beta) - np.tanh((s - psi) * beta) - fsub) / fdiv


def wave_theory(spec: dict, g: float = 9.81):
    """The wave a zone relaxes towards: :class:`sphdvi.motion.WavePaddle` (regular) or
    :class:`sphdvi.motion.SpectrumPaddle` (irregular) of the zone's waves, run from ``start``; its
    :meth:`elevation` and :meth:`orbital_velocity` are at a distance x in front of the zone's centre."""
    from ..motion import SpectrumPaddle, WavePaddle
    paddle = {"type": "piston" if spec["type"] == "rzwaves_regular" else "piston_spectrum", "pistondir": [1, 0, 0],
              "mkbound": None, **{k: v for k, v in spec.items() if k not in ("type", "savemotion", "saveserie",
                                                                              "saveseriewaves")}}
    paddle["waveorder"] = spec.get("waveorder", 1)
    if spec["type"] == "rzwaves_regular":
        return WavePaddle(paddle, g)
    paddle["waveorder"] = 1
    return SpectrumPaddle(paddle, g)


@njit(cache=True)
def _zone_weight(s, psi, beta, fsub, fdiv):
    return (math.tanh((s + psi) * beta) - math.tanh((s - psi) * beta) - fsub) / fdiv


@njit(cache=True, parallel=True)
def _relax_waves(pos, vel, ptype, xc, halfw, psi, beta, fsub, fdiv, cx, cz, swl, depth,
                 amp_w, wk, theta0, qd, inv_den, drift_c):
    """The wave zones' relaxation (module docstring) over every fluid particle with |x − x_c| ≤ halfw:
    components c of amplitude·ω ``amp_w``, wave number k ``wk`` and phase at x_c ``theta0``, with
    q = e^{−2kd} ``qd`` and 1/(1 − q) ``inv_den``: cosh k(z+d)/sinh kd = (e^{kz} + q e^{−kz})/(1 − q), one
    exponential a component.  The drift of the first len(drift_c) components, c_j cosh 2k(z+d)/(2 sinh² kd)
    = c_j (e^{2kz} + q² e^{−2kz})/(1 − q)², from the same exponential.  cx, cz already times the step's factor.
    Where e^{kz} underflows (k z < −745, deep below a short wave) both terms are below e^{−kd}: left out."""
    ndrift = drift_c.shape[0]
    for i in prange(pos.shape[0]):
        if ptype[i] != FLUID:
            continue
        x = pos[i, 0] - xc
        s = x / halfw
        if s < -1.0 or s > 1.0:
            continue
        f = _zone_weight(s, psi, beta, fsub, fdiv)
        z = pos[i, 2] - swl
        u = 0.0
        w = 0.0
        for c in range(wk.shape[0]):
            k = wk[c]
            ez = math.exp(k * z)
            if ez == 0.0:
                continue
            em = qd[c] / ez
            th = theta0[c] - k * x
            a = amp_w[c] * inv_den[c]
            u += a * (ez + em) * math.cos(th)
            w -= a * (ez - em) * math.sin(th)
            if c < ndrift:
                u -= drift_c[c] * (ez * ez + em * em) * inv_den[c] * inv_den[c]
        fx = f * cx
        fz = f * cz
        vel[i, 0] = fx * u + (1.0 - fx) * vel[i, 0]
        vel[i, 2] = fz * w + (1.0 - fz) * vel[i, 2]


@njit(cache=True)
def _relax_uniform(pos, vel, ptype, origin, axes, sizes, centre, normal, halfw, psi, beta, fsub, fdiv, coef, vt):
    """The uniform zone's relaxation (module docstring): particles with 0 < (r − origin)·axes_k < sizes_k."""
    for i in range(pos.shape[0]):
        if ptype[i] != FLUID:
            continue
        inside = True
        for k in range(3):
            d = ((pos[i, 0] - origin[0]) * axes[k, 0] + (pos[i, 1] - origin[1]) * axes[k, 1]
                 + (pos[i, 2] - origin[2]) * axes[k, 2])
            if not (d > 0.0 and d < sizes[k]):
                inside = False
        if not inside:
            continue
        pdis = ((pos[i, 0] - centre[0]) * normal[0] + (pos[i, 1] - centre[1]) * normal[1]
                + (pos[i, 2] - centre[2]) * normal[2])
        fc = _zone_weight(pdis / halfw, psi, beta, fsub, fdiv) * coef
        for k in range(3):
            vel[i, k] = fc * vt[k] + (1.0 - fc) * vel[i, k]


class _Zone:
    """What every zone shares: its clock (``start``, ``duration``), the weight's constants and the
    step's factor min(1, coefdt dt)."""

    def __init__(self, spec: dict, number: int):
        self.spec = spec
        self.number = number
        self.start = float(spec.get("start", 0.0))
        self.duration = float(spec.get("duration", 0.0))
        self.coefdt = float(spec.get("coefdt", 1000.0))
        self.psi, self.beta = float(spec.get("psi", 0.9)), float(spec.get("beta", 1.0))
        self.fsub, self.fdiv = weight_constants(self.psi, self.beta)

    @property
    def name(self) -> str:
        return f"<{self.spec['type']}> {self.number}"

    def clock(self, t: float):
        """τ = t − start while the zone acts (start < t, and t ≤ start + duration unless 0), else None."""
        tau = t - self.start
        if tau <= 0.0 or (self.duration > 0.0 and tau > self.duration):
            return None
        return tau

    def step_factor(self, dt: float) -> float:
        return min(1.0, self.coefdt * dt) if self.coefdt > 0 else 1.0

    def apply(self, state, t: float, dt: float) -> None:
        tau = self.clock(t)
        if tau is not None:
            self._apply(state, tau, self.step_factor(dt))

    def count_inside(self, state) -> int:
        """How many fluid particles of ``state`` the zone holds (numpy; for the start-up check)."""
        return int(np.count_nonzero(self.inside(state.pos) & (state.ptype == FLUID)))


class WaveZone(_Zone):
    """``<rzwaves_regular>`` / ``<rzwaves_spectrum>`` (module docstring)."""

    def __init__(self, spec: dict, number: int, g: float = 9.81):
        super().__init__(spec, number)
        self.theory = wave_theory(spec, g)
        self.centre = np.asarray(spec["center"], float)
        self.face = float(self.centre[0])        # the origin of <savemotion xpos> distances
        self.halfw = 0.5 * float(spec["width"])
        self.swl, self.depth = float(spec["swl"]), float(spec["depth"])
        self.coefdir = np.asarray(spec.get("coefdir", [1.0, 0.0, 0.0]), float)
        self.drift = float(spec.get("driftcorrection", 0.0))
        th = self.theory
        if spec["type"] == "rzwaves_regular":
            self.ramp_time = float(spec.get("ramp", 0.0)) * float(spec["waveperiod"])
            self.amp = np.array([0.5 * th.height])
            self.omega, self.k = np.array([th.omega]), np.array([th.k])
            self.phase, self.t0 = np.array([th.phase]), 0.0
        else:
            self.ramp_time = float(spec.get("ramptime", 0.0))
            self.amp, self.omega, self.k = th.amp, th.omega, th.k
            self.phase, self.t0 = th.phase, th.t0
        self._set_components(spec.get("waveorder", 1) == 2 and spec["type"] == "rzwaves_regular")

    def _set_components(self, bound_harmonic: bool) -> None:
        """The kernel's terms, fixed but for the ramp and the phase: a ω, k, the frequency and the phase of
        each wave (and of Stokes's bound harmonic of a second-order regular wave, as
        WavePaddle.orbital_velocity: (3/16) H² ω k cosh 2k(z+d)/sinh⁴ kd = a2 cosh K(z+d)/sinh Kd with K = 2k,
        a2 = (3/16) H² ω k · 2 cosh kd/sinh³ kd, at twice the wave's frequency and phase); the drift's
        c_d a² ω k and 2k."""
        amp_w, wk, freq, phase = self.amp * self.omega, self.k, self.omega, self.phase
        if bound_harmonic:
            from ..motion import _coth_over_sinh2
            th = self.theory
            a2 = 0.1875 * th.height ** 2 * th.omega * th.k * 2.0 * _coth_over_sinh2(th.k * th.depth)
            amp_w, wk = np.append(amp_w, a2), np.append(wk, 2.0 * th.k)
            freq, phase = np.append(freq, 2.0 * th.omega), np.append(phase, 2.0 * th.phase)
        self._amp_w, self._wk, self._freq, self._phase = amp_w, wk, freq, phase
        self._qd = np.exp(-2.0 * wk * self.depth)
        self._inv_den = 1.0 / -np.expm1(-2.0 * wk * self.depth)
        if self.drift > 0:
            self._drift_c, self._drift_k = self.drift * self.amp ** 2 * self.omega * self.k, 2.0 * self.k
        else:
            self._drift_c, self._drift_k = np.zeros(0), np.zeros(0)

    # what sphdvi.io.paddle_motion reads of a wave maker
    kind = "relaxzone"
    has_stroke = False

    def elevation(self, x, t, order: int = 1):
        return self.theory.elevation(x, t, order)

    def orbital_velocity(self, x: float, z: float, t):
        return self.theory.orbital_velocity(x, z, t)

    def ramp(self, tau: float) -> float:
        return 1.0 if self.ramp_time <= 0 or tau >= self.ramp_time else tau / self.ramp_time

    def components(self, tau: float):
        """(a ω, k, θ at the centre, drift coefficients, drift wave numbers) at τ, under the ramp (the
        drift, of the waves' height squared, under its square)."""
        r = self.ramp(tau)
        return (r * self._amp_w, self._wk, self._freq * (tau + self.t0) + self._phase, r * r * self._drift_c,
                self._drift_k)

    def _apply(self, state, tau: float, factor: float) -> None:
        amp_w, wk, theta0, drift_c, _ = self.components(tau)
        _relax_waves(state.pos, state.vel, state.ptype, float(self.centre[0]), self.halfw, self.psi, self.beta,
                     self.fsub, self.fdiv, float(self.coefdir[0] * factor), float(self.coefdir[2] * factor),
                     self.swl, self.depth, amp_w, wk, theta0, self._qd, self._inv_den, drift_c)

    def inside(self, pos: np.ndarray) -> np.ndarray:
        return np.abs(np.asarray(pos)[:, 0] - self.centre[0]) <= self.halfw


class UniformZone(_Zone):
    """``<rzwaves_uniform>`` (module docstring)."""

    def __init__(self, spec: dict, number: int):
        super().__init__(spec, number)
        from .inout import rotation_matrix
        box = spec["domainbox"]
        rot, shift = np.eye(3), np.zeros(3)
        if box.get("rotation"):
            r = box["rotation"]
            rot, shift = rotation_matrix(r["p1"], r["p2"], r["angle"])
        self.origin = rot @ np.asarray(box["point"], float) + shift
        self.axes = np.ascontiguousarray(rot.T)            # rows: the box's edges' directions
        self.sizes = np.asarray(box["size"], float)
        d = rot @ np.asarray(box["direction"], float)
        self.normal = d / np.linalg.norm(d)
        self.box_centre = self.origin + self.axes.T @ (0.5 * self.sizes)
        self.halfw = 0.5 * float(np.sum(np.abs(self.axes @ self.normal) * self.sizes))
        rows = spec.get("velocitytimes")
        self.times = np.array([r[0] for r in rows]) if rows else None
        self.values = np.array([r[1] for r in rows]) if rows else None
        self.speed = float(spec.get("velocity", 0.0))

    def velocity(self, t: float) -> float:
        """V(t): the table's, linear between rows and held beyond them, or the constant ``velocity``."""
        if self.times is None:
            return self.speed
        return float(np.interp(t, self.times, self.values))

    def _apply(self, state, tau: float, factor: float) -> None:
        vt = self.velocity(tau + self.start) * self.normal
        _relax_uniform(state.pos, state.vel, state.ptype, self.origin, self.axes, self.sizes, self.box_centre,
                       self.normal, self.halfw, self.psi, self.beta, self.fsub, self.fdiv, factor, vt)

    def inside(self, pos: np.ndarray) -> np.ndarray:
        d = (np.asarray(pos) - self.origin) @ self.axes.T
        return np.all((d > 0) & (d < self.sizes), axis=1)


def relaxation_zones(specs, g: float = 9.81) -> list:
    """The zones of ``<special><relaxationzones>`` (the reader's dicts), in the file's order."""
    out = []
    for n, spec in enumerate(specs or [], start=1):
        out.append(UniformZone(spec, n) if spec["type"] == "rzwaves_uniform" else WaveZone(spec, n, g))
    return out

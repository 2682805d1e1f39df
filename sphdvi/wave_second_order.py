"""Second-order irregular long-crested waves and their generation by a piston.

The first-order sea is N linear waves η1 = Re Σ_n A_n e^{iθ_n}, θ_n = ω_n t − k_n x (complex
amplitudes A_n = a_n e^{iφ_n}), with the potential φ1 = Re Σ_n (i g A_n/ω_n) cosh k_n(z+h)/cosh k_n h
e^{iθ_n} (z up from the still water, h the depth). Every second-order quantity of such a sea is a
bilinear form in z_n = A_n e^{iθ_n}:

    Y2 = ½ Re[ Σ_nm G⁺_nm z_n z_m + Σ_nm G⁻_nm z_n z̄_m ],

the sum-frequency (superharmonic, ω_n + ω_m) and difference-frequency (subharmonic, ω_n − ω_m)
interactions, with kernels G± that depend on the waves' frequencies and the depth only. The
kernels are built from each ordered pair of signed terms (a wave or its conjugate) of the first-order
field (Dean & Sharma 1981, "Second-order directional seas and associated wave forces", Soc. Pet.
Eng. J.; Schäffer 1996, "Second-order wavemaker theory for irregular waves", Ocean Eng. 23):

* the bound potential φ2 = Q cosh k±(z+h)/cosh k± h of the forcing of the combined free-surface
  condition φ2_tt + g φ2_z = −∂t|∇φ1|² + (φ1_t/g) ∂z(φ1_tt + g φ1_z) at z = 0, k± = k_n ± k_m,
  Q = F/(g k± tanh k± h − (ω_n ± ω_m)²);
* the bound elevation η2 = −(φ2_t + ½|∇φ1|² + η1 φ1_tz)/g at z = 0;
* a piston's second-order stroke X2, the one that leaves no free wave of frequency ω_n ± ω_m:
  - the superharmonics (ω_n + ω_m) as Madsen (1971) for regular waves, extended to pairs of
    waves (Sand & Mansard 1986): the paddle's condition φ2_x = Ẋ2 − X1 φ1_xx − φ2b_x at x = 0
    (the first-order stroke X1 times the gradient of the flow, and the bound flow that meets the
    paddle) met in the mean over the water column, Ẋ2 = mean(X1 φ1_xx + φ2b_x). One wave's
    self-interaction is Madsen's (H²/32h)(3 cosh kh/sinh³ kh − 2/m1) (tested), DualSPHysics's
    regular piston's;
  - the subharmonics (ω_n − ω_m), the long waves, by volume: the paddle delivers the bound
    field's volume flux at x = 0, h Ẋ2 = ∫ φ2b_x dz + η1 u1|z=0 (the bound long wave's current
    and the short waves' own transport), so that no free long wave carries any of it (the long-wave
    argument of Ottesen Hansen et al. 1980 and Sand 1982). Under a narrow group it is exact:
    h Ẋ2 → c_g η̄, the flux of the set-down η̄ that travels with the group (tested). Madsen's
    mean of the paddle condition taken there instead misses the part of the short waves' transport
    that the evanescent modes carry at the paddle: half of it in deep water.
  The first-order flow is taken without its evanescent modes. Schäffer (1996) keeps them, and
  projects on the free wave's profile cosh κ(z+h): his full theory is the reference these two
  approximations stand in for. DualSPHysics generates irregular waves to second order after Liu
  & Frigaard (2001) (Altomare et al. 2017); whether its kernels are these could not be checked.

The difference kernels' diagonal (zero frequency: a mean level and a mean drift of the paddle) is
left out: the paddle and the still water keep their mean.
"""
from __future__ import annotations

import numpy as np


def wave_numbers(omega, depth: float, g: float = 9.81) -> np.ndarray:
    """k of ω² = g k tanh(k h) for each ω > 0 (Newton iterations from the deep/shallow start, as
    :func:`sphdvi.motion.wave_number`), vectorised."""
    omega = np.asarray(omega, dtype=float)
    k = np.maximum(omega * omega / g, omega / np.sqrt(g * depth))
    for _ in range(100):
        t = np.tanh(k * depth)
        dk = (g * k * t - omega * omega) / (g * t + g * k * depth * (1 - t * t))
        k = k - dk
        if np.all(np.abs(dk) <= 1e-15 * k):
            break
    return k


def depth_mean(p, depth: float) -> np.ndarray:
    """The mean over the water column of cosh p(z+h)/cosh ph: tanh(|p| h)/(|p| h) (1 at p = 0)."""
    x = np.abs(np.asarray(p, dtype=float)) * depth
    small = x < 1e-8
    return np.where(small, 1.0 - x * x / 3.0, np.tanh(x) / np.where(small, 1.0, x))


def _depth_profile(k, z: float, depth: float):
    """cosh k(z+h)/cosh kh and k sinh k(z+h)/cosh kh (k of either sign), for −h ≤ z ≤ 0, without overflow."""
    k = np.asarray(k, dtype=float)
    a = np.abs(k)
    e = np.exp(a * z)                                  # e^{|k| z} ≤ 1
    q = np.exp(-2.0 * a * (z + depth))
    r = 1.0 / (1.0 + np.exp(-2.0 * a * depth))
    return e * (1.0 + q) * r, a * e * (1.0 - q) * r


def symmetric(g_sum, g_diff):
    """The kernels' parts that count: (G⁺ + G⁺ᵀ)/2 and (G⁻ + G⁻ᴴ)/2 give the same ½ Re[zᵀG⁺z + zᵀG⁻z̄]
    for every z. Near the diagonal the difference kernels' other parts grow as 1/(ω_n − ω_m) and
    cancel in pairs: left out, they cost no digits."""
    return 0.5 * (g_sum + g_sum.T), 0.5 * (g_diff + np.conj(g_diff.T))


class SecondOrderSea:
    """The second-order kernels of N linear waves of frequencies ``omega`` (rad/s) in ``depth``:
    the bound elevation's (:attr:`eta_sum`, :attr:`eta_diff`), the bound potential's amplitudes
    (:attr:`pot_sum`, :attr:`pot_diff`, of wave numbers :attr:`k_sum`, :attr:`k_diff`) and, given
    the piston's first-order transfer function ``height_to_stroke`` (H/S of each wave), its
    second-order stroke's (:attr:`paddle_sum`, :attr:`paddle_diff`). Each N×N, for unit complex
    amplitudes (see the module's docstring)."""

    def __init__(self, omega, depth: float, height_to_stroke=None, g: float = 9.81):
        self.omega = np.asarray(omega, dtype=float)
        self.depth, self.g = float(depth), float(g)
        self.k = wave_numbers(self.omega, self.depth, g)
        c1 = None if height_to_stroke is None else np.asarray(height_to_stroke, dtype=float)
        w, k = self.omega, self.k
        kernels = {}
        for name, sign in (("sum", 1.0), ("diff", -1.0)):
            wa, ka = w[:, None], k[:, None]
            wb, kb = sign * w[None, :], sign * k[None, :]
            kernels[name] = self._pair_kernels(wa, ka, wb, kb, None if c1 is None else c1[:, None],
                                               flux=sign < 0)
        for name in ("pot", "k"):
            setattr(self, f"{name}_sum", kernels["sum"][name])
            setattr(self, f"{name}_diff", kernels["diff"][name])
        for name in ("eta", "paddle"):
            pair = (kernels["sum"][name], kernels["diff"][name])
            pair = (None, None) if pair[0] is None else symmetric(*pair)
            setattr(self, f"{name}_sum", pair[0])
            setattr(self, f"{name}_diff", pair[1])

    def _pair_kernels(self, wa, ka, wb, kb, c1a, flux: bool) -> dict:
        """The kernels of the ordered pairs of unit signed terms a (ω_a, k_a) and b (ω_b, k_b): each
        term's potential amplitude P = i g/ω, velocities u = −i k P, w = P ω²/g at z = 0. The
        paddle's: Madsen's mean of the paddle condition, or with ``flux`` the bound field's
        volume flux (the subharmonics)."""
        g, h = self.g, self.depth
        shape = np.broadcast(wa, wb).shape
        wab, kab = wa + wb, ka + kb
        live = np.abs(wab) > 1e-12 * (np.abs(wa) + np.abs(wb))       # zero frequency: left out
        wab_safe = np.where(live, wab, 1.0)
        Pa, Pb = 1j * g / wa, 1j * g / wb
        ua, ub = -1j * ka * Pa, -1j * kb * Pb
        Wa, Wb = Pa * wa ** 2 / g, Pb * wb ** 2 / g
        uu = ua * ub + Wa * Wb
        forcing = -1j * wab * uu + (1j * wa / g) * Pa * Pb * (g * kb ** 2 - wb ** 4 / g)
        akab = np.abs(kab)
        resonance = g * akab * np.tanh(akab * h) - wab ** 2
        pot = np.where(live, forcing / np.where(live, resonance, 1.0), 0.0)
        eta = np.where(live, -(1j * wab * pot + 0.5 * uu + wa * wb ** 3 * Pa * Pb / g ** 2) / g, 0.0)
        out = {"eta": np.broadcast_to(eta, shape).copy(), "pot": np.broadcast_to(pot, shape).copy(),
               "k": np.broadcast_to(kab, shape).copy()}
        if c1a is not None:
            bound_flow = -1j * kab * pot * depth_mean(kab, h)
            if flux:                                                  # η1 u1 at z = 0, u1 = g k/ω there
                rate = bound_flow + g * kb / (wb * h)
            else:
                Xa = -1j * np.sign(wa) / c1a                          # X1 = Re Σ −i A/(H/S) e^{iωt}
                rate = Xa * (-kb ** 2 * Pb) * depth_mean(kb, h) + bound_flow
            out["paddle"] = np.where(live, rate / (1j * wab_safe), 0.0)
        else:
            out["paddle"] = None
        return out

    # -- evaluation --------------------------------------------------------------------------
    @staticmethod
    def bilinear(z, g_sum, g_diff):
        """½ Re[zᵀ G⁺ z + zᵀ G⁻ z̄] for z of shape (N,) or (T, N)."""
        z = np.asarray(z)
        return 0.5 * np.real(np.sum(z * (z @ g_sum.T), axis=-1) + np.sum(z * (np.conj(z) @ g_diff.T), axis=-1))

    CHUNK = 4096        # times evaluated at once: (T, N) complex arrays stay within a few MB

    @classmethod
    def _by_chunks(cls, evaluate, t):
        """``evaluate(t)`` over a long array of times in chunks (a scalar t as is)."""
        t = np.asarray(t, dtype=float)
        if t.ndim == 0 or t.size <= cls.CHUNK:
            return evaluate(t)
        parts = [evaluate(t[i:i + cls.CHUNK]) for i in range(0, t.size, cls.CHUNK)]
        if isinstance(parts[0], tuple):
            return tuple(np.concatenate(p) for p in zip(*parts))
        return np.concatenate(parts)

    def phasors(self, amplitudes, x: float, t):
        """z_n = A_n e^{i(ω_n t − k_n x)} (shape (N,) for a scalar t, (T, N) for an array)."""
        t = np.asarray(t, dtype=float)
        theta = np.multiply.outer(t, self.omega) - self.k * float(x)
        return np.asarray(amplitudes) * np.exp(1j * theta)

    def elevation(self, amplitudes, x: float, t):
        """The bound (second-order) elevation η2 of the sea of complex amplitudes A_n at x, t."""
        return self._by_chunks(lambda tt: self.bilinear(self.phasors(amplitudes, x, tt), self.eta_sum,
                                                         self.eta_diff), t)

    def velocity(self, amplitudes, x: float, z: float, t):
        """The bound flow's (u2, w2) = ∇φ2 at x, at z below the still water (−h ≤ z ≤ 0)."""
        kernels = []
        for derivative in (0, 1):
            pair = []
            for pot, k in ((self.pot_sum, self.k_sum), (self.pot_diff, self.k_diff)):
                ch, ksh = _depth_profile(k, z, self.depth)
                pair.append(pot * (-1j * k * ch if derivative == 0 else ksh))
            kernels.append(symmetric(*pair))

        def evaluate(tt):
            zn = self.phasors(amplitudes, x, tt)
            return self.bilinear(zn, *kernels[0]), self.bilinear(zn, *kernels[1])
        return self._by_chunks(evaluate, t)

    def superharmonic_stroke(self, amplitudes, t: float):
        """The piston's superharmonic stroke ½ Re[zᵀ G⁺ z] and its rate Re[żᵀ G⁺ z] (G⁺ symmetric) at
        time t (the paddle at x = 0): one matrix-vector product."""
        zn = np.asarray(amplitudes) * np.exp(1j * self.omega * float(t))
        gz = self.paddle_sum @ zn
        return 0.5 * float(np.real(zn @ gz)), float(np.real((1j * self.omega * zn) @ gz))


class SubharmonicStroke:
    """A piston's subharmonic stroke S(τ) = ½ Re Σ_nm C_nm e^{i(ω_n − ω_m)τ}, C_nm = G⁻_nm A_n Ā_m (the
    paddle's difference kernel, the waves' complex amplitudes at τ = 0), started from rest.

    The subharmonic stroke is a drift: its rate is the volume flux the waves' bound long waves carry,
    which grows as the waves' squared amplitudes. Under a linear start ramp r over T seconds its rate is
    r² Ṡ, and the stroke

        S_r(τ) = ∫_0^τ r(s)² Ṡ(s) ds = r(τ)² S(τ) − (2/T²) ∫_0^τ s S(s) ds    (τ ≤ T),
        S_r(τ) = S(τ) − (2/T²) ∫_0^T s S(s) ds                                (τ ≥ T),

    S(τ) − S(0) without a ramp: the paddle starts at rest and no free long wave is made by pushing it
    to the series' start value (multiplying S by the ramp instead moves the paddle by S(0) within the
    ramp: a spurious long wave). ∫_0^τ s e^{ibs} ds = e^{ibτ}(τ/(ib) + 1/b²) − 1/b² for each b = ω_n − ω_m
    ≠ 0, so every term is a bilinear form in u_n = e^{iω_n τ}."""

    def __init__(self, kernel, amplitudes, omega, ramp_time: float):
        omega = np.asarray(omega, dtype=float)
        a = np.asarray(amplitudes, dtype=complex)
        b = np.subtract.outer(omega, omega)
        off = b != 0
        b_safe = np.where(off, b, 1.0)
        c = np.where(off, kernel * np.outer(a, np.conj(a)), 0.0)
        self.omega, self.ramp_time = omega, float(ramp_time)
        self.c, self.c_rate = c, c * 1j * b
        self.c_lin, self.c_const = c / (1j * b_safe), c / b_safe ** 2     # ∫ s S ds = τ F1 + F2 − ΣF2(0)
        self.start = self._form(self.c, np.ones_like(omega))             # S(0)
        self.const_at_start = self._form(self.c_const, np.ones_like(omega))
        if self.ramp_time > 0:
            self.after_ramp = -2.0 / self.ramp_time ** 2 * self._moment(self.ramp_time)

    @staticmethod
    def _form(m, u) -> float:
        """½ Re[uᵀ M ū]."""
        return 0.5 * float(np.real(u @ (m @ np.conj(u))))

    def _moment(self, tau: float) -> float:
        """∫_0^τ s S(s) ds."""
        u = np.exp(1j * self.omega * tau)
        return tau * self._form(self.c_lin, u) + self._form(self.c_const, u) - self.const_at_start

    def __call__(self, tau: float):
        """(S_r(τ), its rate)."""
        u = np.exp(1j * self.omega * tau)
        value, rate = self._form(self.c, u), self._form(self.c_rate, u)
        if self.ramp_time <= 0:
            return value - self.start, rate
        if tau >= self.ramp_time:
            return value + self.after_ramp, rate
        r2 = (tau / self.ramp_time) ** 2
        return r2 * value - 2.0 / self.ramp_time ** 2 * self._moment(tau), r2 * rate

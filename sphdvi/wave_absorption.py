"""Active wave absorption at a piston wave maker: DualSPHysics's AWAS-Zsurf (``<awas_zsurf>``;
Altomare et al. 2017, Coastal Engineering 127, 37–54), after Schäffer & Klopman (2000).

A free-surface gauge rides ``gaugex`` in front of the piston's face; it reads η from the level it
measures in the still water at the start (:meth:`PistonAbsorber.calibrate`; ``swl`` is checked
against it). The piston moves with the wave
theory's stroke plus a correction whose velocity is the shallow-water absorption velocity

    u_r = sqrt(g/d) (η_target − η_measured),

η_target the elevation the paddle means to make at the gauge (first or second order), so that a wave
coming back to the paddle is taken out instead of being reflected. In linear theory a piston so driven
reflects R = (1 − G)/(1 + G) of a wave of frequency ω, G = (H/S)(kd) sqrt(g/d)/ω (Biesel's H/S): 0 in
shallow water, −6.4 % at kd = 1.07 (:func:`linear_reflection`). The correction is integrated with the
trapezoidal rule (X = X_theory + C, C' = u_r). Two safeguards, as DualSPHysics's:

* drift correction (``<correction coefstroke coefperiod powerfunc>``): once the piston is more than
  coefstroke stroke amplitudes from the theory's mean position (its rest position, or where the
  series without a ramp centres it: ``paddle.mean_position()``; a second-order irregular piston's
  deliberate subharmonic drift, ``paddle.drift_position(t)``, is not counted) it is brought back by
  that distance over coefperiod wave periods along 1 − (1 − τ/T_c)^p;
* acceleration limit (``limitace``): once AWAS runs, a step's change of the piston's mean velocity is
  held to limitace times the theoretical stroke's peak acceleration.

The absorber measures (:class:`sphdvi.sph.surface_gauge.VerticalSurfaceGauge`) and corrects once per
step, at the step's end; its state goes into restart.h5, so a resumed run continues it exactly.
"""
from __future__ import annotations

import math

import numpy as np

STATE_KEYS = ("offset", "velocity", "ur", "v_prev", "corr_start", "corr_sign", "eta", "target", "level0")


def linear_reflection(paddle_height_to_stroke: float, omega: float, g: float, depth: float) -> float:
    """The linear-theory reflection coefficient R = (1 − G)/(1 + G) of a piston absorbing with the
    shallow-water gain sqrt(g/d), its gauge at the piston: G = (H/S) sqrt(g/d)/ω (H/S Biesel's
    transfer function at ω)."""
    gain = paddle_height_to_stroke * math.sqrt(g / depth) / omega
    return (1.0 - gain) / (1.0 + gain)


def evanescent_wavenumbers(omega: float, depth: float, g: float, n: int) -> np.ndarray:
    """The first ``n`` roots k_m of ω² = −g k tan(k d), k_m d in ((m − ½)π, mπ) (bisection)."""
    out = np.empty(n)
    c = omega * omega * depth / g
    for m in range(1, n + 1):
        lo, hi = (m - 0.5) * math.pi, m * math.pi
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            if c + mid * math.tan(mid) > 0:      # c + x tan x rises from −∞ to c on the interval
                hi = mid
            else:
                lo = mid
        out[m - 1] = 0.5 * (lo + hi) / depth
    return out


def piston_reflection(k: float, depth: float, omega: float, g: float, gauge_x: float, modes: int = 400) -> complex:
    """The complex reflection coefficient of an absorbing piston in linear theory, its gauge
    ``gauge_x`` in front of it: a wave B e^{ikx} arriving leaves as R B e^{−ikx},

        R = 1 − 2 G cos θ / (1 + G e^{−iθ} + sqrt(g/d) E(x_g)),   θ = k x_g,

    G as :func:`linear_reflection`, E(x) = Σ_m (iω/g) 2 sin 2k_m d / (k_m (2k_m d + sin 2k_m d)) e^{−k_m x}
    the evanescent modes' elevation per unit piston velocity (the wavemaker problem, Dean & Dalrymple
    1991 §6.2; e^{iωt}, η in phase with the piston's velocity at x = 0). R = (1 − G e^{iθ})/(1 + G e^{−iθ})
    without them; 0 for a shallow-water wave with the gauge at the piston."""
    kd = k * depth
    progressive = (omega / g) * 2.0 * math.sinh(2 * kd) / (k * (2 * kd + math.sinh(2 * kd)))     # η/U at x = 0
    gain0 = math.sqrt(g / depth)
    km = evanescent_wavenumbers(omega, depth, g, modes)
    kmd = km * depth
    evanescent = complex(np.sum(1j * (omega / g) * 2.0 * np.sin(2 * kmd) / (km * (2 * kmd + np.sin(2 * kmd)))
                                * np.exp(-km * gauge_x)))
    theta = k * gauge_x
    gain = gain0 * progressive
    return 1.0 - 2.0 * gain * math.cos(theta) / (1.0 + gain * complex(math.cos(theta), -math.sin(theta))
                                                  + gain0 * evanescent)


def gauge_distance(opts: dict, dp: float, h: float) -> float:
    """How far in front of the piston's face its gauge stands (m): ``gaugex`` in m, h or dp (5 dp)."""
    gx = opts.get("gaugex") or {"unit": "dp", "value": 5.0}
    return float(gx["value"]) * {"m": 1.0, "h": h, "dp": dp}[gx["unit"]]


class PistonAbsorber:
    """The AWAS correction of one piston (``paddle``: a :class:`sphdvi.motion.WavePaddle` or
    ``SpectrumPaddle``, ``opts``: the case's ``awas`` dict, see :func:`sphdvi.case.wavepaddles_xml._read_awas`).
    ``face_x``: the x of the piston's front face at rest; ``zlim``: the domain's z range (the gauge's
    default); ``dp``, ``h``: the case's. After :meth:`update` at a step's end, ``offset`` and
    ``velocity`` are the correction's displacement and rate, which the paddle adds to its stroke."""

    def __init__(self, paddle, opts: dict, *, g: float, dp: float, h: float, is2d: bool, face_x: float,
                 zlim: tuple, kernel: int = 2):
        from .sph.surface_gauge import VerticalSurfaceGauge
        self.paddle = paddle
        self.depth = float(paddle.spec["depth"])
        self.gain = math.sqrt(g / self.depth)
        self.start = float(opts["startawas"])
        self.swl = float(opts["swl"])
        self.order = int(opts.get("elevation", 2))
        self.gauge_dx = gauge_distance(opts, dp, h)
        self.gauge_y = float(opts.get("gaugey", 0.0))
        zmin = max(float(opts.get("gaugezmin", zlim[0])), zlim[0])
        zmax = min(float(opts.get("gaugezmax", zlim[1])), zlim[1])
        threshold = float(opts.get("coefmasslimit") or (0.4 if is2d else 0.5))
        self.gauge = VerticalSurfaceGauge(zmin, zmax, float(opts.get("gaugedp", 0.1)) * dp, threshold, kernel, h,
                                          is2d)
        self.face_x = float(face_x)
        corr = opts.get("correction") or {}
        self.corr_limit = float(corr.get("coefstroke", 0.0)) * paddle.stroke_amplitude()
        self.corr_time = float(corr.get("coefperiod", 0.0)) * float(paddle.spec["waveperiod"])
        self.corr_power = float(corr.get("powerfunc", 1.0))
        limit = float(opts.get("limitace", 2.0))
        peak = paddle.max_acceleration()
        self.ace_max = limit * peak if limit > 0 and peak > 0 else math.inf
        self.offset = 0.0          # C: the correction's displacement (m)
        self.velocity = 0.0        # its rate over the last step (m/s)
        self.ur = 0.0              # the absorption velocity of the last step (m/s)
        self.v_prev = math.nan     # the piston's mean velocity over the last step (the limiter's)
        self.corr_start = math.nan  # the time a drift correction started (NaN: none running)
        self.corr_sign = 0.0
        self.eta = math.nan        # the last measured and target elevations at the gauge (m)
        self.target = math.nan
        self.level0 = math.nan     # the gauge's reading of the still water (:meth:`calibrate`)
        paddle.absorber = self

    # -- the gauge ---------------------------------------------------------------------------
    def gauge_x(self, t: float) -> float:
        """Where the gauge stands at time t: ``gaugex`` in front of the piston's face."""
        return self.face_x + self.paddle.theory_position(t)[0] + self.offset + self.gauge_dx

    def measure(self, state, t: float) -> float:
        """The free surface's z at the gauge in ``state`` (NaN: no surface on the line)."""
        return self.gauge.level(state, self.gauge_x(t), self.gauge_y)

    def calibrate(self, state) -> float:
        """Read the still water at the start: η is measured from this level, not from ``swl``. The
        kernel-sum surface of a particle block stands a fraction of dp off the level drawn (GenCase
        fills up to and including it, the block's edge half a dp above), and AWAS turns a bias b of
        η into a steady drift of the piston at sqrt(g/d) b (39 mm/s for the 7 mm of the W5 flume at
        dp 0.02). Returns the reading less ``swl``."""
        self.level0 = self.measure(state, 0.0)
        if not math.isfinite(self.level0):
            self.level0 = self.swl
        return self.level0 - self.swl

    # -- the correction ----------------------------------------------------------------------
    def _drift(self, tau: float) -> float:
        """The drift correction's displacement τ into it: limit · (1 − (1 − τ/T_c)^p)."""
        f = min(1.0, tau / self.corr_time) if self.corr_time > 0 else 1.0
        return self.corr_limit * (1.0 - (1.0 - f) ** self.corr_power)

    def absorbs(self, t: float, dt: float) -> bool:
        """Whether the step that ends at ``t`` corrects (it starts after ``startawas``): before it the
        gauge need not be read."""
        return t - dt > self.start

    def update(self, t: float, dt: float, surface_z: float) -> None:
        """Advance the correction over the step that ends at ``t`` (length ``dt``), ``surface_z`` the
        free surface measured at the gauge (NaN: no correction from it)."""
        x_old_theory = self.paddle.theory_position(t - dt)[0]
        x_theory = self.paddle.theory_position(t)[0]
        c_old = self.offset
        active = self.absorbs(t, dt)
        self.target = self.paddle.target_elevation(self.gauge_dx, t, self.order)
        self.eta = surface_z - (self.swl if math.isnan(self.level0) else self.level0)
        ur = 0.0
        if active and math.isfinite(self.eta):
            ur = self.gain * (self.target - self.eta)
        c_new = c_old + 0.5 * (ur + (self.ur if active else 0.0)) * dt
        self.ur = ur
        if self.corr_limit > 0:
            drift = x_theory + c_new - self.paddle.mean_position() - self.paddle.drift_position(t)
            if math.isnan(self.corr_start) and abs(drift) > self.corr_limit:
                self.corr_start = t - dt
                self.corr_sign = -1.0 if drift > 0 else 1.0
            if not math.isnan(self.corr_start):
                tau = t - dt - self.corr_start
                if tau < self.corr_time:
                    c_new += self.corr_sign * (self._drift(tau + dt) - self._drift(tau))
                else:
                    self.corr_start = math.nan
        dx = (x_theory + c_new) - (x_old_theory + c_old)
        v = dx / dt
        if active and math.isfinite(self.v_prev) and abs(v - self.v_prev) > self.ace_max * dt:
            dx = (self.v_prev + math.copysign(self.ace_max * dt, v - self.v_prev)) * dt
            c_new = x_old_theory + c_old + dx - x_theory
            v = dx / dt
        self.v_prev = v
        self.velocity = (c_new - c_old) / dt
        self.offset = c_new

    # -- restart -------------------------------------------------------------------------------
    def get_state(self) -> dict:
        return {k: float(getattr(self, k)) for k in STATE_KEYS}

    def set_state(self, state: dict) -> None:
        for k in STATE_KEYS:
            setattr(self, k, float(state[k]))


def piston_absorbers(motions, data: dict, params: dict) -> list:
    """The absorbers of the case's pistons with ``<awas_zsurf>`` (attached to their paddles in
    ``motions``, a :class:`sphdvi.motion.MotionSet`), in mkbound order; [] when none absorbs."""
    from .coupling import body_labels
    c = data["constants"]
    p = data["particles"]
    fluidcount = int(data["json"]["mkconfig"]["fluidcount"])
    labels = body_labels(p["mk"], fluidcount)
    zlim = (float(data["domain"]["posmin"][2]), float(data["domain"]["posmax"][2]))
    g = float(np.linalg.norm(c["gravity"]))
    out = []
    for mkb, paddle in sorted(motions.paddles.items()):
        opts = paddle.spec.get("awas")
        if not opts:
            continue
        mine = (labels == mkb) & (p["type"] != 3)
        if not mine.any():
            from .errors import InputError
            raise InputError(f"<awas_zsurf> of the piston mkbound={mkb}: the case has no particles of that mkbound")
        out.append(PistonAbsorber(paddle, opts, g=g, dp=float(c["dp"]), h=float(c["h"]), is2d=bool(c["is2d"]),
                                  face_x=float(p["pos"][mine, 0].max()), zlim=zlim,
                                  kernel=int(params.get("Kernel", 2) or 2)))
    return out

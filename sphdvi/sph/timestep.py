r"""Variable time step (Monaghan & Kos 1999; DualSPHysics eq. 10).

  dt_f  = min_a sqrt(h / |f_a|),
  dt_cv = h / (max(c0, 10 max_a |v_a|) + h max_{a,b} h v_ab.r_ab/(r_ab^2+eta^2) / h),
  dt    = CFL min(dt_f, dt_cv),

limited below by DtMin (0 => CoefDtMin h/c0); ``DtFixed`` > 0 replaces it.
As DualSPHysics v5.4: |f| is the interaction's acceleration without gravity
(DualSPHysics zeroes Ace in PreInteraction_Forces, adds the ``<accinputs>``
there, and adds gravity only in the update, ComputeVerletVarsFluid /
ComputeSymplecticPre / Corr) over fluid and floating particles
(JSphCpuSingle::ComputeAceMax runs from Npb on); |v| over fluid and floating
particles (all particles with DtAllParticles = 1); the viscous term over all
particles.  sphdvi's fluid ``ace`` holds gravity, so g is taken off here.
"""
import math

from . import _env  # noqa: F401
from numba import njit


@njit(cache=True, inline="always")
def force_term_ace2(ace, i, pt, gx, gy, gz):
    """|a|^2 of row i in the force condition, as DualSPHysics's ComputeAceMax: fluid (ptype 3)
    less the gravity (gx, gy, gz) its ace holds, floating (2) as it is (no gravity), -1 otherwise."""
    if pt == 3:
        return (ace[i, 0] - gx) ** 2 + (ace[i, 1] - gy) ** 2 + (ace[i, 2] - gz) ** 2
    if pt == 2:
        return ace[i, 0] ** 2 + ace[i, 1] ** 2 + ace[i, 2] ** 2
    return -1.0


@njit(cache=True, error_model="numpy")
def dt_terms(ace, vel, viscdt, ptype, vel_type=2, gx=0.0, gy=0.0, gz=0.0):
    """(max |a - g|^2 over fluid and |a|^2 over floating particles (DualSPHysics's
    ComputeAceMax: no gravity; a floating ``ace`` has none), max |v|^2 over particles
    with ptype >= vel_type (2: fluid and floating, DualSPHysics's default; 0: all,
    DtAllParticles=1), max viscdt over all).  (gx, gy, gz): the gravity in the fluid's ace."""
    amax = 0.0
    vmax = 0.0
    cmax = 0.0
    for i in range(ace.shape[0]):
        if viscdt[i] > cmax:
            cmax = viscdt[i]
        a = force_term_ace2(ace, i, ptype[i], gx, gy, gz)
        if a > amax:
            amax = a
        if ptype[i] >= vel_type:
            v = vel[i, 0] ** 2 + vel[i, 1] ** 2 + vel[i, 2] ** 2
            if v > vmax:
                vmax = v
    return amax, vmax, cmax


def dt_conditions(acemax2, velmax2, viscmax, h, cs0):
    """(dt_f, dt_cv) of eq. 10 before the CFL factor (DualSPHysics ``DtVariable``'s dt1, dt2)."""
    acemax = math.sqrt(acemax2)
    dt1 = math.sqrt(h / acemax) if acemax > 0 else math.inf
    dt2 = h / (max(cs0, 10.0 * math.sqrt(velmax2)) + h * viscmax)
    return dt1, dt2

r"""Variable time step (Monaghan & Kos 1999; DualSPHysics eq. 10).

  dt_f  = min_a sqrt(h / |f_a|),
  dt_cv = h / (max(c0, 10 max_a |v_a|) + h max_{a,b} h v_ab.r_ab/(r_ab^2+eta^2) / h),
  dt    = CFL min(dt_f, dt_cv),

limited below by DtMin (0 => CoefDtMin h/c0); ``DtFixed`` > 0 replaces it.
The maxima run over fluid particles for |f|, over fluid and floating
particles for |v| (all particles with DtAllParticles = 1) and over all
particles for the viscous term, as DualSPHysics does.
"""
import math

from . import _env  # noqa: F401
from numba import njit


@njit(cache=True, error_model="numpy")
def dt_terms(ace, vel, viscdt, ptype, vel_type=2):
    """(max |a|^2 over fluid, max |v|^2 over particles with ptype >= vel_type
    (2: fluid and floating, DualSPHysics's default; 0: all, DtAllParticles=1),
    max viscdt over all)."""
    amax = 0.0
    vmax = 0.0
    cmax = 0.0
    for i in range(ace.shape[0]):
        if viscdt[i] > cmax:
            cmax = viscdt[i]
        if ptype[i] == 3:
            a = ace[i, 0] ** 2 + ace[i, 1] ** 2 + ace[i, 2] ** 2
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

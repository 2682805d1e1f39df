r"""Sub-particle-scale (SPS) turbulence closure, Dalrymple & Rogers (2006),
in the form of DualSPHysics v5.4 (JSph::ConfigConstants2, JSphCpu::ComputeSpsTau).

With the filter length dp_sps = sqrt(2 dp^2)/2 (2D) or sqrt(3 dp^2)/3 (3D),
SpsSmag = 2/3 (C_s dp_sps)^2 and SpsBlin = 2/3 C_I dp_sps^2 (C_s = 0.12,
C_I = 0.0066), |S| = sqrt(2 S_ij S_ij) and nu = SpsSmag |S|:

    tau_ij/rho = 2 nu S_ij - nu div(u) delta_ij - SpsBlin |S|^2 delta_ij.

v5.4 moved the 2/3 of the k term into SpsSmag (sps_k = nu div u, "Factor 2/3
is included in SpsSmag constant"), so its eddy viscosity in the deviatoric
part is 2/3 that of v5.0-5.2 (SpsSmag = (C_s dp_sps)^2, sps_k = 2/3 nu div u);
the 2/3 is counted once, in SpsSmag.  The velocity gradient comes from the
interaction (layout xx, xy, xz, yy, yz, zz with the off-diagonal terms
holding du_i/dx_j + du_j/dx_i, DualSPHysics's two_strain); the result is the
SPS stress divided by rho^2 (times rho: DualSPHysics stores tau/rho), used
as sum_b m_b (tau_a + tau_b) . grad_a W_ab in the momentum equation.
"""
import math

from . import _env  # noqa: F401
from numba import njit, prange


def sps_constants(dp, is2d):
    """(SpsSmag, SpsBlin) of DualSPHysics v5.4 JSph::ConfigConstants2:
    2/3 (0.12 dp_sps)^2 and 2/3 0.0066 dp_sps^2, dp_sps^2 = dp^2/2 (2D), dp^2/3 (3D)."""
    dps2 = dp * dp / (2.0 if is2d else 3.0)
    return (2.0 / 3.0) * 0.0144 * dps2, (2.0 / 3.0) * 0.0066 * dps2


@njit(cache=True, error_model="numpy")
def _tau_range(i0, i1, gradvel, rhop, ptype, smag, blin, tau):
    for i in range(i0, i1):
        if ptype[i] != 3:
            for k in range(6):
                tau[i, k] = 0.0
            continue
        gxx = gradvel[i, 0]
        gxy = gradvel[i, 1]
        gxz = gradvel[i, 2]
        gyy = gradvel[i, 3]
        gyz = gradvel[i, 4]
        gzz = gradvel[i, 5]
        pow1 = gxx * gxx + gyy * gyy + gzz * gzz
        prr = pow1 + pow1 + gxy * gxy + gxz * gxz + gyz * gyz
        visc_sps = smag * math.sqrt(prr)
        div_u = gxx + gyy + gzz
        sps_k = visc_sps * div_u        # the 2/3 is in smag (DualSPHysics v5.4)
        sumsps = -(sps_k + blin * prr)
        two = visc_sps + visc_sps
        one_rho = 1.0 / rhop[i]
        tau[i, 0] = one_rho * (two * gxx + sumsps)
        tau[i, 1] = one_rho * (visc_sps * gxy)
        tau[i, 2] = one_rho * (visc_sps * gxz)
        tau[i, 3] = one_rho * (two * gyy + sumsps)
        tau[i, 4] = one_rho * (visc_sps * gyz)
        tau[i, 5] = one_rho * (two * gzz + sumsps)


@njit(cache=True, error_model="numpy")
def sps_tau_serial(gradvel, rhop, ptype, smag, blin, tau):
    """SPS stress of every fluid particle; smag, blin from :func:`sps_constants`."""
    _tau_range(0, rhop.shape[0], gradvel, rhop, ptype, smag, blin, tau)


@njit(cache=True, parallel=True, error_model="numpy")
def sps_tau_parallel(gradvel, rhop, ptype, smag, blin, tau):
    """Threaded :func:`sps_tau_serial`."""
    n = rhop.shape[0]
    for c in prange((n + 255) // 256):
        _tau_range(c * 256, min(n, (c + 1) * 256), gradvel, rhop, ptype, smag, blin, tau)

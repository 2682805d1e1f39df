"""SPS turbulence closure (ViscoTreatment 2): constants and stress of DualSPHysics v5.4
(JSph::ConfigConstants2, JSphCpu::ComputeSpsTau)."""
import math

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.sps import sps_constants, sps_tau_serial

from _helpers import constants, jittered_block, random_state


@pytest.mark.parametrize("is2d,smag,blin", [(True, 4.8e-7, 2.2e-7), (False, 3.2e-7, 0.0044e-4 / 3)])
def test_sps_constants_are_dualsphysics_v54(is2d, smag, blin):
    """dp 0.01: dp_sps = sqrt(2 dp^2)/2 (2D) or sqrt(3 dp^2)/3 (3D), SpsSmag = 2/3 (0.12
    dp_sps)^2, SpsBlin = 2/3 0.0066 dp_sps^2, and the solver uses them."""
    dp = 0.01
    dps = math.sqrt(2 * dp * dp) / 2 if is2d else math.sqrt(3 * dp * dp) / 3
    assert sps_constants(dp, is2d) == pytest.approx((2 / 3 * (0.12 * dps) ** 2, 2 / 3 * 0.0066 * dps ** 2),
                                                    rel=1e-14)
    assert sps_constants(dp, is2d) == pytest.approx((smag, blin), rel=1e-12)
    rng = np.random.default_rng(1)
    s = random_state(jittered_block(4, dp, is2d, rng), dp, is2d, rng)
    sol = SPHSolver(s, constants(dp, is2d), {"ViscoTreatment": 2, "Visco": 1e-6})
    assert (sol.sps_smag, sol.sps_blin) == pytest.approx((smag, blin), rel=1e-12)


def test_sps_tau_counts_two_thirds_once():
    """tau/rho = 2 nu S - nu div(u) I - SpsBlin |S|^2 I with nu = SpsSmag |S|, |S|^2 =
    2 S:S, the 2/3 of the k term inside SpsSmag (v5.4), in textbook form from the
    velocity gradient; only fluid particles (type 3) get a stress."""
    rng = np.random.default_rng(4)
    n = 7
    L = rng.normal(0.0, 3.0, (n, 3, 3))          # L[i, j] = du_i/dx_j
    grad = np.zeros((n, 6))
    comp = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
    for k, (i, j) in enumerate(comp):
        grad[:, k] = L[:, i, i] if i == j else L[:, i, j] + L[:, j, i]
    rho = 1000.0 + rng.uniform(-5, 5, n)
    ptype = np.array([3, 3, 3, 0, 3, 2, 3], np.int8)
    smag, blin = sps_constants(0.01, False)
    tau = np.full((n, 6), 99.0)
    sps_tau_serial(grad, rho, ptype, smag, blin, tau)
    for a in range(n):
        S = 0.5 * (L[a] + L[a].T)
        mod2 = 2.0 * np.sum(S * S)
        nu = smag * math.sqrt(mod2)
        ref = (2 * nu * S - nu * np.trace(S) * np.eye(3) - blin * mod2 * np.eye(3)) / rho[a]
        want = [ref[i, j] for i, j in comp] if ptype[a] == 3 else [0.0] * 6
        np.testing.assert_allclose(tau[a], want, rtol=1e-12, atol=1e-12 * np.abs(ref).max())

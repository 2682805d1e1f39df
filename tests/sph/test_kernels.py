"""Kernel normalisation and gradient against numerical integration."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from sphdvi.sph.kernels import kernel_alpha, kernel_fac, kernel_w

H = 0.013


@pytest.mark.parametrize("kind", [1, 2])
@pytest.mark.parametrize("is2d", [True, False])
def test_kernel_normalisation(kind, is2d):
    """int W dV = 1 over the support (radial quadrature, 2 pi r dr or 4 pi r^2 dr)."""
    a = kernel_alpha(kind, H, is2d)
    jac = (lambda r: 2 * math.pi * r) if is2d else (lambda r: 4 * math.pi * r * r)
    total, _ = quad(lambda r: kernel_w(kind, r / H, a) * jac(r), 0.0, 2 * H, points=[H],
                    epsabs=1e-13)
    assert abs(total - 1.0) < 1e-10


@pytest.mark.parametrize("kind", [1, 2])
@pytest.mark.parametrize("is2d", [True, False])
def test_kernel_gradient(kind, is2d):
    """fac*r equals dW/dr (central differences) and int x dW/dx dV = -1."""
    a = kernel_alpha(kind, H, is2d)
    ah2 = a / H ** 2
    for q in np.linspace(0.05, 1.95, 39):
        r = q * H
        eps = 1e-7 * H
        num = (kernel_w(kind, (r + eps) / H, a) - kernel_w(kind, (r - eps) / H, a)) / (2 * eps)
        ana = kernel_fac(kind, q, ah2) * r
        assert abs(num - ana) <= 1e-6 * abs(ana) + 1e-9 * a / H
    # int x dW/dx dV = -int W dV = -1 ; angular factor pi (2D) or 4 pi/3 (3D)
    ang, pw = (math.pi, 2) if is2d else (4 * math.pi / 3, 3)
    val, _ = quad(lambda r: kernel_fac(kind, r / H, ah2) * r * r ** pw, 1e-12, 2 * H, points=[H], epsabs=1e-13)
    assert abs(ang * val + 1.0) < 1e-10


@pytest.mark.parametrize("kind", [1, 2])
def test_kernel_lattice_sum_2d(kind):
    """Sum over a square dp lattice of dp^2 W ~ 1 for h = sqrt(2) dp (discrete check)."""
    dp = 0.01
    h = math.sqrt(2) * dp
    a = kernel_alpha(kind, h, True)
    g = np.arange(-4, 5) * dp
    X, Z = np.meshgrid(g, g)
    q = np.hypot(X, Z).ravel() / h
    s = sum(kernel_w(kind, qq, a) for qq in q) * dp * dp
    assert abs(s - 1.0) < 0.02

"""SPH smoothing kernels in the DualSPHysics form.

Both kernels have support 2h.  ``fac`` is (dW/dr)/r, so that the kernel
gradient is ``fac * r_ab`` (r_ab = r_a - r_b), as in DualSPHysics.

* Cubic spline (Monaghan & Lattanzio 1985), ``Kernel=1``:
  W = a (1 - 3/2 q^2 + 3/4 q^3) for q < 1, a/4 (2 - q)^3 for 1 <= q < 2,
  a = 10/(7 pi h^2) in 2D, 1/(pi h^3) in 3D.
* Wendland quintic C2 (Wendland 1995), ``Kernel=2``:
  W = a (1 - q/2)^4 (2q + 1), a = 7/(4 pi h^2) in 2D, 21/(16 pi h^3) in 3D.
"""
import math

from . import _env  # noqa: F401
from numba import njit

KERNEL_CUBIC = 1
KERNEL_WENDLAND = 2


def kernel_alpha(kind, h, is2d):
    """Normalisation constant alpha_D of the kernel."""
    if kind == KERNEL_CUBIC:
        return 10.0 / (7.0 * math.pi * h * h) if is2d else 1.0 / (math.pi * h ** 3)
    if kind == KERNEL_WENDLAND:
        return 7.0 / (4.0 * math.pi * h * h) if is2d else 21.0 / (16.0 * math.pi * h ** 3)
    raise ValueError("Kernel must be 1 (cubic) or 2 (Wendland), got %r" % (kind,))


@njit(cache=True, error_model="numpy")
def kernel_w(kind, q, alpha):
    """Kernel value W(q) (q = r/h); zero for q >= 2."""
    if q >= 2.0:
        return 0.0
    if kind == 1:
        if q < 1.0:
            return alpha * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
        t = 2.0 - q
        return alpha * 0.25 * t * t * t
    t = 1.0 - 0.5 * q
    t2 = t * t
    return alpha * t2 * t2 * (2.0 * q + 1.0)


@njit(cache=True, error_model="numpy")
def kernel_fac(kind, q, alpha_h2):
    """(dW/dr)/r for 0 < q < 2, with ``alpha_h2 = alpha/h^2``."""
    if kind == 1:
        if q < 1.0:
            return alpha_h2 * (-3.0 + 2.25 * q)
        t = 2.0 - q
        return alpha_h2 * (-0.75 * t * t / q)
    t = 1.0 - 0.5 * q
    return alpha_h2 * (-5.0) * t * t * t

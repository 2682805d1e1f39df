"""Small dense solves inside numba kernels (kernel-correction moment matrices)."""
from . import _env  # noqa: F401
from numba import njit


@njit(cache=True, error_model="numpy")
def solve_pivoted(a, b, n, m, tol):
    """Solve a[:n,:n] X = b[:n,:m] in place by Gaussian elimination with
    partial pivoting; returns |det a|, or 0.0 (X undefined) when a pivot is
    not above ``tol`` in magnitude."""
    det = 1.0
    for k in range(n):
        p = k
        for r in range(k + 1, n):
            if abs(a[r, k]) > abs(a[p, k]):
                p = r
        if abs(a[p, k]) <= tol:
            return 0.0
        if p != k:
            for c in range(n):
                t = a[k, c]
                a[k, c] = a[p, c]
                a[p, c] = t
            for c in range(m):
                t = b[k, c]
                b[k, c] = b[p, c]
                b[p, c] = t
        det *= a[k, k]
        for r in range(k + 1, n):
            f = a[r, k] / a[k, k]
            for c in range(k, n):
                a[r, c] -= f * a[k, c]
            for c in range(m):
                b[r, c] -= f * b[k, c]
    for k in range(n - 1, -1, -1):
        for c in range(m):
            s = b[k, c]
            for q in range(k + 1, n):
                s -= a[k, q] * b[q, c]
            b[k, c] = s / a[k, k]
    return abs(det)

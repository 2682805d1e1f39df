"""Kernel interpolation at points (Shepard and first-order MLS), 2D and 3D."""
import numpy as np
import pytest

from sphdvi.measure.core import KernelSpec, fluid_grid, interpolate, kernel_sum, nearest_particle_distance


def block(is2d, dp=0.01, n=20, jitter=0.0, seed=0):
    """A block of fluid particles on a cell-centred lattice (optionally jittered)."""
    ax = np.arange(n) * dp + dp / 2
    if is2d:
        x, z = np.meshgrid(ax, ax, indexing="ij")
        pos = np.stack([x.ravel(), np.zeros(x.size), z.ravel()], axis=1)
    else:
        x, y, z = np.meshgrid(ax, ax, ax, indexing="ij")
        pos = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    rng = np.random.default_rng(seed)
    pos = pos + jitter * dp * rng.uniform(-1, 1, pos.shape)
    if is2d:
        pos[:, 1] = 0.0
    return pos


def linear(p):
    return np.stack([1.0 + 2.0 * p[:, 0] - 3.0 * p[:, 2], 0.5 + p[:, 1], 4.0 * p[:, 2] - p[:, 0]], axis=1)


def make_grid(pos, is2d, kernel=2, dp=0.01):
    h = np.sqrt((2 if is2d else 3) * dp * dp)
    spec = KernelSpec(kernel, h, dp, is2d)
    n = pos.shape[0]
    rho = np.full(n, 1000.0) * (1 + 0.01 * np.sin(50 * pos[:, 0]))     # non-uniform volumes
    mass = 1000.0 * dp ** (2 if is2d else 3) * np.ones(n)
    press = 100.0 * pos[:, 2]
    return spec, fluid_grid(pos, linear(pos), rho, mass, press, np.full(n, 3), spec)


def interior_points(is2d, rng, k=20, lo=0.06, hi=0.14):
    p = rng.uniform(lo, hi, (k, 3))
    if is2d:
        p[:, 1] = 0.0
    return p


@pytest.mark.parametrize("is2d", [True, False])
@pytest.mark.parametrize("kernel", [1, 2])
def test_linear_field_exact_with_linear_correction(is2d, kernel):
    """First-order correction: linear fields reproduced to round-off at arbitrary interior
    points of a jittered particle set (max error ~1e-15 measured)."""
    pos = block(is2d, jitter=0.2)
    spec, g = make_grid(pos, is2d, kernel)
    pts = interior_points(is2d, np.random.default_rng(1))
    vals, ks = interpolate(g, pts, ("vel",), order=1)
    assert np.all(ks > 0.8)
    np.testing.assert_allclose(vals, linear(pts), rtol=0, atol=1e-12)


@pytest.mark.parametrize("is2d", [True, False])
def test_shepard_exact_on_symmetric_lattice_points(is2d):
    """Shepard normalisation: constant fields exact everywhere; linear fields exact where
    the kernel-weighted centroid is the point (lattice nodes, cell corners) of a regular
    lattice; elsewhere the error is first order (about 1e-4 of the field range here)."""
    dp = 0.01
    pos = block(is2d)
    h = np.sqrt((2 if is2d else 3) * dp * dp)
    spec = KernelSpec(2, h, dp, is2d)
    n = pos.shape[0]
    g = fluid_grid(pos, linear(pos), np.full(n, 1000.0), np.full(n, 1000.0 * dp ** (2 if is2d else 3)),
                   np.full(n, 7.0), np.full(n, 3), spec)
    sym = np.array([[0.1, 0.1, 0.1], [0.105, 0.105, 0.105], [0.1, 0.105, 0.095]])
    if is2d:
        sym[:, 1] = 0.0
    vals, _ = interpolate(g, sym, ("vel", "press"))
    np.testing.assert_allclose(vals[:, :3], linear(sym), rtol=0, atol=1e-13)
    np.testing.assert_allclose(vals[:, 3], 7.0, rtol=0, atol=1e-12)
    pts = interior_points(is2d, np.random.default_rng(2))
    vals, _ = interpolate(g, pts, ("vel",))
    assert np.abs(vals - linear(pts)).max() < 2e-4


@pytest.mark.parametrize("is2d", [True, False])
def test_kclimit_and_far_points(is2d):
    pos = block(is2d)
    spec, g = make_grid(pos, is2d)
    far = np.array([[5.0, 0.0, 5.0], [-3.0, 0.0, 0.1], [0.1, 0.0, 0.2 + 0.5 * spec.h]])
    vals, ks = interpolate(g, far, ("vel", "rhop"))
    assert ks[0] == 0 and ks[1] == 0 and 0 < ks[2] < 0.5
    assert np.isnan(vals).all()
    vals, ks2 = interpolate(g, far, ("vel",), kclimit=None)
    assert np.isfinite(vals[2]).all() and ks2[2] == ks[2]
    assert kernel_sum(g, far)[2] == ks[2]


def test_nearest_distance():
    pos = block(False, n=4)
    spec = KernelSpec(2, 0.017, 0.01, False)
    d = nearest_particle_distance(np.array([[0.005, 0.005, 0.005], [0.005, 0.005, 0.045], [1, 1, 1]]), pos,
                                  spec, 1.5 * spec.h)
    np.testing.assert_allclose(d[:2], [0.0, 0.01], atol=1e-15)
    assert d[2] == 1.5 * spec.h

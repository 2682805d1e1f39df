"""The flexible-structure solid (sphdvi.sph.flexstruc) against closed forms: the deformation
gradient of a linear map, the stresses of a stretch and a shear, no force under a rigid motion,
momentum conservation, the sound speed."""
import math

import numpy as np
import pytest

from sphdvi.sph.flexstruc import FlexStruc, constitutive_coefficients, sound_speed

DP = 0.01
E, NU, RHO = 1.4e6, 0.4, 1000.0


def lattice(nx, nz, ny=1, dp=DP):
    """A block of nx x ny x nz particles (2D when ny == 1), all mk 1, moving boundary."""
    xs = np.arange(nx) * dp
    ys = np.arange(ny) * dp if ny > 1 else np.zeros(1)
    zs = np.arange(nz) * dp
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    pos = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    n = pos.shape[0]
    return pos, np.arange(n), np.ones(n, int), np.ones(n, np.int8)


def body(model=1, hg=0.0):
    return {"mkbound": 1, "mkclamp": [0], "density": RHO, "youngmod": E, "poissratio": NU,
            "constitmodel": model, "hgfactor": hg}


def make(pos, idp, mk, ptype, model=1, hg=0.0, is2d=True, coefh=1.0):
    h = coefh * math.sqrt(2.0 if is2d else 3.0) * DP
    return FlexStruc([body(model, hg)], pos, idp, mk, ptype, is2d=is2d, h=h, dp=DP, kernel=2)


def evaluate(fs, pos, idp):
    ace = np.zeros_like(pos)
    pos = np.ascontiguousarray(pos)
    fs.geometry(pos, idp)
    fs.forces(pos, ace)
    return ace


@pytest.mark.parametrize("is2d", [True, False])
def test_deformation_gradient_of_a_linear_map_is_exact_everywhere(is2d):
    """x = A X: the corrected gradient gives F = A at every particle, edges and corners included;
    F = I in the reference configuration."""
    pos, idp, mk, pt = lattice(8, 6) if is2d else lattice(5, 4, 4)
    fs = make(pos, idp, mk, pt, model=1 if is2d else 3, is2d=is2d)
    evaluate(fs, pos, idp)
    assert np.abs(fs.F - np.eye(3)).max() < 1e-12
    A = np.array([[1.02, 0.0, 0.03], [0.0, 1.0, 0.0], [-0.01, 0.0, 0.97]])
    if not is2d:
        A[0, 1], A[1, 0], A[1, 1], A[1, 2], A[2, 1] = 0.01, 0.02, 1.01, -0.02, 0.015
    evaluate(fs, pos @ A.T, idp)
    assert np.abs(fs.F - A).max() < 1e-12


@pytest.mark.parametrize("is2d", [True, False])
def test_rigid_rotation_and_translation_give_no_stress_and_no_force(is2d):
    pos, idp, mk, pt = lattice(8, 5) if is2d else lattice(5, 4, 4)
    fs = make(pos, idp, mk, pt, model=1 if is2d else 3, hg=0.1, is2d=is2d)
    a = math.radians(30.0)
    if is2d:
        R = np.array([[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]])
    else:
        c, s = math.cos(a), math.sin(a)
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    moved = pos @ R.T + np.array([0.3, 0.0 if is2d else -0.2, 0.1])
    ace = evaluate(fs, moved, idp)
    assert np.abs(fs.F - R).max() < 1e-12
    assert np.abs(fs.PL).max() < 1e-6 * E          # round-off of E ~ 1e-16 times E
    # a strain of 1e-12 would give E/(rho dp) 1e-12 = 1.4e-7 m/s^2: this is round-off
    assert np.abs(ace).max() < 1e-12 * E / (RHO * DP)


def _pk1(fs):
    """P = (P L) L^-1 of every particle."""
    return np.einsum("kab,kbc->kac", fs.PL, np.linalg.inv(fs.L))


@pytest.mark.parametrize("model", [1, 2])
def test_uniaxial_stretch_stress(model):
    """x = X + eps X e_x: E_xx = eps + eps^2/2; plane strain S_xx = (lambda + 2 mu) E_xx,
    S_zz = lambda E_xx; plane stress S_xx = E/(1 - nu^2) E_xx, S_zz = nu E/(1 - nu^2) E_xx; P = F S."""
    pos, idp, mk, pt = lattice(9, 5)
    fs = make(pos, idp, mk, pt, model=model)
    for eps in (0.01, 0.1):
        moved = pos.copy()
        moved[:, 0] *= 1.0 + eps
        evaluate(fs, moved, idp)
        exx = eps + 0.5 * eps * eps
        if model == 1:
            lam = E * NU / ((1 + NU) * (1 - 2 * NU))
            mu = E / (2 * (1 + NU))
            sxx, szz = (lam + 2 * mu) * exx, lam * exx
        else:
            sxx, szz = E / (1 - NU ** 2) * exx, NU * E / (1 - NU ** 2) * exx
        P = _pk1(fs)
        assert np.allclose(P[:, 0, 0], (1 + eps) * sxx, rtol=1e-10)
        assert np.allclose(P[:, 2, 2], szz, rtol=1e-10)
        assert np.abs(P[:, 0, 2]).max() < 1e-8 * sxx and np.abs(P[:, 2, 0]).max() < 1e-8 * sxx


def test_simple_shear_stress_has_the_shear_modulus():
    """x = X + gamma Z e_x: S_xz = mu gamma (engineering shear; not 2 mu), E_zz = gamma^2/2."""
    pos, idp, mk, pt = lattice(9, 6)
    fs = make(pos, idp, mk, pt, model=1)
    g = 0.01
    moved = pos.copy()
    moved[:, 0] += g * pos[:, 2]
    evaluate(fs, moved, idp)
    mu = E / (2 * (1 + NU))
    lam = E * NU / ((1 + NU) * (1 - 2 * NU))
    F = np.array([[1, 0, g], [0, 1, 0], [0, 0, 1.0]])
    S = np.array([[lam * g * g / 2, 0, mu * g], [0, 0, 0], [mu * g, 0, (lam + 2 * mu) * g * g / 2]])
    assert np.allclose(_pk1(fs), F @ S, rtol=0, atol=1e-9 * mu * g)


@pytest.mark.parametrize("is2d", [True, False])
def test_internal_forces_conserve_momentum(is2d):
    """A free body, randomly deformed: the elastic and hourglass forces sum to zero."""
    pos, idp, mk, pt = lattice(10, 6) if is2d else lattice(6, 4, 5)
    fs = make(pos, idp, mk, pt, model=1 if is2d else 3, hg=0.1, is2d=is2d)
    rng = np.random.default_rng(3)
    moved = pos + rng.normal(0, 0.05 * DP, pos.shape) * (np.array([1, 0, 1]) if is2d else 1)
    ace = evaluate(fs, moved, idp)
    m = RHO * fs.vol
    assert np.abs(ace).max() > 1.0
    assert np.abs((m * ace).sum(axis=0)).max() < 1e-11 * m * np.abs(ace).sum()


def test_constitutive_coefficients_and_sound_speed():
    d, o, s = constitutive_coefficients(1, E, NU)
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    assert (d, o, s) == pytest.approx((lam + 2 * mu, lam, mu), rel=1e-14)
    assert constitutive_coefficients(2, E, NU) == pytest.approx((E / (1 - NU ** 2), NU * E / (1 - NU ** 2), mu),
                                                                rel=1e-14)
    assert sound_speed(E, NU, RHO) == pytest.approx(54.772, rel=1e-4)     # CSM3's material


def test_clamp_particles_within_2h_and_reference_pairs_per_body():
    """Clamp particles: the clamp mk's particles within 2h of the body; a second body beside the
    first is not paired with it."""
    pos, idp, mk, pt = lattice(12, 4)
    mk[pos[:, 0] < 2.5 * DP] = 0           # three columns of clamp mk
    pt[mk == 0] = 0
    mk[pos[:, 0] > 7.5 * DP] = 2           # a second body
    h = math.sqrt(2.0) * DP
    b2 = dict(body(), mkbound=2, mkclamp=[0])
    fs = FlexStruc([body(), b2], pos, idp, mk, pt, is2d=True, h=h, dp=DP, kernel=2)
    # clamp: the columns of mk 0 within 2h = 2.83 dp of a body-1 particle (x = 3 dp on): x = 1, 2 dp
    clamp_idp = fs.idp[fs.clamp]
    assert set(np.round(pos[clamp_idp, 0] / DP).astype(int)) == {1, 2}
    for k in range(fs.size):
        nbrs = fs.pj[fs.pstart[k]:fs.pstart[k + 1]]
        assert np.all(fs.body[nbrs] == fs.body[k])


def test_a_line_of_particles_is_refused():
    pos, idp, mk, pt = lattice(10, 1)
    with pytest.raises(ValueError, match="too few neighbours"):
        make(pos, idp, mk, pt)

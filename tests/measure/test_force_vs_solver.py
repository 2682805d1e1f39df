"""`measure forces` uses the solver's momentum equation: on floating particles it equals
m_a * ace_a of SPHSolver (fluid force, no gravity) to round-off."""
import math

import numpy as np
import pytest

from sphdvi.measure.core import KernelSpec, fluid_grid, fluid_forces
from sphdvi.sph.solver import SPHSolver
from sphdvi.sph.state import FluidState


def scene(is2d, rng, dp=0.02, n=14):
    g = np.arange(n) * dp
    if is2d:
        x, z = np.meshgrid(g, g, indexing="ij")
        pos = np.stack([x.ravel(), np.zeros(x.size), z.ravel()], axis=1)
    else:
        x, y, z = np.meshgrid(g[:8], g[:8], g[:8], indexing="ij")
        pos = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    pos = pos + rng.uniform(-0.1, 0.1, pos.shape) * dp
    if is2d:
        pos[:, 1] = 0.0
    npart = pos.shape[0]
    centre = pos.mean(axis=0)
    floating = np.linalg.norm(pos - centre, axis=1) < 3.1 * dp          # a disc / ball of floating particles
    ptype = np.where(floating, 2, 3).astype(np.int8)
    vel = rng.normal(0, 0.3, (npart, 3))
    if is2d:
        vel[:, 1] = 0.0
    rho = 1000.0 + rng.uniform(-3, 3, npart)
    mass = 1000.0 * dp ** (2 if is2d else 3) * rng.uniform(0.95, 1.05, npart)
    return FluidState(pos, vel, rho, mass, ptype)


@pytest.mark.parametrize("is2d,kernel,visco", [(True, 2, 1), (True, 1, 3), (False, 1, 1), (False, 2, 3)])
def test_force_equals_solver_ace(is2d, kernel, visco):
    """Wendland/cubic (tensile correction), artificial/laminar viscosity, 2D and 3D.  Per particle
    with RigidAlgorithm 0 (floating particles see the fluid only); with 1, the default, they also
    feel each other (DualSPHysics's FtMode Sph), pair forces that cancel in the body's force, and
    with the artificial viscosity (central pair forces) in its moment too: those then equal the
    fluid's (the laminar term's pair forces lie along v_ab and leave a moment, as in DualSPHysics)."""
    rng = np.random.default_rng(7)
    state = scene(is2d, rng)
    dp = 0.02
    h = math.sqrt(2.0 if is2d else 3.0) * dp
    cs0 = 10.0
    consts = {"dp": dp, "h": h, "cs0": cs0, "rhop0": 1000.0, "gamma": 7.0, "b": cs0 ** 2 * 1000.0 / 7.0,
              "gravity": [0.0, 0.0, -9.81], "is2d": is2d, "cflnumber": 0.2}
    params = {"Kernel": kernel, "ViscoTreatment": visco, "Visco": 0.05 if visco == 1 else 1e-3,
              "ViscoBoundFactor": 1.0, "DensityDT": 0, "RigidAlgorithm": 0}
    sph1 = SPHSolver(state.copy(), consts, dict(params, RigidAlgorithm=1))
    sol = SPHSolver(state, consts, params)
    sol.compute_rates()
    s = sol.state
    fl = s.ptype == 2
    expected = s.mass[fl, None] * sol.ace[fl]
    spec = KernelSpec(kernel, h, dp, is2d, cs0=cs0, rhop0=1000.0, b=consts["b"], gamma=7.0, visco_kind=visco,
                      visco_bound=params["Visco"])
    grid = fluid_grid(s.pos, s.vel, s.rhop, s.mass, sol.press, s.ptype, spec)
    got = fluid_forces(grid, s.pos[fl], s.vel[fl], s.rhop[fl], sol.press[fl], s.mass[fl], spec)
    scale = np.abs(expected).max()
    assert scale > 0
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * scale)
    sph1.compute_rates()
    s1 = sph1.state
    fl1 = s1.ptype == 2
    f1 = s1.mass[fl1, None] * sph1.ace[fl1]
    c = s.pos[fl].mean(axis=0)
    np.testing.assert_allclose(f1.sum(axis=0), got.sum(axis=0), rtol=0, atol=1e-10 * scale)
    if visco == 1:
        np.testing.assert_allclose(np.cross(s1.pos[fl1] - c, f1).sum(axis=0),
                                   np.cross(s.pos[fl] - c, got).sum(axis=0), rtol=0, atol=1e-10 * scale * dp)

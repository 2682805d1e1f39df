"""Weakly-compressible SPH solver (DualSPHysics formulation), arrays in, arrays out.

Importing this package does not import numba; the solver modules are loaded
on first use of :class:`SPHSolver`::

    from sphdvi.sph import FluidState, SPHSolver
    state = FluidState(pos, vel, rhop, mass, ptype, idp, mk)   # (N,3)/(N,) arrays
    solver = SPHSolver(state, constants, params)               # plain dicts
    dt = solver.step()                 # one time step; solver.time, solver.nstep
    solver.ace, solver.ar, solver.press                         # last rates, pressure

Modules: ``state`` (FluidState), ``kernels`` (cubic spline, Wendland),
``cells`` (counting-sort cell lists), ``interaction`` (fused gather-form
momentum/continuity/DDT/viscosity/shifting kernels, 2D and 3D), ``sps``
(Smagorinsky SPS stresses), ``integrators`` (Verlet, Symplectic),
``timestep`` (variable dt), ``periodic`` (ghost copies), ``mdbc`` (mDBC
boundary densities), ``exclusion`` (masks and counts of excluded
particles), ``scenes`` (simple tanks for tests and benchmarks), ``solver``.
"""
from .state import FluidState, FIXED, MOVING, FLOATING, FLUID  # numpy only

__all__ = ["FluidState", "SPHSolver", "DEFAULT_PARAMS", "FIXED", "MOVING", "FLOATING", "FLUID"]


def __getattr__(name):
    if name in ("SPHSolver", "DEFAULT_PARAMS", "resolve_params"):
        from . import solver
        return getattr(solver, name)
    raise AttributeError(name)

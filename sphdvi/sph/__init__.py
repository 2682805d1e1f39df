"""Weakly-compressible SPH solver (DualSPHysics formulation), arrays in, arrays out.

Importing this package does not import numba; the solver modules are loaded
on first use of :class:`SPHSolver` and friends::

    from sphdvi.sph import FluidState, SPHSolver
    solver = SPHSolver(state, constants, params)
    dt = solver.step()
"""
from .state import FluidState, FIXED, MOVING, FLOATING, FLUID  # numpy only

__all__ = ["FluidState", "SPHSolver", "DEFAULT_PARAMS", "FIXED", "MOVING", "FLOATING", "FLUID"]


def __getattr__(name):
    if name in ("SPHSolver", "DEFAULT_PARAMS", "resolve_params"):
        from . import solver
        return getattr(solver, name)
    raise AttributeError(name)

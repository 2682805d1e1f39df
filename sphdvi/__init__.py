"""sphdvi: weakly-compressible SPH coupled to a DVI multibody solver.

Importing the package is cheap: numba, h5py and vtk are imported only by the
modules that need them.
"""
from ._version import __version__

__all__ = ["__version__"]

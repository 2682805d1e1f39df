"""Environment set-up done before numba is imported by the SPH kernels.

``OMP_WAIT_POLICY=PASSIVE`` keeps numba's OpenMP layer from spinning on shared
2-core machines (conventions.md §6.4).  The user can still override it.
"""
import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

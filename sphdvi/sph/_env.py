"""Environment set-up done before numba is imported by the SPH kernels, and the threads' work item.

``OMP_WAIT_POLICY=PASSIVE`` keeps numba's OpenMP layer from spinning on shared
2-core machines (conventions.md §6.4).  The user can still override it.

``CHUNK``: particles per work item of every threaded per-particle kernel of a step (cell
indices, packing, interaction, integrators).  The static schedule splits a prange's items
evenly between the threads, so with one item size each thread gets the same rows in every
kernel: the rows it packs are the ones it interacts and then integrates.  The kernels read it
at compile time and numba's cache keys on each kernel's own file: after changing it, clear
the cache (NUMBA_CACHE_DIR, or the __pycache__ folders).
"""
import os

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

CHUNK = 128

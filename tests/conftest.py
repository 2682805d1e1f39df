import os
import sys
from pathlib import Path

import pytest

from sphdvi.simulation import default_threads     # imports no numba

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
if int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1")) > 1:
    # a worker of ``-n auto`` (pyproject addopts): its share of the CPUs, and at least 2 for the
    # threaded-vs-serial tests; set before numba is imported (NUMBA_NUM_THREADS is read then)
    os.environ.setdefault("NUMBA_NUM_THREADS",
                          str(max(2, default_threads() // int(os.environ["PYTEST_XDIST_WORKER_COUNT"]))))

REPO = Path(__file__).resolve().parents[1]
SHARED_REFERENCE = REPO.parent / "shared" / "reference"
sys.path.insert(0, str(Path(__file__).resolve().parent))


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto`` (pyproject addopts): one worker per CPU this process may use (SLURM_CPUS_PER_TASK
    or the affinity, as ``sphdvi run --threads``), at most 8: each worker compiles the numba kernels
    its files need and holds their scenes."""
    return max(1, min(default_threads(), 8))

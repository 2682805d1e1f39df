import os
import sys
from pathlib import Path

import pytest

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

REPO = Path(__file__).resolve().parents[1]
SHARED_REFERENCE = REPO.parent / "shared" / "reference"
sys.path.insert(0, str(Path(__file__).resolve().parent))


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto`` (pyproject addopts): one worker per CPU this process may use (SLURM_CPUS_PER_TASK
    or the affinity, as ``sphdvi run --threads``), at most 8: each worker compiles the numba kernels
    its files need and holds their scenes."""
    from sphdvi.simulation import default_threads
    return max(1, min(default_threads(), 8))

import math

import numpy as np
import pytest

G = 9.81


def agm(a, b):
    for _ in range(60):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return a


def crossing_times(t, x, direction=1):
    """Times where x crosses 0 going up (direction=1) or down, interpolated."""
    t = np.asarray(t)
    x = np.asarray(x)
    if direction > 0:
        idx = np.where((x[:-1] < 0) & (x[1:] >= 0))[0]
    else:
        idx = np.where((x[:-1] > 0) & (x[1:] <= 0))[0]
    return t[idx] - x[idx] * (t[idx + 1] - t[idx]) / (x[idx + 1] - x[idx])


@pytest.fixture
def rng():
    return np.random.default_rng(12345)

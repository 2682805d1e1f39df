"""An imposed acceleration (``<accinputs>``) against statics: in a 2D tank whose water feels
a_x = 0.1 g (ramped over 3 s, then held), the free surface settles normal to the effective
gravity (a_x, 0, -g), slope a_x/g (``cases/acceltank2d``; dp 0.02, ~12 s on one thread)."""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.vtkhdf import read_step, step_times

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "acceltank2d" / "CaseAccelTank2D_Def.xml"


def surface_slope(step, dp):
    """Least-squares slope of the top of the fluid columns 0.1 m away from the walls."""
    fluid = step["Type"] == 3
    x, z = step["points"][fluid, 0], step["points"][fluid, 2]
    col = np.round(x / dp).astype(int)
    xs = np.unique(col[(col * dp > 0.1) & (col * dp < 0.9)])
    tops = [z[col == c].max() for c in xs]
    return np.polyfit(xs * dp, tops, 1)[0]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("tilt")
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    return out


def test_free_surface_settles_at_slope_a_over_g(run):
    path = str(run / "particles.vtkhdf")
    times = step_times(path)
    held = [k for k, t in enumerate(times) if t >= 3.0 - 1e-9]
    slopes = np.array([surface_slope(read_step(path, k), 0.02) for k in held])
    print(f"slope over t = 3-5 s: mean {slopes.mean():.4f}, range {slopes.min():.4f}-{slopes.max():.4f} (a/g = 0.1)")
    assert abs(slopes.mean() - 0.1) < 0.005            # within 5 % of a_x/g
    assert slopes.min() > 0.085 and slopes.max() < 0.115   # the residual sloshing is small
    # before the acceleration grows the surface is level
    assert abs(surface_slope(read_step(path, 1), 0.02)) < 0.01

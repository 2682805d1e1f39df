"""S12: a 2D box (ρ_b/ρ_w = 0.5) floating in still water settles at its equilibrium draft
within 0.5 dp, stays upright and does not drift (SPH + the multibody engine, coupled).

Equilibrium from the particle mass m (kg/m): the displaced area m/ρ0 over the box width
(particles x nodes × dp) gives the draft below the free surface (top fluid node + dp/2).
Slow (about 1.5 minutes): ``python -m pytest -m slow tests/validation``.
"""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.io.vtkhdf import read_step, step_times

CASE = Path(__file__).resolve().parents[2] / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"


@pytest.mark.slow
def test_floating_box_draft(tmp_path):
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--tmax", "1.5", "--tout", "0.05",
                                  "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    data = read_case_h5(str(next(out.glob("*.h5"))))
    dp = data["constants"]["dp"]
    p = data["particles"]
    box = p["type"] == 2
    width = (np.ptp(p["pos"][box, 0]) + dp)
    mass = p["mass"][box].sum()
    surface = p["pos"][p["type"] == 3, 2].max() + dp / 2
    bottom_eq = surface - mass / (1000.0 * width) + dp / 2        # lowest particle centre at equilibrium
    path = str(out / "particles.vtkhdf")
    zs, xs, tilt = [], [], []
    for k, t in enumerate(step_times(path)):
        if t < 1.0:
            continue
        s = read_step(path, k)
        b = s["Type"] == 2
        pts = s["points"][b]
        zs.append(pts[:, 2].min())
        xs.append(pts[:, 0].mean())
        tilt.append(np.degrees(np.arctan2(np.polyfit(pts[:, 0], pts[:, 2], 1)[0], 1.0)))
    z = float(np.mean(zs))
    print(f"S12: bottom {z:.4f} m, equilibrium {bottom_eq:.4f} m, error {(z - bottom_eq) / dp:+.2f} dp; "
          f"x drift {max(abs(np.array(xs) - 0.5)) / dp:.3f} dp; tilt {max(np.abs(tilt)):.3f} deg")
    assert abs(z - bottom_eq) <= 0.5 * dp
    assert max(abs(np.array(xs) - 0.5)) < 0.1 * dp
    assert max(np.abs(tilt)) < 1.0

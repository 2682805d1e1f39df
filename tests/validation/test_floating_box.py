"""S12: a 2D box (ρ_b/ρ_w = 0.5) floating in still water settles at its equilibrium draft
within 0.5 dp, stays upright and does not drift (SPH + the multibody engine, coupled).

Equilibrium from the particle mass m (kg/m): the displaced area m/ρ0 over the box width
(particles x nodes × dp) gives the draft below the free surface (top fluid node + dp/2).
Slow (about 1.5 minutes): ``python -m pytest -m slow tests/validation``.
"""
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.floating import draft_errors

CASE = Path(__file__).resolve().parents[2] / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml"


@pytest.mark.slow
def test_floating_box_draft(tmp_path):
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--tmax", "1.5", "--tout", "0.05",
                                  "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    res = draft_errors(str(out))
    print(f"S12: draft error {res['draft_dp']:+.2f} dp; x drift {res['drift_dp']:.3f} dp; tilt {res['tilt_deg']:.3f} deg")
    assert abs(res["draft_dp"]) <= 0.5
    assert res["drift_dp"] < 0.1
    assert res["tilt_deg"] < 1.0

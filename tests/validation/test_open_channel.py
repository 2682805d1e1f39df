"""IO4: laminar open-channel flow down a 5 degree slope between an inlet and an outlet
(cases/inout2d/CaseOpenChannel2D_Def.xml, scored by sphdvi.validation.open_channel): the velocity
profile at mid-channel against the film's exact half-Poiseuille profile, at H/dp 10 (default
suite) and 20 (slow), and its error falling with dp."""
import os

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.open_channel import profile_error

CASE = os.path.join(os.path.dirname(__file__), "..", "..", "cases", "inout2d", "CaseOpenChannel2D_Def.xml")


def _run(tmp_path, dp):
    out = tmp_path / f"dp{dp}"
    r = CliRunner().invoke(main, ["run", CASE, "-o", str(out), "--dp", str(dp), "--quiet"])
    assert r.exit_code == 0, r.output
    return profile_error(str(out))


def test_open_channel_profile_at_h_over_dp_10(tmp_path):
    """Measured 0.67 % of u(H) (largest row error), flow rate +0.21 %."""
    e = _run(tmp_path, 0.1)
    assert e["max_rel"] < 0.015 and abs(e["q_rel"]) < 0.01


@pytest.mark.slow
def test_open_channel_profile_converges(tmp_path):
    """H/dp 10 and 20: measured 0.67 and 0.20 % (observed order 1.75); the flow rate within 0.3 %."""
    coarse, fine = _run(tmp_path, 0.1), _run(tmp_path, 0.05)
    assert fine["max_rel"] < 0.005 and fine["max_rel"] < 0.6 * coarse["max_rel"]
    assert abs(fine["q_rel"]) < 0.005

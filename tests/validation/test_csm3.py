"""S20: Turek & Hron's CSM3 beam (cases/flexstruc2d/CaseTurekHronCSM3_Def.xml; sphdvi.validation.csm3):
a flexible structure swinging under its weight, point A against the benchmark at 4 and 8 particles
across the beam (slow). Total Lagrangian SPH's free surfaces under-read the bending strain at first
order in dp/thickness, so the beam is soft at low resolution and stiffens with it."""
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.csm3 import case_errors

CASE = Path(__file__).resolve().parents[2] / "cases" / "flexstruc2d" / "CaseTurekHronCSM3_Def.xml"


@pytest.mark.slow
def test_csm3_beam_converges_to_turek_and_hron(tmp_path):
    errors = {}
    for dp, tmax in ((0.005, "1.2"), (0.0025, "1.1")):
        out = tmp_path / f"dp{dp}"
        r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", str(dp), "--tmax", tmax,
                                      "--tout", "0.01", "--threads", "1", "-q"])
        assert r.exit_code == 0, r.output
        errors[dp] = case_errors(out)
    coarse, fine = errors[0.005], errors[0.0025]
    assert fine["tip_particles"] == 2
    # 8 across: the mean deflection within 25 %, the frequency within 10 % (measured +20 %, -9 %)
    assert abs(fine["uz_mean"]) <= 0.25 and abs(fine["frequency"]) <= 0.10, fine
    # and the errors fall with dp (4 across: +57 %, -23 %)
    assert abs(fine["uz_mean"]) < 0.5 * abs(coarse["uz_mean"])
    assert abs(fine["frequency"]) < 0.5 * abs(coarse["frequency"])
    assert abs(fine["ux_mean"]) < abs(coarse["ux_mean"])

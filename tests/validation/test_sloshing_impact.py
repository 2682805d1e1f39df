"""S8: SPHERIC Test 10 (low filling) from ``cases/sloshing2d``: a tank rolled with the measured angle
record (``<mvrotfile>``), the left-wall pressure read by a point that moves with the tank
(``measure points --trackmkbound``), outputs every 1 ms around the impacts (``<special><timeout>``).

Measured (README, S8) at dp 0.008 (11.6 particles over the depth): the four impacts at
−0.3 / −2.5 / −3.4 / −6.1 % of the roll period from the experiment's; peaks −37 / +24 / +163 /
+49 %.  With the roll turned the other way (right-handed about axisp1 → axisp2, sphdvi's sense
before it followed DualSPHysics's MatrixRot) the water hit the left wall half a period late."""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.sloshing_impact import ROLL_PERIOD, WINDOWS, impact_errors, sensor_pressure

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "sloshing2d" / "CaseSloshingTest10_2D_Def.xml"
REFERENCE = REPO.parent / "shared" / "reference"


@pytest.mark.slow
def test_impacts_on_the_left_wall_come_when_the_experiment_records_them(tmp_path):
    out = tmp_path / "dp0.008"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", "0.008", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    e = impact_errors(out, REFERENCE)
    print({k: round(v, 4) for k, v in e.items()})
    # every impact within 7 % of the roll period (measured ≤ 6.1 %; the first within 0.3 %): the
    # opposite roll sense puts them half a period (50 %) off
    assert e["dt_max"] < 0.07 and abs(e["dt1"]) < 0.02
    # the pressure rises to impact levels in each window (peaks 2.3-10.6 kPa against 2.7-7.1 kPa)
    assert all(e[f"p_sph{k}"] > 0.5 * e[f"p_exp{k}"] for k in range(1, 5))
    # between the windows the sensor sees no impact: the largest pressure outside them stays lower
    t, p = sensor_pressure(out)
    outside = np.ones(t.size, bool)
    for lo, hi in WINDOWS:
        outside &= ~((t >= lo - 0.1 * ROLL_PERIOD) & (t <= hi))
    assert p[outside].max() < min(e[f"p_sph{k}"] for k in range(1, 5))

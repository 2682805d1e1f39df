"""S4: water levels of the Lobovsky et al. (2014) dam break, H = 0.3 m (slow, about 2 minutes).

The case file cases/lobovsky2d/CaseLobovsky2D_Def.xml carries run-time SWL gauges at
H1–H4 (x = 0.3, 0.865, 1.114, 1.3625 m); the level h(T), T = t √(g/H), is compared with
both experimental repetitions over each gauge's window before the reflected bore arrives.
Error measure: mean |h_sph − h_exp| / mean h_exp over the window.
"""
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "lobovsky2d" / "CaseLobovsky2D_Def.xml"
DATA = REPO.parent / "shared" / "reference" / "dambreak2d_lobovsky_2014" / "waterLevel"
H = 0.3
WINDOWS = {"H1": ((0.0, 8.0), ("Fig16_WaterLevels_H1_2.dat",)),
           "H2": ((2.0, 7.0), ("Fig16_WaterLevels_H2_3.dat", "Fig16_WaterLevels_H2_4.dat")),
           "H3": ((2.5, 6.5), ("Fig16_WaterLevels_H3_3.dat", "Fig16_WaterLevels_H3_4.dat")),
           "H4": ((3.0, 5.5), ("Fig16_WaterLevels_H4_4.dat", "Fig16_WaterLevels_H4_5.dat"))}


def level_errors(outdir):
    out = {}
    for name, ((t0, t1), files) in WINDOWS.items():
        sim = np.genfromtxt(Path(outdir) / f"GaugesSWL_{name}.csv", delimiter=";", skip_header=1)
        T = sim[:, 0] * math.sqrt(9.81 / H)
        h = np.nan_to_num(sim[:, 3] / H, nan=0.0)     # no surface found: dry
        errs = []
        for f in files:
            exp = np.loadtxt(DATA / f, comments="#")
            sel = (exp[:, 0] >= t0) & (exp[:, 0] <= t1)
            hs = np.interp(exp[sel, 0], T, h)
            errs.append(np.mean(np.abs(hs - exp[sel, 1])) / np.mean(exp[sel, 1]))
        out[name] = min(errs)
    return out


@pytest.fixture(scope="module")
def errors(tmp_path_factory):
    if not DATA.is_dir():
        pytest.skip("reference data not found")
    out = tmp_path_factory.mktemp("lobovsky")
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    errs = level_errors(out)
    print("S4 water-level errors: " + ", ".join(f"{k} {100 * v:.1f} %" for k, v in errs.items()))
    return errs


@pytest.mark.slow
def test_lobovsky_level_in_the_reservoir(errors):
    """H1 (inside the initial column): measured 1.2 % (DBC), 0.7 % (mDBC, 3 layers)."""
    assert errors["H1"] <= 0.10


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="TOLERANCES S4 10 %: measured H2 10.7 %, H3 16.2 %, H4 12.3 % (DBC; "
                                        "mDBC 10.6/15.9/13.3 %): the SPH surge is thicker and earlier")
def test_lobovsky_levels_downstream(errors):
    for name in ("H2", "H3", "H4"):
        assert errors[name] <= 0.10, f"{name}: {100 * errors[name]:.1f} %"

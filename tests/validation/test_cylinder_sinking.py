"""S13: a heavy 2D cylinder (R = 1 m, 1.2 ρ_w) released with its centre on the still-water level
(cases/cylinder2d/CaseCylinderSinking2D_Def.xml through the CLI), its displacement against T =
t √(g/R) compared with Fekken (2004, ComFLOW) and Moyo & Greenhow (2000, potential flow) by
sphdvi.validation.cylinder.case_errors.
"""
from pathlib import Path

import numpy as np
import pytest
from _caseruns import cached_runs

from sphdvi.validation import cylinder as C

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "cylinder2d" / "CaseCylinderSinking2D_Def.xml"
REF = REPO.parent / "shared" / "reference"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """run(dp) -> case_errors of that run (cached)."""
    if not (REF / C.DATA_DIR).is_dir():
        pytest.skip("reference data not found")

    def report(dp, case, e):
        return ("S13 cylinder, R/dp %.0f: displacement at T = 3 %.3f R (%+.1f %% against Fekken, %+.1f %% against "
                "Moyo & Greenhow); largest error over T = 0.5-3: %.1f / %.1f %%; %d particles, %d steps, %.1f s"
                % (C.RADIUS / dp, e["z3"], 100 * e["at3_Fekken"], 100 * e["at3_Moyo"], 100 * e["Fekken"],
                   100 * e["Moyo"], e["particles"], e["steps"], e["runtime_s"]))
    runs = cached_runs(tmp_path_factory, lambda out: C.case_errors(out, str(REF)), report)
    return lambda dp: runs(dp, CASE)


def test_references_as_read():
    """The two references as the scorer reads them, from the release: Fekken's displacement at T = 3
    is −1.17 R, Moyo & Greenhow's −1.35 R (their file, zeroed at T = 0.5, reads −1.29 R)."""
    if not (REF / C.DATA_DIR).is_dir():
        pytest.skip("reference data not found")
    Tf, zf = C.reference(str(REF), "Fekken")
    Tm, zm = C.reference(str(REF), "Moyo")
    assert np.interp(3.0, Tf, zf) == pytest.approx(-1.170, abs=0.005)
    assert np.interp(3.0, Tm, zm) == pytest.approx(-1.348, abs=0.005)
    assert Tm[0] == pytest.approx(0.5) and zm[0] == pytest.approx(-0.0564, abs=5e-4)
    assert C.release_offset(str(REF), "Fekken") == 0.0


def test_moyo_greenhow_displacement_counts_from_the_release():
    """Moyo & Greenhow's displacement file starts at T = 0.5 with zero; their velocity file starts at
    the release and has the cylinder 0.056 R down by T = 0.5, where Fekken's is 0.055 R down. Read
    from the release, their displacement agrees with their own velocity integrated from T = 0 (within
    0.037 R up to T = 3, as Fekken's two files within 0.019 R) and with Fekken's at T = 0.5; read as
    the file has it, it was 0.056 R above both there (4.4 % of the displacement at T = 3)."""
    if not (REF / C.DATA_DIR).is_dir():
        pytest.skip("reference data not found")
    for name, bound in (("Moyo", 0.04), ("Fekken", 0.02)):
        T, z = C.reference(str(REF), name)
        sel = (T >= C.WINDOW[0]) & (T <= C.WINDOW[1])
        assert np.abs(z[sel] - C.velocity_integral(str(REF), name, T[sel])).max() < bound, name
    Tf, zf = C.reference(str(REF), "Fekken")
    Tm, zm = C.reference(str(REF), "Moyo")
    assert np.interp(0.5, Tm, zm) == pytest.approx(np.interp(0.5, Tf, zf), abs=0.002)


@pytest.mark.slow
def test_s13_against_fekken(run):
    """R/dp 10 and 20 (dp 0.1 / 0.05 m: 7,357 / 29,027 particles, ~35 s / ~4 min on 2 threads):
    the centre drawn on the still water; the displacement up to T = 3 within 10 % of Fekken's
    (TOLERANCES S13: 5-10 %; measured largest error over T = 0.5-3 10.1 / 5.4 %, at T = 3
    −10.2 / −5.5 %: the SPH cylinder sinks a little slower), the error falling with dp."""
    coarse, fine = run(0.1), run(0.05)
    assert abs(coarse["offset_dp"]) < 1e-9 and abs(fine["offset_dp"]) < 1e-9
    assert fine["Fekken"] < 0.10
    assert fine["Fekken"] < coarse["Fekken"]


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="S13 against Moyo & Greenhow (2000), from the release: 17.7 % at R/dp 20 (21.7 % at 10; "
                          "14.1 / 18.3 % with their file's zero at T = 0.5 taken for the release); the two references "
                          "themselves differ by 16 % at T = 3 and the run follows Fekken's")
def test_s13_against_moyo_greenhow(run):
    """TOLERANCES S13 asks 5-10 % against both references, which differ by more than that; at T = 3
    Moyo & Greenhow's potential flow has sunk 1.35 R, Fekken's ComFLOW 1.17 R, the SPH cylinder
    1.10 R (R/dp 20)."""
    assert run(0.05)["Moyo"] < 0.10

"""tools/validate.py (error against run time) runs a case file through `sphdvi run` and
scores it: the S9 Poiseuille channel at its coarsest resolution (20 across, ~1 s of stepping)."""
import csv
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_validate_tool_scores_s9_and_reports_run_time(tmp_path):
    out = tmp_path / "s9.csv"
    r = subprocess.run([sys.executable, str(REPO / "tools" / "validate.py"), "S9", "--coarse", "--csv", str(out)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "observed order" not in r.stdout          # one resolution: no order to print
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 1
    row = rows[0]
    assert (row["case"], row["resolution"], row["status"], row["meets_target"]) == ("S9", "20 across", "completed",
                                                                                     "True")
    assert int(row["particles"]) == 312 and int(row["steps"]) == 2000
    assert 0 < float(row["runtime_s"]) < 120
    assert int(row["threads_used"]) == 1                # 312 particles: serial whatever --threads
    # the centre-line error of tests/validation/test_poiseuille_case.py at 20 across (+0.92 %)
    assert abs(float(row["centreline"]) - 0.0092) < 0.0005
    assert float(row["transient"]) < 0.02

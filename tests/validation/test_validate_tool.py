"""tools/validate.py (error against run time) runs a case file through `sphdvi run` and
scores it: the S9 Poiseuille channel at its coarsest resolution (20 across, ~1 s of stepping)."""
import argparse
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
    assert row["constants"] == ""                       # the case file's own constants


def _validate_module():
    import importlib.util
    spec = importlib.util.spec_from_file_location("validate_tool", REPO / "tools" / "validate.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod                  # its dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


def test_constant_option_writes_a_copy_beside_the_case_with_the_new_values(tmp_path):
    """--constant coefh=1.2: the case file's copy, in its own folder (relative paths hold), with
    coefh set and the other ways of giving h removed; an auto entry turned to the value; a
    missing entry added; bad options exit 2."""
    from lxml import etree

    validate = _validate_module()
    src = tmp_path / "CaseT_Def.xml"
    src.write_text("""<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef><constantsdef>
  <gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><hdp value="2.0" />
  <speedsystem value="0" auto="true" /><coefsound value="20" /><speedsound value="0" auto="true" />
</constantsdef></casedef></case>""")
    copy = validate.case_with_constants(str(src), {"coefh": "1.2", "speedsound": "50", "cflnumber": "0.1"})
    try:
        assert Path(copy).parent == tmp_path and Path(copy).name.endswith("_Def.xml") and Path(copy) != src
        cdef = etree.parse(copy).find(".//constantsdef")
        assert cdef.find("hdp") is None and cdef.find("coefh").get("value") == "1.2"
        assert cdef.find("speedsound").attrib == {"value": "50", "auto": "false"}
        assert cdef.find("speedsystem").get("auto") == "true"          # untouched
        assert cdef.find("cflnumber").get("value") == "0.1"
        assert "hdp" in src.read_text()                                 # the user's file unchanged
    finally:
        Path(copy).unlink()
    ap = argparse.ArgumentParser()
    assert validate.parse_constants(["CoefH=1.2"], ap) == {"coefh": "1.2"}
    for bad in (["coefh"], ["Visco=0.1"], ["gravity=1"]):
        try:
            validate.parse_constants(bad, ap)
        except SystemExit as e:
            assert e.code == 2
        else:
            raise AssertionError(bad)


def test_help_lists_every_case_and_the_slow_ones_all_adds():
    """The usage names every case the tool takes (S3M and S16O included) and ``--all`` names the
    slow cases the default leaves out (its help said "every case, S4 included" while it also
    added S8, S16, S16M, S16O, S18 and W4)."""
    validate = _validate_module()
    every = validate.cases()
    r = subprocess.run([sys.executable, str(REPO / "tools" / "validate.py"), "--help"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())
    names = text.split("cases to run (")[1].split(")")[0].split()
    assert set(names) == {c.name for c in every} | {"S2"} and {"S3M", "S16O"} <= set(names)
    slow = [c.name for c in every if c.slow]
    assert set(slow) == {"S4", "S8", "S16", "S16M", "S16O", "S18", "S19", "S20", "W4", "W9"}
    assert "also the slow cases " + ", ".join(slow) in text
    assert "default: all but the slow " + ", ".join(slow) in text


def test_dp_naming_no_resolution_is_exit_2_and_lists_the_cases_dps():
    """--dp that no chosen case has (a typo) ran nothing and exited 0; now exit 2 naming the dps."""
    r = subprocess.run([sys.executable, str(REPO / "tools" / "validate.py"), "W3", "--dp", "0.03"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "--dp 0.03" in r.stderr and "W3 0.04, 0.02, 0.01" in r.stderr


def test_resolutions_on_request_run_only_when_named_or_with_fine(monkeypatch):
    """W3's depth/dp 40 (an hour on 1 thread) is left out of a plain run, runs with --fine or
    when --dp names it; --coarse still takes the coarsest of what is left."""
    validate = _validate_module()
    ran = []

    def fake_run(case, res, outdir, threads):
        ran.append((case.name, res.dp))
        return {"rc": 1, "status": "failed", "message": "not run", "particles": 0, "steps": 0, "runtime_s": 0.0,
                "us": 0.0, "threads_used": 1}

    monkeypatch.setattr(validate, "run_case", fake_run)
    for argv, expected in ((["W3"], [0.04, 0.02]), (["W3", "--fine"], [0.04, 0.02, 0.01]),
                           (["W3", "--dp", "0.01"], [0.01]), (["W3", "--coarse", "--fine"], [0.04])):
        ran.clear()
        assert validate.main(argv) == 1
        assert ran == [("W3", d) for d in expected], argv

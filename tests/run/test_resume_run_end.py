"""--resume and what a run reports at its end: DtFixedFile's excess over the CFL dt covers the whole
run (it travels in restart.h5), and a run that MinFluidStop ended cannot be resumed (DualSPHysics's
JSphCpuSingle::Run ends the simulation there); bitwise on 1 thread."""
import json
import re
import warnings
from pathlib import Path

import h5py
import numpy as np
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def dambreak(tmp_path, extra_params="", bottomless=False):
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"')
    text = re.sub(r"<gauges>.*?</gauges>", "", text, flags=re.S)
    if bottomless:          # the tank has no bottom: the column falls out of the domain
        text = text.replace("<boxfill>bottom | left", "<boxfill>left")
        text = text.replace('<posmin x="default" y="default" z="default" />',
                            '<posmin x="default" y="default" z="default - 0.05" />')
    text = text.replace("<parameters>", "<parameters>" + extra_params)
    path = tmp_path / "CaseRE_Def.xml"
    path.write_text(text)
    return path


def invoke_excluding(args):
    """``invoke``, asserting that its only warnings are those of the fluid leaving the tank."""
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        r = invoke(args)
    assert all("were excluded" in str(w.message) for w in seen), [str(w.message) for w in seen]
    return r


def state(out):
    with h5py.File(out / "restart.h5", "r") as f:
        return {k: f["state"][k][...] for k in ("idp", "pos", "vel", "rhop")}, dict(f["scalars"].attrs)


def assert_bitwise(a, b):
    sa, ka = state(a)
    sb, kb = state(b)
    assert ka["nstep"] == kb["nstep"] and ka["time"] == kb["time"]
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k


def test_dtfixedfile_excess_covers_the_resumed_run(tmp_path):
    """DtFixedFile 0.2 ms (above the CFL dt, ~0.13 ms) until 0.015 s, then 0.1 ms: resumed at 0.02 s,
    run.json still reports the excess of the first piece (it restarted from -inf: a negative one)."""
    (tmp_path / "dt.txt").write_text("0 0.2\n0.015 0.2\n0.016 0.1\n")
    case = dambreak(tmp_path, '<parameter key="DtFixedFile" value="dt.txt" />')
    common = ["--tout", "0.01", "--threads", "1", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.03"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.03"] + common)
    assert r.exit_code == 0, r.output
    assert_bitwise(a, b)
    ea = json.loads((a / "run.json").read_text())["dtfixedfile_max_excess_s"]
    eb = json.loads((b / "run.json").read_text())["dtfixedfile_max_excess_s"]
    assert ea > 0 and eb == ea
    # an older checkpoint without it: the resume goes on, the excess from the resumed piece alone
    c = tmp_path / "c"
    assert invoke(["run", case, "-o", c, "--tmax", "0.02"] + common).exit_code == 0
    with h5py.File(c / "restart.h5", "a") as f:
        del f["scalars"].attrs["dt_error"]
    r = invoke(["run", c, "--resume", "--tmax", "0.03"] + common)
    assert r.exit_code == 0, r.output
    assert_bitwise(a, c)
    assert json.loads((c / "run.json").read_text())["dtfixedfile_max_excess_s"] < 0


def test_a_run_ended_at_minfluidstop_is_not_resumed(tmp_path):
    """MinFluidStop 0.95 in a tank without a bottom: the run ends (completed) when 5 % of the fluid has
    left; one interrupted before and resumed ends there bitwise; --resume of the ended run (with or
    without a larger --tmax) is refused (exit 2) and changes nothing (it took one more step and wrote
    one more output each time)."""
    case = dambreak(tmp_path, '<parameter key="MinFluidStop" value="0.95" />', bottomless=True)
    common = ["--tout", "0.02", "--threads", "1", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke_excluding(["run", case, "-o", a, "--tmax", "1"] + common).exit_code == 0
    meta = json.loads((a / "run.json").read_text())
    assert meta["status"] == "completed" and "minimum number of fluid particles" in meta["message"]
    t_end = meta["physical_time"]
    assert 0.12 < t_end < 1
    assert invoke_excluding(["run", case, "-o", b, "--tmax", "0.12"] + common).exit_code == 0
    assert sum(json.loads((b / "run.json").read_text())["excluded"].values()) > 0    # fluid lost before
    r = invoke_excluding(["run", b, "--resume", "--tmax", "1"] + common)
    assert r.exit_code == 0, r.output
    assert_bitwise(a, b)
    for name in ("excluded.csv", "run.csv"):
        rows = [[line.rsplit(",", 1)[0] if name == "run.csv" else line for line in (d / name).read_text().splitlines()]
                for d in (a, b)]
        assert rows[0] == rows[1], name
    before = {p.name: p.read_bytes() for p in a.iterdir() if p.is_file()}
    for more in ([], ["--tmax", "2"]):
        r = invoke(["run", a, "--resume", "--threads", "1", "-q"] + more)
        assert r.exit_code == 2, r.output
        assert "minimum number of fluid particles" in r.output and f"t={t_end:.6g}" in r.output
        assert "--overwrite" in r.output and "Traceback" not in r.output
        assert {p.name: p.read_bytes() for p in a.iterdir() if p.is_file()} == before

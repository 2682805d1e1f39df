"""Body-only runs (bodies, no fluid) as `sphdvi run` runs: rows appended at each output,
run.log / run.csv, divergence (exit 3), SIGTERM, SIGKILL + --resume (bitwise), the
checkpoint of the multibody System's state."""
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import sphdvi.io.checkpoint as checkpoint
import sphdvi.io.runfiles as runfiles
import sphdvi.simulation as simulation
from sphdvi.cli import main
from sphdvi.errors import InputError

REPO = Path(__file__).resolve().parents[2]
PENDULUM = (REPO / "cases" / "pendulum" / "CasePendulum_Def.xml").read_text()
BODIES_HEADER = ("time,body,x,y,z,qw,qx,qy,qz,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,"
                 "fx,fy,fz,tx,ty,tz,cfx,cfy,cfz,ctx,cty,ctz,ffx,ffy,ffz,ftx,fty,ftz")


def case_file(tmp_path, text=PENDULUM, name="CasePendulum_Def.xml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def lines(path):
    return Path(path).read_text().splitlines()


def test_rows_appended_at_each_output(tmp_path, monkeypatch):
    """bodies.csv / links.csv grow at each output by exactly that output's rows (the
    TimeOutExtra row before it and the output row), in one append; never rewritten."""
    out = tmp_path / "out"
    seen = {}                       # file name -> [(text appended, content after, inode)]
    real_append = runfiles.append_text

    def append(path, text):
        name = os.path.basename(path)
        before = Path(path).read_text() if os.path.exists(path) else None
        real_append(path, text)
        after = Path(path).read_text()
        assert after == before + text       # grown by exactly the text, nothing else moved
        seen.setdefault(name, []).append((text, os.stat(path).st_ino))

    monkeypatch.setattr(runfiles, "append_text", append)
    r = invoke(["run", case_file(tmp_path), "-o", out, "-q", "--tmax", "0.05", "--tout", "0.01",
                "--set", "TimeOutExtra=0.005"])
    assert r.exit_code == 0, r.output
    for name, nrows in (("bodies.csv", 1), ("links.csv", 1)):
        calls = seen[name]
        assert len(calls) == 6                       # parts 0..5: one append per output
        assert len({ino for _, ino in calls}) == 1   # the same file throughout
        assert os.stat(out / name).st_ino == calls[0][1]
        for k, (text, _) in enumerate(calls):
            times = [float(row.split(",", 1)[0]) for row in text.splitlines()]
            expect = [0.0] if k == 0 else [(k - 0.5) * 0.01, k * 0.01]
            assert np.allclose(times, expect, atol=1e-12), (name, k, text)
            assert text.endswith("\n") and len(text.splitlines()) == nrows * len(expect)
        content = lines(out / name)
        assert content[0] == (BODIES_HEADER if name == "bodies.csv" else "time,link,fx,fy,fz,tx,ty,tz")
        assert "\n".join(content[1:]) + "\n" == "".join(t for t, _ in calls)
    assert len(seen["run.csv"]) == 6 and len(seen["run.log"]) == 6 + 1     # + the final line


def test_run_log_and_csv_rows(tmp_path):
    out = tmp_path / "out"
    r = invoke(["run", case_file(tmp_path), "-o", out, "-q", "--tmax", "0.1", "--tout", "0.02"])
    assert r.exit_code == 0, r.output
    rows = lines(out / "run.csv")
    assert rows[0] == "part,time,steps,particles,excluded,dtmin,dtmax,walltime"
    table = np.array([[float(x) for x in row.split(",")] for row in rows[1:]])
    assert table.shape == (6, 8)
    assert np.array_equal(table[:, 0], np.arange(6))
    assert np.allclose(table[:, 1], np.arange(6) * 0.02, atol=1e-12)
    assert np.array_equal(table[:, 2], np.arange(6) * 20)
    assert np.array_equal(table[:, 3:5], np.zeros((6, 2)))                 # no particles
    assert np.array_equal(table[:, 5], [0] + [0.001] * 5) and np.array_equal(table[:, 5], table[:, 6])
    assert np.all(np.diff(table[:, 7]) >= 0)
    log = lines(out / "run.log")
    assert len(log) == 7
    for k, line in enumerate(log[:6]):
        assert line.startswith(f"Part {k:04d}  t={0.02 * k:.6f} s  steps={20 * k}  bodies=1  links=1")
    assert log[6].startswith("completed: t=0.1 s, 100 steps")
    meta = json.loads((out / "run.json").read_text())
    assert meta["mode"] == "bodies" and meta["status"] == "completed" and meta["message"] == ""
    assert meta["steps"] == 100 and meta["physical_time"] == pytest.approx(0.1) and meta["outputs"] == 6
    assert len(lines(out / "bodies.csv")) == 1 + 6 and len(lines(out / "links.csv")) == 1 + 6
    assert (out / simulation.RESTART_FILE).exists()
    # progress (not quiet) counts the bodies
    r = invoke(["run", case_file(tmp_path), "-o", tmp_path / "out2", "--tmax", "0.02", "--tout", "0.02"])
    assert r.exit_code == 0 and "steps=20 bodies=1 " in r.output


def test_run_bodies_arrays_match_the_run_files(tmp_path):
    """sphdvi.dvi.run_bodies (in memory) steps on the schedule of `sphdvi run`: its arrays are
    the rows of bodies.csv / links.csv (TimeOutExtra rows included)."""
    from sphdvi.dvi import run_bodies
    from sphdvi.io.casefile import read_case_h5
    from sphdvi.mechanism import mechanism_from_case
    out = tmp_path / "out"
    r = invoke(["run", case_file(tmp_path), "-o", out, "-q", "--tmax", "0.1", "--tout", "0.02",
                "--set", "TimeOutExtra=0.005"])
    assert r.exit_code == 0, r.output
    mech = mechanism_from_case(read_case_h5(str(next(out.glob("*.h5")))))
    h = run_bodies(mech["bodies"], mech["links"], tmax=0.1, tout=0.02, dt=1e-3, materials=mech["materials"],
                   tout_extra=0.005, **mech["system"])
    fields = ("pos", "quat", "euler", "vel", "omega", "force", "torque", "contact_force", "contact_torque",
              "fluid_force", "fluid_torque")
    expect = [f"{t:.9g},pend," + ",".join(f"{v:.9g}" for v in np.concatenate([getattr(h, f)[k, 0]
                                                                              for f in fields]))
              for k, t in enumerate(h.time)]
    assert lines(out / "bodies.csv")[1:] == expect and len(expect) == 21
    lexpect = [f"{t:.9g},{h.link_names[0]}," + ",".join(f"{v:.9g}" for v in np.concatenate(
        [h.link_force[k, 0], h.link_torque[k, 0]])) for k, t in enumerate(h.time)]
    assert lines(out / "links.csv")[1:] == lexpect


def free_fall_case(tmp_path):
    """The pendulum's cube without its hinge under an absurd gravity, 1e306 m/s2: with
    DtFixed = 1 s the centre is at z = -1 - 1e306 k(k+1)/2 after step k, beyond the largest
    double (1.8e308) at step 19 (its <simulationdomain> reaches down to -1.79e308: the body leaves no
    domain before it goes non-finite)."""
    text = PENDULUM.replace('z="-9.81"', 'z="-1e306"')
    text = re.sub(r"<link_hinge.*?</link_hinge>", "", text, flags=re.S)
    text = text.replace("</parameters>", '<simulationdomain><posmin x="default" y="default" z="-1.79e308" />'
                        '<posmax x="default" y="default" z="default" /></simulationdomain></parameters>')
    return case_file(tmp_path, text, "CaseFall_Def.xml")


def test_diverging_run_exits_3_and_keeps_rows(tmp_path):
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "sphdvi", "run", str(free_fall_case(tmp_path)), "-o", str(out),
                           "-q", "--tmax", "100", "--tout", "5", "--set", "DtFixed=1"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 3, proc.stderr
    assert "Traceback" not in proc.stderr
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "diverged" and meta["steps"] == 19 and meta["physical_time"] == 19.0
    msg = meta["message"]
    assert msg.startswith("t=19 s, step 19: body 'pend' (mkbound 1) has a non-finite position"), msg
    assert "its last finite state (t=18 s): position (" in msg
    assert "cause: the load on it is absurdly large (force (0, 0, -1e+307) N" in msg
    assert f"diverged: {msg}" in proc.stderr
    # the outputs before stay: t = 0, 5, 10, 15
    rows = [r.split(",") for r in lines(out / "bodies.csv")[1:]]
    assert [float(r[0]) for r in rows] == [0, 5, 10, 15]
    z = np.array([float(r[4]) for r in rows])
    k = np.array([0, 5, 10, 15])
    assert np.allclose(z, -1 - 1e306 * (k * (k + 1) / 2), rtol=1e-8)
    assert len(lines(out / "run.csv")) == 1 + 4
    assert lines(out / "run.log")[-1] == f"diverged: t=19 s, 19 steps, runtime {meta['runtime_s']:.2f} s -- {msg}"


def _start(case, out, args):
    return subprocess.Popen([sys.executable, "-m", "sphdvi", "run", str(case), "-o", str(out)] + args,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def _wait_rows(proc, csv, n, timeout=120):
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        if csv.exists() and csv.read_text().count("\n") >= n + 1:
            return
        time.sleep(0.002)


def test_sigkill_then_resume_is_bitwise(tmp_path):
    """A body-only run killed with SIGKILL (torn last lines added to every row file) resumes
    from its last output and ends with the bodies.csv / links.csv / run.csv rows of an
    uninterrupted run, bit for bit."""
    case = case_file(tmp_path)
    args = ["-q", "--tmax", "3", "--tout", "0.01", "--set", "TimeOutExtra=0.002"]
    full, killed = tmp_path / "full", tmp_path / "killed"
    assert invoke(["run", case, "-o", full] + args).exit_code == 0
    proc = _start(case, killed, args)
    _wait_rows(proc, killed / "run.csv", 10)
    killed_early = proc.poll() is None
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert killed_early, "the run finished before it could be killed"
    assert json.loads((killed / "run.json").read_text())["status"] == "running"
    nrows = len(lines(killed / "bodies.csv"))
    assert 10 < nrows < len(lines(full / "bodies.csv"))
    for name in ("bodies.csv", "links.csv", "run.csv", "run.log"):    # killed in the middle of an append
        with open(killed / name, "a") as fh:
            fh.write("99,0.0")
    r = invoke(["run", killed, "--resume"] + args)
    assert r.exit_code == 0, r.output
    for name in ("bodies.csv", "links.csv"):
        assert (killed / name).read_bytes() == (full / name).read_bytes(), name
    rows = [[r.rsplit(",", 1)[0] for r in lines(d / "run.csv")] for d in (full, killed)]
    assert rows[0] == rows[1] and len(rows[0]) == 1 + 301
    log = (killed / "run.log").read_text()
    assert "99,0.0" not in log and re.search(r"resumed from part \d+ at t=", log)
    meta = json.loads((killed / "run.json").read_text())
    assert meta["status"] == "completed" and meta["steps"] == 3000


def test_sigterm_stops_cleanly_and_resumes(tmp_path):
    case = case_file(tmp_path)
    out = tmp_path / "out"
    args = ["-q", "--tmax", "1000", "--tout", "0.01"]
    proc = _start(case, out, args)
    _wait_rows(proc, out / "run.csv", 5)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1 and "Traceback" not in err
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "interrupted" and "--resume" in meta["message"]
    assert f"interrupted: {meta['message']}" in err
    part = int(re.search(r"from part (\d+)", meta["message"]).group(1))
    assert part >= 4 and len(lines(out / "run.csv")) == 1 + part + 1
    # resume to a nearer end: the same rows as a run straight to it
    tmax = f"{0.01 * (part + 3):.2f}"
    r = invoke(["run", out, "--resume", "-q", "--tmax", tmax, "--tout", "0.01"])
    assert r.exit_code == 0, r.output
    ref = tmp_path / "ref"
    assert invoke(["run", case, "-o", ref, "-q", "--tmax", tmax, "--tout", "0.01"]).exit_code == 0
    assert (out / "bodies.csv").read_bytes() == (ref / "bodies.csv").read_bytes()


def test_resume_without_checkpoint_is_input_error(tmp_path):
    out = tmp_path / "out"
    assert invoke(["run", case_file(tmp_path), "-o", out, "-q", "--tmax", "0.01"]).exit_code == 0
    os.unlink(out / simulation.RESTART_FILE)
    r = invoke(["run", out, "--resume"])
    assert r.exit_code == 2 and "holds no run to continue (no restart.h5" in r.output, r.output


def _mechanism():
    """Bodies with functions inside the System: a moving body (imposed motion), a stiffness
    table (a lambda) on a hinge and a spring."""
    bodies = [dict(name="arm", mass=2.0, inertia=(0.1, 0.2, 0.3), pos=(1, 0, 0), omega=(0, 0.5, 0)),
              dict(name="driver", kind="moving", mass=1.0, inertia=(1, 1, 1), pos=(0, 0, 2),
                   motion=lambda t: ((0.0, 0.0, 0.3 * np.cos(2 * t)), (0.0, 0.0, 0.0))),
              dict(name="bob", mass=0.5, inertia=(0.01, 0.01, 0.01), pos=(0, 0, 1))]
    links = [dict(kind="hinge", body1="arm", point=(0, 0, 0), axis=(0, 1, 0),
                  stiffness=[[0, 1.0], [1, 50.0]], damping=0.2, name="h"),
             dict(kind="spring", body1="bob", body2="driver", point1=(0, 0, 1), point2=(0, 0, 2),
                  stiffness=[[0, 100.0], [1, 300.0]], damping=1.0, rest_length=0.8, name="s")]
    return bodies, links


def test_checkpoint_round_trip_is_exact(tmp_path):
    """The state written at an output and read back into the System the case builds again
    steps bitwise as the original (a moving body, a stiffness table on a hinge, a spring)."""
    from sphdvi.dvi.runner import build_system
    bodies, links = _mechanism()
    a, _ = build_system(bodies, links, gravity=(0, 0, -9.81))
    for _ in range(300):
        a.step(1e-3)
    path = str(tmp_path / "restart.h5")
    checkpoint.save_bodies_checkpoint(path, a.get_state(), part=3, step=300, names=["arm", "driver", "bob"])
    b, _ = build_system(*_mechanism(), gravity=(0, 0, -9.81))
    saved = checkpoint.load_bodies_checkpoint(path, b)
    assert saved == {"part": 3, "step": 300, "names": ["arm", "driver", "bob"]} and b.time == a.time
    for _ in range(300):
        a.step(1e-3)
        b.step(1e-3)
    for name in ("pos", "quat", "vel", "omega_b", "total_force", "link_force", "link_torque"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.time == b.time
    # a case with other bodies: a clear input error
    other, _ = build_system(_mechanism()[0][:2], [], gravity=(0, 0, -9.81))
    with pytest.raises(InputError, match="body-only checkpoint"):
        checkpoint.load_bodies_checkpoint(path, other)


def test_checkpoint_throttled_to_wall_time(tmp_path, monkeypatch):
    """restart.h5 is written at the first and the last output and, between, at most once per
    BODIES_CHECKPOINT_EVERY_S of wall time (outputs a few steps apart would otherwise spend
    most of the run writing it); 0 writes it at every output."""
    saved = []
    real = simulation.save_bodies_checkpoint
    monkeypatch.setattr(simulation, "save_bodies_checkpoint",
                        lambda path, state, **extra: (saved.append(extra["part"]), real(path, state, **extra)))
    case = case_file(tmp_path)
    for every, expected in ((1e9, [0, 10]), (0.0, list(range(11)))):
        saved.clear()
        monkeypatch.setattr(simulation, "BODIES_CHECKPOINT_EVERY_S", every)
        out = tmp_path / f"out{every}"
        r = invoke(["run", case, "-o", out, "-q", "--tmax", "0.1", "--tout", "0.01"])
        assert r.exit_code == 0, r.output
        assert saved == expected
        # resuming a finished run from its checkpoint changes nothing
        before = (out / "bodies.csv").read_bytes()
        assert invoke(["run", out, "--resume", "-q", "--tmax", "0.1", "--tout", "0.01"]).exit_code == 0
        assert (out / "bodies.csv").read_bytes() == before


def test_warm_up_steps_a_copy_and_says_when_it_compiles(tmp_path, monkeypatch):
    """The multibody kernels are compiled (or loaded) before the loop's clock on a copy of the
    System: the run's rows are those of a run without the warm-up, byte for byte; run.json holds
    jit_s; a warm-up past COMPILE_NOTICE_AFTER_S (here 0, the warm-up made 0.3 s slower) says so."""
    args = ["run", case_file(tmp_path), "--tmax", "0.2", "--tout", "0.05"]
    warm_up = simulation._warm_up_bodies
    calls = []

    def slow_warm_up(system, dt):
        time.sleep(0.3)
        calls.append(float(system.time))
        return warm_up(system, dt)

    monkeypatch.setattr(simulation, "COMPILE_NOTICE_AFTER_S", 0.0)
    monkeypatch.setattr(simulation, "_warm_up_bodies", slow_warm_up)
    r = invoke(args + ["-o", tmp_path / "warm"])
    assert r.exit_code == 0, r.output
    assert calls == [0.0]
    assert "compiling the kernels" in r.stderr and "kernels ready after" in r.stderr
    meta = json.loads((tmp_path / "warm" / "run.json").read_text())
    assert meta["jit_s"] > 0 and meta["startup_s"] > meta["jit_s"] + 0.3
    monkeypatch.setattr(simulation, "_warm_up_bodies", lambda system, dt: 0.0)
    r = invoke(args + ["-o", tmp_path / "cold", "-q"])
    assert r.exit_code == 0, r.output
    for name in ("bodies.csv", "links.csv"):
        assert (tmp_path / "warm" / name).read_bytes() == (tmp_path / "cold" / name).read_bytes()


def test_sigterm_during_the_warm_up_ends_interrupted(tmp_path, monkeypatch):
    """A signal that comes while the multibody kernels compile ends the run before its loop:
    exit 1, run.json 'interrupted' during start-up, no step taken."""
    def warm_up(system, dt):
        os.kill(os.getpid(), signal.SIGTERM)
        return 0.0

    monkeypatch.setattr(simulation, "_warm_up_bodies", warm_up)
    out = tmp_path / "out"
    r = invoke(["run", case_file(tmp_path), "-o", out, "-q"])
    assert r.exit_code == 1, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "interrupted" and "during start-up" in meta["message"]
    assert meta.get("steps", 0) == 0

#!/usr/bin/env python
"""Cost of mooring lines: C4's moored box (cases/mooredbox2d/CaseMooredBox2D_Def.xml: two lines of 20
segments, dtM auto) at ``--dp`` (default 0.02: 4,051 particles).

Prints microseconds per particle-step of the whole step and the share the lines take
(``Moorings.step``: their sub-steps over the SPH step and the loads on the body, timed by wrapping
it), with the sub-steps per SPH step and the microseconds per line node and sub-step; best of
``--rounds`` rounds of ``--steps`` steps, after advancing to ``--t0`` (FtPause 0). ``--segments N``
redraws the lines with N segments (dtM auto shrinks as 1/N). Not a test.

    NUMBA_NUM_THREADS=2 python tools/bench_moorings.py [--dp 0.02] [--steps 300] [--rounds 5] [--segments 40]
"""
import argparse
import math
import os
import sys
import tempfile

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import numba  # noqa: E402
from click.testing import CliRunner  # noqa: E402

from benchtiming import time_part  # noqa: E402
from sphdvi.cli import main  # noqa: E402
from sphdvi.io.casefile import read_case_h5  # noqa: E402
from sphdvi.run_options import apply_overrides  # noqa: E402
from sphdvi.simulation import SPHRun, find_case_file, special_parameters  # noqa: E402

CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "mooredbox2d",
                    "CaseMooredBox2D_Def.xml")


def build(dp: float, tmp: str, segments: int) -> SPHRun:
    r = CliRunner().invoke(main, ["gencase", CASE, "-o", tmp, "--dp", str(dp), "--quiet"])
    if r.exit_code:
        raise SystemExit(r.output)
    data = read_case_h5(find_case_file(tmp))
    if segments:
        for line in data["json"]["special"]["moorings"]["lines"]:
            line["segments"] = segments
    return SPHRun(data, apply_overrides(special_parameters(data), ["FtPause=0"]), tmp)


def main_() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dp", type=float, default=0.02)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--segments", type=int, default=0, help="segments per line (0: the case's 20)")
    ap.add_argument("--t0", type=float, default=0.05, help="time advanced before timing (s)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        run = build(a.dp, tmp, a.segments)
        sol, moor = run.solver, run.floating.moorings
        wall, lines_time, dt = time_part(sol, moor, "step", a.t0, a.steps, a.rounds)
        n = sol.state.n
        nsub = max(1, math.ceil(dt / moor.dtm - 1e-9))
        nodes = int(moor.pos.shape[0])
        print(f"C4 moored box dp={a.dp:g}: {n:,} particles, {len(moor.lines)} lines, {nodes} nodes, "
              f"dtM {moor.dtm:.3g} s, {nsub} sub-steps per step (dt {dt:.3g} s), {numba.get_num_threads()} threads, "
              f"{a.steps} steps")
        print(f"  step: {1e3 * wall / a.steps:.3f} ms, {1e6 * wall / a.steps / n:.3f} us per particle-step")
        print(f"  lines: {1e3 * lines_time / a.steps:.3f} ms a step ({100 * lines_time / wall:.1f} %), "
              f"{1e6 * lines_time / a.steps / (2 * nsub * nodes):.3f} us per node and evaluation "
              f"(two a sub-step)")


if __name__ == "__main__":
    main_()

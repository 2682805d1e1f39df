#!/usr/bin/env python
"""Cost of a relaxation zone: W10's flume (cases/waveflume2d/CaseWaveRelaxZone2D_Def.xml, an
``<rzwaves_regular>`` zone with the drift correction and a damping zone) at ``--dp`` (default 0.01:
12,624 particles, 1,509 in the zone).

Prints microseconds per particle-step of the whole step and the share the zone's pass at the step's
end takes (``WaveZone.apply``, timed by wrapping it); best of ``--rounds`` rounds of ``--steps`` steps,
after advancing the flow to ``--t0``.  ``--waves N`` times the zone as a ``<rzwaves_spectrum>`` of N
waves instead (the pass sums every wave at every particle in the zone).  Not a test.

    NUMBA_NUM_THREADS=2 python tools/bench_relaxzones.py [--dp 0.01] [--steps 200] [--rounds 5] [--waves 50]
"""
import argparse
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

CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "waveflume2d",
                    "CaseWaveRelaxZone2D_Def.xml")


def build(dp: float, tmp: str, waves: int) -> SPHRun:
    r = CliRunner().invoke(main, ["gencase", CASE, "-o", tmp, "--dp", str(dp), "--quiet"])
    if r.exit_code:
        raise SystemExit(r.output)
    data = read_case_h5(find_case_file(tmp))
    if waves:           # the same zone as a JONSWAP sea of Hs = H, Tp = T
        zone = data["json"]["special"]["relaxationzones"][0]
        zone.update(type="rzwaves_spectrum", spectrum="jonswap", discretization="stretched", peakcoef=3.3,
                    waves=waves, randomseed=1, serieini=0.0, ramptime=0.0)
    return SPHRun(data, apply_overrides(special_parameters(data), []), tmp)


def main_() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dp", type=float, default=0.01)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--waves", type=int, default=0, help="a spectrum zone of this many waves (0: the regular zone)")
    ap.add_argument("--t0", type=float, default=0.05, help="time advanced before timing (s)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        run = build(a.dp, tmp, a.waves)
        sol, zone = run.solver, run.relax[0]
        wall, pass_time, _ = time_part(sol, zone, "apply", a.t0, a.steps, a.rounds)
        n = sol.state.n
        what = f"spectrum of {a.waves} waves" if a.waves else "regular"
        print(f"W10 flume dp={a.dp:g} ({what} zone): {n:,} particles, {zone.count_inside(sol.state):,} in the zone, "
              f"{numba.get_num_threads()} threads, {a.steps} steps")
        print(f"  step: {1e3 * wall / a.steps:.3f} ms, {1e6 * wall / a.steps / n:.3f} us per particle-step")
        print(f"  zone: {1e3 * pass_time / a.steps:.3f} ms a step ({100 * pass_time / wall:.1f} %)")


if __name__ == "__main__":
    main_()

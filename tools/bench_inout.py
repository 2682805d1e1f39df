#!/usr/bin/env python
"""Cost of inlet/outlet zones: the uniform channel of cases/inout2d/CaseUniformChannel2D_Def.xml
(inlet with imposed velocity and extrapolated density, outlet with extrapolated velocity, boundcorr
walls) at ``--dp`` (default 0.005: 9,933 particles; 0.0025: 36,278).

Prints microseconds per particle-step of the whole step and the share the zones take: the imposed
and extrapolated values before each interaction (``_inout_impose``), the zeroed rates
(``_inout_zero_rates``) and the end-of-step crossings, creations and removals (``_inout_update``),
timed by wrapping those methods; best of ``--rounds`` rounds of ``--steps`` steps, after advancing
the flow to ``--t0``.  Not a test.

    NUMBA_NUM_THREADS=2 python tools/bench_inout.py [--dp 0.005] [--steps 100] [--rounds 5]
"""
import argparse
import os
import sys
import tempfile
import time

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import numba  # noqa: E402
from click.testing import CliRunner  # noqa: E402

from sphdvi.cli import main  # noqa: E402
from sphdvi.io.casefile import read_case_h5  # noqa: E402
from sphdvi.run_options import apply_overrides  # noqa: E402
from sphdvi.simulation import SPHRun, find_case_file, special_parameters  # noqa: E402

CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "inout2d",
                    "CaseUniformChannel2D_Def.xml")
TIMED = ("_inout_impose", "_inout_zero_rates", "_inout_update")


def build(dp: float, tmp: str) -> SPHRun:
    r = CliRunner().invoke(main, ["gencase", CASE, "-o", tmp, "--dp", str(dp), "--quiet"])
    if r.exit_code:
        raise SystemExit(r.output)
    data = read_case_h5(find_case_file(tmp))
    return SPHRun(data, apply_overrides(special_parameters(data), []), tmp)


def main_() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dp", type=float, default=0.005)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--t0", type=float, default=0.05, help="time advanced before timing (s)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        sol = build(a.dp, tmp).solver
        spent = {name: 0.0 for name in TIMED}
        for name in TIMED:
            method = getattr(sol, name)

            def timed(*args, _m=method, _n=name, **kw):
                t = time.perf_counter()
                try:
                    return _m(*args, **kw)
                finally:
                    spent[_n] += time.perf_counter() - t
            setattr(sol, name, timed)
        sol.run(a.t0)
        best = None
        for _ in range(a.rounds):
            for name in TIMED:
                spent[name] = 0.0
            n0, t = sol.state.n, time.perf_counter()
            for _ in range(a.steps):
                sol.step()
            wall = time.perf_counter() - t
            if best is None or wall < best[0]:
                best = (wall, dict(spent), 0.5 * (n0 + sol.state.n))
        wall, shares, n = best
        zones = sum(shares.values())
        print(f"channel dp={a.dp:g}: {n:,.0f} particles, {numba.get_num_threads()} threads, {a.steps} steps")
        print(f"  step: {1e3 * wall / a.steps:.3f} ms, {1e6 * wall / a.steps / n:.3f} us per particle-step")
        print(f"  zones: {1e3 * zones / a.steps:.3f} ms a step ({100 * zones / wall:.1f} %): "
              + ", ".join(f"{k.lstrip('_')} {1e3 * v / a.steps:.3f} ms" for k, v in shares.items()))


if __name__ == "__main__":
    main_()

#!/usr/bin/env python
"""Cost of the DEM contacts (``RigidAlgorithm`` 2, sphdvi.sph.dem): cases/dem2d/CaseDemPile2D_Def.xml,
a 2D pile of 200 pvc blocks (5 x 5 particles, dp 0.01) dropped in rows onto a steel floor, with
(``--water``) or without water around them, Symplectic.

Prints microseconds per particle-step of the whole step and the share of the DEM pass (its two
calls a step: the contacts of every floating particle and the time-step maxima again), timed by
wrapping ``SPHSolver._dem_contacts``; best of ``--rounds`` rounds of ``--steps`` steps after
advancing to ``--t0`` (the pile settling: many contacts). Not a test.

    NUMBA_NUM_THREADS=1 python tools/bench_dem.py [--water] [--steps 200] [--rounds 5]
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
from sphdvi.simulation import SPHRun, find_case_file, special_parameters  # noqa: E402


CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "dem2d", "CaseDemPile2D_Def.xml")
WATER = ('<setmkfluid mk="0" /><fillbox x="0.01" y="0" z="0.01"><modefill>void</modefill>'
         '<point x="-0.01" y="-1" z="0.005" /><size x="1.3" y="2" z="0.38" /></fillbox></mainlist>')


def case_text(water: bool) -> str:
    """cases/dem2d/CaseDemPile2D_Def.xml, with water filled around the blocks up to z = 0.38 m when ``water``."""
    with open(CASE) as fh:
        text = fh.read()
    return text.replace("</mainlist>", WATER, 1) if water else text


def main_() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--water", action="store_true")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--t0", type=float, default=0.15, help="time advanced before timing (s)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "CasePile_Def.xml")
        with open(path, "w") as fh:
            fh.write(case_text(a.water))
        r = CliRunner().invoke(main, ["gencase", path, "-o", tmp, "--quiet"])
        if r.exit_code:
            raise SystemExit(r.output)
        data = read_case_h5(find_case_file(tmp))
        run = SPHRun(data, special_parameters(data), tmp)
        sol = run.solver
        wall, dem_time, dt = time_part(sol, sol, "_dem_contacts", a.t0, a.steps, a.rounds)
        n = sol.state.n
        nf = int((sol.state.ptype == 2).sum())
        print(f"DEM pile (cases/dem2d/CaseDemPile2D): {n:,} particles ({nf:,} floating, "
              f"{int((sol.state.ptype == 3).sum()):,} fluid), dt {dt:.3g} s, {numba.get_num_threads()} threads, "
              f"{a.steps} steps after t = {a.t0:g} s")
        print(f"  step: {1e3 * wall / a.steps:.3f} ms, {1e6 * wall / a.steps / n:.3f} us per particle-step")
        print(f"  DEM: {1e3 * dem_time / a.steps:.3f} ms a step ({100 * dem_time / wall:.1f} %), "
              f"{1e6 * dem_time / a.steps / (2 * max(nf, 1)):.3f} us per floating particle and pass (two a step)")


if __name__ == "__main__":
    main_()

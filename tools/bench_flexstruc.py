#!/usr/bin/env python
"""Cost of the flexible structures (``<special><flexstrucs>``, sphdvi.sph.flexstruc): the structure's
passes (its geometry F, P L before the interaction, the fluid's forces on it and its elastic forces
after it, its update) timed by wrapping ``FlexStruc.geometry``, ``SPHSolver._flex_forces`` and
``SPHSolver._flex_update``, in

* ``csm3``: cases/flexstruc2d/CaseTurekHronCSM3_Def.xml (the beam alone, no fluid), and
* ``dambreak``: cases/flexstruc2d/CaseDambreakFlexPlate2D_Def.xml (water and a plate), where the
  structure is a few hundred of thousands of particles: the price of having one.

Prints microseconds per particle-step of the whole step, the structure's share, and its cost per
flexible-structure particle and step; best of ``--rounds`` rounds of ``--steps`` steps after ``--t0``.
Not a test.

    NUMBA_NUM_THREADS=1 python tools/bench_flexstruc.py csm3 [--dp 0.0025] [--steps 2000] [--rounds 5]
    NUMBA_NUM_THREADS=1 python tools/bench_flexstruc.py dambreak [--dp 0.004]
"""
import argparse
import os
import sys
import tempfile

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))

import numba  # noqa: E402
from click.testing import CliRunner  # noqa: E402

from benchtiming import time_parts  # noqa: E402
from sphdvi.cli import main  # noqa: E402
from sphdvi.io.casefile import read_case_h5  # noqa: E402
from sphdvi.simulation import SPHRun, find_case_file, special_parameters  # noqa: E402

CASES = {"csm3": ("CaseTurekHronCSM3_Def.xml", 0.0025, 0.05), "dambreak": ("CaseDambreakFlexPlate2D_Def.xml", 0.004,
                                                                            0.02)}


def main_() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", choices=sorted(CASES))
    ap.add_argument("--dp", type=float)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--t0", type=float, help="time advanced before timing (s)")
    a = ap.parse_args()
    name, dp, t0 = CASES[a.scene]
    dp = a.dp or dp
    t0 = t0 if a.t0 is None else a.t0
    with tempfile.TemporaryDirectory() as tmp:
        r = CliRunner().invoke(main, ["gencase", os.path.join(HERE, "..", "cases", "flexstruc2d", name), "-o", tmp,
                                      "--dp", str(dp), "--quiet"])
        if r.exit_code:
            raise SystemExit(r.output)
        data = read_case_h5(find_case_file(tmp))
        run = SPHRun(data, special_parameters(data), tmp)
        sol = run.solver
        flex = sol.flex
        wall, part, dt = time_parts(sol, [(flex, "geometry"), (sol, "_flex_forces"), (sol, "_flex_update")],
                                    t0, a.steps, a.rounds)
        n = sol.state.n
        k = flex.size
        print(f"{a.scene} ({name}) at dp {dp:g}: {n:,} particles ({k:,} of the structure: "
              f"{int((~flex.clamp).sum()):,} flexible, {int(flex.clamp.sum()):,} clamp; "
              f"{int((sol.state.ptype == 3).sum()):,} fluid; {flex.pj.size / max(k, 1):.1f} pairs each), dt {dt:.3g} s, "
              f"{numba.get_num_threads()} threads, {a.steps} steps after t = {t0:g} s")
        print(f"  step: {1e3 * wall / a.steps:.3f} ms, {1e6 * wall / a.steps / n:.3f} us per particle-step")
        print(f"  structure: {1e3 * part / a.steps:.3f} ms a step ({100 * part / wall:.1f} %), "
              f"{1e6 * part / a.steps / k:.3f} us per structure particle and step")


if __name__ == "__main__":
    main_()

#!/usr/bin/env python
"""Cost of the DEM contacts (``RigidAlgorithm`` 2, sphdvi.sph.dem): a 2D pile of ``--bodies`` pvc
blocks (5 x 5 particles, dp 0.01) dropped in rows onto a steel floor, with (``--water``) or without
water around them, Symplectic.

Prints microseconds per particle-step of the whole step and the share of the DEM pass (its two
calls a step: the contacts of every floating particle and the time-step maxima again), timed by
wrapping ``SPHSolver._dem_contacts``; best of ``--rounds`` rounds of ``--steps`` steps after
advancing to ``--t0`` (the pile settling: many contacts). Not a test.

    NUMBA_NUM_THREADS=1 python tools/bench_dem.py [--bodies 200] [--water] [--steps 200] [--rounds 5]
"""
import argparse
import math
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
from sphdvi.simulation import SPHRun, find_case_file, special_parameters  # noqa: E402


def case_text(bodies: int, water: bool) -> str:
    """The pile: ``bodies`` blocks of 0.04 x 0.04 m in rows of 20, 6 cm apart, above a 1.3 m floor."""
    per_row = 20
    draw = []
    for k in range(bodies):
        x = 0.02 + 0.06 * (k % per_row) + (0.03 if (k // per_row) % 2 else 0.0)
        z = 0.03 + 0.06 * (k // per_row)
        draw.append(f'<setmkbound mk="{k + 1}" /><drawbox><boxfill>solid</boxfill><point x="{x:.2f}" y="-1" '
                    f'z="{z:.2f}" /><size x="0.04" y="2" z="0.04" /></drawbox>')
    top = 0.03 + 0.06 * ((bodies - 1) // per_row + 1)
    fluid = (f'<setmkfluid mk="0" /><fillbox x="0.01" y="0" z="0.01"><modefill>void</modefill>'
             f'<point x="-0.01" y="-1" z="0.005" /><size x="1.3" y="2" z="{top * 0.6:.2f}" /></fillbox>'
             if water else "")
    return f"""<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef>
  <constantsdef><gravity x="0" y="0" z="-9.81" /><rhop0 value="1000" /><hswl value="{top:.2f}" auto="false" />
    <gamma value="7" /><speedsystem value="0" auto="true" /><coefsound value="20" /><speedsound value="0" auto="true" />
    <coefh value="1.0" /><cflnumber value="0.2" /></constantsdef>
  <mkconfig boundcount="{bodies + 10}" fluidcount="9" />
  <geometry><definition dp="0.01"><pointmin x="-0.1" y="0" z="-0.1" /><pointmax x="1.4" y="0" z="{top + 0.5:.2f}" />
    </definition>
    <commands><mainlist><setshapemode>actual | dp | bound</setshapemode><setdrawmode mode="full" />
      <setmkbound mk="0" /><drawbox><boxfill>bottom | left | right</boxfill><point x="-0.02" y="-1" z="0" />
      <size x="1.32" y="2" z="{top + 0.2:.2f}" /></drawbox>{"".join(draw)}{fluid}</mainlist></commands></geometry>
  <floatings><floating mkbound="1-{bodies}" relativeweight="1.5" property="pvc" /></floatings>
  <properties>
    <property name="steel" Young_Modulus="2.1e11" PoissonRatio="0.3" Restitution_Coefficient="0.8" Kfric="0.45" />
    <property name="pvc" Young_Modulus="3.0e9" PoissonRatio="0.3" Restitution_Coefficient="0.6" Kfric="0.45" />
    <links><link mkbound="0" property="steel" /></links></properties>
</casedef>
<execution><parameters>
  <parameter key="StepAlgorithm" value="2" /><parameter key="Kernel" value="2" /><parameter key="ViscoTreatment" value="1" />
  <parameter key="Visco" value="0.01" /><parameter key="RigidAlgorithm" value="2" /><parameter key="FtPause" value="0" />
  <parameter key="TimeMax" value="10" /><parameter key="TimeOut" value="1" />
</parameters></execution></case>"""


def main_() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bodies", type=int, default=200)
    ap.add_argument("--water", action="store_true")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--t0", type=float, default=0.15, help="time advanced before timing (s)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "CasePile_Def.xml")
        with open(path, "w") as fh:
            fh.write(case_text(a.bodies, a.water))
        r = CliRunner().invoke(main, ["gencase", path, "-o", tmp, "--quiet"])
        if r.exit_code:
            raise SystemExit(r.output)
        data = read_case_h5(find_case_file(tmp))
        run = SPHRun(data, special_parameters(data), tmp)
        sol = run.solver
        spent = [0.0]
        dem = sol._dem_contacts

        def timed(*args):
            t = time.perf_counter()
            try:
                return dem(*args)
            finally:
                spent[0] += time.perf_counter() - t
        sol._dem_contacts = timed
        sol.run(a.t0)
        best = None
        for _ in range(a.rounds):
            spent[0] = 0.0
            t = time.perf_counter()
            for _ in range(a.steps):
                sol.step()
            wall = time.perf_counter() - t
            if best is None or wall < best[0]:
                best = (wall, spent[0], sol.last_dt)
        wall, dem_time, dt = best
        n = sol.state.n
        nf = int((sol.state.ptype == 2).sum())
        print(f"DEM pile: {a.bodies} blocks, {n:,} particles ({nf:,} floating, "
              f"{int((sol.state.ptype == 3).sum()):,} fluid), dt {dt:.3g} s, {numba.get_num_threads()} threads, "
              f"{a.steps} steps after t = {a.t0:g} s")
        print(f"  step: {1e3 * wall / a.steps:.3f} ms, {1e6 * wall / a.steps / n:.3f} us per particle-step")
        print(f"  DEM: {1e3 * dem_time / a.steps:.3f} ms a step ({100 * dem_time / wall:.1f} %), "
              f"{1e6 * dem_time / a.steps / (2 * max(nf, 1)):.3f} us per floating particle and pass (two a step)")


if __name__ == "__main__":
    main_()

#!/usr/bin/env python
"""Benchmark of gencase: a 3D box of 10^6 fluid particles (100^3) in an open tank.

Usage: python tools/bench_gencase.py [--n 100] [--repeat 3] [--keep DIR]

Prints the time of the drawing alone (sphdvi.case.draw.run_geometry) and of the
whole gencase (read + draw + constants + particles + outputs), the best of
``--repeat`` runs each. Target: whole gencase <= 5 s for n = 100.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

CASE = """<?xml version="1.0" encoding="UTF-8" ?>
<!-- benchmark: a {n}^3-particle water block in an open tank -->
<case>
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="0.866025" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="{dp}">
                <pointmin x="-0.05" y="-0.05" z="-0.05" />
                <pointmax x="{xmax}" y="{ymax}" z="{zmax}" />
            </definition>
            <commands>
                <mainlist>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="#Dp" y="#Dp" z="#Dp" />
                        <size x="#({n}-1)*Dp" y="#({n}-1)*Dp" z="#({n}-1)*Dp" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="0" z="0" />
                        <size x="#2*({n}+1)*Dp" y="#({n}+1)*Dp" z="#1.2*({n}+1)*Dp" />
                    </drawbox>
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="TimeMax" value="1" />
            <parameter key="TimeOut" value="0.1" />
        </parameters>
    </execution>
</case>
"""


def best_of(repeat, fn):
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def bench_draw(path, casedir):
    from sphdvi.case.draw import run_geometry
    from sphdvi.case.xmldoc import CaseReader, load_xml, strip_disabled
    root, _ = load_xml(path)
    strip_disabled(root)
    reader = CaseReader(path, base_dir=casedir)
    return run_geometry(reader, root.find("casedef/geometry"), casename="bench", outdir=None)


def bench_gencase(path, outdir):
    from sphdvi.case.gencase import build_case, write_outputs
    result = build_case(path, outdir)
    write_outputs(result, outdir)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="fluid particles per edge (default 100)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--keep", help="folder for the case and the outputs (default: a temp dir)")
    args = ap.parse_args()
    dp = 0.01
    casedir = args.keep or tempfile.mkdtemp(prefix="sphdvi_bench_")
    os.makedirs(casedir, exist_ok=True)
    path = os.path.join(casedir, "Bench_Def.xml")
    with open(path, "w") as fh:
        L = (args.n + 1) * dp
        fh.write(CASE.format(n=args.n, dp=dp, xmax=2 * L + 0.05, ymax=L + 0.05, zmax=1.2 * L + 0.1))
    t, d = best_of(args.repeat, lambda: bench_draw(path, casedir))
    print(f"draw (run_geometry): {t:.3f} s  fluid={d.count_fluid} bound={d.count_bound} "
          f"nodes={d.pos.shape[0]}")
    try:
        import sphdvi.case.gencase  # noqa: F401
    except ImportError as exc:
        print(f"whole gencase: not available ({exc})")
        return
    outdir = os.path.join(casedir, "out")
    t, r = best_of(args.repeat, lambda: bench_gencase(path, outdir))
    print(f"whole gencase (build_case + write_outputs): {t:.3f} s  -> {outdir}")


if __name__ == "__main__":
    main()

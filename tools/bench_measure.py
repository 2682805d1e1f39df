#!/usr/bin/env python
"""Benchmark of ``sphdvi measure points``: 100 points over 100 snapshots of 10^5 particles.

Target (issue 5): <= 5 s.  Writes a synthetic run folder (a 2D water column of
10^5 particles above a boundary layer, moving a little between snapshots) and
times :func:`sphdvi.measure.post.measure_points` (vel, rhop, press) after one
warm-up call (numba compilation / cache load is reported separately).

    python tools/bench_measure.py [--dir /tmp/bench_measure] [--n 100000] [--steps 100] [--points 100]
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def build(folder, n, steps):
    from sphdvi.io.casefile import write_case_h5
    from sphdvi.io.vtkhdf import VTKHDFParticleWriter
    from sphdvi.simulation import POINT_ARRAYS
    dp = 0.005
    nx = 500
    nz = n // nx
    x, z = np.meshgrid((np.arange(nx) + 0.5) * dp, (np.arange(nz) + 0.5) * dp, indexing="ij")
    fluid = np.stack([x.ravel(), np.zeros(x.size), z.ravel()], axis=1)
    bx = (np.arange(-3, nx + 3) + 0.5) * dp
    bottom = np.stack([np.repeat(bx, 3), np.zeros(3 * bx.size), np.tile([-0.5, -1.5, -2.5], bx.size) * dp], 1)
    pos = np.concatenate([bottom, fluid])
    nb, nf = bottom.shape[0], fluid.shape[0]
    ptype = np.concatenate([np.zeros(nb, np.uint8), np.full(nf, 3, np.uint8)])
    mk = np.where(ptype == 3, 1, 2).astype(np.int32)
    n_all = pos.shape[0]
    rhop = np.full(n_all, 1000.0)
    consts = {"dp": dp, "h": np.sqrt(2) * dp, "b": 1e5, "cs0": 20.0, "rhop0": 1000.0, "gamma": 7.0,
              "gravity": [0, 0, -9.81], "massfluid": 1000 * dp * dp, "massbound": 1000 * dp * dp,
              "is2d": True, "posy2d": 0.0}
    parts = {"pos": pos, "vel": np.zeros((n_all, 3)), "rhop": rhop, "mass": np.full(n_all, 1000 * dp * dp),
             "type": ptype, "mk": mk, "idp": np.arange(n_all, dtype=np.int64)}
    os.makedirs(folder, exist_ok=True)
    write_case_h5(os.path.join(folder, "Bench.h5"), casename="Bench", source_file="-", source_xml="<case/>",
                  version="bench", particles=parts, constants=consts, parameters={"Kernel": 2, "TimeOut": 0.01},
                  domain={"posmin": pos.min(0).tolist(), "posmax": pos.max(0).tolist()}, bodies=[],
                  json_items={"mkconfig": {"fluidcount": 1}})
    w = VTKHDFParticleWriter(os.path.join(folder, "particles.vtkhdf"), POINT_ARRAYS)
    rng = np.random.default_rng(0)
    for k in range(steps):
        p = pos.copy()
        p[nb:] += rng.uniform(-0.1, 0.1, (nf, 3)) * dp
        p[:, 1] = 0.0
        vel = rng.normal(size=(n_all, 3)) * 0.1
        w.append(0.01 * k, p, {"Idp": parts["idp"], "Vel": vel, "Rhop": rhop, "Press": np.zeros(n_all),
                               "Type": ptype, "Mk": mk})
    w.close()
    return dp * nx, dp * nz


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", default="/tmp/bench_measure")
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--points", type=int, default=100)
    ap.add_argument("--keep", action="store_true", help="keep the synthetic run folder")
    a = ap.parse_args()
    t0 = time.perf_counter()
    L, H = build(a.dir, a.n, a.steps)
    t_build = time.perf_counter() - t0
    from sphdvi.measure.post import RunOutput, measure_points
    run = RunOutput(a.dir)
    rng = np.random.default_rng(1)
    pts = np.column_stack([rng.uniform(0.05, L - 0.05, a.points), np.zeros(a.points),
                           rng.uniform(0.02, H - 0.02, a.points)])
    t0 = time.perf_counter()
    measure_points(run, pts[:2], last=0)                  # warm-up: numba compile / cache load
    t_warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    table, _ = measure_points(run, pts, ["vel", "rhop", "press"])
    t_run = time.perf_counter() - t0
    nsnap = table.time.shape[0]
    print(f"synthetic run: {a.n} fluid particles x {nsnap} snapshots written in {t_build:.2f} s")
    print(f"warm-up (numba compile or cache load): {t_warm:.2f} s")
    print(f"measure points: {a.points} points x {nsnap} snapshots of {a.n} particles: {t_run:.2f} s "
          f"({1e3 * t_run / nsnap:.1f} ms per snapshot; target <= 5 s: {'OK' if t_run <= 5 else 'SLOW'})")
    if not a.keep:
        import shutil
        shutil.rmtree(a.dir, ignore_errors=True)


if __name__ == "__main__":
    main()

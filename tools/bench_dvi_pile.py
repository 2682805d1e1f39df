#!/usr/bin/env python
"""Benchmark: a pile of 1,000 boxes (about 4,000 contacts) in the DVI engine.

Run single-threaded:  NUMBA_NUM_THREADS=1 python tools/bench_dvi_pile.py
Prints ms per step (collision + rows + solve + integration) and the contacts.
Target (issue 4): <= 20 ms/step at 50 PSOR iterations on one thread.
"""
import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from sphdvi.dvi import System  # noqa: E402


def build_pile(n_side=10, layers=10, half=0.05, gap=0.01, solver="psor", iters=50, seed=1):
    rng = np.random.default_rng(seed)
    s = System(gravity=(0, 0, -9.81), solver=solver, max_iter=iters, envelope=0.002)
    m = s.add_material("wood", friction=0.5)
    s.add_plane(material=m)
    I = (2 * half) ** 2 / 6.0
    pitch = 2 * half + gap
    for k in range(layers):
        for i in range(n_side):
            for j in range(n_side):
                x = (i - n_side / 2) * pitch + 0.001 * rng.standard_normal()
                y = (j - n_side / 2) * pitch + 0.001 * rng.standard_normal()
                z = half + k * (2 * half + 1e-4)
                b = s.add_body(1.0, (I, I, I), pos=(x, y, z))
                s.add_box(b, (half, half, half), material=m)
    return s


def build_heap(n_side=10, layers=10, half=0.05, solver="psor", iters=50, seed=2):
    """Randomly rotated boxes dropped in a loose lattice (a disordered pile
    once settled: vertex-face, edge-edge and face-face contacts)."""
    rng = np.random.default_rng(seed)
    s = System(gravity=(0, 0, -9.81), solver=solver, max_iter=iters, envelope=0.002)
    m = s.add_material("wood", friction=0.5)
    s.add_plane(material=m)
    for wall in range(4):  # a square bin so that the heap stays compact
        ang = wall * np.pi / 2
        nrm = (-np.cos(ang), -np.sin(ang), 0.0)
        s.add_plane(point=(0.6 * np.cos(ang), 0.6 * np.sin(ang), 0.0), normal=nrm, material=m)
    I = (2 * half) ** 2 / 6.0
    pitch = 0.12
    for k in range(layers):
        for i in range(n_side):
            for j in range(n_side):
                q = rng.normal(size=4)
                q /= np.linalg.norm(q)
                pos = ((i - (n_side - 1) / 2) * pitch, (j - (n_side - 1) / 2) * pitch, 0.1 + k * 0.16)
                b = s.add_body(1.0, (I, I, I), pos=pos, quat=q)
                s.add_box(b, (half, half, half), material=m)
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--side", type=int, default=10)
    ap.add_argument("--layers", type=int, default=10)
    ap.add_argument("--iters", type=int, default=50)
    ap.add_argument("--solver", default="psor")
    ap.add_argument("--settle", type=int, default=50)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--heap", action="store_true",
                    help="disordered heap: random orientations dropped into a bin and settled")
    a = ap.parse_args()
    if a.heap:
        s = build_heap(a.side, a.layers, solver=a.solver, iters=a.iters)
    else:
        s = build_pile(a.side, a.layers, solver=a.solver, iters=a.iters)
    t0 = time.perf_counter()
    s.step(a.dt)
    print(f"first step (includes numba JIT/cache load): {time.perf_counter() - t0:.2f} s")
    for _ in range(a.settle):
        s.step(a.dt)
    p0 = s.pos.copy()
    t0 = time.perf_counter()
    nc = []
    for _ in range(a.steps):
        s.step(a.dt)
        nc.append(s.n_contacts)
    dt = (time.perf_counter() - t0) / a.steps
    print(f"bodies={s.nb} contacts={int(np.mean(nc))} rows={s.n_rows} solver={a.solver} "
          f"iterations={a.iters} threads={os.environ.get('NUMBA_NUM_THREADS')}")
    print(f"{dt * 1e3:.2f} ms/step  (target <= 20 ms/step)")
    print(f"last solver residual {s.last_residual:.2e} m/s; max body displacement during the "
          f"timed steps {np.abs(s.pos - p0).max():.2e} m")


if __name__ == "__main__":
    main()

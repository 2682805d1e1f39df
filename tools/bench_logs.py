#!/usr/bin/env python
"""Cost of writing a row log (a gauge file) during a long run: rewriting the whole
file atomically at every output, as sphdvi did before, against appending the new
rows with one write call (sphdvi.io.atomic.append_text, what the run does now).

    python tools/bench_logs.py [--outputs 1000] [--rows 100]

Prints the total time and the time of the last output for each way.
"""
import argparse
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from sphdvi.io.atomic import append_text, write_text_atomic  # noqa: E402


def row_text(r):
    return ";".join([f"{r[0]:.15g}"] + [f"{v:.9g}" for v in r[1:]]) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--outputs", type=int, default=1000)
    ap.add_argument("--rows", type=int, default=100, help="rows added per output (computedt << TimeOut)")
    a = ap.parse_args()
    folder = tempfile.mkdtemp()
    for mode in ("rewrite whole file", "append new rows"):
        path = os.path.join(folder, "g.csv")
        write_text_atomic(path, "time [s];v1;v2;v3;v4;v5;v6\n")
        rows = []
        t_start = time.perf_counter()
        for out in range(1, a.outputs + 1):
            new = [[out + k / a.rows, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0] for k in range(a.rows)]
            t0 = time.perf_counter()
            if mode.startswith("rewrite"):
                rows += new
                write_text_atomic(path, "time [s];v1;v2;v3;v4;v5;v6\n" + "".join(row_text(r) for r in rows))
            else:
                append_text(path, "".join(row_text(r) for r in new))
            last = time.perf_counter() - t0
        print(f"{mode:20s}: {a.outputs} outputs x {a.rows} rows: total {time.perf_counter() - t_start:.2f} s, "
              f"last output {1e3 * last:.2f} ms")


if __name__ == "__main__":
    main()

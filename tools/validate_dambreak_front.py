"""S3 validation: the 2D dam-break front against Martin & Moyce (1952) at several resolutions.

Prints, for each dp, the particles, steps, wall time of the time stepping, the
largest and mean relative error of Z(T) for T in [1, 3] and the error of the
front speed. Usage: python tools/validate_dambreak_front.py [dp ...] [--threads N]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, REPO)
from sphdvi.validation.dambreak import front_errors, front_history, load_martin_moyce  # noqa: E402

CASE = os.path.join(REPO, "cases", "dambreak2d", "CaseDambreakVal2D_Def.xml")
REFERENCE = os.path.join(os.path.dirname(REPO), "shared", "reference")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dp", nargs="*", type=float, default=[0.04, 0.02])
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--tmax", type=float, default=0.72)
    args = ap.parse_args()
    ref = load_martin_moyce(REFERENCE)
    print(f"{'dp':>7} {'particles':>9} {'steps':>7} {'runtime_s':>9} {'max|err| %':>10} {'mean err %':>10} "
          f"{'speed err %':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for dp in args.dp:
            out = os.path.join(tmp, f"dp{dp}")
            subprocess.run([sys.executable, "-m", "sphdvi", "run", CASE, "-o", out, "--dp", str(dp), "--tmax",
                            str(args.tmax), "--tout", "0.01", "--threads", str(args.threads), "-q"], check=True)
            meta = json.load(open(os.path.join(out, "run.json")))
            t, x = front_history(out)
            _, rel, speed = front_errors(t, x, ref)
            print(f"{dp:7.4f} {meta['particles']:9d} {meta['steps']:7d} {meta['runtime_s']:9.1f} "
                  f"{100 * np.abs(rel).max():10.1f} {100 * rel.mean():10.1f} {100 * speed:11.1f}")


if __name__ == "__main__":
    main()

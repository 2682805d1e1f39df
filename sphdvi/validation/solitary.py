"""A solitary wave from a piston (``cases/waveflume2d/CaseWaveSolitary2D_Def.xml``, W6): Goring's
(1978) generation of H = 0.02 m in h = 0.1 m (:class:`sphdvi.motion.SolitaryPaddle`).  From the
run-time gauges WG1-WG3 (x = 1, 1.5, 2 m from the piston's front particles): the crest height
against H, the crest's arrival against the theory's (its crest leaving the piston when the
piston moves fastest, then at c = √(g(h + H))), the speed of the crest between WG1 and WG3
against c, and the rms difference from the theory's sech² profile over the wave (|η| > 1 % of H in
the theory), relative to H.  ``celerity_still_depth``: the crest speed against √(g(h₀ + H)) with h₀
the depth the gauges read in the still water, from the bottom wall's particle centres (z = 0) to the
kernel-sum surface: 0.7 dp above the top fluid particles, so that the SPH water stands deeper than the
case's h (0.107 m at dp 0.01, 0.1036 m at dp 0.005), which alone makes it run faster."""
from __future__ import annotations

import numpy as np

from .runs import gauge_table

GAUGES = {"WG1": 1.0, "WG2": 1.5, "WG3": 2.0}
STILL_UNTIL = 0.3          # s: the gauges' still-water reading, before the wave reaches WG1


def solitary_paddle(outdir: str):
    """The case's :class:`SolitaryPaddle`, as the run built it from the case file in ``outdir``."""
    import glob
    import os
    from ..io.casefile import read_case_h5
    from ..motion import SolitaryPaddle
    path = next(p for p in sorted(glob.glob(os.path.join(str(outdir), "*.h5"))) if not p.endswith("restart.h5"))
    data = read_case_h5(path)
    spec = next(p for p in data["json"]["special"]["wavepaddles"] if p["type"] == "piston_solitary")
    return SolitaryPaddle(spec, float(np.linalg.norm(data["constants"]["gravity"])))


def crest(t: np.ndarray, eta: np.ndarray) -> tuple[float, float]:
    """(time, height) of the highest reading, refined by a parabola through it and its neighbours."""
    i = int(np.clip(np.argmax(eta), 1, eta.size - 2))
    y0, y1, y2 = eta[i - 1], eta[i], eta[i + 1]
    den = y0 - 2 * y1 + y2
    s = 0.5 * (y0 - y2) / den if den < 0 else 0.0
    return float(t[i] + s * (t[i + 1] - t[i])), float(y1 - 0.25 * (y0 - y2) * s)


def solitary_errors(outdir: str) -> dict:
    paddle = solitary_paddle(outdir)
    wave = paddle.strokes[0]
    out, arrivals, still = {}, [], []
    for name, x in GAUGES.items():
        g = gauge_table(outdir, "SWL", name)
        t, z = g[:, 0], g[:, 3]
        still.append(np.mean(z[t <= STILL_UNTIL]))
        eta = z - still[-1]
        tc, hc = crest(t, eta)
        theory = paddle.elevation(x, t)
        xc, tc0 = wave.crest()
        t_theory = paddle.start + tc0 + (x - xc) / wave.c
        wet = theory > 0.01 * wave.H
        out[f"H_{name}"] = hc / wave.H - 1.0
        out[f"arrival_{name}"] = tc - t_theory
        out[f"rms_{name}"] = float(np.sqrt(np.mean((eta[wet] - theory[wet]) ** 2)) / wave.H)
        arrivals.append((x, tc))
    (x1, t1), (x3, t3) = arrivals[0], arrivals[-1]
    out["celerity"] = (x3 - x1) / (t3 - t1) / wave.c - 1.0
    out["still_depth"] = float(np.mean(still))
    out["celerity_still_depth"] = (x3 - x1) / (t3 - t1) / np.sqrt(paddle.g * (out["still_depth"] + wave.H)) - 1.0
    out["H_max"] = max(abs(out[f"H_{n}"]) for n in GAUGES)
    out["rms_max"] = max(out[f"rms_{n}"] for n in GAUGES)
    return out

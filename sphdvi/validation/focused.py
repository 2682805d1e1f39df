"""A focused wave group from a piston (``cases/waveflume2d/CaseWaveFocused2D_Def.xml``, W7): NewWave
(:class:`sphdvi.motion.FocusedPaddle`) of a JONSWAP sea state Hs = 0.03 m, Tp = 1.4 s in d = 0.3 m,
focused at x_f = 2 m.  From the run-time gauges WG1-WG3 (x = 1, 2, 2.5 m): the crest at the focus
(WG2) against the group's A = Σ a_i, its time against t_f, and at each gauge the rms difference from
the linear sum of the group's waves, relative to A, and their correlation, over two peak periods
either side of the theory's largest crest there.  The same group generated to second order
(``CaseWaveFocused2ndOrder2D_Def.xml``, W8) is scored against the group with its bound waves
(:meth:`FocusedPaddle.focus_crest`, :meth:`FocusedPaddle.elevation_at` to the paddle's order).  The elevation is the gauge's level less its
still-water reading before the group arrives."""
from __future__ import annotations

import numpy as np

from .runs import gauge_table
from .solitary import crest

GAUGES = {"WG1": 1.0, "WG2": 2.0, "WG3": 2.5}
FOCUS_GAUGE = "WG2"
STILL_UNTIL = 0.3          # s: the gauges' still-water reading, before the first waves reach WG1
WINDOW_PERIODS = 2.0       # the scored window: this many peak periods either side of the theory's crest


def focused_paddle(outdir: str):
    """The case's :class:`FocusedPaddle`, placed as the run placed it (its face from the particles)."""
    from ..motion import MotionSet
    from .runs import case_data
    data = case_data(outdir)
    js, p = data["json"], data["particles"]
    g = float(np.linalg.norm(data["constants"]["gravity"]))
    motions = MotionSet([], [w for w in js["special"]["wavepaddles"] if w["type"] == "piston_focused"], g)
    motions.place_paddles_from_particles(p, int(js["mkconfig"]["fluidcount"]))
    (paddle,) = motions.paddles.values()
    return paddle


def focused_errors(outdir: str) -> dict:
    paddle = focused_paddle(outdir)
    tp = float(paddle.spec["waveperiod"])
    crest_theory = paddle.focus_crest()
    out = {"crest_theory": crest_theory, "focus_time_theory": paddle.focus_time}
    for name, x in GAUGES.items():
        g = gauge_table(outdir, "SWL", name)
        t, z = g[:, 0], g[:, 3]
        eta = z - np.mean(z[t <= STILL_UNTIL])
        theory = paddle.elevation_at(x, t)
        peak = t[int(np.argmax(theory))]
        win = np.abs(t - peak) <= WINDOW_PERIODS * tp
        d = eta[win] - theory[win]
        out[f"rms_{name}"] = float(np.sqrt(np.mean(d * d)) / paddle.crest)
        out[f"corr_{name}"] = float(np.corrcoef(eta[win], theory[win])[0, 1])
        if name == FOCUS_GAUGE:
            tc, hc = crest(t[win], eta[win])
            out["crest"] = hc / crest_theory - 1.0
            out["focus_time"] = tc - paddle.focus_time
            out["trough"] = float(eta[win].min()) / float(theory[win].min()) - 1.0
    out["rms_max"] = max(out[f"rms_{n}"] for n in GAUGES)
    out["corr_min"] = min(out[f"corr_{n}"] for n in GAUGES)
    return out

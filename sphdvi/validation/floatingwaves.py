"""S16: a floating box in waves from a measured flap motion, against the measured box motion.

``cases/flapwaves2d/CaseFloatingWavesHadzic2D_Def.xml``: the flume of W3 (Hadzic et al. 2005,
"Computation of flow-induced motion of floating bodies", Appl. Math. Modelling 29:1196, as
DualSPHysics's CaseFloatingWavesVal sets it up) with its box, 0.1 x 0.05 m, relative density 0.68,
at x = 2.06-2.16 m.  The experiment recorded the box's heave [m], roll [degrees] and sway [m] from
t = 6.3 s to 8.13 s, one wave group's two highest waves (crests to 37 mm, the box rolling to 23°).

The run's box motion comes from bodies.csv (the floating body ``floating50``, every TimeOutExtra):
- heave: z of the box's centre less its rest height (the mean over ``REST``, settled from its
  drawn position before the first waves of any size reach it);
- roll: the turn about −y in degrees, counterclockwise when seen with the waves running to the
  right (−pitch of bodies.csv, whose angles turn right-handed about +y).  The experiment's file
  does not say its sense.  In this one its roll is negative where the surface falls towards the
  beach (the heave's up-crossings, 7.10 s): the box leans with the surface, as a box whose own
  roll period (~0.5-0.6 s) is shorter than the waves' (~1 s) does; the other sense would have it
  lean against the slope.  The SPH box does the same (correlation 0.54, 0.92 at its best lag of
  −0.1 s, at dp 0.01).  The amplitude scores do not depend on the sense;
- sway: x of the centre, both records taken from their value at the start of the experiment's
  record (its heave, roll and sway all start at zero there: a drift before 6.3 s, which the
  small first waves of the group give the box, is not in the experiment's record).

Each record is scored as the wave probes of W3 (:func:`flapwaves.probe_scores`): correlation,
rms ratio − 1 and the lag of best correlation on a uniform time grid over the experiment's span
within the run, the range (crest to trough) ratio − 1 over its samples.  The roll's rms at lag 0
penalises the SPH box's phase lead (correlation 0.51 at box/dp 10, 0.91 at −0.105 s): its range
is the steadier amplitude measure.  The experiment's roll may itself carry a ~0.1 s time-base
offset: it correlates best with −d(heave)/dt (the surface slope at a box short against the wave)
taken 0.10 s later (0.83; 0.50 at no lag), where the SPH roll is in phase with that slope; it was
digitised apart from the heave (its times rounded to 10 ms, not monotone).  Not provable from the
file: an observation, not corrected.
"""
from __future__ import annotations

import numpy as np

from .flapwaves import load_probe, probe_scores, wave_scores

BODY = "floating50"                 # the box: mkbound 50 of the case
RECORDS = {"heave": 2, "roll": 3, "sway": 4}    # record -> column pair in the experiment's file
REST = (1.0, 2.0)                   # s: the box's rest height is its mean over this window


def body_records(outdir: str, body: str = BODY) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{"heave" [m], "roll" [degrees, about −y], "sway" [m]}: (time, value) of the run's box,
    heave from its rest height, sway from x = its rest x (see the module's docstring)."""
    from .runs import body_log
    rows = body_log(outdir)
    rows = rows[rows["body"] == body]
    t = np.asarray(rows["time"], float)
    rest = (t >= REST[0]) & (t <= REST[1])
    if not rest.any():
        raise ValueError(f"{outdir}: bodies.csv has no rows of {body} within t = {REST} s")
    return {"heave": (t, rows["z"] - rows["z"][rest].mean()),
            "roll": (t, -np.asarray(rows["pitch"], float)),
            "sway": (t, rows["x"] - rows["x"][rest].mean())}


def from_start(t: np.ndarray, v: np.ndarray, t0: float) -> np.ndarray:
    """``v`` less its value at ``t0`` (linear interpolation)."""
    return v - np.interp(t0, t, v)


def body_scores(outdir: str, reference_dir: str, with_waves: bool = True) -> dict:
    """``heave_corr``, ``heave_rms``, ``heave_range``, ``heave_lag`` ... for heave, roll and sway;
    ``amp_max``: the largest |rms| and |range| (each a ratio − 1) of heave and roll (TOLERANCES
    S16: their amplitudes within 10–15 %); ``corr_min`` of heave and roll; with ``with_waves``,
    the wave gauges' scores of W3 as well (``wave_WP1_corr`` ...)."""
    sph = body_records(outdir)
    out: dict = {}
    for name, column in RECORDS.items():
        t_exp, v_exp = load_probe(reference_dir, column)
        t, v = sph[name]
        if name == "sway":
            t0 = t_exp[0]
            v, v_exp = from_start(t, v, t0), from_start(t_exp, v_exp, t0)
        s = probe_scores(t, v, t_exp, v_exp)
        out.update({f"{name}_{k}": val for k, val in s.items()})
    out["amp_max"] = max(abs(out[f"{n}_{k}"]) for n in ("heave", "roll") for k in ("rms", "range"))
    out["corr_min"] = min(out["heave_corr"], out["roll_corr"])
    if with_waves:
        out.update({f"wave_{k}": v for k, v in wave_scores(outdir, reference_dir).items()})
    return out

#!/usr/bin/env python
"""Error against run time: every SPH validation case of ``cases/`` at several resolutions.

Each case file runs through ``sphdvi run`` (a fresh process per resolution, as a user runs it)
and is scored against its analytic solution or experiment (TOLERANCES.md in
``../shared/reference``). One line per resolution: particles, steps, the wall time of the time
stepping (``runtime_s`` of run.json: without start-up and JIT), µs per particle-step, the errors
and whether they meet the target; after each case the observed order of its headline error
between successive resolutions, log(e1/e2)/log(dp1/dp2).

    python tools/validate.py                 # the fast cases (S1/S2, S3, S3M, S5, S5M, S7, S9, S10, S11, S12, S13, A1, W1, W2, W3, W5, W6, W7, W8, W10, W11, C3)
    python tools/validate.py S3 S7 --threads 2
    python tools/validate.py --all           # with the slow S4 (Lobovsky; dp 2.5 mm takes ~12 min on 2 threads), S8 (sloshing)
                                             # and S16 (floating box in waves; dp 0.02 ~2 min, dp 0.005 took 1 h 52 min on 2 threads);
                                             # S16M: S16 with mDBC on the box (dp 0.02, 0.01 and 0.005: 2, 25 and 107 min on 2 threads)
                                             # S16O: S16M with the box's normals from its outline, as GenCase's (dp 0.02, 0.01: ~2, 14 min)
                                             # S18: hinged buoyant flap (dp 0.04, 0.02, 0.01: 0.3, 1.5, 7 min on 2 threads)
                                             # S19: flexible plate hit by a dam break (dp 0.002: 9 min on 2 threads; dp 0.001 on request, 72 min)
                                             # S20: Turek & Hron's CSM3 beam (4, 8 particles across: 1, 4 min on 1 thread; 16 on request, ~17 min to 1 s)
                                             # W4: irregular waves (20 s; dp 0.02, 0.01: 5, ~30 min on 2 threads)
                                             # W9: W4's sea generated to second order (the same times)
    python tools/validate.py W3 --fine       # also the resolutions run only on request (W3 depth/dp 40, dp 0.01: ~15 min on 2 threads;
                                             # W10 H/dp 6, dp 0.005)
    python tools/validate.py S9 --csv s9.csv --keep runs/
    python tools/validate.py S16M --dp 0.02 --dp 0.01 --threads 2     # some of a case's resolutions
    python tools/validate.py S3 S7 --constant coefh=1.2                # the case files with another constant

Not a test: the pytest suite asserts the same figures (tests/validation, tests/sph).
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field, replace
from typing import Callable

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, REPO)
REFERENCE = os.path.join(os.path.dirname(REPO), "shared", "reference")


def case_path(folder: str, name: str) -> str:
    return os.path.join(REPO, "cases", folder, name)


MDBC_BOX = ["--set", "Boundary=2", "--set", "MdbcMkbound=50"]     # S16M: mDBC on the floating box only


@dataclass
class Resolution:
    label: str
    dp: float
    args: list = field(default_factory=list)     # extra `sphdvi run` options (--tmax, --set ...)
    scored: bool = True                          # False: coarser than the resolution TOLERANCES sets the target at
    on_request: bool = False                     # True: an hour or more; runs only when --dp names it or with --fine


@dataclass
class Case:
    """A validation case: its file, resolutions, scoring and targets.

    ``score(outdir) -> dict`` returns the errors of one run; ``columns`` are (header, key,
    format) of what is printed; ``headline`` the key whose observed order is printed;
    ``target(errors) -> bool`` whether TOLERANCES' target is met; ``target_text`` says it."""
    name: str
    title: str
    case: str
    resolutions: list | Callable      # Resolution rows, or a function returning them
    score: Callable
    columns: list
    headline: str
    target: Callable
    target_text: str
    slow: bool = False
    prepare: Callable | None = None   # prepare(outdir): edit the gencase output before the run (an initial field)


# ---- scoring of each case (the functions live in sphdvi.validation, shared with the tests) ----

def score_hydrostatic(outdir):
    from sphdvi.validation.hydrostatic import case_errors
    return case_errors(outdir)


def score_front(outdir):
    import numpy as np

    from sphdvi.validation.dambreak import (column_height_errors, column_height_history, front_errors, front_history,
                                            front_start_delay, load_column_height, load_front_record,
                                            load_martin_moyce)
    t, x = front_history(outdir)
    mm = load_martin_moyce(REFERENCE)
    _, rel, speed = front_errors(t, x, mm)
    _, rel_ko, _ = front_errors(t, x, load_front_record(REFERENCE, "Koshizuka & Oka 1996"))
    delay, shifted = front_start_delay(t, x, mm)
    tau, hrel = column_height_errors(*column_height_history(outdir, _case_dp(outdir)), load_column_height(REFERENCE))
    early = tau <= 1.85
    return {"front_max": float(np.abs(rel).max()), "front_min": float(rel.min()), "speed": float(speed),
            "ko_max": float(np.abs(rel_ko).max()),
            "delay": delay, "shifted": shifted,
            "height_early": float(np.abs(hrel[early]).max()), "height_max": float(np.abs(hrel).max())}


def score_accel_tank(outdir):
    from sphdvi.validation.acceltank import slope_errors
    return slope_errors(outdir)


def score_wave_flume(outdir):
    from sphdvi.validation.waveflume import wave_errors
    return wave_errors(outdir)


def score_irregular_waves(outdir):
    from sphdvi.validation.waveflume import irregular_errors
    return irregular_errors(outdir)


def score_flap_waves(outdir):
    from sphdvi.validation.flapwaves import wave_scores
    return wave_scores(outdir, REFERENCE)


def score_absorption(outdir):
    from sphdvi.validation.waveflume import absorption_errors
    return absorption_errors(outdir)


def score_solitary(outdir):
    from sphdvi.validation.solitary import solitary_errors
    return solitary_errors(outdir)


def score_focused(outdir):
    from sphdvi.validation.focused import focused_errors
    return focused_errors(outdir)


def _wave_flume_case(name, paddle, xml, finest=()):
    """W1/W2/W10: the same flume, waves and scoring, made by a piston, a flap or a relaxation zone;
    ``finest``: resolutions run on request only."""
    return Case(name, f"wave flume: {paddle}, regular waves H = 0.03 m, T = 1.2 s, d = 0.3 m",
                case_path("waveflume2d", xml),
                [Resolution("H/dp 1.5", 0.02), Resolution("H/dp 3", 0.01), *finest],
                score_wave_flume, [("H inc err %", "H_incident", PCT), ("refl %", "reflection", "{:.1f} %"),
                                   ("H WG1 %", "H_WG1", PCT), ("H WG3 %", "H_WG3", PCT),
                                   ("celerity %", "celerity", PCT), ("vs still depth %", "celerity_still_depth", PCT),
                                   ("refl (own k) %", "reflection_fitted_k", "{:.1f} %")],
                "H_incident", lambda e: abs(e["H_incident"]) <= 0.10,
                "incident wave height within 10 % of the target (judgement; DualSPHysics advises H/dp >= 10)")


def _irregular_case(name, title, xml, target):
    """W4/W9: the same flume and irregular sea, generated to first or second order (slow)."""
    return Case(name, title, case_path("waveflume2d", xml), [Resolution("Hs/dp 2", 0.02), Resolution("Hs/dp 4", 0.01)],
                score_irregular_waves, [("corr WG1", "WG1_corr", "{:.3f}"), ("corr WG3", "WG3_corr", "{:.3f}"),
                                        ("rms WG1 %", "WG1_rms", PCT), ("rms WG3 %", "WG3_rms", PCT),
                                        ("lag WG1 s", "WG1_lag", "{:+.2f}"), ("lag WG3 s", "WG3_lag", "{:+.2f}")],
                "rms_max", lambda e: e["corr_min"] >= 0.9 and e["rms_max"] <= 0.15, target, slow=True)


def _focused_case(name, title, xml, target):
    """W7/W8: the same flume and focused group, generated to first or second order."""
    return Case(name, title, case_path("waveflume2d", xml), [Resolution("A/dp 1.4", 0.02), Resolution("A/dp 2.8", 0.01)],
                score_focused, [("crest %", "crest", PCT), ("focus time s", "focus_time", "{:+.3f}"),
                                ("trough %", "trough", PCT), ("corr min", "corr_min", "{:.3f}"),
                                ("rms WG1 %A", "rms_WG1", PCT), ("rms WG2 %A", "rms_WG2", PCT),
                                ("rms WG3 %A", "rms_WG3", PCT)],
                "rms_max", lambda e: abs(e["crest"]) <= 0.10 and e["corr_min"] >= 0.9 and e["rms_max"] <= 0.15, target)


def _front_case(name, title, file):
    """S3/S3M: the dam-break front against Martin & Moyce, at a/dp 25 (not scored) and 50."""
    return Case(name, title, case_path("dambreak2d", file),
                [Resolution("a/dp 25", 0.04, ["--tmax", "0.72", "--tout", "0.01"], scored=False),
                 Resolution("a/dp 50", 0.02, ["--tmax", "0.72", "--tout", "0.01"])],
                score_front, [("Z max|err| %", "front_max", PCT), ("Z min err %", "front_min", PCT),
                              ("speed err %", "speed", PCT), ("K&O max|err| %", "ko_max", PCT),
                              ("ΔT start", "delay", "{:.3f}"),
                              ("Z err after ΔT %", "shifted", "{:.2f} %"), ("height τ≤1.85 %", "height_early", "{:.2f} %"),
                              ("height τ≤2.2 %", "height_max", "{:.2f} %")],
                "front_max", lambda e: e["front_max"] <= 0.05,
                "Z(T) within ±5 % for T in [1, 3] at a/dp >= 50 (judgement: the experiment's gate delays the surge)")


def _floating_waves_case(name, title, resolutions, file="CaseFloatingWavesHadzic2D_Def.xml"):
    """S16/S16M/S16O: the floating box in the Hadzic flume, scored on its heave, roll and sway (slow)."""
    return Case(name, title, case_path("flapwaves2d", file), resolutions,
                score_floating_waves, [("heave corr", "heave_corr", "{:.3f}"), ("heave rms %", "heave_rms", PCT),
                                       ("heave range %", "heave_range", PCT), ("roll corr", "roll_corr", "{:.3f}"),
                                       ("roll rms %", "roll_rms", PCT), ("roll range %", "roll_range", PCT),
                                       ("roll lag s", "roll_lag", "{:+.3f}"), ("sway range %", "sway_range", PCT),
                                       ("corr WP2", "wave_WP2_corr", "{:.3f}")],
                "amp_max", lambda e: e["amp_max"] <= 0.15,
                "heave and roll amplitudes (rms and crest to trough over the record) within 10-15 %", slow=True)


def score_sloshing_impact(outdir):
    from sphdvi.validation.sloshing_impact import impact_errors
    return impact_errors(outdir, REFERENCE)


def _case_dp(outdir):
    from sphdvi.validation.runs import case_data
    return float(case_data(outdir)["constants"]["dp"])


def score_lobovsky(outdir):
    from sphdvi.validation import lobovsky
    levels = lobovsky.level_errors(outdir, REFERENCE)
    press = lobovsky.pressure_scores(outdir, REFERENCE)
    out = {f"level_{k}": v for k, v in levels.items()}
    out["level_max"] = max(levels.values())
    out["impact_max"] = max(abs(ti - te) for n, (ti, te, _, _) in press.items() if n != "P4")
    out["plateau_max"] = max(abs(ps / pe - 1) for n, (_, _, ps, pe) in press.items() if n != "P4")
    ti, te, ps, pe = press["P4"]
    out["plateau_P4"] = ps / pe - 1
    return out


def score_sloshing(outdir):
    from sphdvi.validation.sloshing import case_periods
    r = case_periods(outdir)
    return {"period": r["period_com"] / r["period_theory"] - 1, "decay": r["decay"]}


def score_poiseuille(outdir):
    from sphdvi.validation.poiseuille import case_errors
    return case_errors(outdir)


def score_floating_waves(outdir):
    from sphdvi.validation.floatingwaves import body_scores
    return body_scores(outdir, REFERENCE)


def score_buchner(outdir):
    from sphdvi.validation.buchner import case_errors
    return case_errors(outdir, REFERENCE)


def _buchner_case(name, title, file):
    """S5 / S5M: the Buchner (2002) wall pressure at H/dp 30 and 60."""
    return Case(name, title, case_path("dambreak2d", file), [Resolution("H/dp 30", 0.02), Resolution("H/dp 60", 0.01)],
                score_buchner, [("impact ΔT", "impact", "{:+.3f}"), ("level T 3-5 %", "plateau", PCT),
                                ("2nd peak ΔT", "peak_T", "{:+.3f}"), ("2nd peak %", "peak", PCT)],
                "plateau", lambda e: e["meets"],
                "impact within ±0.1 in T, level over T = 3-5 within 20 %, second peak within ±0.15 in T (judgement)")


def score_hinged_flap(outdir):
    from sphdvi.validation.hingedflap import case_errors
    return case_errors(outdir)


def score_flex_obstacle(outdir):
    from sphdvi.validation.flexobstacle import case_errors
    return case_errors(outdir, REFERENCE)


def score_csm3(outdir):
    from sphdvi.validation.csm3 import case_errors
    return case_errors(outdir)


def score_cylinder(outdir):
    from sphdvi.validation.cylinder import case_errors
    return case_errors(outdir, REFERENCE)


def score_taylor_green(outdir):
    from sphdvi.validation.taylorgreen import case_errors
    return case_errors(outdir)


def prepare_taylor_green(outdir):
    from sphdvi.validation.taylorgreen import impose_initial_field
    impose_initial_field(outdir)


def score_floating(outdir):
    from sphdvi.validation.floating import draft_errors
    return draft_errors(outdir)


def score_slider(outdir):
    from sphdvi.validation.floating import draft_errors, slider_reactions
    return {**draft_errors(outdir, x0=0.3), **slider_reactions(outdir)}


def _resolutions(module: str, attr: str = "RESOLUTIONS") -> Callable:
    """A validation module's RESOLUTIONS ({"label", "dp", "set": [...]}) as Resolution rows
    (imported when the case runs)."""
    def rows():
        import importlib
        table = getattr(importlib.import_module(f"sphdvi.validation.{module}"), attr)
        return [Resolution(r["label"], r["dp"], [a for kv in r.get("set", []) for a in ("--set", kv)]
                           + list(r.get("args", [])), r.get("scored", True)) for r in table]
    return rows


PCT = "{:+.2f} %"


def cases() -> list:
    return [
        Case("S1", "hydrostatic tank and still water (S1/S2)",
             case_path("hydrostatic2d", "CaseHydrostatic2D_Def.xml"), _resolutions("hydrostatic"),
             score_hydrostatic,
             [("p err max %", "rel_max", PCT), ("|p-p0|/ρgH %", "einf", PCT), ("max|u|/√gH", "umax", "{:.1e}"),
              ("Δz_cm/dp", "dzcm", "{:+.1e}")],
             "einf", lambda e: e["rel_max"] <= 0.02 and e["umax"] <= 1e-3 and e.get("lost", 0) == 0,
             "pressure within 2 %, max|u| <= 1e-3 √(gH), nothing lost"),
        _front_case("S3", "dam-break front vs Martin & Moyce (1952)", "CaseDambreakVal2D_Def.xml"),
        _front_case("S3M", "S3 with mDBC: three wall layers, normals from the tank's outline (norgeometry)",
                    "CaseDambreakMdbc2D_Def.xml"),
        Case("S4", "Lobovsky et al. (2014) dam break: levels and wall pressure",
             case_path("lobovsky2d", "CaseLobovsky2D_Def.xml"),
             [Resolution("H/dp 60", 0.005), Resolution("H/dp 120", 0.0025)],
             score_lobovsky, [("level max %", "level_max", PCT), ("H3 %", "level_H3", PCT),
                              ("impact |ΔT| P1-3", "impact_max", "{:.3f}"), ("p level P1-3 %", "plateau_max", PCT),
                              ("p level P4 %", "plateau_P4", PCT)],
             "level_max", lambda e: e["level_max"] <= 0.10 and e["impact_max"] <= 0.05 and e["plateau_max"] <= 0.20,
             "levels within 10 %, first impact ±0.05, quasi-static pressure within 20 % (sensors 1-3)",
             slow=True),
        _buchner_case("S5", "dam break, pressure on the downstream wall vs Buchner (2002)", "CaseBuchner2D_Def.xml"),
        _buchner_case("S5M", "S5 with mDBC: three wall layers, normals from the tank's outline (norgeometry)",
                      "CaseBuchnerMdbc2D_Def.xml"),
        Case("S7", "standing wave, sloshing mode 1 vs linear theory",
             case_path("standingwave2d", "CaseStandingWave2D_Def.xml"),
             [Resolution("d/dp 20", 0.025, scored=False), Resolution("d/dp 40", 0.0125)],
             score_sloshing, [("period err %", "period", PCT), ("loss/period %", "decay", "{:.2f} %")],
             "period", lambda e: abs(e["period"]) <= 0.02 and e["decay"] <= 0.05,
             "period within 1-2 %, amplitude loss <= ~5 %/period, at d/dp >= 40"),
        Case("S9", "Poiseuille flow, laminar viscosity",
             case_path("poiseuille2d", "CasePoiseuille2D_Def.xml"), _resolutions("poiseuille"),
             score_poiseuille, [("centre-line err %", "centreline", PCT), ("transient err %", "transient", "{:.2f} %")],
             "centreline", lambda e: abs(e["centreline"]) <= 0.01 and e.get("transient", 0) <= 0.02,
             "steady centre-line speed within 1 %, transient within 2 %"),
        Case("S10", "Poiseuille flow, artificial viscosity",
             case_path("poiseuille2d", "CasePoiseuille2D_Def.xml"), _resolutions("poiseuille", "RESOLUTIONS_S10"),
             score_poiseuille, [("vs α h c0/8 %", "centreline", PCT),
                                ("vs operator %", "centreline_vs_prediction", PCT)],
             "centreline_vs_prediction", lambda e: abs(e["centreline_vs_prediction"]) <= 0.10,
             "within ~10 % of ν_eff (here the operator's own prediction, 0.43 α h c0/8: "
             "DualSPHysics's term acts on approaching pairs only)"),
        Case("S11", "Taylor-Green vortex, Re = 100, periodic, with shifting",
             case_path("taylorgreen2d", "CaseTaylorGreen2D_Def.xml"), _resolutions("taylorgreen"),
             score_taylor_green, [("decay rate %", "rate_error", PCT), ("E max err %", "energy_error", "{:.2f} %"),
                                  ("u err (t end) %", "velocity_error", "{:.2f} %")],
             "rate_error", lambda e: abs(e["rate_error"]) <= 0.05 and e["monotone"] and e["fluid_lost"] == 0,
             "kinetic-energy decay rate within 5 % of 16π²ν/L², energy monotone, at 100² particles",
             prepare=prepare_taylor_green),
        Case("S13", "heavy cylinder released at the free surface vs Fekken (2004) and Moyo & Greenhow (2000)",
             case_path("cylinder2d", "CaseCylinderSinking2D_Def.xml"),
             [Resolution("R/dp 10", 0.1), Resolution("R/dp 20", 0.05)],
             score_cylinder, [("vs Fekken %", "Fekken", "{:.1f} %"), ("vs Moyo %", "Moyo", "{:.1f} %"),
                              ("T=3 vs Fekken %", "at3_Fekken", PCT)],
             "Fekken", lambda e: e["Fekken"] <= 0.10 and e["Moyo"] <= 0.10,
             "displacement up to T = 3 within 5-10 % of both references (largest error over T = 0.5-3)"),
        Case("S18", "hinged buoyant flap in still water (Chrono link_hinge with a spring): equilibrium tilt",
             case_path("hingedflap2d", "CaseHingedFlap2D_Def.xml"),
             [Resolution("dp 0.04", 0.04, scored=False), Resolution("dp 0.02", 0.02), Resolution("dp 0.01", 0.01)],
             score_hinged_flap, [("tilt err °", "tilt_error", "{:+.2f}"), ("reaction %", "reaction_error", PCT),
                                 ("horizontal %", "reaction_x", PCT), ("torque %", "torque_error", PCT)],
             "tilt_error", lambda e: abs(e["tilt_error"]) <= 1.0,
             "settled tilt within 1° of F r_c sin φ = K (φ0 − φ)", slow=True),
        Case("S19", "dam break through a lifted gate against a flexible plate (Liao et al. 2015): ten trunks on "
             "link_hinge springs EI/dz, Marker 1's displacement",
             case_path("flexobstacle2d", "CaseFlexibleObstacle2D_Def.xml"),
             [Resolution("dp 0.002", 0.002, ["--tmax", "0.8"]),
              Resolution("dp 0.001", 0.001, ["--tmax", "0.8"], on_request=True)],
             score_flex_obstacle, [("plateau %", "plateau", PCT), ("peak %", "peak", PCT),
                                   ("arrival s", "arrival", "{:+.3f}"), ("rms %peak", "rms", "{:.1f} %"),
                                   ("corr", "corr", "{:.3f}"), ("vs DSPH plateau %", "dsph_plateau", PCT)],
             "plateau", lambda e: abs(e["plateau"]) <= 0.20 and abs(e["arrival"]) <= 0.02,
             "the plate's deflection under the running water (t = 0.35-0.70 s) within 20 % of the experiment's and "
             "its arrival within 0.02 s (judgement: DualSPHysics's run of this model is 14 % low, Sun et al.'s SPH "
             "17 %)", slow=True),
        Case("S20", "Turek & Hron's CSM3: an elastic beam (flexible structure, total Lagrangian SPH) clamped in a "
             "cylinder swings under its weight; point A's displacement",
             case_path("flexstruc2d", "CaseTurekHronCSM3_Def.xml"),
             [Resolution("4 across", 0.005, ["--tmax", "2.5"]), Resolution("8 across", 0.0025, ["--tmax", "2"]),
              Resolution("16 across", 0.00125, ["--tmax", "1", "--tout", "0.01"], on_request=True)],
             score_csm3, [("uz mean %", "uz_mean", PCT), ("uz amp %", "uz_amp", PCT), ("ux mean %", "ux_mean", PCT),
                          ("freq %", "frequency", PCT)],
             "uz_mean", lambda e: abs(e["uz_mean"]) <= 0.25 and abs(e["frequency"]) <= 0.10,
             "point A's mean deflection within 25 % and the frequency within 10 % at 8 particles across the beam "
             "(judgement: total Lagrangian SPH converges at first order in dp/thickness)", slow=True),
        Case("A1", "tank under an imposed acceleration a_x = 0.1 g (<accinputs>): free-surface slope",
             case_path("acceltank2d", "CaseAccelTank2D_Def.xml"),
             [Resolution("depth/dp 15", 0.02), Resolution("depth/dp 30", 0.01)],
             score_accel_tank, [("slope err %", "slope_mean", PCT), ("swing %", "slope_swing", "{:.1f} %")],
             "slope_mean", lambda e: abs(e["slope_mean"]) <= 0.02,
             "steady slope (t = 4.5-7 s, the first sloshing mode fitted out) within 2 % of a_x/g (statics; judgement)"),
        Case("S8", "sloshing impacts, SPHERIC Test 10 (low filling): left-wall pressure",
             case_path("sloshing2d", "CaseSloshingTest10_2D_Def.xml"),
             [Resolution("depth/dp 12", 0.008), Resolution("depth/dp 23", 0.004)],
             score_sloshing_impact, [("impact max %T", "dt_max", "{:.2f} %"), ("dt1 %T", "dt1", "{:+.2f} %"),
                                     ("dt4 %T", "dt4", "{:+.2f} %"), ("peak max %", "peak_max", "{:.0f} %")],
             "dt_max", lambda e: e["dt_max"] <= 0.03 and e["peak_max"] <= 0.30,
             "impact times within 3 % (here of the roll period), peaks within 20-30 %", slow=True),
        _wave_flume_case("W1", "piston", "CaseWaveFlume2D_Def.xml"),
        _wave_flume_case("W2", "flap hinged at the bottom", "CaseWaveFlap2D_Def.xml"),
        Case("W5", "absorbing piston (<awas_zsurf>, DualSPHysics's AWAS) in the W1 flume closed by a wall",
             case_path("waveflume2d", "CaseWaveAwas2D_Def.xml"),
             [Resolution("H/dp 1.5", 0.02), Resolution("H/dp 3", 0.01)],
             score_absorption, [("R paddle", "reflection", "{:.3f}"), ("R theory", "reflection_theory", "{:.3f}"),
                                ("R spread", "reflection_spread", "{:.3f}"), ("H inc err %", "H_incident", PCT),
                                ("H before %", "H_before", PCT), ("H back/H", "H_returning", "{:.2f}")],
             "reflection", lambda e: abs(e["reflection"] - e["reflection_theory"]) <= 0.1
             and abs(e["H_incident"]) <= 0.10,
             "the paddle reflects what linear theory says its absorber should (within 0.1; a still piston: 1), "
             "and the wave leaving it stays within 10 % of H (judgement)"),
        _wave_flume_case("W10", "relaxation zone (<relaxationzones><rzwaves_regular>, Altomare et al. 2018) on the "
                         "closed end", "CaseWaveRelaxZone2D_Def.xml", [Resolution("H/dp 6", 0.005, on_request=True)]),
        Case("W11", "relaxation zone in the W5 flume closed by a wall: the zone takes out the wave coming back",
             case_path("waveflume2d", "CaseWaveRelaxZoneWall2D_Def.xml"),
             [Resolution("H/dp 1.5", 0.02), Resolution("H/dp 3", 0.01)],
             score_absorption, [("R zone", "reflection", "{:.3f}"), ("R spread", "reflection_spread", "{:.3f}"),
                                ("H inc err %", "H_incident", PCT), ("H before %", "H_before", PCT),
                                ("H back/H", "H_returning", "{:.2f}")],
             "reflection", lambda e: e["reflection"] <= 0.1 and abs(e["H_incident"]) <= 0.10,
             "the zone reflects at most 10 % of the wave coming back (a still wall: 1), and the wave leaving it "
             "stays within 10 % of H (judgement)"),
        Case("W6", "solitary wave from a piston (<piston_solitary>, Goring 1978: H = 0.02 m in h = 0.1 m)",
             case_path("waveflume2d", "CaseWaveSolitary2D_Def.xml"),
             [Resolution("h/dp 10", 0.01), Resolution("h/dp 20", 0.005)],
             score_solitary, [("H max|err| %", "H_max", PCT), ("H WG1 %", "H_WG1", PCT), ("H WG3 %", "H_WG3", PCT),
                              ("celerity %", "celerity", PCT), ("vs still depth %", "celerity_still_depth", PCT),
                              ("arrival WG1 s", "arrival_WG1", "{:+.3f}"),
                              ("arrival WG3 s", "arrival_WG3", "{:+.3f}"), ("rms max %H", "rms_max", PCT)],
             "H_max", lambda e: e["H_max"] <= 0.10 and abs(e["celerity"]) <= 0.03,
             "crest height within 10 % of H at the three gauges and crest speed within 3 % of sqrt(g(h + H)) "
             "(judgement, as W1)"),
        _focused_case("W7", "focused wave group from a piston (<piston_focused>, NewWave of JONSWAP Hs = 0.03 m, "
                      "Tp = 1.4 s in d = 0.3 m, focused at x = 2 m)", "CaseWaveFocused2D_Def.xml",
                      "crest at the focus within 10 % of the group's A, elevation against the linear group: "
                      "correlation >= 0.9, rms within 15 % of A (judgement, as W1 and W4)"),
        _focused_case("W8", "W7's focused wave group generated to second order (<piston_focused> waveorder 2)",
                      "CaseWaveFocused2ndOrder2D_Def.xml",
                      "as W7, against the group with its bound waves (second-order theory): crest within 10 %, "
                      "correlation >= 0.9, rms within 15 % of A (judgement, as W7)"),
        _irregular_case("W4", "irregular waves from a piston (<piston_spectrum>: JONSWAP Hs = 0.04 m, Tp = 1.4 s, "
                        "d = 0.3 m)", "CaseWaveIrregular2D_Def.xml",
                        "surface elevation against the linear sum of the sea state's waves: correlation >= 0.9, rms "
                        "within 15 % (judgement, as W3)"),
        _irregular_case("W9", "W4's irregular sea generated to second order (<piston_spectrum> waveorder 2)",
                        "CaseWaveIrregular2ndOrder2D_Def.xml",
                        "as W4, against the sea state to second order (the linear waves and their bound waves)"),
        Case("W3", "waves from a measured flap motion (Hadzic et al. 2005 flume): wave probes",
             case_path("flapwaves2d", "CaseFlapWavesHadzic2D_Def.xml"),
             [Resolution("depth/dp 10", 0.04), Resolution("depth/dp 20", 0.02),
              Resolution("depth/dp 40", 0.01, on_request=True)],
             score_flap_waves, [("corr WP1", "WP1_corr", "{:.3f}"), ("corr WP2", "WP2_corr", "{:.3f}"),
                                ("rms WP1 %", "WP1_rms", PCT), ("rms WP2 %", "WP2_rms", PCT),
                                ("lag WP1 s", "WP1_lag", "{:+.3f}"), ("lag WP2 s", "WP2_lag", "{:+.3f}")],
             "rms_max", lambda e: e["corr_min"] >= 0.9 and e["rms_max"] <= 0.15,
             "correlation with the measured probes >= 0.9, rms within 15 % (judgement; no published target)"),
        _floating_waves_case("S16", "floating box in waves from a measured flap motion (Hadzic et al. 2005): "
                             "heave, roll, sway", [Resolution("box/dp 5", 0.02), Resolution("box/dp 10", 0.01),
                                                   Resolution("box/dp 20", 0.005)]),
        _floating_waves_case("S16M", "S16 with mDBC on the box only (--set Boundary=2 --set MdbcMkbound=50; "
                             "walls and flap DBC)",
                             [Resolution("box/dp 5", 0.02, MDBC_BOX), Resolution("box/dp 10", 0.01, MDBC_BOX),
                              Resolution("box/dp 20", 0.005, MDBC_BOX)]),
        _floating_waves_case("S16O", "S16 with mDBC on the box, its normals from its outline as GenCase's "
                             "(norgeometry; CaseFloatingWavesHadzicOutline2D_Def.xml)",
                             [Resolution("box/dp 5", 0.02), Resolution("box/dp 10", 0.01)],
                             "CaseFloatingWavesHadzicOutline2D_Def.xml"),
        Case("S12", "floating box in still water (ρb/ρw = 0.5)",
             case_path("floatingbox2d", "CaseFloatingBox2D_Def.xml"),
             [Resolution("box/dp 10", 0.02, ["--tmax", "1.5", "--tout", "0.05"]),
              Resolution("box/dp 20", 0.01, ["--tmax", "1.5", "--tout", "0.05"])],
             score_floating, [("draft err dp", "draft_dp", "{:+.2f}"), ("drift dp", "drift_dp", "{:.3f}"),
                              ("tilt °", "tilt_deg", "{:.3f}")],
             "draft_dp", lambda e: abs(e["draft_dp"]) <= 0.5 and e["drift_dp"] < 0.1 and e["tilt_deg"] < 1.0,
             "draft within 0.5 dp, no drift, upright"),
        Case("C3", "TOLERANCES' coupled check (c): the S12 box off centre on a vertical slider (link_pointline)",
             case_path("floatingbox2d", "CaseSliderBox2D_Def.xml"),
             [Resolution("box/dp 10", 0.02), Resolution("box/dp 20", 0.01)],
             score_slider, [("draft err dp", "draft_dp", "{:+.2f}"), ("fx / W %", "fx_w", PCT),
                            ("|fx| max / W %", "fx_max_w", "{:.2f} %"), ("ty / (W b/2) %", "ty_wb", PCT)],
             "fx_w", lambda e: abs(e["draft_dp"]) <= 0.5 and abs(e["fx_w"]) < 0.01 and abs(e["ty_wb"]) < 0.01,
             "the free-floating draft within 0.5 dp; the slider's lateral reaction and torque ~0 (within 1 %)"),
    ]


# ---- running ----

# <constantsdef> entries that say the same thing: setting one removes the others
_SMOOTHING_LENGTH = ("coefh", "hdp", "coefhdp", "h")


def case_with_constants(path: str, constants: dict) -> str:
    """A copy of the case file with ``<constantsdef>`` values replaced (``{"coefh": "1.2"}``),
    written beside it so that its relative paths (motion files, meshes) still hold; the caller
    deletes it. An entry that is missing is added; one with ``auto="true"`` is turned to the
    given value; setting one way of giving h (coefh, hdp, coefhdp, h) removes the others."""
    from lxml import etree
    tree = etree.parse(path)
    cdef = tree.find(".//casedef/constantsdef")
    if cdef is None:
        raise SystemExit(f"{path}: no <casedef><constantsdef> to set {', '.join(constants)} in")
    for name, value in constants.items():
        if name in _SMOOTHING_LENGTH:
            for el in [e for other in _SMOOTHING_LENGTH if other != name for e in cdef.findall(other)]:
                cdef.remove(el)
        el = cdef.find(name)
        if el is None:
            el = etree.SubElement(cdef, name)
        el.set("value", value)
        if "auto" in el.attrib:
            el.set("auto", "false")
    folder, base = os.path.split(path)
    stem = base[:-len("_Def.xml")] if base.endswith("_Def.xml") else os.path.splitext(base)[0]
    out = os.path.join(folder, f"{stem}_validate{os.getpid()}_Def.xml")
    tree.write(out, xml_declaration=True, encoding="UTF-8")
    return out


def parse_constants(items: list | None, parser) -> dict:
    """``NAME=VALUE`` options into a dict (names lower case, as <constantsdef> spells them)."""
    from sphdvi.case.parameters import CONSTANTS
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        name = name.strip().lower()
        if not sep or not value.strip():
            parser.error(f"--constant {item}: expected NAME=VALUE, e.g. coefh=1.2")
        if name not in CONSTANTS or name in ("gravity", "lattice"):
            parser.error(f"--constant {item}: {name} is not a single-valued <constantsdef> entry "
                         f"(one of {', '.join(sorted(CONSTANTS - {'gravity', 'lattice'}))})")
        out[name] = value.strip()
    return out


def run_case(case: Case, res: Resolution, outdir: str, threads: int) -> dict:
    """Run one resolution through the CLI; return run.json's figures (status, particles, steps,
    runtime_s, us_per_particle_step, threads_used) and the wall time of the whole command."""
    cmd = [sys.executable, "-m", "sphdvi", "run", case.case, "-o", outdir, "--dp", repr(res.dp),
           "--threads", str(threads), "-q", "--overwrite"] + res.args
    t0 = time.perf_counter()
    if case.prepare is not None:                   # gencase, the case's own initial field, then run the folder
        proc = subprocess.run([sys.executable, "-m", "sphdvi", "gencase", case.case, "-o", outdir, "--dp", repr(res.dp),
                               "-q", "--overwrite"], capture_output=True, text=True)
        if proc.returncode == 0:
            case.prepare(outdir)
            cmd = [sys.executable, "-m", "sphdvi", "run", outdir, "--threads", str(threads), "-q", "--overwrite"] + res.args
    if case.prepare is None or proc.returncode == 0:
        proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    meta = {}
    path = os.path.join(outdir, "run.json")
    if os.path.isfile(path):
        with open(path) as f:
            meta = json.load(f)
    if proc.returncode != 0:
        meta.setdefault("message", proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else "")
    return {"rc": proc.returncode, "status": meta.get("status", "failed"), "particles": meta.get("particles", 0),
            "steps": meta.get("steps", 0), "runtime_s": meta.get("runtime_s", float("nan")),
            "us": meta.get("us_per_particle_step", float("nan")), "threads_used": meta.get("threads_used", 0),
            "command_s": wall,
            "message": meta.get("message", "")}


def observed_order(rows: list, key: str) -> list:
    """log(e_k/e_k+1) / log(dp_k/dp_k+1) between successive resolutions of one case."""
    out = []
    for a, b in zip(rows, rows[1:]):
        ea, eb = abs(a["errors"].get(key, math.nan)), abs(b["errors"].get(key, math.nan))
        ok = ea > 0 and eb > 0 and math.isfinite(ea) and math.isfinite(eb)
        out.append(math.log(ea / eb) / math.log(a["dp"] / b["dp"]) if ok else math.nan)
    return out


def fmt(spec: str, value) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return spec.format(100 * value) if spec.endswith("%") else spec.format(value)


def case_names(every) -> list[str]:
    """The names the command line takes, in the order of ``cases()``; S2 is S1's run."""
    return [n for c in every for n in ((c.name, "S2") if c.name == "S1" else (c.name,))]


def slow_names(every) -> list[str]:
    """The slow cases: left out by default, run by ``--all`` or by name."""
    return [c.name for c in every if c.slow]


def _all_resolutions(case) -> list:
    """Every resolution of ``case``, those run only on request included."""
    return case.resolutions() if callable(case.resolutions) else list(case.resolutions)


def _unmatched_dps(chosen, dps) -> list:
    """The --dp values that no chosen case has a resolution at (a typo: nothing would run for them)."""
    return [d for d in dps or () if not any(math.isclose(r.dp, d, rel_tol=1e-9)
                                            for c in chosen for r in _all_resolutions(c))]


def main(argv=None) -> int:
    every = cases()
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("names", nargs="*", help=f"cases to run ({' '.join(case_names(every))}); "
                                             f"default: all but the slow {', '.join(slow_names(every))}")
    ap.add_argument("--all", action="store_true", help=f"also the slow cases {', '.join(slow_names(every))}")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--coarse", action="store_true", help="only the coarsest resolution of each case")
    ap.add_argument("--dp", type=float, action="append", metavar="DP",
                    help="only the resolutions of this dp (repeatable); a resolution run only on request "
                         "(W3 depth/dp 40) runs when --dp names it")
    ap.add_argument("--fine", action="store_true",
                    help="also the resolutions run only on request (W3 depth/dp 40: ~15 min on 2 threads)")
    ap.add_argument("--keep", metavar="DIR", help="keep the run folders under DIR (default: a temporary folder)")
    ap.add_argument("--csv", metavar="FILE", help="also write every row to FILE")
    ap.add_argument("--constant", action="append", metavar="NAME=VALUE",
                    help="run the case files with this <constantsdef> value (repeatable; e.g. coefh=1.2): "
                         "a copy of each file beside it, removed afterwards")
    args = ap.parse_args(argv)
    constants = parse_constants(args.constant, ap)
    # a kill runs the finally clauses that delete the case copies (--constant)
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    known = {c.name: c for c in every}
    known["S2"] = known["S1"]                      # S1 and S2 are one run of the hydrostatic tank
    unknown = [n for n in args.names if n.upper() not in known]
    if unknown:
        ap.error(f"unknown case(s) {', '.join(unknown)}; expected some of {', '.join(known)}")
    picked = {known[n.upper()].name for n in args.names}
    chosen = [c for c in every if c.name in picked] if args.names else [c for c in every if args.all or not c.slow]
    base = args.keep or tempfile.mkdtemp(prefix="sphdvi-validate-")
    table, failed = [], 0
    unmatched = _unmatched_dps(chosen, args.dp)
    if unmatched:
        ap.error(f"no chosen case has a resolution at --dp {', '.join(f'{d:g}' for d in unmatched)}; their dps: "
                 + "; ".join(f"{c.name} " + ", ".join(f"{r.dp:g}" for r in _all_resolutions(c)) for c in chosen))
    for case in chosen:
        print(f"\n{case.name} {case.title}\n  target: {case.target_text}")
        if constants:
            print("  with " + ", ".join(f"<{k} value=\"{v}\">" for k, v in constants.items()) + " (--constant)")
        head = f"  {'resolution':<11}{'dp':>9}{'particles':>10}{'steps':>8}{'runtime_s':>10}{'µs/p-step':>10}{'thr':>4}"
        print(head + "".join(f"{h:>{max(len(h) + 2, 12)}}" for h, _, _ in case.columns) + "  target")
        rows = []
        resolutions = _all_resolutions(case)
        if args.dp:
            resolutions = [r for r in resolutions if any(math.isclose(r.dp, d, rel_tol=1e-9) for d in args.dp)]
        elif not args.fine:
            resolutions = [r for r in resolutions if not r.on_request]
        if args.coarse:
            resolutions = resolutions[:1]
        if not resolutions and args.dp:
            print(f"  (no resolution of {case.name} at --dp {', '.join(f'{d:g}' for d in args.dp)}; its dps: "
                  + ", ".join(f"{r.dp:g}" for r in _all_resolutions(case)) + ")")
        for res in resolutions:
            outdir = os.path.join(base, f"{case.name}_{res.dp:g}")
            copy = case_with_constants(case.case, constants) if constants else None
            try:
                run = run_case(replace(case, case=copy) if copy else case, res, outdir, args.threads)
            finally:
                if copy:
                    os.remove(copy)
            errors = {}
            if run["rc"] == 0:
                errors = case.score(outdir)
            row = {"case": case.name, "resolution": res.label, "dp": res.dp, "scored": res.scored, **run, "errors": errors,
                   "meets_target": bool(errors) and bool(case.target(errors))}
            rows.append(row)
            line = (f"  {res.label:<11}{res.dp:>9.4g}{run['particles']:>10d}{run['steps']:>8d}"
                    f"{run['runtime_s']:>10.1f}{run['us']:>10.3f}{run['threads_used']:>4d}")
            if run["rc"] != 0:
                print(line + f"  run {run['status']} (exit {run['rc']}): {run['message']}")
                failed += 1
                continue
            line += "".join(f"{fmt(f, errors.get(k)):>{max(len(h) + 2, 12)}}" for h, k, f in case.columns)
            print(line + ("  yes" if row["meets_target"] else "  NO") + ("" if res.scored else " (coarser than the target's)"))
        orders = observed_order([r for r in rows if r["errors"]], case.headline)
        if orders:
            print(f"  observed order of {case.headline}: " + ", ".join(fmt("{:.2f}", o) for o in orders))
        table.extend(rows)
    if args.csv:
        header = ["case", "resolution", "dp", "particles", "steps", "runtime_s", "us_per_particle_step", "threads_used",
                  "status", "meets_target"]
        keys = sorted({k for r in table for k, v in r["errors"].items() if isinstance(v, (int, float, str))}
                      - set(header))
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header + ["target_applies", "constants"] + keys)
            given = " ".join(f"{k}={v}" for k, v in constants.items())      # --constant: not the case files' own
            for r in table:
                w.writerow([r["case"], r["resolution"], r["dp"], r["particles"], r["steps"], r["runtime_s"], r["us"],
                            r["threads_used"], r["status"], r["meets_target"], r["scored"], given]
                           + [r["errors"].get(k, "") for k in keys])
    if args.keep:
        print(f"\nrun folders kept in {base}")
    else:
        import shutil
        shutil.rmtree(base, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""S19: a dam break through a lifted gate against a flexible plate (Liao, Hu & Sueyoshi 2015),
scored from a run of ``cases/flexobstacle2d/CaseFlexibleObstacle2D_Def.xml``.

The plate is a chain of rigid trunks joined by hinges with torsional springs (Capasso et al.
2022): a trunk of length Δ = L/N turns against k = EI/Δ at each joint, 2EI/Δ at the clamp.
The measured quantity is the horizontal displacement of Marker 1, a point of the plate 2.5 mm
below its free end, carried here by the top trunk as a rigid body:

    d(t) = [c(t) + R(t) (p0 − c0)]_x − p0_x                                             (1)

with c the trunk's centre and R its rotation (bodies.csv). The run is scored against the
experiment's record (``flexible_obstacle_liao_2015/`` in the shared reference data) over the
window in which the water loads the plate, and against DualSPHysics's own run of the same
model (its example chrono/13_FlexibleObstacle at dp 1 mm, mDBC), which shows what the hinge
chain reaches.

The dry chain is checked against beam theory by :func:`chain_modes` (small swings of the
linearised chain: M θ̈ + K θ = 0), whose first mode the Euler-Bernoulli cantilever
ω1 = 1.8751² √(EI/(ρA L⁴)) bounds, and :func:`chain_tip_compliance` (the static tip deflection
under a tip load, P L³/(3EI) for the beam).
"""
from __future__ import annotations

import math
import os

import numpy as np

from .runs import body_log, case_data, run_info

REFERENCE_FOLDER = "flexible_obstacle_liao_2015"
MARKER_BELOW_TOP = 0.0025        # m: Marker 1 below the plate's free end
TOP_BODY = "trunk19"
WINDOW = (0.25, 0.75)            # s: the water's first pass over the plate (arrival ~0.29 s, return ~0.72 s)
PLATEAU = (0.35, 0.70)           # s: the quasi-steady deflection under the running water
ARRIVAL_DISPLACEMENT = 0.01      # m: the marker's arrival time is when d first exceeds it


def reference_series(reference_dir: str, which: str = "EXP_Liao2015") -> tuple[np.ndarray, np.ndarray]:
    """(t, d) of ``marker1_displacement_<which>.csv`` (EXP_Liao2015, SPH_Sun2019, DualSPHysics_Chrono)."""
    path = os.path.join(reference_dir, REFERENCE_FOLDER, f"marker1_displacement_{which}.csv")
    data = np.genfromtxt(path, delimiter=",", comments="#", skip_header=2)
    order = np.argsort(data[:, 0])
    return data[order, 0], data[order, 1]


def plate_geometry(outdir: str) -> dict:
    """From the gencase file: the top trunk's centre c0 and Marker 1's start p0 (on the plate's
    centre line, MARKER_BELOW_TOP below the top of its particles' volume), the plate's height L,
    the trunk count and dp."""
    case = case_data(outdir)
    dp = float(case["constants"]["dp"])
    bodies = case["bodies"]
    mkb = [int(m) for m in bodies["mkbound"]]
    top = int(np.argmax(np.asarray(bodies["center"], dtype=float)[:, 2]))     # the highest trunk carries it
    c0 = np.asarray(bodies["center"][top], dtype=float)
    p = case["particles"]
    fluidcount = int(case["json"]["mkconfig"]["fluidcount"])
    sel = np.isin(p["mk"].astype(np.int64) - fluidcount - 1, mkb) & (p["type"] != 3)
    pts = p["pos"][sel]
    top_z = float(pts[:, 2].max()) + 0.5 * dp
    bottom_z = float(pts[:, 2].min()) - 0.5 * dp
    p0 = np.array([0.5 * (pts[:, 0].min() + pts[:, 0].max()), c0[1], top_z - MARKER_BELOW_TOP])
    names = {int(b["mkbound"]): b["id"] for b in case["json"]["chrono"]["bodies"]} if case["json"].get("chrono") \
        else {}
    return {"c0": c0, "p0": p0, "height": top_z - bottom_z, "trunks": len(mkb), "dp": dp,
            "top_body": names.get(mkb[top], TOP_BODY)}


def marker_displacement(outdir: str, geo: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(t, d) of eq. (1) from bodies.csv."""
    geo = geo or plate_geometry(outdir)
    rows = body_log(outdir)
    mine = rows[rows["body"] == geo["top_body"]]
    t = np.asarray(mine["time"], dtype=float)
    c = np.column_stack([mine["x"], mine["y"], mine["z"]]).astype(float)
    q = np.column_stack([mine["qw"], mine["qx"], mine["qy"], mine["qz"]]).astype(float)
    from ..dvi._math import body_rotations
    marker = c + body_rotations(q) @ (geo["p0"] - geo["c0"])
    return t, marker[:, 0] - geo["p0"][0]


def arrival_time(t: np.ndarray, d: np.ndarray, level: float = ARRIVAL_DISPLACEMENT) -> float:
    """The first time d reaches ``level``, interpolated between samples (nan if never)."""
    above = np.flatnonzero(d >= level)
    if above.size == 0:
        return math.nan
    k = int(above[0])
    if k == 0:
        return float(t[0])
    return float(t[k - 1] + (level - d[k - 1]) * (t[k] - t[k - 1]) / (d[k] - d[k - 1]))


GRID = 1e-3                      # s: the uniform time grid the records are compared on


def _on_grid(t: np.ndarray, d: np.ndarray, span: tuple) -> np.ndarray:
    """d(t) interpolated on the uniform GRID over ``span`` (the records' samples are uneven: the
    experiment's every 0.4-14 ms, Sun et al.'s 0.5-32 ms)."""
    return np.interp(np.arange(span[0], span[1] + 0.5 * GRID, GRID), t, d)


def compare(t: np.ndarray, d: np.ndarray, t_ref: np.ndarray, d_ref: np.ndarray) -> dict:
    """A run's d(t) against a reference's, both on a uniform 1 ms grid: ``plateau`` (the mean over
    PLATEAU, relative to the reference's), ``peak`` (the largest d in WINDOW, relative), ``rms``
    (the rms difference over WINDOW over the reference's peak there), ``corr`` (their correlation
    there) and ``arrival`` (the run's arrival time minus the reference's, s)."""
    ours, ref = _on_grid(t, d, WINDOW), _on_grid(t_ref, d_ref, WINDOW)
    win = (t >= WINDOW[0]) & (t <= WINDOW[1])
    peak_ref = float(d_ref[(t_ref >= WINDOW[0]) & (t_ref <= WINDOW[1])].max())
    return {"plateau": float(np.mean(_on_grid(t, d, PLATEAU)) / np.mean(_on_grid(t_ref, d_ref, PLATEAU)) - 1),
            "peak": float(d[win].max()) / peak_ref - 1,
            "rms": float(np.sqrt(np.mean((ours - ref) ** 2))) / peak_ref,
            "corr": float(np.corrcoef(ours, ref)[0, 1]),
            "arrival": arrival_time(t, d) - arrival_time(t_ref, d_ref)}


def chain_model(mechanism: dict, axis: int = 1) -> dict:
    """The plate's hinge chain from :func:`sphdvi.mechanism.mechanism_from_case`: the trunks
    bottom to top (``mass``, ``inertia`` about ``axis`` through the centre, centre height
    ``zc``), the hinge below each (``zh``, ``stiffness``), the plate's top ``top`` (the top of
    its particles' volume) and ``gravity`` (its z)."""
    by_name = {b["name"]: b for b in mechanism["bodies"]}
    below = {}
    for ln in mechanism["links"]:
        if ln["kind"] != "hinge":
            continue
        pair = [n for n in (ln["body1"], ln.get("body2")) if n]
        upper = max(pair, key=lambda n: float(by_name[n]["pos"][2]))      # the hinge is below its upper trunk
        below[upper] = (float(ln["point"][2]), float(ln["stiffness"]))
    order = sorted(below, key=lambda name: below[name][0])
    zc = np.array([float(by_name[n]["pos"][2]) for n in order])
    zh = np.array([below[n][0] for n in order])
    return {"names": order, "mass": np.array([float(by_name[n]["mass"]) for n in order]),
            "inertia": np.array([float(np.asarray(by_name[n]["inertia"])[axis, axis]) for n in order]),
            "zc": zc, "zh": zh, "stiffness": np.array([below[n][1] for n in order]),
            "top": max(float(pts[:, 2].max()) for b, pts in zip(mechanism["bodies"], mechanism["points"])
                       if b["name"] in below) + 0.5 * float(mechanism["dp"]),
            "gravity": float(mechanism["system"]["gravity"][2])}


def _chain_matrices(chain: dict, gravity: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, K, A) of the chain linearised about the upright pose in the trunks' absolute angles θ:
    a point at height z of trunk i moves u = Σ_{j<i} (zh_{j+1} − zh_j) θ_j + (z − zh_i) θ_i, so
    the centres move A θ and M = Aᵀ diag(m) A + diag(I); K holds the springs k_i (θ_i − θ_{i−1})
    (the clamp's on θ_0) and, with ``gravity``, the weights' −g (m_i (zc_i − zh_i) + (zh_{i+1} −
    zh_i) Σ_{k>i} m_k) on the diagonal (an upright plate: its weight lowers the stiffness)."""
    m, zc, zh, k = chain["mass"], chain["zc"], chain["zh"], chain["stiffness"]
    n = m.size
    seg = np.diff(np.append(zh, chain["top"]))
    A = np.zeros((n, n))
    for i in range(n):
        A[i, :i] = seg[:i]
        A[i, i] = zc[i] - zh[i]
    M = A.T @ (m[:, None] * A) + np.diag(chain["inertia"])
    D = np.eye(n) - np.eye(n, k=-1)                 # rows: θ_0, θ_1 − θ_0, ...
    K = D.T @ (k[:, None] * D)
    if gravity:
        above = np.cumsum(m[::-1])[::-1]            # Σ_{k>=i} m_k
        heavy = m * (zc - zh) + seg * np.append(above[1:], 0.0)
        K = K + np.diag(chain["gravity"] * heavy)   # gravity < 0
    return M, K, A


def chain_modes(chain: dict, gravity: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(ω, Θ): the chain's angular frequencies, lowest first, and mode shapes (columns, in θ)
    of M θ̈ + K θ = 0 (:func:`_chain_matrices`)."""
    M, K, _ = _chain_matrices(chain, gravity)
    L = np.linalg.cholesky(M)
    Li = np.linalg.inv(L)
    w2, V = np.linalg.eigh(Li @ K @ Li.T)
    return np.sqrt(w2), Li.T @ V


def chain_tip_compliance(chain: dict) -> float:
    """The top's horizontal deflection per unit horizontal force there, without gravity:
    Σ_i (top − zh_i)² / k_i (the moment P (top − zh_i) turns hinge i by P (top − zh_i)/k_i)."""
    return float(np.sum((chain["top"] - chain["zh"]) ** 2 / chain["stiffness"]))


def beam_first_mode(EI: float, mass_per_length: float, length: float) -> float:
    """ω1 of a clamped-free Euler-Bernoulli beam: 1.87510407² √(EI/(μ L⁴))."""
    return 1.87510407 ** 2 * math.sqrt(EI / (mass_per_length * length ** 4))


def case_errors(outdir: str, reference_dir: str) -> dict:
    """Score a finished run against the experiment (keys of :func:`compare`) and against
    DualSPHysics's run of the same model (the same keys prefixed ``dsph_``), with the run's
    ``plateau_m`` (its mean deflection over PLATEAU, m), ``dp`` and run.json's figures."""
    geo = plate_geometry(outdir)
    t, d = marker_displacement(outdir, geo)
    out = compare(t, d, *reference_series(reference_dir))
    out.update({f"dsph_{k}": v for k, v in
                compare(t, d, *reference_series(reference_dir, "DualSPHysics_Chrono")).items()})
    meta = run_info(outdir)
    out.update({"plateau_m": float(np.mean(_on_grid(t, d, PLATEAU))), "dp": geo["dp"], "particles": meta.get("particles"),
                "steps": meta.get("steps"), "runtime_s": meta.get("runtime_s"), "status": meta.get("status")})
    return out

"""The checks and warnings of a run's start: the case's particles and settings looked at once,
before the first step (fluid densities within RhopOutMin/RhopOutMax, boundaries inside the
domain, mDBC walls and normals, an undamped mDBC setting), and the text helpers of the run's
messages."""
from __future__ import annotations

import warnings

import numpy as np

from .errors import InputError


def outside(pos: np.ndarray, domain, tol: float = 0.0) -> np.ndarray:
    """Rows of ``pos`` outside the box ``domain`` = (posmin, posmax) (beyond ``tol``)."""
    return np.any((pos < domain[0] - tol) | (pos > domain[1] + tol), axis=1)


def and_list(items: list) -> str:
    """'a', 'a and b', 'a, b and c'."""
    return " and ".join(items) if len(items) < 3 else ", ".join(items[:-1]) + " and " + items[-1]


def box_text(domain) -> str:
    return f"{fmt_vec(domain[0])} - {fmt_vec(domain[1])}"


def fmt_vec(v) -> str:
    return "(" + ", ".join(f"{float(x):.5g}" for x in v) + ")"


def check_initial_density(rhop_fluid: np.ndarray, params: dict) -> None:
    """DualSPHysics's JSph::CheckRhoLimits (JSph::LoadCaseParticles): a fluid particle that starts
    with a density outside [RhopOutMin, RhopOutMax] is an input error; the run does not start."""
    if rhop_fluid.size == 0:
        return
    rmin, rmax = float(params.get("RhopOutMin", 700.0)), float(params.get("RhopOutMax", 1300.0))
    out = int(np.count_nonzero((rhop_fluid < rmin) | (rhop_fluid > rmax)))
    if not out:
        return
    lo, hi = float(rhop_fluid.min()), float(rhop_fluid.max())
    raise InputError(f"{out} of {rhop_fluid.size} fluid particles start with a density outside RhopOutMin/RhopOutMax "
                     f"[{rmin:g}, {rmax:g}] (the initial fluid densities span [{lo:.6g}, {hi:.6g}] kg/m3); "
                     "DualSPHysics refuses to start such a case too (\"Initial fluid density is out of limits\"): "
                     "to change the limits modify the value of RhopOutMin and RhopOutMax (<parameters>, or --set)")


_BOUNDARY_KINDS = {0: "fixed", 1: "moving", 2: "floating"}


def check_boundary_in_domain(p: dict, domain, fluidcount: int) -> None:
    """Boundary particles (fixed, moving, floating) outside the simulation domain at the start
    (a <simulationdomain> that cuts the walls) are an input error: DualSPHysics excludes them at
    its first cell division and aborts (JSph::AbortBoundOut, "Fixed, moving or floating particles
    were excluded").  The same tolerance as gencase's check of the fluid."""
    bound = np.flatnonzero(p["type"] != 3)
    if bound.size == 0:
        return
    pos = p["pos"][bound]
    out = outside(pos, domain, 1e-9 * max(1.0, float(np.abs(pos).max())))
    if not out.any():
        return
    from .coupling import body_labels
    rows = bound[out]
    labels = body_labels(p["mk"][rows], fluidcount)
    kinds = p["type"][rows]
    groups = []
    for mkb in np.unique(labels):
        sel = labels == mkb
        groups.append(f"mkbound {int(mkb)} ({_BOUNDARY_KINDS.get(int(kinds[sel][0]), 'boundary')}): "
                      f"{int(sel.sum())}")
    i = int(rows[0])
    raise InputError(f"{rows.size} boundary particles lie outside the simulation domain {box_text(domain)}: "
                     f"{', '.join(groups)} (first: particle {int(p['idp'][i])} at {fmt_vec(p['pos'][i])}); "
                     "DualSPHysics excludes them at its first cell division and stops (AbortBoundOut: \"Fixed, "
                     "moving or floating particles were excluded\"): enlarge <simulationdomain> to hold the walls")


def warn_inward_mdbc_normals(inward: dict, dp: float) -> None:
    """Ghost nodes inside their own wall (:func:`~sphdvi.case.normals.ghosts_in_own_wall`): the
    surface the normals are computed from lies behind the wall's face layer."""
    for mk, count in sorted(inward.items()):
        warnings.warn(f"mDBC on mkbound {mk}: {count} of its particles have their ghost node (r + 2N, where mDBC "
                      "samples the fluid) on a particle of their own wall: the surface their normals are computed "
                      f"from lies behind the wall's face layer, not dp/2 = {0.5 * dp:g} m in front of it, and the "
                      "face layer's normals point back into the wall. Put the surface (the <norgeometry> shapes, "
                      "a <norplane> point) dp/2 in front of the face layer; a shape's face half-way between two "
                      "nodes draws its particles on the side the tie rounds to, which may be outside the shape")


def warn_thin_mdbc_walls(thin: dict, need: int, h_dp: float) -> None:
    """mDBC on walls thinner than the kernel's reach leaks (:func:`~sphdvi.case.normals.thin_wall_mkbounds`)."""
    if not thin:
        return
    vdp = ",".join(str(k) for k in range(need))
    one = sorted(mk for mk, (fewest, _) in thin.items() if fewest == 1)
    more = {mk: v for mk, v in thin.items() if v[0] > 1}
    if one:
        warnings.warn(f"mDBC on mkbound {', '.join(map(str, one))}: a wall one particle thick, through which "
                      "the fluid leaks (S3's dam break at dp 0.02: 200-210 of 5,501 particles out by 0.72 s; "
                      f"with two or three layers 1-2, DBC 0); draw it with <layers vdp=\"{vdp}\"> (the kernel "
                      f"reaches 2h = {2 * h_dp:.1f} dp), or keep it DBC (MdbcMkbound)")
    for mk, (fewest, count) in sorted(more.items()):
        warnings.warn(f"mDBC on mkbound {mk}: the wall is {fewest} particles thick behind {count} of its face "
                      f"particles, where the kernel reaches {need} layers (2h = {2 * h_dp:.2f} dp); the fluid leaks "
                      "through it (a 3D tank with 2 layers on two sides: 35 particles through by 1 s at low "
                      f"viscosity); draw it {need} layers thick (<layers vdp=\"{vdp}\">, or a larger solid box)")


# the share of the fluid within 2h of mDBC walls above which DensityDT 2 with SlipMode 1 is warned about
UNDAMPED_MDBC_SHARE = 0.5


def warn_undamped_mdbc(params: dict, p: dict, normals, c: dict) -> None:
    """mDBC SlipMode 1 extrapolates the walls' density along the gradient measured at their ghost
    nodes, which feeds a pressure mode across a narrow tank (the wall values of a cos(pi y/W) mode
    come out x1.04 / 1.32 / 1.82 by layer at W = 10 dp), and DensityDT 2 (Fourtakas, as DualSPHysics)
    is off for a fluid particle with a boundary particle within 2h, so that nothing damps it: a 3D
    tank 10 dp across grew a 50 Hz mode to a wall force of 140 N on 130 N of water by 0.75 s (still
    with DensityDT 3 or 1, or SlipMode 2).  Warned when more than half the fluid lies within 2h of
    mDBC walls."""
    if int(params.get("SlipMode", 1)) != 1 or int(params.get("DensityDT", 0)) != 2:
        return
    walls = (p["type"] != 3) & np.any(normals != 0.0, axis=1)
    from .sph.cells import share_within
    share = share_within(p["pos"][p["type"] == 3], p["pos"][walls], 2.0 * float(c["h"]), bool(c["is2d"]))
    if share > UNDAMPED_MDBC_SHARE:
        warnings.warn(f"mDBC SlipMode 1 with DensityDT 2: {100 * share:.0f} % of the fluid lies within 2h of mDBC "
                      "walls, where DensityDT 2 (Fourtakas) is off, as in DualSPHysics; an acoustic mode across a "
                      "narrow tank can then grow undamped (a 3D tank 10 dp across: wall forces as large as the "
                      "water's weight). Prefer DensityDT 3 (or 1), SlipMode 2 or 3, or more particles across")

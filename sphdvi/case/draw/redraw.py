"""GenCase's redraw commands on the canvas of node codes: ``redraw``, ``redrawbox``,
``redrawnear``, ``redrawnearbox``.

They change nodes already on the canvas (void included) to the current pen, chosen by what
they hold, not by a shape:

* ``redraw`` / ``redrawbox``: every node (of a box) holding the selected label, or every
  node at all when no label is named.
* ``redrawnear`` / ``redrawnearbox``: the target nodes that touch a border node, repeated
  ``times`` times; each pass sees the previous pass's nodes, so a pen equal to the border
  grows it by one node layer a pass. Nodes touch across a face, an edge or a corner (26
  neighbours in 3D, 8 in 2D): GenCase v4.0's record of DualSPHysics's example RedrawSimple
  (355 nodes redrawn; 258 with face neighbours only), ``tests/case/test_gencase_redraw.py``.

Whole-array numpy work (once per command at gencase time, not in a time loop).
"""
from __future__ import annotations

import itertools

import numpy as np


def label_selection(labels, kinds, mk=None) -> np.ndarray:
    """Boolean table over the canvas codes: the codes of ``kinds`` (a set of "void", "fluid",
    "bound"), restricted to mk ``mk`` for fluid and bound codes when it is given."""
    sel = np.zeros(len(labels), dtype=np.bool_)
    sel[0] = "void" in kinds
    for code, (is_fluid, label_mk) in enumerate(labels[1:], start=1):
        kind = "fluid" if is_fluid else "bound"
        sel[code] = kind in kinds and (mk is None or label_mk == mk)
    return sel


def _touching(mask: np.ndarray) -> np.ndarray:
    """The nodes with a neighbour in ``mask`` across a face, an edge or a corner (26 in 3D, 8 in
    2D; the lattice's edge has no neighbour beyond it)."""
    out = np.zeros_like(mask)
    for shift in itertools.product((-1, 0, 1), repeat=3):
        if shift == (0, 0, 0):
            continue
        dst, src = [], []
        for axis, d in enumerate(shift):
            n = mask.shape[axis]
            if d and n < 2:
                break
            dst.append(slice(max(-d, 0), n - max(d, 0)))
            src.append(slice(max(d, 0), n - max(-d, 0)))
        else:
            out[tuple(dst)] |= mask[tuple(src)]
    return out


def redraw(codes: np.ndarray, selected: np.ndarray, lo, hi, code: int, within=None) -> int:
    """Write ``code`` on the nodes of the index box lo..hi (inclusive, clipped) whose code is
    selected (and that ``within``, shaped as the box, marks, when given); returns the number of
    nodes changed (those holding ``code`` already are not)."""
    sl = tuple(slice(int(lo[a]), int(hi[a]) + 1) for a in range(3))
    view = codes[sl]
    hit = selected[view] & (view != code)
    if within is not None:
        hit &= within
    view[hit] = code
    return int(np.count_nonzero(hit))


def redraw_near(codes: np.ndarray, target: np.ndarray, border: np.ndarray, times: int,
                lo, hi, code: int, within=None) -> int:
    """``times`` passes: write ``code`` on the target nodes of the box lo..hi (those ``within``
    marks, when given) that touch a border node (inside the box or next to it); returns the
    number of nodes written in all. Each pass looks at the box and one node around it only."""
    wlo = [max(int(lo[a]) - 1, 0) for a in range(3)]
    whi = [min(int(hi[a]) + 1, codes.shape[a] - 1) for a in range(3)]
    window = codes[tuple(slice(wlo[a], whi[a] + 1) for a in range(3))]      # a view
    inner = tuple(slice(int(lo[a]) - wlo[a], int(hi[a]) - wlo[a] + 1) for a in range(3))
    view = window[inner]
    written = 0
    for _ in range(times):
        hit = target[view] & (view != code) & _touching(border[window])[inner]
        if within is not None:
            hit &= within
        n = int(np.count_nonzero(hit))
        if n == 0:
            break
        view[hit] = code
        written += n
    return written

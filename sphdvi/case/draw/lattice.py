"""The drawing lattice and the canvas of node codes.

Nodes sit at ``origin + k*dp`` (``k`` integer, per axis). ``origin`` is
``pointmin``, or, when ``<pointref>`` is given, the first node at or above
``pointmin`` on the lattice through ``pointref`` (GenCase aligns its lattice on
``pointref``). An axis has ``n = floor((pointmax - pointmin)/dp)`` nodes, ``origin + k*dp``
for ``k = 0 .. n-1``, all in ``[pointmin, pointmax)``: a node on ``pointmax`` does not exist, as
in GenCase (its logs, v5.0 and v5.4: "Case limits: (-5,0,-5) - (105,0,45)", dp 0.5, "Domain
points: 220 x 1 x 100"; "(-0.05,-0.05,-0.05) - (2,1,1)", dp 0.0085, "241 x 123 x 123"). In 2D
(``pointmin.y == pointmax.y``) there is a single y layer at ``pointmin.y``.

The canvas stores one ``uint16`` code per node: 0 = void, otherwise an index
into a table of ``(is_fluid, mk)`` labels. A later drawing overwrites an
earlier one simply by writing its code.
"""
from __future__ import annotations

import math

import numpy as np

#: tolerance in lattice units (1e-6 dp) for "on the boundary counts as inside"
EPS = 1e-6
VOID = 0
MAX_CODES = 65535


def floor_idx(a: float) -> int:
    """floor with a tolerance: a value within EPS below an integer rounds up to it."""
    return int(math.floor(a + EPS))


def ceil_idx(a: float) -> int:
    """ceil with a tolerance: a value within EPS above an integer rounds down to it."""
    return int(math.ceil(a - EPS))


def round_idx(a: float) -> int:
    """Nearest node index, an exact half rounded up; no tolerance: a value a rounding error
    below a half (100.49999999999999) rounds down, as GenCase's do (see
    :func:`sphdvi.case.draw.raster.aligned_box_pieces`)."""
    return int(math.floor(a + 0.5))


class Lattice:
    """Geometry of the node lattice: origin, spacing, node counts, 2D flag."""

    def __init__(self, dp: float, pointmin, pointmax, pointref=None):
        self.dp = float(dp)
        self.pointmin = np.asarray(pointmin, dtype=np.float64)
        self.pointmax = np.asarray(pointmax, dtype=np.float64)
        self.is2d = bool(self.pointmin[1] == self.pointmax[1])
        self.pointref = (np.asarray(pointref, dtype=np.float64) if pointref is not None
                         else self.pointmin.copy())
        origin = self.pointmin.copy()
        if pointref is not None:
            for a in range(3):
                if a == 1 and self.is2d:
                    continue
                k = math.ceil((self.pointmin[a] - self.pointref[a]) / self.dp - EPS)
                origin[a] = self.pointref[a] + k * self.dp
        self.origin = origin
        self.counts_float = np.maximum(
            np.floor((self.pointmax - self.pointmin) / self.dp + EPS), 0.0)
        if self.is2d:
            self.counts_float[1] = 1.0

    @property
    def node_count(self) -> float:
        """Number of lattice nodes (a float: it may be absurdly large)."""
        return float(np.prod(self.counts_float))

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(int(c) for c in self.counts_float)

    def to_index(self, p) -> np.ndarray:
        """World coordinates -> continuous lattice coordinates (node k at k)."""
        return (np.asarray(p, dtype=np.float64) - self.origin) / self.dp

    def node_pos(self, idx) -> np.ndarray:
        """Integer node indices (..., 3) -> world coordinates."""
        return self.origin + np.asarray(idx, dtype=np.float64) * self.dp

    def axis_coords(self, lo, hi):
        """World coordinates of nodes lo..hi (inclusive) along each axis, as 3 broadcastable arrays."""
        out = []
        for a in range(3):
            c = self.origin[a] + np.arange(lo[a], hi[a] + 1, dtype=np.float64) * self.dp
            sh = [1, 1, 1]
            sh[a] = c.size
            out.append(c.reshape(sh))
        return out

    def clip_range(self, lo, hi, margin: int = 0):
        """Clip an index range to the lattice (optionally widened by margin); None if empty."""
        shape = self.shape
        lo2, hi2 = [], []
        for a in range(3):
            m = 0 if (a == 1 and self.is2d) else margin
            l = max(int(lo[a]), -m)
            h = min(int(hi[a]), shape[a] - 1 + m)
            if l > h:
                return None
            lo2.append(l)
            hi2.append(h)
        return np.array(lo2, dtype=np.int64), np.array(hi2, dtype=np.int64)

    def bbox_range(self, wmin, wmax, pad: float = 0.5):
        """Index range of nodes within pad (lattice units) of a world bounding box, unclipped."""
        a = self.to_index(np.asarray(wmin, dtype=np.float64))
        b = self.to_index(np.asarray(wmax, dtype=np.float64))
        lo = np.array([ceil_idx(v - pad) for v in np.minimum(a, b)], dtype=np.float64)
        hi = np.array([floor_idx(v + pad) for v in np.maximum(a, b)], dtype=np.float64)
        # huge values are clipped later; keep them finite integers
        lo = np.clip(lo, -2**40, 2**40).astype(np.int64)
        hi = np.clip(hi, -2**40, 2**40).astype(np.int64)
        return lo, hi


class Canvas:
    """A dense array of node codes over the whole lattice, plus the code table."""

    def __init__(self, lattice: Lattice):
        self.lattice = lattice
        self.codes = np.zeros(lattice.shape, dtype=np.uint16)
        self.labels: list[tuple[bool, int]] = [(False, -1)]  # code 0 = void
        self._code_of: dict[tuple[bool, int], int] = {}

    def code_for(self, is_fluid: bool, mk: int) -> int:
        """The code of a (fluid/bound, mk) label, creating it on first use."""
        key = (bool(is_fluid), int(mk))
        code = self._code_of.get(key)
        if code is None:
            if len(self.labels) > MAX_CODES:
                raise ValueError(f"more than {MAX_CODES} different mk labels")
            code = len(self.labels)
            self.labels.append(key)
            self._code_of[key] = code
        return code

    def paint(self, lo, mask, code: int) -> int:
        """Write ``code`` on the nodes where ``mask`` (a sub-array starting at ``lo``) is True."""
        lo = [int(v) for v in lo]
        sl = tuple(slice(lo[a], lo[a] + mask.shape[a]) for a in range(3))
        self.codes[sl][mask] = code
        return int(np.count_nonzero(mask))

    def paint_box(self, lo, hi, code: int) -> None:
        """Write ``code`` on every node of the inclusive index box lo..hi (already clipped)."""
        sl = tuple(slice(int(lo[a]), int(hi[a]) + 1) for a in range(3))
        self.codes[sl] = code

    def extract(self):
        """Positions, fluid flags and mk of the non-void nodes, x fastest, then y, then z."""
        view = self.codes.transpose(2, 1, 0)  # (z, y, x): C order makes x the fastest
        kz, ky, kx = np.nonzero(view)
        vals = view[kz, ky, kx]
        lat = self.lattice
        pos = np.empty((kx.size, 3), dtype=np.float64)
        pos[:, 0] = lat.origin[0] + kx * lat.dp
        pos[:, 1] = (lat.pointmin[1] if lat.is2d else lat.origin[1] + ky * lat.dp)
        pos[:, 2] = lat.origin[2] + kz * lat.dp
        table_fluid = np.array([f for f, _ in self.labels], dtype=bool)
        table_mk = np.array([m for _, m in self.labels], dtype=np.int32)
        return pos, table_fluid[vals], table_mk[vals]

r"""Advanced particle shifting (DualSPHysics ``Shifting=4``, ``ShiftAdvCoef``).

Shifting that knows where the free surface is: particles on it, and those
within the kernel support of one, are not shifted (so the free surface does
not swell), interior particles are moved down the gradient of the particle
concentration by a displacement that does not depend on the flow speed
(Sun et al. 2017, the delta-plus-SPH shifting; free-surface detection of
Marrone et al. 2010):

1. **Candidates.**  For fluid particle i, the divergence of position
   :math:`\lambda_i = -\sum_j V_j\,\mathbf r_{ij}\cdot\nabla W_{ij}` (= d, the
   dimension, in the bulk) and the number of neighbours.  i is a free-surface
   candidate (type 2) when λ < 1.7 (2D) or 2.75 (3D), and an isolated particle
   (type 3) when λ < 1.1 / 1.8 with fewer than 0.4 of the neighbours a full
   kernel support holds.
2. **Normal.**  :math:`\mathbf n_i = -L_i^{-1}\nabla C_i / |L_i^{-1}\nabla C_i|`
   with :math:`\nabla C_i = \sum_j V_j \nabla W_{ij}` and the correction matrix
   :math:`L_i = -\sum_j V_j\,\mathbf r_{ij}\otimes\nabla W_{ij}`.
3. **Umbrella scan** (Marrone et al. 2010).  With :math:`T = \mathbf r_i + h\,\mathbf n_i`,
   a candidate stays on the surface only if no neighbour j lies in the scan
   region: :math:`|\mathbf r_j - T| < h` for :math:`r_{ij} \ge \sqrt2 h`, and the
   double cone :math:`|\mathbf n\cdot\mathbf x| + |\mathbf x - (\mathbf n\cdot\mathbf x)\mathbf n| < h`,
   :math:`\mathbf x = \mathbf r_j - T`, for closer ones (its lower half is the
   45° cone with apex at i).
4. **Displacement.**  Interior particles with no surface particle (type 2)
   among their fluid neighbours and no boundary particle in their kernel
   support are moved by
   :math:`\delta\mathbf r_i = u\,h\,\nabla C_i`,
   :math:`u = \min(A h,\ \epsilon/(2 |\nabla C_i|^2 h))`, A = ``ShiftAdvCoef``
   (−0.01; negative, so :math:`u = A h`), ε = 1e-5; each component is capped at
   0.1 dp.  The displacement is applied with the position update (Verlet step,
   Symplectic corrector), independently of dt.

Particle types written to ``fstype``: 0 interior (shifted), 1 near the free
surface, 2 free surface, 3 isolated or touching a boundary; ``fsnormal`` gets the unit normal of
types 2 and 3 (zero elsewhere).  Where DualSPHysics's 2D umbrella test
and isolated-particle test differ from the papers' definitions, the papers'
are used.  DualSPHysics also shifts interior particles next to a wall; near a
thin DBC wall, whose missing kernel support makes grad C point away from it,
that pushes particles through (17 of 5,500 left the 2D dam break through its
one-layer walls in 0.72 s), so particles touching a boundary are not shifted
here.

``ShiftAdvALE`` / ``ShiftAdvNCPress`` (DualSPHysics 5.4, ``JSphCpu_preloop.cpp``
ComputeShiftingVel and ``JSphCpu.cpp`` InteractionForcesFluid; Sun et al. 2019)
use :func:`advanced_shift_ale_serial`, which follows DualSPHysics's
classification: a near-surface particle touching a boundary is type 3; the
interior type-0 particles are flagged in ``nctype`` for the non-conservative
pressure gradient (with DBC walls only those without a boundary particle in
their support, see :func:`_displace_ale_range`).  With ALE:

* near-surface (1) and surface (2) particles are shifted too, along
  :math:`\mathbf s = \nabla C - \theta\,\mathbf n(\mathbf n\cdot\nabla C)`,
  :math:`\theta = \min(1, \max(0, (2h - d)/h))`, d the distance to the
  nearest surface particle (2h when none); the normal of a type-1 particle is
  the :math:`V_j W_{ij}`-weighted mean of its surface neighbours' normals;
  surface particles touching a boundary or whose normal turns by more than
  0.52 rad against a neighbouring candidate's are not shifted;
* the magnitude is :math:`u = \min(A h, \epsilon/(2 |\nabla C\cdot\mathbf s| m))\,m`,
  :math:`m = \min(h, d)` (= h for the interior, as above), capped at 0.1 dp per
  component;
* the interaction (:mod:`sphdvi.sph.interaction`) adds the ALE terms with the
  shifting velocity :math:`\delta\mathbf v = \delta\mathbf r/\Delta t`.

The shift and types are computed before the interaction that uses them: in the
Symplectic predictor, from the positions at t^n, kept for the corrector and
applied in it (DualSPHysics's order, JSphCpuSingle::PreLoopProcedure, for plain
Shifting 4 and with ALE / NCPress); plain Shifting 4 shifts nothing in the first
step, as DualSPHysics (Nstep != 0), while with ALE / NCPress sphdvi computes the
types and shift of the first step too (DualSPHysics starts them as type 3 and no
shift); with Verlet every step, the ALE velocity taking the previous step's dt
(DualSPHysics runs advanced shifting with Symplectic only: its Verlet step
ignores it).
"""
import math

from . import _env  # noqa: F401
from numba import njit, prange

from .kernels import kernel_fac, kernel_w

EPS_LIMIT = 1e-5
CHUNK = 256


@njit(cache=True)
def _row_xyz(nb, j, is2d):
    if is2d:
        return nb[j, 0], 0.0, nb[j, 1]
    return nb[j, 0], nb[j, 1], nb[j, 2]


@njit(cache=True)
def _row_volume(nb, j, is2d):
    """m/rho of packed row j."""
    if is2d:
        return nb[j, 6] * nb[j, 7]
    return nb[j, 8] * nb[j, 9]


@njit(cache=True)
def _cell_xyz(c, ncx, ncy):
    return c % ncx, (c // ncx) % ncy, c // (ncx * ncy)


@njit(cache=True, error_model="numpy")
def _detect_range(i0, i1, kern, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, nzero,
                  fst, nrm, gc, near, bnd):
    """Steps 1-3 for rows i0..i1: candidate type, normal, umbrella scan, grad C, and
    whether a boundary particle is in the kernel support (``bnd``); clears ``near``."""
    h = cst[0]
    inv_h = 1.0 / h
    r2max = cst[1]
    alpha_h2 = cst[4]
    rs = int(cst[18])
    lam_fs = 1.7 if is2d else 2.75
    lam_iso = 1.1 if is2d else 1.8
    two_h2 = 2.0 * h * h
    for i in range(i0, i1):
        fst[i] = 0
        near[i] = 0
        bnd[i] = 0
        for k in range(3):
            nrm[i, k] = 0.0
            gc[i, k] = 0.0
        if ptype[i] != 3:
            continue
        xi, yi, zi = _row_xyz(nb, i, is2d)
        cx, cy, cz = _cell_xyz(cell[i], ncx, ncy)
        neigh = 0
        gx = 0.0
        gy = 0.0
        gz = 0.0
        # L = -sum V r_ij (x) grad W_ij is symmetric (grad W_ij = fac r_ij)
        lxx = 0.0
        lxy = 0.0
        lxz = 0.0
        lyy = 0.0
        lyz = 0.0
        lzz = 0.0
        touch = False
        for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
            for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
                row = (z * ncy + y) * ncx
                for j in range(cell_start[row + max(cx - rs, 0)], cell_start[row + min(cx + rs, ncx - 1) + 1]):
                    xj, yj, zj = _row_xyz(nb, j, is2d)
                    dx = xi - xj
                    dy = yi - yj
                    dz = zi - zj
                    r2 = dx * dx + dy * dy + dz * dz
                    if r2 >= r2max or r2 < 1e-18:
                        continue
                    v = _row_volume(nb, j, is2d) * kernel_fac(kern, math.sqrt(r2) * inv_h, alpha_h2)
                    neigh += 1
                    if ptype[j] != 3:
                        touch = True
                    gx += v * dx
                    gz += v * dz
                    lxx -= v * dx * dx
                    lxz -= v * dx * dz
                    lzz -= v * dz * dz
                    if not is2d:
                        gy += v * dy
                        lxy -= v * dx * dy
                        lyy -= v * dy * dy
                        lyz -= v * dy * dz
        gc[i, 0] = gx
        gc[i, 1] = gy
        gc[i, 2] = gz
        bnd[i] = 1 if touch else 0
        lam = lxx + lyy + lzz       # divergence of position, -sum V r_ij . grad W_ij
        t = 0
        if lam < lam_fs:
            t = 2
        if lam < lam_iso and neigh < 0.4 * nzero:
            t = 3
        if t == 0:
            continue
        # normal: -L^-1 grad C, normalised (grad C itself where L is singular)
        if is2d:
            det = lxx * lzz - lxz * lxz
            if abs(det) > 1e-12:
                nx = (lzz * gx - lxz * gz) / det
                nz = (-lxz * gx + lxx * gz) / det
            else:
                nx = gx
                nz = gz
            ny = 0.0
        else:
            cxx = lyy * lzz - lyz * lyz
            cxy = lxz * lyz - lxy * lzz
            cxz = lxy * lyz - lxz * lyy
            det = lxx * cxx + lxy * cxy + lxz * cxz
            if abs(det) > 1e-12:
                cyy = lxx * lzz - lxz * lxz
                cyz = lxy * lxz - lxx * lyz
                czz = lxx * lyy - lxy * lxy
                nx = (cxx * gx + cxy * gy + cxz * gz) / det
                ny = (cxy * gx + cyy * gy + cyz * gz) / det
                nz = (cxz * gx + cyz * gy + czz * gz) / det
            else:
                nx = gx
                ny = gy
                nz = gz
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
        if norm == 0.0:
            fst[i] = t
            continue
        nx = -nx / norm
        ny = -ny / norm
        nz = -nz / norm
        nrm[i, 0] = nx
        nrm[i, 1] = ny
        nrm[i, 2] = nz
        if t == 2 and _umbrella_covered(i, is2d, nb, cell_start, cx, cy, cz, ncx, ncy, ncz, rs, r2max,
                                        two_h2, h, xi, yi, zi, nx, ny, nz):
            t = 0
        fst[i] = t


@njit(cache=True, error_model="numpy")
def _umbrella_covered(i, is2d, nb, cell_start, cx, cy, cz, ncx, ncy, ncz, rs, r2max, two_h2, h,
                      xi, yi, zi, nx, ny, nz):
    """Whether a neighbour lies in the scan region above i (step 3)."""
    tx = xi + h * nx
    ty = yi + h * ny
    tz = zi + h * nz
    for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
        for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
            row = (z * ncy + y) * ncx
            for j in range(cell_start[row + max(cx - rs, 0)], cell_start[row + min(cx + rs, ncx - 1) + 1]):
                xj, yj, zj = _row_xyz(nb, j, is2d)
                dx = xj - xi
                dy = yj - yi
                dz = zj - zi
                r2 = dx * dx + dy * dy + dz * dz
                if r2 >= r2max or r2 < 1e-18:
                    continue
                qx = xj - tx
                qy = yj - ty
                qz = zj - tz
                if r2 >= two_h2:
                    if qx * qx + qy * qy + qz * qz < h * h:
                        return True
                else:
                    qn = qx * nx + qy * ny + qz * nz
                    px = qx - qn * nx
                    py = qy - qn * ny
                    pz = qz - qn * nz
                    if abs(qn) + math.sqrt(px * px + py * py + pz * pz) < h:
                        return True
    return False


@njit(cache=True, error_model="numpy")
def _mark_near_range(i0, i1, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, fst, near):
    """Flag the fluid neighbours of the free-surface rows among i0..i1 (``near`` = 1;
    concurrent writers all write 1)."""
    r2max = cst[1]
    rs = int(cst[18])
    for i in range(i0, i1):
        if ptype[i] != 3 or fst[i] != 2:
            continue
        xi, yi, zi = _row_xyz(nb, i, is2d)
        cx, cy, cz = _cell_xyz(cell[i], ncx, ncy)
        for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
            for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
                row = (z * ncy + y) * ncx
                for j in range(cell_start[row + max(cx - rs, 0)], cell_start[row + min(cx + rs, ncx - 1) + 1]):
                    if ptype[j] != 3:
                        continue
                    xj, yj, zj = _row_xyz(nb, j, is2d)
                    if (xi - xj) ** 2 + (yi - yj) ** 2 + (zi - zj) ** 2 < r2max:
                        near[j] = 1


@njit(cache=True, error_model="numpy")
def _displace_range(i0, i1, is2d, ptype, oi, cst, coef, dp, fst, nrm, gc, near, bnd, shiftpos,
                    fstype_out, normal_out):
    """Step 4 for rows i0..i1: final type, displacement and normal, written to row oi[i]."""
    h = cst[0]
    cap = 0.1 * dp
    for i in range(i0, i1):
        o = oi[i]
        for k in range(3):
            shiftpos[o, k] = 0.0
            normal_out[o, k] = nrm[i, k]
        if ptype[i] != 3:
            fstype_out[o] = 0
            continue
        t = fst[i]
        if t == 0 and near[i]:
            t = 1
        if t == 0 and bnd[i]:
            t = 3
        fstype_out[o] = t
        if t != 0:
            continue
        gx = gc[i, 0]
        gy = gc[i, 1]
        gz = gc[i, 2]
        g2 = gx * gx + gy * gy + gz * gz
        if g2 == 0.0:
            continue
        u = min(coef * h, abs(EPS_LIMIT / (2.0 * g2 * h))) * h
        d = (u * gx, u * gy, u * gz)
        for k in range(3):
            shiftpos[o, k] = min(max(d[k], -cap), cap)


@njit(cache=True, error_model="numpy")
def _copy_source_types(fst, src_row):
    n = fst.shape[0]
    if src_row.shape[0] == n:
        for i in range(n):
            fst[i] = fst[src_row[i]]


@njit(cache=True, error_model="numpy")
def advanced_shift_serial(kern, is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, cst, nzero,
                          coef, dp, fst, nrm, gc, near, bnd, shiftpos, fstype_out, normal_out, src_row):
    """Free-surface detection and shifting displacement of every fluid row.

    ``src_row`` (periodic runs; empty otherwise): row of the real particle each
    row copies, so that a ghost copy, whose kernel the end of the extended set
    truncates, takes the free-surface type of its real particle."""
    n = nb.shape[0]
    _detect_range(0, n, kern, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, nzero, fst, nrm, gc,
                  near, bnd)
    _copy_source_types(fst, src_row)
    _mark_near_range(0, n, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, fst, near)
    _displace_range(0, n, is2d, ptype, oi, cst, coef, dp, fst, nrm, gc, near, bnd, shiftpos, fstype_out,
                    normal_out)


@njit(cache=True, parallel=True, error_model="numpy")
def advanced_shift_parallel(kern, is2d, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, cst, nzero,
                            coef, dp, fst, nrm, gc, near, bnd, shiftpos, fstype_out, normal_out, src_row):
    """Threaded :func:`advanced_shift_serial` (passes over chunks of rows)."""
    n = nb.shape[0]
    nchunk = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunk):
        _detect_range(c * CHUNK, min(n, (c + 1) * CHUNK), kern, is2d, nb, ptype, cell, cell_start,
                      ncx, ncy, ncz, cst, nzero, fst, nrm, gc, near, bnd)
    _copy_source_types(fst, src_row)   # serial: a real row must not change while its ghosts read it
    for c in prange(nchunk):
        _mark_near_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, nb, ptype, cell, cell_start,
                         ncx, ncy, ncz, cst, fst, near)
    for c in prange(nchunk):
        _displace_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, ptype, oi, cst, coef, dp, fst, nrm, gc,
                        near, bnd, shiftpos, fstype_out, normal_out)


# --------------------------------------------------------------------------
# ShiftAdvALE / ShiftAdvNCPress: the DualSPHysics classification and the
# tangential shifting of (near-)surface particles
# --------------------------------------------------------------------------
COS_CURV = math.cos(0.52)     # surface particles whose normal turns more than 0.52 rad are not shifted


@njit(cache=True, error_model="numpy")
def _ale_scan_range(i0, i1, kern, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, fst, nrm,
                    near, mind, nsm, curv):
    """For the fluid rows i0..i1 (gather form): ``near`` 1 when a free-surface (type 2)
    fluid particle is within the support, ``mind`` the distance to the nearest one
    (2h when none), ``nsm`` their normals summed with weights V_j W_ij, and ``curv`` 1
    when i is a candidate (type 2 or 3) with a candidate neighbour whose normal makes
    more than 0.52 rad with its own.  Only the rows that :func:`_mark_near_range`
    flagged (``near`` on entry) and the candidates are scanned: the others have none
    of these neighbours."""
    h = cst[0]
    inv_h = 1.0 / h
    r2max = cst[1]
    alpha = cst[3]
    rs = int(cst[18])
    for i in range(i0, i1):
        flagged = near[i] != 0
        near[i] = 0
        curv[i] = 0
        mind[i] = 2.0 * h
        for k in range(3):
            nsm[i, k] = 0.0
        cand = fst[i] >= 2
        if ptype[i] != 3 or not (flagged or cand):
            continue
        xi, yi, zi = _row_xyz(nb, i, is2d)
        cx, cy, cz = _cell_xyz(cell[i], ncx, ncy)
        dmin2 = r2max
        nx = 0.0
        ny = 0.0
        nz = 0.0
        for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
            for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
                row = (z * ncy + y) * ncx
                for j in range(cell_start[row + max(cx - rs, 0)], cell_start[row + min(cx + rs, ncx - 1) + 1]):
                    if ptype[j] != 3 or fst[j] < 2:
                        continue
                    xj, yj, zj = _row_xyz(nb, j, is2d)
                    r2 = (xi - xj) ** 2 + (yi - yj) ** 2 + (zi - zj) ** 2
                    if r2 >= r2max or r2 < 1e-18:
                        continue
                    if fst[j] == 2:
                        near[i] = 1
                        if r2 < dmin2:
                            dmin2 = r2
                        w = _row_volume(nb, j, is2d) * kernel_w(kern, math.sqrt(r2) * inv_h, alpha)
                        nx += nrm[j, 0] * w
                        ny += nrm[j, 1] * w
                        nz += nrm[j, 2] * w
                    if cand:
                        c = nrm[i, 0] * nrm[j, 0] + nrm[i, 1] * nrm[j, 1] + nrm[i, 2] * nrm[j, 2]
                        if c < COS_CURV:
                            curv[i] = 1
        if near[i]:
            mind[i] = math.sqrt(dmin2)
            nsm[i, 0] = nx
            nsm[i, 1] = ny
            nsm[i, 2] = nz


@njit(cache=True, error_model="numpy")
def _displace_ale_range(i0, i1, is2d, ale, nc_bnd, ptype, oi, cst, coef, dp, fst, nrm, gc, near, bnd, mind,
                        nsm, curv, shiftpos, fstype_out, normal_out, nctype_out):
    """Final type, displacement, normal and non-conservative-pressure flag of rows i0..i1
    when ShiftAdvALE or ShiftAdvNCPress is on (DualSPHysics ComputeShiftingVel).

    ``nctype_out`` is 1 for DualSPHysics's interior type (not a surface, near-surface
    or isolated particle), the particles on which ShiftAdvNCPress may use the
    non-conservative pressure gradient; those with a boundary particle in their
    support only when ``nc_bnd`` (mDBC: with DBC walls the non-conservative form,
    which lacks the p_a + p_b repulsion that DBC relies on, draws fluid into the
    walls wherever a wall particle's pressure is below the fluid's).  With
    ``ale`` the near-surface (type 1) and surface (type 2) particles are shifted too,
    along s = grad C - theta n (n . grad C), theta = clamp((2h - d)/h, 0, 1), d the
    distance to the nearest surface particle; the magnitude is scaled by min(h, d)
    instead of h.  Surface particles touching a boundary or at a sharp corner
    (``curv``) and near-surface particles touching a boundary are not shifted."""
    h = cst[0]
    cap = 0.1 * dp
    for i in range(i0, i1):
        o = oi[i]
        nctype_out[o] = 0
        for k in range(3):
            shiftpos[o, k] = 0.0
            normal_out[o, k] = nrm[i, k]
        if ptype[i] != 3:
            fstype_out[o] = 0
            continue
        t = fst[i]
        if t == 0 and near[i]:
            t = 3 if bnd[i] else 1
            if ale:
                sn = math.sqrt(nsm[i, 0] ** 2 + nsm[i, 1] ** 2 + nsm[i, 2] ** 2)
                if sn > 0.0:
                    for k in range(3):
                        normal_out[o, k] = nsm[i, k] / sn
        if t == 0:
            if nc_bnd or not bnd[i]:
                nctype_out[o] = 1
            if bnd[i]:
                t = 3       # sphdvi: interior particles touching a boundary are not shifted
        fstype_out[o] = t
        gx = gc[i, 0]
        gy = gc[i, 1]
        gz = gc[i, 2]
        d = mind[i]
        if t == 0:
            sx = gx
            sy = gy
            sz = gz
        elif ale and (t == 1 or (t == 2 and not bnd[i] and not curv[i])):
            nx = normal_out[o, 0]
            ny = normal_out[o, 1]
            nz = normal_out[o, 2]
            theta = min(1.0, max(0.0, (2.0 * h - d) / h))
            gn = theta * (nx * gx + ny * gy + nz * gz)
            sx = gx - gn * nx
            sy = gy - gn * ny
            sz = gz - gn * nz
        else:
            continue
        if is2d:
            sy = 0.0
        m = min(h, d)
        rv = abs(gx * sx + gy * sy + gz * sz) * m
        u = coef * h
        if rv > 0.0:
            u = min(u, abs(EPS_LIMIT / (2.0 * rv)))
        u *= m
        dd = (u * sx, u * sy, u * sz)
        for k in range(3):
            shiftpos[o, k] = min(max(dd[k], -cap), cap)


@njit(cache=True, error_model="numpy")
def _copy_source_normals(nrm, src_row):
    """Periodic copies take their real particle's normal (their own, from a support
    truncated by the end of the extended set, may point anywhere)."""
    n = nrm.shape[0]
    if src_row.shape[0] == n:
        for i in range(n):
            r = src_row[i]
            for k in range(3):
                nrm[i, k] = nrm[r, k]


@njit(cache=True, error_model="numpy")
def advanced_shift_ale_serial(kern, is2d, ale, nc_bnd, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, cst,
                              nzero, coef, dp, fst, nrm, gc, near, bnd, mind, nsm, curv, shiftpos, fstype_out,
                              normal_out, nctype_out, src_row):
    """:func:`advanced_shift_serial` for ShiftAdvALE / ShiftAdvNCPress runs (see
    :func:`_displace_ale_range`)."""
    n = nb.shape[0]
    _detect_range(0, n, kern, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, nzero, fst, nrm, gc,
                  near, bnd)
    _copy_source_types(fst, src_row)
    _copy_source_normals(nrm, src_row)
    _mark_near_range(0, n, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, fst, near)
    _ale_scan_range(0, n, kern, is2d, nb, ptype, cell, cell_start, ncx, ncy, ncz, cst, fst, nrm, near, mind,
                    nsm, curv)
    _displace_ale_range(0, n, is2d, ale, nc_bnd, ptype, oi, cst, coef, dp, fst, nrm, gc, near, bnd, mind, nsm,
                        curv, shiftpos, fstype_out, normal_out, nctype_out)


@njit(cache=True, parallel=True, error_model="numpy")
def advanced_shift_ale_parallel(kern, is2d, ale, nc_bnd, nb, ptype, cell, oi, cell_start, ncx, ncy, ncz, cst,
                                nzero, coef, dp, fst, nrm, gc, near, bnd, mind, nsm, curv, shiftpos, fstype_out,
                                normal_out, nctype_out, src_row):
    """Threaded :func:`advanced_shift_ale_serial`."""
    n = nb.shape[0]
    nchunk = (n + CHUNK - 1) // CHUNK
    for c in prange(nchunk):
        _detect_range(c * CHUNK, min(n, (c + 1) * CHUNK), kern, is2d, nb, ptype, cell, cell_start,
                      ncx, ncy, ncz, cst, nzero, fst, nrm, gc, near, bnd)
    _copy_source_types(fst, src_row)
    _copy_source_normals(nrm, src_row)
    for c in prange(nchunk):
        _mark_near_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, nb, ptype, cell, cell_start,
                         ncx, ncy, ncz, cst, fst, near)
    for c in prange(nchunk):
        _ale_scan_range(c * CHUNK, min(n, (c + 1) * CHUNK), kern, is2d, nb, ptype, cell, cell_start,
                        ncx, ncy, ncz, cst, fst, nrm, near, mind, nsm, curv)
    for c in prange(nchunk):
        _displace_ale_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, ale, nc_bnd, ptype, oi, cst, coef, dp, fst,
                            nrm, gc, near, bnd, mind, nsm, curv, shiftpos, fstype_out, normal_out, nctype_out)


def full_support_neighbours(h, dp, is2d):
    """Neighbours a full kernel support (radius 2h) holds on a lattice of spacing dp."""
    if is2d:
        return math.pi * (2.0 * h) ** 2 / dp ** 2
    return 4.0 / 3.0 * math.pi * (2.0 * h) ** 3 / dp ** 3

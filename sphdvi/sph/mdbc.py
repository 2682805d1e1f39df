r"""Modified dynamic boundary conditions, mDBC (English et al. 2022), as DualSPHysics v5.4.

Each boundary particle b carries a normal vector N_b pointing from the
particle to the boundary surface (|N_b| is the distance to the surface;
DualSPHysics stores 2 N_b).  Its ghost node g = r_b + 2 N_b lies inside the
fluid.  Over the fluid particles j near g (V = m/rho, w = W(|g - r_j|), grad w
its gradient with respect to g) the first-order consistent kernel
interpolation (Liu & Liu 2006) gives the density and its gradient at g:

  [ sum V w        sum V w (r_j-g)^T      ] [rho_g     ]   [ sum m w      ]
  [ sum V grad w   sum V grad w (r_j-g)^T ] [grad rho_g] = [ sum m grad w ]

with the matrix A on the left.  Particles with N_b = 0 keep plain DBC
behaviour in every mode.

Floating bodies: their particles with a normal get the density the walls get
(DualSPHysics's ``UseNormalsFt``: the correction runs over every particle, fluid
excluded), the normals turning with the body
(:mod:`sphdvi.coupling`); the fluid force on the body then comes from the
extrapolated pressure instead of the DBC density, and the water no longer keeps
the DBC gap of ~1 dp off the body.  The fluid sees those particles with the
lattice's mass rho0 dp^d (:func:`sphdvi.case.normals.mdbc_floating_mask`), not
their share of the body's mass as DualSPHysics does: an extrapolated density
does not rise to make up for a light body's small particle mass as a DBC
density does, and the water slipped into the particles of a box of rho/rho0
0.5.  With SlipMode 2 and 3 that density is the only part of mDBC2 a floating
particle takes, as in DualSPHysics v5.4 (InteractionMdbc2CorrectionT2 over Np,
InteractionForcesFluid): a dry one gets rho0 but keeps its mass (the switch-off
acts on wall neighbours only), the viscosity sees its own velocity (the
tangential ghost velocity is the walls'), and the pressure cloning has no wall
acceleration (DualSPHysics's MotionAce is zero for floating particles).

Flexible structures (:mod:`sphdvi.sph.flexstruc`, mDBC2 only, as DualSPHysics v5.4): their
particles are moving walls whose normals turn with the solid's F (set before each correction);
the flexible ones (``flexid`` by particle id; the clamps are ordinary walls) take the Shepard ghost
density (and velocity) whatever the matrix, before the pressure cloning, whose wall acceleration
is that of their own update (InteractionMdbc2CorrectionT2's !CODE_IsFlexStrucFlex test).

SlipMode 1 (DBC velocity; DualSPHysics's original mDBC)
    rho_b = rho_g + (r_b - g) . grad rho_g; the Shepard value
    sum m w / sum V w where |det A| is below ``threshold`` (1e-3); with no fluid
    particle within reach of g (sum V w = 0) rho_b = rho0; with a kernel sum
    not above ``MdbcThreshold`` (default 0; DualSPHysics v5.4 has none) the
    density is left as it is.  Not clamped: where the hydrostatic line extends
    above a free surface rho_b falls below rho0 and the fluid sees a negative
    wall pressure for that interaction, as DualSPHysics v5.4
    (``JSphCpu_mdbc.cpp`` InteractionMdbcCorrectionT2); the integrator's
    rho >= rho0 for boundary particles holds between corrections.  (sphdvi
    clamped the result to rho0 until 2026-11: S16M's roll rms was -23.0 /
    -8.6 % at box/dp 5 / 10 against -15.2 / -10.5 % unclamped, with the box
    normals of then; README, S16.)  The wall particle shows the fluid its own
    (wall) velocity.

SlipMode 2 (no-slip) and 3 (free-slip): DualSPHysics's mDBC2 with a choice of
ghost velocity (``JSphCpu_mdbc.cpp`` InteractionMdbc2CorrectionT2, ``JSphGpu_mdbc_iker.cu``
KerInteractionMdbc2Correction_Fast, ``JSphCpu.cpp`` InteractionForcesFluid;
CPU and GPU agree):

* Submersion: s = -sum V (g - r_j) . grad w (>= 0: grad w = fac (g - r_j),
  fac <= 0), positive as soon as one fluid particle lies within the kernel
  support of g.  With s = 0 the ghost node is dry and the particle is
  switched off for the step: zero mass in the fluid's sums (pressure,
  viscosity, continuity, density diffusion, shifting), rho_b = rho0; as a
  wall neighbour it still switches Fourtakas's diffusion (DensityDT 2) and
  the shifting of modes 1-2 off, as in DualSPHysics.
* Ghost density rho_g: the first row of the solution of the system above if
  the kernel sum sum V w >= 0.1, |det A| >= 1e-3 and the scaled condition
  number dp^2 |A|_inf |A^-1|_inf <= 50 (infinity norms: largest row sum);
  otherwise the Shepard value sum m w / sum V w (raised to rho0 when the
  kernel sum is below 0.1).  The gradient is not used.
* Pressure cloning: with e = N_b/|N_b|, p_g = c0^2 (rho_g - rho0) and a_w the
  wall acceleration,
      p_b = p_g + rho0 ((g_vec - a_w) . e) ((r_b - g) . e),
  the hydrostatic (and inertial) pressure difference between the ghost node
  and the particle, and rho_b = rho0 + p_b / c0^2.  No clamping: rho_b may
  be below rho0.  a_w is (v_w^{n+1} - v_w^n)/dt of the moving particles as
  the motion sets them (DualSPHysics's CopyMotionVelAce), zero for fixed ones.
* Ghost velocity v_g (``MdbcGhostVelocity``, sphdvi's own key): 1 (default)
  the first-order corrected interpolation at g, the first row of the solution
  of the system above with right-hand sides (sum V w v_j, sum V grad w v_j),
  where the density is corrected (else the Shepard average); 0 the plain
  kernel (Shepard) average sum V w v_j / sum V w, as DualSPHysics.  The wall
  particle's velocity v2 is 2 v_w - v_g (no-slip) or v_g (free-slip), v_w
  its own (motion) velocity; dry: v2 = v_w.
* In the fluid's interaction the wall particle keeps its motion velocity v_w
  in the continuity equation (DualSPHysics keeps it in ``velrho``,
  MDBC2_KEEPVEL), while the viscosity (artificial or laminar, and the
  viscous time-step term) sees the tangential part of v2,
  t = v2 - (v2 . e) e (``tvel``, per packed row).
* ``MdbcThreshold`` is not used (DualSPHysics v5.4's mDBC2 has none).

Consequences measured in tests/sph/test_poiseuille.py and test_mdbc_slip.py:
near a wall the Shepard ghost velocity (MdbcGhostVelocity 0) is a one-sided
average, so a no-slip wall acts 0.13-0.15 dp inside the fluid (Poiseuille
centre-line speed -4 x 0.14 dp/d, -1 % at 30 across); the corrected one is
exact for a linear velocity profile and has no such offset.  The linearised
cloning (c0^2 (rho - rho0) for Tait's equation) overestimates the hydrostatic
wall pressure by about 6 (g d / c0^2) rho0 g dz (0.3-0.75 % of rho0 g d at
d/dp = 25-10); the scaled condition number is dimensional (dp in metres): it
rejects no matrix at dp = 0.05 m and some at dp = 2 m.  That is DualSPHysics
v5.4's own rule, checked in its source: ``condinf = Dp*Dp*|A|_inf*|A^-1|_inf``
on the unscaled matrix, ``Dp`` in metres, threshold 50 (JSphCpu_mdbc.cpp,
InteractionMdbc2CorrectionT2; the GPU kernel alike); its determinant (1e-3)
and kernel-sum (0.1) thresholds and the unclamped Shepard fallback are also
the ones used here.

Deviations: the default ghost velocity is the corrected one (above).  A
particle with N_b = 0 shows the viscosity its own velocity
(DualSPHysics reads its TangenVel entry, which nothing sets).

In the Symplectic corrector the correction runs only with ``MDBCCorrector``
(the solver's ``_mdbc_now``): not set, as DualSPHysics v5.4, it is off for
SlipMode 1 (the corrector sees the wall densities the predictor integrated)
and on for SlipMode 2, 3, where v5.4 always corrects (0 is warned and ignored).

Why the ghost velocity is kept out of the continuity equation: the no-slip
wall velocity 2 v_w - v_g is odd about the wall in its tangential component
too.  In the continuity sum of a fluid particle next to a wall that turns
the tangential derivative of the tangential velocity around (its mirror
image has d(-v_t)/ds), so the wall half of the kernel measures a divergence
dv_n/dn - dv_t/ds = 2 dv_n/dn where the flow has none.  In a sloshing tank
that compresses and dilates the water along the side walls in phase with the
wave: sphdvi's earlier SlipMode 2, which showed 2 v_w - v_g (first-order
corrected v_g) to the continuity and the viscosity, shortened the period of
the S7 case by 5.5 % (gauge 17 %) at d/dp = 20; the same with the wall
velocity in the continuity gives -1.4 %, and this treatment -0.7 %
(tests/sph/test_mdbc_slip.py checks a coarse tank).

``NoPenetration`` (slip modes 2 and 3) corrects the fluid particles next to
the walls, not the boundary particles: :mod:`sphdvi.sph.nopen`.

Periodic boundaries: the correction runs on the extended set (the particles and
their copies within 2h of the periodic ends); a copy of a wall or floating
particle then takes its real particle's packed density, pressure, mass (zero
when dry) and tangential velocity (:func:`copy_to_periodic_rows`), as
DualSPHysics gets by wrapping the ghost node into the domain (UpdatePeriodicPos
in InteractionMdbcCorrectionT2 / InteractionMdbc2CorrectionT2): the copy's own
ghost node, up to 2h beyond the end, sees only part of a kernel of fluid
(0.5-1.7 kg/m3 off in a disturbed channel).
"""
import math

from . import _env  # noqa: F401
import numpy as np
from numba import njit, prange

from .interaction import tait_pressure
from .kernels import kernel_fac, kernel_w
from .linalg import solve_pivoted

_NO_SKIP = np.zeros(0, np.int8)      # _ghost_sums leaves out no fluid particle
_NO_IDP = np.zeros(0, np.int64)

# mDBC2 (SlipMode 2, 3) limits, DualSPHysics v5.4 (JSphCpu_mdbc.cpp, JSphGpu_mdbc_iker.cu)
MDBC2_KSUM_MIN = 0.1      # kernel sum at the ghost node below which the Shepard density is used
MDBC2_DET_MIN = 1e-3      # |det A| below which the Shepard density is used
MDBC2_COND_MAX = 50.0     # scaled condition number dp^2 |A|_inf |A^-1|_inf above which likewise


@njit(cache=True, error_model="numpy")
def _ghost_sums(kern, is2d, nb, ptype, cell_start, pmin, inv_cell, ncx, ncy, ncz, cst,
                i, nx, ny, nz, a, b, vsum, skip_of_idp=_NO_SKIP, idp=_NO_IDP, oi=_NO_IDP):
    """Sums over the fluid particles j near the ghost node g = r_i + 2 N of
    packed boundary row i with normal N = (nx, ny, nz):
    the moment matrix a (see the module docstring), the right-hand side
    b[:, 0] = (sum m w, sum m grad w), and, when ``vsum`` has 4 entries (mDBC2),
    sum V w v_j in vsum[0:3], the submersion measure -sum V (g - r_j).grad w
    in vsum[3] and the velocity right-hand sides b[:, 1:4] = (sum V w v_j,
    sum V grad w v_j) of the corrected ghost velocity.  ``skip_of_idp`` (by particle id,
    packed row j's particle oi[j]): fluid particles with a value >= 0 left out (the buffers
    of inlet/outlet zones, :mod:`sphdvi.sph.inout`); empty: none."""
    if is2d:
        gx = nb[i, 0] + 2.0 * nx
        gy = 0.0
        gz = nb[i, 1] + 2.0 * nz
    else:
        gx = nb[i, 0] + 2.0 * nx
        gy = nb[i, 1] + 2.0 * ny
        gz = nb[i, 2] + 2.0 * nz
    h = cst[0]
    r2max = cst[1]
    alpha = cst[3]
    alpha_h2 = cst[4]
    mdbc2 = vsum.shape[0] == 4
    for r in range(4):
        for cc in range(b.shape[1]):
            b[r, cc] = 0.0
        for cc in range(4):
            a[r, cc] = 0.0
    if mdbc2:
        for c in range(4):
            vsum[c] = 0.0
    cx = min(max(int((gx - pmin[0]) * inv_cell), 0), ncx - 1)
    cy = min(max(int((gy - pmin[1]) * inv_cell), 0), ncy - 1) if not is2d else 0
    cz = min(max(int((gz - pmin[2]) * inv_cell), 0), ncz - 1)
    rs = int(cst[18])
    for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
        for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
            row = (z * ncy + y) * ncx
            for j in range(cell_start[row + max(cx - rs, 0)],
                           cell_start[row + min(cx + rs, ncx - 1) + 1]):
                if ptype[j] != 3:
                    continue
                if skip_of_idp.shape[0] and skip_of_idp[idp[oi[j]]] >= 0:
                    continue
                if is2d:
                    dx = gx - nb[j, 0]
                    dy = 0.0
                    dz = gz - nb[j, 1]
                    mj = nb[j, 6]
                    vj = mj * nb[j, 7]
                else:
                    dx = gx - nb[j, 0]
                    dy = gy - nb[j, 1]
                    dz = gz - nb[j, 2]
                    mj = nb[j, 8]
                    vj = mj * nb[j, 9]
                r2 = dx * dx + dy * dy + dz * dz
                if r2 >= r2max:
                    continue
                q = math.sqrt(r2) / h
                w = kernel_w(kern, q, alpha)
                fac = kernel_fac(kern, q, alpha_h2) if r2 > 1e-18 else 0.0
                # gradient with respect to g, and r_j - g
                if is2d:
                    gw0 = fac * dx
                    gw1 = fac * dz
                    d0 = -dx
                    d1 = -dz
                    gw2 = 0.0
                    d2 = 0.0
                else:
                    gw0 = fac * dx
                    gw1 = fac * dy
                    gw2 = fac * dz
                    d0 = -dx
                    d1 = -dy
                    d2 = -dz
                a[0, 0] += vj * w
                a[0, 1] += vj * w * d0
                a[0, 2] += vj * w * d1
                b[0, 0] += mj * w
                a[1, 0] += vj * gw0
                a[1, 1] += vj * gw0 * d0
                a[1, 2] += vj * gw0 * d1
                b[1, 0] += mj * gw0
                a[2, 0] += vj * gw1
                a[2, 1] += vj * gw1 * d0
                a[2, 2] += vj * gw1 * d1
                b[2, 0] += mj * gw1
                if not is2d:
                    a[0, 3] += vj * w * d2
                    a[1, 3] += vj * gw0 * d2
                    a[2, 3] += vj * gw1 * d2
                    a[3, 0] += vj * gw2
                    a[3, 1] += vj * gw2 * d0
                    a[3, 2] += vj * gw2 * d1
                    a[3, 3] += vj * gw2 * d2
                    b[3, 0] += mj * gw2
                if mdbc2:
                    if is2d:
                        u0 = nb[j, 2]
                        u1 = 0.0
                        u2 = nb[j, 3]
                    else:
                        u0 = nb[j, 3]
                        u1 = nb[j, 4]
                        u2 = nb[j, 5]
                    vw = vj * w
                    vsum[0] += vw * u0
                    vsum[1] += vw * u1
                    vsum[2] += vw * u2
                    b[0, 1] += vw * u0
                    b[0, 2] += vw * u1
                    b[0, 3] += vw * u2
                    b[1, 1] += vj * gw0 * u0
                    b[1, 2] += vj * gw0 * u1
                    b[1, 3] += vj * gw0 * u2
                    b[2, 1] += vj * gw1 * u0
                    b[2, 2] += vj * gw1 * u1
                    b[2, 3] += vj * gw1 * u2
                    if not is2d:
                        b[3, 1] += vj * gw2 * u0
                        b[3, 2] += vj * gw2 * u1
                        b[3, 3] += vj * gw2 * u2
                    # -V (g - r_j).grad w = -V fac r^2 >= 0 (fac <= 0)
                    vsum[3] -= vj * fac * r2


@njit(cache=True, error_model="numpy")
def _mdbc_range(i0, i1, kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell,
                ncx, ncy, ncz, cst, threshold, ksum_min, rhop):
    """SlipMode 1: density only, walls and floating particles (module docstring)."""
    rhop0 = cst[10]
    n = 3 if is2d else 4
    a = np.zeros((4, 4))
    b = np.zeros((4, 1))
    novel = np.zeros(0)
    for i in range(i0, i1):
        if ptype[i] == 3:
            continue
        o = oi[i]   # row of particle i in normals and rhop
        nx = normals[o, 0]
        ny = normals[o, 1]
        nz = normals[o, 2]
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            continue
        _ghost_sums(kern, is2d, nb, ptype, cell_start, pmin, inv_cell, ncx, ncy, ncz, cst,
                    i, nx, ny, nz, a, b, novel)
        if a[0, 0] <= 0.0:
            rhop[o] = rhop0
            continue
        if a[0, 0] <= ksum_min:
            continue
        # Shepard value, kept where the corrected system is near-singular
        rho = b[0, 0] / a[0, 0]
        if solve_pivoted(a, b, n, 1, 0.0) >= threshold:
            if is2d:
                rho = b[0, 0] - 2.0 * (nx * b[1, 0] + nz * b[2, 0])
            else:
                rho = b[0, 0] - 2.0 * (nx * b[1, 0] + ny * b[2, 0] + nz * b[3, 0])
        rhop[o] = rho


@njit(cache=True, error_model="numpy")
def _inf_norm(a, n, c0):
    """Largest row sum of |a[:n, c0:c0+n]|."""
    m = 0.0
    for r in range(n):
        s = 0.0
        for c in range(n):
            s += abs(a[r, c0 + c])
        m = max(m, s)
    return m


@njit(cache=True, error_model="numpy")
def _set_packed(nb, i, is2d, rho, cst, dry):
    """Packed density, pressure (Tait) and 1/rho of boundary row i; zero mass when dry."""
    p = tait_pressure(rho, cst[16], cst[10], cst[17])
    if is2d:
        nb[i, 4] = rho
        nb[i, 5] = p
        nb[i, 7] = 1.0 / rho
        if dry:
            nb[i, 6] = 0.0
    else:
        nb[i, 6] = rho
        nb[i, 7] = p
        nb[i, 9] = 1.0 / rho
        if dry:
            nb[i, 8] = 0.0


@njit(cache=True, error_model="numpy")
def _mdbc2_range(i0, i1, kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell,
                 ncx, ncy, ncz, cst, dp, rhop, slip, ghostvel, idp, flexid, tvel, wace):
    """SlipMode 2, 3 (DualSPHysics's mDBC2, module docstring): density with
    pressure cloning, zero mass for a dry ghost node, and the tangential velocity
    the viscosity sees in tvel[i] (packed row i); ghost velocity corrected
    (``ghostvel`` 1) or the Shepard average (0, DualSPHysics).  Floating rows
    (ptype 2) with a normal get the density alone: rho0 when dry, their mass kept,
    no wall acceleration in the cloning.  The particles of a flexible structure
    (``flexid[idp[row]]`` 1; ``flexid`` empty: none) take the Shepard ghost density and
    velocity whatever the matrix (DualSPHysics's !CODE_IsFlexStrucFlex test)."""
    rhop0 = cst[10]
    cs02 = cst[5] * cst[5]
    n = 3 if is2d else 4
    has_ace = wace.shape[0] == rhop.shape[0]
    a = np.zeros((4, 4))
    # right-hand sides: column 0 the density, 1-3 the velocity, 4..3+n the identity (inverse of a)
    b = np.zeros((4, 8))
    vsum = np.zeros(4)
    vw = np.zeros(3)
    v2 = np.zeros(3)
    for i in range(i0, i1):
        if ptype[i] == 3:
            continue
        floating = ptype[i] == 2
        if is2d:
            vw[0] = nb[i, 2]
            vw[1] = 0.0
            vw[2] = nb[i, 3]
        else:
            vw[0] = nb[i, 3]
            vw[1] = nb[i, 4]
            vw[2] = nb[i, 5]
        for c in range(3):
            tvel[i, c] = vw[c]          # no normal: DBC (the wall velocity)
        o = oi[i]   # row of particle i in normals, rhop and wace
        nx = normals[o, 0]
        ny = normals[o, 1]
        nz = normals[o, 2]
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            continue
        nn = math.sqrt(nx * nx + ny * ny + nz * nz)
        ex = nx / nn
        ey = ny / nn
        ez = nz / nn
        _ghost_sums(kern, is2d, nb, ptype, cell_start, pmin, inv_cell, ncx, ncy, ncz, cst,
                    i, nx, ny, nz, a, b, vsum)
        if not vsum[3] > 0.0:
            # dry ghost node: rho0 and the wall velocity; a wall particle is switched off
            # (zero mass), a floating one keeps its mass (DualSPHysics: walls only)
            rhop[o] = rhop0
            _set_packed(nb, i, is2d, rhop0, cst, not floating)
            vn = vw[0] * ex + vw[1] * ey + vw[2] * ez
            tvel[i, 0] = vw[0] - vn * ex
            tvel[i, 1] = vw[1] - vn * ey
            tvel[i, 2] = vw[2] - vn * ez
            continue
        ksum = a[0, 0]
        shepard = b[0, 0] / ksum
        corrected = False
        flexible = False
        if flexid.shape[0]:
            pid = idp[o]
            flexible = pid < flexid.shape[0] and flexid[pid] != 0
        if ksum < MDBC2_KSUM_MIN:
            rho_g = max(rhop0, shepard)
        elif flexible:
            rho_g = shepard
        else:
            rho_g = shepard
            norm_a = _inf_norm(a, n, 0)
            for r in range(n):
                for c in range(n):
                    b[r, 4 + c] = 1.0 if r == c else 0.0
            if solve_pivoted(a, b, n, n + 4, 0.0) >= MDBC2_DET_MIN:
                if dp * dp * norm_a * _inf_norm(b, n, 4) <= MDBC2_COND_MAX:
                    rho_g = b[0, 0]
                    corrected = True
        # pressure cloning: p_b = p_g + rho0 (g - a_w).e ((r_b - g).e), e the unit normal
        fx = cst[12]
        fy = cst[13]
        fz = cst[14]
        if has_ace and not floating:
            fx -= wace[o, 0]
            fy -= wace[o, 1]
            fz -= wace[o, 2]
        if is2d:
            fy = 0.0
        p_b = cs02 * (rho_g - rhop0) - rhop0 * (fx * ex + fy * ey + fz * ez) * 2.0 * nn
        rho = rhop0 + p_b / cs02
        rhop[o] = rho
        _set_packed(nb, i, is2d, rho, cst, False)
        # ghost velocity: corrected (the solution's first row) or the Shepard
        # average; no-slip 2 v_w - v_g, free-slip v_g
        for c in range(3):
            vg = b[0, 1 + c] if ghostvel == 1 and corrected else vsum[c] / ksum
            v2[c] = 2.0 * vw[c] - vg if slip == 2 else vg
        vn = v2[0] * ex + v2[1] * ey + v2[2] * ez
        tvel[i, 0] = v2[0] - vn * ex
        tvel[i, 1] = v2[1] - vn * ey
        tvel[i, 2] = v2[2] - vn * ez


@njit(cache=True, error_model="numpy")
def _refresh_packed(i0, i1, is2d, ptype, oi, rhop, cst, nb):
    """Packed density, pressure and 1/rho of the boundary and floating rows from ``rhop``."""
    for i in range(i0, i1):
        if ptype[i] == 3:
            continue
        _set_packed(nb, i, is2d, rhop[oi[i]], cst, False)


@njit(cache=True, error_model="numpy")
def copy_to_periodic_rows(is2d, nb, ptype, src_row, tvel):
    """Periodic copies of wall and floating particles: the packed density, pressure,
    mass (zero when dry) and 1/rho, and the tangential velocity (``tvel`` with one row
    per packed row, mDBC2; shorter: none) of packed row ``src_row[i]``, the row of the
    real particle, as DualSPHysics gets by wrapping the ghost node into the domain
    (UpdatePeriodicPos in InteractionMdbcCorrectionT2 / InteractionMdbc2CorrectionT2):
    the copy's own ghost node sees only the truncated extended set."""
    c0 = 4 if is2d else 6
    has_tvel = tvel.shape[0] >= nb.shape[0]
    for i in range(nb.shape[0]):
        s = src_row[i]
        if s == i or ptype[i] == 3:
            continue
        for c in range(c0, c0 + 4):
            nb[i, c] = nb[s, c]
        if has_tvel:
            for c in range(3):
                tvel[i, c] = tvel[s, c]


@njit(cache=True, error_model="numpy")
def mdbc_serial(kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx, ncy, ncz,
                cst, threshold, ksum_min, rhop, slip, ghostvel, dp, idp, flexid, tvel, wace):
    """Set the density of every boundary particle with a normal and refresh its
    packed row (module docstring).  SlipMode 2, 3 also set ``tvel`` (packed rows,
    3 columns: the velocity the viscosity sees) and zero the packed mass of the
    particles whose ghost node is dry; ``wace`` is the wall acceleration per
    particle (rows as ``normals``), or an array of another length for none;
    ``flexid`` (int8 by particle id, ``idp`` the ids by row as ``normals``) marks
    the flexible-structure particles, which take the Shepard ghost density (empty:
    none).  ``threshold`` and ``ksum_min`` serve SlipMode 1 only."""
    n = nb.shape[0]
    if slip == 1:
        _mdbc_range(0, n, kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx,
                    ncy, ncz, cst, threshold, ksum_min, rhop)
        _refresh_packed(0, n, is2d, ptype, oi, rhop, cst, nb)
    else:
        _mdbc2_range(0, n, kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx,
                     ncy, ncz, cst, dp, rhop, slip, ghostvel, idp, flexid, tvel, wace)


@njit(cache=True, parallel=True, error_model="numpy")
def mdbc_parallel(kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx, ncy, ncz,
                  cst, threshold, ksum_min, rhop, slip, ghostvel, dp, idp, flexid, tvel, wace):
    """Threaded :func:`mdbc_serial`."""
    n = nb.shape[0]
    nchunk = (n + 511) // 512
    if slip == 1:
        for c in prange(nchunk):
            _mdbc_range(c * 512, min(n, (c + 1) * 512), kern, is2d, nb, ptype, oi, normals,
                        cell_start, pmin, inv_cell, ncx, ncy, ncz, cst, threshold, ksum_min,
                        rhop)
        for c in prange(nchunk):
            _refresh_packed(c * 512, min(n, (c + 1) * 512), is2d, ptype, oi, rhop, cst, nb)
    else:
        # reads only fluid rows of nb and writes only boundary rows: one pass
        for c in prange(nchunk):
            _mdbc2_range(c * 512, min(n, (c + 1) * 512), kern, is2d, nb, ptype, oi, normals,
                         cell_start, pmin, inv_cell, ncx, ncy, ncz, cst, dp, rhop, slip, ghostvel,
                         idp, flexid, tvel, wace)


@njit(cache=True, error_model="numpy")
def keep_moving_velocity(ptype, vel, v0):
    """v0[i] = vel[i] for the moving boundary particles (type 1): their velocity before the motion
    places them, for :func:`moving_wall_ace` (one pass, nothing allocated; audit e, finding 5)."""
    for i in range(ptype.shape[0]):
        if ptype[i] == 1:
            for k in range(3):
                v0[i, k] = vel[i, k]


@njit(cache=True, error_model="numpy")
def moving_wall_ace(ptype, vel, v0, dt, wall_ace):
    """wall_ace[i] = (v^{n+1} − v^n)/dt of the moving boundary particles (type 1), the wall
    acceleration of mDBC2's pressure cloning: DualSPHysics's CopyMotionVelAce (MotionAce)."""
    for i in range(ptype.shape[0]):
        if ptype[i] == 1:
            for k in range(3):
                wall_ace[i, k] = (vel[i, k] - v0[i, k]) / dt

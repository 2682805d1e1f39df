"""Small particle scenes built directly as arrays (tests and benchmarks).

DualSPHysics conventions: 2D runs lie in the x-z plane with gravity along
-z; particles sit on a dp lattice; walls are DBC boundary particles at dp
spacing; fluid starts one dp away from the walls.
"""
import math

import numpy as np

from .state import FIXED, FLUID, FluidState


def lattice_2d(x0, x1, z0, z1, dp):
    """Points of the dp lattice with x0 <= x <= x1, z0 <= z <= z1 (y = 0)."""
    nx = int(math.floor((x1 - x0) / dp + 1e-9)) + 1
    nz = int(math.floor((z1 - z0) / dp + 1e-9)) + 1
    x = x0 + dp * np.arange(nx)
    z = z0 + dp * np.arange(nz)
    X, Z = np.meshgrid(x, z, indexing="xy")
    pos = np.zeros((X.size, 3))
    pos[:, 0] = X.ravel()
    pos[:, 2] = Z.ravel()
    return pos


def constants_2d(dp, coefh=1.0, cs0=None, coefsound=20.0, hswl=1.0, rhop0=1000.0,
                 gamma=7.0, g=9.81, cfl=0.2):
    """GenCase-style constants for a 2D case (h = coefh sqrt(2) dp, c0 = coefsound sqrt(g hswl))."""
    h = coefh * math.sqrt(2.0) * dp
    if cs0 is None:
        cs0 = coefsound * math.sqrt(g * hswl)
    return {"dp": dp, "h": h, "cs0": cs0, "rhop0": rhop0, "gamma": gamma,
            "b": cs0 * cs0 * rhop0 / gamma, "gravity": [0.0, 0.0, -g], "is2d": True,
            "cflnumber": cfl, "massfluid": rhop0 * dp * dp, "massbound": rhop0 * dp * dp}


def tank_2d(tank_w, tank_h, fluid_w, fluid_h, dp, layers=1, hydrostatic=True,
            bound_hydrostatic=False, **const_kw):
    """Open-top 2D tank [0, tank_w] x [0, tank_h] holding a fluid block.

    Boundary: ``layers`` rows of particles at dp spacing on the bottom (z <= 0)
    and the left/right walls (x <= 0, x >= tank_w).  Fluid: the lattice
    x in [dp, fluid_w], z in [dp, fluid_h] (clipped one dp inside the right wall).
    Initial fluid density hydrostatic (DualSPHysics rhopgradient 2) from
    the column top.  Returns (state, constants).
    """
    fl = lattice_2d(dp, min(fluid_w, tank_w - dp), dp, fluid_h, dp)
    hswl = fl[:, 2].max() - fl[:, 2].min()
    c = constants_2d(dp, hswl=const_kw.pop("hswl", hswl), **const_kw)
    walls = []
    for k in range(layers):
        off = k * dp
        walls.append(lattice_2d(-off, tank_w + off, -off, -off, dp))          # bottom
        walls.append(lattice_2d(-off, -off, dp - off * 0, tank_h, dp))        # left
        walls.append(lattice_2d(tank_w + off, tank_w + off, dp, tank_h, dp))  # right
    bd = np.unique(np.round(np.concatenate(walls) / dp).astype(np.int64), axis=0) * dp
    bd = bd.astype(float)
    pos = np.concatenate([bd, fl])
    nb = bd.shape[0]
    n = pos.shape[0]
    ptype = np.full(n, FLUID, np.int8)
    ptype[:nb] = FIXED
    rho = np.full(n, c["rhop0"])
    top = fl[:, 2].max() + 0.5 * dp
    if hydrostatic:
        depth = np.maximum(top - pos[:, 2], 0.0)
        rh = c["rhop0"] * (1.0 + c["rhop0"] * abs(c["gravity"][2]) * depth / c["b"]) ** (1.0 / c["gamma"])
        sel = ptype == FLUID
        if bound_hydrostatic:
            sel = sel | (pos[:, 2] <= top)
        rho[sel] = rh[sel]
    mass = np.where(ptype == FLUID, c["massfluid"], c["massbound"])
    mk = np.where(ptype == FLUID, 1, 11).astype(np.int32)
    state = FluidState(pos, rhop=rho, mass=mass, ptype=ptype, mk=mk)
    return state, c


def tank_normals_2d(state, tank_w, dp):
    """mDBC normals of the walls built by :func:`tank_2d` (DualSPHysics
    convention: vector from the boundary particle to the wall surface, which
    lies dp/2 inside the first wall layer; corners point to the corner)."""
    x, z = state.pos[:, 0], state.pos[:, 2]
    bound = state.ptype < 2
    sx = np.where(x < 0.5 * tank_w, 0.5 * dp, tank_w - 0.5 * dp)     # wall surfaces
    sz = 0.5 * dp
    nx = np.where((x <= 0) | (x >= tank_w), sx - x, 0.0)
    nz = np.where(z <= 0, sz - z, 0.0)
    n = np.zeros_like(state.pos)
    n[:, 0] = np.where(bound, nx, 0.0)
    n[:, 2] = np.where(bound, nz, 0.0)
    return n


def dambreak_2d(dp=0.01, coefh=1.0):
    """The benchmark dam break: 1 m x 2 m column in a 4 m x 3 m tank.

    c0 = 20 sqrt(9.81 * 2), h = coefh sqrt(2) dp; at dp = 0.01 this is
    20,000 fluid + 1,001 boundary particles.
    """
    return tank_2d(4.0, 3.0, 1.0, 2.0, dp, coefh=coefh, cs0=20.0 * math.sqrt(9.81 * 2.0))


def shepard_pressure(state, press, points, h, kernel=2, is2d=True):
    """Kernel-weighted (Shepard) fluid pressure at ``points`` (M, 3), as gauges do."""
    from .kernels import kernel_alpha
    fl = state.ptype == FLUID
    p = state.pos[fl]
    pr = press[fl]
    vol = state.mass[fl] / state.rhop[fl]
    alpha = kernel_alpha(kernel, h, is2d)
    out = np.empty(len(points))
    for k, x in enumerate(np.asarray(points, float)):
        d = p - x
        if is2d:
            d[:, 1] = 0.0
        q = np.sqrt((d * d).sum(1)) / h
        w = np.zeros_like(q)
        m = q < 2.0
        if kernel == 2:
            t = 1.0 - 0.5 * q[m]
            w[m] = alpha * t ** 4 * (2.0 * q[m] + 1.0)
        else:
            qq = q[m]
            w[m] = alpha * np.where(qq < 1.0, 1 - 1.5 * qq ** 2 + 0.75 * qq ** 3, 0.25 * (2 - qq) ** 3)
        ws = (w * vol).sum()
        out[k] = (w * vol * pr).sum() / ws if ws > 0 else np.nan
    return out

"""Analytic particle snapshots written as a run folder (case h5 + particles.vtkhdf)."""
import os

import numpy as np

from sphdvi.io.casefile import write_case_h5
from sphdvi.io.vtkhdf import VTKHDFParticleWriter
from sphdvi.simulation import POINT_ARRAYS

G = 9.81
RHOP0 = 1000.0
GAMMA = 7.0


def lattice(lo, hi, dp, is2d):
    """Cell-centred lattice filling the box [lo, hi] (centres at dp/2 from the faces)."""
    axes = [np.arange(lo[k] + dp / 2, hi[k] - 1e-9 * dp, dp) for k in range(3)]
    if is2d:
        axes[1] = np.array([0.0])
    g = np.meshgrid(*axes, indexing="ij")
    return np.stack([a.ravel() for a in g], axis=1)


def hydrostatic_tank(length, depth, dp, is2d, width=None, layers=3, coefh=None, kernel=2, fluid_vel=None):
    """Still water of ``depth`` in a tank of ``length`` (x) [x ``width`` (y) in 3D], walls
    of ``layers`` boundary layers. Returns a dict of particle arrays and constants."""
    width = width or length
    coefh = coefh or (1.0 if is2d else 1.0)
    h = coefh * np.sqrt((2 if is2d else 3) * dp * dp)
    cs0 = 10.0 * np.sqrt(G * depth)
    b = cs0 * cs0 * RHOP0 / GAMMA
    wall = layers * dp
    lo_f = np.array([0.0, 0.0, 0.0])
    hi_f = np.array([length, 0.0 if is2d else width, depth])
    fluid = lattice(lo_f, hi_f, dp, is2d)
    lo_b = np.array([-wall, 0.0 if is2d else -wall, -wall])
    hi_b = np.array([length + wall, 0.0 if is2d else width + wall, depth + 4 * dp])
    box = lattice(lo_b, hi_b, dp, is2d)
    inside = (box[:, 0] > 0) & (box[:, 0] < length) & (box[:, 2] > 0)
    if not is2d:
        inside &= (box[:, 1] > 0) & (box[:, 1] < width)
    bound = box[~inside]
    pos = np.concatenate([bound, fluid])
    nb, nf = bound.shape[0], fluid.shape[0]
    ptype = np.concatenate([np.zeros(nb, np.uint8), np.full(nf, 3, np.uint8)])
    # bottom (mkbound 0) and the side walls (mkbound 1)
    fluidcount = 1
    mk = np.where(ptype == 3, 1, np.where(bound_is_bottom(pos), 0, 1) + fluidcount + 1).astype(np.int32)
    zc = np.minimum(pos[:, 2], depth)
    rhop = hydrostatic_density(depth - zc, cs0)
    vol = dp ** (2 if is2d else 3)
    mass = rhop * vol           # the lattice volume: compressed water weighs more
    vel = np.zeros((pos.shape[0], 3))
    if fluid_vel is not None:
        vel[ptype == 3] = fluid_vel(pos[ptype == 3])
    consts = {"dp": dp, "h": h, "b": b, "cs0": cs0, "rhop0": RHOP0, "gamma": GAMMA,
              "gravity": [0.0, 0.0, -G], "massfluid": RHOP0 * vol, "massbound": RHOP0 * vol,
              "is2d": bool(is2d), "posy2d": 0.0, "cflnumber": 0.2}
    params = {"Kernel": kernel, "Visco": 0.01, "ViscoBoundFactor": 1.0, "ViscoTreatment": 1,
              "TimeOut": 0.01, "TimeMax": 0.02}
    return {"pos": pos, "vel": vel, "rhop": rhop, "mass": mass, "type": ptype, "mk": mk,
            "idp": np.arange(pos.shape[0], dtype=np.int64), "constants": consts, "parameters": params,
            "fluidcount": fluidcount, "weight": float(mass[ptype == 3].sum()) * G, "nfluid": nf}


def hydrostatic_density(d, cs0):
    """Density at depth d of water in hydrostatic balance with Tait's EOS
    (dp/dz = -rho g, B = cs0^2 rho0/gamma): rho0 (1 + (gamma-1) g d/cs0^2)^(1/(gamma-1))."""
    return RHOP0 * (1.0 + (GAMMA - 1.0) * G * d / (cs0 * cs0)) ** (1.0 / (GAMMA - 1.0))


def bound_is_bottom(pos):
    return pos[:, 2] < 0


def write_run(outdir, tank, times=(0.0,), gauges=None, moves=None):
    """Write ``tank`` as a gencase file and a particles.vtkhdf with one step per time
    (``moves(t, tank)`` may return (pos, vel, rhop) for each time)."""
    os.makedirs(outdir, exist_ok=True)
    c = tank["constants"]
    parts = {k: tank[k] for k in ("pos", "vel", "rhop", "mass", "type", "mk", "idp")}
    lo = tank["pos"].min(axis=0) - c["h"]
    hi = tank["pos"].max(axis=0) + c["h"]
    write_case_h5(os.path.join(outdir, "Tank.h5"), casename="Tank", source_file="Tank_Def.xml",
                  source_xml="<case/>", version="test", particles=parts, constants=c,
                  parameters=tank["parameters"], domain={"posmin": lo.tolist(), "posmax": hi.tolist()},
                  bodies=[], json_items={"mkconfig": {"fluidcount": tank["fluidcount"], "boundcount": 2},
                                         "gauges": gauges or {}})
    w = VTKHDFParticleWriter(os.path.join(outdir, "particles.vtkhdf"), POINT_ARRAYS)
    for t in times:
        pos, vel, rhop = (tank["pos"], tank["vel"], tank["rhop"]) if moves is None else moves(t, tank)
        press = c["b"] * ((rhop / c["rhop0"]) ** c["gamma"] - 1.0)
        w.append(t, pos, {"Idp": tank["idp"], "Vel": vel, "Rhop": rhop, "Press": press, "Type": tank["type"],
                          "Mk": tank["mk"]})
    w.close()
    return outdir

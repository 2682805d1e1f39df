"""Particle state as a structure of arrays (numpy only, no numba)."""
import numpy as np

FIXED = 0      # fixed boundary particle (DBC)
MOVING = 1     # moving boundary particle (imposed motion)
FLOATING = 2   # floating-body particle (motion from the body solver)
FLUID = 3


class FluidState:
    """Particles of an SPH run.

    Attributes (length N, the current number of live particles):
      pos   (N, 3) float64  position [m] (2D runs use the x-z plane)
      vel   (N, 3) float64  velocity [m/s]
      rhop  (N,)   float64  density [kg/m^3]
      mass  (N,)   float64  mass [kg] (per metre of width in 2D)
      ptype (N,)   int8     0 fixed bound, 1 moving, 2 floating, 3 fluid
      idp   (N,)   int64    permanent particle id
      mk    (N,)   int32    DualSPHysics mk label

    The solver reorders the particles (all arrays together) by cell every
    step: use ``idp`` to follow a particle, and re-read the attributes after
    each step (the solver may swap the arrays for others of the same shape).
    """

    __slots__ = ("pos", "vel", "rhop", "mass", "ptype", "idp", "mk")
    FIELDS = ("pos", "vel", "rhop", "mass", "ptype", "idp", "mk")

    def __init__(self, pos, vel=None, rhop=None, mass=None, ptype=None, idp=None, mk=None,
                 rhop0=1000.0):
        pos = np.ascontiguousarray(pos, dtype=np.float64)
        if pos.ndim != 2 or pos.shape[1] != 3:
            raise ValueError("pos must have shape (N, 3), got %r" % (pos.shape,))
        n = pos.shape[0]
        self.pos = pos.copy()
        self.vel = (np.zeros((n, 3)) if vel is None
                    else np.ascontiguousarray(vel, dtype=np.float64).reshape(n, 3).copy())
        self.rhop = (np.full(n, float(rhop0)) if rhop is None
                     else np.ascontiguousarray(rhop, dtype=np.float64).reshape(n).copy())
        if mass is None:
            raise ValueError("mass is required")
        self.mass = np.ascontiguousarray(np.broadcast_to(np.asarray(mass, np.float64), (n,))).copy()
        self.ptype = (np.full(n, FLUID, np.int8) if ptype is None
                      else np.ascontiguousarray(ptype, dtype=np.int8).reshape(n).copy())
        self.idp = (np.arange(n, dtype=np.int64) if idp is None
                    else np.ascontiguousarray(idp, dtype=np.int64).reshape(n).copy())
        self.mk = (np.zeros(n, np.int32) if mk is None
                   else np.ascontiguousarray(mk, dtype=np.int32).reshape(n).copy())
        if np.any((self.ptype < 0) | (self.ptype > 3)):
            raise ValueError("ptype must be 0 (fixed), 1 (moving), 2 (floating) or 3 (fluid)")

    @property
    def n(self):
        return self.pos.shape[0]

    def copy(self):
        return FluidState(self.pos, self.vel, self.rhop, self.mass, self.ptype, self.idp, self.mk)

    def sorted_by_idp(self):
        """A copy with the particles in idp order (handy for comparisons)."""
        o = np.argsort(self.idp, kind="stable")
        return FluidState(self.pos[o], self.vel[o], self.rhop[o], self.mass[o],
                          self.ptype[o], self.idp[o], self.mk[o])

    def select(self, keep):
        """Keep only the particles where the boolean mask ``keep`` is true (in place)."""
        for f in self.FIELDS:
            setattr(self, f, np.ascontiguousarray(getattr(self, f)[keep]))

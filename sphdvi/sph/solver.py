"""The SPH solver: advances a :class:`FluidState` one time step at a time.

Physics sees arrays only: no files, no CLI.  Built from two plain dicts:

``constants`` (names as GenCase resolves them, ``sphdvi.case`` Constants.to_dict()):
  dp, h, b, cs0, rhop0, gamma, gravity (3 floats), is2d, cflnumber,
  massfluid / mass_fluid, massbound / mass_bound (used only by helpers that
  build states; the state carries the per-particle mass).

``params`` (DualSPHysics ``<execution><parameters>`` names, case-format.md
§2.8; missing keys take the DualSPHysics defaults in :data:`DEFAULT_PARAMS`,
unknown keys are ignored):
  StepAlgorithm, VerletSteps, Kernel, ViscoTreatment, Visco,
  ViscoBoundFactor, ViscoLaminarEta (sphdvi's own key: eta/h of the laminar term's
  r^2/(r^2 + eta^2), DualSPHysics's 0.1 by default; 0 gives the exact Morris operator,
  finite because grad W / r is finite at r = 0), DensityDT, DensityDTvalue, Shifting, ShiftCoef, ShiftTFS,
  ShiftAdvCoef, ShiftAdvALE, ShiftAdvNCPress (Shifting 4, :mod:`sphdvi.sph.shifting_adv`),
  CoefDtMin, DtIni, DtMin,
  DtFixed, DtAllParticles, RhopOutMin, RhopOutMax, Boundary,
  SlipMode (1 DBC velocity, 2 no-slip, 3 free-slip), MdbcThreshold (SlipMode 1),
  MdbcGhostVelocity (sphdvi's own key, SlipMode 2 and 3: 1, the default, interpolates
  the velocity at the ghost node with the first-order corrected kernel, like the density;
  0 takes DualSPHysics v5.4's plain Shepard average, which puts no-slip walls ~0.14 dp
  inside the water; :mod:`sphdvi.sph.mdbc`), MDBCCorrector (the correction also in the
  Symplectic corrector; not set: as DualSPHysics v5.4, off with SlipMode 1, on with 2 and 3,
  where 0 is warned and ignored),
  NoPenetration (mDBC no-penetration correction of the fluid next to the walls,
  :mod:`sphdvi.sph.nopen`; as DualSPHysics, only with Boundary=2 and SlipMode 2
  or 3: otherwise it is warned and ignored) and the periodic keys (XPeriodicIncY ...,
  XYPeriodic ...; see the ``periodic`` argument).

DtFixedFile is passed as ``dt_table`` (the case reader loads the file);
DtAllParticles selects the particles whose speed limits dt.

"""
import math
import warnings

from . import _env  # noqa: F401
import numba
import numpy as np

from . import cells as _cells
from . import integrators as _int
from . import interaction as _ia
from . import shift_zones as _shift_zones
from . import sps as _sps
from . import timestep as _ts
from .accinput import add_acc_input, fluid_ace_max2
from .exclusion import REASON_NAMES
from .kernels import kernel_alpha, kernel_w
from .specialise import specialised
from .clock import time_reached
from .state import FLUID, FluidState
from ..tables import TimeTable

DEFAULT_PARAMS = {
    "StepAlgorithm": 1, "VerletSteps": 40, "Kernel": 2, "ViscoTreatment": 1,
    "Visco": 0.01, "ViscoBoundFactor": 1.0, "ViscoLaminarEta": 0.1, "DensityDT": 0, "DensityDTvalue": 0.1,
    "Shifting": 0, "ShiftCoef": -2.0, "ShiftTFS": 0.0, "ShiftAdvCoef": -0.01, "CoefDtMin": 0.05,
    "DtIni": 0.0, "DtMin": 0.0, "DtFixed": 0.0, "RhopOutMin": 700.0,
    "RhopOutMax": 1300.0, "Boundary": 1,
}
# Below this many particles every kernel runs serially.  Measured on the 2D dam
# break, 2 threads against 1 (Verlet, whole steps): x0.86 at 301 particles,
# x1.1 at 530-1,000, x1.35-1.58 at 1,900, x1.55-1.66 at 3,600-5,500.
PARALLEL_THRESHOLD = 1500
# Steps between moves of the particle arrays into cell order.  In between, the
# neighbour data are gathered into cell order each step and the particles stay
# put (a full permutation of every array costs ~5 % of a 2D step and does not
# speed up on 2 threads; the gather is a third of it).
REORDER_EVERY = 16
# From this many particles the light kernels (cell indices, packing, integrators) run
# threaded too, on the interaction's rows (sphdvi.sph._env.CHUNK).  2D dam break on 2
# threads, the step threaded against the step with these kernels serial, the median of 40
# paired interleaved rounds: 1.056 of the time at 2,500 particles, 1.008 at 5,500 and
# 10,800, 0.988-0.996 at 21,000, 0.986 at 42,000, each round +-5 % (quartiles): no gain to
# measure on this machine below ~50,000.
LIGHT_THRESHOLD = 50000

_NO_FLEX = np.zeros(0, np.int8)     # mDBC's flexible-particle flags by id: none
_NO_IDS = np.zeros(0, np.int64)

# Compiled entry points shared by all solvers, keyed by the feature flags
# (kept off the instances so that solvers can be deep-copied and pickled).
_ENTRY_CACHE = {}


def resolve_params(params):
    """DualSPHysics defaults updated with ``params`` (unknown keys kept as given)."""
    p = dict(DEFAULT_PARAMS)
    if params:
        p.update({k: v for k, v in params.items() if v is not None})
    return p


class SPHSolver:
    """Weakly-compressible SPH (DualSPHysics formulation) on a FluidState.

    Parameters
    ----------
    state : FluidState
        The particles; modified in place (arrays may be swapped, see FluidState).
    constants, params : dict
        See the module docstring.
    domain : (pmin, pmax) or None
        Simulation box: fluid particles leaving it are excluded and the cell
        grid covers it.  None: the grid follows the particle bounding box and
        no particle is excluded for its position.
    motion_hook : callable(solver, t, dt) or None
        Called at the end of every step (time already advanced).  It must
        set ``state.pos`` and ``state.vel`` of the moving (ptype 1) and
        floating (ptype 2) particles.  Without a hook those particles move
        with their current velocity, r += v dt.  The attribute ``half_step_hook``
        (callable(solver, dt_half), None by default) is called by the Symplectic
        step between the predictor and the corrector's interaction (time not yet
        advanced), to place the floating particles at the half step.
    parallel_threshold : int
        Below this many particles the serial kernels run (no thread launch).
    light_threshold : int
        Below this many particles the light kernels (cell indices, packing, integrators:
        a few ns per particle) run serially, the interaction threaded or not.
    periodic : iterable of "x", "y", "z" or None
        Periodic axes.  DualSPHysics switches an axis on when its
        ``*PeriodicInc*`` key is present in the case (even with value 0), which
        the caller knows; here an axis is periodic when it is listed, when one
        of its Inc keys is non-zero, or when XYPeriodic/XZPeriodic/YZPeriodic
        is 1 (that pair only, increments reset, as DualSPHysics); y in 2D is a
        ValueError.  See :mod:`sphdvi.sph.periodic`.
    cell_mode : "auto" (default), "2h" or "h"
        Cell size of the neighbour search (DualSPHysics ``-cellmode``: full = 2h,
        half = h); ``auto`` takes h unless the grid would be sparse (see
        :meth:`_choose_cell_mode`).
    normals : (N, 3) array or None
        mDBC (``Boundary=2``): per particle (in the order of ``state``), the
        vector from a boundary particle to the boundary surface (DualSPHysics
        convention, ghost node = r + 2 N); zero rows keep DBC.  Required for
        Boundary=2.  See :mod:`sphdvi.sph.mdbc`.
    dt_table : (n, 2) array or None
        ``DtFixedFile`` as (time [s], dt [s]) rows: the time step is
        interpolated linearly at the start of each step (end values outside),
        as DualSPHysics's JSphDtFixed does; ``dt_error`` keeps the largest
        excess of the imposed dt over the variable (CFL) one.
    shift_zones : list of dict or None
        ``<special><shifting><shiftingzone>`` boxes (``posref``, ``vecs``: the three edge
        vectors as rows): with Shifting 1-3 only the fluid particles inside one of them
        are shifted (:mod:`sphdvi.sph.shift_zones`).
    visco_table : (n, 2) array or None
        ``ViscoTime`` as (time [s], Visco) rows: Visco (and Visco x
        ViscoBoundFactor) is interpolated linearly at the start of each step
        (end values outside), as DualSPHysics's JDsViscoInput.

    inout : sphdvi.sph.inout.InOut or None
        Inlet/outlet zones (``<special><inout>``): their buffer particles' velocity and density
        are imposed before each interaction, their rates zeroed after it, and at the end of each
        step particles cross between buffers and fluid, new ones are created and others removed
        (:mod:`sphdvi.sph.inout`); ``N`` changes from step to step.
    bound_corr : (normals, determlimit) or None
        ``<special><boundcorr>`` with DBC (Boundary=1): once a step (the predictor's interaction), mDBC's
        SlipMode 1 density extrapolation on the particles with a non-zero normal (the vector to their
        limit plane; :func:`sphdvi.sph.inout.boundcorr_normals`), first order where |det A| >= determlimit.
    flex : sphdvi.sph.flexstruc.FlexStruc or None
        ``<special><flexstrucs>``: elastic bodies of moving boundary particles, moved by their own solid
        (the motion hook must leave them alone).  Under mDBC2 their normals (from ``normals`` at the
        start) turn with the solid, they take the Shepard ghost density and their own wall acceleration
        (:mod:`sphdvi.sph.flexstruc`).

    After :meth:`step`, ``ace`` (N, 3), ``ar`` (N,) and ``press`` hold the
    accelerations, density rates and pressures of the last interaction, in
    the current particle order (``state.idp`` identifies the particles).
    For floating particles ``ace`` is the fluid force per unit mass, without
    gravity.
    """

    def __init__(self, state, constants, params=None, *, domain=None, motion_hook=None,
                 parallel_threshold=PARALLEL_THRESHOLD, light_threshold=LIGHT_THRESHOLD,
                 periodic=None, normals=None,
                 cell_mode="auto", dt_table=None, visco_table=None, acc_inputs=None, shift_zones=None,
                 inout=None, bound_corr=None, dem=None, flex=None):
        if not isinstance(state, FluidState):
            raise TypeError("state must be a FluidState")
        self.dem = dem                                # RigidAlgorithm 2: the blocks' DEM materials (sphdvi.sph.dem)
        self.flex = flex                              # <flexstrucs>: the flexible bodies (sphdvi.sph.flexstruc)
        self.dem_dt = 0.0                             # DualSPHysics's DemDtForce of the next interaction
        self.acc_inputs = list(acc_inputs or [])     # imposed accelerations (sphdvi.sph.accinput)
        self.inout = inout                            # inlet/outlet zones (sphdvi.sph.inout.InOut) or None
        # <boundcorr>: mDBC's density extrapolation on the DBC walls it lists (normals, determlimit)
        self.bc_determlimit = float(bound_corr[1]) if bound_corr is not None else 0.0
        self.dt_table = None if dt_table is None else np.asarray(dt_table, float).reshape(-1, 2)
        self.dt_error = -np.inf
        self.visco_table = None if visco_table is None else np.asarray(visco_table, float).reshape(-1, 2)
        # looked up every step: contiguous columns and a kept row (sphdvi.tables)
        self._dt_lookup = None if self.dt_table is None else TimeTable.of_rows(self.dt_table)
        self._visco_lookup = None if self.visco_table is None else TimeTable.of_rows(self.visco_table)
        self.state = state
        self.constants = dict(constants)
        self.params = resolve_params(params)
        self.motion_hook = motion_hook
        self.parallel_threshold = int(parallel_threshold)
        self.light_threshold = int(light_threshold)
        self.time = 0.0
        self.nstep = 0
        self.n_dtmin = 0          # steps where dt was raised to DtMin (DtModif)
        self.n_excluded = {name: 0 for name in REASON_NAMES.values()}
        self.excluded = []        # exclusion events since take_excluded(): dicts of time (the end of
                                  # the step that removed them), idp, pos, vel, rhop, reason
        self.last_dt = 0.0
        self._setup_constants()
        self._warn_fixed_below_dtmin()
        self._domain = None
        if domain is not None:
            self._domain = (np.array(domain[0], float), np.array(domain[1], float))
        self.periodicity = self._setup_periodic(periodic)
        if flex is not None:
            self._setup_flex()
        self.bc_normals = None
        if bound_corr is not None and self.boundary == 1:
            self.bc_normals = np.ascontiguousarray(bound_corr[0], dtype=np.float64).reshape(state.n, 3).copy()
        self.shift_zones = None
        if shift_zones and self.rates_shift:
            self.shift_zones = _shift_zones.zone_arrays(shift_zones)
        self.cell_mode = self._choose_cell_mode(cell_mode)
        self.cells = _cells.CellList(self.h, self.is2d, half=self.cell_mode == "h")
        self.cst[18] = self.cells.stencil
        if self.boundary == 2:
            if normals is None:
                raise ValueError("Boundary=2 (mDBC) needs the boundary normals (normals=...)")
            self.normals = np.ascontiguousarray(normals, dtype=np.float64).reshape(state.n, 3).copy()
        # mDBC2 (SlipMode 2, 3) with moving walls: their acceleration, for the pressure cloning
        self._wall_ace_on = self.boundary == 2 and self.slip > 1 and bool(np.any(state.ptype == 1))
        if self._wall_ace_on:
            self.wall_ace = np.zeros((state.n, 3))
            self._wall_v0 = np.zeros((state.n, 3))     # the moving walls' velocity before the hook
        self._no_wall_ace = np.zeros((1, 3))
        self._no_tvel = np.zeros((1, 3))
        # flexible structures under mDBC2: their normals turn with F (from those at the start), their
        # ghost density is Shepard's, their wall acceleration is that of their own update
        self._flex_of_idp = _NO_FLEX
        self._flex_ace = False
        if flex is not None and self._mdbc2_flag:
            flex.set_normals0(self.normals, state.idp)
            self._flex_of_idp = flex.flex_of_idp()
            self._flex_ace = self._wall_ace_on
        self.ftmode = self._floating_mode(state)
        # Symplectic: called between the predictor and the corrector's interaction with the
        # half step dt/2, to move the floating bodies there (set by the caller; see _step_symplectic)
        self.half_step_hook = None
        self._verlet_count = 0
        self.reorder_every = REORDER_EVERY
        self._reorder_next = False
        self._alloc()
        self.dt_pre = self.dtini
        # <savedt>: the terms of the latest dt (dt_terms) and of the step just taken
        # (step_dt_terms), kept only when asked for (keep_dt_terms)
        self.keep_dt_terms = False
        self.dt_terms = self.step_dt_terms = (math.nan,) * 5

    # ------------------------------------------------------------------ set-up
    def _setup_constants(self):
        c = self.constants
        p = self.params
        self.is2d = bool(c["is2d"])
        self.h = h = float(c["h"])
        self.dp = float(c["dp"])
        self.cs0 = float(c["cs0"])
        self.rhop0 = float(c["rhop0"])
        self.gamma = float(c["gamma"])
        self.b = float(c.get("b") or self.cs0 ** 2 * self.rhop0 / self.gamma)
        self.gravity = np.asarray(c["gravity"], float).reshape(3)
        self.cfl = float(c.get("cflnumber", 0.2))
        self.boundary = int(p["Boundary"])
        if self.boundary not in (1, 2):
            raise ValueError("Boundary must be 1 (DBC) or 2 (mDBC)")
        self.slip = int(p.get("SlipMode", 1) or 1) if self.boundary == 2 else 1
        if self.slip not in (1, 2, 3):
            raise ValueError("SlipMode must be 1 (DBC velocity), 2 (no-slip) or 3 (free-slip)")
        self.mdbc_ksum = float(p.get("MdbcThreshold") or 0.0)
        self.ghostvel = int(p.get("MdbcGhostVelocity", 1))
        if self.ghostvel not in (0, 1):
            raise ValueError("MdbcGhostVelocity must be 0 (Shepard average) or 1 (corrected)")
        # the mDBC correction in the Symplectic corrector: DualSPHysics v5.0-5.2 read
        # MDBCCorrector (default 0: the corrector keeps the predictor's wall densities);
        # v5.4 sets it itself, off for SlipMode 1 and on for its mDBC2 modes (2, 3)
        corr = p.get("MDBCCorrector")
        self.mdbc_corrector = self.slip > 1 if corr is None else bool(int(corr))
        if self.boundary == 2 and self.slip > 1 and not self.mdbc_corrector:
            warnings.warn("MDBCCorrector=0 is ignored with SlipMode 2 or 3: the mDBC2 wall "
                          "values are computed in every evaluation (as DualSPHysics v5.4)")
            self.mdbc_corrector = True
        self._in_corrector = False      # True while the Symplectic corrector evaluates the rates
        # NoPenetration: DualSPHysics reads it only for its mDBC2 slip modes (2, 3)
        self.nopen = bool(int(p.get("NoPenetration") or 0))
        if self.nopen and (self.boundary != 2 or self.slip == 1):
            warnings.warn("NoPenetration=1 needs Boundary=2 (mDBC) with SlipMode 2 or 3; "
                          "ignored (as DualSPHysics)")
            self.nopen = False
        self._need_nopen = True         # False in the Symplectic predictor (not corrected)
        self.kernel = int(p["Kernel"])
        self.visco_kind = int(p["ViscoTreatment"])
        self.ddt = int(p["DensityDT"])
        self.shift = int(p["Shifting"])
        if self.kernel not in (1, 2):
            raise ValueError("Kernel must be 1 or 2")
        if self.visco_kind not in (1, 2, 3):
            raise ValueError("ViscoTreatment must be 1, 2 or 3")
        if self.ddt not in (0, 1, 2, 3):
            raise ValueError("DensityDT must be 0..3")
        if self.shift not in (0, 1, 2, 3, 4):
            raise ValueError("Shifting must be 0..4")
        # Shifting 4 (advanced, sphdvi.sph.shifting_adv) runs its own pass; the
        # interaction computes the classic shifting terms of modes 1-3 only
        self.rates_shift = self.shift if self.shift < 4 else 0
        self.shift_adv_coef = float(p["ShiftAdvCoef"])
        # ShiftAdvALE (bit 0) and ShiftAdvNCPress (bit 1) of Shifting 4: a compile-time flag
        # of the interaction, 0 (nothing extra compiled) otherwise
        self.adv = 0
        if self.shift == 4:
            for bit, key in ((1, "ShiftAdvALE"), (2, "ShiftAdvNCPress")):
                v = int(p.get(key) or 0)
                if v not in (0, 1):
                    raise ValueError(f"{key} must be 0 or 1")
                if v:
                    self.adv |= bit
        # whether the next compute_rates runs the advanced-shifting pass: the Symplectic
        # predictor (DualSPHysics order: shift and types from the positions at t^n, used by
        # both interactions of the step and applied in the corrector); Verlet every step
        self._need_shift_adv = True
        self.step_algorithm = int(p["StepAlgorithm"])
        if self.step_algorithm not in (1, 2):
            raise ValueError("StepAlgorithm must be 1 (Verlet) or 2 (Symplectic)")
        if self.shift == 4 and self.step_algorithm == 1:
            warnings.warn("Shifting=4 with StepAlgorithm=1 (Verlet): DualSPHysics v5.4 refuses "
                          "this combination ('Advanced shifting is not allowed with Verlet'); "
                          "sphdvi shifts at every Verlet step, so results have no DualSPHysics "
                          "counterpart (use StepAlgorithm=2)")
        self.verlet_steps = int(p["VerletSteps"])
        alpha = kernel_alpha(self.kernel, h, self.is2d)
        cst = np.zeros(24)
        cst[0] = h
        cst[1] = 4.0 * h * h
        cst[2] = (0.1 * h) ** 2
        cst[3] = alpha
        cst[4] = alpha / (h * h)
        cst[5] = self.cs0
        cst[8] = float(p["DensityDTvalue"]) * 2.0 * h * self.cs0
        cst[9] = self.rhop0 * self.gravity[2] / self.b
        cst[10] = self.rhop0
        cst[11] = 1.0 / self.gamma
        cst[12:15] = self.gravity
        # cubic tensile correction f = (W(r)/W(dp))^4 with DualSPHysics's W(dp) = W(q = 2/3)
        # (FunSphKernel.h GetKernelCubic_Ctes: deltap = 1/1.5 fixed, i.e. h = 1.5 dp assumed
        # whatever coefh), not W at the case's own dp/h
        cst[15] = 1.0 / kernel_w(1, 1.0 / 1.5, kernel_alpha(1, h, self.is2d)) if self.kernel == 1 else 0.0
        cst[16] = self.b
        cst[17] = self.gamma
        cst[18] = 1.0
        cst[20] = 0.0       # 1/dt of the shifting velocity (ShiftAdvALE), set each step
        # DensityDT 1: a floating neighbour no heavier than 1.2 fluid particles stops the DDT
        # (DualSPHysics's DELTA_HEAVYFLOATING, massp <= MassFluid*1.2)
        massfluid = c.get("massfluid", c.get("mass_fluid")) or self.rhop0 * self.dp ** (2 if self.is2d else 3)
        cst[23] = 1.2 * float(massfluid)
        self.cst = cst
        self._set_visco(float(p["Visco"]))
        self.dtmin = float(p["DtMin"]) or float(p["CoefDtMin"]) * h / self.cs0
        self.dtini = float(p["DtIni"]) or h / self.cs0
        self.dtfixed = float(p["DtFixed"] or 0.0)
        # DtAllParticles 1: every particle's speed limits dt; 0: fluid and floating
        self.dt_vel_type = 0 if int(p.get("DtAllParticles") or 0) else 2
        cst[19] = self.dt_vel_type
        # laminar term r^2/(r^2 + eta^2): DualSPHysics eta = 0.1 h (ViscoLaminarEta)
        cst[21] = (float(p.get("ViscoLaminarEta", 0.1)) * h) ** 2
        # Molteni-Colagrossi DDT: DualSPHysics switches it off next to DBC walls but sums
        # over mDBC walls (their density is the corrected one)
        cst[22] = 1.0 if self.boundary == 2 else 0.0
        self.sps_smag, self.sps_blin = _sps.sps_constants(self.dp, self.is2d)
        self.shift_tfs = float(p["ShiftTFS"])
        self.ip = np.zeros(17)
        self.ip[1] = self.rhop0
        self.ip[2] = float(p["RhopOutMin"])
        self.ip[3] = float(p["RhopOutMax"])
        self.ip[4] = float(p["ShiftCoef"]) * h
        self.ip[5] = self.shift_tfs
        self.ip[14] = 0.1 * self.dp                                  # shifting limit per component
        self.ip[15] = (2.0 if self.is2d else 3.0) - self.shift_tfs   # TFS ramp's denominator
        # DualSPHysics's MovLimit = 0.9 Scell, Scell = 2h (CellMode full, its default): a fluid
        # particle moving more in one update is excluded ("movement"); sphdvi's own cell size
        # (h or 2h, a speed choice) does not change it
        self.movlimit = 0.9 * 2.0 * h
        self.ip[16] = self.movlimit

    def _setup_flex(self):
        """Flexible structures: no periodic conditions, no original mDBC (SlipMode 1), no mDBC with Verlet
        (DualSPHysics refuses them too; mDBC2 is run as its v5.4, sphdvi.sph.flexstruc); DtIni and DtMin
        from the structure's sound speed where it exceeds the fluid's or there is no fluid (JSph's
        LoadCaseConfig), unless the case sets them."""
        from ..case.flexstruc_xml import flexstruc_parameter_problem      # the rule gencase checks (numpy only)
        problem = flexstruc_parameter_problem(
            {"Boundary": self.boundary, "SlipMode": self.slip, "StepAlgorithm": self.step_algorithm},
            self.periodicity is not None)
        if problem:
            raise ValueError(problem)
        has_fluid = bool(np.any(self.state.ptype == 3))
        # the fluid's forces on the structure: only where there is (or an inlet brings) fluid
        self._flex_fluid = has_fluid or self.inout is not None
        cs = float(self.flex.csound.max())
        if cs > self.cs0 or not has_fluid:
            p = self.params
            if not float(p["DtIni"]):
                self.dtini = self.h / cs
            if not float(p["DtMin"]):
                self.dtmin = float(p["CoefDtMin"]) * self.h / cs
        self._flex_dom = np.zeros(6)
        if self._domain is not None:
            self._flex_dom[:3] = self._domain[0]
            self._flex_dom[3:] = self._domain[1]

    def _warn_fixed_below_dtmin(self):
        """DtFixed, or a DtFixedFile value, below DtMin is kept (sphdvi steps with it), but
        DualSPHysics's DtVariable raises the imposed dt to DtMin too ("DTs adjusted to DtMin")."""
        what = []
        if self.dtfixed > 0.0 and self.dtfixed < self.dtmin:
            what.append(f"DtFixed ({self.dtfixed:g} s)")
        elif self.dtfixed == 0.0 and self.dt_table is not None and self.dt_table.shape[0]:
            low = float(self.dt_table[:, 1].min())
            if 0.0 < low < self.dtmin:
                what.append(f"DtFixedFile (down to {low:g} s)")
        for w in what:
            warnings.warn(f"{w} is below DtMin ({self.dtmin:g} s): sphdvi steps with it, DualSPHysics would "
                          "raise each such step to DtMin (its DtVariable clamps the imposed dt too); set "
                          "DtMin below it for the same run in both")

    def _floating_mode(self, state):
        """The interaction's ``ftmode`` flag (DualSPHysics's FtMode, JSph::LoadConfigParameters):
        0 without floating particles; 1 for ``RigidAlgorithm`` 1 (FtMode Sph, the default:
        floating particles feel walls and other bodies through the SPH terms); 2 for 0 and 3
        (FtMode Ext: fluid only, collisions are the multibody engine's)."""
        if not np.any(state.ptype == 2):
            return 0
        ra = self.params.get("RigidAlgorithm")
        return 1 if ra is None or int(ra) == 1 else 2      # 0, 2 (DEM: sphdvi.sph.dem) and 3: FtMode Ext

    def _choose_cell_mode(self, mode):
        """Cells of h (5x5 / 125-cell stencil) where the grid stays small, else 2h.

        Cells of h leave fewer candidates per particle (2D: 47 instead of 68
        for ~21 neighbours); on a developed 2D dam break the interaction is
        ~25 % faster, in 3D ~15 %.  Their grid has 2^d times more cells, so
        ``auto`` takes them only while the grid has at most 8 cells per
        particle (a sparse domain would otherwise spend memory and time on
        empty cells)."""
        if mode in ("h", "2h"):
            return mode
        if mode != "auto":
            raise ValueError("cell_mode must be 'auto', 'h' or '2h'")
        pos = self.state.pos
        if pos.shape[0] == 0:
            return "2h"
        lo, hi = pos.min(axis=0), pos.max(axis=0)
        if self._domain is not None:
            dlo, dhi = self._domain
            lo = np.where(np.isfinite(dlo), np.minimum(dlo, lo), lo)
            hi = np.where(np.isfinite(dhi), np.maximum(dhi, hi), hi)
        ext = np.floor((hi - lo) / self.h) + 1.0
        if self.is2d:
            ext[1] = 1.0
        return "h" if float(np.prod(ext)) <= 8.0 * pos.shape[0] else "2h"

    def _setup_periodic(self, periodic):
        """The periodic axes: those listed, those with a non-zero Inc key, or the pair of a
        XYPeriodic/XZPeriodic/YZPeriodic = 1, which (as in DualSPHysics) also switches
        the third axis off and resets the increments; a periodic y in 2D is refused."""
        from .periodic import PERIODIC_KEYS, Periodicity, periodic_config
        # a key counts here when it has a value (the caller lists the axes the case's keys switch on)
        given = {k for k in PERIODIC_KEYS if self.params.get(k)}
        axes, incs = periodic_config(given, self.params, self.is2d)
        axes = set(axes) | set(periodic or ())
        if self.is2d and "y" in axes:
            raise ValueError("cannot use periodic conditions in Y with 2D simulations (as DualSPHysics)")
        if not axes:
            return None
        p = {**{k: v for k, v in self.params.items() if k not in PERIODIC_KEYS}, **incs}
        per = Periodicity(axes, self.state.pos, self.dp, p)
        per.check_length(2.0 * self.h)
        if self._domain is not None:
            for k in per.axes:      # no exclusion along a periodic axis
                self._domain[0][k] = -np.inf
                self._domain[1][k] = np.inf
        return per

    def _aux_names(self):
        names = []
        if self.step_algorithm == 1:
            names += ["vel_m1", "rhop_m1"]
        else:
            names += ["pos_pre", "vel_pre", "rhop_pre"]
        if self.visco_kind == 2:
            names += ["tau"]
        if self.boundary == 2:
            names += ["normals"]
            if self._wall_ace_on:
                names += ["wall_ace"]
        if getattr(self, "bc_normals", None) is not None:
            names += ["bc_normals"]
        return names

    def _alloc(self, reuse=False, keep=()):
        """(Re)allocate the per-particle work arrays for the current N, zeroed.  ``reuse``: after an
        exclusion (N shrinks), in the memory they already hold (views of their first rows, zeroed
        as new ones; the reorder and extended-set buffers kept too), as DualSPHysics keeps its arrays
        when particles go out; ``keep``: names of work arrays already compacted (not zeroed)."""
        s = self.state
        n = s.n

        def z(name, shape, dtype=np.float64):
            old = getattr(self, name, None) if reuse else None
            if (old is None or not isinstance(old, np.ndarray) or old.dtype != dtype
                    or old.shape[1:] != shape[1:] or old.shape[0] < shape[0] or not old.flags.c_contiguous):
                return np.zeros(shape, dtype)
            view = old[:shape[0]]
            if name not in keep:
                view.fill(0)
            return view

        if not hasattr(self, "tau"):
            if self.step_algorithm == 1:
                self.vel_m1 = s.vel.copy()
                self.rhop_m1 = s.rhop.copy()
            else:
                self.pos_pre = s.pos.copy()
                self.vel_pre = s.vel.copy()
                self.rhop_pre = s.rhop.copy()
            self.tau = np.zeros((n, 6)) if self.visco_kind == 2 else np.zeros((1, 6))
        self.nb = z("nb", (n, 8 if self.is2d else 10))
        self.ace = z("ace", (n, 3))
        self.ar = z("ar", (n,))
        self.viscdt = z("viscdt", (n,))
        self.out = z("out", (n,), np.int8)
        self.cell_sorted = z("cell_sorted", (n,), np.int64)
        self.ptype_s = z("ptype_s", (n,), np.int8)
        self.tau_s = z("tau_s", (n, 6) if self.visco_kind == 2 else (1, 6))
        old = getattr(self, "_identity", None) if reuse else None
        self._identity = old[:n] if old is not None and old.shape[0] >= n else np.arange(n, dtype=np.int64)
        # the rows the last interaction read its particles from (cell order)
        self._rows = (s.ptype, self._identity, self.tau)
        if self.shift:
            self.shiftpos = z("shiftpos", (n, 3))
            self.shiftdet = z("shiftdet", (n,))
        else:
            self.shiftpos = z("shiftpos", (1, 3))
            self.shiftdet = z("shiftdet", (1,))
        if self.shift == 4:
            # per particle: 0 interior (shifted), 1 near the free surface, 2 on it, 3 isolated
            self.fstype = z("fstype", (n,), np.int8)
            self.fsnormal = z("fsnormal", (n, 3))
            self._fs_work = self._shift_adv_work(n)
        # ShiftAdvNCPress: 1 where the non-conservative pressure gradient may be used
        self.nctype = z("nctype", (n if self.adv else 1,), np.int8)
        self.gradvel = z("gradvel", (n, 6) if self.visco_kind == 2 else (1, 6))
        if self.nopen:
            from .nopen import NCOL
            self.npshift = z("npshift", (n, NCOL))
        self.dtmax = z("dtmax", ((n + _ia.CHUNK - 1) // _ia.CHUNK, 3))
        if not reuse:
            self._bufs = {}
            self._ghost_bufs = {}      # Periodicity.ghosts's work arrays

    # ------------------------------------------------------------------ kernels
    def _use_parallel(self, light=False):
        """Threaded kernels for this N?  ``light`` kernels (cell indices, packing, the
        integrators: a few ns per particle, bound by memory traffic) are threaded from
        ``light_threshold`` particles on.  Below it, waking the passive pool (5-8 us for an
        empty region) and moving cache lines between the cores cost what they save (see
        LIGHT_THRESHOLD).  Threaded, they give each thread the rows it interacts
        (``_env.CHUNK``)."""
        n = self.state.n
        if light and n < self.light_threshold:
            return False
        return n >= self.parallel_threshold and numba.get_num_threads() > 1

    def threads_in_use(self) -> int:
        """The threads the interaction runs on now: 1 below ``parallel_threshold`` particles
        (a small scene runs serially whatever the thread count)."""
        return int(numba.get_num_threads()) if self._use_parallel() else 1

    def _kernels(self, parallel):
        """Entry points of the compiled interaction kernels for this run's flags."""
        key = ("rates", self.is2d, self.kernel, self.visco_kind, self.ddt, self.rates_shift, self.adv,
               self._mdbc2_flag, self.ftmode, bool(parallel))
        if key in _ENTRY_CACHE:
            return _ENTRY_CACHE[key]
        sfx = "parallel" if parallel else "serial"
        rates = getattr(_ia, ("rates_2d_" if self.is2d else "rates_3d_") + sfx)
        k = {
            "rates": specialised(rates, self._rates_args(), (0, 1, 2, 3, 4, 5, 6)),
            "pack": getattr(_ia, "pack_" + sfx),
            "sps": getattr(_sps, "sps_tau_" + sfx),
        }
        _ENTRY_CACHE[key] = k
        return k

    def _integrators(self, parallel):
        """Entry points of the compiled integrators for this run's flags."""
        key = ("int", self.shift, self.step_algorithm, bool(parallel))
        if key in _ENTRY_CACHE:
            return _ENTRY_CACHE[key]
        sfx = "parallel" if parallel else "serial"
        k = {}
        if self.step_algorithm == 1:
            k["verlet"] = specialised(getattr(_int, "verlet_" + sfx), self._verlet_args(False), (0,))
        else:
            k["sym_pre"] = getattr(_int, "symplectic_pre_" + sfx)
            k["sym_corr"] = specialised(getattr(_int, "symplectic_corr_" + sfx),
                                        self._corr_args(), (0,))
        _ENTRY_CACHE[key] = k
        return k

    def _rates_args(self):
        ncx, ncy, ncz = self.cells.shape
        ptype_rows, oi, tau_rows = self._rows
        geo = (ncx, ncz) if self.is2d else (ncx, ncy, ncz)
        return ((self.kernel, self.visco_kind, self.ddt, self.rates_shift, self.adv, self._mdbc2_flag,
                 self.ftmode, self.nb, ptype_rows, self.cell_sorted, oi, self.cells.cell_start) + geo
                + (self.cst, tau_rows, self.ace, self.ar, self.viscdt, self.shiftpos,
                   self.shiftdet, self.gradvel, self._tvel(self.nb.shape[0]), self.dtmax, self.nctype))

    def _verlet_args(self, euler):
        s = self.state
        return (self.shift, bool(euler), s.pos, s.vel, s.rhop, self.vel_m1, self.rhop_m1,
                self.ace, self.ar, s.ptype, self.shiftpos, self.shiftdet, self.ip, self.out)

    def _corr_args(self):
        s = self.state
        return (self.shift, s.pos, s.vel, s.rhop, self.pos_pre, self.vel_pre, self.rhop_pre,
                self.ace, self.ar, s.ptype, self.shiftpos, self.shiftdet, self.ip, self.out)

    # ------------------------------------------------------------------ steps
    _STATE_DTYPES = {"pos": np.float64, "vel": np.float64, "rhop": np.float64, "mass": np.float64,
                     "ptype": np.int8, "idp": np.int64, "mk": np.int32}

    def _check_state_arrays(self):
        """Coerce the state arrays to the dtypes and C layout the compiled entry
        points were specialised for (they do not check their arguments).  Arrays already
        checked (the same objects as at the last call) are not looked at again: what the
        user, a motion hook, an exclusion or a checkpoint puts in their place is."""
        s = self.state
        n = s.pos.shape[0]
        last = getattr(self, "_checked_arrays", None)
        if (last is not None and last[0] is s.pos and last[1] is s.vel and last[2] is s.rhop
                and last[3] is s.mass and last[4] is s.ptype and last[5] is s.idp and last[6] is s.mk):
            if self.nb.shape[0] != n:
                self._alloc()
            return
        for name, dt in self._STATE_DTYPES.items():
            a = getattr(s, name)
            if a.dtype != dt or not a.flags.c_contiguous or a.shape[0] != n:
                if a.shape[0] != n:
                    raise ValueError("state.%s has %d rows, pos has %d" % (name, a.shape[0], n))
                setattr(s, name, np.ascontiguousarray(a, dtype=dt))
        # kept (not only their ids) so that no other array can take an id of theirs
        self._checked_arrays = (s.pos, s.vel, s.rhop, s.mass, s.ptype, s.idp, s.mk)
        if self.nb.shape[0] != n:
            self._alloc()

    def _sorted_into_cells(self):
        """Check the state arrays and counting-sort the particles into cells (over
        the domain when one is set, else their bounding box); returns ``order``."""
        self._check_state_arrays()
        pos = self.state.pos
        par = self._use_parallel(light=True)
        if self._domain is not None:
            return self.cells.build(pos, self._domain[0], self._domain[1], parallel=par)
        return self.cells.build(pos, parallel=par)

    def _reorder_and_pack(self):
        """Counting-sort the particles by cell, permute every per-particle array
        and fill the packed neighbour array, in one pass (one thread launch)."""
        s = self.state
        order = self._sorted_into_cells()
        n = order.shape[0]
        aux = [a for a in self._aux_names() if getattr(self, a).shape[0] == n]
        f2 = ["pos", "vel"] + [a for a in aux if getattr(self, a).ndim == 2]
        f1 = ["rhop", "mass"] + [a for a in aux if getattr(self, a).ndim == 1]
        holder = {name: (s if name in FluidState.FIELDS else self)
                  for name in f2 + f1 + ["ptype", "idp", "mk"]}
        src = {name: getattr(holder[name], name) for name in holder}
        dst = {}
        for name, a in src.items():
            buf = self._bufs.get(name)
            if (buf is None or buf.shape[1:] != a.shape[1:] or buf.dtype != a.dtype
                    or buf.shape[0] < a.shape[0]):
                buf = np.empty_like(a)
            dst[name] = buf[:a.shape[0]]        # (longer after an exclusion: its first rows)
        fn = _ia.reorder_pack_parallel if self._use_parallel(light=True) else _ia.reorder_pack_serial
        fn(order, self.is2d, self.cst, self.nb, tuple(src[k] for k in f2), tuple(dst[k] for k in f2),
           tuple(src[k] for k in f1), tuple(dst[k] for k in f1), src["ptype"], dst["ptype"],
           src["idp"], dst["idp"], src["mk"], dst["mk"], self.cells.cell, self.cell_sorted)
        for name in src:
            setattr(holder[name], name, dst[name])
            self._bufs[name] = src[name]

    def _sort_and_pack(self):
        """Sort the particles into cells and fill the packed neighbour array in
        cell order, leaving the particle arrays where they are (row k of the
        packed array is particle ``order[k]``; the interaction writes its
        results back to the particles' own rows)."""
        s = self.state
        order = self._sorted_into_cells()
        fn = _ia.sort_pack_parallel if self._use_parallel(light=True) else _ia.sort_pack_serial
        fn(order, self.is2d, self.cst, self.nb, s.pos, s.vel, s.rhop, s.mass, s.ptype, self.ptype_s,
           self.cells.cell, self.cell_sorted, self.tau, self.tau_s)
        self._rows = (self.ptype_s, order, self.tau_s)

    def compute_rates(self):
        """Sort into cells (every ``reorder_every`` steps also moving the
        particles into cell order, for memory locality), then evaluate
        accelerations, density rates and dt terms; then the imposed accelerations."""
        if self.periodicity is not None:
            self._compute_rates_periodic()
        else:
            self._compute_rates_cells()
        if self.shift_zones is not None:
            _shift_zones.unshift_outside(self.state.pos, self.state.ptype, self.shiftpos, *self.shift_zones)
        if self.acc_inputs:
            self._add_acc_inputs()
        if self.inout is not None:
            self._inout_zero_rates()

    def _add_acc_inputs(self):
        """``<accinputs>`` at the time the step started; the force term of dt then sees
        them, as in DualSPHysics (they enter its acceleration before the interaction)."""
        s = self.state
        added = False
        for inp in self.acc_inputs:
            added |= add_acc_input(self.ace, s.pos, s.vel, s.mk, s.ptype, inp, self.time, self.gravity, self.is2d,
                                   parallel=self._use_parallel(light=True))
        if added:
            self.dtmax[:, 0] = 0.0
            self.dtmax[0, 0] = fluid_ace_max2(self.ace, s.ptype, *self.gravity)

    def _compute_rates_cells(self):
        if self._reorder_next:
            self._reorder_and_pack()
            self._rows = (self.state.ptype, self._identity, self.tau)
        else:
            self._sort_and_pack()
        self._reorder_next = False
        par = self._use_parallel()
        k = self._kernels(par)
        s = self.state
        ptype_rows, oi, _ = self._rows
        if self.inout is not None and not self._in_corrector:
            self._inout_impose(ptype_rows, oi)
        if self.flex is not None:
            # F of the flexible structures before the mDBC correction, which needs their normals
            self.flex.geometry(s.pos, s.idp, parallel=par)
            if self._flex_of_idp.shape[0]:
                self.flex.turn_normals(self.normals)
        corr = self._wall_correction()
        if corr is not None:
            from . import mdbc
            fn = mdbc.mdbc_parallel if par else mdbc.mdbc_serial
            ncx, ncy, ncz = self.cells.shape
            normals, threshold, ksum_min, slip, ghostvel = corr
            flexid = self._flex_of_idp
            fn(self.kernel, self.is2d, self.nb, ptype_rows, oi, normals, self.cells.cell_start,
               self.cells.pmin, 1.0 / self.cells.cellsize, ncx, ncy, ncz, self.cst, threshold,
               ksum_min, s.rhop, slip, ghostvel, self.dp, s.idp if flexid.shape[0] else _NO_IDS, flexid,
               self._tvel(s.n), self.wall_ace if self._wall_ace_on else self._no_wall_ace)
            if self.nopen and self._need_nopen:
                self._nopen_detect(par, self.nb, ptype_rows, self.cell_sorted, oi, self.normals,
                                   s.vel, s.pos, self.npshift)
        if self.shift == 4 and self._need_shift_adv:
            # before the interaction, which reads the shift with ShiftAdvALE / NCPress
            self._advanced_shift(par, self.nb, ptype_rows, self.cell_sorted, oi, self.shiftpos, self.fstype,
                                 self.fsnormal, self._fs_work, nctype=self.nctype)
        k["rates"](*self._rates_args())
        if self.dem is not None:
            self._dem_contacts(par, self.nb, ptype_rows, self.cell_sorted, oi, oi, self.dtmax)
        if self.flex is not None:
            self._flex_forces(par, ptype_rows, oi)
        if self.visco_kind == 2:
            k["sps"](self.gradvel, s.rhop, s.ptype, self.sps_smag, self.sps_blin, self.tau)

    def _flex_forces(self, par, ptype_rows, oi):
        """Flexible structures (:mod:`sphdvi.sph.flexstruc`): the fluid's forces on their particles, then
        the elastic ones (from the F found before the mDBC correction, the same positions); their |a|
        enters the force condition of dt."""
        from .flexstruc import fluid_on_structure
        f = self.flex
        s = self.state
        ncx, ncy, ncz = self.cells.shape
        mdbc2 = bool(self._mdbc2_flag)
        if self._flex_fluid:
            fluid_on_structure(self.kernel, self.visco_kind, self.is2d, self.nb, ptype_rows, self.cell_sorted, oi,
                               self.cells.cell_start, ncx, ncy, ncz, int(self.cst[18]), self.cst, s.idp, f.slot,
                               f.clamp, f.body, f.rho_s, f.vol, mdbc2, self._tvel(self.nb.shape[0]), self.ace)
        f.forces(s.pos, self.ace, parallel=par)
        if f.amax2 > self.dtmax[0, 0]:
            self.dtmax[0, 0] = f.amax2

    def _flex_update(self, kind, dt):
        """Move the flexible particles: ``euler`` (Verlet steps), ``pre`` or ``corr`` (Symplectic)."""
        from .flexstruc import keep_velocity, update_corrector, update_euler, update_predictor
        f = self.flex
        s = self.state
        f.locate(s.idp)
        if self._flex_ace and kind != "corr":
            keep_velocity(f.rows, f.clamp, s.vel, f.v0)      # v^n, for the wall acceleration (step)
        usedom = self._domain is not None
        if kind == "euler":
            update_euler(f.rows, f.clamp, s.pos, s.vel, self.ace, self.gravity, dt, self.ip[13] != 0.0, usedom,
                         self._flex_dom, f.fail)
        else:
            fn = update_predictor if kind == "pre" else update_corrector
            fn(f.rows, f.clamp, s.pos, s.vel, self.pos_pre, self.vel_pre, self.ace, self.gravity, dt, usedom,
               self._flex_dom, f.fail)

    def _dem_contacts(self, par, nb, ptype_rows, cell_rows, oi, src, dtmax):
        """RigidAlgorithm 2: the DEM contacts of the floating particles (:mod:`sphdvi.sph.dem`) on top
        of their fluid forces, and the time-step maxima again with them."""
        from .dem import dem_parallel, dem_serial       # imported (and compiled) only for RigidAlgorithm 2
        d = self.dem
        ncx, ncy, ncz = self.cells.shape
        fn = dem_parallel if par else dem_serial
        if src is self._identity:
            mk_rows = self.state.mk
        else:                                   # gathered into row order, in a buffer kept between passes
            buf = self._bufs.get("dem_mk")
            if buf is None or buf.shape[0] < src.shape[0]:
                buf = self._bufs["dem_mk"] = np.empty(src.shape[0] + src.shape[0] // 16 + 16, self.state.mk.dtype)
            mk_rows = np.take(self.state.mk, src, out=buf[:src.shape[0]])
        fn(self.is2d, nb, ptype_rows, cell_rows, oi, self.cells.cell_start, ncx, ncy, ncz,
           int(self.cst[18]), self.cst[1], mk_rows, d.mat_of_mk, d.tau, d.restitution, d.kfric, d.body_mass,
           self.dp, self.dem_dt, self.ace, self.viscdt, int(self.cst[19]), dtmax, self.cst)

    def _shift_adv_work(self, n):
        """Work arrays of the advanced shifting, one row per packed row: type, normal, grad C,
        near-surface flag, boundary-contact flag; with ALE / NCPress also the distance to the
        surface, the smoothed normal and the curvature flag."""
        w = (np.zeros(n, np.int8), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.int8),
             np.zeros(n, np.int8))
        if self.adv:
            w += (np.zeros(n), np.zeros((n, 3)), np.zeros(n, np.int8))
        return w

    def _advanced_shift(self, par, nb, ptype_rows, cell_rows, oi, shiftpos, fstype, fsnormal, work,
                        src_row=None, nctype=None):
        """Shifting 4: free-surface detection and displacement (sphdvi.sph.shifting_adv)."""
        from . import shifting_adv as _sa
        ncx, ncy, ncz = self.cells.shape
        src = np.zeros(0, np.int64) if src_row is None else src_row
        nzero = _sa.full_support_neighbours(self.h, self.dp, self.is2d)
        if self.adv:
            fn = _sa.advanced_shift_ale_parallel if par else _sa.advanced_shift_ale_serial
            # NCPress next to walls only with mDBC (see shifting_adv._displace_ale_range)
            fn(self.kernel, self.is2d, bool(self.adv & 1), self.boundary == 2, nb, ptype_rows, cell_rows, oi,
               self.cells.cell_start, ncx, ncy, ncz, self.cst, nzero, self.shift_adv_coef, self.dp, *work,
               shiftpos, fstype, fsnormal, nctype, src)
            return
        fn = _sa.advanced_shift_parallel if par else _sa.advanced_shift_serial
        fn(self.kernel, self.is2d, nb, ptype_rows, cell_rows, oi, self.cells.cell_start, ncx, ncy, ncz,
           self.cst, nzero, self.shift_adv_coef, self.dp, *work, shiftpos, fstype, fsnormal, src)

    def _nopen_detect(self, par, nb, ptype_rows, cell_rows, oi, normals, wallvel, pos, npshift):
        """NoPenetration: corrections of the fluid next to the walls (sphdvi.sph.nopen)."""
        from . import nopen
        fn = nopen.detect_parallel if par else nopen.detect_serial
        ncx, ncy, ncz = self.cells.shape
        # the correction reaches 1.25 dp: fewer cells than the 2h stencil when cells are of h
        rs = min(int(self.cells.stencil), int(np.ceil(1.25 * self.dp / self.cells.cellsize - 1e-9)))
        fn(self.is2d, nb, ptype_rows, cell_rows, oi, normals, wallvel, pos, self.cells.cell_start,
           ncx, ncy, ncz, max(rs, 1), self.dp, npshift)

    def _nopen_apply(self, symplectic):
        """Apply the NoPenetration corrections after the integrator; returns the
        change in the number of particles flagged for exclusion."""
        from . import nopen
        s = self.state
        par = self._use_parallel(light=True)
        if symplectic:
            fn = nopen.apply_symplectic_parallel if par else nopen.apply_symplectic_serial
            return fn(s.pos, s.vel, self.pos_pre, self.vel_pre, s.rhop, s.ptype, self.npshift,
                      self.ip, self.out)
        fn = nopen.apply_verlet_parallel if par else nopen.apply_verlet_serial
        return fn(s.pos, s.vel, self.vel_m1, s.rhop, s.ptype, self.npshift, self.ip, self.out)

    def _mdbc_now(self):
        """Whether this evaluation of the rates runs the mDBC correction: always with
        Boundary=2, except in the Symplectic corrector without MDBCCorrector, where the
        walls keep the densities the predictor gave them (DualSPHysics's runmdbc)."""
        return self.boundary == 2 and (self.mdbc_corrector or not self._in_corrector)

    def _wall_correction(self):
        """The wall density correction this evaluation of the rates runs, as the arguments of
        sphdvi.sph.mdbc.mdbc_serial (normals, threshold, ksum_min, slip, ghostvel): mDBC's
        (:meth:`_mdbc_now`), or ``<boundcorr>``'s under DBC (SlipMode 1 with its determlimit, in
        the predictor only: once a step, as JSphBoundCorr); None for neither."""
        if self._mdbc_now():
            return self.normals, 1e-3, self.mdbc_ksum, self.slip, self.ghostvel
        if self.bc_normals is not None and not self._in_corrector:
            return self.bc_normals, self.bc_determlimit, 0.0, 1, 1
        return None

    @property
    def _mdbc2_flag(self):
        """1 for the mDBC2 slip modes (2, 3): the interaction's compile-time flag."""
        return 1 if self.boundary == 2 and self.slip > 1 else 0

    def _tvel(self, n):
        """mDBC2: (>= n, 3) work array, per packed row the tangential velocity a
        wall particle shows the viscosity (set by sphdvi.sph.mdbc); a (1, 3)
        dummy otherwise."""
        if not self._mdbc2_flag:
            return self._no_tvel
        w = getattr(self, "_tvel_work", None)
        if w is None or w.shape[0] < n:
            w = self._tvel_work = np.zeros((max(n, 1), 3))
        return w

    def _periodic_work(self, name, n, tail=(), dtype=np.float64, zero=True):
        """The first ``n`` rows of a work array of the periodic extended set, kept between steps
        in ``_bufs`` (as the reorder's) and grown when the set outgrows it (with a quarter more
        room: the number of ghosts changes from step to step); zeroed when ``zero``."""
        key = "periodic_" + name
        buf = self._bufs.get(key)
        if buf is None or buf.shape[0] < n or buf.shape[1:] != tuple(tail) or buf.dtype != dtype:
            buf = self._bufs[key] = np.empty((n + n // 4 + 1,) + tuple(tail), dtype)
        view = buf[:n]
        if zero:
            view.fill(0)
        return view

    def _periodic_rows(self, n):
        """0, 1, ..., n - 1 (kept between steps)."""
        buf = self._bufs.get("periodic_rows")
        if buf is None or buf.shape[0] < n:
            buf = self._bufs["periodic_rows"] = np.arange(n + n // 4 + 1, dtype=np.int64)
        return buf[:n]

    def _compute_rates_periodic(self):
        """Rates with ghost copies across the periodic boundaries (no reordering
        of the real particles; the extended set is sorted by cell instead).  One compiled
        pass packs the extended set in cell order (:func:`interaction.periodic_pack_serial`);
        the interaction computes the real rows only, straight into the particles' rows, and
        their time-step terms (the copies are neighbours only, as DualSPHysics's periodic
        particles).  The extended set's arrays are work arrays kept between steps
        (_periodic_work)."""
        self._check_state_arrays()
        s = self.state
        per = self.periodicity
        per.wrap(s.pos)
        n = s.n
        src, disp = per.ghosts(s.pos, 2.0 * self.h, self._ghost_bufs)
        ne = n + src.shape[0]
        w = self._periodic_work
        light = self._use_parallel(light=True)
        unsorted = w("pos_x", ne, (3,), zero=False)     # the real particles', then the ghosts'
        _extend_positions(s.pos, src, disp, unsorted)
        order = self.cells.build(unsorted, parallel=light)
        # the gather into cell order: row k is extended row order[k], of real particle idx[k];
        # oi[k] its row, or -1 - idx[k] for a copy
        idx = w("idx", ne, (), np.int64, zero=False)
        oi = w("oi", ne, (), np.int64, zero=False)
        ptype_e = w("ptype", ne, (), s.ptype.dtype, zero=False)
        cell_e = w("cell", ne, (), self.cells.cell.dtype, zero=False)
        nb = w("nb", ne, self.nb.shape[1:], zero=False)
        tau = w("tau", ne, self.tau.shape[1:], zero=False) if self.visco_kind == 2 else self.tau
        pack = _ia.periodic_pack_parallel if light else _ia.periodic_pack_serial
        pack(n, order, src, unsorted, self.is2d, self.cst, nb, s.vel, s.rhop, s.mass, s.ptype, ptype_e,
             self.cells.cell, cell_e, idx, oi, self.tau, tau)
        rows_e = self._periodic_rows(ne)
        par = self._use_parallel()
        k = self._kernels(par)
        ncx, ncy, ncz = self.cells.shape
        if self.inout is not None and not self._in_corrector:
            self._inout_impose(ptype_e, oi, nb=nb, prow=idx)
        corr = self._wall_correction()
        if corr is not None:
            # mDBC (or <boundcorr>) on the extended set: ghost copies see the fluid across the
            # periodic boundary; the real boundary particles keep their density
            from . import mdbc
            fn = mdbc.mdbc_parallel if par else mdbc.mdbc_serial
            normals, threshold, ksum_min, slip, ghostvel = corr
            rhop_e = np.take(s.rhop, idx, out=w("rhop", ne, zero=False), mode="clip")
            normals_e = np.ascontiguousarray(normals[idx])
            wace_e = np.ascontiguousarray(self.wall_ace[idx]) if self._wall_ace_on else self._no_wall_ace
            fn(self.kernel, self.is2d, nb, ptype_e, rows_e, normals_e, self.cells.cell_start,
               self.cells.pmin, 1.0 / self.cells.cellsize, ncx, ncy, ncz, self.cst, threshold,
               ksum_min, rhop_e, slip, ghostvel, self.dp, _NO_IDS, _NO_FLEX, self._tvel(ne), wace_e)
            # a copy's ghost node sees a truncated extended set: it takes its real particle's result
            real_e = order < n
            row_of = np.empty(n, np.int64)
            row_of[order[real_e]] = np.flatnonzero(real_e)
            mdbc.copy_to_periodic_rows(self.is2d, nb, ptype_e, row_of[idx], self._tvel(ne))
            bound = real_e & (ptype_e != 3)
            s.rhop[order[bound]] = rhop_e[bound]
            if self.nopen and self._need_nopen:
                npshift = w("npshift", ne, self.npshift.shape[1:])
                pos_e = np.take(unsorted, order, axis=0, out=w("pos", ne, (3,), zero=False), mode="clip")
                vel_e = np.take(s.vel, idx, axis=0, out=w("vel", ne, (3,), zero=False), mode="clip")
                self._nopen_detect(par, nb, ptype_e, cell_e, rows_e, normals_e, vel_e, pos_e, npshift)
                real_rows = np.flatnonzero(order < n)
                _copy_rows_2d(npshift, real_rows, self.npshift, order[real_rows])
        geo = (ncx, ncz) if self.is2d else (ncx, ncy, ncz)
        if self.shift == 4 and self._need_shift_adv:
            real = order < n
            dst = order[real]
            rr = np.flatnonzero(real)       # the real particles' rows of the extended set, at dst
            back = _copy_rows_2d, _copy_rows_1d
            shiftpos = w("shiftpos", ne, (3,))
            fstype = w("fstype", ne, (), np.int8)
            fsnormal = w("fsnormal", ne, (3,))
            nctype = w("nctype", ne if self.adv else 1, (), np.int8)
            row_of = np.empty(n, np.int64)
            row_of[dst] = rr
            work = tuple(w(f"shift_adv{k}", ne, a.shape[1:], a.dtype) for k, a in enumerate(self._fs_work))
            self._advanced_shift(par, nb, ptype_e, cell_e, rows_e, shiftpos, fstype, fsnormal, work,
                                 src_row=row_of[idx], nctype=nctype)
            for a, out in ((fstype, self.fstype), (fsnormal, self.fsnormal), (shiftpos, self.shiftpos)) + (
                    ((nctype, self.nctype),) if self.adv else ()):
                back[a.ndim == 1](a, rr, out, dst)
        # the real rows' rates straight into the particles' rows (oi), a copy's shift (ALE)
        # read from its particle's row; the time-step terms of the real rows only (a ghost at
        # the edge of the extended set misses neighbours)
        self.dtmax = w("dtmax", (ne + _ia.CHUNK - 1) // _ia.CHUNK, (3,), zero=False)
        k["rates"](self.kernel, self.visco_kind, self.ddt, self.rates_shift, self.adv, self._mdbc2_flag,
                   self.ftmode, nb, ptype_e, cell_e, oi, self.cells.cell_start, *geo, self.cst, tau,
                   self.ace, self.ar, self.viscdt, self.shiftpos, self.shiftdet, self.gradvel, self._tvel(ne),
                   self.dtmax, self.nctype)
        if self.dem is not None:
            self._dem_contacts(par, nb, ptype_e, cell_e, oi, idx, self.dtmax)
        if self.visco_kind == 2:
            k["sps"](self.gradvel, s.rhop, s.ptype, self.sps_smag, self.sps_blin, self.tau)

    def _fixed_dt(self, t):
        """DtFixed, or the DtFixedFile value at time t; 0 when dt is variable."""
        if self.dtfixed > 0.0:
            return self.dtfixed
        if self.dt_table is not None:
            return self._dt_lookup.value(t)
        return 0.0

    def _set_visco(self, visco):
        """Visco of the interaction: fluid-fluid pairs, and times ViscoBoundFactor for the
        fluid-boundary ones."""
        self.cst[6] = visco
        self.cst[7] = visco * float(self.params["ViscoBoundFactor"])

    def _variable_dt(self, t, count=True):
        """The dt of a step starting at time t (eq. 10, or the imposed one), DualSPHysics's
        DtVariable: a variable dt below DtMin is raised to it (``_clamped`` says whether it
        was; counted in ``n_dtmin`` when ``count``)."""
        self._clamped = False
        fixed = self._fixed_dt(t)
        if fixed > 0.0 and self.dt_table is None and not self.keep_dt_terms:
            return fixed
        # left by the interaction, per chunk of rows (numpy's max(axis=0) costs ~20 us)
        a2, v2, cv = _dtmax_columns(self.dtmax) if self.dtmax.shape[0] else self.dtmax.max(axis=0)
        dt1, dt2 = _ts.dt_conditions(a2, v2, cv, self.h, self.cs0)
        if self.keep_dt_terms:                  # <savedt>: CFL dt1, CFL dt2, AceMax, ViscDtMax, VelMax
            self.dt_terms = (self.cfl * dt1, self.cfl * dt2, math.sqrt(a2), float(cv), math.sqrt(v2))
        if fixed > 0.0 and self.dt_table is None:
            return fixed
        dt = self.cfl * min(dt1, dt2)
        if self.flex is not None and self.flex.cmax > 0.0:
            dt = min(dt, self.cfl * self.h / self.flex.cmax)      # DualSPHysics's dt3 of the structures
        if fixed > 0.0:
            self.dt_error = max(self.dt_error, fixed - dt)
            return fixed
        if dt < self.dtmin:
            dt = self.dtmin
            self._clamped = True
            if count:
                self.n_dtmin += 1
        return dt

    def _set_ip(self, dt):
        ip = self.ip
        ip[0] = dt
        if self._domain is not None:
            ip[6] = 1.0
            ip[7:10] = self._domain[0]
            ip[10:13] = self._domain[1]
        ip[13] = 0.0 if self.motion_hook is not None else 1.0

    def step(self):
        """Advance one time step; returns dt."""
        # move the particles into cell order every reorder_every steps (a
        # function of the step number, so that a resumed run does the same)
        self._reorder_next = self.nstep % self.reorder_every == 0
        if self.visco_table is not None:
            self._set_visco(self._visco_lookup.value(self.time))
        if self.step_algorithm == 1:
            dt = self._step_verlet()
        else:
            dt = self._step_symplectic()
        if self.periodicity is not None:
            self.periodicity.wrap(self.state.pos)
        self.time += dt
        self.nstep += 1
        self.last_dt = dt
        if self.motion_hook is not None:
            if self._wall_ace_on:
                # mDBC2 pressure cloning: wall acceleration (v^{n+1} - v^n)/dt of the moving
                # particles, as DualSPHysics's CopyMotionVelAce (two passes over the type 1 rows)
                from .mdbc import keep_moving_velocity, moving_wall_ace
                s = self.state
                if self._wall_v0.shape[0] < s.n:
                    self._wall_v0 = np.zeros((s.n, 3))
                v0 = self._wall_v0[:s.n]
                keep_moving_velocity(s.ptype, s.vel, v0)
                self.motion_hook(self, self.time, dt)
                moving_wall_ace(self.state.ptype, self.state.vel, v0, dt, self.wall_ace)
            else:
                self.motion_hook(self, self.time, dt)
        if self._flex_ace:
            # the flexible particles' (v^{n+1} - v^n)/dt (the hook's pass above leaves them 0: it does
            # not move them), as DualSPHysics's CopyMotionVelAce over the flexible structures' particles
            from .flexstruc import structure_wall_ace
            f = self.flex
            f.locate(self.state.idp)
            structure_wall_ace(f.rows, f.clamp, self.state.vel, f.v0, dt, self.wall_ace)
        if self.inout is not None:
            self._inout_update()
        return dt

    def _step_verlet(self):
        if self.adv & 1:
            # the shifting velocity of the ALE terms is dr/dt; Verlet's dt follows from
            # this step's rates, so the previous step's (or the imposed) dt stands in
            self.cst[20] = 1.0 / (self._fixed_dt(self.time) or self.last_dt or self.dt_pre)
        self.dem_dt = self.last_dt or self.dtini        # DualSPHysics's DemDtForce: the previous step's dt
        self.compute_rates()
        dt = self._variable_dt(self.time)
        self.step_dt_terms = self.dt_terms
        self._set_ip(dt)
        # DualSPHysics's ComputeVerlet: VerletStep++ first, an Euler step when it reaches
        # VerletSteps (steps VerletSteps, 2 VerletSteps, ...), then back to 0
        self._verlet_count += 1
        euler = self._verlet_count >= self.verlet_steps
        if euler:
            self._verlet_count = 0
        k = self._integrators(self._use_parallel(light=True))
        nout = k["verlet"](*self._verlet_args(euler))
        if self.flex is not None:
            self._flex_update("euler", dt)
        if self.nopen:
            nout += self._nopen_apply(False)
        if nout:
            self._exclude(self.time + dt)
        return dt

    def _step_symplectic(self):
        dt = self._fixed_dt(self.time) or self.dt_pre
        self.step_dt_terms = self.dt_terms      # those of dt_pre, found at the end of the last step
        self._set_ip(dt)
        s = self.state
        if self.adv & 1:
            self.cst[20] = 1.0 / dt      # ALE: shifting velocity dr/dt of this step
        # Shifting 4: shift (and types) from the positions at t^n, in the predictor, applied
        # in the corrector; plain Shifting 4 not in the first step (DualSPHysics's
        # PreLoopProcedure: runshift = predictor && Nstep != 0)
        self._need_shift_adv = self.shift == 4 and (self.nstep != 0 or bool(self.adv))
        if self.shift == 4 and not self._need_shift_adv:
            self.shiftpos[:] = 0.0
        self._need_nopen = False
        self.dem_dt = 0.5 * dt                           # DemDtForce: dt/2 in the predictor, dt in the corrector
        self.compute_rates()
        # DualSPHysics's ComputeStep_Sym: dt_p = DtVariable(false) from the predictor's terms
        dt_p = self._variable_dt(self.time + dt, count=False)
        clamped = self._clamped
        self._need_shift_adv = False
        self._need_nopen = True
        k = self._integrators(self._use_parallel(light=True))
        npre = k["sym_pre"](s.pos, s.vel, s.rhop, self.pos_pre, self.vel_pre, self.rhop_pre,
                            self.ace, self.ar, s.ptype, self.ip, self.out)
        if self.flex is not None:
            self._flex_update("pre", dt)
        if self.half_step_hook is not None:
            # floating bodies to t + dt/2 for the corrector (DualSPHysics: RunFloating(dt/2, predictor))
            self.half_step_hook(self, 0.5 * dt)
        if npre:
            # flagged at the half step: out before the corrector, as DualSPHysics's RunCellDivide;
            # Shifting 4's shift, found in the predictor, goes on to the corrector
            self._exclude(self.time + dt,
                          carry=("shiftpos", "nctype", "fstype", "fsnormal") if self.shift == 4 else ())
        self._in_corrector = True
        self.dem_dt = dt
        try:
            self.compute_rates()
        finally:
            self._in_corrector = False
        self._need_shift_adv = True
        nout = k["sym_corr"](*self._corr_args())
        if self.flex is not None:
            self._flex_update("corr", dt)
        if self.nopen:
            nout += self._nopen_apply(True)
        # the next step's dt: min(dt_p, dt_c) as ComputeStep_Sym (<savedt> keeps the corrector's
        # terms, as its SaveDt); a step counts once in n_dtmin when either was raised to DtMin
        self.dt_pre = min(dt_p, self._variable_dt(self.time + dt, count=False))
        if clamped or self._clamped:
            self.n_dtmin += 1
        if nout:
            self._exclude(self.time + dt)
        return dt

    def run(self, tmax, max_steps=None):
        """Step until the clock reaches ``tmax`` to round-off, as ``sphdvi run`` does (or
        ``max_steps``); returns the number of steps."""
        n = 0
        while not time_reached(self.time, tmax) and (max_steps is None or n < max_steps):
            self.step()
            n += 1
        return n

    # ------------------------------------------------------------------ inlet/outlet
    def _inout_impose(self, ptype_rows, oi, nb=None, prow=None):
        """The buffer particles' imposed or extrapolated velocity and density, into the state
        and the packed rows, before the interaction (sphdvi.sph.inout.impose_serial).  Periodic runs
        pass the extended set's packed array ``nb``, ``oi`` (-1 - particle for a copy) and ``prow``
        (every row's particle); the copies of buffers then take their particles' values."""
        from .inout import impose_parallel, impose_serial, refresh_buffer_copies
        nb = self.nb if nb is None else nb
        prow = oi if prow is None else prow
        io = self.inout
        s = self.state
        io.update_time(self.time, s)
        verlet = self.step_algorithm == 1
        ncx, ncy, ncz = self.cells.shape
        # not a light kernel: the extrapolation sums a kernel's worth of fluid per buffer particle
        fn = impose_parallel if self._use_parallel() else impose_serial
        fn(self.kernel, self.is2d, nb, ptype_rows, oi, prow, s.pos, s.vel, s.rhop, s.mass, s.idp, io.zone_of_idp,
           self.cells.cell_start, self.cells.pmin, 1.0 / self.cells.cellsize, ncx, ncy, ncz, self.cst, io.geo,
           io.cfg, io.coef, io.zsurf, io.determlimit, io.coef_hydro,
           self.vel_m1 if verlet else self._no_m1[0], self.rhop_m1 if verlet else self._no_m1[1], self.dp)
        if prow is not oi:
            refresh_buffer_copies(nb, ptype_rows, oi, prow, s.idp, io.zone_of_idp, s.vel, s.rhop, self.is2d,
                                  self.cst)

    _no_m1 = (np.zeros((0, 3)), np.zeros(0))
    _no_axes = np.zeros(0, np.int64)
    _no_shift = np.zeros((3, 3))

    def _inout_zero_rates(self):
        """Buffer particles take no acceleration, density rate or shift; the force term of dt is
        taken again without them (as after the imposed accelerations)."""
        from .inout import zero_rates_parallel, zero_rates_serial
        s = self.state
        zero_rates = zero_rates_parallel if self._use_parallel(light=True) else zero_rates_serial
        zero_rates(s.ptype, s.idp, self.inout.zone_of_idp, self.ace, self.ar, self.shiftpos)
        self.dtmax[:, 0] = 0.0
        self.dtmax[0, 0] = fluid_ace_max2(self.ace, s.ptype, *self.gravity)

    def _inout_update(self):
        """End of step: buffer particles that crossed their plane become fluid (a new one taking
        each one's place behind), those that left the buffer's back are removed, fluid entering a
        zone is converted or removed (sphdvi.sph.inout.classify_serial); advanced refilling fills
        the columns the flow emptied."""
        from .inout import (REMOVE, TO_BUFFER, TO_FLUID, TO_FLUID_REFILL, G_N, G_W, classify_parallel, classify_serial,
                            refill_columns)
        io = self.inout
        s = self.state
        self._check_state_arrays()
        action = np.empty(s.n, np.int8)
        classify = classify_parallel if self._use_parallel() else classify_serial
        per = self.periodicity
        paxes = np.asarray(per.axes, np.int64) if per is not None else self._no_axes
        pshift = per.shift if per is not None else self._no_shift
        classify(s.pos, s.ptype, s.idp, io.zone_of_idp, io.geo, io.cfg, io.zsurf, self.dp, action, paxes, pshift)
        moved = np.flatnonzero(action != 0)
        new_pos = new_src = new_zone = None
        if moved.size:
            act = action[moved]
            ids = s.idp[moved]
            crossing = moved[(act == TO_FLUID) | (act == TO_FLUID_REFILL)]
            refill = moved[act == TO_FLUID_REFILL]
            if refill.size:
                zr = io.zone_of_idp[s.idp[refill]].astype(np.int64)
                new_pos = s.pos[refill] - io.geo[zr, G_W][:, None] * io.geo[zr, G_N:G_N + 3]
                new_src, new_zone = refill, zr
            io.mark(s.idp[crossing], -1)
            io.counts["to_fluid"] += int(crossing.size)
            conv = act >= TO_BUFFER
            if conv.any():
                io.mark(ids[conv], (act[conv] - TO_BUFFER).astype(np.int8))
                io.counts["to_buffer"] += int(np.count_nonzero(conv))
        if io.pts_all.shape[0]:
            depth = np.empty(io.pts_all.shape[0])
            zrow = io.zone_of_idp[s.idp]
            rows = np.flatnonzero((s.ptype == FLUID) & (zrow >= 0) & io.refill2[np.maximum(zrow, 0)])
            refill_columns(io.pts_all, io.pts_zone, io.geo, io.zsurf, s.pos, rows, zrow[rows].astype(np.int64),
                           self.dp, depth)
            ok = np.flatnonzero(depth >= 0)
            if ok.size:
                zr = io.pts_zone[ok]
                fill = io.pts_all[ok] - depth[ok][:, None] * io.geo[zr, G_N:G_N + 3]
                src = self._buffer_row_of_zone(zr)
                keep = src >= 0
                if keep.any():
                    fill, zr, src = fill[keep], zr[keep], src[keep]
                    new_pos = fill if new_pos is None else np.concatenate([new_pos, fill])
                    new_src = src if new_src is None else np.concatenate([new_src, src])
                    new_zone = zr if new_zone is None else np.concatenate([new_zone, zr])
        if new_pos is not None and len(new_pos):
            self._append_buffer_particles(new_pos, new_src, new_zone)
            action = np.concatenate([action, np.zeros(len(new_pos), np.int8)])
        gone = action == REMOVE
        if gone.any():
            io.counts["removed"] += int(np.count_nonzero(gone))
            self._remove_rows(gone.astype(np.int8))

    def _buffer_row_of_zone(self, zones):
        """A particle row to copy mass, mk and density from for new particles of each zone: one of
        its buffer particles (-1 for a zone with none)."""
        s = self.state
        zrow = self.inout.zone_of_idp[s.idp]
        out = np.full(len(zones), -1, np.int64)
        for z in np.unique(zones):
            rows = np.flatnonzero((zrow == z) & (s.ptype == FLUID))
            if rows.size:
                out[zones == z] = rows[0]
        return out

    def _append_buffer_particles(self, pos, src, zones):
        """Add buffer particles at ``pos`` of ``zones``, with the mass, mk, density and velocity
        of rows ``src``; every per-particle work array gains zero rows (the Verlet previous-step
        values copy the source's)."""
        s = self.state
        io = self.inout
        m = len(pos)
        ids = io.take_ids(m)
        io.mark(ids, np.asarray(zones, np.int8))
        io.counts["created"] += m
        new = {"pos": np.asarray(pos, float), "vel": s.vel[src], "rhop": s.rhop[src], "mass": s.mass[src],
               "ptype": np.full(m, FLUID, np.int8), "idp": ids, "mk": s.mk[src]}
        n = s.n
        for name in self._aux_names():
            a = getattr(self, name)
            if a.shape[0] != n:
                continue
            if name in ("vel_m1", "rhop_m1"):
                extra = a[src]
            else:
                extra = np.zeros((m,) + a.shape[1:], a.dtype)
            setattr(self, name, np.concatenate([a, extra]))
        for f in FluidState.FIELDS:
            setattr(s, f, np.concatenate([getattr(s, f), new[f]]))
        self._alloc()

    def _remove_rows(self, codes, carry=()):
        """Drop the rows where ``codes`` is not 0 from the state and the per-particle arrays.
        ``carry``: per-particle work arrays (attribute names) kept, less those rows, rather than
        zeroed.  The kept rows move down in place (:func:`_compact_rows`) and every array becomes a
        view of its first rows: nothing is allocated (DualSPHysics moves the excluded particles to
        the end of its arrays and shrinks Np, JCellDivCpu)."""
        s = self.state
        n = codes.shape[0]
        for f in FluidState.FIELDS:
            setattr(s, f, _compacted(getattr(s, f), codes))
        for name in self._aux_names():
            a = getattr(self, name)
            if a.shape[0] == n:
                setattr(self, name, _compacted(a, codes))
        kept = tuple(name for name in carry if getattr(self, name).shape[0] == n)
        for name in kept:
            setattr(self, name, _compacted(getattr(self, name), codes))
        self._alloc(reuse=True, keep=kept)

    # ------------------------------------------------------------------ exclusion
    def _exclude(self, t_end: float, carry=()):
        """Remove the flagged fluid particles from the state and work arrays
        (:meth:`_remove_rows`, ``carry`` as there), and keep an event of them (what they were
        when the step ending at ``t_end`` removed them)."""
        s = self.state
        codes = self.out.copy()
        bad = codes != 0
        for code, name in REASON_NAMES.items():
            self.n_excluded[name] += int(np.count_nonzero(codes == code))
        self.excluded.append({
            "time": t_end, "idp": s.idp[bad].copy(), "pos": s.pos[bad].copy(),
            "vel": s.vel[bad].copy(), "rhop": s.rhop[bad].copy(),
            "reason": [REASON_NAMES[int(c)] for c in codes[bad]]})
        self._remove_rows(codes, carry)

    def take_excluded(self) -> list:
        """The exclusion events since the last call (oldest first); the list starts anew."""
        events, self.excluded = self.excluded, []
        return events

    # ------------------------------------------------------------------ checkpoints
    CHECKPOINT_SCALARS = ("time", "nstep", "n_dtmin", "_verlet_count", "dt_pre", "last_dt", "dt_error")
    # what an older sphdvi's checkpoint may lack, and the value it then starts from
    CHECKPOINT_DEFAULTS = {"dt_error": -np.inf}

    def get_checkpoint(self) -> dict:
        """What a resumed run needs to go on bitwise: the particle state, the integrator's
        work arrays (previous-step values, SPS stresses, mDBC normals…), the clock and
        step counters, and the exclusion counts.  The arrays are the solver's own, not copies."""
        aux = {name: getattr(self, name) for name in self._aux_names()}
        if self.inout is not None:
            aux.update(self.inout.get_state())
        return {"state": {name: getattr(self.state, name) for name in self.state.FIELDS},
                "aux": aux,
                "scalars": {name: getattr(self, name) for name in self.CHECKPOINT_SCALARS},
                "n_excluded": dict(self.n_excluded)}

    def set_checkpoint(self, ck: dict) -> list:
        """Restore what :meth:`get_checkpoint` returned; a work array missing from ``ck``
        (written by an older sphdvi) starts from zero.  Returns the names of those."""
        for name in self.state.FIELDS:
            setattr(self.state, name, np.ascontiguousarray(ck["state"][name]))
        self._alloc()
        n = self.state.n
        missing = []
        for name in self._aux_names():
            if name in ck["aux"]:
                setattr(self, name, np.ascontiguousarray(ck["aux"][name]))
                continue
            cur = getattr(self, name)
            setattr(self, name, np.zeros((n,) + cur.shape[1:], cur.dtype))
            missing.append(name)
        for name in self.CHECKPOINT_SCALARS:
            value = ck["scalars"].get(name, self.CHECKPOINT_DEFAULTS.get(name))
            if value is None:
                raise KeyError(name)
            setattr(self, name, value.item() if isinstance(value, np.generic) else value)
        if self.inout is not None:
            if "inout_zone_of_idp" not in ck["aux"]:
                raise KeyError("inout_zone_of_idp")
            self.inout.set_state(ck["aux"])
        # a reason added since the checkpoint was written ("movement") starts from 0
        self.n_excluded = {**{name: 0 for name in REASON_NAMES.values()}, **dict(ck["n_excluded"])}
        return missing

    # ------------------------------------------------------------------ outputs
    @property
    def press(self):
        """Pressure from Tait's EOS for the current densities."""
        return self.b * ((self.state.rhop / self.rhop0) ** self.gamma - 1.0)

    @property
    def n_fluid(self):
        return int(np.count_nonzero(self.state.ptype == FLUID))

    def memory_bytes(self):
        """Bytes held in arrays by the state and the solver: its array attributes, those held in
        tuples and lists (Shifting 4's work arrays, the cell list's spare room) and the work
        buffers; each buffer counted once, whole (a view counts as the array it is a view of,
        spare rows included)."""
        seen = {}

        def add(a):
            if isinstance(a, np.ndarray):
                while isinstance(a.base, np.ndarray):
                    a = a.base
                seen[id(a)] = a.nbytes

        for obj in (self.state, self, self.cells):
            names = obj.__slots__ if hasattr(obj, "__slots__") else vars(obj)
            for name in names:
                a = getattr(obj, name, None)
                for item in (a if isinstance(a, (tuple, list)) else (a,)):
                    add(item)
        for a in list(self._bufs.values()) + list(self._ghost_bufs.values()):
            add(a)
        return int(sum(seen.values()))

    def particle_forces(self):
        """m_a a_a for every particle (for floating bodies: fluid force, no gravity)."""
        return self.state.mass[:, None] * self.ace


def _compacted(a: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """``a`` less the rows where ``codes`` is not 0, moved down in place: a view of its first rows
    (a[codes == 0] in its own memory)."""
    if not a.flags.c_contiguous:
        return np.ascontiguousarray(a[codes == 0])
    words = a.view(_WORDS[a.dtype.itemsize]) if a.dtype.itemsize in _WORDS else a.view(np.uint8)
    m = _compact_rows(words.reshape(a.shape[0], -1), codes)
    return a[:m]


_WORDS = {8: np.uint64, 4: np.uint32, 1: np.uint8}     # rows copied as words of the item's size


@numba.njit(cache=True)
def _compact_rows(a, codes):
    """The rows of ``a`` (rows of words) where ``codes`` is 0 moved down in order, in place; their count."""
    m = 0
    for i in range(a.shape[0]):
        if codes[i] == 0:
            if m != i:
                for b in range(a.shape[1]):
                    a[m, b] = a[i, b]
            m += 1
    return m


@numba.njit(cache=True)
def _copy_rows_2d(src, rows, out, dst):
    """out[dst[k]] = src[rows[k]]: the periodic extended set's real rows back to their particles
    (numpy's 2D fancy indexing costs ~100 us per array at a few thousand rows)."""
    for k in range(rows.shape[0]):
        for j in range(src.shape[1]):
            out[dst[k], j] = src[rows[k], j]


@numba.njit(cache=True)
def _copy_rows_1d(src, rows, out, dst):
    """out[dst[k]] = src[rows[k]] (1D arrays)."""
    for k in range(rows.shape[0]):
        out[dst[k]] = src[rows[k]]


@numba.njit(cache=True)
def _dtmax_columns(dtmax):
    """The maxima of the three columns of the interaction's per-chunk time-step terms, as
    numpy's dtmax.max(axis=0) (a NaN propagates) for a (k >= 1, 3) array."""
    a = dtmax[0, 0]
    v = dtmax[0, 1]
    c = dtmax[0, 2]
    for k in range(1, dtmax.shape[0]):
        x = dtmax[k, 0]
        if x > a or x != x:
            a = x
        x = dtmax[k, 1]
        if x > v or x != x:
            v = x
        x = dtmax[k, 2]
        if x > c or x != x:
            c = x
    return a, v, c


@numba.njit(cache=True, error_model="numpy")
def _extend_positions(pos, src, disp, out):
    """The periodic extended set's positions: out[:n] = pos, then out[n + g] = pos[src[g]] +
    disp[g] for the ghost copies (JSphCpuSingle::PeriodicMakeList's displaced copies)."""
    n = pos.shape[0]
    for i in range(n):
        for m in range(3):
            out[i, m] = pos[i, m]
    for g in range(src.shape[0]):
        i = src[g]
        for m in range(3):
            out[n + g, m] = pos[i, m] + disp[g, m]


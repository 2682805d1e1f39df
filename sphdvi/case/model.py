"""Typed data read from a case file (what the solver, the multibody engine and
the measurement tools consume). Plain dataclasses of numbers, lists and dicts:
they serialise to JSON and HDF5 without custom code."""
from __future__ import annotations

from dataclasses import dataclass, field, asdict

import numpy as np


@dataclass
class ConstantsDef:
    """``<constantsdef>`` as written; ``None`` means ``auto``."""
    lattice_bound: int = 1
    lattice_fluid: int = 1
    gravity: list = field(default_factory=lambda: [0.0, 0.0, -9.81])
    rhop0: float = 1000.0
    rhopgradient: int = 2
    hswl: float | None = None
    gamma: float = 7.0
    speedsystem: float | None = None
    coefsound: float = 20.0
    speedsound: float | None = None
    coefh: float | None = None
    hdp: float | None = None
    cflnumber: float = 0.2
    h: float | None = None
    b: float | None = None
    massbound: float | None = None
    massfluid: float | None = None


@dataclass
class Constants:
    """Resolved simulation constants (DualSPHysics's auto rules applied)."""
    dp: float
    h: float
    b: float
    cs0: float
    rhop0: float
    gamma: float
    gravity: list
    cflnumber: float
    hswl: float
    speedsystem: float
    coefsound: float
    coefh: float
    massfluid: float
    massbound: float
    is2d: bool
    posy2d: float
    rhopgradient: int

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class Material:
    """A ``<property>``: contact material for Chrono-style bodies."""
    name: str
    young: float | None = None
    poisson: float | None = None
    restitution: float | None = None
    kfric: float | None = None
    sfric: float | None = None
    extra: dict = field(default_factory=dict)
    user: list = field(default_factory=list)    # the values given as *_User (they win in a combination)


@dataclass
class FloatingDef:
    """A ``<floating>`` entry as written (one per mkbound list)."""
    mkbound: list
    line: int
    rhopbody: float | None = None
    relativeweight: float | None = None
    massbody: float | None = None
    masspart: float | str | None = None
    center: list | None = None
    inertia: list | None = None          # 3x3 nested list
    translation_dof: list = field(default_factory=lambda: [1, 1, 1])
    rotation_dof: list = field(default_factory=lambda: [1, 1, 1])
    linearvelini: list = field(default_factory=lambda: [0.0, 0.0, 0.0])
    angularvelini: list = field(default_factory=lambda: [0.0, 0.0, 0.0])
    linearvel: dict | None = None        # {"times": [...], "values": [[x|None,...]]} (a file is read at gencase; older case files hold {"file": path})
    angularvel: dict | None = None
    linearforce: dict | None = None
    angularforce: dict | None = None
    property: str | None = None


@dataclass
class Body:
    """A floating body resolved from its particles (what GenCase writes)."""
    mkbound: int
    mk: int
    begin: int
    count: int
    mass: float
    masspart: float
    center: list
    inertia: list                        # 3x3
    translation_dof: list
    rotation_dof: list
    linearvelini: list
    angularvelini: list
    property: str | None = None
    analytic: dict | None = None         # {"shape":..., "mass":..., "inertia": 3x3} when a primitive
    linearvel: dict | None = None
    angularvel: dict | None = None
    linearforce: dict | None = None
    angularforce: dict | None = None


@dataclass
class Case:
    """Everything read from a case file except the particles."""
    name: str
    file: str
    source: str
    constantsdef: ConstantsDef
    boundcount: int = 240
    fluidcount: int = 9
    floatings: list = field(default_factory=list)       # FloatingDef
    initials: list = field(default_factory=list)        # dicts
    motions: list = field(default_factory=list)         # dicts (one per objreal)
    materials: dict = field(default_factory=dict)       # name -> Material
    material_links: list = field(default_factory=list)  # {"mkbound"|"mkfluid": [...], "property": "A+B"}
    normals: list = field(default_factory=list)         # dicts
    special: dict = field(default_factory=dict)         # chrono, gauges, wavepaddles, damping, shifting, ...
    parameters: dict = field(default_factory=dict)      # key -> value (all keys, defaults filled)
    parameters_set: list = field(default_factory=list)  # keys written in the file
    simulationdomain: dict = field(default_factory=dict)  # posmin/posmax: list of 3 strings ("default - 20%")


def mk_of_bound(mkbound: int, fluidcount: int) -> int:
    """Global mk of a boundary label (``mk = mkbound + fluidcount + 1``... DualSPHysics numbering)."""
    return int(mkbound) + int(fluidcount) + 1


def mk_of_fluid(mkfluid: int) -> int:
    """Global mk of a fluid label (``mk = mkfluid + 1``)."""
    return int(mkfluid) + 1


def as_list(a) -> list:
    return np.asarray(a, dtype=float).tolist()

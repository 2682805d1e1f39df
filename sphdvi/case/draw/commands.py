"""The GenCase command interpreter: ``<geometry>`` -> particles.

See the package docstring (:mod:`sphdvi.case.draw`) for the drawing rules.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..expressions import ExpressionError
from . import raster, shapes
from . import redraw as redraw_kernels
from . import transform as tf
from .lattice import Canvas, Lattice, ceil_idx, floor_idx, round_idx
from .shapeout import FORMATS, merge_shapes, write_points, write_shapes

MAX_COMMANDS = 1_000_000      # commands executed in all (runlist loops included)
MAX_LIST_DEPTH = 64
MAX_POINTS = 1_000_000        # points or triangles written inline in one command
MAX_SHAPE_TRIANGLES = 5_000_000  # triangles kept for <shapeout>
DRAW_MODES = {"full", "face", "solid", "wire"}
BOX_TOKENS = {"solid", "all", "bottom", "top", "left", "right", "front", "back"}
FILL_TOKENS = {"void", "border", "fluid", "bound"}
FILLS = {"fillpoint", "fillbox"}    # _record shapes of the fill commands
#: _record shapes of the commands that change nodes by what they hold, not by a shape
REDRAWS = {"redraw", "redrawbox", "redrawnear", "redrawnearbox"}
SKIPPED_ATTRS = {"comment", "units_comment", "comment2", "rem", "active"}

#: commands of GenCase that sphdvi does not implement
UNSUPPORTED = {
    "drawwave",
    "clipdomain", "clipplane", "clipbox",
    "clipreset", "setpattern", "patterns", "fillfigure", "fillprism",
    "setmknextauto", "setmkbackvoid", "setmkbackfluid",
    "setmkbackbound", "setmkbackclear", "rotateadv",
}
BOX_LIMIT_MODES = {"full", "inner"}
#: commands accepted without effect (they tune GenCase's own output or sampling)
NO_EFFECT = {"setdpctes", "dpctessave", "dpctesload", "dpctesreset", "setshapemode",
             "setnormalinvert", "exportvar", "debugout", "cellsout", "pointsmkout"}


@dataclass
class Drawing:
    """Result of the ``<geometry>`` section: the particles and what was drawn."""

    dp: float
    pointmin: np.ndarray
    pointmax: np.ndarray
    pointref: np.ndarray
    is2d: bool
    posy2d: float
    pos: np.ndarray
    is_fluid: np.ndarray
    mk: np.ndarray
    primitives: list = field(default_factory=list)
    shape_files: list = field(default_factory=list)
    shape_sets: dict = field(default_factory=dict)   # <shapeout file> name -> (triangles, mk)
    messages: list = field(default_factory=list)
    origin: np.ndarray | None = None   # first lattice node (pointmin, or pointref-aligned)

    @property
    def count_fluid(self) -> int:
        return int(np.count_nonzero(self.is_fluid))

    @property
    def count_bound(self) -> int:
        return int(self.is_fluid.size - np.count_nonzero(self.is_fluid))


@dataclass
class DrawState:
    """The pen: what is drawn (kind + mk), how (mode), where (matrix)."""

    kind: str | None = None      # "fluid", "bound", "void" or None (nothing set yet)
    mk: int = 0
    mode: str = "full"
    matrix: np.ndarray = field(default_factory=tf.identity)
    draw_points: bool = True
    draw_shapes: bool = True
    box_limit: str = "inner"     # <setboxlimitmode>: the nodes a <fillbox> may fill

    def copy(self) -> "DrawState":
        return DrawState(self.kind, self.mk, self.mode, self.matrix.copy(), self.draw_points,
                         self.draw_shapes, self.box_limit)


def _point_summary(pts: np.ndarray, keep: int = 100) -> dict:
    """Parameters of a point set: the points themselves when few, else count and bounds."""
    if len(pts) <= keep:
        return {"points": pts.tolist()}
    return {"count": int(len(pts)), "min": pts.min(axis=0).tolist(),
            "max": pts.max(axis=0).tolist()}


def _hash_interpolate(vars_, text: str) -> str:
    """Each ``#expr#`` in ``text`` replaced by the value of ``expr``, where it is one."""
    def value(m):
        try:
            return vars_.interpolate("[" + m.group(1) + "]")
        except ExpressionError:
            return m.group(0)
    return re.sub(r"#([^#\n]+)#", value, text)


def _attr_items(el):
    """User attributes of a variable command (name, value), skipping comments and _private ones."""
    return [(k, v) for k, v in el.attrib.items()
            if k not in SKIPPED_ATTRS and not k.startswith("_") and not k.endswith("_comment")]


class GeometryRunner:
    """Executes the command lists of ``<geometry>`` on a canvas."""

    def __init__(self, reader, lattice: Lattice | None, casename: str, outdir: str | None):
        self.reader = reader
        self.vars = reader.vars
        self.lat = lattice
        self.canvas = Canvas(lattice) if lattice is not None else None
        self.casename = casename
        self.outdir = outdir
        self.state = DrawState()
        self.saved_matrices: list[np.ndarray] = []
        self.saved_states: list[DrawState] = []
        self.saved_mk: tuple | None = None
        self.last_mk: dict = {"fluid": None, "bound": None}   # the last mk of each kind (setmknext*)
        self.saved_vars: list = []
        self.lists: dict = {}
        self.call_stack: list[str] = []
        self.executed = 0
        self.line_begin = None
        self.primitives: list = []
        self.shapes: list = []
        self.keep_shapes = True      # False when the document has no <shapeout>
        self.shape_triangles = 0
        self.shape_files: list = []
        self.shape_sets: dict = {}
        self.messages: list = []
        self.bathymetries = 0         # <drawbathymetry> commands run (names their debug files)
        self.handlers = self._handler_table()

    # ------------------------------------------------------------ dispatch
    def _handler_table(self):
        names = ["newvar", "newvarcte", "setvar", "newvarstr", "newvarstrcte", "setvarstr",
                 "delvar", "varssave", "varsload", "printf", "abort", "runlist",
                 "setmkfluid", "setmkbound", "setmkvoid", "setmknextbound", "setmknextfluid",
                 "mksave", "mkload", "setdrawmode", "setfrdrawmode",
                 "setactive", "resetdraw", "setboxlimitmode", "move", "scale", "rotate", "rotateline", "matrixreset",
                 "matrixsave", "matrixload", "statesave", "stateload",
                 "drawpoint", "drawpoints", "drawline", "drawlines", "setlinebegin", "drawlineto",
                 "drawtriangle", "drawquadri", "drawtrianglesstrip", "drawtrianglesfan",
                 "drawpolygon", "drawtriangles", "drawfigure", "drawbox", "drawsphere",
                 "drawellipsoid", "drawcylinder", "drawprism", "drawpyramid", "drawbeach",
                 "drawextrude", "drawfilestl",
                 "drawfileply", "drawfilevtk", "drawfilevtm", "drawfilecsv", "drawbathymetry",
                 "fillpoint", "fillvoidpoint", "fillbox", "shapeout",
                 "redraw", "redrawbox", "redrawnear", "redrawnearbox"]
        return {n: getattr(self, "cmd_" + n) for n in names}

    def run_commands(self, container, only_variables: bool = False) -> None:
        """Execute every command element of a list, in order."""
        for el in self.reader.children(container):
            self.run_command(el, only_variables)

    def run_command(self, el, only_variables: bool = False) -> None:
        self.executed += 1
        if self.executed > MAX_COMMANDS:
            raise self.reader.error(el, f"more than {MAX_COMMANDS} commands executed "
                                        "(runlist loop?)", "fewer runlist repetitions")
        tag = el.tag
        if only_variables and tag not in VARIABLE_COMMANDS:
            raise self.reader.error(el, f"<{tag}> is not allowed in <predefinition>",
                                    "variable commands only: " + ", ".join(sorted(VARIABLE_COMMANDS)))
        if tag in UNSUPPORTED:
            raise self.reader.error(el, f"GenCase command <{tag}> is not supported by sphdvi",
                                    "a supported drawing command (see sphdvi.case.draw)")
        if tag in NO_EFFECT:
            self.reader.mark(el, *el.attrib.keys())
            return
        handler = self.handlers.get(tag)
        if handler is None:
            raise self.reader.error(el, f"unknown command <{tag}>",
                                    "one of " + ", ".join(sorted(self.handlers)))
        try:
            handler(el)
        except ExpressionError as exc:
            raise self.reader.error(el, str(exc)) from None
        except (ValueError, ArithmeticError) as exc:
            # degenerate geometry that slipped through the checks (e.g. 1e308 sizes)
            raise self.reader.error(el, f"cannot draw this shape: {exc}",
                                    "finite, reasonably sized geometry") from None

    # ------------------------------------------------------------ small readers
    def _points(self, el, tag: str = "point", least: int = 0, exact: int | None = None):
        kids = self.reader.children(el, tag)
        if len(kids) > MAX_POINTS:
            raise self.reader.error(el, f"{len(kids)} <{tag}> elements", f"at most {MAX_POINTS}")
        if exact is not None and len(kids) != exact:
            raise self.reader.error(el, f"{len(kids)} <{tag}> elements", f"exactly {exact}")
        if len(kids) < least:
            raise self.reader.error(el, f"{len(kids)} <{tag}> elements", f"at least {least}")
        return np.array([self.reader.vec3(k) for k in kids], dtype=np.float64).reshape(-1, 3)

    def _check(self, el, allowed) -> None:
        self.reader.check_children(el, set(allowed) | {"rem"}, "child element")

    def _need_pen(self, el) -> None:
        if self.state.kind is None:
            raise self.reader.error(el, "nothing to draw with: no mk selected",
                                    "<setmkfluid>, <setmkbound> or <setmkvoid> before drawing")

    def _code(self) -> int:
        s = self.state
        if s.kind == "void":
            return 0
        return self.canvas.code_for(s.kind == "fluid", s.mk)

    def _paint(self, el, pieces) -> int:
        """Paint pieces with the current pen; returns the number of nodes written."""
        if not self.state.draw_points:
            return 0
        code = self._code()
        n = 0
        for p in pieces:
            p.paint(self.canvas, code)
            n += p.count()
        return n

    def _record(self, el, shape: str, params: dict, tris, solid: bool, nodes: int) -> None:
        s = self.state
        prim = {"shape": shape, "fluid": s.kind == "fluid", "void": s.kind == "void",
                "mk": int(s.mk) if s.kind in ("fluid", "bound") else -1, "solid": bool(solid),
                "mode": s.mode, "nodes": nodes, "line": el.sourceline, "params": params}
        self.primitives.append(prim)
        if (nodes == 0 and s.draw_points and s.kind in ("fluid", "bound") and shape not in FILLS
                and shape not in REDRAWS):
            self._warn_nothing_drawn(el, tris, params)
        if s.draw_shapes and tris is not None and self.keep_shapes:
            tris = np.asarray(tris)
            if self.shape_triangles + len(tris) > MAX_SHAPE_TRIANGLES:
                self.reader.warn(el, f"more than {MAX_SHAPE_TRIANGLES} shape triangles: this and "
                                     "later shapes are left out of <shapeout> files")
                self.keep_shapes = False
                return
            self.shape_triangles += len(tris)
            self.shapes.append({"triangles": tris, "mk": prim["mk"], "fluid": prim["fluid"]})

    def _warn_nothing_drawn(self, el, tris, params: dict) -> None:
        """A fluid or boundary drawing command that creates no particle at all (its shape misses
        the domain, or in 2D the plane y = posy, or lies between the lattice nodes) is warned
        about: its wall or fluid silently vanished before (warn_no_fluid caught only a case with
        no fluid at all). Fills and void drawing are left out: they may rightly change nothing."""
        s, lat = self.state, self.lat
        msg = f"this <{el.tag}> (mk{s.kind} {s.mk}) creates no particles: "
        pts = tris if tris is not None and len(tris) else params.get("points", params.get("point"))
        lo = hi = None
        if pts is not None and np.size(pts):
            p = np.asarray(pts, dtype=np.float64).reshape(-1, 3)
            lo, hi = p.min(axis=0), p.max(axis=0)
        tol = 1e-6 * lat.dp
        if lat.is2d and lo is not None and not lo[1] - tol <= lat.pointmin[1] <= hi[1] + tol:
            msg += (f"it spans y = {lo[1]:g}..{hi[1]:g} and misses the 2D plane y = "
                    f"{lat.pointmin[1]:g} (a shape of a 2D case must cross it)")
        elif lo is not None and (np.any(hi < lat.pointmin - tol) or np.any(lo > lat.pointmax + tol)):
            msg += (f"it lies outside the domain pointmin {lat.pointmin.tolist()} .. pointmax "
                    f"{lat.pointmax.tolist()}")
        else:
            msg += ("no lattice node of it lies in the domain" + (" or its mask leaves every face out"
                                                                  if params.get("mask") else ""))
        self.reader.warn(el, msg)

    def _mask(self, el) -> frozenset:
        """The ``mask`` attribute: the numbers (from 1) of the faces left out, joined by ``|``.

        ``mask="1 | 2 | 6 | 7"`` hides faces 1, 2, 6 and 7 (a list, not a bit set); 0 hides none.
        """
        text = self.reader.text_attr(el, "mask", "0")
        hidden = set()
        for tok in str(text).split("|"):
            tok = tok.strip()
            if not tok:
                continue
            try:
                v = float(self.vars.number(tok[1:] if tok.startswith("#") else tok))
            except ExpressionError:
                raise self.reader.error(el, f"mask={text!r} is not valid",
                                        "face numbers joined by |, e.g. mask=\"1 | 2\"") from None
            if v != int(v) or v < 0 or v > 2**31:
                raise self.reader.error(el, f"mask={text!r} is not valid",
                                        "non-negative integer face numbers joined by |")
            if v > 0:
                hidden.add(int(v))
        return frozenset(hidden)

    def _warn_missing_faces(self, el, hidden: frozenset, nfaces: int) -> None:
        """A mask none of whose numbers is a face of the shape hides nothing: warned (GenCase's
        ``mask`` lists face numbers 1..nfaces; ``mask="96"`` on a prism passed silently before).
        A number beyond the faces beside valid ones is passed silently, as GenCase does: the
        official flumes write ``mask="1 | 2 | 6 | 7"`` on 4-point prisms (faces 1 to 6)."""
        extra = sorted(f for f in hidden if f > nfaces)
        if extra and len(extra) == len(hidden):
            self.reader.warn(el, f"mask names face{'s' if len(extra) > 1 else ''} "
                                 f"{', '.join(map(str, extra))} but this <{el.tag}> has faces 1 to "
                                 f"{nfaces} only: {'they hide' if len(extra) > 1 else 'it hides'} "
                                 "nothing (mask lists face numbers joined by |, e.g. mask=\"1 | 2\")")

    def _open_shape_flags(self, el, hidden: frozenset, nfaces: int):
        """(solid, faces, wire) of a shape with ``nfaces`` faces of which ``hidden`` are left out.

        With a face left out, ``full`` draws the remaining faces alone (an open shape: the fluid
        drawn before or filled after stays inside, DualSPHysics v5.4's CaseWavemaker,
        CasePointAbsorber, CaseFloatingWavesVal); ``solid`` draws no surface, so the mask changes
        nothing there: the closed shape's volume is drawn (GenCase v4.0.053's record of
        DualSPHysics's motion/Motion08: three cylinders with mask="1" in solid mode, 110, 311 and
        312 particles, the whole disks).
        """
        solid, surface, wire = self._mode_flags()
        if any(1 <= f <= nfaces for f in hidden) and self.state.mode != "solid":
            solid = False
        return solid, surface, wire

    def _mode_flags(self):
        """(solid, surface, wire) for the current draw mode."""
        m = self.state.mode
        return m in ("full", "solid"), m in ("full", "face"), m == "wire"

    # ------------------------------------------------------------ variables
    def _define_vars(self, el, constant: bool, redefine: bool, text: bool) -> None:
        for name, value in _attr_items(el):
            self.reader.mark(el, name)
            raw = value.strip()
            try:
                if text:
                    val = self.vars.interpolate(value)
                else:
                    val = self.vars.evaluate(raw[1:] if raw.startswith("#") else raw)
                    if isinstance(val, float) and not math.isfinite(val):
                        raise ExpressionError(f"{name}={value!r} is not finite")
                if not redefine and name not in self.vars.values:
                    raise ExpressionError(f"variable '{name}' does not exist "
                                          f"({el.tag} changes existing variables)")
                self.vars.define(name, val, constant=constant)
            except ExpressionError as exc:
                raise self.reader.error(el, f"{name}: {exc}") from None

    def cmd_newvar(self, el):
        self._define_vars(el, False, True, False)

    def cmd_newvarcte(self, el):
        self._define_vars(el, True, True, False)

    def cmd_setvar(self, el):
        self._define_vars(el, False, False, False)

    def cmd_newvarstr(self, el):
        self._define_vars(el, False, True, True)

    def cmd_newvarstrcte(self, el):
        self._define_vars(el, True, True, True)

    def cmd_setvarstr(self, el):
        self._define_vars(el, False, False, True)

    def cmd_delvar(self, el):
        for pat in self.reader.text_attr(el, "vars").split(","):
            if pat.strip():
                self.vars.delete(pat.strip())

    def cmd_varssave(self, el):
        self.saved_vars.append(self.vars.copy())

    def cmd_varsload(self, el):
        if not self.saved_vars:
            raise self.reader.error(el, "no variables saved", "a <varssave> before <varsload>")
        saved = self.saved_vars[-1]
        self.vars.values = dict(saved.values)
        self.vars.constant = set(saved.constant)

    def _condition(self, el) -> bool:
        """The ``if`` of <printf>/<abort>; ``text`` is marked read here too, as a false
        condition skips the command with both attributes valid (GenCase_CaseTemplate.xml)."""
        cond = el.get("if")
        self.reader.mark(el, "if", "text")
        if cond is None:
            return True
        c = cond.strip()
        return bool(self.vars.evaluate(c[1:] if c.startswith("#") else c))

    def _text(self, el) -> str:
        """``<printf>``/``<abort>`` text: ``[expr]`` (GenCase_CaseTemplate.xml: ``"It is [Dp]"``) and
        ``#expr#`` (examples/others/Variables/GenericWaveTank.xml: ``"...parameter: #wheight/wlen#"``)
        replaced by their values; a ``#...#`` that is no expression of the case stays as written."""
        raw = el.get("text", "")
        self.reader.mark(el, "text")
        return _hash_interpolate(self.vars, self.vars.interpolate(raw)).replace("\\n", "\n")

    def cmd_printf(self, el):
        if self._condition(el):
            msg = self._text(el)
            self.messages.append(msg)
            print(msg)

    def cmd_abort(self, el):
        if self._condition(el):
            msg = self._text(el) or "execution aborted"
            raise self.reader.error(el, f"<abort>: {msg}")

    def cmd_runlist(self, el):
        name = self.reader.text_attr(el, "name")
        times = self.reader.integer(el, "times", 1, lo=0, hi=MAX_COMMANDS)
        target = self.lists.get(name)
        if target is None:
            raise self.reader.error(el, f"no <list name=\"{name}\">",
                                    "one of: " + (", ".join(sorted(self.lists)) or "(no lists)"))
        if name in self.call_stack or len(self.call_stack) >= MAX_LIST_DEPTH:
            chain = " -> ".join(self.call_stack + [name])
            raise self.reader.error(el, f"recursive runlist ({chain})", "lists that do not call "
                                    "themselves")
        self.call_stack.append(name)
        try:
            for _ in range(times):
                self.run_commands(target)
        finally:
            self.call_stack.pop()

    # ------------------------------------------------------------ pen state
    def _set_pen(self, kind: str, mk: int) -> None:
        self.state.kind, self.state.mk = kind, mk
        if kind in self.last_mk:
            self.last_mk[kind] = mk

    def cmd_setmkfluid(self, el):
        self._set_pen("fluid", self.reader.integer(el, "mk", lo=0, hi=65535))

    def cmd_setmkbound(self, el):
        self._set_pen("bound", self.reader.integer(el, "mk", lo=0, hi=65535))

    def cmd_setmkvoid(self, el):
        self.state.kind, self.state.mk = "void", 0

    def _next_mk(self, el, kind: str) -> None:
        """``<setmknextbound next="true"/>`` / ``<setmknextfluid next="true"/>``: the pen takes the
        next mk of that kind (the last one set, plus one). DualSPHysics's chrono examples
        CaseFlexibleGate (gate segments mkbound 1-5 from a list ending in it) and CaseBreakingWall
        (blocks 51-77) use it so; ``next="false"`` is not documented and is refused."""
        if not self.reader.boolean(el, "next", True):
            raise self.reader.error(el, 'next="false" is not supported by sphdvi (GenCase\'s documentation '
                                        "does not say what it does)", 'next="true": the next mk')
        last = self.last_mk[kind]
        if last is None:
            raise self.reader.error(el, f"no mk{kind} set before it", f"a <setmk{kind}> first")
        if last >= 65535:
            raise self.reader.error(el, f"mk{kind} {last} has no next", "an mk below 65535")
        self._set_pen(kind, last + 1)

    def cmd_setmknextbound(self, el):
        self._next_mk(el, "bound")

    def cmd_setmknextfluid(self, el):
        self._next_mk(el, "fluid")

    def cmd_mksave(self, el):
        self.saved_mk = (self.state.kind, self.state.mk)

    def cmd_mkload(self, el):
        if self.saved_mk is None:
            raise self.reader.error(el, "no mk saved", "a <mksave> before <mkload>")
        self._set_pen(*self.saved_mk)

    def cmd_setdrawmode(self, el):
        self.state.mode = self.reader.text_attr(el, "mode", choices=DRAW_MODES).lower()

    def cmd_setactive(self, el):
        self.state.draw_points = self.reader.boolean(el, "drawpoints", self.state.draw_points)
        self.state.draw_shapes = self.reader.boolean(el, "drawshapes", self.state.draw_shapes)
        self.reader.boolean(el, "vtkout", True)

    def cmd_resetdraw(self, el):
        """Back to the initial drawing configuration: no mk selected, ``full`` mode, identity
        matrix, points and shapes active, no line start. Variables, lists,
        the saved stacks and everything drawn so far are kept (GenCase_CaseTemplate.xml lists it
        as a plain state command; nothing there says it touches what was drawn)."""
        self.state = DrawState()
        self.line_begin = None

    def cmd_setfrdrawmode(self, el):
        """GenCase's free drawing: with ``auto="true"`` the shapes that follow get particles off the
        lattice (rings along a cylinder's or a sphere's surface, dp apart: its rule is not published);
        sphdvi draws them on the lattice as without it, and warns. ``auto="false"`` (back to the
        lattice) does nothing."""
        if self.reader.boolean(el, "auto"):
            self.reader.warn(el, "free drawing (auto=\"true\": particles off the lattice, along the shape) is not "
                                 "supported by sphdvi, whose GenCase rule is not published: the shapes that follow are "
                                 "drawn on the lattice, as with auto=\"false\"")

    def cmd_setboxlimitmode(self, el):
        """The limits of the ``<fillbox>`` commands that follow: ``inner`` (GenCase's default)
        fills the nodes at least dp/2 inside the box, ``full`` every node from the one nearest the
        min corner to the one nearest the max corner, as a solid ``<drawbox>`` (GenCase v5.4's record of
        feynman0406/DualSPHysicsGPT CaseSloshingHR: with ``full``, a fill top at 46.5 dp filled the
        row at 47 dp, 21,103 fluid particles). ``<drawbox>`` is not affected."""
        self.state.box_limit = self.reader.text_attr(el, "mode", choices=BOX_LIMIT_MODES).lower()

    # ------------------------------------------------------------ transforms
    def _compose(self, el, m) -> None:
        new = self.state.matrix @ m
        try:
            tf.inverse(new)
        except ValueError as exc:
            raise self.reader.error(el, str(exc), "a non-degenerate transformation") from None
        self.state.matrix = new

    def cmd_move(self, el):
        self._compose(el, tf.translation(self.reader.vec3(el)))

    def cmd_scale(self, el):
        if not any(el.get(n) is not None for n in "xyz"):
            raise self.reader.error(el, "missing scale factors", "x, y and z")
        v = np.array([self.reader.num(el, n, 1.0) for n in "xyz"])
        if np.any(v == 0):
            raise self.reader.error(el, "a scale factor is 0", "non-zero x, y, z")
        self._compose(el, tf.scaling(v))

    def cmd_rotate(self, el):
        ang = self.reader.num(el, "ang")
        axis = self.reader.vec3(el)
        if not np.linalg.norm(axis) > 0:
            raise self.reader.error(el, "rotation axis (x, y, z) is zero", "a non-zero axis")
        self._compose(el, tf.rotation_line(ang, np.zeros(3), axis))     # DualSPHysics's sense

    def cmd_rotateline(self, el):
        self._check(el, {"point"})
        ang = self.reader.num(el, "ang")
        p = self._points(el, exact=2)
        if not np.linalg.norm(p[1] - p[0]) > 0:
            raise self.reader.error(el, "the two points of the line coincide", "distinct points")
        self._compose(el, tf.rotation_line(ang, p[0], p[1]))

    def cmd_matrixreset(self, el):
        self.state.matrix = tf.identity()

    def cmd_matrixsave(self, el):
        self.saved_matrices.append(self.state.matrix.copy())

    def cmd_matrixload(self, el):
        if not self.saved_matrices:
            raise self.reader.error(el, "no matrix saved", "a <matrixsave> before <matrixload>")
        self.state.matrix = self.saved_matrices.pop().copy()

    def cmd_statesave(self, el):
        self.saved_states.append(self.state.copy())

    def cmd_stateload(self, el):
        if not self.saved_states:
            raise self.reader.error(el, "no state saved", "a <statesave> before <stateload>")
        self.state = self.saved_states.pop()

    # ------------------------------------------------------------ points and lines
    def _world(self, pts):
        return tf.apply(self.state.matrix, pts)

    def cmd_drawpoint(self, el):
        self._need_pen(el)
        p = self._world(self.reader.vec3(el)[None, :])
        n = self._paint(el, raster.point_pieces(self.lat, p))
        self._record(el, "point", {"point": p[0].tolist()}, None, False, n)

    def cmd_drawpoints(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._world(self._points(el, least=1))
        n = self._paint(el, raster.point_pieces(self.lat, p))
        self._record(el, "points", _point_summary(p), None, False, n)

    def _draw_polyline(self, el, pts, shape):
        w = self._world(pts)
        segs = np.stack([w[:-1], w[1:]], axis=1)
        n = self._paint(el, raster.segment_pieces(self.lat, segs))
        self._record(el, shape, _point_summary(w), None, False, n)
        self.line_begin = pts[-1]

    def cmd_drawline(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        self._draw_polyline(el, self._points(el, exact=2), "line")

    def cmd_drawlines(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        self._draw_polyline(el, self._points(el, least=2), "lines")

    def cmd_setlinebegin(self, el):
        self.line_begin = self.reader.vec3(el)

    def cmd_drawlineto(self, el):
        self._need_pen(el)
        if self.line_begin is None:
            raise self.reader.error(el, "no line start", "a <setlinebegin> or a line before")
        self._draw_polyline(el, np.array([self.line_begin, self.reader.vec3(el)]), "line")

    # ------------------------------------------------------------ planar surfaces
    def _draw_surface(self, el, tris_local, shape, params=None):
        """Draw open triangles: the surface in full/face/solid modes, the edges in wire mode."""
        tris = self._world(tris_local)
        if self.state.mode == "wire":
            segs = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
            pieces = raster.segment_pieces(self.lat, segs)
        else:
            pieces = raster.triangle_pieces(self.lat, tris)
        n = self._paint(el, pieces)
        p = {"triangles": len(tris)}
        p.update(params or {})
        self._record(el, shape, p, tris, False, n)

    def cmd_drawtriangle(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, exact=3)
        self._draw_surface(el, p[None], "triangle", {"vertices": self._world(p).tolist()})

    def cmd_drawquadri(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, exact=4)
        self._draw_surface(el, np.array([p[[0, 1, 2]], p[[0, 2, 3]]]), "quadri",
                           {"vertices": self._world(p).tolist()})

    def cmd_drawtrianglesstrip(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, least=3)
        tris = np.array([p[[i, i + 1, i + 2]] for i in range(len(p) - 2)])
        self._draw_surface(el, tris, "trianglesstrip")

    def cmd_drawtrianglesfan(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, least=3)
        tris = np.array([p[[0, i, i + 1]] for i in range(1, len(p) - 1)])
        self._draw_surface(el, tris, "trianglesfan")

    def cmd_drawpolygon(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, least=3)
        if len(p) > 256:
            raise self.reader.error(el, f"{len(p)} polygon points", "at most 256 (use "
                                    "<drawtriangles> for big surfaces)")
        tris = shapes.faces_to_triangles(p, [tuple(range(len(p)))])
        if len(tris) == 0:
            raise self.reader.error(el, "the polygon has no area", "at least 3 non-collinear points")
        self._draw_surface(el, tris, "polygon", {"vertices": self._world(p).tolist()})

    def cmd_drawtriangles(self, el):
        self._need_pen(el)
        self._check(el, {"points", "triangles"})
        pts_el = self.reader.child(el, "points", required=True)
        tri_el = self.reader.child(el, "triangles", required=True)
        self._check(pts_el, {"point"})
        self._check(tri_el, {"triangle"})
        pts = self._points(pts_el, least=3)
        kids = self.reader.children(tri_el, "triangle")
        if not kids or len(kids) > MAX_POINTS:
            raise self.reader.error(tri_el, f"{len(kids)} <triangle> elements",
                                    f"1 to {MAX_POINTS}")
        idx = np.array([[self.reader.integer(k, n, lo=0, hi=len(pts) - 1) for n in "xyz"]
                        for k in kids], dtype=np.int64)
        self._draw_surface(el, pts[idx], el.tag[4:])

    cmd_drawfigure = cmd_drawtriangles

    # ------------------------------------------------------------ box
    def _box_extent(self, el):
        """(point, size) from <point> and <size> or <endpoint>; size may be negative."""
        p_el = self.reader.child(el, "point", required=True)
        point = self.reader.vec3(p_el)
        s_el = self.reader.child(el, "size")
        e_el = self.reader.child(el, "endpoint")
        if (s_el is None) == (e_el is None):
            raise self.reader.error(el, "needs exactly one of <size> and <endpoint>",
                                    "<point> with <size> or <endpoint>")
        size = self.reader.vec3(s_el) if s_el is not None else self.reader.vec3(e_el) - point
        # a negative size extends the box the other way
        lo = np.minimum(point, point + size)
        return lo, np.abs(size)

    def _box_fill(self, el):
        """(solid, faces) from <boxfill>; without it the draw mode decides."""
        bf = self.reader.child(el, "boxfill")
        if bf is None:
            solid, surface, wire = self._mode_flags()
            return solid, (list(raster.FACE_AXIS) if surface else []), wire
        text = self.reader.element_text(bf)
        # "a | b" adds faces, "all ^ top" removes them (left to right)
        parts = re.split(r"\s*([|^])\s*", text.strip().lower())
        tokens, ops = parts[0::2], ["|"] + parts[1::2]
        bad = [t for t in tokens if t not in BOX_TOKENS]
        if bad or not text.strip():
            raise self.reader.error(bf, f"invalid boxfill '{text}'",
                                    "solid, all, or faces bottom | top | left | right | front | "
                                    "back, combined with | (add) or ^ (remove)")
        chosen: set = set()
        for op, tok in zip(ops, tokens):
            names = set(raster.FACE_AXIS) if tok == "all" else {tok}
            chosen = chosen | names if op == "|" else chosen - names
        faces = [f for f in raster.FACE_AXIS if f in chosen]
        tokens = chosen
        return "solid" in tokens, faces, False

    def _layers(self, el) -> list[float]:
        """Offsets (in dp, outward positive) of ``<layers vdp="0,1,-0.5*">``; [0] without it or
        with an empty ``vdp``.

        A trailing ``*`` (GenCase: also save that layer's shape) is accepted and ignored.
        """
        lay = self.reader.child(el, "layers")
        if lay is None:
            return [0.0]
        text = self.reader.text_attr(lay, "vdp")
        if not text.strip():
            return [0.0]        # GenCase v5.4 draws the shape once (yupengxiang/DualSPHysics F2_SLOT)
        out = []
        for tok in text.split(","):
            tok = tok.strip().rstrip("*").strip()
            try:
                v = self.vars.number(tok[1:] if tok.startswith("#") else tok)
            except ExpressionError:
                raise self.reader.error(lay, f"vdp={text!r} is not valid",
                                        "numbers separated by commas, e.g. vdp=\"0,1,2\"") from None
            if abs(v) > 1e6:
                raise self.reader.error(lay, f"layer offset {v:g} dp", "at most 1e6 dp")
            out.append(v)
        if not out or len(out) > 1000:
            raise self.reader.error(lay, f"{len(out)} layers", "1 to 1000 layers")
        return out

    def cmd_drawbox(self, el):
        self._need_pen(el)
        self._check(el, {"boxfill", "point", "size", "endpoint", "angles", "layers"})
        point, size = self._box_extent(el)
        ang_el = self.reader.child(el, "angles")
        angles = self.reader.vec3(ang_el) if ang_el is not None else None
        solid, faces, wire = self._box_fill(el)
        for layer in self._layers(el):
            grow = layer * self.lat.dp
            if np.any(size + 2 * grow < 0):
                self.reader.warn(el, f"layer {layer:g} shrinks the box to nothing; skipped")
                continue
            pieces, params, tris = shapes.draw_box(self.lat, self.state.matrix, point, size,
                                                   angles, solid=solid, faces=faces, wire=wire,
                                                   grow=grow)
            params["faces"] = faces
            params["layer"] = layer
            n = self._paint(el, pieces)
            self._record(el, "box", params, tris, solid, n)

    # ------------------------------------------------------------ curved shapes
    def _curved_flags(self):
        """(solid, shell): full and solid fill the volume; face and wire draw the inner shell."""
        mode = self.state.mode
        return mode in ("full", "solid"), mode in ("face", "wire")

    def _curved_reach(self, solid: bool) -> float:
        """How far beyond its surface a closed sphere, ellipsoid or cylinder fills in ``full``
        mode (world units): ``shapes.CURVED_FULL_REACH`` dp; 0 in the other modes."""
        return shapes.CURVED_FULL_REACH * self.lat.dp if solid and self.state.mode == "full" else 0.0

    def _layers_unsupported(self, el):
        lay = self.reader.child(el, "layers")
        if lay is not None:
            raise self.reader.error(lay, f"<layers> of <{el.tag}> is not supported by sphdvi",
                                    "one shape per layer")

    def cmd_drawsphere(self, el):
        self._need_pen(el)
        self._check(el, {"point", "layers"})
        r0 = self.reader.num(el, "radius", positive=True)
        c = self._points(el, exact=1)[0]
        solid, shell = self._curved_flags()
        for layer in self._layers(el):
            r = r0 + layer * self.lat.dp
            if not r > 0:
                self.reader.warn(el, f"layer {layer:g} gives radius {r:g}; skipped")
                continue
            pieces, params, tris = shapes.draw_sphere(self.lat, self.state.matrix, c, r,
                                                      solid=solid, shell=shell,
                                                      reach=self._curved_reach(solid))
            params["layer"] = layer
            n = self._paint(el, pieces)
            self._record(el, "sphere", params, tris, solid, n)

    def cmd_drawellipsoid(self, el):
        self._need_pen(el)
        self._check(el, {"point", "center", "radius", "size", "layers"})
        self._layers_unsupported(el)
        solid, shell = self._curved_flags()
        radii_el = self.reader.child(el, "radius")
        if radii_el is None:
            radii_el = self.reader.child(el, "size")
        frame = None
        if radii_el is not None:
            c_el = self.reader.child(el, "center")
            c = self.reader.vec3(c_el) if c_el is not None else self._points(el, exact=1)[0]
            radii = self.reader.vec3(radii_el)
            if not np.all(radii > 0):
                raise self.reader.error(radii_el, "semi-axes must be positive", "x, y, z > 0")
        else:
            pts = self._points(el, exact=2)
            r = self.reader.num(el, "radius", positive=True)
            try:
                c, frame, radii = shapes.foci_ellipsoid(pts[0], pts[1], r)
            except ValueError as exc:
                raise self.reader.error(el, str(exc), "radius > half the distance between the "
                                        "two focus points") from None
        pieces, params, tris = shapes.draw_ellipsoid_axes(self.lat, self.state.matrix, c, radii,
                                                          solid=solid, shell=shell, frame=frame,
                                                          reach=self._curved_reach(solid))
        n = self._paint(el, pieces)
        self._record(el, "ellipsoid", params, tris, solid, n)

    def cmd_drawcylinder(self, el):
        self._need_pen(el)
        self._check(el, {"point", "layers"})
        r0 = self.reader.num(el, "radius", positive=True)
        p = self._points(el, exact=2)
        mask = self._mask(el)
        self._warn_missing_faces(el, mask, 3)
        solid, shell = self._curved_flags()
        if any(1 <= f <= 3 for f in mask):
            # an open cylinder (a cover or the tube left out) has no inside: its faces only
            solid = self._open_shape_flags(el, mask, 3)[0]
            shell = self.state.mode != "solid"
        length = float(np.linalg.norm(p[1] - p[0]))
        if not length > 0:
            raise self.reader.error(el, "the two points of the cylinder axis coincide",
                                    "two distinct axis points")
        u = (p[1] - p[0]) / length
        for layer in self._layers(el):
            grow = layer * self.lat.dp
            r = r0 + grow
            if not r > 0 or not length + 2 * grow > 0:
                self.reader.warn(el, f"layer {layer:g} shrinks the cylinder to nothing; skipped")
                continue
            # a layer widens the radius and moves both covers outwards by the same offset
            pieces, params, tris = shapes.draw_cylinder(
                self.lat, self.state.matrix, p[0] - grow * u, p[1] + grow * u, r,
                solid=solid, shell=shell, mask=mask, reach=self._curved_reach(solid))
            params["mask"] = sorted(mask)
            params["layer"] = layer
            n = self._paint(el, pieces)
            self._record(el, "cylinder", params, tris, solid, n)

    # ------------------------------------------------------------ polyhedra
    def _draw_polyhedron(self, el, verts, faces, shape):
        mask = self._mask(el)
        self._warn_missing_faces(el, mask, len(faces))
        solid, surface, wire = self._open_shape_flags(el, mask, len(faces))
        pieces, params, tris = shapes.draw_polyhedron(self.lat, self.state.matrix, verts, faces,
                                                      solid=solid, surface=surface, wire=wire,
                                                      mask=mask)
        params["mask"] = sorted(mask)
        n = self._paint(el, pieces)
        self._record(el, shape, params, tris, solid, n)

    def cmd_drawprism(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, least=6)
        if len(p) % 2 or len(p) > 2 * 64:
            raise self.reader.error(el, f"{len(p)} points", "an even number (base then top), "
                                    "6 or 8 typically")
        self._draw_polyhedron(el, p, shapes.prism_faces(len(p) // 2), "prism")

    def cmd_drawpyramid(self, el):
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, least=4)
        if len(p) > 65:
            raise self.reader.error(el, f"{len(p)} points", "apex + at most 64 base points")
        self._draw_polyhedron(el, p, shapes.pyramid_faces(len(p) - 1), "pyramid")

    def cmd_drawbeach(self, el):
        """GenCase's ``<drawbeach mask>``: a prism whose cross-section is the closed polygon of the
        profile points (one x-z plane; GenCase: "the lateral points that form the profile of the
        beach"), extruded along y. Faces and ``mask`` are those of ``<drawprism>``: 1 and 2 the
        two profile polygons, 3... the sides from points 1-2 on, the last one closing the profile
        (XML guide: ``mask="128"``, face 8, hides the closing top line of its 6-point beach; the
        v5.4 examples hide 1|2 (CasePeriodicity) and 1|2|5 (CaseBowling, the closing side of a
        3-point ramp)); an open beach is hollow in ``full`` mode like a masked prism.

        How far a beach extends in y is not documented: in a 2D case it crosses the plane
        y = posy whatever the y of its points (CasePeriodicity and CaseBowling give y = 1 and 2
        for planes y = 0 and 1), its polygons 1 dp either side; a 3D case is refused.
        """
        self._need_pen(el)
        self._check(el, {"point"})
        p = self._points(el, least=3)
        if len(p) > 64:
            raise self.reader.error(el, f"{len(p)} points", "3 to 64 profile points")
        if not self.lat.is2d:
            raise self.reader.error(el, "<drawbeach> in a 3D case is not supported by sphdvi "
                                        "(GenCase's documentation does not say how far a beach "
                                        "extends in y)", "a 2D case (pointmin y = pointmax y), "
                                    "or a <drawprism> with both profiles written out")
        tol = 1e-9 * max(1.0, float(np.max(np.abs(p))))
        if np.ptp(p[:, 1]) > tol:
            raise self.reader.error(el, f"the profile points have different y "
                                        f"({p[:, 1].min():g} to {p[:, 1].max():g})",
                                    "a beach profile in one x-z plane (the same y for every point)")
        m = self.state.matrix
        if max(abs(m[1, 0]), abs(m[1, 2]), abs(m[0, 1]), abs(m[2, 1])) > 1e-12 * np.abs(m[:3, :3]).max():
            raise self.reader.error(el, "<drawbeach> under a transformation that tilts the y axis "
                                        "is not supported by sphdvi",
                                    "moves, scales and rotations about y only before it")
        dp, posy = self.lat.dp, float(self.lat.pointmin[1])
        ya, yb = ((posy - dp - m[1, 3]) / m[1, 1], (posy + dp - m[1, 3]) / m[1, 1])
        verts = shapes.beach_prism(p, min(ya, yb), max(ya, yb))
        self._draw_polyhedron(el, verts, shapes.prism_faces(len(p)), "beach")

    def cmd_drawextrude(self, el):
        """GenCase's ``<drawextrude closed="false">``: the open polyline of the ``<point>``
        elements swept by the vector ``<extrude>`` (XML guide: "draws an extruded line of points
        to create a 3-D shape"), a surface of one quadrilateral per segment, drawn like the other
        open surfaces (``drawtrianglesstrip``): the planar-surface rule in ``full``, ``face`` and
        ``solid`` modes, its edges in ``wire`` mode. Repeated consecutive points are dropped.

        ``<layers vdp>`` draws it once per offset, moved offset*dp along the face normal
        (P_i+1 - P_i) x extrude, i.e. outwards by GenCase's counter-clockwise rule, like the
        outward ``<layers>`` of a box: in CaseStillWedge and CaseWaveTank (mDBC, v5.4) the fluid
        lies on that side, layers 0, -1, -2 are the wall and +0.5 the boundary for the normals.
        A layer is the mitred parallel curve, its ends not lengthened and the sweep not widened
        along the extrusion (the docs leave both open; the 2D examples do not depend on the
        latter). ``closed="true"`` (undocumented: caps? an inside?) is refused; ``closed``
        absent means false, like GenCase's other boolean attributes (autofill, advanced).
        """
        self._need_pen(el)
        self._check(el, {"point", "extrude", "layers"})
        if self.reader.boolean(el, "closed", False):
            raise self.reader.error(el, "<drawextrude closed=\"true\"> is not supported by sphdvi "
                                        "(GenCase's documentation does not say how a closed "
                                        "extrusion is drawn)",
                                    "closed=\"false\" (an open polyline), or a <drawprism>")
        pts = self._points(el, least=2)
        vec = self.reader.vec3(self.reader.child(el, "extrude", required=True))
        keep = np.r_[True, np.any(pts[1:] != pts[:-1], axis=1)]
        pts = pts[keep]
        if len(pts) < 2:
            raise self.reader.error(el, "all the points coincide", "at least 2 distinct points")
        elen = float(np.linalg.norm(vec))
        if not elen > 0 or not np.isfinite(elen):
            raise self.reader.error(el, f"the <extrude> vector {vec.tolist()} is zero",
                                    "a non-zero extrusion vector")
        seg = pts[1:] - pts[:-1]
        flat = np.linalg.norm(np.cross(seg, vec), axis=1) <= 1e-9 * np.linalg.norm(seg, axis=1) * elen
        if flat.any():
            k = int(np.argmax(flat))
            raise self.reader.error(el, f"the segment from {pts[k].tolist()} to {pts[k + 1].tolist()} "
                                        "is parallel to the <extrude> vector (it sweeps no area)",
                                    "points whose segments are not parallel to <extrude>")
        for layer in self._layers(el):
            pieces, params, tris = shapes.draw_extrude(
                self.lat, self.state.matrix, pts, vec, wire=self.state.mode == "wire",
                offset=layer * self.lat.dp)
            params["layer"] = layer
            n = self._paint(el, pieces)
            self._record(el, "extrude", params, tris, False, n)

    # ------------------------------------------------------------ mesh files
    def _file_transform(self, el, tags=("drawscale", "drawrotate", "drawmove"),
                        angles=("angx", "angy", "angz")) -> np.ndarray:
        """The matrix of a file's scale, rotation (degrees about x, y, z) and move children
        (``<drawscale>``, ``<drawrotate angx angy angz>``, ``<drawmove>``; a bathymetry's
        ``<scale>``, ``<rotate x y z>``, ``<move>``), applied in that order (scale first)."""
        local = tf.identity()
        sc, rot, mv = (self.reader.child(el, t) for t in tags)
        if sc is not None:
            s = np.array([self.reader.num(sc, n, 1.0) for n in "xyz"])
            if np.any(s == 0):
                raise self.reader.error(sc, "a scale factor is 0", "non-zero x, y, z")
            local = tf.scaling(s) @ local
        if rot is not None:
            local = tf.rotation_xyz([self.reader.num(rot, n, 0.0) for n in angles]) @ local
        if mv is not None:
            local = tf.translation(self.reader.vec3(mv)) @ local
        return local

    def _draw_mesh(self, el, tris, shape: str, params: dict, solid: bool = False) -> None:
        """Draw world triangles as a surface (and with ``solid`` their inside, by parity) and
        record them: mesh files and bathymetries."""
        pieces = raster.triangle_pieces(self.lat, tris, surface=True, solid=solid)
        n = self._paint(el, pieces)
        params.update({"triangles": int(len(tris)), "min": tris.reshape(-1, 3).min(axis=0).tolist(),
                       "max": tris.reshape(-1, 3).max(axis=0).tolist()})
        self._record(el, shape, params, tris, solid, n)

    def _draw_file(self, el, kind):
        from . import meshfile
        self._need_pen(el)
        self._check(el, {"drawmove", "drawrotate", "drawscale", "depth", "polyselec"})
        for tag in ("depth", "polyselec"):
            if self.reader.child(el, tag) is not None:
                raise self.reader.error(self.reader.child(el, tag),
                                        f"<{tag}> is not supported by sphdvi", "a plain mesh file")
        if self.reader.boolean(el, "advanced", False):
            raise self.reader.error(el, "advanced=\"true\" is not supported by sphdvi",
                                    "advanced=\"false\"")
        path = self.reader.resolve_path(el, "file")
        autofill = self.reader.boolean(el, "autofill", False)
        self.reader.boolean(el, "reverse", False)
        local = self._file_transform(el)
        try:
            tris_local = meshfile.read_triangles(path, kind)
        except (meshfile.MeshError, OSError) as exc:
            raise self.reader.error(el, f"cannot read '{os.path.basename(path)}': {exc}",
                                    f"a valid {kind.upper()} triangle mesh") from None
        tris = tf.apply(self.state.matrix @ local, tris_local)
        self._draw_mesh(el, tris, "mesh", {"file": path, "autofill": autofill}, solid=autofill)

    def cmd_drawfilestl(self, el):
        self._draw_file(el, "stl")

    def cmd_drawfileply(self, el):
        self._draw_file(el, "ply")

    def cmd_drawfilevtk(self, el):
        self._draw_file(el, "vtk")

    def cmd_drawfilevtm(self, el):
        """A VTK multiblock file (.vtm): the triangles of all its blocks, as ``drawfilevtk``."""
        self._draw_file(el, "vtm")

    # ------------------------------------------------------------ bathymetries
    def cmd_drawfilecsv(self, el):
        """``<drawfilecsv file mode="bathymetry">``: a table of heights (GenCase_Bathymetry.csv)
        drawn as a surface, two triangles a cell, after ``<drawscale>``, ``<drawrotate>``,
        ``<drawmove>``. Other modes are not documented and are refused."""
        from . import bathymetry
        self._need_pen(el)
        self._check(el, {"drawmove", "drawrotate", "drawscale"})
        mode = self.reader.text_attr(el, "mode", choices={"bathymetry"})
        path = self.reader.resolve_path(el, "file")
        xs, ys, z = bathymetry.read_height_table(path)
        tris = tf.apply(self.state.matrix @ self._file_transform(el), bathymetry.grid_triangles(xs, ys, z))
        self._draw_mesh(el, tris, "bathymetry", {"file": path, "mode": mode.lower(), "grid": [len(xs), len(ys)]})

    def _xy(self, el, tag: str, positive: bool = False):
        c = self.reader.child(el, tag, required=True)
        return np.array([self.reader.num(c, n, positive=positive) for n in "xy"])

    def _bathymetry_points(self, zp):
        """The points of ``<zpoints file>`` after its ``<scale>``, ``<rotate x y z>`` (degrees) and
        ``<move>`` (in that order), and kept inside its ``<selection>`` rectangle in (x, y)."""
        from . import bathymetry
        self.reader.check_children(zp, {"move", "rotate", "scale", "selection", "rem"}, "child element")
        pts = bathymetry.read_points(self.reader.resolve_path(zp, "file"))
        pts = tf.apply(self._file_transform(zp, ("scale", "rotate", "move"), "xyz"), pts)
        sel = self.reader.child(zp, "selection")
        if sel is not None:
            self.reader.check_children(sel, {"point", "size", "rem"}, "child element")
            lo, size = self._xy(sel, "point"), self._xy(sel, "size", positive=True)
            inside = np.all((pts[:, :2] >= lo) & (pts[:, :2] <= lo + size), axis=1)
            if np.count_nonzero(inside) < 3:
                raise self.reader.error(sel, f"{np.count_nonzero(inside)} of the {len(pts)} points "
                                             "lie inside the selection",
                                        "a rectangle holding at least 3 points")
            pts = pts[inside]
        return pts

    def _bathymetry_expands(self, ex):
        """``<expands>``: per side (xmin, xmax, ymin, ymax) the ramps (size, z), (size2, z2)."""
        from . import bathymetry
        self.reader.check_children(ex, set(bathymetry.SIDES) | {"rem"}, "child element")
        out = []
        for side in bathymetry.SIDES:
            c = self.reader.child(ex, side)
            if c is None:
                continue
            segs = []
            for k in ("", "2"):
                if self.reader.has(c, "size" + k):
                    size = self.reader.num(c, "size" + k)
                    if not size > 0:
                        raise self.reader.error(c, f"size{k}={size:g}: sphdvi widens a bed only "
                                                   "(GenCase's documentation does not say what a "
                                                   "size <= 0 does)", "a length > 0")
                    segs.append((size, self.reader.num(c, "z" + k, None)))
                elif self.reader.has(c, "z" + k):
                    raise self.reader.error(c, f"z{k} without size{k}", f"size{k} with z{k}")
            if segs:
                out.append((side, segs))
        return out

    def _bathymetry_source(self, el):
        """(``<zpoints>``, ``<grid>``, grid by dp?) of a ``<drawbathymetry>``, checked: the points
        come from ``<zpoints file>`` or from ``<grid file>``, never both; ``<grid>`` has dp or
        file; ``<initdomain>``/``<expands>`` need dp; ``<periodicx>``/``<periodicy>`` are refused."""
        zp = self.reader.child(el, "zpoints")
        grid = self.reader.child(el, "grid")
        if grid is None:
            if zp is None:
                raise self.reader.error(el, "no <zpoints file> and no <grid file>",
                                        "the bed's points in one of them")
            return zp, None, False
        self.reader.check_children(grid, {"initdomain", "expands", "periodicx", "periodicy",
                                          "finalmove", "rem"}, "child element")
        for tag in ("periodicx", "periodicy"):
            if self.reader.child(grid, tag) is not None:
                raise self.reader.error(self.reader.child(grid, tag),
                                        f"<{tag}> is not supported by sphdvi (GenCase's documentation "
                                        "does not say how it ramps the bed to make it periodic)",
                                        "a bed without <periodicx>/<periodicy>")
        with_dp, with_file = self.reader.has(grid, "dp"), self.reader.has(grid, "file")
        if with_dp == with_file:
            raise self.reader.error(grid, "both dp and file" if with_dp else "neither dp nor file",
                                    "dp (a grid over <zpoints>) or file (the grid's points)")
        if zp is None and with_dp:
            raise self.reader.error(el, "no <zpoints file> and no <grid file>",
                                    "the bed's points in one of them")
        if zp is not None and with_file:
            raise self.reader.error(grid, "<grid file> beside <zpoints>", "one source of points")
        if with_file and any(self.reader.child(grid, t) is not None for t in ("initdomain", "expands")):
            raise self.reader.error(grid, "<initdomain> and <expands> need a grid of spacing dp",
                                    "<grid dp> over <zpoints>")
        return zp, grid, with_dp

    def cmd_drawbathymetry(self, el):
        """``<drawbathymetry>``: a bed from scattered points (see :mod:`.bathymetry`). Without
        ``<grid>`` the points' Delaunay triangulation is drawn; ``<grid dp>`` resamples it on a
        regular grid (over ``<initdomain>``, else over the points' extent), widened by
        ``<expands>`` and moved by ``<finalmove>``; ``<grid file>`` gives the grid's points
        directly. ``<periodicx>``/``<periodicy>`` are refused (their ramps are not documented)."""
        from . import bathymetry
        self._need_pen(el)
        self._check(el, {"zpoints", "grid", "savepoints", "savegrid"})
        zp, grid, with_dp = self._bathymetry_source(el)
        params = {}
        try:
            if zp is None:
                pts = bathymetry.read_points(self.reader.resolve_path(grid, "file"))
            else:
                pts = self._bathymetry_points(zp)
            tri_idx = bathymetry.delaunay(pts)
            if with_dp:
                tris, params = self._bathymetry_grid(grid, pts, tri_idx)
            else:
                tris = pts[tri_idx]
            if grid is not None and self.reader.child(grid, "finalmove") is not None:
                tris = tris + self.reader.vec3(self.reader.child(grid, "finalmove"))
        except bathymetry.BathymetryError as exc:
            raise self.reader.error(el, str(exc), "a bed of points spanning an area") from None
        params["points"] = int(len(pts))
        self._save_bathymetry(el, pts, tris)
        self._draw_mesh(el, tf.apply(self.state.matrix, tris), "bathymetry", params)

    def _bathymetry_grid(self, grid, pts, tri_idx):
        from . import bathymetry
        dp = self.reader.num(grid, "dp", positive=True)
        dom = self.reader.child(grid, "initdomain")
        if dom is not None:
            self.reader.check_children(dom, {"point", "size", "rem"}, "child element")
            lo, size = self._xy(dom, "point"), self._xy(dom, "size", positive=True)
        else:
            lo = pts[:, :2].min(axis=0)
            size = pts[:, :2].max(axis=0) - lo
        xs, ys = bathymetry.grid_axis(lo[0], size[0], dp), bathymetry.grid_axis(lo[1], size[1], dp)
        bathymetry.check_grid_size(len(xs), len(ys))
        z, outside = bathymetry.resample(pts, tri_idx, xs, ys)
        if outside:
            self.reader.warn(grid, f"{outside} of the {z.size} grid nodes lie outside the points' "
                                   "convex hull: they take the height of the nearest point")
        ex = self.reader.child(grid, "expands")
        if ex is not None:
            for side, segs in self._bathymetry_expands(ex):
                xs, ys, z = bathymetry.expand(xs, ys, z, side, segs, dp)
            bathymetry.check_grid_size(len(xs), len(ys))
        return bathymetry.grid_triangles(xs, ys, z), {"grid": [len(xs), len(ys)], "dp": dp,
                                                      "outside": outside}

    def _save_bathymetry(self, el, pts, tris) -> None:
        """``<savepoints file="true">`` and ``<savegrid file="true">``: the bed's points and its
        triangles (before the current matrix) as ``<casename>_Bathymetry[N]_Points.vtk`` and
        ``..._Grid.vtk`` in the output folder (N from the second ``<drawbathymetry>`` on)."""
        self.bathymetries += 1
        tag = "" if self.bathymetries == 1 else str(self.bathymetries)
        for child, suffix in (("savepoints", "Points"), ("savegrid", "Grid")):
            c = self.reader.child(el, child)
            if c is None or not self.reader.boolean(c, "file", False) or self.outdir is None:
                continue
            path = os.path.join(self.outdir, f"{self.casename}_Bathymetry{tag}_{suffix}.vtk")
            if suffix == "Points":
                write_points(path, pts)
            else:
                write_shapes(path, [{"triangles": tris, "mk": -1, "fluid": False}], "vtk")
            self.messages.append(f"bathymetry {suffix.lower()}: {path}")

    # ------------------------------------------------------------ fills
    def _fill_modes(self, el):
        mf = self.reader.child(el, "modefill")
        if mf is None:
            return {"void"}
        tokens = {t.strip().lower() for t in self.reader.element_text(mf).split("|") if t.strip()}
        if not tokens or tokens - FILL_TOKENS:
            raise self.reader.error(mf, f"invalid modefill '{self.reader.element_text(mf)}'",
                                    "void, border, fluid, bound joined by |")
        if tokens == {"border"}:
            tokens = {"void"}
        return tokens

    def _fill(self, el, seed, modes, lo, hi, shape, allowed=None):
        self._need_pen(el)
        mkfluid = self.reader.integer(el, "mkfluid", None, lo=0)
        mkbound = self.reader.integer(el, "mkbound", None, lo=0)
        code = self._code()
        labels = self.canvas.labels
        fillable = np.zeros(len(labels), dtype=np.bool_)
        fillable[0] = "void" in modes
        for c, (is_fluid, mk) in enumerate(labels[1:], start=1):
            if is_fluid:
                fillable[c] = "fluid" in modes and (mkfluid is None or mk == mkfluid)
            else:
                fillable[c] = "bound" in modes and (mkbound is None or mk == mkbound)
        s = np.array([round_idx(v) for v in self.lat.to_index(seed)], dtype=np.int64)
        r = self.lat.clip_range(lo, hi)
        if r is not None:
            r = (np.asarray(r[0], dtype=np.int64), np.asarray(r[1], dtype=np.int64))
            shape_r = tuple(int(v) for v in r[1] - r[0] + 1)
            if allowed is None:    # the whole box (seed_fill's empty mask)
                allowed_r = np.zeros((0, 0, 0), dtype=np.bool_)
            else:   # ``allowed`` covers lo..hi: its part inside the lattice
                off = r[0] - np.asarray(lo, dtype=np.int64)
                allowed_r = np.ascontiguousarray(allowed[tuple(slice(int(o), int(o) + n)
                                                               for o, n in zip(off, shape_r))])
        n = 0
        if (r is None or np.any(s < r[0]) or np.any(s > r[1])
                or (allowed_r.size and not allowed_r[tuple(int(v) for v in s - r[0])])):
            self.reader.warn(el, "the seed point is outside the lattice (or the fill box); "
                                 "nothing filled")
        elif not self.state.draw_points:
            pass
        else:
            from .kernels import seed_fill
            n = int(seed_fill(self.canvas.codes, fillable, s, r[0], r[1], code, allowed_r))
            if n == 0:
                self.reader.warn(el, "the seed node is not of a kind listed in <modefill>; "
                                     "nothing filled")
        self._record(el, shape, {"seed": seed.tolist(), "modes": sorted(modes)}, None, False, n)

    def cmd_fillpoint(self, el):
        self._check(el, {"modefill"})
        seed = self._world(self.reader.vec3(el)[None])[0]
        big = 2**40
        self._fill(el, seed, self._fill_modes(el), [-big] * 3, [big] * 3, "fillpoint")

    def cmd_fillvoidpoint(self, el):
        self._check(el, set())
        seed = self._world(self.reader.vec3(el)[None])[0]
        big = 2**40
        self._fill(el, seed, {"void"}, [-big] * 3, [big] * 3, "fillpoint")

    def _turned_box_nodes(self, el, point, size, inner: bool):
        """(lo, hi, allowed) of a box command drawn under a rotation (``<fillbox>``,
        ``<redrawbox>``, ``<redrawnearbox>``): the nodes of a solid ``<drawbox>`` over the turned
        box (the box widened by dp/2 along its own axes), or with ``inner`` those at least dp/2
        inside it; in a 2D case the box's own y extent is widened by dp/2 either way (the plane
        must lie in it, as for drawbox). None when no node is in it."""
        m = self.state.matrix
        scale = tf.uniform_scale(m)
        if scale is None:
            raise self.reader.error(el, f"<{el.tag}> under a non-uniform scale or a shear is not "
                                        "supported by sphdvi", "a rotation, a move and a uniform scale")
        margin = 0.5 * self.lat.dp / scale
        grow = np.full(3, -margin if inner else margin)
        if self.lat.is2d:
            grow[1] = margin
        tol = 1e-9 * max(float(np.abs(size).max()), self.lat.dp / scale)
        qlo, qhi = point - grow - tol, point + size + grow + tol
        if np.any(qhi < qlo):
            return None

        def inside(qx, qy, qz):
            return [(q >= qlo[a]) & (q <= qhi[a]) for a, q in enumerate((qx, qy, qz))]
        pieces = raster.analytic_pieces(self.lat, m, qlo, qhi, inside, solid=True, shell_faces=())
        if not pieces:
            return None
        lo = np.min([p.lo for p in pieces], axis=0)
        hi = np.max([p.lo + np.array(p.mask.shape) - 1 for p in pieces], axis=0)
        allowed = np.zeros(tuple(int(v) for v in hi - lo + 1), dtype=np.bool_)
        for p in pieces:
            allowed[tuple(slice(int(a), int(a) + n) for a, n in zip(p.lo - lo, p.mask.shape))] |= p.mask
        return lo, hi, allowed

    def cmd_fillbox(self, el):
        self._check(el, {"modefill", "point", "size", "endpoint"})
        seed = self._world(self.reader.vec3(el)[None])[0]
        point, size = self._box_extent(el)
        if not tf.is_axis_aligned(self.state.matrix):
            limit = self._turned_box_nodes(el, point, size, inner=self.state.box_limit != "full")
            if limit is None:
                self.reader.warn(el, "the fill box holds no node; nothing filled")
                self._record(el, "fillbox", {"seed": seed.tolist()}, None, False, 0)
                return
            lo, hi, allowed = limit
            self._fill(el, seed, self._fill_modes(el), lo, hi, "fillbox", allowed)
            return
        corners = self._world(np.array([point, point + size]))
        a = self.lat.to_index(corners.min(axis=0))
        b = self.lat.to_index(corners.max(axis=0))
        # GenCase fills only the nodes lying at least dp/2 inside the box (a node on the box's
        # face, or closer than dp/2 to it, stays void): one node layer less than a solid
        # <drawbox> over the same box at a face on the lattice. GenCase's outputs, all at the
        # box's top (the free surface): WallRegAwas2 (top 1/3 dp above a node: 21,457 fluid),
        # GenericWaveTank and FtSloshing (top on a node: 97,122 and 5,345). The other faces
        # are taken alike (no output tells them apart: walls stop those fills); exactly dp/2
        # inside counts as inside.
        # <setboxlimitmode mode="full"> fills the box of a solid <drawbox> instead.
        if self.state.box_limit == "full":
            lo = [round_idx(v) for v in a]
            hi = [round_idx(v) for v in b]
        else:
            lo = [ceil_idx(v + 0.5) for v in a]
            hi = [floor_idx(v - 0.5) for v in b]
        if self.lat.is2d:
            lo[1] = hi[1] = 0
        self._fill(el, seed, self._fill_modes(el), lo, hi, "fillbox")

    # ------------------------------------------------------------ redraw
    def _redraw_box_range(self, el):
        """(lo, hi, within) of the nodes of a redraw command's box (those of a solid
        ``<drawbox>``: from the node nearest the min corner to the node nearest the max corner;
        under a rotation ``within`` marks those of the turned box in lo..hi, else it is None),
        or of the whole lattice without a box; None when the box misses the lattice."""
        if el.tag.endswith("box") and not tf.is_axis_aligned(self.state.matrix):
            point, size = self._box_extent(el)
            return self._turned_box_nodes(el, point, size, inner=False)
        if el.tag.endswith("box"):
            point, size = self._box_extent(el)
            corners = self._world(np.array([point, point + size]))
            lo = [round_idx(v) for v in self.lat.to_index(corners.min(axis=0))]
            hi = [round_idx(v) for v in self.lat.to_index(corners.max(axis=0))]
        else:
            lo, hi = [0, 0, 0], [n - 1 for n in self.lat.shape]
        if self.lat.is2d:
            lo[1] = hi[1] = 0
        r = self.lat.clip_range(lo, hi)
        return None if r is None else (r[0], r[1], None)

    def _redraw_label(self, el, kind_attr: str | None, mk_attr: str | None):
        """(kinds, mk) named by a redraw command: ``mkfluid``/``mkbound`` (redraw, redrawbox;
        ``kind_attr`` None), or the attributes ``kind_attr`` (void, fluid, bound joined by |) and
        ``mk_attr`` (redrawnear: targettp/targetmk, bordertp/bordermk)."""
        if kind_attr is None:
            mkfluid = self.reader.integer(el, "mkfluid", None, lo=0)
            mkbound = self.reader.integer(el, "mkbound", None, lo=0)
            if mkfluid is not None and mkbound is not None:
                raise self.reader.error(el, "names both mkfluid and mkbound", "one of them, or neither")
            if mkfluid is not None:
                return {"fluid"}, mkfluid
            if mkbound is not None:
                return {"bound"}, mkbound
            return {"void", "fluid", "bound"}, None
        text = self.reader.text_attr(el, kind_attr)
        kinds = {t.strip().lower() for t in text.split("|") if t.strip()}
        if not kinds or kinds - {"void", "fluid", "bound"}:
            raise self.reader.error(el, f"{kind_attr}={text!r} is not recognised",
                                    "void, fluid or bound (joined by |)")
        return kinds, self.reader.integer(el, mk_attr, None, lo=0)

    def _redraw_record(self, el, params: dict, n: int, what: str) -> None:
        """Recorded like a shape; ``redraws`` tells a floating body's analytic mass (gencase)
        that nodes drawn before may have changed label. A redraw that changes no node is warned
        about (``what`` says what it looked for): a label misspelt or not drawn yet."""
        self._record(el, el.tag, params, None, False, n)
        self.primitives[-1]["redraws"] = True
        if n == 0 and self.state.draw_points and params.get("times", 1) > 0:
            where = " within its box" if el.tag.endswith("box") else ""
            self.reader.warn(el, f"this <{el.tag}> changed no node: {what}{where}")

    def cmd_redraw(self, el):
        """``<redraw [mkfluid|mkbound]>``: every node holding that label (every node, void
        included, without one) takes the current pen."""
        self._need_pen(el)
        self._check(el, {"point", "size", "endpoint"} if el.tag == "redrawbox" else set())
        kinds, mk = self._redraw_label(el, None, None)
        r = self._redraw_box_range(el)
        n = 0
        if r is not None and self.state.draw_points:
            code = self._code()     # first: it may add the pen's label to the table
            n = redraw_kernels.redraw(self.canvas.codes,
                                      redraw_kernels.label_selection(self.canvas.labels, kinds, mk),
                                      r[0], r[1], code, within=r[2])
        what = ("every node already holds the pen's label" if mk is None else
                f"no node holds mk{'fluid' if 'fluid' in kinds else 'bound'} {mk} (other than the pen's)")
        self._redraw_record(el, {"kinds": sorted(kinds), "mk": mk}, n, what)

    cmd_redrawbox = cmd_redraw

    def cmd_redrawnear(self, el):
        """``<redrawnear times targettp targetmk bordertp bordermk>``: ``times`` passes, each
        giving the current pen to the target nodes with a border node among their 26 neighbours
        (8 in 2D)."""
        self._need_pen(el)
        allowed = {"dirfilter"} | ({"point", "size", "endpoint"} if el.tag == "redrawnearbox" else set())
        self._check(el, allowed)
        times = self.reader.integer(el, "times", 1, lo=0, hi=1_000_000)
        tkinds, tmk = self._redraw_label(el, "targettp", "targetmk")
        bkinds, bmk = self._redraw_label(el, "bordertp", "bordermk")
        df = self.reader.child(el, "dirfilter")
        if df is not None and self.reader.element_text(df).strip().lower() != "all":
            raise self.reader.error(df, f"<dirfilter>{self.reader.element_text(df)}</dirfilter> is not "
                                        "supported by sphdvi (GenCase's direction rule is not documented)",
                                    "no <dirfilter>, or all")
        r = self._redraw_box_range(el)
        n = 0
        if r is not None and self.state.draw_points and times > 0:
            code = self._code()     # first: it may add the pen's label to the table
            labels = self.canvas.labels
            n = redraw_kernels.redraw_near(self.canvas.codes,
                                           redraw_kernels.label_selection(labels, tkinds, tmk),
                                           redraw_kernels.label_selection(labels, bkinds, bmk),
                                           times, r[0], r[1], code, within=r[2])
        def named(kinds, mk):
            return " or ".join(sorted(kinds)) + ("" if mk is None else f" mk {mk}")
        self._redraw_record(el, {"times": times, "target": sorted(tkinds), "targetmk": tmk,
                                 "border": sorted(bkinds), "bordermk": bmk}, n,
                            f"no {named(tkinds, tmk)} node (other than the pen's) touches a "
                            f"{named(bkinds, bmk)} node")

    cmd_redrawnearbox = cmd_redrawnear

    # ------------------------------------------------------------ shape output
    def cmd_shapeout(self, el):
        value = self.reader.text_attr(el, "file")
        fmt = self.reader.text_attr(el, "format", "vtk", choices=set(FORMATS)).lower()
        reset = self.reader.boolean(el, "reset", True)
        self.reader.num(el, "savenormal", 0.0)
        base = os.path.basename(value.replace("\\", "/"))
        if base.lower().endswith("." + fmt):
            base = base[: -len(fmt) - 1]
        if not value.strip():
            base = "Shapes"  # GenCase examples use file="" for the default name
        if not base or base in (".", "..") or not re.fullmatch(r"[A-Za-z0-9_.\-]+", base):
            raise self.reader.error(el, f"file={value!r} is not a usable file name",
                                    "a plain name of letters, digits, '_', '-', '.'")
        tris, _, mk, fluid = merge_shapes(self.shapes)
        self.shape_sets[base] = (tris, mk, fluid.astype(bool))
        if self.outdir is not None:
            name = f"{self.casename}_{base}.{fmt}" if self.casename else f"{base}.{fmt}"
            path = os.path.join(self.outdir, name)
            try:
                write_shapes(path, self.shapes, fmt)
            except OSError as exc:
                raise self.reader.error(el, f"cannot write {path}: {exc.strerror}") from None
            self.shape_files.append(path)
        if reset:
            self.shapes = []
            self.shape_triangles = 0


VARIABLE_COMMANDS = {"newvar", "newvarcte", "setvar", "newvarstr", "newvarstrcte", "setvarstr",
                     "delvar", "printf", "abort", "varssave", "varsload", "exportvar"}


# ---------------------------------------------------------------- entry point
def _define_builtin(vars_, name, value) -> None:
    vars_.delete(name)
    vars_.define(name, value, constant=True)


def _read_definition(reader, geometry_el):
    d = reader.child(geometry_el, "definition", required=True)
    reader.check_children(d, {"pointref", "pointmin", "pointmax", "rem"}, "child element")
    dp = reader.num(d, "dp", positive=True)
    _define_builtin(reader.vars, "Dp", dp)        # GenCase's points may use it: x="#-int(bx/Dp)*Dp"
    pmin = reader.vec3(reader.child(d, "pointmin", required=True))
    pmax_el = reader.child(d, "pointmax", required=True)
    pmax = reader.vec3(pmax_el)
    ref_el = reader.child(d, "pointref")
    pref = reader.vec3(ref_el) if ref_el is not None else None
    if np.any(pmax < pmin):
        raise reader.error(pmax_el, f"pointmax {pmax.tolist()} is below pointmin "
                                    f"{pmin.tolist()}", "pointmax >= pointmin on every axis")
    if not np.all(np.isfinite((pmax - pmin) / dp)):
        raise reader.error(d, "domain size / dp is not finite", "a finite number of nodes")
    return d, dp, pmin, pmax, pref


def run_geometry(reader, geometry_el, *, casename: str, outdir: str | None,
                 max_nodes: int = 200_000_000) -> Drawing:
    """Execute ``<geometry>`` (predefinition, definition, commands) and return the particles."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return _run_geometry(reader, geometry_el, casename, outdir, max_nodes)


def _run_geometry(reader, geometry_el, casename, outdir, max_nodes) -> Drawing:
    reader.check_children(geometry_el, {"predefinition", "definition", "commands", "rem"},
                          "child element")
    pre = reader.child(geometry_el, "predefinition")
    runner = GeometryRunner(reader, None, casename, outdir)
    runner.keep_shapes = any(True for _ in geometry_el.iter("shapeout"))
    if pre is not None:
        runner.run_commands(pre, only_variables=True)
    d, dp, pmin, pmax, pref = _read_definition(reader, geometry_el)
    lat = Lattice(dp, pmin, pmax, pref)
    if lat.node_count > max_nodes:
        raise reader.error(d, f"domain has {lat.node_count:.4g} lattice nodes "
                              f"({' x '.join(f'{c:.4g}' for c in lat.counts_float)}); "
                              f"at most {max_nodes}",
                           "a larger dp or a smaller pointmin..pointmax")
    runner.lat = lat
    runner.canvas = Canvas(lat)
    v = reader.vars
    v.lattice = (lat.origin.copy(), dp)      # roundposx/y/z
    _define_builtin(v, "Dp", dp)
    for i, ax in enumerate("xyz"):
        _define_builtin(v, f"PosMin_{ax}", float(pmin[i]))
        _define_builtin(v, f"PosMax_{ax}", float(pmax[i]))
    _define_builtin(v, "Data2D", 1.0 if lat.is2d else 0.0)
    _define_builtin(v, "Data2DPosy", float(pmin[1]) if lat.is2d else 0.0)
    if "CaseName" not in v.values:
        v.define("CaseName", casename)
    commands = reader.child(geometry_el, "commands")
    if commands is not None:
        reader.check_children(commands, {"list", "mainlist", "rem"}, "child element")
        for lst in reader.children(commands, "list"):
            name = reader.text_attr(lst, "name")
            reader.boolean(lst, "printcall", True)
            if name in runner.lists:
                raise reader.error(lst, f"list '{name}' is defined twice", "unique list names")
            runner.lists[name] = lst
        mains = reader.children(commands, "mainlist")
        if len(mains) > 1:
            raise reader.error(mains[1], "more than one <mainlist>", "a single <mainlist>")
        if mains:
            runner.run_commands(mains[0])
    pos, is_fluid, mk = runner.canvas.extract()
    return Drawing(dp=dp, pointmin=pmin, pointmax=pmax, pointref=lat.pointref, is2d=lat.is2d,
                   posy2d=float(pmin[1]) if lat.is2d else 0.0, pos=pos, is_fluid=is_fluid,
                   mk=mk, primitives=runner.primitives, shape_files=runner.shape_files,
                   shape_sets=runner.shape_sets,
                   messages=runner.messages, origin=lat.origin)

"""Expressions and user variables of DualSPHysics case files.

Attribute values that start with ``#`` are expressions (``x="#SizeX/2"``); the
values of ``<newvar>``, ``<newvarcte>`` and ``<setvar>`` are expressions without
the ``#``. The grammar is C-like: ``+ - * / %``, ``^`` (power), comparisons,
``&& || !``, parentheses, function calls, and array-like names ``x[1+1]`` that
mean the variable ``x2``. As in C (GenCase's evaluator; GenCase_CaseTemplate.xml's
``if="Dp!=0.1==(true||false)"``), ``!`` binds tighter than any binary operator, ``< <= > >=``
tighter than ``== !=``, and comparisons do not chain: ``a!=b==c`` is ``(a!=b)==c`` with the
first result taken as 0 or 1. Strings (``<newvarstr>``) may interpolate
expressions between brackets: ``"[Text1]_[Dp*100]"``.

The evaluator walks a Python AST restricted to these node types, so nothing
else can be executed.
"""
from __future__ import annotations

import ast
import math
import random
import re

__all__ = ["ExpressionError", "Variables", "FUNCTIONS"]


class ExpressionError(ValueError):
    """An expression could not be evaluated; the message says why."""


def _wavelength(gravity, depth, period):
    """Linear wave length 2π/k, with ω² = g k tanh(k d) (see :func:`sphdvi.motion.wave_number`)."""
    from ..motion import wave_number
    g = abs(gravity)
    if g <= 0 or depth <= 0 or period <= 0:
        raise ExpressionError("wavelength(gravity, depth, period) needs positive values")
    return 2.0 * math.pi / wave_number(period, depth, g)


def _eval_cond(cond, a, b):
    return a if cond else b


def _fmodr(a, b):
    """Remainder with the sign of the divisor (floored modulo)."""
    return a - b * math.floor(a / b)


def _rand(a=None, b=None):
    if a is None:
        return random.random()
    if b is None:
        return random.random() * a
    return a + (b - a) * random.random()


def _randinit(seed):
    random.seed(int(seed))
    return 0.0


def _int(a):
    return float(int(a))


def _round_node(pos, posmin, dp):
    """``posmin + k*dp`` nearest to ``pos`` (halves up, 1e-6 dp tolerance as the drawing's
    node rounding, :func:`sphdvi.case.draw.lattice.round_idx`)."""
    if not dp > 0:
        raise ExpressionError("roundpos(pos, posmin, dp) needs dp > 0")
    return posmin + math.floor((pos - posmin) / dp + 0.5 + 1e-6) * dp


FUNCTIONS = {
    "pi": lambda: math.pi, "e": lambda: math.e,
    "min": min, "max": max, "abs": abs, "sqrt": math.sqrt, "exp": math.exp,
    "log": math.log, "log10": math.log10, "pow": math.pow,
    "sin": math.sin, "cos": math.cos, "tan": math.tan,
    "sindg": lambda a: math.sin(math.radians(a)), "cosdg": lambda a: math.cos(math.radians(a)),
    "tandg": lambda a: math.tan(math.radians(a)),
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh,
    "asin": math.asin, "acos": math.acos, "atan": math.atan, "atan2": math.atan2,
    "floor": math.floor, "ceil": math.ceil, "round": lambda a: float(math.floor(a + 0.5)),
    "fmod": math.fmod, "fmodr": _fmodr, "float": float, "int": _int,
    "rand": _rand, "randint": lambda a, b: float(random.randint(int(a), int(b))),
    "randinit": _randinit, "eval": _eval_cond, "wavelength": _wavelength,
    "roundpos": _round_node,
}
#: roundposx/y/z(pos): GenCase_CaseTemplate.xml lists them (with roundpos(pos,posmin,dp)) without
#: a definition; sphdvi takes the evident one: the nearest lattice position along that axis,
#: ``origin + k*Dp`` with the lattice origin of <definition> (pointmin, or the first node of the
#: pointref-aligned lattice; in 2D the y axis is rounded the same way from posy)
LATTICE_FUNCTIONS = {"roundposx": 0, "roundposy": 1, "roundposz": 2}

_BINOPS = {
    ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b, ast.Mod: math.fmod, ast.Pow: lambda a, b: a ** b,
}
_CMPOPS = {
    ast.Eq: lambda a, b: a == b, ast.NotEq: lambda a, b: a != b, ast.Lt: lambda a, b: a < b,
    ast.LtE: lambda a, b: a <= b, ast.Gt: lambda a, b: a > b, ast.GtE: lambda a, b: a >= b,
}
_MAX_LEN = 2000
_MAX_POW = 1e6


def _to_python(text: str) -> str:
    """Rewrite the C-like operators of DualSPHysics expressions as Python ones.  ``@@`` is ``&&``
    written without XML's ``&amp;`` (DualSPHysics's examples/others/Variables/GenericWaveTank.xml:
    ``<abort if="use_beach @@ (ang<2 || ang>90)">``)."""
    s = text.replace("&&", " and ").replace("@@", " and ").replace("||", " or ")
    s = re.sub(r"!(?!=)", " ~", s)     # C's unary ! (Python's ~ has unary precedence)
    s = s.replace("^", "**")
    s = re.sub(r"\btrue\b", "True", s)
    s = re.sub(r"\bfalse\b", "False", s)
    return s.strip()


class Variables:
    """The user and built-in variables of a case, and the evaluator that reads them."""

    def __init__(self):
        self.values: dict[str, object] = {}
        self.constant: set[str] = set()
        self.lattice: tuple | None = None   # (origin xyz, dp) once <definition> is read

    def copy(self) -> "Variables":
        other = Variables()
        other.values = dict(self.values)
        other.constant = set(self.constant)
        other.lattice = self.lattice
        return other

    # -- definitions -------------------------------------------------------
    def define(self, name: str, value, constant: bool = False, redefine: bool = True) -> None:
        """Create or change a variable. Constants cannot be changed afterwards."""
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise ExpressionError(f"'{name}' is not a valid variable name")
        if name in self.constant:
            raise ExpressionError(f"variable '{name}' is a constant (newvarcte) and cannot be changed")
        if not redefine and name not in self.values:
            raise ExpressionError(f"variable '{name}' does not exist (setvar changes existing variables; use newvar)")
        self.values[name] = value
        if constant:
            self.constant.add(name)

    def delete(self, pattern: str) -> None:
        """Delete variables whose names match a shell-style pattern (``Size?``, ``Tex*``)."""
        import fnmatch
        for name in [n for n in self.values if fnmatch.fnmatchcase(n, pattern)]:
            self.values.pop(name, None)
            self.constant.discard(name)

    # -- evaluation --------------------------------------------------------
    def evaluate(self, text: str):
        """Evaluate an expression (without the leading ``#``); returns float, bool or str."""
        if text is None:
            raise ExpressionError("empty expression")
        text = str(text).strip()
        if not text:
            raise ExpressionError("empty expression")
        if len(text) > _MAX_LEN:
            raise ExpressionError(f"expression longer than {_MAX_LEN} characters")
        try:
            tree = ast.parse(_to_python(text), mode="eval")
        except SyntaxError:
            raise ExpressionError(f"cannot parse expression '{text}'") from None
        try:
            return self._eval(tree.body)
        except ExpressionError:
            raise
        except ZeroDivisionError:
            raise ExpressionError(f"division by zero in '{text}'") from None
        except (ValueError, OverflowError, TypeError, RecursionError) as exc:
            raise ExpressionError(f"cannot evaluate '{text}': {exc}") from None

    def number(self, text: str) -> float:
        """Evaluate to a finite float."""
        value = self.evaluate(text)
        if isinstance(value, str):
            raise ExpressionError(f"'{text}' is text, not a number")
        value = float(value)
        if not math.isfinite(value):
            raise ExpressionError(f"'{text}' gives {value}, not a finite number")
        return value

    def interpolate(self, text: str) -> str:
        """Replace every ``[expression]`` in a string by its value."""
        text = str(text)
        out, i = [], 0
        while i < len(text):
            if text[i] != "[":
                out.append(text[i])
                i += 1
                continue
            depth, j = 0, i
            while j < len(text):
                depth += {"[": 1, "]": -1}.get(text[j], 0)
                if depth == 0:
                    break
                j += 1
            if depth:
                raise ExpressionError(f"unbalanced '[' in '{text}'")
            out.append(self._format(self.evaluate(text[i + 1:j])))
            i = j + 1
        return "".join(out)

    @staticmethod
    def _format(value) -> str:
        """A number as text: a whole number without a decimal point, others to 15 significant
        digits, so binary rounding noise stays out of the text (``[Dp*3]`` with Dp = 0.1 is
        "0.3", not "0.30000000000000004": a file name built from it is the one meant)."""
        if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
            return str(int(value))
        if isinstance(value, float):
            return f"{value:.15g}"
        return str(value)

    def _eval(self, node):
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool):
                return node.value
            if isinstance(node.value, (int, float)):
                return float(node.value)
            if isinstance(node.value, str):
                return node.value
            raise ExpressionError(f"unsupported constant {node.value!r}")
        if isinstance(node, ast.Name):
            return self._lookup(node.id)
        if isinstance(node, ast.Subscript):
            if not isinstance(node.value, ast.Name):
                raise ExpressionError("only names can be indexed (x[1] means variable x1)")
            index = self._eval(node.slice)
            if isinstance(index, str) or float(index) != int(index):
                raise ExpressionError(f"index of '{node.value.id}' must be an integer")
            return self._lookup(f"{node.value.id}{int(index)}")
        if isinstance(node, ast.BinOp):
            op = _BINOPS.get(type(node.op))
            if op is None:
                raise ExpressionError("unsupported operator")
            a, b = self._eval(node.left), self._eval(node.right)
            if isinstance(node.op, ast.Add) and isinstance(a, str) and isinstance(b, str):
                return a + b
            a, b = self._num(a), self._num(b)
            if isinstance(node.op, ast.Pow) and abs(b) > _MAX_POW:
                raise ExpressionError("exponent too large")
            return float(op(a, b))
        if isinstance(node, ast.UnaryOp):
            value = self._eval(node.operand)
            if isinstance(node.op, (ast.Not, ast.Invert)):
                return not value
            if isinstance(node.op, ast.USub):
                return -self._num(value)
            if isinstance(node.op, ast.UAdd):
                return self._num(value)
            raise ExpressionError("unsupported unary operator")
        if isinstance(node, ast.BoolOp):
            values = [self._eval(v) for v in node.values]
            return all(values) if isinstance(node.op, ast.And) else any(values)
        if isinstance(node, ast.Compare):
            return self._compare(node)
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.keywords:
                raise ExpressionError("only plain function calls are allowed")
            if node.func.id in LATTICE_FUNCTIONS:
                return self._round_lattice(node)
            fn = FUNCTIONS.get(node.func.id)
            if fn is None:
                known = ", ".join(sorted([*FUNCTIONS, *LATTICE_FUNCTIONS]))
                raise ExpressionError(f"unknown function '{node.func.id}()'; known: {known}")
            args = [self._eval(a) for a in node.args]
            if node.func.id != "eval":
                args = [self._num(a) for a in args]
            return fn(*args)
        if isinstance(node, ast.IfExp):
            return self._eval(node.body) if self._eval(node.test) else self._eval(node.orelse)
        raise ExpressionError(f"unsupported syntax ({type(node).__name__})")

    def _compare(self, node):
        """A comparison as C evaluates it: ``< <= > >=`` before ``== !=``, each left to right,
        a comparison's result (0 or 1) the left operand of the next (no Python chaining)."""
        groups, eq_ops = [self._eval(node.left)], []
        for op, comp in zip(node.ops, node.comparators):
            fn = _CMPOPS.get(type(op))
            if fn is None:
                raise ExpressionError("unsupported comparison")
            right = self._eval(comp)
            if isinstance(op, (ast.Eq, ast.NotEq)):
                eq_ops.append(fn)
                groups.append(right)
            else:
                groups[-1] = fn(groups[-1], right)
        result = groups[0]
        for fn, right in zip(eq_ops, groups[1:]):
            result = fn(result, right)
        return bool(result)

    def _round_lattice(self, node):
        """roundposx/y/z(pos): the nearest lattice position along x, y or z (see LATTICE_FUNCTIONS)."""
        name = node.func.id
        if len(node.args) != 1:
            raise ExpressionError(f"{name}(pos) takes one argument")
        if self.lattice is None:
            raise ExpressionError(f"{name}() needs the particle lattice: use it after <definition> "
                                  "(not in <predefinition>)")
        origin, dp = self.lattice
        axis = LATTICE_FUNCTIONS[name]
        return _round_node(self._num(self._eval(node.args[0])), float(origin[axis]), float(dp))

    def _lookup(self, name: str):
        if name in self.values:
            value = self.values[name]
            return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else value
        if name in FUNCTIONS:
            raise ExpressionError(f"'{name}' is a function: write {name}(...)")
        known = ", ".join(sorted(self.values)) or "none"
        raise ExpressionError(f"unknown variable '{name}' (defined: {known})")

    @staticmethod
    def _num(value):
        if isinstance(value, str):
            raise ExpressionError(f"text '{value}' used as a number")
        return float(value)

"""Reading DualSPHysics XML case files: lenient parsing, disabled elements,
typed attribute access with ``file:line: element:`` errors, unknown-attribute warnings.

DualSPHysics reads its files with TinyXML, which accepts a few things XML does
not: a blank line before ``<?xml`` or a comment before it (DesignSPHysics's files),
a raw ``<`` or ``&`` inside an attribute value (``<abort if="Dp<0.1"/>``), and ``--``
inside a comment (``<!---walls--->``). These are repaired before parsing;
anything else that is malformed is reported with its line and column.

Elements whose tag starts with ``_`` and elements with ``active="false"`` are
removed before anything reads the tree.
"""
from __future__ import annotations

import math
import os
import re

import numpy as np
from lxml import etree

from ..errors import CaseError, Warnings
from .expressions import ExpressionError, Variables

MAX_CASE_BYTES = 64 * 1024 * 1024
#: note attributes, on any element: ``cmt`` (DualSPHysics's examples, ``<drawbox cmt="piston">``) and
#: ``objname`` (DesignSPHysics writes it on every object it draws) as well as the comments
IGNORED_ATTRIBUTES = {"comment", "units_comment", "comment2", "rem", "cmt", "objname"}
#: attributes GenCase writes itself (its output case files are valid input), per element; GenCase's
#: ``<casedef requiredversion="v5.0.295">`` (GenCase_CaseTemplate.xml) is the GenCase version a
#: case needs, which GenCase checks against its own: sphdvi reads the v5.4 format
GENERATED_ATTRIBUTES = {"case": {"app", "date"}, "casedef": {"requiredversion"}}
#: attributes of real DualSPHysics files that DualSPHysics does not read, per element: a block's
#: ``name`` label (examples/main/04_ExternalForces: ``<setmkfluid mk="0" name="FluidLeft"/>``) and
#: ``<chrono datadir=".">`` (examples/chrono/06_ZipLine; JChronoObjects takes its data folder from
#: the case's, not from the XML)
LABEL_ATTRIBUTES = {"setmkfluid": {"name"}, "setmkbound": {"name"}, "setmkvoid": {"name"},
                    "chrono": {"datadir"}}
REQUIRED = object()
_TRUE = {"true", "1", "yes"}
_FALSE = {"false", "0", "no"}


def _blank(text: str) -> str:
    """``text`` with every character but a newline turned into a space (line numbers kept)."""
    return re.sub(r"[^\n]", " ", text)


def _repair_tinyxml_text(text: str) -> str:
    """What TinyXML (DualSPHysics's XML reader) takes and XML does not, made well-formed, each
    line kept where it was: a raw ``<`` or a stray ``&`` inside a quoted attribute value of a
    start tag is escaped; a comment's body loses its hyphens (TinyXML ends a comment at the first
    ``-->`` and reads nothing in it: ``<!---wall boundaries--->`` is a comment, which XML refuses
    for its ``--``); an ``<?xml ...?>`` declaration that does not open the file is blanked
    (DesignSPHysics writes ``<!-- Case name: ... -->`` on the line before it)."""
    out = []
    i = 0
    n = len(text)
    in_tag = False
    quote = None
    while i < n:
        c = text[i]
        if quote:
            if c == quote:
                quote = None
                out.append(c)
            elif c == "<":
                out.append("&lt;")
            elif c == "&" and not re.match(r"&(#\d+|#x[0-9a-fA-F]+|[A-Za-z]+);", text[i:i + 12]):
                out.append("&amp;")
            else:
                out.append(c)
        elif in_tag:
            if c in "\"'":
                quote = c
            elif c == ">":
                in_tag = False
            out.append(c)
        else:
            if c == "<":
                if text.startswith("<!--", i):
                    j = text.find("-->", i + 4)
                    if j < 0:
                        out.append(text[i:])
                        break
                    out.append("<!--" + text[i + 4:j].replace("-", " ") + "-->")
                    i = j + 3
                    continue
                if i > 0 and re.match(r"<\?xml\s", text[i:i + 6]):
                    j = text.find("?>", i)
                    j = n if j < 0 else j + 2
                    out.append(_blank(text[i:j]))
                    i = j
                    continue
                if text.startswith("<![CDATA[", i):
                    j = text.find("]]>", i)
                    j = n if j < 0 else j + 3
                    out.append(text[i:j])
                    i = j
                    continue
                in_tag = True
            out.append(c)
        i += 1
    return "".join(out)


def parse_xml_text(text: str, file: str) -> etree._Element:
    """Parse case XML text, repairing what TinyXML tolerates; raise CaseError otherwise."""
    stripped = text.lstrip("\ufeff \t\r\n")
    # keep line numbers: count the lines removed before <?xml
    removed_lines = text[: len(text) - len(stripped)].count("\n")
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False,
                             remove_comments=True, remove_pis=True, load_dtd=False)
    candidates = [stripped, _repair_tinyxml_text(stripped)]
    first_error = None
    for candidate in candidates:
        try:
            root = etree.fromstring(candidate.encode("utf-8"), parser)
        except etree.XMLSyntaxError as exc:
            if first_error is None:
                first_error = exc
            continue
        if removed_lines:
            for el in root.iter():
                if el.sourceline:
                    el.sourceline = el.sourceline + removed_lines
        return root
    line, col = (first_error.position if first_error.position else (0, 0))
    msg = first_error.msg if hasattr(first_error, "msg") else str(first_error)
    raise CaseError(f"malformed XML at column {col}: {msg}", file=file, line=line + removed_lines,
                    expected="a well-formed XML document with a <case> root")


def load_xml(path: str) -> tuple[etree._Element, str]:
    """Read and parse a case file. Returns (root element, source text)."""
    name = os.path.basename(path)
    try:
        size = os.path.getsize(path)
    except OSError as exc:
        raise CaseError(f"cannot read case file: {exc.strerror}", file=path) from None
    if size > MAX_CASE_BYTES:
        raise CaseError(f"case file is {size} bytes", file=path,
                        expected=f"at most {MAX_CASE_BYTES} bytes")
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise CaseError(f"cannot read case file: {exc.strerror}", file=path) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    if "\x00" in text:
        raise CaseError("file contains NUL bytes; it is not a text XML file", file=path)
    root = parse_xml_text(text, path)
    if not isinstance(root.tag, str) or root.tag != "case":
        raise CaseError(f"root element is <{root.tag}>", file=path, line=root.sourceline,
                        expected="<case>")
    del name
    return root, text


def strip_disabled(root: etree._Element, file: str | None = None) -> None:
    """Remove ``_``-prefixed elements and elements with ``active="false"`` (and their children);
    an ``active`` that is not a boolean (nor a ``#`` expression) is a CaseError naming ``file``."""
    doomed = []
    for el in root.iter():
        if not isinstance(el.tag, str):
            doomed.append(el)
            continue
        if el.tag.startswith("_"):
            doomed.append(el)
            continue
        active = el.get("active")
        if active is None:
            continue
        text = active.strip().lower()
        if text in _FALSE:
            doomed.append(el)
        elif text not in _TRUE and not text.startswith("#"):
            raise CaseError(f"active={active!r} is not a boolean", file=file, line=el.sourceline,
                            element=el.tag, expected="true/false or 1/0")
    for el in doomed:
        parent = el.getparent()
        if parent is not None:
            # keep the text that followed the removed element
            parent.remove(el)


class CaseReader:
    """Typed, located access to the attributes of a case document.

    Every accessor raises :class:`CaseError` naming the file, line and element,
    what was wrong and what was expected. Attributes that are read are marked,
    so :meth:`warn_unread_attributes` can warn about the ones nobody knows.
    Values starting with ``#`` are expressions over :attr:`vars`.
    """

    def __init__(self, file: str, variables: Variables | None = None,
                 warnings: Warnings | None = None, base_dir: str | None = None):
        self.file = file
        self.vars = variables if variables is not None else Variables()
        self.warnings = warnings if warnings is not None else Warnings()
        self.base_dir = base_dir if base_dir is not None else os.path.dirname(os.path.abspath(file))
        self.root = None          # the document, where the reader was made for one
        self._read: dict[etree._Element, set[str]] = {}

    # -- errors ------------------------------------------------------------
    def error(self, el, message: str, expected: str | None = None) -> CaseError:
        line = getattr(el, "sourceline", None) if el is not None else None
        tag = el.tag if el is not None and isinstance(getattr(el, "tag", None), str) else None
        return CaseError(message, file=self.file, line=line, element=tag, expected=expected)

    def line_of(self, path: str) -> int | None:
        """The line of the element at ``path`` (an ElementPath from the document's root), or None."""
        el = self.root.find(path) if self.root is not None else None
        return getattr(el, "sourceline", None)

    def warn(self, el, message: str) -> None:
        line = getattr(el, "sourceline", None) if el is not None else None
        tag = el.tag if el is not None else None
        self.warnings.add(message, file=self.file, line=line, element=tag)

    # -- raw access --------------------------------------------------------
    def mark(self, el, *names: str) -> None:
        self._read.setdefault(el, set()).update(names)

    def has(self, el, name: str) -> bool:
        return el is not None and el.get(name) is not None

    def raw(self, el, name: str, default=REQUIRED, expected: str = "a value"):
        self.mark(el, name)
        value = el.get(name)
        if value is None:
            if default is REQUIRED:
                raise self.error(el, f"missing attribute '{name}'", expected)
            return default
        return value

    # -- typed attributes --------------------------------------------------
    def num(self, el, name: str, default=REQUIRED, *, positive: bool = False,
            nonnegative: bool = False, lo: float | None = None, hi: float | None = None) -> float:
        """A finite float attribute (literal or ``#expression``), optionally range-checked."""
        raw = self.raw(el, name, default, "a number")
        if raw is default and default is not REQUIRED:
            return default
        value = self._number(el, name, raw)
        if positive and not value > 0:
            raise self.error(el, f"{name}={raw!r} is not positive", "a number > 0")
        if nonnegative and value < 0:
            raise self.error(el, f"{name}={raw!r} is negative", "a number >= 0")
        if lo is not None and value < lo:
            raise self.error(el, f"{name}={raw!r} is below {lo}", f"a number >= {lo}")
        if hi is not None and value > hi:
            raise self.error(el, f"{name}={raw!r} is above {hi}", f"a number <= {hi}")
        return value

    def integer(self, el, name: str, default=REQUIRED, *, lo: int | None = None,
                hi: int | None = None) -> int:
        raw = self.raw(el, name, default, "an integer")
        if raw is default and default is not REQUIRED:
            return default
        value = self._number(el, name, raw)
        if value != math.floor(value):
            raise self.error(el, f"{name}={raw!r} is not an integer", "an integer")
        value = int(value)
        if lo is not None and value < lo:
            raise self.error(el, f"{name}={raw!r} is below {lo}", f"an integer >= {lo}")
        if hi is not None and value > hi:
            raise self.error(el, f"{name}={raw!r} is above {hi}", f"an integer <= {hi}")
        return value

    def boolean(self, el, name: str, default=REQUIRED) -> bool:
        raw = self.raw(el, name, default, "true or false")
        if raw is default and default is not REQUIRED:
            return default
        text = str(raw).strip().lower()
        if text.startswith("#"):
            try:
                return bool(self.vars.evaluate(text[1:]))
            except ExpressionError as exc:
                raise self.error(el, f"attribute '{name}': {exc}") from None
        if text in _TRUE:
            return True
        if text in _FALSE:
            return False
        raise self.error(el, f"{name}={raw!r} is not a boolean", "true/false or 1/0")

    def text_attr(self, el, name: str, default=REQUIRED, choices=None) -> str:
        raw = self.raw(el, name, default, "a text value")
        if raw is default and default is not REQUIRED:
            return default
        value = str(raw).strip()
        if value.startswith("#"):
            try:
                value = str(self.vars.evaluate(value[1:]))
            except ExpressionError as exc:
                raise self.error(el, f"attribute '{name}': {exc}") from None
        if choices is not None and value.lower() not in choices:
            raise self.error(el, f"{name}={raw!r} is not recognised",
                             "one of " + ", ".join(sorted(choices)))
        return value

    def _number(self, el, name: str, raw) -> float:
        text = str(raw).strip()
        try:
            if text.startswith("#"):
                value = self.vars.number(text[1:])
            else:
                value = float(text)
        except ExpressionError as exc:
            raise self.error(el, f"attribute '{name}': {exc}", "a finite number") from None
        except ValueError:
            # DualSPHysics also accepts plain expressions in a few places; try them
            try:
                value = self.vars.number(text)
            except ExpressionError:
                raise self.error(el, f"{name}={raw!r} is not a number", "a finite number") from None
        if not math.isfinite(value):
            raise self.error(el, f"{name}={raw!r} is not finite", "a finite number")
        return value

    # -- composite values ----------------------------------------------------
    def vec3(self, el, default=REQUIRED, names=("x", "y", "z"), missing=REQUIRED) -> np.ndarray:
        """A 3-vector from attributes x, y, z; a missing component is an error (as in DualSPHysics's
        reader: ``<size x="1" y="2"/>`` drew nothing, z being 0) unless ``missing`` gives its value."""
        if el is None:
            if default is REQUIRED:
                raise CaseError("missing 3-vector element", file=self.file)
            return default
        if not any(el.get(n) is not None for n in names):
            if default is REQUIRED:
                raise self.error(el, "missing attributes " + ", ".join(names), "x, y and z numbers")
            return default
        return np.array([self.num(el, n, missing) for n in names], dtype=np.float64)

    def child(self, el, tag: str, required: bool = False):
        found = el.find(tag) if el is not None else None
        if found is None and required:
            raise self.error(el, f"missing child element <{tag}>", f"a <{tag}> element")
        if found is not None:
            self.mark(found)
        return found

    def children(self, el, tag: str | None = None) -> list:
        if el is None:
            return []
        kids = [c for c in el if isinstance(c.tag, str) and (tag is None or c.tag == tag)]
        for c in kids:
            self.mark(c)
        return kids

    def child_value(self, el, tag: str, default=REQUIRED, attr: str = "value", **checks) -> float:
        """The numeric ``value`` attribute of child ``<tag>`` (DualSPHysics's scalar style)."""
        c = self.child(el, tag, required=default is REQUIRED)
        if c is None:
            return default
        return self.num(c, attr, **checks)

    def check_children(self, el, allowed, what: str = "element") -> None:
        """Raise on a child element whose tag is not in ``allowed``."""
        for c in el:
            if isinstance(c.tag, str) and c.tag not in allowed:
                raise self.error(c, f"unknown {what} <{c.tag}> inside <{el.tag}>",
                                 "one of " + ", ".join(f"<{a}>" for a in sorted(allowed)))

    def check_no_repeats(self, el, tags=None) -> None:
        """Raise on a second child of ``el`` with the same tag (among ``tags``; None: any tag)."""
        seen = set()
        for c in self.children(el):
            if tags is None or c.tag in tags:
                if c.tag in seen:
                    raise self.error(c, f"a second <{c.tag}> inside <{el.tag}>", f"at most one <{c.tag}>")
                seen.add(c.tag)

    def element_text(self, el) -> str:
        return (el.text or "").strip() if el is not None else ""

    def resolve_path(self, el, name: str, must_exist: bool = True) -> str:
        """A file attribute, resolved against the case folder and kept inside it."""
        value = self.text_attr(el, name)
        if not value:
            raise self.error(el, f"empty file name in '{name}'", "a file name")
        if "\x00" in value:
            raise self.error(el, f"{name}: invalid file name", "a file name")
        path = os.path.normpath(os.path.join(self.base_dir, value))
        base = os.path.normpath(os.path.abspath(self.base_dir))
        if os.path.commonpath([os.path.abspath(path), base]) != base:
            raise self.error(el, f"file '{value}' lies outside the case folder {base}",
                             "a path inside the folder of the case file")
        if must_exist and not os.path.isfile(path):
            raise self.error(el, f"file '{value}' not found (looked for {path})", "an existing file")
        return path

    # -- unknown attributes ------------------------------------------------
    def warn_unread_attributes(self, root) -> None:
        """Warn once per unknown attribute on every element that was read."""
        for el, names in list(self._read.items()):
            for attr in el.keys():
                if attr in names or attr in IGNORED_ATTRIBUTES or attr.startswith("_") \
                        or attr == "active" or attr.endswith("_comment") \
                        or attr in GENERATED_ATTRIBUTES.get(el.tag, ()) \
                        or attr in LABEL_ATTRIBUTES.get(el.tag, ()):
                    continue
                self.warn(el, f"unknown attribute '{attr}' ignored")

"""Structure and type check of a case document against ``schemas/case.xsd``."""
from __future__ import annotations

import functools
import re
from importlib import resources

from lxml import etree

from ..errors import CaseError


@functools.lru_cache(maxsize=1)
def case_schema() -> etree.XMLSchema:
    path = resources.files("sphdvi").joinpath("schemas/case.xsd")
    with resources.as_file(path) as p:
        return etree.XMLSchema(etree.parse(str(p)))


# what an attribute of each of the XSD's simple types holds (a pattern error names only the
# pattern it tried last: every attribute was said to expect a number)
EXPECTED_BY_TYPE = {"number": "a finite number or a #expression",
                    "boolean": "true/false or 1/0 (or a #expression)",
                    "mklist": "an mk number, a range or a list of them (5, 1-3 or 1-3,7)"}


@functools.lru_cache(maxsize=1)
def _attribute_types() -> dict:
    """Attribute name -> its simple type in the XSD, where every declaration agrees."""
    path = resources.files("sphdvi").joinpath("schemas/case.xsd")
    with resources.as_file(path) as p:
        doc = etree.parse(str(p))
    seen: dict = {}
    for a in doc.iter("{http://www.w3.org/2001/XMLSchema}attribute"):
        if a.get("name") and a.get("type"):
            seen.setdefault(a.get("name"), set()).add(a.get("type").split(":")[-1])
    return {name: next(iter(types)) for name, types in seen.items() if len(types) == 1}


_ELEMENT = re.compile(r"^Element '([^']+)'(?:, attribute '([^']+)')?: (.*)$", re.S)


def validate_structure(root, file: str) -> None:
    """Raise a :class:`CaseError` for the first XSD violation (file:line: element: message)."""
    schema = case_schema()
    if schema.validate(root):
        return
    err = schema.error_log[0]
    message = err.message
    element = None
    m = _ELEMENT.match(message)
    if m:
        element = m.group(1)
        message = m.group(3)
        if m.group(2):
            message = f"attribute '{m.group(2)}': {message}"
    message = message.replace("'{number}'", "number").replace("the atomic type 'number'", "a number")
    message = re.sub(r"\[facet 'pattern'\] The value '([^']*)' is not accepted by the pattern '[^']*'\.",
                     r"the value '\1' is not valid", message)
    expected = None
    if "number" in message or "is not valid" in message:
        kind = _attribute_types().get(m.group(2)) if m and m.group(2) else None
        expected = EXPECTED_BY_TYPE.get(kind, EXPECTED_BY_TYPE["number"])
    raise CaseError(message.strip(), file=file, line=err.line, element=element, expected=expected)

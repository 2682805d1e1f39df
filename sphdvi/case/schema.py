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
        expected = "a finite number or a #expression"
    raise CaseError(message.strip(), file=file, line=err.line, element=element, expected=expected)

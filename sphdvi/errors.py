"""Errors and warnings shown to users, and the process exit codes.

Exit codes (see ../shared/design/conventions.md §4.1):
0 success, 1 runtime failure, 2 bad input (case file, options), 3 a run that diverged.
"""
from __future__ import annotations

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_INPUT = 2
EXIT_DIVERGED = 3


class SphdviError(Exception):
    """Base class of the errors sphdvi reports without a traceback."""

    exit_code = EXIT_FAILURE


class CaseError(SphdviError):
    """A problem in a case file: where it is, what was wrong, what was expected.

    Printed as ``file:line: element: message; expected ...``.
    """

    exit_code = EXIT_INPUT

    def __init__(self, message: str, file: str | None = None, line: int | None = None,
                 element: str | None = None, expected: str | None = None):
        self.message = message
        self.file = file
        self.line = line
        self.element = element
        self.expected = expected
        super().__init__(str(self))

    def __str__(self) -> str:
        where = self.file or "<case>"
        if self.line:
            where += f":{self.line}"
        text = f"{where}: "
        if self.element:
            text += f"<{self.element}>: "
        text += self.message
        if self.expected:
            text += f"; expected {self.expected}"
        return text


class InputError(SphdviError):
    """Bad command-line input or a bad file that is not a case XML."""

    exit_code = EXIT_INPUT


class DivergenceError(SphdviError):
    """A simulation went unstable (NaN, dt stuck at DtMin, too many particles excluded)."""

    exit_code = EXIT_DIVERGED


def h5_reason(exc: BaseException) -> str:
    """What an HDF5 (h5py) exception says, without its boilerplate: 'file signature not
    found', 'object 'pos' doesn't exist', ... (for messages that name the file themselves)."""
    text = str(exc.args[0]) if exc.args else type(exc).__name__
    if "(" in text and text.rstrip().endswith(")"):
        text = text[text.index("(") + 1:text.rstrip().rindex(")")]
    return text.replace("Unable to synchronously open file ", "").strip() or type(exc).__name__


class Warnings:
    """Collects warnings (``file:line: element: text``) so the CLI can print them once."""

    def __init__(self):
        self.items: list[str] = []

    def add(self, message: str, file: str | None = None, line: int | None = None,
            element: str | None = None) -> None:
        where = (file or "<case>") + (f":{line}" if line else "")
        tag = f"<{element}>: " if element else ""
        text = f"{where}: warning: {tag}{message}"
        if text not in self.items:
            self.items.append(text)

    def __iter__(self):
        return iter(self.items)

    def __len__(self):
        return len(self.items)

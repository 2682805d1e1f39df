"""Atomic file writing: write to a temporary file in the same folder, then rename."""
from __future__ import annotations

import contextlib
import os
import re
import tempfile

# the process's umask, read once (os.umask can only be read by setting it): atomically
# written files get the mode a plain open() would give them, not mkstemp's 0600
_UMASK = os.umask(0o022)
os.umask(_UMASK)


@contextlib.contextmanager
def atomic_path(path: str):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically.

    On an exception the temporary file is removed and ``path`` is left untouched.
    """
    folder = os.path.dirname(os.path.abspath(path)) or "."
    if os.path.isdir(path):
        from ..errors import InputError
        raise InputError(f"{path} is a folder, where a file is to be written; move the folder away")
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    try:
        os.fchmod(fd, 0o666 & ~_UMASK)
    finally:
        os.close(fd)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


# what atomic_path's mkstemp names: "." + name + "." + 8 characters of [a-z0-9_] + ".tmp" (any
# ".X.Y.tmp" went before: a user's ".my.backup.tmp" too)
_TEMPORARY = re.compile(r"\..+\.[a-z0-9_]{8}\.tmp")


def remove_leftover_temporaries(folder: str) -> list[str]:
    """Delete the temporary files :func:`atomic_path` leaves when its process is killed
    (SIGKILL) between creating and renaming one: ``.NAME.XXXXXXXX.tmp``.  Returns their names.
    Call it only where no other process writes into ``folder``."""
    removed = []
    with contextlib.suppress(FileNotFoundError):
        for entry in os.scandir(folder):
            name = entry.name
            if _TEMPORARY.fullmatch(name) and entry.is_file():
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
                    removed.append(name)
    return sorted(removed)


def write_text_atomic(path: str, text: str) -> None:
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)


def append_text(path: str, text: str) -> None:
    """Append ``text`` (whole lines) with one ``write`` system call.

    For the logs that grow by rows during a run (gauges, bodies, run.csv): the cost of an
    output no longer grows with the rows already written.  A reader sees the file grow by
    whole blocks; a run killed in the middle of a write leaves at most a torn last line,
    which :func:`complete_lines` drops and a resume cuts (it rewrites the file atomically).
    """
    data = memoryview(text.encode("utf-8"))
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
    try:
        while data:
            data = data[os.write(fd, data):]
    finally:
        os.close(fd)


def complete_lines(path: str) -> list[str]:
    """The lines of a text file that end with a newline (a torn last line is dropped);
    [] when the file does not exist."""
    if not os.path.exists(path):
        return []
    with open(path, encoding="utf-8", newline="") as fh:
        text = fh.read()
    lines = text.split("\n")
    return lines[:-1]          # the part after the last newline is '' or a torn line


def make_folder(path: str, option: str = "-o") -> None:
    """Create the output folder ``path`` (and its parents) for ``option``: a path that cannot
    be a folder (a file on the way, no permission, a read-only file system) is an InputError
    (exit 2) naming the option; it was exit 1 with a bare 'Not a directory'."""
    from ..errors import InputError
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as exc:
        why = exc.strerror or str(exc)
        raise InputError(f"{option} {path}: the folder cannot be made ({why}"
                         + (f": {exc.filename}" if exc.filename and exc.filename != path else "")
                         + "); expected a folder that exists or can be created") from None
    if not os.path.isdir(path):
        raise InputError(f"{option} {path}: exists and is not a folder; expected a folder")

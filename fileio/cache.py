"""A private cache directory, and a memory of documents that passed a check.

A start should not pay again for work whose result cannot have changed: the QoS grammar's parse
tables (:mod:`qos.grammar`) and "this document passed this JSON Schema"
(:func:`fileio.positions.schema_problems`). Only a directory of this user's own, closed to others,
is used, since what is kept there is trusted when read back; without one nothing is kept and the
work is done every time. Losing the cache loses nothing but time.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

#: how many passed documents each check remembers (a kiosk runs one questionnaire, a station a few)
REMEMBERED = 32


def private_dir(name: str) -> Path | None:
    """``<user cache dir>/kiosk/<name>``, created 0700; None when it cannot be had, or is not this
    user's own or is open to others."""
    import platformdirs

    folder = Path(platformdirs.user_cache_dir("kiosk")) / name
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        status = folder.stat()
    except OSError:
        return None
    if status.st_uid != os.getuid() or status.st_mode & 0o077:
        return None
    return folder


def digest(*parts: str) -> str:
    """One key for everything the result of a check depends on."""
    hashed = hashlib.sha256()
    for part in parts:
        hashed.update(part.encode("utf-8", "surrogatepass") + b"\0")
    return hashed.hexdigest()


def passed(check: str, key: str) -> bool:
    """Whether ``key`` (see :func:`digest`) passed ``check`` before (and is still remembered)."""
    folder = private_dir("checked")
    if folder is None:
        return False
    try:
        return key in (folder / check).read_text(encoding="ascii").split()
    except (OSError, ValueError):
        return False


def remember(check: str, key: str) -> None:
    """Note that ``key`` passed ``check``; the oldest of more than :data:`REMEMBERED` are forgotten.
    Written whole under another name, then renamed: a reader never sees half a file."""
    folder = private_dir("checked")
    if folder is None:
        return
    path = folder / check
    try:
        known = path.read_text(encoding="ascii").split() if path.exists() else []
    except (OSError, ValueError):
        known = []
    if key in known:
        return
    temporary = path.with_name(f".{path.name}.{os.getpid()}")
    try:
        temporary.write_text("\n".join([*known, key][-REMEMBERED:]) + "\n", encoding="ascii")
        os.replace(temporary, path)
    except OSError:
        temporary.unlink(missing_ok=True)

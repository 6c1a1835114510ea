"""A private cache directory, a memory of documents that passed a check, and objects kept whole.

A start should not pay again for work whose result cannot have changed: the QoS grammar's parse
tables (:mod:`qos.grammar`), "this document passed this JSON Schema"
(:func:`fileio.positions.schema_problems`) and a parsed QoS model (:mod:`qos.kept`). Only a
directory of this user's own, closed to others, is used, since what is kept there is trusted when
read back; without one nothing is kept and the work is done every time. Losing the cache loses nothing but time.
"""

from __future__ import annotations

import hashlib
import os
import pickle
from collections.abc import Iterable
from pathlib import Path

#: how many passed documents each check remembers (a kiosk runs one questionnaire, a station a few)
REMEMBERED = 32


def private_dir(name: str) -> Path | None:
    """``<user cache dir>/kiosk/<name>``, both created 0700; None when it cannot be had, or is not this
    user's own or is open to others."""
    import platformdirs

    top = Path(platformdirs.user_cache_dir("kiosk"))
    folder = top / name
    try:
        top.parent.mkdir(parents=True, exist_ok=True)  # ~/.cache, as any program makes it
        for level in (top, folder):  # 0700 like the data directory (issue 32: the top was 0755)
            level.mkdir(mode=0o700, exist_ok=True)
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


def code_digest(folder: Path) -> str:
    """One key for the Python source in ``folder`` (not its sub-folders): an object kept by an
    older version of the code that made it is not read back."""
    hashed = hashlib.sha256()
    for path in sorted(folder.glob("*.py")):
        hashed.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return hashed.hexdigest()


def _file_digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def kept(kind: str, key: str) -> object | None:
    """What :func:`keep` kept under ``key`` (see :func:`digest`), if every file it was made from
    still reads the same; else None. Kept objects are unpickled, so only a private directory is
    read; a damaged or stale one costs the work again, never the start."""
    folder = private_dir(kind)
    if folder is None:
        return None
    try:
        with open(folder / f"{key[:40]}.pickle", "rb") as file:
            stored_key, files, value = pickle.load(file)
        if stored_key != key or any(_file_digest(Path(path)) != sha for path, sha in files):
            return None
    except Exception:  # whatever is wrong with a kept file, the work is done again
        return None
    return value


def keep(kind: str, key: str, value: object, files: Iterable[Path] = ()) -> None:
    """Keep ``value`` under ``key`` with the digests of the ``files`` it was also made from (the
    key covers the rest); 0600, written whole under another name, then renamed. The oldest of
    more than :data:`REMEMBERED` are removed. Nothing is kept when it cannot be written."""
    folder = private_dir(kind)
    if folder is None:
        return
    path = folder / f"{key[:40]}.pickle"
    temporary = folder / f".{path.name}.{os.getpid()}"
    try:
        data = pickle.dumps((key, [(str(f), _file_digest(f)) for f in files], value), pickle.HIGHEST_PROTOCOL)
        descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(descriptor, "wb") as file:
            file.write(data)
        os.replace(temporary, path)
        others = sorted(folder.glob("*.pickle"), key=lambda p: p.stat().st_mtime)
        for old in others[:-REMEMBERED]:
            old.unlink(missing_ok=True)
    except (OSError, pickle.PicklingError, TypeError, AttributeError):
        temporary.unlink(missing_ok=True)

"""Opening the session database file: the data directory (0700) and file (0600) made safe before
SQLite touches them, WAL and full sync, an integrity check, the schema brought up to date, and one
message for a file that is damaged or cannot be used."""

from __future__ import annotations

import os
import sqlite3
from collections.abc import Callable
from pathlib import Path

from basis.errors import KioskError
from kiosk.store.migrations import InForce, SchemaError, migrate

DB_NAME = "kiosk.sqlite3"
#: how long a write waits for another kiosk's transaction on the same file before giving up
BUSY_TIMEOUT_S = 10.0


class StorageError(KioskError, RuntimeError):
    """The data directory or database cannot be used (message says where and why)."""


def _secure_dir(path: Path) -> None:
    """Create the data directory readable by its owner only (and tighten an existing one)."""
    path.mkdir(mode=0o700, parents=True, exist_ok=True)
    if path.stat().st_mode & 0o077:
        os.chmod(path, 0o700)


def _secure_file(path: Path) -> None:
    """Create the database file 0600 before SQLite opens it (SQLite gives its WAL/SHM files the
    database file's permissions)."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o600)
    os.close(fd)
    if path.stat().st_mode & 0o077:
        os.chmod(path, 0o600)


def _damaged(path: Path, exc: BaseException | str) -> StorageError:
    """The one message for a database that is not one, or is corrupt: which file, what to do."""
    detail = " ".join(str(exc).split())  # one line: SQLite's checks can span several
    return StorageError(
        f"{path} is damaged ({detail}); nothing was changed. Stop the kiosk, keep a copy of {path.name} "
        f"(and {path.name}-wal, -shm if present) for the engineers, then move them out of {path.parent} "
        "and restore a backup, or start with an empty database"
    )


#: the tables every database of this schema has (a dropped one is damage, found at open)
TABLES = (
    "patients",
    "sessions",
    "answers",
    "not_answered",
    "practice",
    "contexts",
    "metric_samples",
    "adaptations",
    "events",
    "leases",
    "outbox",
    "definitions",
    "tug_results",
)


def _is_damage(exc: sqlite3.DatabaseError) -> bool:
    message = str(exc).lower()
    return type(exc) is sqlite3.DatabaseError or "malformed" in message or "not a database" in message


def connect(data_dir: str | Path, create: bool, in_force: Callable[[], InForce]) -> tuple[sqlite3.Connection, Path]:
    """The connection to the database in ``data_dir`` (created with it unless ``create`` is False)
    and its path, schema up to date (``in_force``: see :func:`kiosk.store.migrations.migrate`);
    StorageError naming the file and what to do otherwise."""
    if any(not c.isprintable() for c in str(data_dir)):
        raise StorageError(
            f"the data directory {str(data_dir)!r} holds a control character or bytes that are not UTF-8"
        )
    try:
        directory = Path(data_dir).expanduser()
    except RuntimeError:  # ~user for a user this machine does not have
        raise StorageError(f"no data directory {data_dir} (no such user to expand ~ for)") from None
    path = directory / DB_NAME
    if not create:
        if not directory.is_dir():
            raise StorageError(f"no data directory {directory}")
        if not path.is_file():
            raise StorageError(f"no session database in {directory} (expected {DB_NAME}; nothing stored there)")
    db = None
    try:
        _secure_dir(directory)
        _secure_file(path)
        db = sqlite3.connect(path, isolation_level=None, timeout=BUSY_TIMEOUT_S)
        db.execute("PRAGMA journal_mode=WAL")
        db.execute("PRAGMA synchronous=FULL")
        db.execute("PRAGMA foreign_keys=ON")
        check = db.execute("PRAGMA quick_check").fetchall()
        if check != [("ok",)]:
            raise _damaged(path, "; ".join(str(row[0]) for row in check[:3]))
        migrate(db, str(path), in_force)
        tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if missing := [t for t in TABLES if t not in tables]:
            raise _damaged(path, f"the table {missing[0]} is missing")
    except SchemaError as exc:
        db.close() if db else None
        raise StorageError(str(exc)) from None
    except sqlite3.DatabaseError as exc:
        db.close() if db else None
        if _is_damage(exc):
            raise _damaged(path, exc) from None
        raise StorageError(f"cannot use the data directory {directory}: {exc}") from None
    except OSError as exc:
        raise StorageError(f"cannot use the data directory {directory}: {exc}") from None
    except StorageError:
        db.close() if db else None
        raise
    return db, path

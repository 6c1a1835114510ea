"""The kiosk database's schema: a version number and the ordered migrations that reach it.

The version lives in SQLite's ``PRAGMA user_version``. Version 1 is the schema the kiosk shipped
before it had versions (its databases say 0 but already hold the tables; the v1 script only
creates what is missing, so it upgrades them and builds a fresh database alike). Each later
migration is one script run in one transaction with the version bump: a kiosk killed during an
upgrade leaves the old version, never half of the new one. A database written by a newer kiosk
is refused (``SchemaError``): this code would misread what it does not know.

Add a migration by appending to :data:`MIGRATIONS`; never edit one that has shipped.
"""

from __future__ import annotations

import sqlite3

V1 = """
CREATE TABLE IF NOT EXISTS patients (
    id TEXT PRIMARY KEY,
    created_at TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS sessions (
    id TEXT PRIMARY KEY,
    patient_id TEXT NOT NULL REFERENCES patients(id),
    questionnaire_id TEXT NOT NULL,
    language TEXT NOT NULL,
    answered_by TEXT NOT NULL,
    timing TEXT NOT NULL,
    started_at TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('running', 'finished', 'abandoned')),
    finished_at TEXT,
    total INTEGER,
    complete INTEGER,
    band TEXT
);
CREATE TABLE IF NOT EXISTS answers (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    item_id TEXT NOT NULL,
    option INTEGER NOT NULL,
    points INTEGER NOT NULL,
    attempt INTEGER NOT NULL,
    channel TEXT NOT NULL,
    answered_by TEXT NOT NULL,
    t REAL NOT NULL,
    at TEXT NOT NULL,
    detail TEXT NOT NULL DEFAULT '',
    PRIMARY KEY (session_id, item_id)
);
CREATE TABLE IF NOT EXISTS not_answered (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    item_id TEXT NOT NULL,
    t REAL NOT NULL,
    at TEXT NOT NULL,
    PRIMARY KEY (session_id, item_id)
);
CREATE TABLE IF NOT EXISTS practice (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    question_id TEXT NOT NULL,
    checks TEXT NOT NULL,
    outcome TEXT NOT NULL CHECK (outcome IN ('right', 'wrong', 'not_answered', 'skipped')),
    option INTEGER,
    channel TEXT,
    t REAL NOT NULL,
    at TEXT NOT NULL,
    detail TEXT NOT NULL DEFAULT '',
    PRIMARY KEY (session_id, seq)
);
CREATE TABLE IF NOT EXISTS contexts (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    t REAL NOT NULL,
    sets TEXT NOT NULL,
    emits TEXT NOT NULL,
    PRIMARY KEY (session_id, seq)
);
CREATE TABLE IF NOT EXISTS metric_samples (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    t REAL NOT NULL,
    metrics TEXT NOT NULL,
    fired TEXT NOT NULL,
    PRIMARY KEY (session_id, seq)
);
CREATE TABLE IF NOT EXISTS adaptations (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    t REAL NOT NULL,
    name TEXT NOT NULL,
    active INTEGER NOT NULL,
    reason TEXT NOT NULL,
    PRIMARY KEY (session_id, seq)
);
CREATE TABLE IF NOT EXISTS events (
    session_id TEXT NOT NULL REFERENCES sessions(id),
    seq INTEGER NOT NULL,
    t REAL NOT NULL,
    kind TEXT NOT NULL,
    detail TEXT NOT NULL,
    PRIMARY KEY (session_id, seq)
);
"""

# Version 2: interrupted and simulated sessions, the one-kiosk-per-session lease, the station outbox.
# SQLite cannot change a CHECK constraint in place, so the sessions table is rebuilt (foreign keys
# are off while a migration runs). Sessions that `kiosk replay` stored before they were marked are
# recognised by the simulated clock's epoch (its first hour; see kiosk.clock.SIM_EPOCH) in whole
# seconds (scripts start on whole seconds; a real clock's start has microseconds, so a patient
# tested on New Year's night is not taken for a script).
V2 = """
CREATE TABLE sessions_v2 (
    id TEXT PRIMARY KEY,
    patient_id TEXT NOT NULL REFERENCES patients(id),
    questionnaire_id TEXT NOT NULL,
    language TEXT NOT NULL,
    answered_by TEXT NOT NULL,
    timing TEXT NOT NULL,
    started_at TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('running', 'finished', 'abandoned', 'interrupted')),
    finished_at TEXT,
    total INTEGER,
    complete INTEGER,
    band TEXT,
    simulated INTEGER NOT NULL DEFAULT 0,
    interrupted_at TEXT,
    interrupted_reason TEXT
);
INSERT INTO sessions_v2 (id, patient_id, questionnaire_id, language, answered_by, timing, started_at, status,
                         finished_at, total, complete, band, simulated)
    SELECT id, patient_id, questionnaire_id, language, answered_by, timing, started_at, status,
           finished_at, total, complete, band,
           started_at >= '2026-01-01T00:00:00' AND started_at < '2026-01-01T01:00:00'
           AND started_at NOT LIKE '%.%'
    FROM sessions;
DROP TABLE sessions;
ALTER TABLE sessions_v2 RENAME TO sessions;
CREATE TABLE leases (
    session_id TEXT PRIMARY KEY REFERENCES sessions(id),
    host TEXT NOT NULL,
    pid INTEGER NOT NULL,
    token TEXT NOT NULL,
    taken_at REAL NOT NULL,
    renewed_at REAL NOT NULL
);
CREATE TABLE outbox (
    seq INTEGER PRIMARY KEY AUTOINCREMENT,
    kind TEXT NOT NULL,
    session_id TEXT,
    payload TEXT NOT NULL,
    at TEXT NOT NULL,
    alert INTEGER NOT NULL DEFAULT 0,
    parked TEXT
);
"""

#: (version, script) in order; a database at version v runs every script after v
MIGRATIONS: tuple[tuple[int, str], ...] = ((1, V1), (2, V2))
LATEST = MIGRATIONS[-1][0]


class SchemaError(RuntimeError):
    """The database's schema cannot be used by this code (message says which file and what to do)."""


def version(db: sqlite3.Connection) -> int:
    """The database's schema version (0: empty, or written before versions existed)."""
    return int(db.execute("PRAGMA user_version").fetchone()[0])


def _refuse_newer(found: int, name: str) -> None:
    if found > LATEST:
        raise SchemaError(f"{name} has schema version {found}, newer than this kiosk understands (up to "
                          f"{LATEST}): it was written by a newer kiosk. Run that version, or update this one; "
                          "nothing was changed")


def migrate(db: sqlite3.Connection, name: str) -> int:
    """Bring the database up to :data:`LATEST`; returns the version it had. ``db`` is in
    autocommit mode (``isolation_level=None``); ``name`` names the file in messages."""
    found = version(db)
    _refuse_newer(found, name)
    if found == LATEST:
        return found
    db.execute("PRAGMA foreign_keys=OFF")  # a no-op inside a transaction: switched before it
    try:
        # the write lock first: of two kiosks starting together one migrates, the other then sees it done
        db.execute("BEGIN IMMEDIATE")
        try:
            found = version(db)
            _refuse_newer(found, name)
            for number, script in MIGRATIONS:
                if number > found:
                    for statement in _statements(script):
                        db.execute(statement)
            problems = db.execute("PRAGMA foreign_key_check").fetchall()
            if problems:
                raise SchemaError(f"{name}: upgrading to schema version {LATEST} found rows pointing nowhere "
                                  f"({problems[0]}); nothing was changed")
            db.execute(f"PRAGMA user_version = {LATEST}")
            db.execute("COMMIT")
        except BaseException:
            db.execute("ROLLBACK")
            raise
    finally:
        db.execute("PRAGMA foreign_keys=ON")
    return found


def _statements(script: str) -> list[str]:
    """The script's statements (executescript would commit the migration's transaction)."""
    statements, current = [], ""
    for line in script.splitlines(keepends=True):
        current += line
        if sqlite3.complete_statement(current):
            statements.append(current.strip())
            current = ""
    return [s for s in statements if s]

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

import json
import sqlite3
from collections.abc import Callable, Mapping
from datetime import UTC, datetime
from typing import Any

from basis import record
from basis.errors import KioskError
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.questionnaire.definition import canonical, canonical_json, digest

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
# recognised by the simulated clock's epoch (its first hour; see kiosk.core.clock.SIM_EPOCH) in whole
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

# Version 3: the instrument definition each session ran, stored once per content (SHA-256 of its
# canonical JSON, kiosk.core.questionnaire.definition), and the identity it was recorded under (site, kiosk id, FHIR
# systems). Sessions stored before have neither: the upgrade attaches the definition and identity
# in force when it runs (:func:`attach_in_force`) and marks them attached later.
V3 = """
CREATE TABLE definitions (
    sha256 TEXT PRIMARY KEY CHECK (length(sha256) = 64),
    questionnaire_id TEXT NOT NULL,
    version TEXT NOT NULL,
    body TEXT NOT NULL,
    stored_at TEXT NOT NULL
);
ALTER TABLE sessions ADD COLUMN definition TEXT REFERENCES definitions(sha256);
ALTER TABLE sessions ADD COLUMN definition_attached_later INTEGER NOT NULL DEFAULT 0;
ALTER TABLE sessions ADD COLUMN identity TEXT;
ALTER TABLE sessions ADD COLUMN identity_attached_later INTEGER NOT NULL DEFAULT 0;
"""

# Version 4: Timed Up and Go results (issue 34, kiosk.store.tug): times, phases, quality flags, who
# confirmed and who decided; never pictures, landmarks (pose-landmarks/1 text) only where a site keeps them.
V4 = """
CREATE TABLE tug_results (
    id TEXT PRIMARY KEY,
    patient_id TEXT NOT NULL REFERENCES patients(id),
    visit_id TEXT,
    at TEXT NOT NULL,
    confirmed_by TEXT NOT NULL,
    confirmed_t REAL NOT NULL,
    go_t REAL,
    decision TEXT NOT NULL CHECK (decision IN ('accepted', 'stopwatch', 'rejected')),
    decided_by TEXT NOT NULL,
    total_s REAL,
    method TEXT CHECK (method IN ('camera', 'stopwatch')),
    camera_total_s REAL,
    phases TEXT NOT NULL,
    reasons TEXT NOT NULL,
    person_share REAL NOT NULL,
    body_cut_off INTEGER NOT NULL,
    turn_seen INTEGER NOT NULL,
    threshold_s REAL NOT NULL,
    get_up_go INTEGER CHECK (get_up_go BETWEEN 1 AND 5),
    walking_aid TEXT,
    landmarks TEXT
);
"""

#: (version, script) in order; a database at version v runs every script after v
MIGRATIONS: tuple[tuple[int, str], ...] = ((1, V1), (2, V2), (3, V3), (4, V4))
LATEST = MIGRATIONS[-1][0]


@record
class InForce:
    """What describes sessions recorded before definitions were captured: the definition (canonical
    JSON, :func:`kiosk.core.questionnaire.definition.canonical`) and identity (site, kiosk id, FHIR systems) in force
    when the database is upgraded."""

    definition: Mapping[str, Any]
    identity: Mapping[str, str]
    #: when the upgrade ran (ISO 8601 UTC)
    at: str = ""


def bundled_in_force(export: Mapping[str, str], wall: Callable[[], float]) -> Callable[[], InForce]:
    """The default :class:`InForce`: the bundled questionnaire (loaded only when asked) and ``export``."""

    def now() -> InForce:
        at = datetime.fromtimestamp(wall(), UTC).isoformat().replace("+00:00", "Z")
        return InForce(canonical(load_questionnaire()), dict(export), at)

    return now


def store_definition(db: sqlite3.Connection, definition: Mapping[str, Any], at: str) -> str:
    """Store a definition once (by its content address) in the current transaction; returns its SHA-256."""
    sha = digest(definition)
    db.execute(
        "INSERT OR IGNORE INTO definitions (sha256, questionnaire_id, version, body, stored_at) VALUES (?, ?, ?, ?, ?)",
        (sha, str(definition.get("id", "")), str(definition.get("version", "")), canonical_json(definition), at),
    )
    return sha


def attach_in_force(db: sqlite3.Connection, in_force: InForce) -> None:
    """Give every session without a captured definition or identity the ones in force, marked
    attached later; pending outbox rows that create such a session carry them too (the station
    then marks them alike)."""
    missing = db.execute("SELECT COUNT(*) FROM sessions WHERE definition IS NULL OR identity IS NULL").fetchone()[0]
    if not missing:
        return
    sha = store_definition(db, in_force.definition, in_force.at)
    db.execute("UPDATE sessions SET definition = ?, definition_attached_later = 1 WHERE definition IS NULL", (sha,))
    db.execute(
        "UPDATE sessions SET identity = ?, identity_attached_later = 1 WHERE identity IS NULL",
        (json.dumps(dict(in_force.identity), sort_keys=True),),
    )
    for seq, payload in db.execute("SELECT seq, payload FROM outbox WHERE kind = 'create_session'").fetchall():
        body = json.loads(payload)
        if "definition" in body:
            continue
        body |= {"definition": dict(in_force.definition), "definition_sha256": sha, "definition_attached_later": True}
        if not body.get("export"):
            body |= {"export": dict(in_force.identity), "export_attached_later": True}
        db.execute("UPDATE outbox SET payload = ? WHERE seq = ?", (json.dumps(body, ensure_ascii=False), seq))


class SchemaError(KioskError, RuntimeError):
    """The database's schema cannot be used by this code (message says which file and what to do)."""


def version(db: sqlite3.Connection) -> int:
    """The database's schema version (0: empty, or written before versions existed)."""
    return int(db.execute("PRAGMA user_version").fetchone()[0])


def _refuse_newer(found: int, name: str) -> None:
    if found > LATEST:
        raise SchemaError(
            f"{name} has schema version {found}, newer than this kiosk understands (up to "
            f"{LATEST}): it was written by a newer kiosk. Run that version, or update this one; "
            "nothing was changed"
        )


def migrate(db: sqlite3.Connection, name: str, in_force: Callable[[], InForce] | None = None) -> int:
    """Bring the database up to :data:`LATEST`; returns the version it had. ``db`` is in
    autocommit mode (``isolation_level=None``); ``name`` names the file in messages; ``in_force``
    gives what version 3 attaches to the sessions stored before it (asked only when there are
    some; without it such an upgrade is refused)."""
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
            if found < 3 and db.execute("SELECT 1 FROM sessions WHERE definition IS NULL LIMIT 1").fetchone():
                if in_force is None:
                    raise SchemaError(
                        f"{name}: upgrading to schema version {LATEST} needs the questionnaire and "
                        "identity in force to attach to the sessions stored before; nothing was changed"
                    )
                try:
                    now = in_force()
                except ValueError as exc:  # the configuration or questionnaire file in force is unusable
                    raise SchemaError(
                        f"{name}: upgrading to schema version {LATEST} attaches the questionnaire "
                        f"in force to the sessions stored before, but it cannot be read ({exc}); "
                        "nothing was changed"
                    ) from None
                attach_in_force(db, now)
            problems = db.execute("PRAGMA foreign_key_check").fetchall()
            if problems:
                raise SchemaError(
                    f"{name}: upgrading to schema version {LATEST} found rows pointing nowhere "
                    f"({problems[0]}); nothing was changed"
                )
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

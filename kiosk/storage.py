"""Safe storage of sessions in SQLite (stdlib ``sqlite3``).

One database file in the kiosk's data directory (directory 0700, files 0600), in WAL mode with
``synchronous=FULL``: every call that records something commits before it returns, so a kiosk
killed mid-session (power cut, SIGKILL) loses no recorded answer. The next start finds the session
in :meth:`Store.unfinished_sessions` and can continue it at the first question without an outcome
(:meth:`kiosk.session.Session.from_stored`).

Stored per session: the patient's pseudonymous id (never a name), answers (item, option, points,
attempt, channel, who answered, time), questions not answered, the familiarisation's practice
outcomes (right, wrong, not answered, skipped; never part of the QoS trace), the QoS context trace, a metric
sample after each QoS update, adaptation events and the session log (incidents, ignored inputs).
A stored total is kept for listing only; results always recompute it from the answers.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import secrets
import sqlite3
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kiosk.channels import Channel
from kiosk.session import Answer, AnsweredBy

DB_NAME = "kiosk.sqlite3"
#: a pseudonymous patient id: letters, digits, '-' and '_', no spaces (so not "Ann Smith")
PATIENT_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{1,63}$")

_SCHEMA = """
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


class StorageError(RuntimeError):
    """The data directory or database cannot be used (message says where and why)."""


def new_patient_id() -> str:
    """A fresh random pseudonymous patient id, e.g. ``P-7K3Q-X9M4-TB2H``.

    60 random bits: across a hospital's kiosks, a clash among a million patients has a chance of
    about 4 in 10 million (six characters, as before, gave 5 % among 10,000). Ids stored with the
    older, shorter form stay valid."""
    alphabet = "ABCDEFGHJKLMNPQRSTUVWXYZ23456789"  # no 0/O, 1/I: read aloud and typed by staff
    return "P-" + "-".join("".join(secrets.choice(alphabet) for _ in range(4)) for _ in range(3))


@dataclass(frozen=True)
class SessionSummary:
    """One line of the session list. ``total`` is as stored; results recompute it."""

    id: str
    patient_id: str
    started_at: str
    finished_at: str | None
    status: str
    language: str
    answered: int
    not_answered: int


@dataclass(frozen=True)
class MetricSample:
    """The QoS metrics after one update, and what fired."""

    t: float
    metrics: Mapping[str, float]
    fired: tuple[str, ...]


@dataclass(frozen=True)
class AdaptationRecord:
    """An adaptation switched on or off during a session."""

    t: float
    name: str
    active: bool
    reason: str


@dataclass(frozen=True)
class PracticeRecord:
    """How one familiarisation question went: it checks whether the patient can hear, read or choose."""

    question_id: str
    #: "hear", "read" or "select"
    checks: str
    #: "right", "wrong", "not_answered" or "skipped"
    outcome: str
    #: the option chosen (None when not answered or skipped)
    option: int | None
    channel: Channel | None
    t: float
    #: the input's detail for an answer; why it was skipped ("no voice out")
    detail: str = ""


@dataclass(frozen=True)
class LogEntry:
    """A line of the session log (start, pause, ignored input, ...)."""

    t: float
    kind: str
    detail: str


@dataclass(frozen=True)
class StoredSession:
    """Everything stored about one session."""

    id: str
    patient_id: str
    questionnaire_id: str
    language: str
    answered_by: AnsweredBy
    timing: Mapping[str, float]
    started_at: str
    status: str
    finished_at: str | None
    answers: tuple[Answer, ...]
    not_answered: tuple[str, ...]
    #: the context trace: [{"t":..., "set": {...}, "emit": [...]}] in recording order
    trace: tuple[dict[str, Any], ...]
    metrics: tuple[MetricSample, ...]
    adaptations: tuple[AdaptationRecord, ...]
    log: tuple[LogEntry, ...]
    #: the familiarisation's outcomes, in the order they happened (empty without practice)
    practice: tuple[PracticeRecord, ...] = ()


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


class Store:
    """The session database. Not shared between threads: use it from the session's thread."""

    def __init__(self, connection: sqlite3.Connection, path: Path) -> None:
        self._db = connection
        self.path = path
        #: depth of nested transaction() blocks; writes inside them commit when the outermost ends
        self._grouping = 0

    @classmethod
    def open(cls, data_dir: str | Path, create: bool = True) -> Store:
        """Open the database in ``data_dir``, creating both if needed; with ``create=False`` (the
        tools that only read, where a mistyped directory must not become an empty database) a
        missing directory or database is a StorageError."""
        directory = Path(data_dir).expanduser()
        path = directory / DB_NAME
        if not create:
            if not directory.is_dir():
                raise StorageError(f"no data directory {directory}")
            if not path.is_file():
                raise StorageError(f"no session database in {directory} (expected {DB_NAME}; nothing stored there)")
        try:
            _secure_dir(directory)
            _secure_file(path)
            db = sqlite3.connect(path, isolation_level=None)
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=FULL")
            db.execute("PRAGMA foreign_keys=ON")
            db.executescript(_SCHEMA)
        except (OSError, sqlite3.Error) as exc:
            raise StorageError(f"cannot use the data directory {directory}: {exc}") from None
        return cls(db, path)

    def close(self) -> None:
        """Close the database (everything is already committed)."""
        self._db.close()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextlib.contextmanager
    def transaction(self) -> Iterator[None]:
        """Group writes into one commit (fsynced): a crash keeps all of them or none.

        The session runs each of its operations in one, so an answer is never stored without the
        QoS context batch it published. Nested use joins the outer transaction. What was written is
        committed even if the block raises: recorded answers are never thrown away.

        The transaction begins with its first write, so an operation that writes nothing (most
        polls of the attempt clock) takes no write lock and syncs nothing.
        """
        self._grouping += 1
        try:
            yield
        finally:
            self._grouping -= 1
            if not self._grouping and self._db.in_transaction:
                self._db.commit()

    def _write(self, sql: str, args: tuple[Any, ...]) -> None:
        with self.transaction():
            if not self._db.in_transaction:
                self._db.execute("BEGIN IMMEDIATE")
            self._db.execute(sql, args)

    def _next_seq(self, table: str, session_id: str) -> int:
        row = self._db.execute(f"SELECT COALESCE(MAX(seq), -1) + 1 FROM {table} WHERE session_id = ?",
                               (session_id,)).fetchone()
        return int(row[0])

    # -- writing (kiosk.session.SessionStore) ----------------------------------------------------

    def create_session(self, *, session_id: str, patient_id: str, questionnaire_id: str, language: str,
                       answered_by: str, started_at: str, timing: Mapping[str, float]) -> None:
        """Record a new running session (and its patient, the first time)."""
        if not PATIENT_ID.match(patient_id):
            raise ValueError(f"patient id {patient_id!r} is not a pseudonymous id "
                             "(2-64 letters, digits, '-' or '_'; never a name)")
        with self.transaction():
            self._write("INSERT OR IGNORE INTO patients (id, created_at) VALUES (?, ?)", (patient_id, started_at))
            self._write(
                "INSERT INTO sessions (id, patient_id, questionnaire_id, language, answered_by, timing, started_at,"
                " status) VALUES (?, ?, ?, ?, ?, ?, ?, 'running')",
                (session_id, patient_id, questionnaire_id, language, answered_by, json.dumps(dict(timing)), started_at),
            )

    def record_answer(self, session_id: str, *, item_id: str, option: int, points: int, attempt: int,
                      channel: str, answered_by: str, t: float, at: str, detail: str = "") -> None:
        """Commit one answer."""
        self._write("INSERT INTO answers VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (session_id, item_id, option, points, attempt, channel, answered_by, t, at, detail))

    def record_not_answered(self, session_id: str, *, item_id: str, t: float, at: str) -> None:
        """Commit that both attempts of a question timed out."""
        self._write("INSERT INTO not_answered VALUES (?, ?, ?, ?)", (session_id, item_id, t, at))

    def record_practice(self, session_id: str, *, question_id: str, checks: str, outcome: str, option: int | None,
                        channel: str | None, t: float, at: str, detail: str = "") -> None:
        """Commit a practice question's outcome ("right", "wrong", "not_answered" or "skipped")."""
        self._write("INSERT INTO practice VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (session_id, self._next_seq("practice", session_id), question_id, checks, outcome, option,
                     channel, t, at, detail))

    def record_context(self, session_id: str, *, t: float, set: Mapping[str, Any], emit: list[str]) -> None:
        """Commit one batch of the session's QoS context trace."""
        self._write("INSERT INTO contexts VALUES (?, ?, ?, ?, ?)",
                    (session_id, self._next_seq("contexts", session_id), t, json.dumps(dict(set)), json.dumps(list(emit))))

    def record_metrics(self, session_id: str, *, t: float, metrics: Mapping[str, float], fired: list[str]) -> None:
        """Commit the QoS metrics after one update."""
        self._write("INSERT INTO metric_samples VALUES (?, ?, ?, ?, ?)",
                    (session_id, self._next_seq("metric_samples", session_id), t, json.dumps(dict(metrics)),
                     json.dumps(list(fired))))

    def record_adaptation(self, session_id: str, *, t: float, name: str, active: bool, reason: str) -> None:
        """Commit an adaptation switched on or off."""
        self._write("INSERT INTO adaptations VALUES (?, ?, ?, ?, ?, ?)",
                    (session_id, self._next_seq("adaptations", session_id), t, name, int(active), reason))

    def record_event(self, session_id: str, *, t: float, kind: str, detail: str = "") -> None:
        """Commit a line of the session log."""
        self._write("INSERT INTO events VALUES (?, ?, ?, ?, ?)",
                    (session_id, self._next_seq("events", session_id), t, kind, detail))

    def finish_session(self, session_id: str, *, finished_at: str, total: int, complete: bool,
                       band: str | None) -> None:
        """Mark a session finished (the total is kept for listing; results recompute it)."""
        self._write("UPDATE sessions SET status = 'finished', finished_at = ?, total = ?, complete = ?, band = ?"
                    " WHERE id = ?", (finished_at, total, int(complete), band, session_id))

    def abandon(self, session_id: str) -> None:
        """Mark an unfinished session as not to be resumed (its answers stay)."""
        self._write("UPDATE sessions SET status = 'abandoned' WHERE id = ? AND status = 'running'", (session_id,))

    # -- reading ------------------------------------------------------------------------------------

    def sessions(self) -> list[SessionSummary]:
        """Every stored session, newest first."""
        rows = self._db.execute(
            "SELECT s.id, s.patient_id, s.started_at, s.finished_at, s.status, s.language,"
            " (SELECT COUNT(*) FROM answers a WHERE a.session_id = s.id),"
            " (SELECT COUNT(*) FROM not_answered n WHERE n.session_id = s.id)"
            " FROM sessions s ORDER BY s.started_at DESC, s.rowid DESC").fetchall()
        return [SessionSummary(*row) for row in rows]

    def unfinished_sessions(self) -> list[StoredSession]:
        """Sessions that were running when the kiosk stopped (crash, power cut), newest first."""
        ids = [r[0] for r in self._db.execute(
            "SELECT id FROM sessions WHERE status = 'running' ORDER BY started_at DESC, rowid DESC")]
        return [self.session(i) for i in ids]

    def resolve(self, ref: str) -> str:
        """A session id from a full id or a unique prefix; KeyError naming the problem otherwise."""
        rows = [r[0] for r in self._db.execute("SELECT id FROM sessions WHERE substr(id, 1, ?) = ?",
                                               (len(ref), ref))]
        if ref in rows:
            return ref
        if len(rows) == 1:
            return rows[0]
        raise KeyError(f"no session {ref!r}" if not rows else f"{ref!r} matches {len(rows)} sessions; give more of the id")

    def session(self, ref: str) -> StoredSession:
        """Everything stored about one session (full id or unique prefix)."""
        session_id = self.resolve(ref)
        row = self._db.execute(
            "SELECT id, patient_id, questionnaire_id, language, answered_by, timing, started_at, status, finished_at"
            " FROM sessions WHERE id = ?", (session_id,)).fetchone()
        answers = tuple(
            Answer(item_id, option, points, attempt, Channel(channel), AnsweredBy(by), t, detail)
            for item_id, option, points, attempt, channel, by, t, detail in self._db.execute(
                "SELECT item_id, option, points, attempt, channel, answered_by, t, detail FROM answers"
                " WHERE session_id = ? ORDER BY t, rowid", (session_id,))
        )
        not_answered = tuple(r[0] for r in self._db.execute(
            "SELECT item_id FROM not_answered WHERE session_id = ? ORDER BY t, rowid", (session_id,)))
        trace = []
        for t, sets, emits in self._db.execute(
                "SELECT t, sets, emits FROM contexts WHERE session_id = ? ORDER BY seq", (session_id,)):
            event: dict[str, Any] = {"t": t}
            if json.loads(sets):
                event["set"] = json.loads(sets)
            if json.loads(emits):
                event["emit"] = json.loads(emits)
            trace.append(event)
        metrics = tuple(MetricSample(t, json.loads(m), tuple(json.loads(f))) for t, m, f in self._db.execute(
            "SELECT t, metrics, fired FROM metric_samples WHERE session_id = ? ORDER BY seq", (session_id,)))
        adaptations = tuple(AdaptationRecord(t, n, bool(a), r) for t, n, a, r in self._db.execute(
            "SELECT t, name, active, reason FROM adaptations WHERE session_id = ? ORDER BY seq", (session_id,)))
        log = tuple(LogEntry(*r) for r in self._db.execute(
            "SELECT t, kind, detail FROM events WHERE session_id = ? ORDER BY seq", (session_id,)))
        practice = tuple(
            PracticeRecord(q, c, o, opt, Channel(ch) if ch else None, t, d)
            for q, c, o, opt, ch, t, d in self._db.execute(
                "SELECT question_id, checks, outcome, option, channel, t, detail FROM practice"
                " WHERE session_id = ? ORDER BY seq", (session_id,)))
        return StoredSession(
            id=row[0], patient_id=row[1], questionnaire_id=row[2], language=row[3], answered_by=AnsweredBy(row[4]),
            timing=json.loads(row[5]), started_at=row[6], status=row[7], finished_at=row[8], answers=answers,
            not_answered=not_answered, trace=tuple(trace), metrics=metrics, adaptations=adaptations, log=log,
            practice=practice,
        )

"""Safe storage of sessions in SQLite (stdlib ``sqlite3``).

One database file in the kiosk's data directory (directory 0700, files 0600), in WAL mode with
``synchronous=FULL``. Each session operation is one transaction (:meth:`Store.transaction`):
an answer is committed together with its QoS context and metrics before anyone learns of it, and
an operation cut short (an exception, Ctrl-C, a kill) keeps none of its writes. The schema has a
version and ordered migrations (:mod:`kiosk.store.migrations`); a damaged file is refused with one message.

One running kiosk holds a session at a time (a lease, :mod:`kiosk.store.lease`): it is taken when the
session is created or continued, checked in every write transaction, renewed while the kiosk
runs and released when it stops. A running session whose kiosk is gone, or older than the
configured limit, is marked *interrupted* (:meth:`Store.interrupt_stale`); only staff continue
one (:meth:`Store.continue_session`), never a patient. Sessions of scripted patients
(``kiosk replay``) are stored *simulated* and are never offered.

With ``outbox=True`` (a ward station is configured) every stored change is also written, in the
same transaction, as a row of the ``outbox`` table that ``kiosk.sync`` delivers
(``docs/station-protocol.md`` §1). Without it nothing is queued.

Stored per session: the patient's pseudonymous id (never a name), answers (item, option, points,
attempt, channel, who answered, time), questions not answered, the familiarisation's practice
outcomes (right, wrong, not answered, skipped; never part of the QoS trace), the QoS context trace, a metric
sample after each QoS update, adaptation events and the session log (incidents, ignored inputs).
A stored total is kept for listing only; results always recompute it from the answers.

Each session also keeps what describes it: the exact instrument definition it ran (canonical JSON,
:mod:`kiosk.core.questionnaire.definition`, stored once per content in ``definitions`` and referenced by SHA-256) and
the identity it was recorded under (site, kiosk id, FHIR systems: the ``export`` the store was
opened with). Exports, the clinician's screens and the station describe the session with those,
never with the questionnaire file or configuration current when they run.
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import re
import secrets
import sqlite3
import time
from collections.abc import Callable, Iterator, Mapping
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from kiosk.core.channels import Channel
from kiosk.core.session import Answer, AnsweredBy
from kiosk.store.custody import Custody
from kiosk.store.lease import LEASE_TTL_S, Owner, SessionTaken
from kiosk.store.migrations import (
    InForce,
    SchemaError,
    bundled_in_force,
    migrate,
    store_definition,
)
from kiosk.store.records import (
    AdaptationRecord,
    LogEntry,
    MetricSample,
    PracticeRecord,
    SessionSummary,
    StoredSession,
)

__all__ = [
    "DB_NAME",
    "PATIENT_ID",
    "AdaptationRecord",
    "LogEntry",
    "MetricSample",
    "PracticeRecord",
    "SessionSummary",
    "SessionTaken",
    "StorageError",
    "Store",
    "StoredSession",
    "new_patient_id",
]

DB_NAME = "kiosk.sqlite3"
#: a pseudonymous patient id: letters, digits, '-' and '_', no spaces (so not "Ann Smith"); the
#: (?!\n) keeps a final line break out, which a bare '$' lets through (the script schema's pattern)
PATIENT_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{1,63}(?!\n)$")
#: how long a write waits for another kiosk's transaction on the same file before giving up
BUSY_TIMEOUT_S = 10.0
#: session-log kinds that are alerts for the ward, with the name the station protocol gives them
ALERT_EVENTS = {
    "call_doctor": "doctor_called",
    "clinician_continue": "doctor_continued",
    "person_lost": "person_lost",
    "person_back": "person_back",
}


class StorageError(RuntimeError):
    """The data directory or database cannot be used (message says where and why)."""


def new_patient_id() -> str:
    """A fresh random pseudonymous patient id, e.g. ``P-7K3Q-X9M4-TB2H``.

    60 random bits: across a hospital's kiosks, a clash among a million patients has a chance of
    about 4 in 10 million (six characters, as before, gave 5 % among 10,000). Ids stored with the
    older, shorter form stay valid."""
    alphabet = "ABCDEFGHJKLMNPQRSTUVWXYZ23456789"  # no 0/O, 1/I: read aloud and typed by staff
    return "P-" + "-".join("".join(secrets.choice(alphabet) for _ in range(4)) for _ in range(3))


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
    return StorageError(
        f"{path} is damaged ({exc}); nothing was changed. Stop the kiosk, keep a copy of {path.name} "
        f"(and {path.name}-wal, -shm if present) for the engineers, then move them out of {path.parent} "
        "and restore a backup, or start with an empty database"
    )


#: the tables every database of this schema has (a dropped one is damage, found at open)
_TABLES = (
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
)


def _reading(method: Callable[..., Any]) -> Callable[..., Any]:
    """A reading method whose rows this code cannot read (a value no kiosk writes, such as an
    unknown channel, or SQL that fails on an edited file) raises one StorageError naming the
    database, instead of a traceback from deep inside. KeyError (no such session) passes."""

    @functools.wraps(method)
    def read(self: Store, *args: Any) -> Any:
        try:
            return method(self, *args)
        except (sqlite3.Error, ValueError, TypeError) as exc:
            if isinstance(exc, sqlite3.OperationalError) and "locked" in str(exc):  # busy, not damaged
                raise StorageError(f"{self.path} is busy (another kiosk is writing); try again") from None
            raise StorageError(
                f"{self.path} holds what this kiosk cannot read ({exc}); nothing was changed. "
                "Keep a copy for the engineers and restore a backup"
            ) from None

    return read


def _is_damage(exc: sqlite3.DatabaseError) -> bool:
    message = str(exc).lower()
    return type(exc) is sqlite3.DatabaseError or "malformed" in message or "not a database" in message


class Store(Custody):
    """The session database. Not shared between threads: use it from the session's thread.

    ``owner`` is this kiosk process (leases name it); ``simulated`` marks every session it creates
    as a scripted patient's; ``outbox`` queues every change for the ward station;
    ``interrupt_after_s`` is the age after which a running session counts as interrupted (None: no
    limit); ``wall`` gives the epoch seconds leases are dated with; ``export`` (the fields of
    :class:`kiosk.export.ExportSite`) is the identity each new session is recorded under, and goes
    to the station with it (without it none is sent, and exports name the defaults: site ``local``,
    the kiosk id of the host or of the station's kiosk); ``in_force``
    gives the definition and identity attached to sessions stored before they were captured (an
    upgrade) and the definition of a session created without one (default: the bundled
    questionnaire and ``export``).
    """

    def __init__(
        self,
        connection: sqlite3.Connection,
        path: Path,
        *,
        owner: Owner | None = None,
        simulated: bool = False,
        outbox: bool = False,
        interrupt_after_s: float | None = None,
        lease_ttl_s: float = LEASE_TTL_S,
        wall: Callable[[], float] = time.time,
        export: Mapping[str, str] | None = None,
        in_force: Callable[[], InForce] | None = None,
    ) -> None:
        self._db = connection
        #: how this kiosk's exports name things (site, kiosk, FHIR systems), sent to the station with
        #: each new session so that the station's exports of it carry the same identifiers
        self.export = dict(export or {})
        self._in_force = in_force or bundled_in_force(self.export, wall)
        self.path = path
        self.owner = owner or Owner()
        self.simulated = simulated
        self.outbox = outbox
        self.interrupt_after_s = interrupt_after_s
        self.lease_ttl_s = lease_ttl_s
        self._wall = wall
        #: depth of nested transaction() blocks; writes inside them commit when the outermost ends
        self._grouping = 0
        #: sessions whose lease this transaction has checked (a check per transaction is enough: it
        #: holds the write lock, so no other kiosk can take the lease before it ends)
        self._held: set[str] = set()
        #: outbox rows written in this transaction: (any, any alert)
        self._queued = (False, False)
        #: called after a commit that queued outbox rows (True: one is an alert): the sync client's wake-up
        self.on_outbox: Callable[[bool], None] | None = None

    @classmethod
    def open(cls, data_dir: str | Path, create: bool = True, **options: Any) -> Store:
        """Open the database in ``data_dir``, creating both if needed, and bring its schema up to
        date; with ``create=False`` (the tools that only read, where a mistyped directory must not
        become an empty database) a missing directory or database is a StorageError. ``options``
        are the constructor's keywords."""
        if any(not c.isprintable() for c in str(data_dir)):
            raise StorageError(
                f"the data directory {str(data_dir)!r} holds a control character or bytes that are not UTF-8"
            )
        try:
            directory = Path(data_dir).expanduser()
        except RuntimeError:  # ~user for a user this machine does not have
            raise StorageError(f"no data directory {data_dir} (no such user to expand ~ for)") from None
        in_force = options.setdefault(
            "in_force", bundled_in_force(options.get("export") or {}, options.get("wall", time.time))
        )
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
            if missing := [t for t in _TABLES if t not in tables]:
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
        return cls(db, path, **options)

    def close(self) -> None:
        """Release this kiosk's leases (a session still running is marked interrupted: its kiosk
        was closed) and close the database."""
        try:
            for session_id in self._my_sessions():
                self.release(session_id, "its kiosk was closed")
        except sqlite3.Error:
            pass  # closing must not fail: whatever is left lapses with this process
        finally:
            self._db.close()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextlib.contextmanager
    def transaction(self) -> Iterator[None]:
        """Group writes into one commit (fsynced): a crash keeps all of them or none.

        The session runs each of its operations in one, so an answer is never stored without the
        QoS context batch it published. Nested use joins the outer transaction. If the outermost
        block raises (an error, Ctrl-C) everything it wrote is rolled back: half an operation is
        never stored.

        The transaction begins with its first write, so an operation that writes nothing (most
        polls of the attempt clock) takes no write lock and syncs nothing.
        """
        self._grouping += 1
        completed = False
        try:
            yield
            completed = True
        finally:
            self._grouping -= 1
            if not self._grouping and self._db.in_transaction:
                if completed:
                    self._commit()
                else:
                    self._rollback()

    def _commit(self) -> None:
        try:
            self._db.commit()
        except BaseException:
            self._rollback()
            raise
        queued, alert = self._queued
        self._held.clear()
        self._queued = (False, False)
        if queued and self.on_outbox is not None:
            self.on_outbox(alert)

    def _rollback(self) -> None:
        self._held.clear()
        self._queued = (False, False)
        if self._db.in_transaction:
            self._db.rollback()

    def _write(self, sql: str, args: tuple[Any, ...], session: str | None = None) -> None:
        """One statement in the current transaction; with ``session``, only while this kiosk holds it."""
        with self.transaction():
            if not self._db.in_transaction:
                self._db.execute("BEGIN IMMEDIATE")
            if session is not None and session not in self._held:
                self._check_held(session)
            self._db.execute(sql, args)

    def _record(self, kind: str, session_id: str, payload: dict[str, Any], sql: str, args: tuple[Any, ...]) -> None:
        """A change to a held session, and its outbox row, in one transaction."""
        with self.transaction():
            self._write(sql, args, session=session_id)
            self._queue(kind, session_id, payload)

    def _queue(self, kind: str, session_id: str | None, payload: dict[str, Any]) -> None:
        """The change's outbox row (protocol §1), when a station is configured."""
        if not self.outbox:
            return
        alert = kind == "record_event" and payload.get("kind") in ALERT_EVENTS
        if alert:
            payload = {**payload, "kind": ALERT_EVENTS[payload["kind"]]}
        self._db.execute(
            "INSERT INTO outbox (kind, session_id, payload, at, alert) VALUES (?, ?, ?, ?, ?)",
            (kind, session_id, json.dumps(payload, ensure_ascii=False), self._iso_now(), int(alert)),
        )
        self._queued = (True, self._queued[1] or alert)

    def _next_seq(self, table: str, session_id: str) -> int:
        row = self._db.execute(
            f"SELECT COALESCE(MAX(seq), -1) + 1 FROM {table} WHERE session_id = ?", (session_id,)
        ).fetchone()
        return int(row[0])

    def _iso_now(self) -> str:
        return datetime.fromtimestamp(self._wall(), timezone.utc).isoformat().replace("+00:00", "Z")

    # -- writing (kiosk.core.session.SessionStore) ----------------------------------------------------

    def create_session(
        self,
        *,
        session_id: str,
        patient_id: str,
        questionnaire_id: str,
        language: str,
        answered_by: str,
        started_at: str,
        timing: Mapping[str, float],
        definition: Mapping[str, Any] | None = None,
    ) -> None:
        """Record a new running session (and its patient, the first time), held by this kiosk, with
        the definition it runs (:func:`kiosk.core.questionnaire.definition.canonical`; None: the one in force, marked
        attached later) and this store's identity."""
        if not PATIENT_ID.match(patient_id):
            raise ValueError(
                f"patient id {patient_id!r} is not a pseudonymous id (2-64 letters, digits, '-' or '_'; never a name)"
            )
        later = definition is None
        if definition is None:
            definition = self._in_force().definition
        with self.transaction():
            self._write("INSERT OR IGNORE INTO patients (id, created_at) VALUES (?, ?)", (patient_id, started_at))
            sha = store_definition(self._db, definition, self._iso_now())
            self._write(
                "INSERT INTO sessions (id, patient_id, questionnaire_id, language, answered_by, timing, started_at,"
                " status, simulated, definition, definition_attached_later, identity)"
                " VALUES (?, ?, ?, ?, ?, ?, ?, 'running', ?, ?, ?, ?)",
                (
                    session_id,
                    patient_id,
                    questionnaire_id,
                    language,
                    answered_by,
                    json.dumps(dict(timing)),
                    started_at,
                    int(self.simulated),
                    sha,
                    int(later),
                    json.dumps(self.export, sort_keys=True),
                ),
            )
            self._take(session_id)
            self._queue(
                "create_session",
                session_id,
                {
                    "session_id": session_id,
                    "patient_id": patient_id,
                    "questionnaire_id": questionnaire_id,
                    "language": language,
                    "answered_by": answered_by,
                    "started_at": started_at,
                    "timing": dict(timing),
                    "simulated": self.simulated,
                    **({"export": self.export} if self.export else {}),
                    "definition": dict(definition),
                    "definition_sha256": sha,
                    **({"definition_attached_later": True} if later else {}),
                },
            )

    def record_answer(
        self,
        session_id: str,
        *,
        item_id: str,
        option: int,
        points: int,
        attempt: int,
        channel: str,
        answered_by: str,
        t: float,
        at: str,
        detail: str = "",
    ) -> None:
        """Store one answer."""
        self._record(
            "record_answer",
            session_id,
            {
                "item_id": item_id,
                "option": option,
                "points": points,
                "attempt": attempt,
                "channel": channel,
                "answered_by": answered_by,
                "t": t,
                "at": at,
                "detail": detail,
            },
            "INSERT INTO answers VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (session_id, item_id, option, points, attempt, channel, answered_by, t, at, detail),
        )

    def withdraw_answer(self, session_id: str, *, item_id: str, t: float, at: str, reason: str) -> None:
        """Take back a committed answer (the patient's "Change my answer"): its row is deleted and
        the session log keeps what it was (an ``answer_withdrawn`` event, detail JSON), in one commit."""
        row = self._db.execute(
            "SELECT option, points, attempt, channel, answered_by, t, at, detail FROM answers"
            " WHERE session_id = ? AND item_id = ?",
            (session_id, item_id),
        ).fetchone()
        if row is None:
            raise KeyError(f"session {session_id} has no answer to {item_id!r} to withdraw")
        withdrawn = dict(zip(("option", "points", "attempt", "channel", "answered_by", "t", "at", "detail"), row))
        with self.transaction():
            self._record(
                "withdraw_answer",
                session_id,
                {"item_id": item_id, "t": t, "at": at, "reason": reason},
                "DELETE FROM answers WHERE session_id = ? AND item_id = ?",
                (session_id, item_id),
            )
            self.record_event(
                session_id,
                t=t,
                kind="answer_withdrawn",
                detail=json.dumps(
                    {"item": item_id, "withdrawn": withdrawn, "at": at, "reason": reason}, ensure_ascii=False
                ),
            )

    def record_not_answered(self, session_id: str, *, item_id: str, t: float, at: str) -> None:
        """Store that both attempts of a question timed out."""
        self._record(
            "record_not_answered",
            session_id,
            {"item_id": item_id, "t": t, "at": at},
            "INSERT INTO not_answered VALUES (?, ?, ?, ?)",
            (session_id, item_id, t, at),
        )

    def record_practice(
        self,
        session_id: str,
        *,
        question_id: str,
        checks: str,
        outcome: str,
        option: int | None,
        channel: str | None,
        t: float,
        at: str,
        detail: str = "",
    ) -> None:
        """Store a practice question's outcome ("right", "wrong", "not_answered" or "skipped")."""
        self._record(
            "record_practice",
            session_id,
            {
                "question_id": question_id,
                "checks": checks,
                "outcome": outcome,
                "option": option,
                "channel": channel,
                "t": t,
                "at": at,
                "detail": detail,
            },
            "INSERT INTO practice VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (
                session_id,
                self._next_seq("practice", session_id),
                question_id,
                checks,
                outcome,
                option,
                channel,
                t,
                at,
                detail,
            ),
        )

    def record_context(self, session_id: str, *, t: float, set: Mapping[str, Any], emit: list[str]) -> None:
        """Store one batch of the session's QoS context trace."""
        self._record(
            "record_context",
            session_id,
            {"t": t, "set": dict(set), "emit": list(emit)},
            "INSERT INTO contexts VALUES (?, ?, ?, ?, ?)",
            (session_id, self._next_seq("contexts", session_id), t, json.dumps(dict(set)), json.dumps(list(emit))),
        )

    def record_metrics(self, session_id: str, *, t: float, metrics: Mapping[str, float], fired: list[str]) -> None:
        """Store the QoS metrics after one update."""
        self._record(
            "record_metrics",
            session_id,
            {"t": t, "metrics": dict(metrics), "fired": list(fired)},
            "INSERT INTO metric_samples VALUES (?, ?, ?, ?, ?)",
            (
                session_id,
                self._next_seq("metric_samples", session_id),
                t,
                json.dumps(dict(metrics)),
                json.dumps(list(fired)),
            ),
        )

    def record_adaptation(self, session_id: str, *, t: float, name: str, active: bool, reason: str) -> None:
        """Store an adaptation switched on or off."""
        self._record(
            "record_adaptation",
            session_id,
            {"t": t, "name": name, "active": active, "reason": reason},
            "INSERT INTO adaptations VALUES (?, ?, ?, ?, ?, ?)",
            (session_id, self._next_seq("adaptations", session_id), t, name, int(active), reason),
        )

    def record_event(self, session_id: str, *, t: float, kind: str, detail: str = "") -> None:
        """Store a line of the session log (a call for the doctor, a patient leaving: alerts first)."""
        self._record(
            "record_event",
            session_id,
            {"t": t, "kind": kind, "detail": detail},
            "INSERT INTO events VALUES (?, ?, ?, ?, ?)",
            (session_id, self._next_seq("events", session_id), t, kind, detail),
        )

    def finish_session(
        self, session_id: str, *, finished_at: str, total: int, complete: bool, band: str | None
    ) -> None:
        """Mark a session finished (the total is kept for listing; results recompute it)."""
        self._record(
            "finish_session",
            session_id,
            {"finished_at": finished_at, "total": total, "complete": complete, "band": band},
            "UPDATE sessions SET status = 'finished', finished_at = ?, total = ?, complete = ?, band = ? WHERE id = ?",
            (finished_at, total, int(complete), band, session_id),
        )

    def abandon(self, session_id: str) -> None:
        """Mark an unfinished session as not to be continued (its answers stay): this kiosk's
        running session, or an interrupted one that staff end."""
        with self.transaction():
            status = self._status(session_id)
            if status not in ("running", "interrupted"):
                return
            self._write(
                "UPDATE sessions SET status = 'abandoned' WHERE id = ?",
                (session_id,),
                session=session_id if status == "running" else None,
            )
            self._db.execute("DELETE FROM leases WHERE session_id = ?", (session_id,))
            self._queue("abandon", session_id, {})

    # -- reading ------------------------------------------------------------------------------------

    @_reading
    def sessions(self) -> list[SessionSummary]:
        """Every stored session, newest first."""
        rows = self._db.execute(
            "SELECT s.id, s.patient_id, s.started_at, s.finished_at, s.status, s.language,"
            " (SELECT COUNT(*) FROM answers a WHERE a.session_id = s.id),"
            " (SELECT COUNT(*) FROM not_answered n WHERE n.session_id = s.id), s.simulated, s.interrupted_reason"
            " FROM sessions s ORDER BY s.started_at DESC, s.rowid DESC"
        ).fetchall()
        return [SessionSummary(*row[:8], simulated=bool(row[8]), interrupted_reason=row[9]) for row in rows]

    def unfinished_sessions(self) -> list[StoredSession]:
        """The tests staff may continue, newest first: interrupted (their kiosk stopped, or they grew
        too old: see :meth:`interrupt_stale`, run first), never simulated ones."""
        self.interrupt_stale()
        ids = [
            r[0]
            for r in self._db.execute(
                "SELECT id FROM sessions WHERE status = 'interrupted' AND simulated = 0"
                " ORDER BY started_at DESC, rowid DESC"
            )
        ]
        return [self.session(i) for i in ids]

    @_reading
    def outbox_waiting(self) -> tuple[int, int]:
        """Outbox rows waiting for the station, and rows it refused (parked, kept for an engineer)."""
        waiting, parked = self._db.execute("SELECT COUNT(*) - COUNT(parked), COUNT(parked) FROM outbox").fetchone()
        return int(waiting), int(parked)

    @_reading
    def resolve(self, ref: str) -> str:
        """A session id from a full id or a unique prefix; KeyError naming the problem otherwise."""
        rows = [r[0] for r in self._db.execute("SELECT id FROM sessions WHERE substr(id, 1, ?) = ?", (len(ref), ref))]
        if ref in rows:
            return ref
        if len(rows) == 1:
            return rows[0]
        raise KeyError(
            f"no session {ref!r}" if not rows else f"{ref!r} matches {len(rows)} sessions; give more of the id"
        )

    @_reading
    def session(self, ref: str) -> StoredSession:
        """Everything stored about one session (full id or unique prefix)."""
        session_id = self.resolve(ref)
        row = self._db.execute(
            "SELECT s.id, patient_id, s.questionnaire_id, language, answered_by, timing, started_at, status, finished_at,"
            " simulated, interrupted_reason, interrupted_at, s.definition, d.body, definition_attached_later,"
            " identity, identity_attached_later"
            " FROM sessions s LEFT JOIN definitions d ON d.sha256 = s.definition WHERE s.id = ?",
            (session_id,),
        ).fetchone()
        answers = tuple(
            Answer(item_id, option, points, attempt, Channel(channel), AnsweredBy(by), t, detail)
            for item_id, option, points, attempt, channel, by, t, detail in self._db.execute(
                "SELECT item_id, option, points, attempt, channel, answered_by, t, detail FROM answers"
                " WHERE session_id = ? ORDER BY t, rowid",
                (session_id,),
            )
        )
        not_answered = tuple(
            r[0]
            for r in self._db.execute(
                "SELECT item_id FROM not_answered WHERE session_id = ? ORDER BY t, rowid", (session_id,)
            )
        )
        trace = []
        for t, sets, emits in self._db.execute(
            "SELECT t, sets, emits FROM contexts WHERE session_id = ? ORDER BY seq", (session_id,)
        ):
            event: dict[str, Any] = {"t": t}
            if json.loads(sets):
                event["set"] = json.loads(sets)
            if json.loads(emits):
                event["emit"] = json.loads(emits)
            trace.append(event)
        metrics = tuple(
            MetricSample(t, json.loads(m), tuple(json.loads(f)))
            for t, m, f in self._db.execute(
                "SELECT t, metrics, fired FROM metric_samples WHERE session_id = ? ORDER BY seq", (session_id,)
            )
        )
        adaptations = tuple(
            AdaptationRecord(t, n, bool(a), r)
            for t, n, a, r in self._db.execute(
                "SELECT t, name, active, reason FROM adaptations WHERE session_id = ? ORDER BY seq", (session_id,)
            )
        )
        log = tuple(
            LogEntry(*r)
            for r in self._db.execute(
                "SELECT t, kind, detail FROM events WHERE session_id = ? ORDER BY seq", (session_id,)
            )
        )
        practice = tuple(
            PracticeRecord(q, c, o, opt, Channel(ch) if ch else None, t, d)
            for q, c, o, opt, ch, t, d in self._db.execute(
                "SELECT question_id, checks, outcome, option, channel, t, detail FROM practice"
                " WHERE session_id = ? ORDER BY seq",
                (session_id,),
            )
        )
        return StoredSession(
            id=row[0],
            patient_id=row[1],
            questionnaire_id=row[2],
            language=row[3],
            answered_by=AnsweredBy(row[4]),
            timing=json.loads(row[5]),
            started_at=row[6],
            status=row[7],
            finished_at=row[8],
            answers=answers,
            not_answered=not_answered,
            trace=tuple(trace),
            metrics=metrics,
            adaptations=adaptations,
            log=log,
            practice=practice,
            simulated=bool(row[9]),
            interrupted_reason=row[10],
            interrupted_at=row[11],
            definition=json.loads(row[13]) if row[13] else None,
            definition_sha256=row[12] or "",
            definition_attached_later=bool(row[14]),
            identity=json.loads(row[15]) if row[15] else {},
            identity_attached_later=bool(row[16]),
        )

"""Safe storage of sessions in SQLite (stdlib ``sqlite3``).

One database file in the kiosk's data directory (directory 0700, files 0600), in WAL mode with
``synchronous=FULL``. Each session operation is one transaction (:meth:`Store.transaction`):
an answer is committed together with its QoS context and metrics before anyone learns of it, and
an operation cut short (an exception, Ctrl-C, a kill) keeps none of its writes. The schema has a
version and ordered migrations (:mod:`kiosk.store.migrations`); a damaged file is refused with one message.

One running kiosk holds a session at a time (:mod:`kiosk.store.custody`); a running session whose
kiosk is gone, or older than the configured limit, is marked *interrupted*, and only staff continue
it. Sessions of scripted patients (``kiosk replay``) are stored *simulated* and never offered. With
``outbox=True`` every change also queues, in its transaction, a row for the ward station
(:mod:`kiosk.store.transactions`, ``docs/station-protocol.md`` §1).

The parts: :mod:`.connection` (opening the file), :mod:`.transactions` (writes and the outbox),
:mod:`.custody` (leases), :mod:`.reading` (queries), :mod:`.migrations` (the schema).

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
import json
import sqlite3
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kiosk.store.connection import DB_NAME, StorageError, connect
from kiosk.store.connection import TABLES as _TABLES
from kiosk.store.custody import Custody
from kiosk.store.lease import LEASE_TTL_S, Owner, SessionTaken
from kiosk.store.migrations import InForce, bundled_in_force, store_definition
from kiosk.store.patients import PATIENT_ID, new_patient_id
from kiosk.store.reading import Reader
from kiosk.store.records import (
    AdaptationRecord,
    LogEntry,
    MetricSample,
    PracticeRecord,
    SessionSummary,
    StoredSession,
)
from kiosk.store.staff_answers import record_staff_answer
from kiosk.store.transactions import ALERT_EVENTS, Transactions

if TYPE_CHECKING:  # its analysis imports numpy: loaded when the store first reads a TUG
    from kiosk.store.tug import TugResults

__all__ = [
    "ALERT_EVENTS",
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
    "_TABLES",
    "new_patient_id",
]


class Store:
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
        self.simulated = simulated
        self.outbox = outbox
        self._tx = Transactions(connection, wall=wall, outbox=outbox, guard=self._check_held)
        #: this kiosk's leases on sessions (taken, checked in every write, renewed, released)
        self.custody = Custody(
            self._tx, owner=owner or Owner(), lease_ttl_s=lease_ttl_s, interrupt_after_s=interrupt_after_s, wall=wall
        )
        self._reader = Reader(connection, path)
        self._tug: TugResults | None = None

    @property
    def tug(self) -> TugResults:
        """Timed Up and Go results (:mod:`kiosk.store.tug`), loaded on first use (numpy: not at start)."""
        if self._tug is None:
            from kiosk.store.tug import TugResults

            self._tug = TugResults(self._tx, self._db, export=self.export, simulated=self.simulated)
        return self._tug

    @classmethod
    def open(cls, data_dir: str | Path, create: bool = True, **options: Any) -> Store:
        """Open the database in ``data_dir``, creating both if needed, and bring its schema up to
        date; with ``create=False`` (the tools that only read, where a mistyped directory must not
        become an empty database) a missing directory or database is a StorageError. ``options``
        are the constructor's keywords."""
        in_force = options.setdefault(
            "in_force", bundled_in_force(options.get("export") or {}, options.get("wall", time.time))
        )
        db, path = connect(data_dir, create, in_force)
        return cls(db, path, **options)

    def close(self) -> None:
        """Release this kiosk's leases (a session still running is marked interrupted: its kiosk
        was closed) and close the database."""
        try:
            for session_id in self.custody.my_sessions():
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
        """Group writes into one commit (see :meth:`kiosk.store.transactions.Transactions.transaction`)."""
        with self._tx.transaction():
            yield

    @property
    def on_outbox(self) -> Callable[[bool], None] | None:
        """Called after a commit that queued outbox rows (True: one is an alert): the sync client's wake-up."""
        return self._tx.on_outbox

    @on_outbox.setter
    def on_outbox(self, callback: Callable[[bool], None] | None) -> None:
        self._tx.on_outbox = callback

    def _check_held(self, session_id: str) -> None:
        self.custody.check_held(session_id)

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
        with self._tx.transaction():
            self._tx.write("INSERT OR IGNORE INTO patients (id, created_at) VALUES (?, ?)", (patient_id, started_at))
            sha = store_definition(self._db, definition, self._tx.iso_now())
            self._tx.write(
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
            self.custody.take(session_id)
            self._tx.queue(
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
        self._tx.record(
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
        with self._tx.transaction():
            self._tx.record(
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

    def record_staff_answer(
        self,
        session_id: str,
        *,
        item_id: str,
        option: int | None,
        points: int | None,
        value: float | None,
        by: str,
        at: str | None = None,
    ) -> None:
        """Store what staff entered for a staff item, audited in the log (:mod:`kiosk.store.staff_answers`)."""
        record_staff_answer(
            self._tx, self.custody, session_id, item_id=item_id, option=option, points=points, value=value, at=at, by=by
        )

    def record_not_answered(self, session_id: str, *, item_id: str, t: float, at: str) -> None:
        """Store that both attempts of a question timed out."""
        self._tx.record(
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
        seq = self._tx.next_seq("practice", session_id)
        self._tx.record(
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
            (session_id, seq, question_id, checks, outcome, option, channel, t, at, detail),
        )

    def record_context(self, session_id: str, *, t: float, set: Mapping[str, Any], emit: list[str]) -> None:
        """Store one batch of the session's QoS context trace."""
        self._tx.record(
            "record_context",
            session_id,
            {"t": t, "set": dict(set), "emit": list(emit)},
            "INSERT INTO contexts VALUES (?, ?, ?, ?, ?)",
            (session_id, self._tx.next_seq("contexts", session_id), t, json.dumps(dict(set)), json.dumps(list(emit))),
        )

    def record_metrics(self, session_id: str, *, t: float, metrics: Mapping[str, float], fired: list[str]) -> None:
        """Store the QoS metrics after one update."""
        self._tx.record(
            "record_metrics",
            session_id,
            {"t": t, "metrics": dict(metrics), "fired": list(fired)},
            "INSERT INTO metric_samples VALUES (?, ?, ?, ?, ?)",
            (
                session_id,
                self._tx.next_seq("metric_samples", session_id),
                t,
                json.dumps(dict(metrics)),
                json.dumps(list(fired)),
            ),
        )

    def record_adaptation(self, session_id: str, *, t: float, name: str, active: bool, reason: str) -> None:
        """Store an adaptation switched on or off."""
        self._tx.record(
            "record_adaptation",
            session_id,
            {"t": t, "name": name, "active": active, "reason": reason},
            "INSERT INTO adaptations VALUES (?, ?, ?, ?, ?, ?)",
            (session_id, self._tx.next_seq("adaptations", session_id), t, name, int(active), reason),
        )

    def record_event(self, session_id: str, *, t: float, kind: str, detail: str = "") -> None:
        """Store a line of the session log (a call for the doctor, a patient leaving: alerts first)."""
        self._tx.record(
            "record_event",
            session_id,
            {"t": t, "kind": kind, "detail": detail},
            "INSERT INTO events VALUES (?, ?, ?, ?, ?)",
            (session_id, self._tx.next_seq("events", session_id), t, kind, detail),
        )

    def finish_session(
        self, session_id: str, *, finished_at: str, total: int, complete: bool, band: str | None
    ) -> None:
        """Mark a session finished (the total is kept for listing; results recompute it)."""
        self._tx.record(
            "finish_session",
            session_id,
            {"finished_at": finished_at, "total": total, "complete": complete, "band": band},
            "UPDATE sessions SET status = 'finished', finished_at = ?, total = ?, complete = ?, band = ? WHERE id = ?",
            (finished_at, total, int(complete), band, session_id),
        )

    def abandon(self, session_id: str) -> None:
        """Mark an unfinished session as not to be continued (its answers stay): this kiosk's
        running session, or an interrupted one that staff end."""
        with self._tx.transaction():
            status = self.custody.status(session_id)
            if status not in ("running", "interrupted"):
                return
            self._tx.write(
                "UPDATE sessions SET status = 'abandoned' WHERE id = ?",
                (session_id,),
                session=session_id if status == "running" else None,
            )
            self._db.execute("DELETE FROM leases WHERE session_id = ?", (session_id,))
            self._tx.queue("abandon", session_id, {})

    # -- reading ------------------------------------------------------------------------------------

    def sessions(self) -> list[SessionSummary]:
        """Every stored session, newest first."""
        return self._reader.sessions()

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

    def outbox_waiting(self) -> tuple[int, int]:
        """Outbox rows waiting for the station, and rows it refused (parked, kept for an engineer)."""
        return self._reader.outbox_waiting()

    def resolve(self, ref: str) -> str:
        """A session id from a full id or a unique prefix; KeyError naming the problem otherwise."""
        return self._reader.resolve(ref)

    def session(self, ref: str) -> StoredSession:
        """Everything stored about one session (full id or unique prefix)."""
        return self._reader.session(ref)

    # -- leases (see kiosk.store.custody) -------------------------------------------------------------

    @property
    def owner(self) -> Owner:
        """This kiosk process (leases name it)."""
        return self.custody.owner

    def why_not_held(self, session_id: str) -> str | None:
        """Why this kiosk may not record in the session (a sentence for staff), or None if it holds it."""
        return self.custody.why_not_held(session_id)

    def held_elsewhere(self, session_id: str) -> bool:
        """Whether another running kiosk process holds the session."""
        return self.custody.held_elsewhere(session_id)

    def holds(self, session_id: str) -> bool:
        """Whether this kiosk holds the session now."""
        return self.custody.holds(session_id)

    def renew(self) -> None:
        """Renew this kiosk's leases (the running kiosk calls this every third of the lease time)."""
        self.custody.renew()

    def release(self, session_id: str, reason: str = "its kiosk moved on to another test") -> None:
        """Give up the session: this kiosk no longer records in it. Still running, it is interrupted."""
        self.custody.release(session_id, reason)

    def release_others(self, keep: str) -> None:
        """Release every session this kiosk holds but ``keep`` (its running one)."""
        self.custody.release_others(keep)

    def interrupt_stale(self) -> list[str]:
        """Mark interrupted every running session whose kiosk is gone or that grew too old; their ids."""
        return self.custody.interrupt_stale()

    def continue_session(self, ref: str) -> StoredSession:
        """Staff continue an interrupted session on this kiosk: it is taken (atomically; SessionTaken
        if a running kiosk holds it) and running again. ValueError if it cannot be continued."""
        session_id = self.resolve(ref)
        self.custody.continue_session(session_id)
        return self.session(session_id)

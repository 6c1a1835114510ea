"""Reading what the store holds: the list of sessions, one session in full, the outbox's state.

A row this code cannot read (a value no kiosk writes, or SQL that fails on an edited file) is one
:class:`~kiosk.store.connection.StorageError` naming the database, never a traceback."""

from __future__ import annotations

import functools
import json
import sqlite3
from collections.abc import Callable
from pathlib import Path
from typing import Any

from kiosk.core.channels import Channel
from kiosk.core.session import Answer, AnsweredBy
from kiosk.store.connection import StorageError
from kiosk.store.records import (
    AdaptationRecord,
    LogEntry,
    MetricSample,
    PracticeRecord,
    SessionSummary,
    StoredSession,
)


def _reading(method: Callable[..., Any]) -> Callable[..., Any]:
    """A reading method whose rows this code cannot read (a value no kiosk writes, such as an
    unknown channel, or SQL that fails on an edited file) raises one StorageError naming the
    database, instead of a traceback from deep inside. KeyError (no such session) passes."""

    @functools.wraps(method)
    def read(self: Reader, *args: Any) -> Any:
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


class Reader:
    """Queries on the database ``db`` at ``path`` (the path names it in messages)."""

    def __init__(self, db: sqlite3.Connection, path: Path) -> None:
        self._db = db
        self.path = path

    @_reading
    def sessions(self) -> list[SessionSummary]:
        """Every stored session, newest first."""
        rows = self._db.execute(
            "SELECT s.id, s.patient_id, s.started_at, s.finished_at, s.status, s.language,"
            " (SELECT COUNT(*) FROM answers a WHERE a.session_id = s.id),"
            " (SELECT COUNT(*) FROM not_answered n WHERE n.session_id = s.id), s.simulated, s.interrupted_reason,"
            " s.questionnaire_id FROM sessions s ORDER BY s.started_at DESC, s.rowid DESC"
        ).fetchall()
        return [
            SessionSummary(
                id_, patient, started, finished, status, language, answered, missed, bool(simulated), reason, qid
            )
            for id_, patient, started, finished, status, language, answered, missed, simulated, reason, qid in rows
        ]

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
            "SELECT s.id, patient_id, s.questionnaire_id, language, answered_by, timing, started_at, status,"
            " finished_at, simulated, interrupted_reason, interrupted_at, s.definition, d.body,"
            " definition_attached_later, identity, identity_attached_later"
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

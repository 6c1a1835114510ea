"""A session read back from what its kiosk sent: the inbox rows folded in ``seq`` order into the
kiosk's own :class:`kiosk.store.database.StoredSession`, so scoring, labels and exports are the session
core's, not a copy. A row that arrived late (alerts go first) simply takes its place in the order.
The session carries the definition it ran and the identity its kiosk recorded it under (what the
kiosk sent with ``create_session``), so pages and exports describe it as it was recorded. A row the
station cannot read (stored before rows were checked) is listed in the log, never a failure.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import replace
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from basis import record
from kiosk.core.channels import Channel
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.session import Answer, AnsweredBy
from kiosk.export import ExportError
from kiosk.store.database import (
    AdaptationRecord,
    LogEntry,
    MetricSample,
    PracticeRecord,
    StoredSession,
)
from station import definitions
from station.db import inbox, sessions
from station.definitions import questionnaire_for

#: the outbox kinds that change a session's status (they refresh the session list)
LIFECYCLE = ("create_session", "finish_session", "abandon", "mark_interrupted", "continue_session")


@record
class Row:
    """One outbox row as the kiosk sent it."""

    seq: int
    kind: str
    payload: dict[str, Any]
    at: str


class NotFound(KeyError):
    """No session with that id has reached the station."""


def rows_of(connection: Connection, session_id: str, kinds: Iterable[str] | None = None) -> list[Row]:
    """The session's rows in the kiosk's order."""
    query = (
        sa.select(inbox.c.seq, inbox.c.kind, inbox.c.payload, inbox.c.at)
        .where(inbox.c.session_id == session_id)
        .order_by(inbox.c.seq)
    )
    if kinds is not None:
        query = query.where(inbox.c.kind.in_(list(kinds)))
    return [Row(seq, kind, json.loads(payload), at) for seq, kind, payload, at in connection.execute(query)]


def status_of(rows: Iterable[Row]) -> dict[str, Any]:
    """The session's patient, start, status and finish from its lifecycle rows (in order)."""
    state: dict[str, Any] = {"patient_id": None, "started_at": None, "status": "pending", "finished_at": None}
    for row in rows:
        if row.kind == "create_session":
            state.update(patient_id=row.payload.get("patient_id"), started_at=row.payload.get("started_at"))
            if state["status"] == "pending":
                state["status"] = "running"
        elif row.kind == "finish_session":
            state.update(status="finished", finished_at=row.payload.get("finished_at"))
        elif row.kind == "abandon" and state["status"] in ("running", "pending", "interrupted"):
            state["status"] = "abandoned"  # staff may end an interrupted test too
        elif row.kind == "mark_interrupted" and state["status"] in ("running", "pending"):
            state["status"] = "interrupted"
        elif row.kind == "continue_session" and state["status"] == "interrupted":
            state["status"] = "running"  # staff continued it on a kiosk
    return state


def fold(session_id: str, rows: Iterable[Row]) -> StoredSession:
    """The session as the kiosk stored it, from its rows in seq order. Rows of kinds this station
    does not know are kept in the inbox and listed in the log, never dropped."""
    head: dict[str, Any] = {}
    answers: dict[str, Answer] = {}
    not_answered: list[str] = []
    trace: list[dict[str, Any]] = []
    metrics: list[MetricSample] = []
    adaptations: list[AdaptationRecord] = []
    log: list[LogEntry] = []
    practice: list[PracticeRecord] = []
    interrupted: dict[str, Any] = {}
    status = status_of(rows := list(rows))
    for row in rows:
        try:
            _apply(row, head, answers, not_answered, trace, metrics, adaptations, log, practice, interrupted)
        except (KeyError, TypeError, ValueError, AttributeError):
            log.append(LogEntry(0.0, f"unreadable:{row.kind}", json.dumps(row.payload)[:200]))
    ordered = sorted(answers.values(), key=lambda a: a.t)
    language = head["language"] if isinstance(head.get("language"), str) else "en"
    try:
        answered_by = AnsweredBy(head.get("answered_by", "patient"))
    except ValueError:
        answered_by = AnsweredBy.PATIENT
    return StoredSession(
        id=session_id,
        patient_id=status["patient_id"] or "?",
        questionnaire_id=str(head.get("questionnaire_id", "barthel")),
        language=language,
        answered_by=answered_by,
        timing=head.get("timing", {}) if isinstance(head.get("timing"), dict) else {},
        started_at=str(status["started_at"] or ""),
        status=status["status"],
        finished_at=status["finished_at"],
        answers=tuple(ordered),
        not_answered=tuple(not_answered),
        trace=tuple(trace),
        metrics=tuple(metrics),
        adaptations=tuple(adaptations),
        log=tuple(log),
        practice=tuple(practice),
        simulated=head.get("simulated") is True,
        identity=_identity(head),
        identity_attached_later=bool(head.get("export_attached_later")),
        **(interrupted if status["status"] == "interrupted" else {}),
    )


def _identity(head: dict[str, Any]) -> dict[str, str]:
    identity = head.get("export")
    return {k: v for k, v in identity.items() if isinstance(v, str)} if isinstance(identity, dict) else {}


def _apply(
    row: Row,
    head: dict[str, Any],
    answers: dict[str, Answer],
    not_answered: list[str],
    trace: list[dict[str, Any]],
    metrics: list[MetricSample],
    adaptations: list[AdaptationRecord],
    log: list[LogEntry],
    practice: list[PracticeRecord],
    interrupted: dict[str, Any],
) -> None:
    """Fold one row into the session being read."""
    p = row.payload
    if row.kind == "create_session":
        head.clear()
        head.update(p)
    elif row.kind == "record_answer":
        answers[p["item_id"]] = Answer(
            p["item_id"],
            int(p["option"]),
            int(p["points"]),
            int(p["attempt"]),
            Channel(p["channel"]),
            AnsweredBy(p["answered_by"]),
            float(p["t"]),
            p.get("detail", ""),
        )
        if p["item_id"] in not_answered:
            not_answered.remove(p["item_id"])
    elif row.kind == "withdraw_answer":  # the patient's "Change my answer": the answer is gone
        answers.pop(p["item_id"], None)
    elif row.kind == "record_not_answered":
        if p["item_id"] not in answers and p["item_id"] not in not_answered:
            not_answered.append(p["item_id"])
    elif row.kind == "record_practice":
        practice.append(
            PracticeRecord(
                p["question_id"],
                p["checks"],
                p["outcome"],
                p.get("option"),
                Channel(p["channel"]) if p.get("channel") else None,
                float(p["t"]),
                p.get("detail", ""),
            )
        )
    elif row.kind == "record_context":
        event: dict[str, Any] = {"t": float(p["t"])}
        if p.get("set"):
            event["set"] = p["set"]
        if p.get("emit"):
            event["emit"] = p["emit"]
        trace.append(event)
    elif row.kind == "record_metrics":
        metrics.append(MetricSample(float(p["t"]), p["metrics"], tuple(p.get("fired", ()))))
    elif row.kind == "record_adaptation":
        adaptations.append(AdaptationRecord(float(p["t"]), p["name"], bool(p["active"]), p.get("reason", "")))
    elif row.kind == "record_event":
        log.append(LogEntry(float(p["t"]), p["kind"], p.get("detail", "")))
    elif row.kind == "mark_interrupted":
        interrupted.clear()
        interrupted.update(interrupted_reason=p.get("reason"), interrupted_at=row.at)
    elif row.kind == "continue_session":
        interrupted.clear()
    elif row.kind not in LIFECYCLE:
        log.append(LogEntry(float(p.get("t", 0.0)), f"unrecognised:{row.kind}", json.dumps(p)[:200]))


def _heads(connection: Connection, session_ids: list[str]) -> dict[str, Any]:
    """The sessions' rows of ``sessions`` (kiosk and definition), by id, in one query."""
    columns = (
        sessions.c.id,
        sessions.c.kiosk_id,
        sessions.c.definition_sha256,
        sessions.c.definition_attached_later,
        sessions.c.patient_id,
    )
    return {r.id: r for r in connection.execute(sa.select(*columns).where(sessions.c.id.in_(session_ids)))}


def _with_definition(stored: StoredSession, head: Any, kept: dict[str, Any]) -> StoredSession:
    """``stored`` with the definition it runs (None if its create_session never arrived), only
    what fits it (see :func:`fitted`), and the patient identifier of its row (staff may have
    given a walk-up its hospital identifier: station.identify)."""
    if head.patient_id and head.patient_id != stored.patient_id:
        stored = replace(stored, patient_id=head.patient_id)
    found = kept.get(head.definition_sha256) if head.definition_sha256 else None
    if found is None:
        return stored
    stored = replace(
        stored,
        definition=found.body,
        definition_sha256=head.definition_sha256,
        definition_attached_later=bool(head.definition_attached_later),
    )
    try:
        return fitted(stored, questionnaire_for(stored))
    except ExportError:
        return stored


def fitted(stored: StoredSession, q: Questionnaire) -> StoredSession:
    """``stored`` without what does not fit ``q``: rows stored before the station checked them (an
    option the item lacks, an unknown item or practice question, a language ``q`` lacks). Each is
    listed in the session's log instead (``unfit:...``), so the rest can be shown, corrected,
    signed off and exported."""
    items = {item.id: item for item in q.items}
    practice_ids = {p.id for p in q.familiarisation}
    log = list(stored.log)

    def fits(a: Answer) -> bool:
        item = items.get(a.item_id)
        return item is not None and 1 <= a.option <= len(item.options) and item.option(a.option).points == a.points

    answers = tuple(a for a in stored.answers if fits(a))
    log += [
        LogEntry(a.t, "unfit:answer", f"{a.item_id} option {a.option} ({a.points} points)")
        for a in stored.answers
        if not fits(a)
    ]
    practice = tuple(p for p in stored.practice if p.question_id in practice_ids)
    log += [
        LogEntry(p.t, "unfit:practice", p.question_id) for p in stored.practice if p.question_id not in practice_ids
    ]
    language = stored.language
    if language not in q.languages:
        log.append(LogEntry(0.0, "unfit:language", f"{language!r}; shown in {q.languages[0]}"))
        language = q.languages[0]
    if len(log) == len(stored.log):
        return stored
    return replace(
        stored,
        answers=answers,
        practice=practice,
        language=language,
        log=tuple(log),
        not_answered=tuple(i for i in stored.not_answered if i in items),
    )


def load(connection: Connection, session_id: str) -> tuple[str, StoredSession]:
    """The kiosk a session came from, and the session with its definition and identity (NotFound
    if it never arrived)."""
    found = load_many(connection, [session_id])
    if session_id not in found:
        raise NotFound(session_id)
    return found[session_id]


#: the rows a result's score, state and list entry need (no metrics or contexts): the log's
#: events too, as a number staff entered at the kiosk is a log line (kiosk.core.staff.STAFF_ANSWER)
#: and without it the lists and the print view gave such a result no total
RESULT_KINDS = (*LIFECYCLE, "record_answer", "withdraw_answer", "record_not_answered", "record_event")


#: the rows no export reads (the QoS engine's samples and context, its adaptations): two thirds of
#: a session's rows, left out of the month's export (station.exports)
SAMPLE_KINDS = ("record_metrics", "record_context", "record_adaptation")


def load_many(
    connection: Connection,
    session_ids: Iterable[str],
    kinds: Iterable[str] | None = None,
    without: Iterable[str] = (),
) -> dict[str, tuple[str, StoredSession]]:
    """Several sessions as :func:`load` reads one, in three queries whatever their number (their
    heads, their rows, the definitions this process has not parsed yet); sessions that never
    arrived are absent. ``kinds`` reads only rows of those kinds (a list of results needs
    :data:`RESULT_KINDS`, not every metric sample), ``without`` all but those."""
    ids = list(dict.fromkeys(session_ids))
    if not ids:
        return {}
    heads = _heads(connection, ids)
    query = (
        sa.select(inbox.c.session_id, inbox.c.seq, inbox.c.kind, inbox.c.payload, inbox.c.at)
        .where(inbox.c.session_id.in_(list(heads)))
        .order_by(inbox.c.session_id, inbox.c.seq)
    )
    if kinds is not None:
        query = query.where(inbox.c.kind.in_(list(kinds)))
    if without:
        query = query.where(inbox.c.kind.not_in(list(without)))
    rows: dict[str, list[Row]] = {session_id: [] for session_id in heads}
    for session_id, seq, kind, payload, at in connection.execute(query):
        rows[session_id].append(Row(seq, kind, json.loads(payload), at))
    kept = definitions.parsed(connection, [h.definition_sha256 for h in heads.values()])
    return {
        session_id: (
            heads[session_id].kiosk_id,
            _with_definition(fold(session_id, rows[session_id]), heads[session_id], kept),
        )
        for session_id in ids
        if session_id in heads
    }

"""The kiosk's outbox arriving (protocol §1, ``POST /api/v1/sync``).

A batch is stored in one transaction, idempotently on ``(kiosk_id, seq)``: a row already stored
is acknowledged again, never stored twice; the same seq with different content is refused
(:class:`Conflict`, so the kiosk parks that row instead of the station silently keeping either).
A row is checked before anything is stored: known kinds carry the fields their ``Store`` method
takes, a new session's patient id is pseudonymous, and a session belongs to the kiosk that
created it -- so an answer can never land under another kiosk's patient.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from kiosk.storage import PATIENT_ID
from station import alert_rules, db, orders
from station.db import alerts, inbox, sessions
from station.sessions import LIFECYCLE, rows_of, status_of

MAX_BATCH = 500
#: fields each known kind's payload must carry (the Store method's required keyword arguments)
REQUIRED: dict[str, tuple[str, ...]] = {
    "create_session": ("session_id", "patient_id", "questionnaire_id", "language", "answered_by", "started_at"),
    "record_answer": ("item_id", "option", "points", "attempt", "channel", "answered_by", "t"),
    "record_not_answered": ("item_id", "t"),
    "withdraw_answer": ("item_id", "t"),
    "record_practice": ("question_id", "checks", "outcome", "t"),
    "record_context": ("t",),
    "record_metrics": ("t", "metrics"),
    "record_adaptation": ("t", "name", "active"),
    "record_event": ("t", "kind"),
    "finish_session": ("finished_at",),
    "abandon": (),
}
#: session-log kinds that raise an alert, and the kinds that end one. The protocol names them
#: doctor_called/doctor_continued; today's session log says call_doctor/clinician_continue.
RAISES = {"doctor_called": "doctor_called", "call_doctor": "doctor_called", "person_lost": "person_lost"}
ENDS = {"doctor_continued": "doctor_called", "clinician_continue": "doctor_called", "person_back": "person_lost"}


def is_alert(event: Event) -> bool:
    """A row the protocol sends first: a doctor call, a patient leaving, and their ends."""
    return event.kind == "record_event" and event.payload.get("kind") in RAISES.keys() | ENDS.keys()


class SyncError(ValueError):
    """A batch the station refuses; ``status`` is the HTTP status (400 malformed, 409 conflict,
    422 a row that breaks a rule)."""

    status = 400


class Conflict(SyncError):
    status = 409


class Refused(SyncError):
    status = 422


@dataclass(frozen=True)
class Event:
    seq: int
    kind: str
    session_id: str
    payload: dict[str, Any]
    at: str


def parse(body: Any) -> list[Event]:
    """The batch's events, checked (SyncError naming the event and the problem)."""
    if not isinstance(body, dict) or not isinstance(body.get("events"), list):
        raise SyncError("the body must be a JSON object with an 'events' list")
    if len(body["events"]) > MAX_BATCH:
        raise SyncError(f"at most {MAX_BATCH} events per request, got {len(body['events'])}")
    events = []
    for index, raw in enumerate(body["events"]):
        where = f"events[{index}]"
        if not isinstance(raw, dict):
            raise SyncError(f"{where}: not an object")
        seq, kind, session_id, payload, at = (raw.get(k) for k in ("seq", "kind", "session_id", "payload", "at"))
        if not isinstance(seq, int) or isinstance(seq, bool) or seq < 0:
            raise SyncError(f"{where}: 'seq' must be a non-negative integer")
        where = f"seq {seq}"
        for name, value in (("kind", kind), ("session_id", session_id), ("at", at)):
            if not isinstance(value, str) or not value or len(value) > 64:
                raise SyncError(f"{where}: '{name}' must be a non-empty string of at most 64 characters")
        if not isinstance(payload, dict):
            raise SyncError(f"{where}: 'payload' must be an object")
        missing = [k for k in REQUIRED.get(kind, ()) if k not in payload]
        if missing:
            raise Refused(f"{where}: {kind} without {', '.join(missing)}")
        if kind == "create_session":
            if payload["session_id"] != session_id:
                raise Refused(f"{where}: create_session for {payload['session_id']!r} in a row of {session_id!r}")
            if not isinstance(payload["patient_id"], str) or not PATIENT_ID.match(payload["patient_id"]):
                raise Refused(f"{where}: the patient id is not pseudonymous (2-64 letters, digits, '-' or '_')")
        events.append(Event(seq, kind, session_id, payload, at))
    return events


def _same(stored: Any, event: Event) -> bool:
    return (stored.kind, stored.session_id, json.loads(stored.payload)) == (event.kind, event.session_id, event.payload)


def intake(connection: Connection, kiosk_id: str, events: Sequence[Event]) -> tuple[list[int], list[dict[str, Any]]]:
    """Store a batch from ``kiosk_id`` in the caller's transaction; returns the seqs now stored
    (new and already known) and the bus messages to publish once committed."""
    messages: list[dict[str, Any]] = []
    seqs = [e.seq for e in events]
    if len(set(seqs)) != len(seqs):
        raise SyncError("a seq appears twice in one batch")
    received = db.now()
    known = {row.seq: row for row in connection.execute(
        sa.select(inbox.c.seq, inbox.c.kind, inbox.c.session_id, inbox.c.payload).where(
            inbox.c.kiosk_id == kiosk_id, inbox.c.seq.in_(seqs)))}
    for event in events:
        if event.seq in known and not _same(known[event.seq], event):
            raise Conflict(f"seq {event.seq}: already stored with different content (was this kiosk's "
                           "database replaced? its rows are kept apart until someone checks)")
    new = [e for e in events if e.seq not in known]
    _claim_sessions(connection, kiosk_id, new, received)
    db.insert_ignore(connection, inbox, [{"kiosk_id": kiosk_id, "seq": e.seq, "kind": e.kind,
                                          "session_id": e.session_id, "payload": json.dumps(e.payload), "at": e.at,
                                          "received_at": received} for e in new], ["kiosk_id", "seq"])
    for session_id in {e.session_id for e in new if e.kind in LIFECYCLE}:
        connection.execute(sessions.update().where(sessions.c.id == session_id).values(
            updated_at=received, **status_of(rows_of(connection, session_id, LIFECYCLE))))
    if new:
        messages += _alerts(connection, kiosk_id, new, received)
        messages += alert_rules.settle(connection, kiosk_id, new)  # staff's own doing, situations ended
        messages += orders.on_rows(connection, kiosk_id, new)  # visits, orders, results waiting
    return seqs, messages


def _claim_sessions(connection: Connection, kiosk_id: str, new: Sequence[Event], received: float) -> None:
    """A session belongs to the first kiosk that sent a row of it; another kiosk's row is refused."""
    ids = sorted({e.session_id for e in new})
    if not ids:
        return
    owners = dict(connection.execute(sa.select(sessions.c.id, sessions.c.kiosk_id).where(sessions.c.id.in_(ids))).all())
    for session_id in ids:
        owner = owners.get(session_id)
        if owner is not None and owner != kiosk_id:
            seq = next(e.seq for e in new if e.session_id == session_id)
            raise Conflict(f"seq {seq}: session {session_id} belongs to kiosk {owner}, not {kiosk_id}")
    db.insert_ignore(connection, sessions, [{"id": s, "kiosk_id": kiosk_id, "status": "pending", "updated_at": received}
                                   for s in ids if s not in owners], ["id"])


def _alerts(connection: Connection, kiosk_id: str, new: Sequence[Event], received: float) -> list[dict[str, Any]]:
    """Raise an alert for each doctor call or patient leaving; mark the matching one resolved when
    the kiosk reports its end (it stays on the pages until staff acknowledge it)."""
    messages = []
    for event in sorted(new, key=lambda e: e.seq):
        if event.kind != "record_event":
            continue
        log_kind = event.payload.get("kind")
        if log_kind in RAISES:
            db.insert_ignore(connection, alerts, [{"kiosk_id": kiosk_id, "seq": event.seq, "session_id": event.session_id,
                                          "kind": RAISES[log_kind], "raised_at": event.at, "received_at": received}],
                    ["kiosk_id", "seq"])
            messages.append({"type": "alert", "kiosk": kiosk_id})
        elif log_kind in ENDS:
            open_alert = connection.execute(sa.select(alerts.c.id).where(
                alerts.c.session_id == event.session_id, alerts.c.kind == ENDS[log_kind],
                alerts.c.resolved_at.is_(None), alerts.c.seq < event.seq).order_by(alerts.c.seq.desc())).scalar()
            if open_alert is not None:
                connection.execute(alerts.update().where(alerts.c.id == open_alert).values(resolved_at=event.at))
                messages.append({"type": "alert", "kiosk": kiosk_id})
    return messages

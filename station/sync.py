"""The kiosk's outbox arriving (protocol §1, ``POST /api/v1/sync``).

A batch is stored in one transaction, idempotently on ``(kiosk_id, seq)``: a row already stored
is acknowledged again, never stored twice; the same seq with different content is refused
(:class:`Conflict`, so the kiosk parks that row instead of the station silently keeping either).
A row is checked before anything is stored (:mod:`station.checks`): known kinds carry the fields
their ``Store`` method takes, with the types, values and lengths the pages, exports and both
engines take, and what a row says about the questionnaire fits the definition its session runs --
the one the kiosk sent with ``create_session`` (stored once per content in ``definitions``; a kiosk
that sends none gets the bundled questionnaire, marked attached later). A session belongs to the
kiosk that created it, so an answer can never land under another kiosk's patient. A refused row is
a 422 naming its seq (and the body's ``seq``), so the kiosk parks it and delivers the rest.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from functools import lru_cache
from typing import Any, cast

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from basis import record
from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from kiosk.core.questionnaire.definition import canonical, canonical_json, digest, questionnaire_from
from station import alert_rules, db, identify, order_progress, tugs
from station.checks import (
    ID_MAX,
    NEEDS_DEFINITION,
    RowRefused,
    check_create,
    check_definition,
    check_row,
    iso_time,
    sha_of,
    text,
)
from station.db import alerts, definitions, inbox, sessions
from station.orders import LinkRefused
from station.sessions import LIFECYCLE, rows_of, status_of
from station.tug_checks import CheckedTug, check_tug

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
    "record_tug": ("tug_id", "patient_id"),
}
#: rows that are results of their own, not of a session (their session_id is the result's id)
OWN_RESULTS = ("record_tug",)
#: session-log kinds that raise an alert, and the kinds that end one. The protocol names them
#: doctor_called/doctor_continued; today's session log says call_doctor/clinician_continue. A
#: patient away raises the alert only once away as long as the kiosk's site says (away_alert; the
#: person_lost that came before it raises none); no answer to questions in a row raises unattended.
RAISES = {
    "doctor_called": "doctor_called",
    "call_doctor": "doctor_called",
    "away_alert": "person_lost",
    "unattended": "unattended",
}
ENDS = {
    "doctor_continued": "doctor_called",
    "clinician_continue": "doctor_called",
    "person_back": "person_lost",
    "unattended_ended": "unattended",
}
#: the rows sent first that neither raise nor end an alert: the patient left (the alert may follow)
URGENT = {"person_lost"}


def is_alert(event: Event) -> bool:
    """A row the protocol sends first: a doctor call, a patient leaving, no answer, and their ends."""
    return event.kind == "record_event" and event.payload.get("kind") in RAISES.keys() | ENDS.keys() | URGENT


class SyncError(ValueError):
    """A batch the station refuses; ``status`` is the HTTP status (400 malformed, 409 conflict,
    422 a row that breaks a rule); ``seq`` the row at fault, when one is."""

    status = 400

    def __init__(self, message: str, seq: int | None = None) -> None:
        super().__init__(message)
        self.seq = seq


class Conflict(SyncError):
    status = 409


class Refused(SyncError):
    """A row that breaks a rule."""

    status = 422


@record
class Event:
    seq: int
    kind: str
    session_id: str
    #: as stored: a create_session's definition is kept apart (``definition``), by its SHA-256
    payload: dict[str, Any]
    at: str
    #: the definition a create_session carried, checked (None: none sent)
    definition: dict[str, Any] | None = None
    #: a record_tug row's result, checked
    tug: CheckedTug | None = None


def _bundled() -> tuple[dict[str, Any], str]:
    """The bundled questionnaire's definition and its SHA-256 (what a kiosk that sends none runs)."""
    global _BUNDLED
    if _BUNDLED is None:
        definition = canonical(load_questionnaire())
        _BUNDLED = (definition, digest(definition))
    return _BUNDLED


_BUNDLED: tuple[dict[str, Any], str] | None = None


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
        if not isinstance(seq, int) or isinstance(seq, bool) or not 0 <= seq < 2**63:
            raise SyncError(f"{where}: 'seq' must be a non-negative integer")
        where = f"seq {seq}"
        try:
            for name, value in (("kind", kind), ("session_id", session_id)):
                text(value, f"{where}: {name}", ID_MAX, empty=False)
            iso_time(at, f"{where}: at")
            kind, session_id, at = cast(str, kind), cast(str, session_id), cast(str, at)  # text: checked above
            if not isinstance(payload, dict):
                raise RowRefused(f"{where}: payload: must be an object")
            missing = [k for k in REQUIRED.get(kind, ()) if k not in payload]
            if missing:
                raise RowRefused(f"{where}: {kind} without {', '.join(missing)}")
            definition = None
            if kind == "create_session" and "definition_sha256" in payload:
                sha_of(payload["definition_sha256"], f"{where}: create_session.definition_sha256")
            if kind == "create_session" and "definition" in payload:
                payload = dict(payload)
                definition = payload.pop("definition")  # stored once by its hash; checked after the token
                if not isinstance(definition, dict):
                    raise RowRefused(f"{where}: create_session.definition: must be an object")
                sent = payload.get("definition_sha256")
                payload["definition_sha256"] = digest(definition)
                if sent is not None and sent != payload["definition_sha256"]:
                    raise RowRefused(
                        f"{where}: create_session.definition_sha256: is not the SHA-256 of the "
                        "definition's canonical JSON"
                    )
            tug = check_tug(payload, f"{where}: record_tug", session_id) if kind == "record_tug" else None
        except RowRefused as exc:
            raise Refused(str(exc), seq) from None
        events.append(Event(seq, kind, session_id, payload, at, definition, tug))
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
    known = {
        row.seq: row
        for row in connection.execute(
            sa.select(inbox.c.seq, inbox.c.kind, inbox.c.session_id, inbox.c.payload).where(
                inbox.c.kiosk_id == kiosk_id, inbox.c.seq.in_(seqs)
            )
        )
    }
    for event in events:
        if event.seq in known and not _same(known[event.seq], event):
            raise Conflict(
                f"seq {event.seq}: already stored with different content (was this kiosk's "
                "database replaced? its rows are kept apart until someone checks)",
                event.seq,
            )
    new = [e for e in events if e.seq not in known]
    of_sessions = [e for e in new if e.kind not in OWN_RESULTS]
    _claim_sessions(connection, kiosk_id, of_sessions, received)
    _check_against_definitions(connection, of_sessions)
    db.insert_ignore(
        connection,
        inbox,
        [
            {
                "kiosk_id": kiosk_id,
                "seq": e.seq,
                "kind": e.kind,
                "session_id": e.session_id,
                "payload": json.dumps(e.payload),
                "at": e.at,
                "received_at": received,
            }
            for e in new
        ],
        ["kiosk_id", "seq"],
    )
    touched = {e.session_id for e in new if e.kind in LIFECYCLE}
    given = identify.kept_in(connection, touched)  # staff gave these their identifier: it stays
    for session_id in touched:
        status = status_of(rows_of(connection, session_id, LIFECYCLE))
        if session_id in given:
            del status["patient_id"]
        connection.execute(sessions.update().where(sessions.c.id == session_id).values(updated_at=received, **status))
    if of_sessions:
        messages += _alerts(connection, kiosk_id, of_sessions, received)
        messages += alert_rules.settle(connection, kiosk_id, of_sessions)  # staff's own doing, situations ended
        messages += order_progress.on_rows(connection, kiosk_id, of_sessions)  # visits, orders, results waiting
    messages += _tugs(connection, kiosk_id, [e for e in new if e.tug is not None], received)
    return seqs, messages


def _tugs(connection: Connection, kiosk_id: str, new: Sequence[Event], received: float) -> list[dict[str, Any]]:
    """Store the Timed Up and Go results (station.tugs) and move their orders on."""
    messages: list[dict[str, Any]] = []
    for event in sorted(new, key=lambda e: e.seq):
        assert event.tug is not None
        try:
            tugs.store(connection, kiosk_id, event.seq, event.tug, received)
        except tugs.TugClash as exc:
            raise Conflict(str(exc), event.seq) from None
        if event.tug.order_id is not None:
            try:
                messages += order_progress.on_tug(
                    connection, kiosk_id, event.seq, event.tug.order_id, event.tug.patient_id
                )
            except LinkRefused as exc:
                raise Refused(str(exc), event.seq) from None
        messages.append({"type": "sessions", "kiosk": kiosk_id})
    return messages


def _definition_of(connection: Connection, session_id: str) -> str | None:
    return connection.execute(sa.select(sessions.c.definition_sha256).where(sessions.c.id == session_id)).scalar()


def _questionnaire(connection: Connection, sha: str, cache: dict[str, Questionnaire]) -> Questionnaire:
    """The questionnaire of a stored definition (rebuilt once per content in this process)."""
    if sha not in cache:
        body = connection.execute(sa.select(definitions.c.body).where(definitions.c.sha256 == sha)).scalar()
        cache[sha] = _rebuilt(body or canonical_json(_bundled()[0]))
    return cache[sha]


@lru_cache(maxsize=64)
def _rebuilt(body: str) -> Questionnaire:
    return questionnaire_from(json.loads(body))


def _store_definition(connection: Connection, definition: dict[str, Any], sha: str) -> None:
    db.insert_ignore(
        connection,
        definitions,
        [
            {
                "sha256": sha,
                "questionnaire_id": str(definition.get("id", "")),
                "version": str(definition.get("version", "")),
                "body": canonical_json(definition),
                "stored_at": db.now_iso(),
            }
        ],
        ["sha256"],
    )


def _check_against_definitions(connection: Connection, new: Sequence[Event]) -> None:
    """Check each new row against its session's definition, in seq order; check and store the
    definitions a create_session brings (each content once) and note which one each new session
    runs (Refused naming the row)."""
    running: dict[str, str | None] = {}
    cache: dict[str, Questionnaire] = {}
    for event in sorted(new, key=lambda e: e.seq):
        where = f"seq {event.seq}: {event.kind}"
        if event.session_id not in running:
            running[event.session_id] = _definition_of(connection, event.session_id)
        try:
            if event.kind == "create_session":
                if running[event.session_id] is not None:
                    raise RowRefused(f"{where}: session {event.session_id} was created already")
                later = event.definition is None and "definition_sha256" not in event.payload
                if event.definition is not None:
                    sha = event.payload["definition_sha256"]
                    known = connection.execute(
                        sa.select(definitions.c.sha256).where(definitions.c.sha256 == sha)
                    ).scalar()
                    if sha not in cache and known is None:  # stored ones were checked as they came
                        cache[sha] = check_definition(event.definition, f"{where}.definition")
                        _store_definition(connection, event.definition, sha)
                elif later:
                    definition, sha = _bundled()
                    _store_definition(connection, definition, sha)
                else:
                    sha = event.payload["definition_sha256"]
                    if (
                        connection.execute(sa.select(definitions.c.sha256).where(definitions.c.sha256 == sha)).scalar()
                        is None
                    ):
                        raise RowRefused(
                            f"{where}.definition_sha256: this station has no definition {sha[:12]}; "
                            "send the definition with the session"
                        )
                check_create(event.payload, where, event.session_id, _questionnaire(connection, sha, cache))
                connection.execute(
                    sessions.update()
                    .where(sessions.c.id == event.session_id)
                    .values(definition_sha256=sha, definition_attached_later=later)
                )
                running[event.session_id] = sha
            sha = running[event.session_id]
            if event.kind in NEEDS_DEFINITION and sha is None:
                raise RowRefused(
                    f"{where}: session {event.session_id} has no questionnaire at this station "
                    "(its create_session has not arrived)"
                )
            check_row(event.kind, event.payload, where, _questionnaire(connection, sha, cache) if sha else None)
        except RowRefused as exc:
            raise Refused(str(exc), event.seq) from None


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
            raise Conflict(f"seq {seq}: session {session_id} belongs to kiosk {owner}, not {kiosk_id}", seq)
    db.insert_ignore(
        connection,
        sessions,
        [{"id": s, "kiosk_id": kiosk_id, "status": "pending", "updated_at": received} for s in ids if s not in owners],
        ["id"],
    )


def _alerts(connection: Connection, kiosk_id: str, new: Sequence[Event], received: float) -> list[dict[str, Any]]:
    """Raise an alert for each doctor call or patient leaving; mark the matching one resolved when
    the kiosk reports its end (it stays on the pages until staff acknowledge it)."""
    messages = []
    for event in sorted(new, key=lambda e: e.seq):
        if event.kind != "record_event":
            continue
        log_kind = event.payload.get("kind")
        if log_kind in RAISES:
            db.insert_ignore(
                connection,
                alerts,
                [
                    {
                        "kiosk_id": kiosk_id,
                        "seq": event.seq,
                        "session_id": event.session_id,
                        "kind": RAISES[log_kind],
                        "raised_at": event.at,
                        "received_at": received,
                    }
                ],
                ["kiosk_id", "seq"],
            )
            messages.append({"type": "alert", "kiosk": kiosk_id})
        elif log_kind in ENDS:
            open_alert = connection.execute(
                sa.select(alerts.c.id)
                .where(
                    alerts.c.session_id == event.session_id,
                    alerts.c.kind == ENDS[log_kind],
                    alerts.c.resolved_at.is_(None),
                    alerts.c.seq < event.seq,
                )
                .order_by(alerts.c.seq.desc())
            ).scalar()
            if open_alert is not None:
                connection.execute(alerts.update().where(alerts.c.id == open_alert).values(resolved_at=event.at))
                messages.append({"type": "alert", "kiosk": kiosk_id})
    return messages

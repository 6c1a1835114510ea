"""Clinicians validate a session: correct an item (new option and why; the kiosk's answer is
kept), fill an item the patient did not answer, then a doctor signs off; a doctor may reopen a
signed result to amend it (with a reason), after which it is changed and signed off again. Every
step is a row of the append-only audit trail, and the :class:`kiosk.core.review.Review` exports take
is derived from those rows (:func:`kiosk.core.review.review_from_steps`), so what an export says can
always be traced to who did it and why.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.review import Review, review_from_steps
from kiosk.core.staff import every_entered
from kiosk.export import ExportError
from kiosk.store.database import StoredSession
from station import db, order_progress
from station.auth import User
from station.db import audit, sessions
from station.definitions import questionnaire_for
from station.sessions import load

#: a session that is over (only these can be validated)
REVIEWABLE = ("finished", "abandoned", "interrupted")


class ValidationError(ValueError):
    """A change the station refuses (message says why)."""


@record
class AuditEntry:
    at: str
    author: str
    action: str
    item_id: str | None
    option: int | None
    previous_option: int | None
    reason: str

    @classmethod
    def of(cls, row: Any) -> AuditEntry:
        return cls(row.at, row.author, row.action, row.item_id, row.option, row.previous_option, row.reason)


def _entries(connection: Connection, session_id: str) -> list[AuditEntry]:
    rows = connection.execute(sa.select(audit).where(audit.c.session_id == session_id).order_by(audit.c.id)).all()
    return [AuditEntry.of(r) for r in rows]


def trail(engine: Engine, session_id: str) -> list[AuditEntry]:
    """The session's audit trail, oldest first."""
    with engine.connect() as connection:
        return _entries(connection, session_id)


def lock(connection: Connection, session_id: str) -> None:
    """Hold the session's lock until the transaction ends (PostgreSQL; SQLite serialises writers)."""
    if connection.dialect.name == "postgresql":
        connection.execute(sa.text("SELECT pg_advisory_xact_lock(hashtext(:s))"), {"s": session_id})


def _locked(connection: Connection, session_id: str) -> tuple[StoredSession, list[AuditEntry]]:
    """The session and its trail, read under a per-session lock on PostgreSQL, so two clinicians
    changing one session at once go one after the other (SQLite writers are serialised anyway)."""
    lock(connection, session_id)
    _, stored = load(connection, session_id)
    return stored, _entries(connection, session_id)


def review_of(entries: list[AuditEntry]) -> Review:
    """The review the audit trail amounts to (the kiosk core's one reading of a trail)."""
    return review_from_steps(entries)


def review_in(connection: Connection, session_id: str) -> Review:
    """The session's review, read on an open connection (an export reads it with the session)."""
    return review_of(_entries(connection, session_id))


def review(engine: Engine, session_id: str) -> Review:
    return review_of(trail(engine, session_id))


def reviews(engine: Engine, session_ids: list[str]) -> dict[str, Review]:
    """The reviews of several sessions, read in one query (the ward page's result list)."""
    with engine.connect() as connection:
        return reviews_in(connection, session_ids)


def reviews_in(connection: Connection, session_ids: list[str]) -> dict[str, Review]:
    """:func:`reviews` on an open connection."""
    return {session_id: review_of(found) for session_id, found in trails_in(connection, session_ids).items()}


def trail_in(connection: Connection, session_id: str) -> list[AuditEntry]:
    """The session's audit trail, oldest first, on an open connection."""
    return _entries(connection, session_id)


def trails_in(connection: Connection, session_ids: list[str]) -> dict[str, list[AuditEntry]]:
    """The audit trails of several sessions (oldest first each), read in one query."""
    entries: dict[str, list[AuditEntry]] = {session_id: [] for session_id in session_ids}
    if session_ids:
        query = sa.select(audit).where(audit.c.session_id.in_(session_ids)).order_by(audit.c.id)
        for r in connection.execute(query):
            entries[r.session_id].append(AuditEntry.of(r))
    return entries


def change_item(
    engine: Engine, q: Questionnaire, session_id: str, item_id: str, option: int, reason: str, by: User
) -> None:
    """Correct an answered item or fill an unanswered one (nurse or doctor), before sign-off."""
    reason = reason.strip()
    if not reason:
        raise ValidationError("say why: a correction needs a reason (e.g. 'patient misheard; confirmed by nurse')")
    try:
        item = q.item(item_id)
        item.option(option)
    except KeyError as exc:
        raise ValidationError(str(exc.args[0])) from None
    with engine.begin() as connection:
        stored, entries = _locked(connection, session_id)
        current = review_of(entries)
        _check_open(stored, current)
        previous = current.options({a.item_id: a.option for a in stored.answers}).get(item_id)
        if previous == option:
            raise ValidationError(f"{item_id} already has option {option}")
        connection.execute(
            audit.insert().values(
                session_id=session_id,
                at=db.now_iso(),
                author=by.name,
                action="fill" if previous is None else "correct",
                item_id=item_id,
                option=option,
                previous_option=previous,
                reason=reason[:1000],
            )
        )


def sign_off(
    engine: Engine, session_id: str, by: User, *, incomplete: str = "", fallback: Questionnaire | None = None
) -> str:
    """A doctor makes the result final (as recorded, or with the corrections made): the audit
    row, the session's review state and its order change in one transaction, so a result and its
    order never disagree. A result with unanswered items is signed off only as incomplete, with
    the reason ``incomplete`` (ValidationError naming the items without one); ``fallback``: the
    questionnaire of a session that captured none. Returns the reason stored ('' : complete)."""
    with engine.begin() as connection:
        return sign_off_in(connection, session_id, by, incomplete=incomplete, fallback=fallback)


def unanswered(stored: StoredSession, q: Questionnaire, entries: list[AuditEntry]) -> tuple[str, ...]:
    """The items the result still lacks (after corrections and every number staff entered); an
    answer an older station stored without checking it (an item or option ``q`` lacks) counts
    as none, as the pages show it."""
    items = {item.id: item for item in q.items}
    options = {
        item_id: option
        for item_id, option in review_of(entries).options({a.item_id: a.option for a in stored.answers}).items()
        if item_id in items and items[item_id].entry is None and 1 <= option <= len(items[item_id].options)
    }
    return tuple(q.score_answers(options, values=every_entered(q, stored.log, entries)).missing)


def sign_off_in(
    connection: Connection,
    session_id: str,
    by: User,
    at: str | None = None,
    *,
    incomplete: str = "",
    fallback: Questionnaire | None = None,
) -> str:
    """:func:`sign_off` in the caller's transaction (``at``: when, default now; a history loaded
    in bulk signs many in one transaction, bench/_history.py)."""
    if not by.is_doctor:
        raise ValidationError("only a doctor can sign off a result")
    stored, entries = _locked(connection, session_id)
    _check_open(stored, review_of(entries))
    try:
        missing = unanswered(stored, questionnaire_for(stored, fallback=fallback), entries)
    except (ExportError, ValueError) as exc:
        raise ValidationError(f"the result cannot be scored, so it cannot be signed off: {exc}") from None
    reason = incomplete.strip()[:1000] if missing else ""
    if missing and not reason:
        raise ValidationError(
            f"{len(missing)} item{'s' if len(missing) != 1 else ''} not answered ({', '.join(missing)}): "
            "sign off as incomplete, saying why (e.g. 'patient too tired to go on; not to be repeated')"
        )
    at = at or db.now_iso()
    connection.execute(
        audit.insert().values(session_id=session_id, at=at, author=by.name, action="sign_off", reason=reason)
    )
    connection.execute(sessions.update().where(sessions.c.id == session_id).values(signed_at=at))
    order_progress.signed_off(connection, session_id, by)
    return reason


def amend(engine: Engine, session_id: str, reason: str, by: User) -> None:
    """A doctor reopens a signed-off result to amend it: it can be changed again, and is final
    once a doctor signs it off again (the earlier sign-off stays in the trail). The audit row,
    the session's review state (waiting again) and its order change in one transaction."""
    if not by.is_doctor:
        raise ValidationError("only a doctor can amend a signed-off result")
    reason = reason.strip()
    if not reason:
        raise ValidationError(
            "say why: amending a signed-off result needs a reason (e.g. 'new information from the physiotherapist')"
        )
    with engine.begin() as connection:
        _, entries = _locked(connection, session_id)
        if not review_of(entries).final:
            raise ValidationError("the result is not signed off: change it directly, no need to amend")
        connection.execute(
            audit.insert().values(
                session_id=session_id, at=db.now_iso(), author=by.name, action="amend", reason=reason[:1000]
            )
        )
        connection.execute(sessions.update().where(sessions.c.id == session_id).values(signed_at=None))
        order_progress.reopened(connection, session_id, by)


def _check_open(stored: StoredSession, current: Review) -> None:
    if stored.status not in REVIEWABLE:
        raise ValidationError(f"the session is {stored.status}: it can be validated once it is over")
    if current.final:
        raise ValidationError(
            f"signed off by {current.signed_by} at {current.signed_at}: the result is final "
            "(a doctor can amend it, giving a reason)"
        )


def corrected(
    stored: StoredSession, q: Questionnaire, current: Review, values: Mapping[str, float] | None = None
) -> dict[str, Any]:
    """The items' options after corrections, and the score they give with the numbers staff
    entered (``values``, :func:`kiosk.core.staff.every_entered`) (for the pages and exports)."""
    options = current.options({a.item_id: a.option for a in stored.answers})
    return {"options": options, "score": q.score_answers(options, values=values or {})}

"""The visit as the ward reads and signs it (issue 36): every instrument of one visit with its
total, band, review state, staff items, who answered and every change, and one sign-off for
the whole visit.

A visit is the sessions of one order (a battery: one session per instrument); a session no order
started is a visit of its own. The visit's key is its order's id, else its session's id; any
session id of the visit finds it too. The summary of each instrument (title, total, band, who
answered, who signed) is the print view's (:func:`station.printing.visits_of`); this module adds
what a doctor checks before signing: the changes and staff-entered values in words, the items
still unanswered, and what each result will be called once signed.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from datetime import tzinfo

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.questionnaire import Item, Questionnaire
from kiosk.core.review import review_state, state_once_signed
from kiosk.core.staff import ENTER, STAFF_ANSWER, every_entered, number_text, read_detail
from kiosk.export import ExportError
from station import db, printing, tugs, validation
from station.auth import User
from station.db import audit, sessions, visits
from station.definitions import questionnaire_for
from station.sessions import SAMPLE_KINDS, NotFound, StoredSession, load_many
from station.tugs import StationTug
from station.validation import AuditEntry, ValidationError


@record
class InstrumentResult:
    """One instrument of a visit as its page and its sign-off show it."""

    #: title, total, band, who answered, who signed (the print view's reading)
    printed: printing.PrintedResult
    #: the review state now, and the one a sign-off gives it (kiosk.core.review)
    state: str
    will_be: str
    #: every change made at the station, in words (corrections and filled items)
    changes: list[str]
    #: each staff item: its text and the value or option entered, or "not entered"
    staff: list[str]
    #: the items still unanswered, by their text (a sign-off then needs a reason)
    missing: list[str]
    #: over (finished, abandoned, interrupted) and not signed off: a doctor can sign it off
    signable: bool
    #: signed off (final): a doctor can reopen it to amend it
    final: bool
    #: the session's status when it is not over ("in progress"), else ""
    running: str

    @property
    def session_id(self) -> str:
        return self.printed.session_id

    @property
    def state_words(self) -> str:
        return self.state.replace("_", " ")

    @property
    def will_be_words(self) -> str:
        return ("signed off as incomplete" if self.missing else self.will_be.replace("_", " ")) + (
            f" with {len(self.changes)} change{'s' if len(self.changes) != 1 else ''}" if self.changes else ""
        )


@record
class Visit:
    """One visit: the patient, when and where, and each instrument in the order run."""

    key: str
    patient_id: str
    kiosk_id: str
    date: str
    order_id: str | None
    results: list[InstrumentResult]
    #: what the visit looked like when read (its sessions, their states, their audit): a sign-off
    #: made from this reading is refused if the visit changed since (:func:`sign_off`)
    seen: str
    #: the visit's Timed Up and Go results (station.tugs), oldest first
    tugs: tuple[StationTug, ...] = ()

    @property
    def signable(self) -> list[InstrumentResult]:
        return [r for r in self.results if r.signable]

    @property
    def running(self) -> list[InstrumentResult]:
        return [r for r in self.results if r.running]


def sessions_of(connection: Connection, key: str) -> tuple[str, list[str]]:
    """The visit ``key`` names (an order id, or any session id of the visit): its canonical key
    and its sessions that reached the station (NotFound if none)."""
    members = list(connection.execute(sa.select(visits.c.session_id).where(visits.c.order_id == key)).scalars())
    if members:
        return key, members
    order_id = connection.execute(sa.select(visits.c.order_id).where(visits.c.session_id == key)).scalar()
    if order_id:
        return order_id, list(
            connection.execute(sa.select(visits.c.session_id).where(visits.c.order_id == order_id)).scalars()
        )
    if connection.execute(sa.select(sessions.c.id).where(sessions.c.id == key)).first() is None:
        raise NotFound(key)
    return key, [key]


def _seen(connection: Connection, ids: list[str]) -> str:
    """A fingerprint of the visit's sessions, their states and their audit trails."""
    states = connection.execute(
        sa.select(sessions.c.id, sessions.c.status, sessions.c.signed_at)
        .where(sessions.c.id.in_(ids))
        .order_by(sessions.c.id)
    ).all()
    last = connection.execute(sa.select(sa.func.max(audit.c.id)).where(audit.c.session_id.in_(ids))).scalar()
    return hashlib.sha256(json.dumps([[list(r) for r in states], last]).encode()).hexdigest()[:20]


def _in(texts: Mapping[str, str], language: str, fallback: str) -> str:
    return texts.get(language) or texts.get("en") or next(iter(texts.values()), fallback)


def _option(item: Item | None, option: int | None, language: str) -> str:
    """An option as staff read it: its label in quotes, else its number."""
    if option is None:
        return "not answered"
    if item is not None and 1 <= option <= len(item.options):
        return f"“{_in(item.option(option).label, language, str(option))}”"
    return f"option {option}"


def _changes(q: Questionnaire, stored: StoredSession, trail: list[AuditEntry]) -> list[str]:
    """Every correction, filled item and number entered at the station, in words, oldest first."""
    items = {item.id: item for item in q.items}
    language, found = stored.language, []
    for step in trail:
        item = items.get(step.item_id or "")
        text = _in(item.text, language, step.item_id or "") if item else step.item_id or ""
        if step.action in ("correct", "fill"):
            found.append(
                f"{text}: {_option(item, step.previous_option, language)} changed to "
                f"{_option(item, step.option, language)} by {step.author} (“{step.reason}”)"
            )
        elif step.action == ENTER:
            unit = f" {item.entry.unit}" if item and item.entry and item.entry.unit else ""
            found.append(f"{text}: {step.reason}{unit} entered by {step.author}")
    return found


def _staff(q: Questionnaire, stored: StoredSession, trail: list[AuditEntry], options: Mapping[str, int]) -> list[str]:
    """Each staff item with what was entered for it (at the kiosk or the station)."""
    entered = every_entered(q, stored.log, trail)
    by = {step.item_id: step.author for step in trail if step.action == ENTER}
    for line in stored.log:
        data = read_detail(line.detail) if line.kind == STAFF_ANSWER else None
        if data is not None and data["item_id"] not in by:
            by[data["item_id"]] = f"{data.get('by') or 'staff'} at the kiosk"
    found = []
    for item in (i for i in q.items if i.staff):
        text = _in(item.text, stored.language, item.id)
        if item.id in entered:
            unit = f" {item.entry.unit}" if item.entry and item.entry.unit else ""
            found.append(f"{text}: {number_text(entered[item.id])}{unit} (entered by {by.get(item.id, 'staff')})")
        elif item.id in options:
            found.append(f"{text}: {_option(item, options[item.id], stored.language)}")
        else:
            found.append(f"{text}: not entered")
    return found


def _instrument(
    printed: printing.PrintedResult, stored: StoredSession, q: Questionnaire, trail: list[AuditEntry]
) -> InstrumentResult:
    review = validation.review_of(trail)
    recorded = {a.item_id: a.option for a in stored.answers}
    over = stored.status in validation.REVIEWABLE
    try:
        ran = questionnaire_for(stored, fallback=q if stored.questionnaire_id == q.id else None)
    except ExportError:
        ran = None
    changes: list[str] = []
    staff: list[str] = []
    missing: list[str] = []
    if ran is not None and ran.id == stored.questionnaire_id:
        texts = {item.id: _in(item.text, stored.language, item.id) for item in ran.items}
        changes = _changes(ran, stored, trail)
        staff = _staff(ran, stored, trail, review.options(recorded))
        missing = [texts.get(i, i) for i in validation.unanswered(stored, ran, trail)] if over else []
    return InstrumentResult(
        printed,
        review_state(review, recorded).value,
        state_once_signed(review, recorded).value,
        changes,
        staff,
        missing,
        over and not review.final,
        review.final,
        "" if over else stored.status.replace("_", " "),
    )


def read(engine: Engine, q: Questionnaire, key: str, zone: tzinfo | None = None) -> Visit:
    """The visit ``key`` names (:func:`sessions_of`), read in one connection (NotFound if no
    session of it reached the station)."""
    with engine.connect() as connection:
        key, ids = sessions_of(connection, key)
        found = printing.visits_of(connection, q, ids, zone)
        if not found:
            raise NotFound(key)
        loaded = load_many(connection, ids, without=SAMPLE_KINDS)
        trails = validation.trails_in(connection, ids)
        seen = _seen(connection, ids)
        found_tugs = tugs.of_sessions(connection, ids)
    shown = found[0]
    return Visit(
        key,
        shown.patient_id,
        shown.kiosk_id,
        shown.date,
        shown.order_id,
        [_instrument(p, loaded[p.session_id][1], q, trails[p.session_id]) for p in shown.results],
        seen,
        tuple(found_tugs),
    )


def sign_off(
    engine: Engine,
    q: Questionnaire,
    key: str,
    by: User,
    *,
    seen: str,
    reasons: Mapping[str, str] | None = None,
) -> list[str]:
    """A doctor signs off every result of the visit that waits for it, in ONE transaction: all
    are signed or none (a result with unanswered items only as incomplete, with its reason in
    ``reasons`` by session id; :func:`station.validation.sign_off_in`). Refused when the visit
    changed since the doctor read it (``seen``: :attr:`Visit.seen`), or nothing in it waits.
    Returns the sessions signed, in the order run."""
    if not by.is_doctor:
        raise ValidationError("only a doctor can sign off a visit")
    reasons = reasons or {}
    with engine.begin() as connection:
        key, ids = sessions_of(connection, key)
        for session_id in sorted(ids):  # one order of locks: two doctors signing never deadlock
            validation.lock(connection, session_id)
        if _seen(connection, ids) != seen:
            raise ValidationError(
                "the visit changed since you read it (a result arrived or was changed): check it again"
            )
        waiting = connection.execute(
            sa.select(sessions.c.id, sessions.c.started_at).where(
                sessions.c.id.in_(ids), sessions.c.status.in_(validation.REVIEWABLE), sessions.c.signed_at.is_(None)
            )
        ).all()
        if not waiting:
            raise ValidationError("nothing in this visit waits for sign-off")
        at = db.now_iso()
        signed = []
        for row in sorted(waiting, key=lambda r: (r.started_at or "", r.id)):
            try:
                validation.sign_off_in(connection, row.id, by, at, incomplete=reasons.get(row.id, ""), fallback=q)
            except ValidationError as exc:
                raise ValidationError(f"{_title(connection, q, row.id)}: {exc}; nothing was signed off") from None
            signed.append(row.id)
    return signed


def _title(connection: Connection, q: Questionnaire, session_id: str) -> str:
    """An instrument's title as staff read it, for a refusal's message."""
    _, stored = load_many(connection, [session_id], ("create_session",))[session_id]
    try:
        ran = questionnaire_for(stored, fallback=q if stored.questionnaire_id == q.id else None)
    except ExportError:
        return stored.questionnaire_id
    return _in(ran.title, stored.language, ran.id)


def questionnaire_of(engine: Engine, session_id: str, fallback: Questionnaire | None = None) -> Questionnaire:
    """The questionnaire a session ran (its captured definition, else ``fallback``)."""
    with engine.connect() as connection:
        _, stored = load_many(connection, [session_id], ("create_session",))[session_id]
    return questionnaire_for(stored, fallback=fallback)

"""Visits ordered from the ward: who orders what for which patient on which kiosk, and the order's
way from ``ordered`` to ``signed off``.

An order names the patient by the identifier the hospital gives (pseudonymous: see
:func:`check_patient_id`), one kiosk, the instruments (a list, so a battery fits; today the
station's one questionnaire), the language, whether a relative answers and, optionally, how the
person answering is related to the patient (:func:`check_relationship`). Its states::

    ordered -> in_progress -> awaiting_validation -> signed_off
       |            |
       +-> cancelled <-+          (an abandoned session puts an order back to ordered)

The kiosk takes an order only with the short code the station shows on the order's page, typed at
the kiosk by staff who see the patient (:func:`start`): so a result never lands under a patient who
is not there. The kiosk's session then says which order it is for (a ``visit`` entry of its log,
protocol §4); :func:`on_rows` links it when that row arrives and moves the order on as the session
finishes or is abandoned. Every step is a row of the append-only audit trail, keyed by the
order's id (``order-…``), so an order's history reads like a session's.
"""

from __future__ import annotations

import json
import math
import secrets
from collections.abc import Sequence
from datetime import UTC, datetime
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.answerers import RELATIONSHIPS, TEXT_MAX
from kiosk.core.visits import DEFAULT_ID_PATTERN, HOSPITAL_ID, TUG
from kiosk.core.visits import check_patient_id as identifier_problem
from station import bookings, db
from station.db import audit, code_failures, kiosks, orders

#: a hospital's patient identifier: letters, digits, '-' and '_', 2 to 64, and at least one digit,
#: and, where staff type one, the site's pattern (digit-dominant by default), so "Maria Lopez",
#: "LOPEZ" or "MariaLopez19450312" are refused: identifiers such as "NHC-0012345" or "12345678"
#: are what a ward types. The kiosk's clinician screen checks the same rule (one definition, in
#: kiosk.core.visits: check_patient_id).
PATIENT_ID = HOSPITAL_ID
STATES = ("ordered", "in_progress", "awaiting_validation", "signed_off", "cancelled")
WORDS = {
    "ordered": "ordered",
    "in_progress": "in progress",
    "awaiting_validation": "awaiting validation",
    "signed_off": "signed off",
    "cancelled": "cancelled",
}
OPEN = ("ordered", "in_progress")
#: the Timed Up and Go as staff order it (id ``tug``): no language of its own (the kiosk speaks
#: the visit's), staff beside the patient -- as at every ordered visit, whose code staff type
TUG_TITLE = "Timed Up and Go"
#: digits of the confirmation code typed at the kiosk
CODE_DIGITS = 4
#: wrong codes are throttled by spacing the kiosk's checks, never by refusing its right code
#: (issue 32; docs/visit-code.md): with n wrong codes in the last CODE_WINDOW_S, the next check
#: waits CODE_GAPS_S[n] (the last entry beyond) after the latest one. A typo costs nothing, a
#: second 15 s; a guesser settles at one check per 120 s, the 5 per 10 minutes of the lockout
#: this replaces, and staff with the right code wait at most 120 s, whatever was typed before.
CODE_WINDOW_S = 10 * 60
CODE_GAPS_S = (0, 0, 15, 60, 120)
#: who may order (every staff role) and who signs off (doctors: station.validation)
ORDER_ROLES = ("nurse", "doctor")
#: orders one member of staff may place within the window (a ward round is a few dozen at most:
#: more is a script or a session left open on a stolen phone)
MAX_ORDERS_PER_USER = 30
ORDER_WINDOW_S = 10 * 60


class OrderError(ValueError):
    """An order or a step the station refuses (one sentence naming the field and the problem)."""


class TooManyCodes(OrderError):
    """The kiosk's next code cannot be checked yet: :attr:`retry_after_s` says when it can."""

    status = 429

    def __init__(self, retry_after_s: int) -> None:
        self.retry_after_s = retry_after_s
        super().__init__(f"after wrong codes the station checks the next one in {retry_after_s} seconds")


class DoubleBooking(OrderError):
    """The order would double-book a patient or a kiosk (:mod:`station.bookings`): ordered only
    when staff confirm, ``anyway``; :attr:`warnings` say what they confirm."""

    status = 409

    def __init__(self, warnings: list[str]) -> None:
        self.warnings = warnings
        super().__init__("; ".join(warnings))


class LinkRefused(OrderError):
    """A kiosk's session claims an order it may not (another kiosk's, another patient's): the
    sync refuses the row (422, so the kiosk parks it) and nothing is filed under the order."""

    status = 422


@record
class Order:
    id: str
    kiosk_id: str
    patient_id: str
    instruments: tuple[str, ...]
    language: str
    answered_by: str
    code: str
    state: str
    ordered_by: str
    ordered_at: str
    session_id: str | None
    updated_at: str
    #: how the person answering is related to the patient (kiosk.core.answerers), None: not said
    relationship: str | None = None
    #: the relationship in words, for "other" only
    relationship_text: str | None = None

    @classmethod
    def of(cls, row: Any) -> Order:
        values = dict(row._mapping)
        values["instruments"] = tuple(json.loads(values["instruments"]))
        return cls(**values)

    @property
    def words(self) -> str:
        return WORDS.get(self.state, self.state)

    @property
    def relative(self) -> bool:
        return self.answered_by == "relative"

    @property
    def answerer(self) -> str:
        """Who answers, in words: "the patient", "a relative", "their daughter", "other: lodger"."""
        if self.relationship == "other":
            return f"other: {self.relationship_text}"
        if self.relationship:
            return f"their {self.relationship}"
        return "a relative" if self.relative else "the patient"

    def for_kiosk(self) -> dict[str, Any]:
        """What the kiosk is told of the order (never the code: staff bring it from the station);
        ``relationship`` (and, for "other", ``relationship_text``) only when staff said (§4)."""
        told: dict[str, Any] = {
            "id": self.id,
            "patient_id": self.patient_id,
            "instruments": list(self.instruments),
            "language": self.language,
            "answered_by": self.answered_by,
            "ordered_by": self.ordered_by,
            "ordered_at": self.ordered_at,
        }
        if self.relationship:
            told["relationship"] = self.relationship
            if self.relationship == "other":
                told["relationship_text"] = self.relationship_text or ""
        return told


def check_patient_id(value: str, pattern: str = DEFAULT_ID_PATTERN) -> str:
    """The identifier, stripped, if it is pseudonymous (:data:`PATIENT_ID`) and matches the site's
    ``pattern``; else OrderError."""
    value = value.strip()
    if not value:
        raise OrderError("patient identifier: give the identifier the hospital uses (e.g. NHC-0012345)")
    problem = identifier_problem(value, pattern)
    if problem is not None:
        raise OrderError(f"patient identifier: {problem}")
    return value


def check_relationship(relationship: str, text: str) -> tuple[str | None, str | None]:
    """Who answers for the patient, as the order form gives it: ``(relationship, text)``, both
    None when not said; OrderError when the relationship is not one of
    kiosk.core.answerers.RELATIONSHIPS, or the text is given without "other", missing with it,
    longer than :data:`TEXT_MAX` or more than one line (the kiosk refuses such an order)."""
    relationship, text = relationship.strip(), text.strip()
    where = "who answers for the patient"
    if not relationship:
        if text:
            raise OrderError(f'{where}: choose "other" to describe the relationship in words')
        return None, None
    if relationship not in RELATIONSHIPS:
        raise OrderError(f"{where}: {relationship[:40]!r} is not one of {', '.join(RELATIONSHIPS)}")
    if relationship != "other":
        if text:
            raise OrderError(f'{where}: words are only for "other" (you chose {relationship})')
        return relationship, None
    if not text:
        raise OrderError(f'{where}: say in words how they are related to the patient (for "other")')
    if len(text) > TEXT_MAX or any(ord(c) < 32 for c in text):
        raise OrderError(f"{where}: the relationship in words must be one line of at most {TEXT_MAX} characters")
    return relationship, text


def audit_order(connection: Connection, order_id: str, author: str, action: str, reason: str) -> None:
    connection.execute(
        audit.insert().values(
            session_id=order_id, at=db.now_iso(), author=author[:64], action=action, reason=reason[:1000]
        )
    )


@record
class Instrument:
    """An instrument staff may order: its id, title (English, else any) and languages."""

    id: str
    title: str
    languages: tuple[str, ...]


def instruments(engine: Engine, bundled: Any) -> list[Instrument]:
    """What staff may order: the station's bundled questionnaire, then every other one a kiosk
    has run here (its latest stored definition), so a site running its own questionnaire can
    order it, then the Timed Up and Go (no languages: it takes the visit's); the kiosks still
    take only orders for instruments they give."""
    found = {bundled.id: Instrument(bundled.id, bundled.title.get("en") or bundled.id, tuple(bundled.languages))}
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(db.definitions.c.questionnaire_id, db.definitions.c.body)
            .where(db.definitions.c.questionnaire_id != bundled.id)
            .order_by(db.definitions.c.stored_at.desc())
        ).all()
    for row in rows:
        if row.questionnaire_id in found:
            continue
        try:
            body = json.loads(row.body)
            title, languages = body.get("title") or {}, [str(lang) for lang in body["languages"]]
        except (ValueError, KeyError, TypeError, AttributeError):
            continue  # stored definitions were checked at sync; one that does not read is not offered
        name = title.get("en") or next(iter(title.values()), row.questionnaire_id) if isinstance(title, dict) else ""
        found[row.questionnaire_id] = Instrument(
            row.questionnaire_id, str(name or row.questionnaire_id), tuple(languages)
        )
    found[TUG] = Instrument(TUG, TUG_TITLE, ())
    return list(found.values())


def create(
    engine: Engine,
    *,
    kiosk_id: str,
    patient_id: str,
    instruments: Sequence[str],
    language: str,
    relative: bool,
    by: Any,
    known_instruments: Sequence[str],
    languages: Sequence[str],
    id_pattern: str = DEFAULT_ID_PATTERN,
    relationship: str = "",
    relationship_text: str = "",
    anyway: bool = False,
) -> Order:
    """Order a visit (a nurse or a doctor) for a patient whose identifier ``id_pattern`` (the
    site's rule) matches; returns it with its confirmation code. A ``relationship``
    (:func:`check_relationship`) says who answers for the patient, so a relative does. A double
    booking (:mod:`station.bookings`) is refused, or raises :class:`DoubleBooking` unless staff
    order ``anyway`` (the trail then says what they confirmed)."""
    if by.role not in ORDER_ROLES:
        raise OrderError("only nurses and doctors may order a visit")
    patient_id = check_patient_id(patient_id, id_pattern)
    relationship_code, words = check_relationship(relationship, relationship_text)
    relative = relative or relationship_code is not None
    chosen = [i for i in dict.fromkeys(instruments) if i]
    if not chosen:
        raise OrderError("instruments: choose at least one")
    if all(i == TUG for i in chosen):  # the kiosk gives it within a visit, beside a questionnaire
        raise OrderError(f"instruments: the {TUG_TITLE} is given within a visit: choose an instrument with it")
    unknown = [i for i in chosen if i not in known_instruments]
    if unknown:
        raise OrderError(
            f"instruments: {', '.join(unknown)} is not one this station knows ({', '.join(known_instruments)})"
        )
    if language not in languages:
        raise OrderError(f"language {language!r}: choose one of {', '.join(languages)}")
    now = db.now_iso()
    since = datetime.fromtimestamp(db.now() - ORDER_WINDOW_S, UTC).isoformat(timespec="milliseconds")
    with engine.begin() as connection:
        recent = connection.execute(
            sa.select(sa.func.count())
            .select_from(orders)
            .where(orders.c.ordered_by == by.name, orders.c.ordered_at > since)
        ).scalar_one()
        if recent >= MAX_ORDERS_PER_USER:
            raise OrderError(
                f"you have ordered {recent} visits in the last {ORDER_WINDOW_S // 60} minutes: "
                "wait a little, or ask a colleague"
            )
        row = connection.execute(sa.select(kiosks.c.revoked_at).where(kiosks.c.name == kiosk_id)).first()
        if row is None or row.revoked_at is not None:
            raise OrderError(f"kiosk {kiosk_id!r}: no such kiosk with a valid token")
        refusal, warnings = bookings.check(connection, kiosk_id, patient_id)
        if refusal is not None:
            raise OrderError(refusal)
        if warnings and not anyway:
            raise DoubleBooking(warnings)
        taken = set(
            connection.execute(
                sa.select(orders.c.code).where(orders.c.kiosk_id == kiosk_id, orders.c.state.in_(OPEN))
            ).scalars()
        )
        code = _new_code(taken)
        order_id = "order-" + secrets.token_hex(6)
        connection.execute(
            orders.insert().values(
                id=order_id,
                kiosk_id=kiosk_id,
                patient_id=patient_id,
                instruments=json.dumps(chosen),
                language=language,
                answered_by="relative" if relative else "patient",
                code=code,
                state="ordered",
                ordered_by=by.name,
                ordered_at=now,
                updated_at=now,
                relationship=relationship_code,
                relationship_text=words,
            )
        )
        audit_order(
            connection,
            order_id,
            by.name,
            "order",
            f"{', '.join(chosen)} for {patient_id} on {kiosk_id} ({language}"
            f"{', a relative answers' if relative else ''}"
            f"{f', related: {relationship_code}' if relationship_code else ''}{f': {words}' if words else ''})"
            + (f"; ordered anyway: {'; '.join(warnings)}" if warnings else ""),
        )
        return Order.of(connection.execute(sa.select(orders).where(orders.c.id == order_id)).one())


def _new_code(taken: set[str]) -> str:
    """A code no open order of the kiosk has (the kiosk finds the order by it)."""
    while True:
        code = f"{secrets.randbelow(10**CODE_DIGITS):0{CODE_DIGITS}d}"
        if code not in taken:
            return code


def get(engine: Engine, order_id: str) -> Order | None:
    with engine.connect() as connection:
        row = connection.execute(sa.select(orders).where(orders.c.id == order_id)).first()
    return Order.of(row) if row else None


def listing(
    engine: Engine,
    *,
    kiosk_id: str | None = None,
    states: Sequence[str] | None = None,
    patient_id: str | None = None,
    limit: int = 200,
) -> list[Order]:
    """Orders, newest first, optionally of one kiosk, in some states, of one patient."""
    query = sa.select(orders).order_by(orders.c.ordered_at.desc()).limit(limit)
    if kiosk_id:
        query = query.where(orders.c.kiosk_id == kiosk_id)
    if states:
        query = query.where(orders.c.state.in_(list(states)))
    if patient_id:
        query = query.where(orders.c.patient_id == patient_id)
    with engine.connect() as connection:
        return [Order.of(r) for r in connection.execute(query)]


def ready_for(connection: Connection, kiosk_id: str) -> list[Order]:
    """The kiosk's orders waiting to be started, oldest first."""
    return [
        Order.of(r)
        for r in connection.execute(
            sa.select(orders)
            .where(orders.c.kiosk_id == kiosk_id, orders.c.state == "ordered")
            .order_by(orders.c.ordered_at)
        )
    ]


#: the kiosk's latest cancelled orders told on every orders poll beside the held ones: a visit
#: cancelled just after its code started it, before the kiosk's poll could say it holds it
RECENT_CANCELLED = 5


def cancelled_for(connection: Connection, kiosk_id: str, held: set[str]) -> list[str]:
    """The kiosk's cancelled orders it may still be running (protocol §4, ``cancelled``): those it
    says it holds, and its :data:`RECENT_CANCELLED` latest; the kiosk ends a running one."""
    mine = sa.and_(orders.c.kiosk_id == kiosk_id, orders.c.state == "cancelled")
    recent = connection.execute(
        sa.select(orders.c.id).where(mine).order_by(orders.c.updated_at.desc()).limit(RECENT_CANCELLED)
    ).scalars()
    found = set(recent)
    if held:
        found |= set(connection.execute(sa.select(orders.c.id).where(mine, orders.c.id.in_(sorted(held)))).scalars())
    return sorted(found)


def cancel(engine: Engine, order_id: str, by: Any, reason: str) -> Order:
    """Cancel an order not yet done (who and why go to the trail)."""
    if by.role not in ORDER_ROLES:
        raise OrderError("only nurses and doctors may cancel a visit")
    with engine.begin() as connection:
        row = connection.execute(sa.select(orders).where(orders.c.id == order_id)).first()
        if row is None:
            raise OrderError(f"no order {order_id}")
        if row.state not in OPEN:
            raise OrderError(f"the order is {WORDS[row.state]}: only an ordered or running visit can be cancelled")
        connection.execute(
            orders.update().where(orders.c.id == order_id).values(state="cancelled", updated_at=db.now_iso())
        )
        audit_order(connection, order_id, by.name, "order_cancel", reason.strip() or "cancelled")
        return Order.of(connection.execute(sa.select(orders).where(orders.c.id == order_id)).one())


def next_check_in(connection: Connection, kiosk_id: str, now: float) -> float:
    """Seconds until the station checks the kiosk's next code (0 or less: now): the gap of
    :data:`CODE_GAPS_S` for its wrong codes in the window, counted from the latest of them."""
    failures, latest = connection.execute(
        sa.select(sa.func.count(), sa.func.max(code_failures.c.at)).where(
            code_failures.c.kiosk_id == kiosk_id, code_failures.c.at > now - CODE_WINDOW_S
        )
    ).one()
    if not failures:
        return 0.0
    return float(latest) + CODE_GAPS_S[min(failures, len(CODE_GAPS_S) - 1)] - now


def start(connection: Connection, kiosk_id: str, code: str) -> Order | None:
    """The kiosk's staff typed ``code``: the kiosk's ordered visit with that code moves to in
    progress and is returned; None for a wrong code, which is counted (in the caller's
    transaction, so commit it). A code sent before its slot (:func:`next_check_in`) is not looked
    at: :class:`TooManyCodes` says when to send it again, and any code sent then, the right one
    included, is checked. Callers hold the kiosk's row (``auth.touch_kiosk``), so concurrent
    guesses take their slots one by one. Another kiosk's order is never found: the code is looked
    up among this kiosk's orders only."""
    now = db.now()
    since = now - CODE_WINDOW_S
    wait = next_check_in(connection, kiosk_id, now)
    if wait > 0:
        raise TooManyCodes(math.ceil(wait))
    code = str(code).strip()
    row = None
    if code.isdigit() and len(code) == CODE_DIGITS:
        row = connection.execute(
            sa.select(orders)
            .where(orders.c.kiosk_id == kiosk_id, orders.c.state == "ordered", orders.c.code == code)
            .with_for_update()
        ).first()
    if row is None:
        connection.execute(code_failures.delete().where(code_failures.c.at < since))
        connection.execute(code_failures.insert().values(kiosk_id=kiosk_id, at=now))
        return None
    connection.execute(
        orders.update().where(orders.c.id == row.id).values(state="in_progress", updated_at=db.now_iso())
    )
    audit_order(
        connection,
        row.id,
        f"kiosk {kiosk_id}",
        "order_start",
        f"staff confirmed patient {row.patient_id} at {kiosk_id} with the order's code",
    )
    return Order.of(connection.execute(sa.select(orders).where(orders.c.id == row.id)).one())

"""A clinician's own result of the same instrument for the same visit (a validation study, issue
36 part 8): the answer the clinician got for each item, entered at the station beside the kiosk's
result and kept apart from it (:data:`station.db.reference_results`), so it never changes the
kiosk's answers, its total, its review or its exports.

Each entry is a row with the staff member who entered it and when; the table is append-only in
the database, so a corrected answer is a newer row and the latest per item is the clinician's
answer (:func:`answers_in`). Only the patient's items with options are asked (a number staff
enter, or an item staff answer anyway, is the same on both sides).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.questionnaire import Item, Questionnaire
from kiosk.store.database import StoredSession
from station import db
from station.auth import User
from station.db import reference_results
from station.definitions import questionnaire_for
from station.sessions import load

#: a result the clinician's can stand beside: the kiosk's is over and complete as far as it went
FINISHED = "finished"


class EntryRefused(ValueError):
    """An entry the station refuses (message names the item and what is wrong)."""


@record
class ReferenceAnswer:
    """One answer the clinician got for an item, as entered."""

    item_id: str
    option: int
    entered_by: str
    entered_at: str


def questionnaire_of(stored: StoredSession, fallback: Questionnaire) -> Questionnaire:
    """The questionnaire the session ran (the clinician answers the same one); ExportError if
    the station cannot read it."""
    return questionnaire_for(stored, fallback=fallback)


def asked(q: Questionnaire) -> list[Item]:
    """The items a clinician's result answers: the patient's items with options, in order."""
    return [item for item in q.items if item.options and not item.staff]


def _rows(connection: Connection, session_ids: list[str]) -> Iterable[sa.Row]:
    query = (
        sa.select(reference_results)
        .where(reference_results.c.session_id.in_(session_ids))
        .order_by(reference_results.c.session_id, reference_results.c.id)
    )
    return connection.execute(query)


def history_in(connection: Connection, session_id: str) -> list[ReferenceAnswer]:
    """Every entry for the session, oldest first (the page's trail)."""
    return [ReferenceAnswer(r.item_id, r.option, r.entered_by, r.entered_at) for r in _rows(connection, [session_id])]


def answers_in(connection: Connection, session_ids: list[str]) -> dict[str, dict[str, ReferenceAnswer]]:
    """The clinician's answer per item (the latest entry) of each session that has one."""
    found: dict[str, dict[str, ReferenceAnswer]] = {}
    if session_ids:
        for r in _rows(connection, session_ids):
            found.setdefault(r.session_id, {})[r.item_id] = ReferenceAnswer(
                r.item_id, r.option, r.entered_by, r.entered_at
            )
    return found


def checked(q: Questionnaire, chosen: Mapping[str, str]) -> dict[str, int]:
    """The options ``chosen`` (item id -> the option number as the form sent it; "" for an item
    the clinician did not ask) as numbers; EntryRefused naming the first that is not one of the
    item's options, or when none is chosen."""
    items = {item.id: item for item in asked(q)}
    options: dict[str, int] = {}
    for item_id, text in chosen.items():
        if not text.strip():
            continue
        item = items.get(item_id)
        if item is None:
            raise EntryRefused(f"{item_id[:64]!r} is not a question of {q.id} a clinician answers")
        try:
            option = int(text)
        except ValueError:
            option = 0
        if not 1 <= option <= len(item.options):
            raise EntryRefused(
                f"{item_id}: {text[:20]!r} is not one of its {len(item.options)} answers; choose one from the list"
            )
        options[item_id] = option
    if not options:
        raise EntryRefused("Choose the clinician's answer for at least one question.")
    return options


def record_answers(engine: Engine, q: Questionnaire, session_id: str, chosen: Mapping[str, str], by: User) -> int:
    """Store the clinician's answers ``chosen`` for the session (EntryRefused, NotFound); an
    answer equal to the one already stored is not stored again. Returns how many were stored."""
    options = checked(q, chosen)
    with engine.begin() as connection:
        if connection.dialect.name == "postgresql":  # two clinicians entering at once: one after the other
            connection.execute(sa.text("SELECT pg_advisory_xact_lock(hashtext(:s))"), {"s": "reference:" + session_id})
        _, stored = load(connection, session_id)
        if stored.status != FINISHED:
            raise EntryRefused(
                f"the kiosk's result is {stored.status}, not finished: "
                "a clinician's result is entered beside a finished one"
            )
        if stored.questionnaire_id != q.id:
            raise EntryRefused(f"the session ran {stored.questionnaire_id}, not {q.id}")
        current = answers_in(connection, [session_id]).get(session_id, {})
        new = {i: o for i, o in options.items() if i not in current or current[i].option != o}
        at = db.now_iso()
        if new:
            connection.execute(
                reference_results.insert(),
                [
                    {
                        "session_id": session_id,
                        "questionnaire_id": q.id,
                        "item_id": item_id,
                        "option": option,
                        "entered_by": by.name,
                        "entered_at": at,
                    }
                    for item_id, option in new.items()
                ],
            )
    return len(new)

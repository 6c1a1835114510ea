"""Staff items (``answered_by: staff``) entered at the station: the number form of a session page.

A staff item with options is filled like any unanswered item (the corrections form, audited with
a reason). A number (``input:``, a weight in kg) is entered here: checked against the item's
range (:func:`kiosk.core.staff.entry_text`) and stored as one audit row, action
:data:`kiosk.core.staff.ENTER`, its ``reason`` column holding the number as typed (no schema change: the
audit already says who and when). The session's numbers are those the kiosk's staff entered (its
log) overlaid by the station's (:func:`values`).
"""

from __future__ import annotations

from collections.abc import Iterable
from urllib.parse import quote

from sqlalchemy.engine import Engine
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import Route

from kiosk.core.questionnaire import Questionnaire
from kiosk.core.staff import ENTER, EnteredStep, entry_text, every_entered
from kiosk.store.database import StoredSession
from station import db
from station.auth import User
from station.definitions import questionnaire_for
from station.redirects import see_other
from station.rendering import checked_form
from station.sessions import NotFound, load
from station.validation import ValidationError, _check_open, _locked, review_of


def values(q: Questionnaire, stored: StoredSession, trail: Iterable[EnteredStep]) -> dict[str, float]:
    """Every number staff entered for the session: at the kiosk, then at the station (later wins)."""
    return every_entered(q, stored.log, trail)


def enter_value(engine: Engine, q: Questionnaire, session_id: str, item_id: str, typed: str, by: User) -> None:
    """Store the number ``typed`` for staff item ``item_id`` (ValidationError naming the item
    and its range when it is none, or when the result is signed off)."""
    try:
        item = q.item(item_id)
    except KeyError as exc:
        raise ValidationError(str(exc.args[0])) from None
    if not item.staff or item.entry is None:
        raise ValidationError(f"{item_id} is not a number staff enter")
    try:
        text = entry_text(item, typed)
    except ValueError as exc:
        raise ValidationError(str(exc)) from None
    with engine.begin() as connection:
        stored, entries = _locked(connection, session_id)
        _check_open(stored, review_of(entries))
        connection.execute(
            db.audit.insert().values(
                session_id=session_id,
                at=db.now_iso(),
                author=by.name,
                action=ENTER,
                item_id=item_id,
                reason=text,  # as entered (never %g: 1234567 stays 1234567)
            )
        )


def _load(engine: Engine, session_id: str) -> StoredSession:
    with engine.connect() as connection:
        return load(connection, session_id)[1]


async def enter_page(request: Request) -> Response:
    """POST a number for a staff item; back to the session page saying what happened."""
    form = await checked_form(request)
    engine = request.app.state.engine
    session_id, item_id = request.path_params["session_id"], request.path_params["item_id"]
    try:
        stored = await run_in_threadpool(_load, engine, session_id)
        q = questionnaire_for(stored, fallback=request.app.state.questionnaire)
        user = request.state.user
        await run_in_threadpool(enter_value, engine, q, session_id, item_id, str(form.get("value", "")), user)
        message = f"{item_id} entered."
    except (ValidationError, NotFound) as exc:
        message = str(exc)
    return see_other(f"/sessions/{quote(session_id)}", message=message)


routes = [Route("/sessions/{session_id}/staff/{item_id}", enter_page, methods=["POST"])]

"""The validation study's pages (issue 36, part 8): a clinician's result entered beside a kiosk
result (``/sessions/{id}/reference``), and a study's agreement as a page and a CSV (``/study``).

Routes only: read the form or the query, call :mod:`station.reference` or :mod:`station.study`,
render or redirect. Pages need a staff login (:class:`station.web.LoginRequired`; a kiosk's token
opens none), and the form carries the login's CSRF token as every other form.
"""

from __future__ import annotations

from datetime import UTC, datetime
from typing import Any
from urllib.parse import quote

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Route

from kiosk.core.questionnaire import Questionnaire
from kiosk.export import ExportError
from kiosk.store.database import StoredSession
from station import db, reference, study
from station.download import attachment
from station.redirects import see_other
from station.rendering import checked_form, render
from station.sessions import NotFound, load

#: the form's field for an item's answer: ``item-<item id>``
FIELD = "item-"


def _in(texts: Any, language: str) -> str:
    """A text in ``language``, else in English, else in the first language it has."""
    return texts.get(language) or texts.get("en") or next(iter(texts.values()), "")


def _session(engine: Any, session_id: str) -> tuple[StoredSession, list[reference.ReferenceAnswer]]:
    with engine.connect() as connection:
        return load(connection, session_id)[1], reference.history_in(connection, session_id)


def _questions(q: Questionnaire, stored: StoredSession, current: dict[str, reference.ReferenceAnswer]) -> list[dict]:
    """One row per item the clinician answers: the question, its options, the answer entered
    (never the kiosk's: the clinician's result is entered blind to it)."""
    rows = []
    for item in reference.asked(q):
        labels = [(o.number, _in(o.label, stored.language)) for o in item.options]
        rows.append(
            {
                "id": item.id,
                "text": _in(item.text, stored.language),
                "options": labels,
                "chosen": current[item.id].option if item.id in current else None,
            }
        )
    return rows


async def reference_page(request: Request) -> Response:
    engine = request.app.state.engine
    session_id = request.path_params["session_id"]
    try:
        stored, trail = await run_in_threadpool(_session, engine, session_id)
        q = reference.questionnaire_of(stored, request.app.state.questionnaire)
    except NotFound:
        return PlainTextResponse(f"no session {session_id} has reached this station", status_code=404)
    except ExportError as exc:
        return PlainTextResponse(f"session {session_id} cannot be shown: {exc}", status_code=422)
    current = {entry.item_id: entry for entry in trail}  # oldest first: the latest stays
    return render(
        request,
        "reference.html",
        s=stored,
        title=_in(q.title, stored.language) or q.id,
        questions=_questions(q, stored, current),
        trail=trail,
        labels={item.id: {o.number: _in(o.label, stored.language) for o in item.options} for item in q.items},
        texts={item.id: _in(item.text, stored.language) for item in q.items},
        finished=stored.status == reference.FINISHED,
        message=request.query_params.get("message"),
    )


async def reference_post(request: Request) -> Response:
    form = await checked_form(request)
    engine = request.app.state.engine
    session_id = request.path_params["session_id"]
    page = f"/sessions/{quote(session_id)}/reference"
    chosen = {name[len(FIELD) :]: value for name, value in form.items() if name.startswith(FIELD)}
    try:
        stored, _ = await run_in_threadpool(_session, engine, session_id)
        q = reference.questionnaire_of(stored, request.app.state.questionnaire)
        stored_count = await run_in_threadpool(
            reference.record_answers, engine, q, session_id, chosen, request.state.user
        )
    except NotFound:
        return PlainTextResponse(f"no session {session_id} has reached this station", status_code=404)
    except (reference.EntryRefused, ExportError) as exc:
        return see_other(page, message=str(exc))
    words = "answer" if stored_count == 1 else "answers"
    return see_other(
        page, message=f"{stored_count} clinician's {words} stored." if stored_count else "Nothing changed."
    )


def _today() -> Any:
    return datetime.fromtimestamp(db.now(), UTC).date()


async def _study(request: Request) -> tuple[study.Study | None, dict[str, Any]]:
    """The study the query names (None with an error when it cannot be read) and the form's state."""
    engine = request.app.state.engine
    names = await run_in_threadpool(study.instruments, engine)
    instrument = request.query_params.get("instrument") or (names[0][0] if names else "")
    start, end = request.query_params.get("from", ""), request.query_params.get("to", "")
    state: dict[str, Any] = {"instruments": names, "instrument": instrument, "error": None}
    try:
        first, last = study.period(start, end, _today())
    except study.StudyError as exc:
        first, last = study.period("", "", _today())
        state["error"] = str(exc)
    state.update(first=first.isoformat(), last=last.isoformat())
    if state["error"] or not instrument:
        return None, state
    found = await run_in_threadpool(study.study, engine, request.app.state.questionnaire, instrument, first, last)
    return found, state


async def study_page(request: Request) -> Response:
    found, state = await _study(request)
    return render(request, "study.html", status=400 if state["error"] else 200, found=found, **state)


async def study_csv(request: Request) -> Response:
    found, state = await _study(request)
    if found is None:
        return PlainTextResponse(state["error"] or "no instrument has a clinician's result yet", status_code=400)
    stem = f"agreement-{found.instrument}-{found.first}-{found.last}"
    return Response(
        study.csv_text(found), media_type="text/csv", headers={"content-disposition": attachment(stem, ".csv")}
    )


routes = [
    Route("/sessions/{session_id}/reference", reference_page, methods=["GET"]),
    Route("/sessions/{session_id}/reference", reference_post, methods=["POST"]),
    Route("/study", study_page),
    Route("/study.csv", study_csv),
]

"""Sign-off asks first: a confirmation step showing the total the result will have, its band, and
every change made, with what the result will be called (signed off as recorded, or amended).
Signing off cannot be undone by a tap, so the doctor sees what they sign before they do.

GET shows the step (no change); its form POSTs to the sign-off route (:mod:`station.pages`).
"""

from __future__ import annotations

from urllib.parse import quote

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, RedirectResponse, Response
from starlette.routing import Route

from kiosk.core.review import state_once_signed
from kiosk.core.staff import every_entered
from kiosk.export import ExportError
from kiosk.store.records import StoredSession
from station import validation
from station.definitions import questionnaire_for
from station.rendering import render
from station.sessions import NotFound, load


async def confirm_page(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    session_id = request.path_params["session_id"]

    def read() -> tuple[str, StoredSession]:
        with engine.connect() as connection:
            return load(connection, session_id)

    try:
        kiosk, stored = await run_in_threadpool(read)
    except NotFound:
        return PlainTextResponse(f"no session {session_id} has reached this station", status_code=404)
    trail = await run_in_threadpool(validation.trail, engine, session_id)
    current = validation.review_of(trail)
    if current.final or stored.status not in validation.REVIEWABLE:
        return RedirectResponse(f"/sessions/{session_id}", status_code=303)
    if not request.state.user.is_doctor:
        return RedirectResponse(
            f"/sessions/{session_id}?message={quote('Only a doctor can sign off.')}", status_code=303
        )
    try:  # the questionnaire the session ran, not the one the station bundles
        q = questionnaire_for(stored, fallback=q)
    except ExportError as exc:
        return PlainTextResponse(f"session {session_id} cannot be described: {exc}", status_code=422)
    values = every_entered(q, stored.log, trail)
    score = (await run_in_threadpool(validation.corrected, stored, q, current, values))["score"]  # off the event loop
    language = stored.language
    labels = {item.id: item.text.get(language) or item.text.get("en") or item.id for item in q.items}
    # what the result will be called once signed: the one review-state function's answer, so the
    # step never says "amended" for changes that came back to the kiosk's answers
    recorded = {a.item_id: a.option for a in stored.answers}
    will_be = state_once_signed(current, recorded)
    return render(
        request,
        "sign_off.html",
        s=stored,
        kiosk=kiosk,
        review=current,
        score=score,
        labels=labels,
        title=q.title.get(language) or q.title.get("en") or q.id,
        will_be=will_be.value,
    )


routes = [Route("/sessions/{session_id}/sign-off", confirm_page, methods=["GET"])]

"""The staff pages: the ward view (kiosks, alerts, commands) and the validation of a session.

Thin handlers: check the form (CSRF), call :mod:`station.ward` or :mod:`station.validation`,
publish what changed, redirect back (post/redirect/get, so a reload never repeats an action).
"""

from __future__ import annotations

from typing import Any
from urllib.parse import quote

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, RedirectResponse, Response
from starlette.routing import Route

from kiosk.export import csv_text, fhir_response, practice_outcomes, site_from_identity
from kiosk.questionnaire import Questionnaire
from kiosk.storage import StoredSession
from station import db, orders, validation, ward
from station.plot import INCIDENTS, qos_svg
from station.rendering import checked_form, render, templates
from station.result_pages import ward_results
from station.sessions import NotFound, load, load_for_export

def kiosk_event(app: Starlette, name: str) -> dict[str, Any]:
    """A kiosk's tile, rendered for the live feed."""
    views = ward.kiosk_views(app.state.engine, name)
    html = templates.get_template("_tile.html").render(k=views[0], now=db.now(), csrf="__CSRF__") if views else ""
    return {"name": name, "html": html}


def alerts_event(app: Starlette) -> dict[str, Any]:
    """The open alerts, rendered for the live feed, with their ids (the page sounds new ones)."""
    pending = ward.open_alerts(app.state.engine)
    html = templates.get_template("_alerts.html").render(alerts=pending, csrf="__CSRF__")
    return {"ids": [a.id for a in pending], "html": html,
            "alerts": [{"id": a.id, "kiosk": a.kiosk_id, "kind": a.kind, "raised_at": a.raised_at,
                        "text": f"{a.text} — {a.kiosk_id}"} for a in pending]}


async def ward_page(request: Request) -> Response:
    engine = request.app.state.engine
    views = await run_in_threadpool(ward.kiosk_views, engine)
    pending = await run_in_threadpool(ward.open_alerts, engine)
    recent = await run_in_threadpool(ward_results, engine, request.app.state.questionnaire)
    return render(request, "ward.html", kiosks=views, alerts=pending, results=recent,
                  now=db.now(), message=request.query_params.get("message"))


def _back(request: Request, message: str | None = None, to: str = "/") -> Response:
    return RedirectResponse(f"{to}?message={quote(message)}" if message else to, status_code=303)


async def acknowledge(request: Request) -> Response:
    await checked_form(request)
    engine = request.app.state.engine
    try:
        kiosk = await run_in_threadpool(ward.acknowledge, engine, int(request.path_params["alert_id"]),
                                        request.state.user.name)
    except ward.WardError as exc:
        return _back(request, str(exc))
    await run_in_threadpool(request.app.state.bus.publish, {"type": "ack", "kiosk": kiosk})
    return _back(request)


async def command(request: Request) -> Response:
    form = await checked_form(request)
    engine, kiosk = request.app.state.engine, request.path_params["name"]
    try:
        await run_in_threadpool(ward.queue_command, engine, kiosk, form.get("session_id", ""), form.get("kind", ""),
                                request.state.user.name)
    except ward.WardError as exc:
        return _back(request, str(exc))
    await run_in_threadpool(request.app.state.bus.publish, {"type": "command", "kiosk": kiosk},
                            {"type": "ack", "kiosk": kiosk})
    return _back(request, ward.COMMAND_WORDS[form.get("kind", "")].format(kiosk=kiosk))


def _items(q: Questionnaire, stored: StoredSession, review: Any) -> list[dict[str, Any]]:
    """One row per questionnaire item: what the kiosk recorded, what it is now, how it was answered."""
    answers = {a.item_id: a for a in stored.answers}
    options = review.options({a.item_id: a.option for a in stored.answers})
    # a question's attempts timing out are logged as "ITEM attempt N"
    outcomes = sorted([(a.t, a.item_id) for a in stored.answers] + [
        (e.t, e.detail.split(" ")[0]) for e in stored.log if e.kind == "attempt_timed_out"])
    start = next((e.t for e in stored.log if e.kind == "start"), 0.0)
    rows, previous_t = [], start
    for number, item in enumerate(q.items, 1):
        a = answers.get(item.id)
        taken = None
        if a is not None:
            taken = max(a.t - previous_t, 0.0)
            previous_t = a.t
        elif item.id in stored.not_answered:
            previous_t = max([t for t, i in outcomes if i == item.id] + [previous_t])
        option = options.get(item.id)
        changes = [c for c in review.corrections if c.item_id == item.id]
        rows.append({
            "number": number, "id": item.id, "text": item.text.get(stored.language, item.text["en"]),
            "recorded": a, "recorded_label": item.option(a.option).label_in(stored.language) if a else None,
            "option": option, "label": item.option(option).label_in(stored.language) if option else None,
            "points": item.option(option).points if option else None, "taken": taken,
            "not_answered": item.id in stored.not_answered, "changes": changes,
            "options": [(o.number, o.label_in(stored.language), o.points) for o in item.options],
        })
    return rows


async def session_page(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    session_id = request.path_params["session_id"]
    try:
        kiosk, stored = await run_in_threadpool(_load, engine, session_id)
    except NotFound:
        return PlainTextResponse(f"no session {session_id} has reached this station", status_code=404)
    entries = await run_in_threadpool(validation.trail, engine, session_id)
    current = validation.review_of(entries)
    score = validation.corrected(stored, q, current)["score"]
    return render(request, "session.html", s=stored, kiosk=kiosk, review=current, trail=entries,
                  items=_items(q, stored, current), score=score, practice=practice_outcomes(q, stored),
                  plot=qos_svg(stored), incidents=[e for e in stored.log if e.kind in INCIDENTS],
                  incident_words=INCIDENTS, commands=await run_in_threadpool(ward.recent_commands, engine, session_id),
                  reviewable=stored.status in validation.REVIEWABLE and not current.final,
                  visit=(await run_in_threadpool(orders.visit_kinds, engine, [session_id])).get(session_id),
                  message=request.query_params.get("message"))


def _load(engine: Any, session_id: str) -> tuple[str, StoredSession]:
    with engine.connect() as connection:
        return load(connection, session_id)


def _load_for_export(engine: Any, session_id: str) -> tuple[str, StoredSession, dict[str, Any]]:
    with engine.connect() as connection:
        return load_for_export(connection, session_id)


async def change_item(request: Request) -> Response:
    form = await checked_form(request)
    engine, q = request.app.state.engine, request.app.state.questionnaire
    session_id = request.path_params["session_id"]
    page = f"/sessions/{session_id}"
    try:
        option = int(form.get("option", ""))
    except ValueError:
        return _back(request, "Choose the new answer.", to=page)
    try:
        await run_in_threadpool(validation.change_item, engine, q, session_id, request.path_params["item_id"],
                                option, form.get("reason", ""), request.state.user)
    except (validation.ValidationError, NotFound) as exc:
        return _back(request, str(exc), to=page)
    return _back(request, "Change recorded.", to=page)


async def sign_off(request: Request) -> Response:
    await checked_form(request)
    session_id = request.path_params["session_id"]
    page = f"/sessions/{session_id}"
    try:
        await run_in_threadpool(validation.sign_off, request.app.state.engine, session_id, request.state.user)
    except (validation.ValidationError, NotFound) as exc:
        return _back(request, str(exc), to=page)
    await run_in_threadpool(orders.signed_off, request.app.state.engine, session_id, request.state.user)
    await run_in_threadpool(request.app.state.bus.publish, {"type": "result", "session": session_id})
    return _back(request, "Signed off.", to=page)


async def export(request: Request) -> Response:
    """FHIR QuestionnaireResponse or CSV of the session as it stands: corrections applied, and
    the review state said (unreviewed, signed off, amended)."""
    engine, q = request.app.state.engine, request.app.state.questionnaire
    session_id, fmt = request.path_params["session_id"], request.path_params["fmt"]
    try:
        kiosk, stored, identity = await run_in_threadpool(_load_for_export, engine, session_id)
    except NotFound:
        return PlainTextResponse(f"no session {session_id}", status_code=404)
    current = await run_in_threadpool(validation.review, engine, session_id)
    # named as the kiosk names it in its own exports (its site, kiosk id and FHIR systems, sent
    # with the session), so a hospital importing both gets one result, not two
    site = site_from_identity(identity, kiosk)
    if fmt == "json":
        import json

        body = json.dumps(fhir_response(q, stored, current, site), indent=2, ensure_ascii=False)
        media = "application/fhir+json"
    else:
        body, media = csv_text(q, [stored], [current], site), "text/csv"
    return Response(body, media_type=media, headers={
        "content-disposition": f'attachment; filename="{session_id}.{"fhir.json" if fmt == "json" else "csv"}"'})


routes = [
    Route("/", ward_page),
    Route("/alerts/{alert_id:int}/ack", acknowledge, methods=["POST"]),
    Route("/kiosks/{name}/command", command, methods=["POST"]),
    Route("/sessions/{session_id}", session_page),
    Route("/sessions/{session_id}/items/{item_id}", change_item, methods=["POST"]),
    Route("/sessions/{session_id}/sign-off", sign_off, methods=["POST"]),
    Route("/sessions/{session_id}/export.{fmt:str}", export),
]

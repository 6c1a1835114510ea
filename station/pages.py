"""The staff pages: the ward view (kiosks, alerts, commands) and the validation of a session.

Thin handlers: check the form (CSRF), call :mod:`station.ward` or :mod:`station.validation`,
publish what changed, redirect back (post/redirect/get, so a reload never repeats an action).
A session is shown and exported with the questionnaire it ran and the identity its kiosk recorded
it under (:mod:`kiosk.export.captured`), never with the station's bundled file; what of a session does
not fit its questionnaire (rows stored before they were checked) is left out, never a 500.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Iterator, Mapping
from functools import partial
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response, StreamingResponse
from starlette.routing import Route

from kiosk.core.questionnaire import Questionnaire, Score, pending_words
from kiosk.core.review import review_state, state_once_signed
from kiosk.core.staff import number_text
from kiosk.export import ExportError, practice_outcomes
from kiosk.store.database import StoredSession
from station import db, exports, order_progress, staff_items, tugs, validation, ward
from station.definitions import questionnaire_for
from station.download import attachment
from station.formulas import GuardedQuestionnaire
from station.plot import INCIDENTS, qos_svg
from station.redirects import see_other
from station.rendering import checked_form, render, templates
from station.result_pages import ward_results
from station.sessions import NotFound, load


def kiosk_event(app: Starlette, name: str) -> dict[str, Any]:
    """A kiosk's tile, rendered for the live feed."""
    views = ward.kiosk_views(app.state.engine, name)
    html = (
        templates.get_template("_tile.html").render(k=views[0], now=db.now(), csrf="__CSRF__", zone=app.state.zone)
        if views
        else ""
    )
    return {"name": name, "html": html}


def alerts_event(app: Starlette) -> dict[str, Any]:
    """The open alerts, rendered for the live feed, with their ids (the page sounds new ones)."""
    pending = ward.open_alerts(app.state.engine)
    html = templates.get_template("_alerts.html").render(alerts=pending, csrf="__CSRF__", zone=app.state.zone)
    return {
        "ids": [a.id for a in pending],
        "html": html,
        "alerts": [
            {
                "id": a.id,
                "kiosk": a.kiosk_id,
                "kind": a.kind,
                "raised_at": a.raised_at,
                "text": f"{a.text} — {a.kiosk_id}",
            }
            for a in pending
        ],
    }


async def ward_page(request: Request) -> Response:
    engine = request.app.state.engine
    views = await run_in_threadpool(ward.kiosk_views, engine)
    pending = await run_in_threadpool(ward.open_alerts, engine)
    recent = await run_in_threadpool(ward_results, engine, request.app.state.questionnaire)
    return render(
        request,
        "ward.html",
        kiosks=views,
        alerts=pending,
        results=recent,
        now=db.now(),
        today=db.now_iso()[:10],
        message=request.query_params.get("message"),
    )


def _back(request: Request, message: str | None = None, to: str = "/") -> Response:
    return see_other(to, message=message) if message else see_other(to)


async def acknowledge(request: Request) -> Response:
    await checked_form(request)
    engine = request.app.state.engine
    try:
        kiosk = await run_in_threadpool(
            ward.acknowledge, engine, int(request.path_params["alert_id"]), request.state.user.name
        )
    except ward.WardError as exc:
        return _back(request, str(exc))
    await run_in_threadpool(request.app.state.bus.publish, {"type": "ack", "kiosk": kiosk})
    return _back(request)


async def command(request: Request) -> Response:
    form = await checked_form(request)
    engine, kiosk = request.app.state.engine, request.path_params["name"]
    try:
        await run_in_threadpool(
            ward.queue_command, engine, kiosk, form.get("session_id", ""), form.get("kind", ""), request.state.user.name
        )
    except ward.WardError as exc:
        return _back(request, str(exc))
    await run_in_threadpool(
        request.app.state.bus.publish, {"type": "command", "kiosk": kiosk}, {"type": "ack", "kiosk": kiosk}
    )
    return _back(request, ward.COMMAND_WORDS[form.get("kind", "")].format(kiosk=kiosk))


def _fits(item: Any, option: int | None) -> bool:
    return option is not None and 1 <= option <= len(item.options)


def _score(q: Questionnaire, stored: StoredSession, review: Any, values: Mapping[str, float] | None = None) -> Score:
    """The score of the answers (after corrections) that fit the questionnaire, with the numbers
    staff entered for its staff items (``values``, :mod:`station.staff_items`)."""
    items = {item.id: item for item in q.items}
    options = review.options({a.item_id: a.option for a in stored.answers})
    fitting = {i: o for i, o in options.items() if i in items and _fits(items[i], o)}
    return q.score_answers(fitting, values=values or {})


def _items(q: Questionnaire, stored: StoredSession, review: Any) -> list[dict[str, Any]]:
    """One row per questionnaire item: what the kiosk recorded, what it is now, how it was answered."""
    items = {item.id for item in q.items}
    answers = {a.item_id: a for a in stored.answers if a.item_id in items}
    options = review.options({a.item_id: a.option for a in stored.answers})
    # a question's attempts timing out are logged as "ITEM attempt N"
    outcomes = sorted(
        [(a.t, a.item_id) for a in stored.answers]
        + [(e.t, e.detail.split(" ")[0]) for e in stored.log if e.kind == "attempt_timed_out"]
    )
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
        option = options.get(item.id) if _fits(item, options.get(item.id)) else None
        changes = [c for c in review.corrections if c.item_id == item.id]
        rows.append(
            {
                "number": number,
                "id": item.id,
                "text": _in(item.text, stored.language),
                "recorded": a,
                "recorded_label": _in(item.option(a.option).label, stored.language)
                if a and _fits(item, a.option)
                else None,
                "option": option,
                "label": _in(item.option(option).label, stored.language) if option else None,
                "points": item.option(option).points if option else None,
                "taken": taken,
                "not_answered": item.id in stored.not_answered,
                "changes": changes,
                "options": [(o.number, _in(o.label, stored.language), o.points) for o in item.options],
            }
        )
    return rows


def _in(texts: Any, language: str) -> str:
    """A text in ``language``, else in the first language it has."""
    return texts.get(language) or next(iter(texts.values()), "")


def _practice(q: Questionnaire, stored: StoredSession) -> list[Any]:
    try:
        return practice_outcomes(q, stored)
    except (ExportError, KeyError, ValueError):
        return ["the practice questions do not fit this session's questionnaire"]


async def session_page(request: Request) -> Response:
    engine = request.app.state.engine
    session_id = request.path_params["session_id"]
    try:
        kiosk, stored = await run_in_threadpool(_load, engine, session_id)
    except NotFound:
        return PlainTextResponse(f"no session {session_id} has reached this station", status_code=404)
    q = questionnaire_for(stored, fallback=request.app.state.questionnaire)
    entries = await run_in_threadpool(validation.trail, engine, session_id)
    current = validation.review_of(entries)
    entered = staff_items.values(q, stored, entries)
    # scored off the event loop: a formula may take its whole budget (station.formulas)
    score = await run_in_threadpool(_score, q, stored, current, entered)
    recorded = {a.item_id: a.option for a in stored.answers}
    state = review_state(current, recorded)
    return render(
        request,
        "session.html",
        s=stored,
        kiosk=kiosk,
        review=current,
        state=state,
        trail=entries,
        will_be=state_once_signed(current, recorded).value,
        q=q,
        items=_items(q, stored, current),
        score=score,
        entered={item_id: number_text(v) for item_id, v in entered.items()},  # as typed, never %g
        awaiting=pending_words(q, score) if score.awaiting_staff else "",
        practice=_practice(q, stored),
        plot=qos_svg(stored),
        incidents=[e for e in stored.log if e.kind in INCIDENTS],
        unfit=[e for e in stored.log if e.kind.startswith(("unfit:", "unreadable:"))],
        incident_words=INCIDENTS,
        commands=await run_in_threadpool(ward.recent_commands, engine, session_id),
        reviewable=stored.status in validation.REVIEWABLE and not current.final,
        reopened=bool(current.reopenings) and not current.final,
        visit=(await run_in_threadpool(order_progress.visit_kinds, engine, [session_id])).get(session_id),
        tugs=await run_in_threadpool(tugs.of_session, engine, session_id),
        unknown_definition=isinstance(q, GuardedQuestionnaire) and not q.known,
        message=request.query_params.get("message"),
    )


def _load(engine: Any, session_id: str) -> tuple[str, StoredSession]:
    with engine.connect() as connection:
        return load(connection, session_id)


async def change_item(request: Request) -> Response:
    form = await checked_form(request)
    engine = request.app.state.engine
    session_id = request.path_params["session_id"]
    page = f"/sessions/{session_id}"
    try:
        option = int(form.get("option", ""))
    except ValueError:
        return _back(request, "Choose the new answer.", to=page)
    try:
        _, stored = await run_in_threadpool(_load, engine, session_id)
        q = questionnaire_for(stored, fallback=request.app.state.questionnaire)
        await run_in_threadpool(
            validation.change_item,
            engine,
            q,
            session_id,
            request.path_params["item_id"],
            option,
            form.get("reason", ""),
            request.state.user,
        )
    except (validation.ValidationError, NotFound) as exc:
        return _back(request, str(exc), to=page)
    return _back(request, "Change recorded.", to=page)


async def sign_off(request: Request) -> Response:
    """POST the sign-off (a result with unanswered items only as incomplete, with the form's
    ``incomplete_reason``: :func:`station.validation.sign_off`)."""
    form = await checked_form(request)
    session_id = request.path_params["session_id"]
    page = f"/sessions/{session_id}"
    reason = str(form.get("incomplete_reason", ""))
    try:
        stored_reason = await run_in_threadpool(
            partial(validation.sign_off, incomplete=reason, fallback=request.app.state.questionnaire),
            request.app.state.engine,
            session_id,
            request.state.user,
        )
    except (validation.ValidationError, NotFound) as exc:
        return _back(request, str(exc), to=page)
    await run_in_threadpool(request.app.state.bus.publish, {"type": "result", "session": session_id})
    return _back(request, "Signed off as incomplete." if stored_reason else "Signed off.", to=page)


async def amend(request: Request) -> Response:
    """POST a reopening; back to the result's page, or to its visit's when the visit's page sent it."""
    form = await checked_form(request)
    session_id = request.path_params["session_id"]
    back = form.get("back", "")
    page = back if back.startswith("/visits/") and "//" not in back else f"/sessions/{session_id}"
    try:
        await run_in_threadpool(
            validation.amend, request.app.state.engine, session_id, form.get("reason", ""), request.state.user
        )
    except (validation.ValidationError, NotFound) as exc:
        return _back(request, str(exc), to=page)
    await run_in_threadpool(request.app.state.bus.publish, {"type": "result", "session": session_id})
    return _back(request, "Reopened to amend: change the answers, then sign off again.", to=page)


def _attachment(body: str, media: str, stem: str, suffix: str) -> Response:
    """A download of ``<stem><suffix>``; the stem may come from a kiosk, so it is made safe."""
    return Response(body, media_type=media, headers={"content-disposition": attachment(stem, suffix)})


async def export(request: Request) -> Response:
    """The session as it stands (corrections applied, the review state said): a FHIR transaction
    Bundle (response, total, Device, Questionnaire, Provenance) or CSV, from the kiosk's own
    export code (:mod:`station.exports`)."""
    engine, q = request.app.state.engine, request.app.state.questionnaire
    session_id, fmt = request.path_params["session_id"], request.path_params["fmt"]
    if fmt not in ("json", "csv"):
        return PlainTextResponse(f"no export .{fmt[:20]}: choose export.json (FHIR) or export.csv", status_code=404)
    try:
        if fmt == "json":
            bundle = await run_in_threadpool(exports.result_bundle, engine, q, session_id)
            return _attachment(
                json.dumps(bundle, indent=2, ensure_ascii=False), "application/fhir+json", session_id, ".fhir.json"
            )
        body = await run_in_threadpool(exports.result_csv, engine, q, session_id)
    except NotFound:
        return PlainTextResponse(f"no session {session_id}", status_code=404)
    except ExportError as exc:
        return PlainTextResponse(f"session {session_id} cannot be exported: {exc}", status_code=422)
    return _attachment(body, "text/csv", session_id, ".csv")


def _joined(chunks: Iterator[str], size: int = 1 << 16) -> Iterator[str]:
    """``chunks`` joined into pieces of about ``size`` characters: one worker-thread hop per
    piece, not per FHIR entry."""
    piece: list[str] = []
    length = 0
    for chunk in chunks:
        piece.append(chunk)
        length += len(chunk)
        if length >= size:
            yield "".join(piece)
            piece, length = [], 0
    if piece:
        yield "".join(piece)


async def period_export(request: Request) -> Response:
    """Every result signed off in a period (``?from=YYYY-MM-DD&to=YYYY-MM-DD``, UTC days, both
    included) as one FHIR transaction Bundle, streamed as it is read (constant memory, however
    many results: :func:`station.exports.period_chunks`)."""
    engine, q = request.app.state.engine, request.app.state.questionnaire
    start, end = request.query_params.get("from", ""), request.query_params.get("to", "")
    try:
        first, last = exports.period(start, end)
    except exports.PeriodError as exc:
        return PlainTextResponse(str(exc), status_code=400)
    pieces = _joined(exports.period_chunks(engine, q, first, last))
    try:
        head = await run_in_threadpool(next, pieces, "")
    except ExportError as exc:
        return PlainTextResponse(
            f"the results signed off from {first} to {last} cannot be exported: {exc}", status_code=422
        )
    stem = f"signed-off-{first}-{last}"
    return StreamingResponse(
        itertools.chain([head], pieces),
        media_type="application/fhir+json",
        headers={"content-disposition": attachment(stem, ".fhir.json")},
    )


routes = [
    Route("/", ward_page),
    Route("/alerts/{alert_id:int}/ack", acknowledge, methods=["POST"]),
    Route("/kiosks/{name}/command", command, methods=["POST"]),
    Route("/sessions/{session_id}", session_page),
    Route("/sessions/{session_id}/items/{item_id}", change_item, methods=["POST"]),
    Route("/sessions/{session_id}/sign-off", sign_off, methods=["POST"]),
    Route("/sessions/{session_id}/amend", amend, methods=["POST"]),
    Route("/sessions/{session_id}/export.{fmt:str}", export),
    Route("/exports/signed-off.json", period_export),
]

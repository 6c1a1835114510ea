"""The clinician's pages of results: the inbox of visits waiting for validation (filter by kiosk
and review state), patient search, and one patient's course (every visit, newest first, and a
step plot per instrument). Read-only: a visit is validated on its page (:mod:`station.visit_pages`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import sqlalchemy as sa
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import HTMLResponse, PlainTextResponse, RedirectResponse, Response
from starlette.routing import Route

from station import db, orders, results, tugs, visit_inbox
from station.course_plot import course_svg
from station.rendering import render, templates
from station.tug_plot import tug_svg

#: sessions in the ward page's Results list
RECENT = 50


def _kiosk_names(engine: Any) -> list[str]:
    with engine.connect() as connection:
        return list(connection.execute(sa.select(db.kiosks.c.name).order_by(db.kiosks.c.name)).scalars())


async def inbox_page(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    state = request.query_params.get("state", "waiting")
    if state not in visit_inbox.INBOX_STATES:
        state = "waiting"
    kiosk = request.query_params.get("kiosk") or ""
    after = request.query_params.get("after") or ""
    found = await run_in_threadpool(
        lambda: visit_inbox.inbox(engine, q, state=state, kiosk_id=kiosk or None, after=after)
    )
    names = await run_in_threadpool(_kiosk_names, engine)
    return render(
        request,
        "inbox.html",
        visits=found.visits,
        more=found.after,
        after=after,
        state=state,
        kiosk=kiosk,
        kiosks=names,
    )


async def patients_page(request: Request) -> Response:
    """Search by patient identifier; an exact identifier goes straight to the patient's page."""
    engine = request.app.state.engine
    text = request.query_params.get("q", "").strip()
    found = await run_in_threadpool(results.search, engine, text) if text else []
    if len(found) == 1 and found[0][0].lower() == text.lower():
        return RedirectResponse(f"/patients/{found[0][0]}", status_code=303)
    return render(request, "patients.html", q=text, found=found)


async def patient_page(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    patient_id = request.path_params["patient_id"]
    visits = await run_in_threadpool(results.course, engine, q, patient_id)
    ordered = await run_in_threadpool(lambda: orders.listing(engine, patient_id=patient_id))
    timed = await run_in_threadpool(tugs.patient_course, engine, patient_id)
    if not visits and not ordered and not timed:
        return PlainTextResponse(f"no visit of patient {patient_id} has reached this station", status_code=404)
    ran = await run_in_threadpool(results.instruments, engine, q, visits)
    return render(
        request,
        "patient.html",
        patient_id=patient_id,
        visits=visit_inbox.patient_visits(visits),
        orders=ordered,
        plots=[(i.id, i.title.get("en", i.id), course_svg(i, visits)) for i in ran],
        tugs=timed,
        tug_plot=tug_svg(timed) if timed else "",
    )


routes = [
    Route("/inbox", inbox_page),
    Route("/patients", patients_page),
    Route("/patients/{patient_id}", patient_page),
]


# -- live: the results event and the fragments the open pages fetch when it comes ----------------


def results_event(app: Any, finished: list[str]) -> dict[str, Any]:
    """The count of results waiting, and the ones that just finished (the pages ring for them).
    Cheap on purpose (two small indexed queries, no session folded); alerts never wait for it
    (:mod:`station.live` renders them on a thread of their own)."""
    engine = app.state.engine
    rung = []
    if finished:
        with engine.connect() as connection:
            columns = (db.sessions.c.id, db.sessions.c.patient_id, db.sessions.c.kiosk_id)
            rows = connection.execute(
                sa.select(*columns).where(db.sessions.c.id.in_(finished), db.sessions.c.status == "finished")
            ).all()
        rung = [
            {
                "session": r.id,
                "href": visit_inbox.visit_href(r.id),
                "text": f"Result waiting: {r.patient_id}, kiosk {r.kiosk_id}",
            }
            for r in rows
        ]
    return {"count": results.waiting_count(engine), "rung": rung}


async def inbox_rows(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    state = request.query_params.get("state", "waiting")
    kiosk = request.query_params.get("kiosk") or None
    after = request.query_params.get("after") or ""
    found = await run_in_threadpool(
        lambda: visit_inbox.inbox(
            engine, q, state=state if state in visit_inbox.INBOX_STATES else "waiting", kiosk_id=kiosk, after=after
        )
    )
    template = templates.get_template("_visit_row.html")
    html = (
        "".join(template.render(v=v, zone=request.app.state.zone) for v in found.visits)
        or '<li class="muted" id="inbox-empty">Nothing here.</li>'
    )

    return HTMLResponse(html)


def ward_results(engine: Any, q: Any) -> list[results.Result]:
    """The ward page's Results: the latest sessions of every status, newest first."""
    with engine.connect() as connection:
        ids = connection.execute(
            sa.select(db.sessions.c.id)
            .where(db.sessions.c.status != "pending")
            .order_by(db.sessions.c.started_at.desc())
            .limit(RECENT)
        ).all()
    return _cancelled_shown(engine, results.results_of(engine, q, ids))


def _cancelled_shown(engine: Any, found: list[results.Result]) -> list[results.Result]:
    """A session of a cancelled order, not finished, reads "cancelled" (running: the kiosk is
    ending it; abandoned: it ended it), not "abandoned": staff see the cancellation took."""
    order_ids = {r.order_id for r in found if r.order_id and r.status != "finished"}
    if not order_ids:
        return found
    with engine.connect() as connection:
        cancelled = set(
            connection.execute(
                sa.select(db.orders.c.id).where(db.orders.c.id.in_(sorted(order_ids)), db.orders.c.state == "cancelled")
            ).scalars()
        )
    return [replace(r, status="cancelled") if r.order_id in cancelled and r.status != "finished" else r for r in found]


async def ward_rows(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    found = await run_in_threadpool(ward_results, engine, q)
    return HTMLResponse(templates.get_template("_ward_results.html").render(results=found, zone=request.app.state.zone))


routes += [
    Route("/fragments/inbox", inbox_rows),
    Route("/fragments/results", ward_rows),
]

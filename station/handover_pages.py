"""The handover page (issue 36, part 7): a shift's summary and today's visits per kiosk.

Route only: read the window typed on the page, call :func:`station.handover.shift` (one
connection), render; a window that cannot be read shows the last hours with a message naming it.
"""

from __future__ import annotations

from datetime import UTC, datetime

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import Route

from station import db, handover, orders
from station.rendering import render


async def handover_page(request: Request) -> Response:
    engine, q, zone = request.app.state.engine, request.app.state.questionnaire, request.app.state.zone
    now = datetime.fromtimestamp(db.now(), UTC)
    start, end = request.query_params.get("from", ""), request.query_params.get("to", "")
    error = None
    try:
        chosen = handover.window(start, end, now, zone)
    except handover.HandoverError as exc:
        error, chosen = str(exc), handover.window("", "", now, zone)
    found = await run_in_threadpool(handover.shift, engine, q, chosen, now, zone)
    offered = await run_in_threadpool(orders.instruments, engine, q)
    typed_from, typed_to = chosen.typed(zone)
    return render(
        request,
        "handover.html",
        status=400 if error else 200,
        shift=found,
        typed_from=typed_from,
        typed_to=typed_to,
        error=error,
        hours=handover.DEFAULT_HOURS,
        today=now.astimezone(zone).strftime("%A %d %B %Y"),
        titles={i.id: i.title for i in offered},  # staff read titles, never ids
    )


routes = [Route("/handover", handover_page)]

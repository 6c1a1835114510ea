"""The kiosk's side of orders (protocol §4): ``GET /api/v1/orders`` long-polls the kiosk's
visits waiting to be started, ``POST /api/v1/orders/start`` starts one with the code staff typed.

Same rules as the rest of the kiosk API (:mod:`station.api`): a bearer token names the kiosk, an
unknown or revoked one gets 401, and a kiosk only ever sees and starts its own orders (the code is
looked up among them alone, so another kiosk's code is simply wrong here).
"""

from __future__ import annotations

import asyncio
import hashlib
import json
from collections.abc import Awaitable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from sqlalchemy.engine import Connection
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from station import auth, order_progress, orders
from station.api import MAX_WAIT_S, _error, _in_worker, _json, _refused, _token, _Unauthorised, _unauthorised
from station.bus import long_poll

#: worker threads for the orders' long polls and order forms only: a waiting visit neither queues
#: behind the kiosks' routine rows nor behind a burst of alerts (measured: bench/station.py)
ORDER_LANE = ThreadPoolExecutor(max_workers=2, thread_name_prefix="station-orders")


def _ready(engine: Any, kiosk: str, held: set[str]) -> dict[str, Any]:
    """The kiosk's waiting visits, the cancelled ones it may be running (it ends those:
    :func:`orders.cancelled_for`) and a version of both (the long poll answers when it changes)."""
    with engine.connect() as connection:
        ready = [o.for_kiosk() for o in orders.ready_for(connection, kiosk)]
        cancelled = orders.cancelled_for(connection, kiosk, held)
    listed = {"orders": ready, "cancelled": cancelled}
    version = hashlib.sha256(json.dumps(listed, sort_keys=True).encode()).hexdigest()[:16]
    return {"version": version, **listed}


def _release(bus: Any, kiosk: str, held: set[str]) -> None:
    """The kiosk's orders in progress that it no longer holds heal (:func:`order_progress.release_unheld`)."""
    with bus.transaction() as (connection, messages):
        if order_progress.release_unheld(connection, kiosk, held):
            messages.append({"type": "order", "kiosk": kiosk})


async def get_orders(request: Request) -> Response:
    """Long poll: the list at once when its version differs from ``version`` (or none was given),
    else when an order of this kiosk changes (by any station process) or ``wait`` seconds pass.
    Subscribing before looking means a change in between is not missed. ``held`` (comma-separated
    order ids): the orders the kiosk still runs; its other orders in progress are released first,
    and the cancelled ones among them are listed (``cancelled``) for the kiosk to end."""
    token = _token(request)
    loop = asyncio.get_running_loop()
    # the whole poll on the urgent lane (cheap reads): a waiting visit never queues behind the
    # kiosks' routine rows in the shared worker threads
    kiosk = await loop.run_in_executor(ORDER_LANE, auth.kiosk_for, request.app.state.engine, token) if token else None
    if kiosk is None:
        return _unauthorised()
    try:
        wait = min(max(float(request.query_params.get("wait", "0")), 0.0), MAX_WAIT_S)
    except ValueError:
        return _error(400, "'wait' must be a number of seconds")
    known = request.query_params.get("version")
    engine, bus = request.app.state.engine, request.app.state.bus
    held = {h for h in (request.query_params.get("held") or "").split(",") if h}
    if request.query_params.get("held") is not None:
        await loop.run_in_executor(ORDER_LANE, _release, bus, kiosk, held)
    queue = bus.subscribe(kiosk, ("order", "resync"))
    try:

        def fetch() -> Awaitable[dict[str, Any]]:
            return loop.run_in_executor(ORDER_LANE, _ready, engine, kiosk, held)

        current = await long_poll(queue, wait, await fetch(), fetch, lambda listed: listed["version"] != known)
    finally:
        bus.unsubscribe(queue)
    return JSONResponse(current)


async def post_start(request: Request) -> Response:
    """``{"code": "1234"}``: 200 with the order started, 404 when no waiting visit of this kiosk
    has that code, 429 when the code came before its slot after wrong codes (``Retry-After`` and
    ``retry_after_s`` say when any code, the right one included, will be checked)."""
    if request.headers.get("authorization") is None:
        return _unauthorised()
    try:
        body = await _json(request)
        if not isinstance(body, dict) or not isinstance(body.get("code"), str):
            raise ValueError('the body must be {"code": "1234"}')
    except ValueError as exc:
        return _refused(exc)

    def work(connection: Connection, kiosk: str) -> tuple[Any, list[dict[str, Any]]]:
        found = orders.start(connection, kiosk, body["code"])
        if found is None:
            return None, []
        return found.for_kiosk(), [{"type": "order", "kiosk": kiosk}]

    try:
        started = await _in_worker(request, work)
    except _Unauthorised:
        return _unauthorised()
    except orders.TooManyCodes as exc:
        return JSONResponse(
            {"error": str(exc), "retry_after_s": exc.retry_after_s},
            status_code=429,
            headers={"retry-after": str(exc.retry_after_s)},
        )
    if started is None:
        return _error(404, "no visit ordered for this kiosk has that code")
    return JSONResponse({"order": started})


routes = [
    Route("/api/v1/orders", get_orders, methods=["GET"]),
    Route("/api/v1/orders/start", post_start, methods=["POST"]),
]

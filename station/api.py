"""The kiosk's side of the station (protocol v1): ``/api/v1/sync``, ``/status``, ``/commands``.

Every request carries ``Authorization: Bearer <kiosk token>``; an unknown or revoked token gets
401 and nothing else happens. Routes are thin: they parse, call :mod:`station.sync` or
:mod:`station.ward` in a worker thread (the database calls block), publish what changed, answer.
"""

from __future__ import annotations

import asyncio
import json
from typing import Any

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from station import auth, sync, ward
from station.bus import Bus

#: the longest long poll the station holds open (seconds)
MAX_WAIT_S = 30.0
MAX_BODY = 4 * 1024 * 1024


def _error(status: int, message: str) -> JSONResponse:
    return JSONResponse({"error": message}, status_code=status)


async def _kiosk(request: Request) -> str | None:
    header = request.headers.get("authorization", "")
    scheme, _, token = header.partition(" ")
    if scheme.lower() != "bearer" or not token.strip():
        return None
    return await run_in_threadpool(auth.kiosk_for, request.app.state.engine, token.strip())


async def _json(request: Request) -> Any:
    body = await request.body()
    if len(body) > MAX_BODY:
        raise ValueError(f"the body is larger than {MAX_BODY} bytes")
    return json.loads(body)


def _unauthorised() -> JSONResponse:
    return JSONResponse({"error": "unknown or revoked kiosk token"}, status_code=401,
                        headers={"WWW-Authenticate": "Bearer"})


async def post_sync(request: Request) -> Response:
    kiosk = await _kiosk(request)
    if kiosk is None:
        return _unauthorised()
    try:
        body = await _json(request)
        if isinstance(body, dict) and body.get("kiosk_id") not in (None, kiosk):
            return _error(403, f"this token belongs to kiosk {kiosk!r}, not {body.get('kiosk_id')!r}")
        events = sync.parse(body)
        stored, messages = await run_in_threadpool(sync.intake, request.app.state.engine, kiosk, events)
    except ValueError as exc:  # json errors are ValueErrors too
        return _error(getattr(exc, "status", 400), str(exc))
    bus: Bus = request.app.state.bus
    await run_in_threadpool(bus.publish, *messages)
    return JSONResponse({"stored": stored})


async def post_status(request: Request) -> Response:
    kiosk = await _kiosk(request)
    if kiosk is None:
        return _unauthorised()
    try:
        body = await _json(request)
        if isinstance(body, dict) and body.get("kiosk_id") not in (None, kiosk):
            return _error(403, f"this token belongs to kiosk {kiosk!r}, not {body.get('kiosk_id')!r}")
        status = ward.parse_status(body)
    except ValueError as exc:
        return _error(400, str(exc))
    await run_in_threadpool(ward.report_status, request.app.state.engine, kiosk, status)
    await run_in_threadpool(request.app.state.bus.publish, {"type": "kiosk", "kiosk": kiosk})
    return JSONResponse({"ok": True})


async def get_commands(request: Request) -> Response:
    """Long poll: pending commands at once, else wait until one is queued (by any station process)
    or ``wait`` seconds pass. Subscribing before looking means a command queued in between is
    not missed."""
    kiosk = await _kiosk(request)
    if kiosk is None:
        return _unauthorised()
    try:
        wait = min(max(float(request.query_params.get("wait", "0")), 0.0), MAX_WAIT_S)
    except ValueError:
        return _error(400, "'wait' must be a number of seconds")
    engine, bus = request.app.state.engine, request.app.state.bus
    queue = bus.subscribe()
    try:
        await run_in_threadpool(ward.seen, engine, kiosk)
        pending = await run_in_threadpool(ward.pending_commands, engine, kiosk)
        deadline = asyncio.get_running_loop().time() + wait
        while not pending:
            left = deadline - asyncio.get_running_loop().time()
            if left <= 0:
                break
            try:
                message = await asyncio.wait_for(queue.get(), timeout=left)
            except TimeoutError:
                break
            if message.get("type") in ("command", "resync") and message.get("kiosk") in (kiosk, None):
                pending = await run_in_threadpool(ward.pending_commands, engine, kiosk)
    finally:
        bus.unsubscribe(queue)
    return JSONResponse({"commands": pending})


async def post_command_ack(request: Request) -> Response:
    kiosk = await _kiosk(request)
    if kiosk is None:
        return _unauthorised()
    try:
        body = await _json(request)
        await run_in_threadpool(ward.ack_command, request.app.state.engine, kiosk,
                                int(request.path_params["command_id"]), body)
    except ward.WardError as exc:
        return _error(404 if str(exc).startswith("no command") else 400, str(exc))
    except ValueError as exc:
        return _error(400, str(exc))
    await run_in_threadpool(request.app.state.bus.publish, {"type": "kiosk", "kiosk": kiosk})
    return JSONResponse({"ok": True})


routes = [
    Route("/api/v1/sync", post_sync, methods=["POST"]),
    Route("/api/v1/status", post_status, methods=["POST"]),
    Route("/api/v1/commands", get_commands, methods=["GET"]),
    Route("/api/v1/commands/{command_id:int}/ack", post_command_ack, methods=["POST"]),
]

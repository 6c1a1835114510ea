"""The kiosk's side of the station (protocol v1): ``/api/v1/sync``, ``/status``, ``/commands``.

Every request carries ``Authorization: Bearer <kiosk token>``; an unknown or revoked token gets
401 and nothing else happens. Routes are thin: they parse, call :mod:`station.sync` or
:mod:`station.ward` in a worker thread (the database calls block), publish what changed, answer.
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import anyio
import anyio.to_thread
from sqlalchemy.engine import Connection
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from fileio.bounded import BadFile, load_json
from station import auth, sync, ward
from station.bus import long_poll

#: the longest long poll the station holds open (seconds)
MAX_WAIT_S = 30.0
MAX_BODY = 4 * 1024 * 1024
#: worker threads for alert batches only (the protocol sends alerts in a request of their own)
ALERT_LANE = ThreadPoolExecutor(max_workers=4, thread_name_prefix="station-alerts")


def _error(status: int, message: str) -> JSONResponse:
    return JSONResponse({"error": message}, status_code=status)


def _refused(exc: ValueError) -> JSONResponse:
    """A request refused for what it sent: 413 for a body over :data:`MAX_BODY`, 422 for a row
    that breaks a rule (the body names its ``seq`` too), else 400."""
    seq = getattr(exc, "seq", None)
    return JSONResponse(
        {"error": str(exc)} | ({"seq": seq} if seq is not None else {}), status_code=getattr(exc, "status", 400)
    )


def _token(request: Request) -> str | None:
    scheme, _, token = request.headers.get("authorization", "").partition(" ")
    return token.strip() if scheme.lower() == "bearer" and token.strip() else None


async def _kiosk(request: Request) -> str | None:
    token = _token(request)
    return await run_in_threadpool(auth.kiosk_for, request.app.state.engine, token) if token else None


#: threads the kiosks' routine batches may hold at once: past a few they only wait for one
#: another's writes, and a staff page's reads queued behind them took seconds (bench/station.py
#: --history); the pages keep the shared workers
ROUTINE_LANE_THREADS = 6
_lanes: dict[int, anyio.CapacityLimiter] = {}


def _routine_lane() -> anyio.CapacityLimiter:
    """The routine batches' limiter (one per event loop: a limiter belongs to its loop)."""
    loop = id(asyncio.get_running_loop())
    if loop not in _lanes:
        _lanes[loop] = anyio.CapacityLimiter(ROUTINE_LANE_THREADS)
    return _lanes[loop]


class _Unauthorised(Exception):
    pass


def _in_worker(request: Request, work: Any, urgent: bool = False, status: str | None = None) -> Any:
    """Authenticate, do the work and publish what changed in one worker-thread hop: under load the
    hops, not the queries, are what a request waits for. Urgent work (a batch of alerts) runs on
    threads of its own, so a doctor call never queues behind the kiosks' routine rows."""
    token = _token(request)
    bus = request.app.state.bus

    def run() -> Any:
        if token is None:
            raise _Unauthorised
        with bus.transaction(urgent) as (connection, messages):
            kiosk = auth.touch_kiosk(connection, token, status)
            if kiosk is None:
                raise _Unauthorised
            result, more = work(connection, kiosk)
            messages += more
        return result

    if urgent:
        return asyncio.get_running_loop().run_in_executor(ALERT_LANE, run)
    return anyio.to_thread.run_sync(run, limiter=_routine_lane())


class _TooLarge(ValueError):
    status = 413


async def _json(request: Request) -> Any:
    """The request's JSON body, read under the same limits as the kiosk's own files
    (:func:`fileio.bounded.load_json`: nesting, duplicate keys, NaN, huge numbers), at most
    :data:`MAX_BODY` bytes and never buffered beyond that: a ``ValueError`` naming what is wrong."""
    declared = request.headers.get("content-length", "")
    if declared.isdigit() and int(declared) > MAX_BODY:
        raise _TooLarge(f"the body is larger than {MAX_BODY} bytes")
    body = bytearray()
    async for chunk in request.stream():
        body += chunk
        if len(body) > MAX_BODY:
            raise _TooLarge(f"the body is larger than {MAX_BODY} bytes")
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"the body is not UTF-8 text (byte {exc.start})") from None
    try:
        return load_json(text, "the request body")
    except BadFile as exc:
        raise ValueError(str(exc)) from None


def _unauthorised() -> JSONResponse:
    return JSONResponse(
        {"error": "unknown or revoked kiosk token"}, status_code=401, headers={"WWW-Authenticate": "Bearer"}
    )


class _WrongKiosk(ValueError):
    status = 403


def _check_kiosk_id(body: Any, kiosk: str) -> None:
    if isinstance(body, dict) and body.get("kiosk_id") not in (None, kiosk):
        raise _WrongKiosk(f"this token belongs to kiosk {kiosk!r}, not {body.get('kiosk_id')!r}")


async def post_sync(request: Request) -> Response:
    if _token(request) is None:  # no key at all: refused before its body is read
        return _unauthorised()
    try:
        body = await _json(request)
        events = sync.parse(body)
    except ValueError as exc:  # json errors are ValueErrors too
        return _refused(exc)

    def work(connection: Connection, kiosk: str) -> tuple[list[int], list[dict[str, Any]]]:
        _check_kiosk_id(body, kiosk)
        return sync.intake(connection, kiosk, events)

    try:
        stored = await _in_worker(request, work, urgent=all(sync.is_alert(e) for e in events))
    except _Unauthorised:
        return _unauthorised()
    except ValueError as exc:
        return _refused(exc)
    return JSONResponse({"stored": stored})


async def post_status(request: Request) -> Response:
    if _token(request) is None:  # no key at all: refused before its body is read
        return _unauthorised()
    try:
        body = await _json(request)
        status = ward.parse_status(body)
    except ValueError as exc:
        return _refused(exc)

    def work(connection: Connection, kiosk: str) -> tuple[None, list[dict[str, Any]]]:
        _check_kiosk_id(body, kiosk)  # raising rolls the status back
        ward.report_status(connection, kiosk, status)
        return None, [{"type": "kiosk", "kiosk": kiosk}]

    try:
        await _in_worker(request, work)
    except _Unauthorised:
        return _unauthorised()
    except ValueError as exc:
        return _refused(exc)
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
    queue = bus.subscribe(kiosk, ("command", "resync"))
    try:
        await run_in_threadpool(ward.seen, engine, kiosk)

        def fetch() -> Awaitable[list[dict[str, Any]]]:
            return run_in_threadpool(ward.pending_commands, engine, kiosk)

        pending = await long_poll(queue, wait, await fetch(), fetch, bool)
    finally:
        bus.unsubscribe(queue)
    return JSONResponse({"commands": pending})


async def post_command_ack(request: Request) -> Response:
    kiosk = await _kiosk(request)
    if kiosk is None:
        return _unauthorised()
    try:
        body = await _json(request)
        await run_in_threadpool(
            ward.ack_command, request.app.state.engine, kiosk, int(request.path_params["command_id"]), body
        )
    except ward.WardError as exc:
        return _error(404 if str(exc).startswith("no command") else 400, str(exc))
    except ValueError as exc:
        return _refused(exc)
    await run_in_threadpool(request.app.state.bus.publish, {"type": "kiosk", "kiosk": kiosk})
    return JSONResponse({"ok": True})


routes = [
    Route("/api/v1/sync", post_sync, methods=["POST"]),
    Route("/api/v1/status", post_status, methods=["POST"]),
    Route("/api/v1/commands", get_commands, methods=["GET"]),
    Route("/api/v1/commands/{command_id:int}/ack", post_command_ack, methods=["POST"]),
]

"""The station's web application: pages for staff, the kiosk API, live events.

Routes only check who is asking, read the form and call the module that owns the concept
(:mod:`station.ward`, :mod:`station.validation`); pages are Jinja2 templates. Every POST from a
page carries the login session's CSRF token and a same-origin ``Origin`` when the browser sends
one; the login cookie is HttpOnly, SameSite=Strict, and Secure when served over TLS.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import AsyncIterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import asynccontextmanager
from datetime import tzinfo
from pathlib import Path
from typing import Any
from urllib.parse import quote

import anyio.to_thread
import sqlalchemy as sa
from sqlalchemy.engine import Engine
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.middleware import Middleware
from starlette.middleware.sessions import SessionMiddleware
from starlette.requests import Request
from starlette.responses import PlainTextResponse, RedirectResponse, Response, StreamingResponse
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from kiosk.core.visits import DEFAULT_ID_PATTERN
from station import (
    api,
    api_orders,
    auth,
    db,
    definition_pages,
    errors,
    formulas,
    handover_pages,
    identify_pages,
    logins,
    order_pages,
    pages,
    print_pages,
    result_pages,
    results,
    signoff_pages,
    staff_items,
    study_pages,
    throttle,
    tug_pages,
    visit_pages,
)
from station.batteries import Battery
from station.bodylimit import BodyLimit
from station.bus import Bus
from station.live import Live
from station.rendering import Forbidden, checked_form, current_user, render

HERE = Path(__file__).parent
ROUTINE_WORKERS = 12
#: threads for staff's login check alone: a nurse's order or sign-off never waits for it behind the
#: kiosks' routine rows in the shared workers (measured: up to 375 ms there, bench/station.py)
STAFF_LANE = ThreadPoolExecutor(max_workers=2, thread_name_prefix="station-staff")
#: the longest page address a login sends the browser back to (a longer one goes to the ward view)
MAX_NEXT = 512
SECURITY_HEADERS = {
    # no inline script or style, nothing from elsewhere: the pages work with the network cut
    "content-security-policy": "default-src 'self'; img-src 'self' data:; frame-ancestors 'none'; form-action 'self'",
    "x-content-type-options": "nosniff",
    "referrer-policy": "no-referrer",
    "x-frame-options": "DENY",
    "cache-control": "no-store",
}


class SecurityHeaders:
    """Adds :data:`SECURITY_HEADERS` to every response (plain ASGI, so SSE streams are untouched)."""

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        async def send_with_headers(message: Any) -> None:
            if message["type"] == "http.response.start":
                message.setdefault("headers", [])
                present = {k.decode().lower() for k, _ in message["headers"]}
                message["headers"] += [
                    (k.encode(), v.encode()) for k, v in SECURITY_HEADERS.items() if k not in present
                ]
            await send(message)

        await self.app(scope, receive, send_with_headers if scope["type"] == "http" else send)


# -- login ---------------------------------------------------------------------------------------


async def login_page(request: Request) -> Response:
    return render(request, "login.html", next=request.query_params.get("next", "/"))


async def login_post(request: Request) -> Response:
    try:
        form = await checked_form(request)
    except Forbidden as exc:
        return render(request, "login.html", status=403, error=str(exc), next="/")
    engine = request.app.state.engine
    name, password = form.get("name", "").strip(), form.get("password", "")
    address = throttle.client_address(
        request.client.host if request.client else None,
        request.headers.getlist("x-forwarded-for"),
        request.app.state.trusted_proxies,
    )
    target = form.get("next", "/")
    if not target.startswith("/") or target.startswith("//"):
        target = "/"
    wait, failures = await run_in_threadpool(throttle.admit, engine, name, address)
    if wait > 0:
        throttle.log_refused(name, address, wait)
        seconds = math.ceil(wait)
        response = render(
            request,
            "login.html",
            status=429,
            next=target,
            error=f"Too many failed logins for this name from your address: try again in {seconds} "
            "seconds, or ask an administrator.",
        )
        response.headers["retry-after"] = str(seconds)
        return response
    found = await run_in_threadpool(auth.login, engine, name, password, address)
    if found is None:
        throttle.log_failure(name, address, failures)
        return render(request, "login.html", status=401, next=target, error="Wrong user name or password.")
    session_id = await run_in_threadpool(logins.start, engine, found.name)
    request.session.clear()  # a new session on login: no fixation of an earlier cookie
    request.session.update(sid=session_id, csrf=auth.new_csrf_token())
    return RedirectResponse(target, status_code=303)


async def logout(request: Request) -> Response:
    try:
        await checked_form(request)
    except Forbidden as exc:
        return PlainTextResponse(str(exc), status_code=403)
    session_id = request.session.get("sid")
    if isinstance(session_id, str):  # ended on the server: a copy of the cookie opens nothing
        await run_in_threadpool(logins.end, request.app.state.engine, session_id)
    request.session.clear()
    return RedirectResponse("/login", status_code=303)


async def events(request: Request) -> Response:
    if current_user(request) is None:
        return PlainTextResponse("log in first", status_code=401)
    live: Live = request.app.state.live
    return StreamingResponse(live.stream(), media_type="text/event-stream", headers={"x-accel-buffering": "no"})


def _user_and_count(request: Request) -> tuple[auth.User | None, int | None]:
    """The login's user and, for a page, the navigation's count of results waiting: one hop off
    the event loop for both (the count is an index range, :func:`station.results.waiting_count`)."""
    found = current_user(request)
    if found is None or request.method != "GET":
        return found, None
    return found, results.waiting_count(request.app.state.engine)


class LoginRequired:
    """Page routes need a logged-in user; the kiosk API, login, events and static files do not
    (they check their own credentials)."""

    OPEN = ("/login", "/static/", "/api/", "/events", "/healthz")

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http" or scope["path"].startswith(self.OPEN):
            await self.app(scope, receive, send)
            return
        request = Request(scope, receive)
        found, waiting = await asyncio.get_running_loop().run_in_executor(STAFF_LANE, _user_and_count, request)
        if found is None:
            back = scope["path"] if len(scope["path"]) <= MAX_NEXT else "/"  # never a huge Location
            response: Response = RedirectResponse(f"/login?next={quote(back)}", status_code=303)
            await response(scope, receive, send)
            return
        scope.setdefault("state", {}).update(user=found, waiting=waiting)
        await self.app(scope, receive, send)


async def forbidden(request: Request, exc: Exception) -> Response:
    return PlainTextResponse(str(exc), status_code=403)


#: one thread for the health check's write probe: it never queues behind pages or kiosks
HEALTH_LANE = ThreadPoolExecutor(max_workers=1, thread_name_prefix="station-health")
HEALTH_TIMEOUT_S = 5.0


def write_probe(engine: Engine) -> None:
    """Commit a heartbeat (the settings row ``heartbeat``: the time of this check): the database
    takes writes now (raises the driver's error otherwise: read-only, disk full, server gone). A
    commit, not a rolled-back write: SQLite only meets a full disk when it writes its log."""
    with engine.begin() as connection:
        now = db.now_iso()
        changed = connection.execute(
            db.settings.update().where(db.settings.c.key == "heartbeat").values(value=now)
        ).rowcount
        if not changed:
            db.insert_ignore(connection, db.settings, [{"key": "heartbeat", "value": now}], ["key"])


async def healthz(request: Request) -> Response:
    """200 ``ok`` only when the database can be written now; else 503 naming why."""
    loop = asyncio.get_running_loop()
    try:
        await asyncio.wait_for(
            loop.run_in_executor(HEALTH_LANE, write_probe, request.app.state.engine), HEALTH_TIMEOUT_S
        )
    except TimeoutError:
        return PlainTextResponse(f"database: a test write took longer than {HEALTH_TIMEOUT_S:g} s", status_code=503)
    except sa.exc.SQLAlchemyError as exc:
        return PlainTextResponse(f"database cannot be written: {errors.reason(exc)}", status_code=503)
    return PlainTextResponse("ok")


def create_app(
    engine: Engine,
    questionnaire: Questionnaire | None = None,
    https: bool = False,
    trusted_proxies: tuple[throttle.Network, ...] = (),
    id_pattern: str = DEFAULT_ID_PATTERN,
    zone: tzinfo | None = None,
    batteries: tuple[Battery, ...] = (),
) -> Starlette:
    """The station application on ``engine`` (already migrated); ``X-Forwarded-For`` counts only
    from ``trusted_proxies``; orders take the patient identifiers ``id_pattern`` matches whole,
    and offer the site's ``batteries`` (:mod:`station.batteries`); times are shown in ``zone``
    (None: the machine's own)."""
    bus = Bus(engine)
    q = questionnaire or load_questionnaire()

    @asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        # fewer routine workers than the default 40: past a few, more threads only share the GIL
        # thinner, and the alert lane's threads would get less of it
        anyio.to_thread.current_default_thread_limiter().total_tokens = ROUTINE_WORKERS
        bus.start(asyncio.get_running_loop())
        app.state.live.start()
        yield
        await app.state.live.stop()
        bus.stop()
        formulas.WORKER.stop()

    routes = [
        Route("/login", login_page, methods=["GET"]),
        Route("/login", login_post, methods=["POST"]),
        Route("/logout", logout, methods=["POST"]),
        Route("/events", events),
        Route("/healthz", healthz),
        *pages.routes,
        *order_pages.routes,
        *result_pages.routes,
        *print_pages.routes,
        *tug_pages.routes,
        *handover_pages.routes,
        *signoff_pages.routes,
        *identify_pages.routes,
        *visit_pages.routes,
        *definition_pages.routes,
        *staff_items.routes,
        *study_pages.routes,
        *api.routes,
        *api_orders.routes,
        Mount("/static", StaticFiles(directory=HERE / "static"), name="static"),
    ]
    middleware = [
        Middleware(SecurityHeaders),
        Middleware(BodyLimit),
        Middleware(
            SessionMiddleware,
            secret_key=auth.secret_key(engine),
            session_cookie="station_session",
            max_age=logins.MAX_AGE_S,
            same_site="strict",
            https_only=https,
        ),
        Middleware(LoginRequired),
    ]
    app = Starlette(
        routes=routes,
        middleware=middleware,
        lifespan=lifespan,
        exception_handlers={Forbidden: forbidden, Exception: errors.station_error},
    )
    app.state.engine, app.state.bus, app.state.questionnaire = engine, bus, q
    app.state.trusted_proxies = trusted_proxies
    app.state.id_pattern = id_pattern
    app.state.zone = zone
    app.state.batteries = batteries
    app.state.live = Live(
        bus,
        lambda name: pages.kiosk_event(app, name),
        lambda: pages.alerts_event(app),
        lambda finished: result_pages.results_event(app, finished),
    )
    return app

"""The served kiosk's gate: textual-serve's aiohttp server with a device key, an Origin and Host
check, and a cap on the kiosk processes it runs.

* **Device key.** Staff run `kiosk serve --new-token` once; it prints an address with
  ``?token=…`` to open in the kiosk's browser. That request is answered with a redirect to the
  address without the token and an HttpOnly, SameSite=Strict cookie holding it; from then on the
  cookie opens the page and its websocket. The configuration keeps only the key's SHA-256. Without
  the key the page is a refusal, and the websocket (which is what starts a kiosk) is refused too.
* **Origin and Host.** Every request must name one of the served addresses in ``Host`` (a DNS
  rebinding page names its own), and the websocket must come from a page of the served origin
  (another page open in the kiosk's browser, even on the same machine, is another origin).
* **Cap.** At most ``max_sessions`` kiosk processes run at once; beyond that the page says the
  kiosk is busy and retries by itself. A closed connection's process is asked to quit, then
  killed if it does not, and only then is its place given to another.
"""

from __future__ import annotations

import asyncio
import hashlib
import hmac
import html
import logging
import ssl
from pathlib import Path
from typing import Any

from aiohttp import web
from textual_serve.app_service import AppService
from textual_serve.server import Server, to_int

#: the folder of the page the browser loads (``app_index.html``)
PAGE_DIR = Path(__file__).parent / "web"

log = logging.getLogger("kiosk.ui.serve.server")

#: the cookie that carries the device key after the first visit
COOKIE = "kiosk_device"
#: Chromium keeps a cookie at most 400 days
COOKIE_MAX_AGE_S = 400 * 24 * 3600
#: how long a request waits for a place held by a connection that is closing (a page reload)
SLOT_GRACE_S = 5.0
#: how long a closed connection's kiosk gets to quit before it is killed
QUIT_GRACE_S = 10.0
#: the busy page tries again this often (seconds)
BUSY_RETRY_S = 10


def token_digest(token: str) -> str:
    """The SHA-256 (hex) the configuration keeps of a device key."""
    return hashlib.sha256(token.encode()).hexdigest()


def _page(status: int, title: str, text: str, retry_s: int | None = None) -> web.Response:
    refresh = f'<meta http-equiv="refresh" content="{retry_s}">' if retry_s else ""
    body = (
        f'<!doctype html><html lang="en"><head><meta charset="utf-8">{refresh}<title>{html.escape(title)}'
        "</title><style>body{font:2rem/1.4 sans-serif;margin:3rem;background:#fdfbf5;color:#111}"
        "h1{font-size:2.6rem}</style></head>"
        f"<body><h1>{html.escape(title)}</h1><p>{html.escape(text)}</p></body></html>"
    )
    return web.Response(status=status, text=body, content_type="text/html")


def refused_page() -> web.Response:
    """The page for a browser without the device key."""
    return _page(
        403,
        "This screen is not set up as a kiosk",
        "The kiosk only opens on a screen that staff have set up. Staff: on the kiosk computer run "
        "`kiosk serve --new-token` and open the address it prints once in this browser.",
    )


def busy_page(limit: int) -> web.Response:
    """The page when every kiosk place is taken."""
    screens = "one screen" if limit == 1 else f"{limit} screens"
    return _page(
        503,
        "The kiosk is in use",
        f"The kiosk is already open on {screens}. Close one of them, or wait: this page tries "
        f"again every {BUSY_RETRY_S} seconds.",
        retry_s=BUSY_RETRY_S,
    )


class KioskServer(Server):
    """textual-serve's server behind the device key, the Origin/Host check and the cap.

    ``hosts`` are the ``Host`` values the kiosk is reached by (``127.0.0.1:8000``, …); the page's
    origins are those hosts with ``scheme``. ``token_sha256`` is the device key's digest.
    """

    def __init__(
        self,
        command: str,
        *,
        host: str,
        port: int,
        hosts: set[str],
        token_sha256: str,
        max_sessions: int,
        ssl_context: ssl.SSLContext | None = None,
        title: str = "Barthel kiosk",
    ) -> None:
        # the kiosk's own page (kiosk/ui/serve/web: offline font, large text that fits the display) over
        # textual-serve's static files
        super().__init__(command, host=host, port=port, title=title, templates_path=PAGE_DIR)
        self.scheme = "https" if ssl_context is not None else "http"
        self.hosts = set(hosts)
        self.origins = {f"{self.scheme}://{name}" for name in self.hosts}
        self.ssl_context = ssl_context
        self.max_sessions = max_sessions
        self._token_sha256 = token_sha256
        #: kiosk processes started and not yet reaped
        self.live = 0
        self._freed: asyncio.Condition | None = None

    # -- the gate --------------------------------------------------------------------------------

    def _has_key(self, token: str | None) -> bool:
        return token is not None and hmac.compare_digest(token_digest(token), self._token_sha256)

    @web.middleware
    async def _gate(self, request: web.Request, handler: Any) -> web.StreamResponse:
        if request.host not in self.hosts:
            log.warning("refused %s %s: Host %r is not a served address", request.method, request.path, request.host)
            return _page(421, "Wrong address", "This kiosk is not served under that name.")
        origin = request.headers.get("Origin")
        websocket = request.path == "/ws"
        if (origin is not None or websocket) and origin not in self.origins:
            log.warning("refused %s %s: Origin %r is not the kiosk's page", request.method, request.path, origin)
            return _page(403, "Refused", "Only the kiosk's own page may open the kiosk.")
        if request.path.startswith("/static/"):
            return await handler(request)  # textual-serve's own scripts and styles: nothing of the kiosk
        if request.path == "/" and "token" in request.query:
            return self._welcome_device(request)
        if not self._has_key(request.cookies.get(COOKIE)):
            log.warning("refused %s %s: no device key", request.method, request.path)
            return refused_page()
        if request.path == "/" and not await self._place_free():
            return busy_page(self.max_sessions)
        return await handler(request)

    def _welcome_device(self, request: web.Request) -> web.StreamResponse:
        """``/?token=…``: keep the key in a cookie and go on to the address without it (so it is
        in no bookmark, no Referer, no screenshot of the address bar)."""
        if not self._has_key(request.query.get("token")):
            log.warning("refused a wrong device key")
            return refused_page()
        rest = request.rel_url.with_query({k: v for k, v in request.query.items() if k != "token"})
        response = web.HTTPSeeOther(location=str(rest))
        response.set_cookie(
            COOKIE,
            request.query["token"],
            max_age=COOKIE_MAX_AGE_S,
            path="/",
            httponly=True,
            samesite="Strict",
            secure=self.ssl_context is not None,
        )
        return response

    @staticmethod
    async def _harden(request: web.Request, response: web.StreamResponse) -> None:
        # no other page may frame the kiosk, and its address (with a token) goes to nobody
        response.headers.setdefault("X-Frame-Options", "DENY")
        response.headers.setdefault("Content-Security-Policy", "frame-ancestors 'none'")
        response.headers.setdefault("Referrer-Policy", "no-referrer")
        response.headers.setdefault("Cache-Control", "no-store")

    async def _make_app(self) -> web.Application:
        app = await super()._make_app()
        app.middlewares.append(self._gate)
        app.on_response_prepare.append(self._harden)
        return app

    # -- the cap -----------------------------------------------------------------------------------

    async def _place_free(self) -> bool:
        """A kiosk process may start now, waiting briefly for one that is closing (a reload)."""
        if self._freed is None:
            self._freed = asyncio.Condition()
        async with self._freed:
            try:
                await asyncio.wait_for(self._freed.wait_for(lambda: self.live < self.max_sessions), SLOT_GRACE_S)
            except TimeoutError:
                return False
        return True

    async def handle_index(self, request: web.Request) -> Any:
        """textual-serve's page, with the websocket at the address this browser used (the key's
        cookie belongs to that host name)."""
        self.public_url = f"{self.scheme}://{request.host}"  # read before this handler's first await
        return await super().handle_index(request)

    # a plain busy page answers when no place is free (textual-serve's own handler always upgrades,
    # and is typed to return a WebSocketResponse: the busy page is the wider StreamResponse)
    async def handle_websocket(self, request: web.Request) -> web.StreamResponse:  # type: ignore[override]  # busy page
        """One browser connection: one kiosk process, if a place is free; reaped when it closes."""
        if not await self._place_free():
            return busy_page(self.max_sessions)
        self.live += 1  # no await since the check: no other connection can take this place
        try:
            return await self._connection(request)
        finally:
            self.live -= 1
            assert self._freed is not None
            async with self._freed:
                self._freed.notify_all()

    async def _connection(self, request: web.Request) -> web.WebSocketResponse:
        websocket = web.WebSocketResponse(heartbeat=15)
        await websocket.prepare(request)
        service = AppService(
            self.command,
            write_bytes=websocket.send_bytes,
            write_str=websocket.send_str,
            close=websocket.close,  # type: ignore[arg-type]  # awaited; its bool result is not used
            download_manager=self.download_manager,
            debug=self.debug,
        )
        try:
            await service.start(
                to_int(request.query.get("width", "80"), 80), to_int(request.query.get("height", "24"), 24)
            )
            await self._process_messages(websocket, service)
        except asyncio.CancelledError:
            pass
        except Exception:  # a broken browser message ends this connection, never the server
            log.exception("kiosk connection failed")
        finally:
            await self._reap(service)
            await websocket.close()
        return websocket

    @staticmethod
    async def _reap(service: AppService) -> None:
        """Ask the kiosk to quit, and kill it if it has not within :data:`QUIT_GRACE_S`."""
        try:
            await asyncio.wait_for(service.stop(), QUIT_GRACE_S)
        except (TimeoutError, Exception):  # a kiosk that does not quit is killed below
            pass
        process = service._process  # textual-serve keeps its process private and offers no kill
        if process is not None and process.returncode is None:
            process.kill()
            await process.wait()

    def serve(self, debug: bool = False) -> None:
        """Run until interrupted, with TLS when a context was given (textual-serve's own serve has none)."""
        self.debug = debug
        self.initialize_logging()
        # no access log: its request lines would write the device key of a first visit into the log
        web.run_app(
            self._make_app(),
            host=self.host,
            port=self.port,
            ssl_context=self.ssl_context,
            access_log=None,
            print=lambda *args: None,
        )

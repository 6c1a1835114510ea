"""A cap on the body of every page request (login, logout, staff forms), checked before anything
parses it: the kiosk API caps its JSON itself (:data:`station.api.MAX_BODY`).

A declared ``Content-Length`` over the cap is refused before a byte is read; a body sent without
one (chunked) is counted as it arrives and refused once past the cap, so an unauthenticated
client can never make the station hold more than :data:`MAX_FORM` bytes of it. The answer is
413 with one sentence, and the connection is closed (the rest of the body is never read).

A client that leaves before its whole body has arrived (a phone losing the ward's Wi-Fi, a tab
closed mid-upload) is answered by nobody and logged by nobody: there is no one to tell, and the
ASGI traceback it used to leave in the log hid real faults (issue 32). That holds on every path,
the kiosk API's included.
"""

from __future__ import annotations

from typing import Any

from starlette.requests import ClientDisconnect
from starlette.responses import PlainTextResponse

#: the station's forms are a name, a password, a reason, a CSRF token: a few hundred bytes
MAX_FORM = 64 * 1024
MESSAGE = f"The form is too large (more than {MAX_FORM // 1024} KiB); nothing was saved."


class _TooLarge(Exception):
    pass


class BodyLimit:
    """ASGI middleware: page requests (all but ``skip`` paths) carry at most ``limit`` bytes."""

    def __init__(self, app: Any, limit: int = MAX_FORM, skip: tuple[str, ...] = ("/api/",)) -> None:
        self.app, self.limit, self.skip = app, limit, skip

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        try:
            await self._limited(scope, receive, send)
        except ClientDisconnect:
            pass  # the client left mid-body: nobody is there to answer, nothing was stored

    async def _limited(self, scope: Any, receive: Any, send: Any) -> None:
        if scope["path"].startswith(self.skip):
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length", b"")
        if declared and (not declared.isdigit() or int(declared) > self.limit):
            await self._refuse(scope, receive, send)
            return
        seen = 0
        started = whole = False

        async def counted() -> Any:
            nonlocal seen, whole
            message = await receive()
            if message["type"] == "http.disconnect" and not whole:  # mid-body: the route stops here
                raise ClientDisconnect  # (after the body, a disconnect is a stream's normal end)
            if message["type"] == "http.request":
                whole = not message.get("more_body", False)
                seen += len(message.get("body", b""))
                if seen > self.limit:
                    raise _TooLarge
            return message

        async def tracked(message: Any) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, counted, tracked)
        except _TooLarge:
            if not started:  # (a route that answered before reading its body has said its piece)
                await self._refuse(scope, receive, send)

    @staticmethod
    async def _refuse(scope: Any, receive: Any, send: Any) -> None:
        response = PlainTextResponse(MESSAGE, status_code=413, headers={"connection": "close"})
        await response(scope, receive, send)

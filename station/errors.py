"""Errors mapped to answers in one place: staff read a page saying what is wrong, a kiosk reads
JSON naming it, never a bare 500.

The station's database failing (a full disk, a read-only file, a lost server) is the one error
a hospital meets in the field; it gets a 503 saying the station cannot store or read its data
and why, so the ward knows to call IT rather than retry. Anything else unexpected is a 500 page
that still says what happened (its traceback goes to the station's log, not to the page).
"""

from __future__ import annotations

import logging
from html import escape

import sqlalchemy as sa
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, Response

from station.sessions import NotFound

log = logging.getLogger("station.errors")


def reason(exc: BaseException) -> str:
    """The database's own words for what went wrong, on one line (no SQL, no parameters)."""
    orig = getattr(exc, "orig", None) or exc
    text = str(orig).strip().splitlines()
    return text[0][:300] if text else type(orig).__name__


def _storage(exc: BaseException) -> bool:
    return isinstance(exc, (sa.exc.OperationalError, sa.exc.InternalError)) or (
        isinstance(exc, sa.exc.DBAPIError) and exc.connection_invalidated
    )


def answer_for(path: str, exc: BaseException) -> tuple[int, str]:
    """The status and the sentence for ``exc`` raised while answering ``path``."""
    if isinstance(exc, NotFound):
        return 404, f"No session {exc.args[0] if exc.args else ''} has reached this station."
    if _storage(exc):
        return 503, f"The station cannot store data: {reason(exc)}. Tell the hospital's IT staff."
    if isinstance(exc, sa.exc.SQLAlchemyError):
        return 503, f"The station's database refused the request: {reason(exc)}. Tell the hospital's IT staff."
    return 500, f"The station failed to answer ({type(exc).__name__}); the error is in the station's log."


PAGE = """<!doctype html><html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1"><title>{title} — Ward station</title>
<link rel="stylesheet" href="/static/station.css"></head><body>
<header class="bar"><a class="brand" href="/">Ward station</a></header>
<main><h1>{title}</h1><p class="error" role="alert" id="station-error">{message}</p>
<p><a href="javascript:history.back()">Back</a> · <a href="/">Ward</a></p></main></body></html>"""


async def station_error(request: Request, exc: Exception) -> Response:
    """The one handler for whatever a route or middleware raised (Starlette's outermost one)."""
    status, message = answer_for(request.url.path, exc)
    if status >= 500:
        log.error("station: %s %s: %s", request.method, request.url.path, message, exc_info=exc)
    if request.url.path.startswith("/api/"):
        return JSONResponse({"error": message}, status_code=status)
    title = "Not found" if status == 404 else "The station has a problem"
    return HTMLResponse(PAGE.format(title=title, message=escape(message)), status_code=status)

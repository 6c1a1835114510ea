"""The one way a page sends the browser on with a message or a form's fields: every value is
capped before it goes into the ``Location`` header, so what a client typed can never grow the
header (issue 32: a 10,000-character kiosk field came back whole in it).

A message is cut with an ellipsis (it is only read); a form field longer than any valid value
(:data:`FIELD`) is not sent back at all, so a cut value is never offered as if it had been typed.
"""

from __future__ import annotations

from urllib.parse import quote, urlencode

from starlette.responses import RedirectResponse

#: a message's longest echo: one sentence naming a field and its problem
MESSAGE = 300
#: the longest form field worth sending back to its form (kiosk ids and identifiers are at most 64)
FIELD = 64


def capped(text: str, limit: int = MESSAGE) -> str:
    """``text``, cut to ``limit`` characters with an ellipsis when longer."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def see_other(path: str, *, fields: dict[str, str] | None = None, **messages: str) -> RedirectResponse:
    """303 to ``path`` with ``messages`` (capped) and ``fields`` (dropped when over :data:`FIELD`)
    in its query string."""
    query = {name: capped(text) for name, text in messages.items()}
    query |= {name: value for name, value in (fields or {}).items() if len(value) <= FIELD}
    target = f"{path}?{urlencode(query, quote_via=quote)}" if query else path
    return RedirectResponse(target, status_code=303)

"""Rendering pages and checking forms: the Jinja2 templates, the login session's user, CSRF.

Shared by the login routes (:mod:`station.web`) and the staff pages (:mod:`station.pages`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from jinja2 import pass_context
from starlette.requests import Request
from starlette.responses import Response
from starlette.templating import Jinja2Templates

from station import auth, logins, times, ward

templates = Jinja2Templates(directory=Path(__file__).with_name("templates"))
templates.env.globals["offline_after"] = ward.OFFLINE_AFTER_S
#: who answered, as staff write it
templates.env.globals["answered_words"] = {
    "patient": "the patient",
    "relative": "a relative",
    "caregiver": "a caregiver",
    "staff": "staff",
}


@pass_context
def _when(context: Any, iso: Any, form: str = "minute") -> str:
    """``{{ r.finished_at|when }}``: a stored time in the site's zone (:mod:`station.times`)."""
    request = context.get("request")  # a page; a fragment for the live feed passes its ``zone``
    zone = getattr(request.app.state, "zone", None) if request is not None else context.get("zone")
    return times.shown(iso, zone, form)


templates.env.filters["when"] = _when
#: the same, as the visit pages name it (``{{ x|shown }}``, minutes)
templates.env.filters["shown"] = _when

#: a language as staff read it (``{{ s.language|language }}``), never its code; one the list does
#: not have shows its code
LANGUAGE_WORDS = {
    "en": "English",
    "es": "Spanish",
    "fr": "French",
    "de": "German",
    "it": "Italian",
    "pt": "Portuguese",
    "ca": "Catalan",
    "eu": "Basque",
    "gl": "Galician",
    "nl": "Dutch",
    "ar": "Arabic",
    "ro": "Romanian",
    "pl": "Polish",
}
templates.env.filters["language"] = lambda code: LANGUAGE_WORDS.get(str(code), str(code))
#: a command as staff name it (the buttons' words), never its protocol name
templates.env.globals["command_labels"] = {
    "continue": "Continue session",
    "person_away": "Patient away",
    "person_back": "Patient back",
    "end": "End session",
}


class Forbidden(Exception):
    """A page request without a valid CSRF token or from another origin."""


def current_user(request: Request) -> auth.User | None:
    """The user of the request's login session, if that session is still live on the server."""
    session_id = request.session.get("sid")
    return logins.user_of(request.app.state.engine, session_id) if isinstance(session_id, str) else None


def csrf_token(request: Request) -> str:
    token = request.session.get("csrf")
    if not token:
        token = request.session["csrf"] = auth.new_csrf_token()
    return token


async def checked_form(request: Request) -> dict[str, str]:
    """The POSTed form, after the CSRF and origin checks (Forbidden otherwise)."""
    origin = request.headers.get("origin")
    if origin and origin != "null" and urlsplit(origin).netloc != request.headers.get("host"):
        raise Forbidden("cross-origin form")
    form = await request.form()
    values = {k: str(v) for k, v in form.items()}
    if not auth.csrf_ok(request.session.get("csrf"), values.get("csrf")):
        raise Forbidden("missing or stale CSRF token (reload the page and try again)")
    return values


def render(request: Request, name: str, status: int = 200, **context: Any) -> Response:
    context.setdefault("user", getattr(request.state, "user", None))
    if context["user"] is not None and "waiting" not in context:  # the navigation's count
        context["waiting"] = getattr(request.state, "waiting", None)
        if context["waiting"] is None:  # read with the login, in the staff lane (station.web)
            from station.results import waiting_count

            context["waiting"] = waiting_count(request.app.state.engine)
    context["csrf"] = csrf_token(request)
    return templates.TemplateResponse(request, name, context, status_code=status)

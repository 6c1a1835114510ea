"""The visit's pages (issue 36): the visit (every instrument, its changes and staff items, the
TUG's place), the one sign-off's confirmation, and the sign-off itself.

Routes only: read the path and the form, call :mod:`station.visit_review`, publish, redirect
(post/redirect/get). A result's own page (``/sessions/ID``) stays where items are corrected and
numbers entered; the visit links to it, and its amend form comes back here.
"""

from __future__ import annotations

from functools import partial

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Route

from station import visit_review
from station.redirects import see_other
from station.rendering import checked_form, render
from station.sessions import NotFound
from station.validation import ValidationError
from station.visit_inbox import visit_href

#: the sign-off form's field of one result's reason to sign it off incomplete
REASON_FIELD = "incomplete_reason:"


async def _read(request: Request) -> visit_review.Visit | Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    key = request.path_params["key"]
    try:
        return await run_in_threadpool(visit_review.read, engine, q, key, request.app.state.zone)
    except NotFound:
        return PlainTextResponse(f"no visit {key} has reached this station", status_code=404)


async def visit_page(request: Request) -> Response:
    found = await _read(request)
    if isinstance(found, Response):
        return found
    return render(
        request, "visit.html", v=found, href=visit_href(found.key), message=request.query_params.get("message")
    )


async def confirm_page(request: Request) -> Response:
    """The confirmation: each instrument's total and every change in words, then one button."""
    found = await _read(request)
    if isinstance(found, Response):
        return found
    if not request.state.user.is_doctor:
        return see_other(visit_href(found.key), message="Only a doctor can sign off.")
    if not found.signable:
        return see_other(visit_href(found.key), message="Nothing in this visit waits for sign-off.")
    return render(
        request,
        "visit_sign_off.html",
        v=found,
        href=visit_href(found.key),
        reason_field=REASON_FIELD,
        message=request.query_params.get("message"),
    )


async def sign_off(request: Request) -> Response:
    """POST the visit's sign-off: every waiting result in one transaction, or none."""
    form = await checked_form(request)
    engine, q = request.app.state.engine, request.app.state.questionnaire
    key = request.path_params["key"]
    reasons = {name[len(REASON_FIELD) :]: value for name, value in form.items() if name.startswith(REASON_FIELD)}
    try:
        signed = await run_in_threadpool(
            partial(visit_review.sign_off, seen=form.get("seen", ""), reasons=reasons),
            engine,
            q,
            key,
            request.state.user,
        )
    except NotFound:
        return PlainTextResponse(f"no visit {key} has reached this station", status_code=404)
    except ValidationError as exc:
        return see_other(f"{visit_href(key)}/sign-off", message=str(exc))
    bus = request.app.state.bus
    await run_in_threadpool(bus.publish, *({"type": "result", "session": s} for s in signed))
    count = len(signed)
    return see_other(visit_href(key), message=f"Signed off: {count} result{'s' if count != 1 else ''} of the visit.")


routes = [
    Route("/visits/{key}", visit_page),
    Route("/visits/{key}/sign-off", confirm_page, methods=["GET"]),
    Route("/visits/{key}/sign-off", sign_off, methods=["POST"]),
]

"""A doctor approves a questionnaire definition a kiosk sent and the station did not know
(:mod:`station.known`): from then on its total formula is run (in the formula process,
:mod:`station.formulas`) and its results get their totals."""

from __future__ import annotations

from urllib.parse import quote

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import RedirectResponse, Response
from starlette.routing import Route

from station import known
from station.rendering import checked_form


async def approve(request: Request) -> Response:
    form = await checked_form(request)
    sha = request.path_params["sha"]
    back = form.get("back", "/")
    if not back.startswith("/") or back.startswith("//"):
        back = "/"
    try:
        await run_in_threadpool(known.approve, request.app.state.engine, sha, request.state.user)
    except known.KnownError as exc:
        return RedirectResponse(f"{back}?message={quote(str(exc))}", status_code=303)
    await run_in_threadpool(request.app.state.bus.publish, {"type": "sessions"})
    return RedirectResponse(f"{back}?message={quote('Definition approved: its results are scored.')}", status_code=303)


routes = [Route("/definitions/{sha:str}/approve", approve, methods=["POST"])]

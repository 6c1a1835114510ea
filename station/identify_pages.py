"""The form that gives a walk-up result its hospital identifier (:mod:`station.identify`), on the
result's page: thin, as the other pages (CSRF, the use case, publish, redirect back)."""

from __future__ import annotations

from urllib.parse import quote

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import Response
from starlette.routing import Route

from station import identify
from station.redirects import see_other
from station.rendering import checked_form


async def identify_result(request: Request) -> Response:
    form = await checked_form(request)
    session_id = request.path_params["session_id"]
    back = f"/sessions/{quote(session_id)}"
    try:
        old = await run_in_threadpool(
            identify.identify,
            request.app.state.engine,
            session_id,
            str(form.get("patient_id", "")),
            request.state.user,
            request.app.state.id_pattern,
            str(form.get("reason", "")),
        )
    except identify.IdentifyError as exc:
        return see_other(back, message=str(exc))
    # the Results lists name the patient: they follow
    await run_in_threadpool(request.app.state.bus.publish, {"type": "sessions"})
    new = str(form.get("patient_id", "")).strip()
    return see_other(back, message=f"The result is now filed under {new} (it was recorded as {old}).")


routes = [Route("/sessions/{session_id}/identify", identify_result, methods=["POST"])]

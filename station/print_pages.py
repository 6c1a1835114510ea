"""The print views for the paper chart (issue 36, part 3): a visit and a patient's course.

Routes only: read the path, call :mod:`station.printing` (one connection), render. The page is
made to be printed (``@media print`` in ``station.css`` hides the navigation and every form); its
"Print or save as PDF" button opens the browser's print dialog, whose "Save as PDF" makes the PDF.
"""

from __future__ import annotations

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Route

from station import db, printing
from station.rendering import render
from station.sessions import NotFound


def _now(request: Request) -> str:
    return printing.shown_time(db.now_iso(), request.app.state.zone)


async def visit_print(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    session_id = request.path_params["session_id"]
    try:
        found = await run_in_threadpool(printing.visit, engine, q, session_id, request.app.state.zone)
    except NotFound:
        return PlainTextResponse(f"no session {session_id} has reached this station", status_code=404)
    return render(
        request, "print_visit.html", visits=[found], patient_id=found.patient_id, course=False, printed_at=_now(request)
    )


async def course_print(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    patient_id = request.path_params["patient_id"]
    found = await run_in_threadpool(printing.course, engine, q, patient_id, request.app.state.zone)
    if not found:
        return PlainTextResponse(f"no visit of patient {patient_id} has reached this station", status_code=404)
    return render(
        request, "print_visit.html", visits=found, patient_id=patient_id, course=True, printed_at=_now(request)
    )


routes = [
    Route("/sessions/{session_id}/print", visit_print),
    Route("/patients/{patient_id}/print", course_print),
]

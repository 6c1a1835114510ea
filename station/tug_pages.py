"""The pages of one Timed Up and Go result: the result itself (for a TUG ordered alone, which has
no session page; a visit's questionnaire sessions show it on theirs), its FHIR and CSV exports
(:mod:`station.tug_exports`) and its print view for the chart. Read-only: staff decided it at
the kiosk.
"""

from __future__ import annotations

import json

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, Response
from starlette.routing import Route

from station import db, printing, tug_exports, tugs
from station.download import attachment
from station.rendering import render


def _missing(tug_id: str) -> Response:
    return PlainTextResponse(f"no Timed Up and Go {tug_id} has reached this station", status_code=404)


async def tug_page(request: Request) -> Response:
    tug_id = request.path_params["tug_id"]
    found = await run_in_threadpool(tugs.get, request.app.state.engine, tug_id)
    if found is None:
        return _missing(tug_id)
    return render(request, "tug.html", tugs=[found])


async def tug_export(request: Request) -> Response:
    tug_id, fmt = request.path_params["tug_id"], request.path_params["fmt"]
    if fmt not in ("json", "csv"):
        return PlainTextResponse(f"no export .{fmt[:20]}: choose export.json (FHIR) or export.csv", status_code=404)
    found = await run_in_threadpool(tugs.get, request.app.state.engine, tug_id)
    if found is None:
        return _missing(tug_id)
    if found.time() is None:
        return PlainTextResponse(f"Timed Up and Go {tug_id} was rejected: it has no time to export", status_code=404)
    if fmt == "json":
        body, media, suffix = json.dumps(tug_exports.bundle([found]), indent=2), "application/fhir+json", ".fhir.json"
    else:
        body, media, suffix = tug_exports.csv_text([found]), "text/csv", ".csv"
    return Response(body, media_type=media, headers={"content-disposition": attachment(f"tug-{tug_id}", suffix)})


async def tug_print(request: Request) -> Response:
    engine, q = request.app.state.engine, request.app.state.questionnaire
    tug_id = request.path_params["tug_id"]
    found = await run_in_threadpool(printing.tug_visit, engine, q, tug_id)
    if found is None:
        return _missing(tug_id)
    now = printing.shown_time(db.now_iso())
    return render(
        request, "print_visit.html", visits=[found], patient_id=found.patient_id, course=False, printed_at=now
    )


routes = [
    Route("/tugs/{tug_id}", tug_page),
    Route("/tugs/{tug_id}/export.{fmt:str}", tug_export),
    Route("/tugs/{tug_id}/print", tug_print),
]

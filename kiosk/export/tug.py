"""A Timed Up and Go time as FHIR R4 and CSV: the Observation, its phases, how it was timed.

The time is LOINC 89423-8 (time to rise from a chair, walk 10 feet and back, and return to sitting,
in s; its panel is 89422-0), per /work reference tug.md: **unverified here against loinc.org**,
check before a site relies on it. The phases have no LOINC codes: they are components coded in the
kiosk's own system (``urn:barthel-kiosk:tug-phase``), as is the method (camera or stopwatch).
Stored results (:mod:`kiosk.store.tug`) come out through :func:`tug_times` (``kiosk results``); the
Get Up & Go rating and the walking aid are components too, and the site's threshold a note worded
"above the site's threshold", never an interpretation code (it is not a diagnosis).
"""

from __future__ import annotations

import csv
import io
import uuid
from collections.abc import Sequence
from typing import Any
from urllib.parse import quote

from basis import record
from kiosk.core.site import ExportSite
from kiosk.core.tug.analysis import Phase
from kiosk.export.fhir import device_reference, instant, practitioner
from kiosk.store.tug import StoredTug

LOINC = "http://loinc.org"
UCUM = "http://unitsofmeasure.org"
TUG_CODE = {"system": LOINC, "code": "89423-8", "display": "Timed up and go [Time]"}
PHASE_SYSTEM = "urn:barthel-kiosk:tug-phase"
METHOD_SYSTEM = "urn:barthel-kiosk:tug-method"
STAFF_ITEM_SYSTEM = "urn:barthel-kiosk:tug-staff-item"
METHODS = {"camera": "Timed by the kiosk's camera", "stopwatch": "Timed by staff with a stopwatch"}
PHASE_NAMES = {
    "sit_to_stand": "Sit to stand",
    "walk_out": "Walk out",
    "turn": "Turn",
    "walk_back": "Walk back",
    "turn_and_sit": "Turn and sit",
}


@record
class TugTime:
    """One accepted time: ``total_s``, how it was taken (``method``: camera or stopwatch), when,
    the phases (camera only), who accepted it and the result's identifier."""

    result_id: str
    patient_id: str
    total_s: float
    method: str
    effective: str
    phases: tuple[Phase, ...] = ()
    accepted_by: str = ""
    staff_system: str = "urn:barthel-kiosk:staff"
    #: staff items: the Get Up & Go rating (1-5) and the walking aid
    get_up_go: int | None = None
    walking_aid: str | None = None
    #: the site's fall-risk threshold (s) when the test was taken, None: not said
    threshold_s: float | None = None


def _seconds(value: float) -> dict[str, Any]:
    return {"value": round(value, 2), "unit": "s", "system": UCUM, "code": "s"}


def fhir_tug(time: TugTime, site: ExportSite | None = None) -> dict[str, Any]:
    """The time as an R4 Observation (final once staff accepted it, else preliminary)."""
    if time.method not in METHODS:
        raise ValueError(f"method {time.method!r}: one of {', '.join(METHODS)}")
    site = site or ExportSite()
    observation: dict[str, Any] = {
        "resourceType": "Observation",
        "identifier": [{"system": site.identifier_system, "value": site.result_id(time.result_id) + "/tug"}],
        "status": "final" if time.accepted_by else "preliminary",
        "category": [
            {"coding": [{"system": "http://terminology.hl7.org/CodeSystem/observation-category", "code": "exam"}]}
        ],
        "code": {"coding": [TUG_CODE], "text": "Timed Up and Go"},
        "subject": {"type": "Patient", "identifier": {"system": site.patient_system, "value": time.patient_id}},
        "effectiveDateTime": instant(time.effective),
        "valueQuantity": _seconds(time.total_s),
        "method": {
            "coding": [{"system": METHOD_SYSTEM, "code": time.method, "display": METHODS[time.method]}],
            "text": METHODS[time.method],
        },
    }
    if time.method == "camera":
        observation["device"] = device_reference(site)
    if time.accepted_by:
        observation["performer"] = [practitioner(time.accepted_by, time.staff_system)]
    components: list[dict[str, Any]] = [
        {
            "code": {"coding": [{"system": PHASE_SYSTEM, "code": p.name, "display": PHASE_NAMES[p.name]}]},
            "valueQuantity": _seconds(p.duration_s),
        }
        for p in time.phases
    ]
    if time.get_up_go is not None:
        code = {"system": STAFF_ITEM_SYSTEM, "code": "get_up_go", "display": "Get Up & Go rating (1-5)"}
        components.append({"code": {"coding": [code]}, "valueInteger": time.get_up_go})
    if time.walking_aid is not None:
        code = {"system": STAFF_ITEM_SYSTEM, "code": "walking_aid", "display": "Walking aid"}
        components.append({"code": {"coding": [code]}, "valueString": time.walking_aid})
    if components:
        observation["component"] = components
    if time.threshold_s is not None:
        side = "above" if time.total_s > time.threshold_s else "not above"
        observation["note"] = [{"text": f"{side} the site's threshold ({time.threshold_s:g} s)"}]
    return observation


CSV_COLUMNS = ("result_id", "patient_id", "effective", "method", "measure", "seconds", "accepted_by")


def tug_csv_rows(time: TugTime) -> list[tuple[str, ...]]:
    """Long-format rows (:data:`CSV_COLUMNS`): the total, then one row per phase."""
    base = (time.result_id, time.patient_id, time.effective, time.method)
    rows: list[tuple[str, ...]] = [(*base, "total", f"{time.total_s:.2f}", time.accepted_by)]
    rows += [(*base, p.name, f"{p.duration_s:.2f}", time.accepted_by) for p in time.phases]
    return rows


def phases_total(phases: Sequence[Phase]) -> float:
    """The phases' durations added up (they tile the course from onset to seated)."""
    return sum(p.duration_s for p in phases)


def tug_times(stored: Sequence[StoredTug]) -> list[TugTime]:
    """The stored results that have a time (accepted or entered by stopwatch), as :class:`TugTime`."""
    times = []
    for tug in stored:
        result = tug.result
        if result.total_s is None or result.method is None:
            continue  # rejected: no time to send
        times.append(
            TugTime(
                result_id=tug.id,
                patient_id=tug.patient_id,
                total_s=result.total_s,
                method=result.method,
                effective=tug.at,
                phases=result.phases if result.method == "camera" else (),
                accepted_by=result.decided_by,
                get_up_go=result.get_up_go,
                walking_aid=result.walking_aid,
                threshold_s=result.threshold_s,
            )
        )
    return times


def tug_entries(times: Sequence[TugTime], site: ExportSite | None = None) -> list[dict[str, Any]]:
    """Transaction Bundle entries for ``times`` (conditional create on the identifier, as the
    questionnaire results' are)."""
    entries = []
    for time in times:
        observation = fhir_tug(time, site)
        identifier = observation["identifier"][0]
        condition = "identifier=" + quote(f"{identifier['system']}|{identifier['value']}", safe="")
        full_url = f"urn:uuid:{uuid.uuid5(uuid.NAMESPACE_URL, identifier['system'] + '|' + identifier['value'])}"
        request = {"method": "POST", "url": "Observation", "ifNoneExist": condition}
        entries.append({"fullUrl": full_url, "resource": observation, "request": request})
    return entries


def tug_csv(times: Sequence[TugTime], *, bom: bool = False) -> str:
    """The CSV file of ``times``: a header of :data:`CSV_COLUMNS`, then their rows."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for time in times:
        writer.writerows(tug_csv_rows(time))
    return ("\ufeff" if bom else "") + out.getvalue()

"""A Timed Up and Go time as FHIR R4 and CSV: the Observation, its phases, how it was timed.

The time is LOINC 89423-8 (time to rise from a chair, walk 10 feet and back, and return to sitting,
in s; its panel is 89422-0), per /work reference tug.md: **unverified here against loinc.org**,
check before a site relies on it. The phases have no LOINC codes: they are components coded in the
kiosk's own system (``urn:barthel-kiosk:tug-phase``), as is the method (camera or stopwatch). Not
yet wired to stored visits (issue 34 parts 3-4): callers pass what they have.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from basis import record
from kiosk.core.site import ExportSite
from kiosk.core.tug.analysis import Phase
from kiosk.export.fhir import device_reference, instant, practitioner

LOINC = "http://loinc.org"
UCUM = "http://unitsofmeasure.org"
TUG_CODE = {"system": LOINC, "code": "89423-8", "display": "Timed up and go [Time]"}
PHASE_SYSTEM = "urn:barthel-kiosk:tug-phase"
METHOD_SYSTEM = "urn:barthel-kiosk:tug-method"
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
    if time.phases:
        observation["component"] = [
            {
                "code": {"coding": [{"system": PHASE_SYSTEM, "code": p.name, "display": PHASE_NAMES[p.name]}]},
                "valueQuantity": _seconds(p.duration_s),
            }
            for p in time.phases
        ]
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

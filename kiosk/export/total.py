"""The total as an R4 Observation (see :mod:`kiosk.export.fhir`'s docstring): every complete
result has one, coded with the instrument's standard ``total_code`` or else the site's own code
(:func:`site_total_code`); a result signed off incomplete has one without a value, ``final`` with
a ``dataAbsentReason``; an incomplete result not signed off has none, so a partial sum is never
charted as a total."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from kiosk.core.questionnaire import Questionnaire
from kiosk.core.review import Review, ReviewState
from kiosk.core.site import ExportSite
from kiosk.export.calculated import subscale_components
from kiosk.export.fhir import (
    DATA_ABSENT,
    SURVEY,
    TOTAL_TEXT,
    code_coding,
    device_reference,
    instant,
    labelled,
    patient_reference,
    practitioner,
)
from kiosk.export.result import Result, result
from kiosk.store.database import StoredSession


def site_total_system(site: ExportSite) -> str:
    """The site's own code system for totals of instruments with no standard code."""
    return f"urn:barthel-kiosk:{site.site}:total"


def site_total_code(q: Questionnaire, site: ExportSite) -> dict[str, str]:
    """The total's Coding for an instrument without a standard ``total_code`` (the Lawton, the
    SARC-F, a site's own): the site's code system, the instrument's id as code and its English
    title as display, so a hospital that charts Observations charts these too."""
    return {"system": site_total_system(site), "code": q.id, "display": f"{q.title['en']} total"}


def observation_status(r: Result) -> str:
    """``preliminary`` until a clinician signs off; then ``final``, or ``amended`` with corrections."""
    return {ReviewState.AMENDED: "amended", ReviewState.SIGNED_OFF: "final"}.get(r.state, "preliminary")


def fhir_total(
    q: Questionnaire,
    stored: StoredSession,
    review: Review | None = None,
    site: ExportSite | None = None,
    values: Mapping[str, float] | None = None,
) -> dict[str, Any] | None:
    """The total as an R4 Observation (coded with the instrument's ``total_code``, the Barthel's
    LOINC 96761-2) derived from the response; None when the result is incomplete, so a partial sum
    is never charted as a total."""
    site = site or ExportSite()
    response = {
        "type": "QuestionnaireResponse",
        "identifier": {"system": site.identifier_system, "value": site.result_id(stored.id)},
    }
    return total_of(q, result(q, stored, review, values), site, response)


def total_of(q: Questionnaire, r: Result, site: ExportSite, response: dict[str, Any]) -> dict[str, Any] | None:
    """A :class:`Result`'s total as an Observation derived from ``response`` (a Reference); None
    when incomplete and not signed off. Every complete result has one: coded with the
    instrument's ``total_code`` where it has a standard one, else with :func:`site_total_code`.
    A result signed off incomplete has one without a value: ``final`` with a ``dataAbsentReason``
    saying why, so a chart shows the missing total rather than nothing (or a partial sum)."""
    if not r.complete and not r.final:
        return None
    stored, language = r.stored, r.stored.language
    observation: dict[str, Any] = {
        "resourceType": "Observation",
        "language": language,
        "identifier": [{"system": site.identifier_system, "value": site.result_id(stored.id) + "/total"}],
        "status": observation_status(r),
        "category": [{"coding": [SURVEY]}],
        "code": {
            "coding": [code_coding(q.total_code) if q.total_code else site_total_code(q, site)],
            "text": f"{q.title[language]}: {TOTAL_TEXT.get(language, 'Total')}",
        },
        "subject": patient_reference(site, stored),
        "effectiveDateTime": instant(stored.finished_at or stored.started_at),
        "device": device_reference(site),
        "derivedFrom": [response],
    }
    if r.complete:
        observation["valueQuantity"] = {
            "value": r.score.total,
            "unit": "{score}",
            "system": "http://unitsofmeasure.org",
            "code": "{score}",
        }
    else:  # R4 obs-6: a reason for the missing value instead of one
        observation["dataAbsentReason"] = {
            "coding": [{"system": DATA_ABSENT, "code": "unknown", "display": "Unknown"}],
            "text": r.incomplete_words,
        }
    components = subscale_components(q, r, language)
    if components:
        observation["component"] = components
    band_set = q.bands_named(r.score.band_set)
    if r.complete and r.score.band is not None:
        observation["interpretation"] = [
            {
                "coding": [
                    {
                        # the instrument's id too: two instruments' "normal" bands are not one code
                        "system": f"urn:barthel-kiosk:band-set:{q.id}:{band_set.id}",
                        "code": r.score.band.id,
                        "display": r.score.band.label["en"],
                    }
                ],
                "text": f"{r.score.band.label[language]} ({band_set.id}: {band_set.source})",
            }
        ]
    if r.final:
        observation["issued"] = instant(r.review.signed_at or "")
        observation["performer"] = [practitioner(r.review.signed_by or "", r.review.staff_system)]
    notes = [
        {
            "authorString": c.author,
            "time": instant(c.at),
            "text": f"{c.item_id}: option {c.previous_option or 'none'} -> {c.option} ({c.reason})",
        }
        for c in r.review.corrections
    ]
    if notes:
        observation["note"] = notes
    return labelled(observation, stored)

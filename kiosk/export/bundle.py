"""FHIR R4 transaction Bundles of results: what a hospital's FHIR server takes as it is, from the
kiosk (``kiosk results --fhir``) and from the ward station (one result, or every result signed off
in a period) alike.

Every result travels with what describes it (:class:`Described`: the questionnaire it was answered
on and its identity, :class:`ExportSite`), given by the caller, never read here from a file or a
configuration. For each result the Bundle holds, in order: the Questionnaire of its language
(conditional create on url+version) and its kiosk's Device (conditional create on identifier), each
once per Bundle; the QuestionnaireResponse and, when complete, the total Observation (conditional
create on their identifier until signed off, then conditional update ``PUT Type?identifier=…`` so
the signed-off or amended version replaces the earlier one); one Provenance per change
(:mod:`kiosk.export.provenance`, update-as-create on a stable id). fullUrls are UUIDs derived from
identifiers, so re-exports are byte-identical and references inside the Bundle resolve.
"""

from __future__ import annotations

import uuid
from collections.abc import Sequence
from typing import Any
from urllib.parse import quote

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.review import Review
from kiosk.core.site import ExportSite
from kiosk.export.fhir import fhir_device, fhir_questionnaire, questionnaire_canonical, response_of
from kiosk.export.provenance import fhir_provenances
from kiosk.export.result import Result, questionnaire_version, results
from kiosk.export.total import total_of
from kiosk.store.database import StoredSession


@record
class Described:
    """One result with what describes it: the questionnaire it was answered on and the identity
    (site, kiosk, FHIR systems) it was recorded under."""

    questionnaire: Questionnaire
    result: Result
    site: ExportSite


def _full_url(system: str, value: str) -> str:
    return f"urn:uuid:{uuid.uuid5(uuid.NAMESPACE_URL, f'{system}|{value}')}"


def _query(**params: str) -> str:
    return "&".join(f"{name}={quote(value, safe='')}" for name, value in params.items())


def _entry(resource: dict[str, Any], full_url: str, condition: str, update: bool) -> dict[str, Any]:
    kind = resource["resourceType"]
    request = (
        {"method": "PUT", "url": f"{kind}?{condition}"}
        if update
        else {"method": "POST", "url": kind, "ifNoneExist": condition}
    )
    return {"fullUrl": full_url, "resource": {k: v for k, v in resource.items() if k != "id"}, "request": request}


def _questionnaire_entry(q: Questionnaire, site: ExportSite, language: str) -> dict[str, Any]:
    url, version = questionnaire_canonical(q, site, language), questionnaire_version(q)
    return _entry(
        fhir_questionnaire(q, language, site), _full_url(url, version), _query(url=url, version=version), update=False
    )


def _result_entries(d: Described, device_url: str) -> list[dict[str, Any]]:
    q, r, site = d.questionnaire, d.result, d.site
    response = response_of(q, r, site)
    response["author"] = response["author"] | {"reference": device_url}
    value = site.result_id(r.stored.id)
    response_url = _full_url(site.identifier_system, value)
    entries = [_entry(response, response_url, _query(identifier=f"{site.identifier_system}|{value}"), update=r.final)]
    total = total_of(
        q, r, site, {"reference": response_url, "type": "QuestionnaireResponse", "identifier": response["identifier"]}
    )
    if total is not None:
        total["device"] |= {"reference": device_url}
        entries.append(
            _entry(
                total,
                _full_url(site.identifier_system, value + "/total"),
                _query(identifier=f"{site.identifier_system}|{value}/total"),
                update=r.final,
            )
        )
    device = response["author"]
    for provenance in fhir_provenances(
        q, r, site, {"reference": response_url, "type": "QuestionnaireResponse"}, device
    ):
        entries.append(
            {
                "fullUrl": f"urn:uuid:{provenance['id']}",
                "resource": provenance,
                "request": {"method": "PUT", "url": f"Provenance/{provenance['id']}"},
            }
        )
    return entries


def bundle_of(described: Sequence[Described]) -> dict[str, Any]:
    """Results, each with its own questionnaire and identity, as one R4 transaction Bundle (see
    the module docstring): the Questionnaires first, then the Devices, then the results."""
    questionnaires: dict[str, dict[str, Any]] = {}
    devices: dict[str, dict[str, Any]] = {}
    results_: list[dict[str, Any]] = []
    for d in described:
        site = d.site
        entry = _questionnaire_entry(d.questionnaire, site, d.result.stored.language)
        questionnaires.setdefault(entry["fullUrl"], entry)
        device_url = _full_url(site.device_system, site.kiosk_id)
        if device_url not in devices:
            devices[device_url] = _entry(
                fhir_device(site), device_url, _query(identifier=f"{site.device_system}|{site.kiosk_id}"), update=False
            )
        results_ += _result_entries(d, device_url)
    entries = [*questionnaires.values(), *devices.values(), *results_]
    # FHIR JSON has no empty arrays: a Bundle of nothing has no entry at all
    return {"resourceType": "Bundle", "type": "transaction"} | ({"entry": entries} if entries else {})


def transaction_bundle(
    q: Questionnaire,
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review] | None = None,
    site: ExportSite | None = None,
) -> dict[str, Any]:
    """Sessions answered on ``q`` under one identity ``site``, with their reviews (same order;
    None: unreviewed), as one R4 transaction Bundle (:func:`bundle_of`)."""
    site = site or ExportSite()
    return bundle_of([Described(q, r, site) for r in results(q, sessions, reviews)])


def questionnaire_bundle(
    q: Questionnaire | Sequence[Questionnaire], site: ExportSite | None = None, language: str | None = None
) -> dict[str, Any]:
    """The questionnaire (or each of a battery's instruments) in every language, or only in
    ``language``, as a transaction Bundle of conditional creates."""
    site = site or ExportSite()
    instruments = [q] if isinstance(q, Questionnaire) else list(q)
    return {
        "resourceType": "Bundle",
        "type": "transaction",
        "entry": [
            _questionnaire_entry(one, site, lang)
            for one in instruments
            for lang in one.languages
            if language is None or lang == language
        ],
    }

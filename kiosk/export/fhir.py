"""FHIR R4 exports: Questionnaire, QuestionnaireResponse, the total as an Observation, and a
transaction Bundle a FHIR server takes as it is.

Choices, each from the R4 specification:

- **One Questionnaire per language** (``URL-en``, ``URL-es``, ``URL-fr``; ``language`` set), each
  also carrying the other languages in the ``translation`` extension on every text and option
  display. A response points at the Questionnaire of its own language, so its item texts and
  answer displays are the Questionnaire's, word for word, in every language.
- **Version** from the content (:func:`kiosk.export.result.questionnaire_version`): editing the file
  gives a new version, and responses name the exact one (``questionnaire``: ``URL-es|version``).
- **Answers**: LOINC answer codes where the YAML has them (else a local code per option); each
  option's points ride on the option with ``itemWeight`` and R4's ``ordinalValue`` (older
  readers), never on a code, since the same LOINC code scores differently on different items.
- **Status** says what happened: ``completed`` only when every item has an answer;
  ``in-progress`` for a session still running or finished with items unanswered (a clinician is
  expected to complete it), ``stopped`` for one abandoned or signed off incomplete; ``amended``
  once a clinician's corrections changed the kiosk's answers (signed off or still in review: the
  signature and the Observation's status tell which). The ``total`` item (LOINC 96761-2) has an answer
  only when the result is complete, and its calculatedExpression gives none otherwise.
- **Review**: a sign-off is the R4 ``questionnaireresponse-signature`` extension (a Verification
  Signature: who and when). ``author`` ("who recorded the answers") is the kiosk (a Device), or
  the clinician who last changed an answer; ``authored`` is when the answers last changed (the
  latest correction, else the end of the session).
- **Identity**: ``identifier`` ``SITE/KIOSK/SESSION`` in the site's system (stable, so re-exports
  never duplicate); the patient's pseudonym in the site's patient system (a logical reference:
  no Patient resource is made); the kiosk as a Device identified by its kiosk id.
- **Total Observation** (LOINC 96761-2, ``derivedFrom`` the response, ``device`` the kiosk, the
  band and its band set as ``interpretation``) only for a complete result: ``preliminary`` until
  signed off, then ``final`` (``amended`` with corrections, each correction as a ``note``).
- **Test data**: a session stored by ``kiosk replay`` (a scripted patient) is labelled ``HTEST``
  (``meta.security``, "test health data") on its response and total, so no EHR takes it for a
  patient's result.
- **Bundle** (transaction): the Questionnaires used and the kiosk Device are conditional creates
  (``ifNoneExist`` on url+version / identifier). Results not yet signed off are conditional creates
  on their identifier, so re-sending never duplicates and never overwrites; signed-off results are
  conditional updates (``PUT Type?identifier=…``), so the final version replaces the preliminary.
"""

from __future__ import annotations

import re
import uuid
from collections.abc import Mapping, Sequence
from datetime import datetime, timezone
from typing import Any
from urllib.parse import quote

from kiosk.export.result import (
    TOTAL_LINK,
    ExportError,
    ExportSite,
    Result,
    questionnaire_version,
    result,
    results,
)
from kiosk.questionnaire import Code, Questionnaire
from kiosk.review import Review, ReviewState
from kiosk.storage import StoredSession
from kiosk.visits import visit_of

ITEM_WEIGHT = "http://hl7.org/fhir/StructureDefinition/itemWeight"
ORDINAL_VALUE = "http://hl7.org/fhir/StructureDefinition/ordinalValue"
TRANSLATION = "http://hl7.org/fhir/StructureDefinition/translation"
SIGNATURE = "http://hl7.org/fhir/StructureDefinition/questionnaireresponse-signature"
CALCULATED = "http://hl7.org/fhir/uv/sdc/StructureDefinition/sdc-questionnaire-calculatedExpression"
#: ASTM E1762-95 "Verification Signature": the signer checked the content is complete and correct
VERIFICATION = {"system": "urn:iso-astm:E1762-95:2013", "code": "1.2.840.10065.1.12.1.5",
                "display": "Verification Signature"}
#: the security label of test data: a scripted patient's session (``kiosk replay``) is no patient's result
TEST_DATA = {"system": "http://terminology.hl7.org/CodeSystem/v3-ActReason", "code": "HTEST",
             "display": "test health data"}
SURVEY = {"system": "http://terminology.hl7.org/CodeSystem/observation-category", "code": "survey",
          "display": "Survey"}
TOTAL_TEXT = {"en": "Total score", "es": "Puntuación total", "fr": "Score total"}


def instant(value: str) -> str:
    """An ISO-8601 time as a FHIR instant (seconds and a zone; UTC when the value has none)."""
    try:
        moment = datetime.fromisoformat(value.replace("Z", "+00:00"))
    except ValueError:
        raise ExportError(f"{value!r} is not an ISO-8601 date and time") from None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=timezone.utc)
    return moment.isoformat(timespec="milliseconds" if moment.microsecond else "seconds")


def questionnaire_canonical(q: Questionnaire, site: ExportSite, language: str) -> str:
    """The canonical URL of the questionnaire in one language (without the version)."""
    return f"{site.questionnaire_url or f'urn:barthel-kiosk:{site.site}:questionnaire:{q.id}'}-{language}"


def _text(key: str, texts: Mapping[str, str], language: str) -> dict[str, Any]:
    """``{key: text in language, _key: the other languages}`` (FHIR translation extension; no
    ``_key`` for a text in one language only, as FHIR JSON has no empty arrays)."""
    others = [{"url": TRANSLATION, "extension": [{"url": "lang", "valueCode": lang},
                                                 {"url": "content", "valueString": text}]}
              for lang, text in texts.items() if lang != language]
    return {key: texts[language]} | ({f"_{key}": {"extension": others}} if others else {})


def _coding(code: Code, display: str | None = None) -> dict[str, str]:
    return {"system": code.system, "code": code.code} | ({"display": display} if display else {})


def _option_coding(q: Questionnaire, item_id: str, number: int, language: str) -> dict[str, Any]:
    option = q.item(item_id).option(number)
    code = option.code or Code(f"urn:barthel-kiosk:option:{q.id}:{item_id}", str(number))
    return _coding(code, option.label_in(language))


def _total_expression(q: Questionnaire) -> str:
    """The total as FHIRPath: the sum of the answers' weights, and nothing while an item is unanswered."""
    answered = f"%resource.item.where(linkId != '{TOTAL_LINK}' and answer.exists())"
    return (f"iif({answered}.count() = {len(q.items)}, "
            f"{answered}.answer.value.weight().sum(), {{}})")


def _computable_name(title: str) -> str:
    """A title as R4 wants a computable name (invariant que-0): letters and digits, a capital first."""
    name = "".join(word[:1].upper() + word[1:] for word in re.findall(r"[A-Za-z0-9]+", title)).lstrip("0123456789")
    return name or "Questionnaire"


def fhir_questionnaire(q: Questionnaire, language: str = "en", site: ExportSite | None = None) -> dict[str, Any]:
    """The questionnaire in ``language`` as an R4 Questionnaire (other languages as translations)."""
    if language not in q.languages:
        raise ExportError(f"{q.id} has no language {language!r} (it has {', '.join(q.languages)})")
    site = site or ExportSite()
    items = []
    for item in q.items:
        entry: dict[str, Any] = {"linkId": item.id, **_text("text", item.text, language), "type": "choice",
                                 "required": True}
        if item.code:
            entry["code"] = [_coding(item.code)]
        entry["answerOption"] = [
            {"extension": [{"url": ITEM_WEIGHT, "valueDecimal": option.points},
                           {"url": ORDINAL_VALUE, "valueDecimal": option.points}],
             "valueCoding": _option_coding(q, item.id, option.number, language)
             | _text("display", option.label, language)}
            for option in item.options
        ]
        items.append(entry)
    total: dict[str, Any] = {
        "extension": [{"url": CALCULATED, "valueExpression": {"language": "text/fhirpath",
                                                               "expression": _total_expression(q)}}],
        "linkId": TOTAL_LINK,
        **_text("text", {lang: TOTAL_TEXT.get(lang, TOTAL_TEXT["en"]) for lang in q.languages}, language),
        "type": "integer", "readOnly": True,
    }
    if q.total_code:
        total["code"] = [_coding(q.total_code)]
    items.append(total)
    resource: dict[str, Any] = {
        "resourceType": "Questionnaire", "id": f"{q.id}-{language}", "language": language,
        "url": questionnaire_canonical(q, site, language), "version": questionnaire_version(q),
        "name": _computable_name(q.title["en"]) + language.upper(),
        **_text("title", q.title, language),
        "status": "active", "subjectType": ["Patient"], "item": items,
    }
    if q.code:
        resource["code"] = [_coding(q.code)]
    return resource


def response_status(r: Result) -> str:
    """The QuestionnaireResponse status of a result (see the module docstring)."""
    if r.complete:
        return "amended" if r.amended or r.changers else "completed"
    return "stopped" if r.stored.status == "abandoned" or r.final else "in-progress"


def device_reference(site: ExportSite) -> dict[str, Any]:
    """The kiosk as a logical Device reference (its kiosk id in the site's device system)."""
    return {"type": "Device", "identifier": {"system": site.device_system, "value": site.kiosk_id},
            "display": f"Barthel kiosk {site.kiosk_id}"}


def fhir_device(site: ExportSite) -> dict[str, Any]:
    """The kiosk as an R4 Device resource."""
    return {"resourceType": "Device", "identifier": [{"system": site.device_system, "value": site.kiosk_id}],
            "status": "active", "deviceName": [{"name": f"Barthel kiosk {site.kiosk_id}", "type": "user-friendly-name"}]}


def _patient(site: ExportSite, stored: StoredSession) -> dict[str, Any]:
    return {"type": "Patient", "identifier": {"system": site.patient_system, "value": stored.patient_id}}


def _clinician(name: str) -> dict[str, Any]:
    return {"type": "Practitioner", "display": name}


def _authored(r: Result) -> str:
    changes = [c.at for c in r.review.corrections]
    return instant(max(changes, key=instant) if changes else r.stored.finished_at or r.stored.started_at)


def fhir_response(q: Questionnaire, stored: StoredSession, review: Review | None = None,
                  site: ExportSite | None = None) -> dict[str, Any]:
    """A stored session (with its clinician's review, if any) as an R4 QuestionnaireResponse."""
    return _response(q, result(q, stored, review), site or ExportSite())


def _response(q: Questionnaire, r: Result, site: ExportSite) -> dict[str, Any]:
    stored, language = r.stored, r.stored.language
    items = []
    for item in q.items:
        entry: dict[str, Any] = {"linkId": item.id, "text": item.text[language]}
        if item.id in r.options:
            entry["answer"] = [{"valueCoding": _option_coding(q, item.id, r.options[item.id], language)}]
        items.append(entry)
    total: dict[str, Any] = {"linkId": TOTAL_LINK, "text": TOTAL_TEXT.get(language, TOTAL_TEXT["en"])}
    if r.complete:
        total["answer"] = [{"valueInteger": r.score.total}]
    items.append(total)
    resource: dict[str, Any] = {
        "resourceType": "QuestionnaireResponse", "id": stored.id, "language": language,
        "identifier": {"system": site.identifier_system, "value": site.result_id(stored.id)},
        "questionnaire": f"{questionnaire_canonical(q, site, language)}|{questionnaire_version(q)}",
        "status": response_status(r), "subject": _patient(site, stored), "authored": _authored(r),
        "author": _clinician(r.changers[-1]) if r.changers else device_reference(site),
        "source": _patient(site, stored) if stored.answered_by.value == "patient"
        else {"type": "RelatedPerson", "display": stored.answered_by.value},
        "item": items,
    }
    if r.final:
        resource["extension"] = [_signature(r.review)]
    return _labelled(resource, stored)


#: how the visit began (kiosk.visits), as a meta tag: "order", "staff" or "walk-up"
VISIT_SYSTEM = "urn:barthel-kiosk:visit"


def _labelled(resource: dict[str, Any], stored: StoredSession) -> dict[str, Any]:
    meta: dict[str, Any] = {}
    if stored.simulated:
        meta["security"] = [TEST_DATA]
    visit = visit_of(stored.log)
    if visit:
        meta["tag"] = [{"system": VISIT_SYSTEM, "code": visit.split(" ", 1)[0], "display": visit}]
    if meta:
        resource["meta"] = meta
    return resource


def _signature(review: Review) -> dict[str, Any]:
    if not review.signed_by or not review.signed_at:
        raise ExportError(f"a review in state {ReviewState(review.state).value} needs who signed it off and when")
    return {"url": SIGNATURE, "valueSignature": {"type": [VERIFICATION], "when": instant(review.signed_at),
                                                 "who": _clinician(review.signed_by)}}


def observation_status(r: Result) -> str:
    """``preliminary`` until a clinician signs off; then ``final``, or ``amended`` with corrections."""
    return ("amended" if r.amended else "final") if r.final else "preliminary"


def fhir_total(q: Questionnaire, stored: StoredSession, review: Review | None = None,
               site: ExportSite | None = None) -> dict[str, Any] | None:
    """The total as an R4 Observation (LOINC 96761-2) derived from the response; None when the
    result is incomplete, so a partial sum is never charted as a Barthel total."""
    site = site or ExportSite()
    response = {"type": "QuestionnaireResponse",
                "identifier": {"system": site.identifier_system, "value": site.result_id(stored.id)}}
    return _total(q, result(q, stored, review), site, response)


def _total(q: Questionnaire, r: Result, site: ExportSite, response: dict[str, Any]) -> dict[str, Any] | None:
    if not r.complete or q.total_code is None:
        return None
    stored, language = r.stored, r.stored.language
    observation: dict[str, Any] = {
        "resourceType": "Observation", "language": language,
        "identifier": [{"system": site.identifier_system, "value": site.result_id(stored.id) + "/total"}],
        "status": observation_status(r), "category": [{"coding": [SURVEY]}],
        "code": {"coding": [_coding(q.total_code)], "text": f"{q.title[language]}: {TOTAL_TEXT.get(language, 'Total')}"},
        "subject": _patient(site, stored), "effectiveDateTime": instant(stored.finished_at or stored.started_at),
        "device": device_reference(site), "derivedFrom": [response],
        "valueQuantity": {"value": r.score.total, "unit": "{score}", "system": "http://unitsofmeasure.org",
                          "code": "{score}"},
    }
    band_set = q.bands_named(r.score.band_set)
    if r.score.band is not None:
        observation["interpretation"] = [{
            "coding": [{"system": f"urn:barthel-kiosk:band-set:{band_set.id}", "code": r.score.band.id,
                        "display": r.score.band.label["en"]}],
            "text": f"{r.score.band.label[language]} ({band_set.id}: {band_set.source})"}]
    if r.final:
        observation["issued"] = instant(r.review.signed_at or "")
        observation["performer"] = [_clinician(r.review.signed_by or "")]
    notes = [{"authorString": c.author, "time": instant(c.at),
              "text": f"{c.item_id}: option {c.previous_option or 'none'} -> {c.option} ({c.reason})"}
             for c in r.review.corrections]
    if notes:
        observation["note"] = notes
    return _labelled(observation, stored)


def _full_url(system: str, value: str) -> str:
    return f"urn:uuid:{uuid.uuid5(uuid.NAMESPACE_URL, f'{system}|{value}')}"


def _query(**params: str) -> str:
    return "&".join(f"{name}={quote(value, safe='')}" for name, value in params.items())


def _entry(resource: dict[str, Any], full_url: str, condition: str, update: bool) -> dict[str, Any]:
    kind = resource["resourceType"]
    request = ({"method": "PUT", "url": f"{kind}?{condition}"} if update
               else {"method": "POST", "url": kind, "ifNoneExist": condition})
    return {"fullUrl": full_url, "resource": {k: v for k, v in resource.items() if k != "id"}, "request": request}


def transaction_bundle(q: Questionnaire, sessions: Sequence[StoredSession], reviews: Sequence[Review] | None = None,
                       site: ExportSite | None = None) -> dict[str, Any]:
    """Sessions with their reviews (same order; None: unreviewed) as one R4 transaction Bundle with
    the Questionnaires they answer and the kiosk Device (see the module docstring for the
    conditional requests)."""
    site = site or ExportSite()
    reviewed = results(q, sessions, reviews)
    version = questionnaire_version(q)
    entries = []
    for language in dict.fromkeys(r.stored.language for r in reviewed):
        url = questionnaire_canonical(q, site, language)
        entries.append(_entry(fhir_questionnaire(q, language, site), _full_url(url, version),
                              _query(url=url, version=version), update=False))
    device_url = _full_url(site.device_system, site.kiosk_id)
    if reviewed:
        entries.append(_entry(fhir_device(site), device_url,
                              _query(identifier=f"{site.device_system}|{site.kiosk_id}"), update=False))
    for r in reviewed:
        response = _response(q, r, site)
        response["author"] = response["author"] | ({"reference": device_url} if response["author"]["type"] == "Device"
                                                   else {})
        value = site.result_id(r.stored.id)
        response_url = _full_url(site.identifier_system, value)
        entries.append(_entry(response, response_url, _query(identifier=f"{site.identifier_system}|{value}"),
                              update=r.final))
        total = _total(q, r, site, {"reference": response_url, "type": "QuestionnaireResponse",
                                    "identifier": response["identifier"]})
        if total is not None:
            total["device"] |= {"reference": device_url}
            entries.append(_entry(total, _full_url(site.identifier_system, value + "/total"),
                                  _query(identifier=f"{site.identifier_system}|{value}/total"), update=r.final))
    # FHIR JSON has no empty arrays: a Bundle of nothing has no entry at all
    return {"resourceType": "Bundle", "type": "transaction"} | ({"entry": entries} if entries else {})


def questionnaire_bundle(q: Questionnaire, site: ExportSite | None = None) -> dict[str, Any]:
    """The questionnaire in every language as a transaction Bundle of conditional creates."""
    site = site or ExportSite()
    version = questionnaire_version(q)
    return {"resourceType": "Bundle", "type": "transaction", "entry": [
        _entry(fhir_questionnaire(q, language, site), _full_url(questionnaire_canonical(q, site, language), version),
               _query(url=questionnaire_canonical(q, site, language), version=version), update=False)
        for language in q.languages]}

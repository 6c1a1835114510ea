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
- **Codes and words**: a ``Coding.display`` is the code system's display for the code (the
  ``display`` the YAML gives each LOINC code, LOINC's English display; one code, one display in
  every Questionnaire and response), never our wording. The words the kiosk used travel beside it
  in the extension :data:`WORDING` (``urn:barthel-kiosk:fhir:StructureDefinition:wording``, a
  complex extension in the resource's language with ``clinical`` (the clinicians' text or label),
  ``patient`` (what the patient's screen showed) and ``spoken`` (what the kiosk said, questions
  only) as ``valueString`` sub-extensions): on each Questionnaire item and ``answerOption``, and
  on each response item (the question) and answer (the option). A local code without a display
  takes the option's label as display, with the other languages as ``translation`` extensions.
- **Status** says what happened: ``completed`` only when every item has an answer;
  ``in-progress`` for a session still running or finished with items unanswered (a clinician is
  expected to complete it), ``stopped`` for one abandoned or signed off incomplete; ``amended``
  once a clinician's corrections changed the kiosk's answers (signed off or still in review: the
  signature and the Observation's status tell which). Where a result stands comes from one
  function, :func:`kiosk.core.review.review_state`, which the CSV's ``review_state`` also states.
  As SDC does, an unanswered item is left out of the response, and the ``total`` item (LOINC
  96761-2) is there only when the result is complete (its calculatedExpression gives none otherwise).
- **Review**: a sign-off is the R4 ``questionnaireresponse-signature`` extension (a Verification
  Signature: when, and who as a Practitioner reference carrying the staff account's name as its
  identifier in the station's staff system, :attr:`kiosk.core.review.Review.staff_system`). ``author``
  ("who recorded the answers") stays the kiosk (a Device), which recorded every answer nobody
  changed; each change is a Provenance (:mod:`kiosk.export.provenance`: who, when, why, and the
  answer it replaced with that answer's author). ``authored`` is when the answers last changed
  (the latest correction, else the end of the session).
- **Identity**: ``identifier`` ``SITE/KIOSK/SESSION`` in the site's system (stable, so re-exports
  never duplicate); the patient's pseudonym in the site's patient system (a logical reference:
  no Patient resource is made); the kiosk as a Device identified by its kiosk id. Every function
  takes the questionnaire and the identity (:class:`ExportSite`) it is given: it reads no file
  and no configuration.
- **Total Observation** (LOINC 96761-2, ``derivedFrom`` the response, ``device`` the kiosk, the
  band and its band set as ``interpretation``) for every complete result (an instrument with no
  standard total code is coded in the site's own system, :func:`site_total_code`): ``preliminary``
  until signed off, then ``final`` (``amended`` with corrections, each correction as a ``note``).
- **Test data**: a session stored by ``kiosk replay`` (a scripted patient) is labelled ``HTEST``
  (``meta.security``, "test health data") on its response and total, so no EHR takes it for a
  patient's result.
- **Format v2** (:mod:`kiosk.export.calculated`): the total item's ``calculatedExpression`` is
  the instrument's FHIRPath formula when it has one; subscales are calculated items and
  components of the total Observation; staff items carry the ``answered-by`` extension, and a
  number staff enter is an ``integer``/``decimal`` item with its range and unit.
- **Bundle** (transaction, :mod:`kiosk.export.bundle`): the Questionnaires used and the kiosk
  Device are conditional creates (``ifNoneExist`` on url+version / identifier). Results not yet
  signed off are conditional creates on their identifier, so re-sending never duplicates and never
  overwrites; signed-off results are conditional updates (``PUT Type?identifier=…``), so the final
  version replaces the preliminary, and an amended one replaces the final (a new version each time).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from datetime import UTC, datetime
from typing import Any

from kiosk.core.answerers import answerer_of
from kiosk.core.questionnaire import Code, Questionnaire
from kiosk.core.review import Review, ReviewState
from kiosk.core.site import ExportSite
from kiosk.core.visits import visit_of
from kiosk.core.words import Table
from kiosk.export.calculated import (
    calculated,
    entry_answer,
    entry_fields,
    staff_mark,
    subscale_code,
    subscale_expression,
    subscale_items,
    total_expression,
)
from kiosk.export.result import (
    TOTAL_LINK,
    ExportError,
    Result,
    questionnaire_version,
    result,
)
from kiosk.store.database import StoredSession

ITEM_WEIGHT = "http://hl7.org/fhir/StructureDefinition/itemWeight"
ORDINAL_VALUE = "http://hl7.org/fhir/StructureDefinition/ordinalValue"
TRANSLATION = "http://hl7.org/fhir/StructureDefinition/translation"
SIGNATURE = "http://hl7.org/fhir/StructureDefinition/questionnaireresponse-signature"
#: ASTM E1762-95 "Verification Signature": the signer checked the content is complete and correct
VERIFICATION = {
    "system": "urn:iso-astm:E1762-95:2013",
    "code": "1.2.840.10065.1.12.1.5",
    "display": "Verification Signature",
}
#: the security label of test data: a scripted patient's session (``kiosk replay``) is no patient's result
TEST_DATA = {
    "system": "http://terminology.hl7.org/CodeSystem/v3-ActReason",
    "code": "HTEST",
    "display": "test health data",
}
SURVEY = {"system": "http://terminology.hl7.org/CodeSystem/observation-category", "code": "survey", "display": "Survey"}
#: the total's label per language (``export.total_score`` in its words file)
TOTAL_TEXT: Mapping[str, str] = Table(lambda words: words.export["total_score"])
#: why a result with unanswered items was signed off as incomplete (the doctor's words), on its response
INCOMPLETE = "urn:barthel-kiosk:fhir:StructureDefinition:incomplete-reason"
#: R4's reasons for a missing value: "unknown", with the doctor's reason as text
DATA_ABSENT = "http://terminology.hl7.org/CodeSystem/data-absent-reason"
#: the words the kiosk used beside a code (see the module docstring): ``clinical``, ``patient``, ``spoken``
WORDING = "urn:barthel-kiosk:fhir:StructureDefinition:wording"


def instant(value: str) -> str:
    """An ISO-8601 time as a FHIR instant (seconds and a zone; UTC when the value has none)."""
    try:
        moment = datetime.fromisoformat(value.replace("Z", "+00:00"))
    except ValueError:
        raise ExportError(f"{value!r} is not an ISO-8601 date and time") from None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=UTC)
    return moment.isoformat(timespec="milliseconds" if moment.microsecond else "seconds")


def questionnaire_canonical(q: Questionnaire, site: ExportSite, language: str) -> str:
    """The canonical URL of the questionnaire in one language (without the version). A site's
    ``questionnaire_url`` with ``{id}`` in it gives each instrument of a battery its own URL
    (``.../Questionnaire/{id}``); one without names a single instrument, as it always did."""
    base = site.questionnaire_url.replace("{id}", q.id) if site.questionnaire_url else ""
    return f"{base or f'urn:barthel-kiosk:{site.site}:questionnaire:{q.id}'}-{language}"


def _text(key: str, texts: Mapping[str, str], language: str) -> dict[str, Any]:
    """``{key: text in language, _key: the other languages}`` (FHIR translation extension; no
    ``_key`` for a text in one language only, as FHIR JSON has no empty arrays)."""
    others = [
        {"url": TRANSLATION, "extension": [{"url": "lang", "valueCode": lang}, {"url": "content", "valueString": text}]}
        for lang, text in texts.items()
        if lang != language
    ]
    return {key: texts[language]} | ({f"_{key}": {"extension": others}} if others else {})


def code_coding(code: Code, display: str | None = None) -> dict[str, str]:
    shown = code.display or display
    return {"system": code.system, "code": code.code} | ({"display": shown} if shown else {})


def option_coding(q: Questionnaire, item_id: str, number: int, language: str) -> dict[str, Any]:
    """An option's Coding: the code system's display for its code; a local code (no published
    one) shows the option's label, with the other languages as translations."""
    option = q.item(item_id).option(number)
    if option.code is not None and option.code.display:
        return code_coding(option.code)
    code = option.code or Code(f"urn:barthel-kiosk:option:{q.id}:{item_id}", str(number))
    return {"system": code.system, "code": code.code} | _text("display", option.label, language)


def wording(
    language: str,
    *,
    clinical: Mapping[str, str],
    patient: Mapping[str, str] | None = None,
    spoken: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """The :data:`WORDING` extension: the words in ``language`` (patient's wording defaults to
    the clinical one, as on the kiosk's screen; ``spoken`` only where given)."""
    parts = [("clinical", clinical[language]), ("patient", (patient or {}).get(language) or clinical[language])]
    if spoken and spoken.get(language):
        parts.append(("spoken", spoken[language]))
    return {"url": WORDING, "extension": [{"url": name, "valueString": text} for name, text in parts]}


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
        entry: dict[str, Any] = {
            "extension": [
                wording(language, clinical=item.text, patient=item.patient, spoken=item.spoken),
                *staff_mark(item),
            ],
            "linkId": item.id,
            **_text("text", item.text, language),
            "type": "choice",
            "required": True,
        }
        if item.code:
            entry["code"] = [code_coding(item.code)]
        if item.entry is not None:
            fields = entry_fields(item)
            entry |= {"type": fields["type"], "extension": entry["extension"] + fields["extension"]}
            items.append(entry)
            continue
        entry["answerOption"] = [
            {
                "extension": [
                    {"url": ITEM_WEIGHT, "valueDecimal": option.points},
                    {"url": ORDINAL_VALUE, "valueDecimal": option.points},
                    wording(language, clinical=option.label, patient=option.patient),
                ],
                "valueCoding": option_coding(q, item.id, option.number, language),
            }
            for option in item.options
        ]
        items.append(entry)
    for subscale in q.subscales:
        items.append(
            {
                "extension": [calculated(subscale_expression(subscale))],
                "linkId": subscale.id,
                **_text("text", subscale.label, language),
                "code": [subscale_code(q, subscale)],
                "type": "integer",
                "readOnly": True,
            }
        )
    total: dict[str, Any] = {
        "extension": [calculated(total_expression(q))],
        "linkId": TOTAL_LINK,
        **_text("text", {lang: TOTAL_TEXT.get(lang, TOTAL_TEXT["en"]) for lang in q.languages}, language),
        "type": "integer",
        "readOnly": True,
    }
    if q.total_code:
        total["code"] = [code_coding(q.total_code)]
    items.append(total)
    resource: dict[str, Any] = {
        "resourceType": "Questionnaire",
        "id": f"{q.id}-{language}",
        "language": language,
        "url": questionnaire_canonical(q, site, language),
        "version": questionnaire_version(q),
        "name": _computable_name(q.title["en"]) + language.upper(),
        **_text("title", q.title, language),
        "status": "active",
        "subjectType": ["Patient"],
        "item": items,
    }
    if q.code:
        resource["code"] = [code_coding(q.code)]
    return resource


def response_status(r: Result) -> str:
    """The QuestionnaireResponse status of a result (see the module docstring)."""
    if r.complete:
        return "amended" if r.changed else "completed"
    return "stopped" if r.stored.status == "abandoned" or r.final else "in-progress"


def device_reference(site: ExportSite) -> dict[str, Any]:
    """The kiosk as a logical Device reference (its kiosk id in the site's device system)."""
    return {
        "type": "Device",
        "identifier": {"system": site.device_system, "value": site.kiosk_id},
        "display": f"Barthel kiosk {site.kiosk_id}",
    }


def fhir_device(site: ExportSite) -> dict[str, Any]:
    """The kiosk as an R4 Device resource."""
    return {
        "resourceType": "Device",
        "identifier": [{"system": site.device_system, "value": site.kiosk_id}],
        "status": "active",
        "deviceName": [{"name": f"Barthel kiosk {site.kiosk_id}", "type": "user-friendly-name"}],
    }


def patient_reference(site: ExportSite, stored: StoredSession) -> dict[str, Any]:
    return {"type": "Patient", "identifier": {"system": site.patient_system, "value": stored.patient_id}}


def _related_person(site: ExportSite, stored: StoredSession) -> dict[str, Any]:
    """The person who answered for the patient (R4 RelatedPerson: ``patient`` is required; its
    ``relationship`` is the answerer the session logged, coded where the kiosk has a code)."""
    related: dict[str, Any] = {
        "resourceType": "RelatedPerson",
        "id": "answerer",
        "patient": patient_reference(site, stored),
    }
    who = answerer_of(stored.log)
    if who is not None:
        code = who.code
        coding = [{"system": code.system, "code": code.code, "display": code.display}] if code else []
        related["relationship"] = [{"coding": coding, "text": who.display} if coding else {"text": who.display}]
    return related


def practitioner(name: str, staff_system: str) -> dict[str, Any]:
    """A staff account as a logical Practitioner reference: its name as identifier in the
    station's staff system (and as display)."""
    return {"type": "Practitioner", "identifier": {"system": staff_system, "value": name}, "display": name}


def _authored(r: Result) -> str:
    changes = [c.at for c in r.review.corrections]
    return instant(max(changes, key=instant) if changes else r.stored.finished_at or r.stored.started_at)


def fhir_response(
    q: Questionnaire,
    stored: StoredSession,
    review: Review | None = None,
    site: ExportSite | None = None,
    values: Mapping[str, float] | None = None,
) -> dict[str, Any]:
    """A stored session (with its clinician's review, if any, and the numbers staff entered for
    its ``input`` items, ``values``) as an R4 QuestionnaireResponse."""
    return response_of(q, result(q, stored, review, values), site or ExportSite())


def response_of(q: Questionnaire, r: Result, site: ExportSite) -> dict[str, Any]:
    """A :class:`Result` as an R4 QuestionnaireResponse (what :func:`fhir_response` and Bundles say)."""
    stored, language = r.stored, r.stored.language
    changed = {c.item_id for c in r.review.corrections}
    items = []
    for item in q.items:
        if item.entry is not None and item.id in r.values:
            items.append(
                {
                    "extension": [wording(language, clinical=item.text, patient=item.patient, spoken=item.spoken)],
                    "linkId": item.id,
                    "text": item.text[language],
                    "answer": [entry_answer(item, r.values[item.id])],
                }
            )
        if item.id not in r.options:
            continue  # unanswered (or a number, above): left out, as SDC does
        option = item.option(r.options[item.id])
        entry: dict[str, Any] = {"id": item.id} if item.id in changed else {}  # a Provenance's targetElement
        entry |= {
            "extension": [wording(language, clinical=item.text, patient=item.patient, spoken=item.spoken)],
            "linkId": item.id,
            "text": item.text[language],
            "answer": [
                {
                    "extension": [wording(language, clinical=option.label, patient=option.patient)],
                    "valueCoding": option_coding(q, item.id, option.number, language),
                }
            ],
        }
        items.append(entry)
    items += subscale_items(q, r, language)
    if r.complete:
        items.append(
            {
                "linkId": TOTAL_LINK,
                "text": TOTAL_TEXT.get(language, TOTAL_TEXT["en"]),
                "answer": [{"valueInteger": r.score.total}],
            }
        )
    resource: dict[str, Any] = {
        "resourceType": "QuestionnaireResponse",
        "id": stored.id,
        "language": language,
        "identifier": {"system": site.identifier_system, "value": site.result_id(stored.id)},
        "questionnaire": f"{questionnaire_canonical(q, site, language)}|{questionnaire_version(q)}",
        "status": response_status(r),
        "subject": patient_reference(site, stored),
        "authored": _authored(r),
        "author": device_reference(site),
        "source": patient_reference(site, stored),
    }
    if stored.answered_by.value != "patient":  # who answered, and how they are related, as a contained RelatedPerson
        resource["contained"] = [_related_person(site, stored)]
        resource["source"] = {"reference": "#answerer", "type": "RelatedPerson", "display": stored.answered_by.value}
    if items:  # FHIR JSON has no empty arrays
        resource["item"] = items
    if r.final:
        resource["extension"] = [_signature(r.review)]
        if not r.complete:
            resource["extension"].append({"url": INCOMPLETE, "valueString": r.incomplete_words})
    return labelled(resource, stored)


#: how the visit began (kiosk.core.visits), as a meta tag: "order", "staff" or "walk-up"
VISIT_SYSTEM = "urn:barthel-kiosk:visit"


def labelled(resource: dict[str, Any], stored: StoredSession) -> dict[str, Any]:
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
    return {
        "url": SIGNATURE,
        "valueSignature": {
            "type": [VERIFICATION],
            "when": instant(review.signed_at),
            "who": practitioner(review.signed_by, review.staff_system),
        },
    }

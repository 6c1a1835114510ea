"""Who changed a result, when, why, and what it said before: one R4 Provenance per change.

Each staff correction (or filled item) of a result is a Provenance:

- ``target``: the QuestionnaireResponse, with R4's ``targetElement`` extension naming the item
  (the response item's ``id`` is its linkId);
- ``recorded``: when; ``reason``: the clinician's words (``CodeableConcept.text``);
  ``activity``: v3-DataOperation ``UPDATE`` (``CREATE`` for an item the kiosk left unanswered);
- ``agent``: the staff account as a Practitioner reference carrying its identifier in the
  station's staff system (:func:`kiosk.export.fhir.practitioner`), type ``author``;
- ``entity`` (role ``revision``, only when the item had an answer): the answer it replaced, in
  ``what.display`` for people ("feeding as recorded by the kiosk: LA31630-9 …, 5 points") and in
  the extension :data:`REPLACED_ANSWER` (``valueCoding``, the Coding the response had) for
  machines; its ``entity.agent`` is who gave that answer: the kiosk Device for the kiosk's own
  answer, so the Device stays the author of the answers it recorded, item by item.

A doctor reopening a signed result to amend it is a Provenance too (reason: theirs; entity: the
signed version it set aside). Provenance has no business identifier in R4, so each has a stable
id (a UUID from the result's identifier and the change's place in the trail) and is sent as an
update-as-create (``PUT Provenance/<id>``): re-sending a Bundle never duplicates one.
"""

from __future__ import annotations

import uuid
from typing import Any

from kiosk.core.questionnaire import Questionnaire
from kiosk.core.site import ExportSite
from kiosk.export.fhir import device_reference, instant, option_coding, practitioner
from kiosk.export.result import Result

#: the answer a change replaced, as the response's Coding had it (on ``Provenance.entity``)
REPLACED_ANSWER = "urn:barthel-kiosk:fhir:StructureDefinition:replaced-answer"
#: R4's extension naming the element of the target a Provenance is about
TARGET_ELEMENT = "http://hl7.org/fhir/StructureDefinition/targetElement"
DATA_OPERATION = "http://terminology.hl7.org/CodeSystem/v3-DataOperation"
AUTHOR = {
    "coding": [
        {
            "system": "http://terminology.hl7.org/CodeSystem/provenance-participant-type",
            "code": "author",
            "display": "Author",
        }
    ]
}


def provenance_id(site: ExportSite, r: Result, n: int) -> str:
    """The stable id of the ``n``-th change of a result (the same in every export)."""
    return str(uuid.uuid5(uuid.NAMESPACE_URL, f"{site.identifier_system}|{site.result_id(r.stored.id)}/change/{n}"))


def _replaced(
    q: Questionnaire, r: Result, item_id: str, option: int, device: dict[str, Any], author: str | None
) -> dict[str, Any]:
    """The answer a change replaced, and who gave it (``author`` None: the kiosk ``device``)."""
    language = r.stored.language
    choice = q.item(item_id).option(option)
    coding = option_coding(q, item_id, option, language)
    what = (
        f"{item_id} as recorded by {author or 'the kiosk'}: option {option} {choice.label_in(language)!r} "
        f"({coding['code']}, {choice.points} points)"
    )
    return {
        "extension": [{"url": REPLACED_ANSWER, "valueCoding": coding}],
        "role": "revision",
        "what": {"display": what},
        "agent": [{"who": practitioner(author, r.review.staff_system) if author else device}],
    }


def fhir_provenances(
    q: Questionnaire, r: Result, site: ExportSite, response: dict[str, Any], device: dict[str, Any] | None = None
) -> list[dict[str, Any]]:
    """One Provenance per change of ``r`` (corrections and reopenings, in the order they
    happened), targeting ``response`` (a Reference) and naming ``device`` (default: the kiosk as
    a logical reference) as the author of the kiosk's answers."""
    device = device or device_reference(site)
    staff = r.review.staff_system
    events: list[tuple[str, dict[str, Any]]] = []
    authors: dict[str, str] = {}  # item -> who last changed it (absent: its answer is the kiosk's)
    for c in r.review.corrections:
        kiosk_answer = c.item_id not in authors  # no earlier change: the answer replaced is the kiosk's
        resource: dict[str, Any] = {
            "resourceType": "Provenance",
            "target": [response | {"extension": [{"url": TARGET_ELEMENT, "valueUri": c.item_id}]}],
            "recorded": instant(c.at),
            "reason": [{"text": c.reason}],
            "activity": {
                "coding": [
                    {"system": DATA_OPERATION, "code": "CREATE", "display": "create"}
                    if c.previous_option is None
                    else {"system": DATA_OPERATION, "code": "UPDATE", "display": "revise"}
                ]
            },
            "agent": [{"type": AUTHOR, "who": practitioner(c.author, staff)}],
        }
        if c.previous_option is not None:
            resource["entity"] = [
                _replaced(q, r, c.item_id, c.previous_option, device, None if kiosk_answer else authors[c.item_id])
            ]
        authors[c.item_id] = c.author
        events.append((c.at, resource))
    for reopening in r.review.reopenings:
        events.append(
            (
                reopening.at,
                {
                    "resourceType": "Provenance",
                    "target": [response],
                    "recorded": instant(reopening.at),
                    "reason": [{"text": reopening.reason}],
                    "activity": {
                        "coding": [{"system": DATA_OPERATION, "code": "UPDATE", "display": "revise"}],
                        "text": "reopened a signed-off result to amend it",
                    },
                    "agent": [{"type": AUTHOR, "who": practitioner(reopening.author, staff)}],
                    "entity": [
                        {
                            "role": "revision",
                            "what": {
                                "display": f"the result as signed off by {reopening.signed_by} at {reopening.signed_at}"
                            },
                            "agent": [{"who": practitioner(reopening.signed_by, staff)}],
                        }
                    ],
                },
            )
        )
    events.sort(key=lambda event: instant(event[0]))  # stable: a correction before a reopening at one instant
    return [resource | {"id": provenance_id(site, r, n)} for n, (_, resource) in enumerate(events)]

"""Who answers an instrument and how they are related to the patient.

An instrument says who answers it (``answered_by:`` in its file: patient, caregiver or staff). A
caregiver instrument (the Zarit burden interview) is about the patient but answered by the person
who looks after them, so a walk-up patient never starts one: it runs only in a visit ordered from
the station or started by staff (:func:`walk_up_instruments`). When someone other than the patient
answers, how they are related to the patient is recorded in the session's log (an ``answerer``
entry, :class:`Answerer`) and exported (FHIR RelatedPerson, CSV).

The codes: HL7 v3 RoleCode (the value set FHIR R4's RelatedPerson.relationship binds to) where it
has one; "paid carer" has none we could confirm, so it keeps a local code. Verify before shipping.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from basis import record
from kiosk.core.questionnaire import PATIENT, Code, Questionnaire

#: HL7 v3 RoleCode (http://terminology.hl7.org/CodeSystem/v3-RoleCode), unverified: verify before shipping
ROLE_CODE = "http://terminology.hl7.org/CodeSystem/v3-RoleCode"
#: the kiosk's own codes where v3 RoleCode has none
LOCAL = "urn:barthel-kiosk:relationship"
#: the relationships staff choose from: name -> code ("other" is free text only)
RELATIONSHIPS: dict[str, Code | None] = {
    "spouse": Code(ROLE_CODE, "SPS", "spouse"),
    "daughter": Code(ROLE_CODE, "DAUC", "daughter"),
    "son": Code(ROLE_CODE, "SONC", "son"),
    "sibling": Code(ROLE_CODE, "SIB", "sibling"),
    "grandchild": Code(ROLE_CODE, "GRNDCHILD", "grandchild"),
    "friend": Code(ROLE_CODE, "FRND", "unrelated friend"),
    "neighbour": Code(ROLE_CODE, "NBOR", "neighbor"),
    "paid carer": Code(LOCAL, "paid-carer", "paid carer"),
    "other": None,
}
#: the longest free text kept about the relationship (it goes into exports; no names, please)
TEXT_MAX = 60
#: the log entry's kind
KIND = "answerer"


@record
class Answerer:
    """How the person answering is related to the patient: one of :data:`RELATIONSHIPS`, and
    free text (needed for "other")."""

    relationship: str
    text: str = ""

    @property
    def code(self) -> Code | None:
        return RELATIONSHIPS.get(self.relationship)

    @property
    def detail(self) -> str:
        """The log entry's detail: ``daughter`` or ``other: lodger``."""
        return f"{self.relationship}: {self.text}" if self.text else self.relationship

    @property
    def display(self) -> str:
        return self.text if self.relationship == "other" else self.detail


def answerer(relationship: object, text: object = "") -> Answerer:
    """An :class:`Answerer` from what staff or the station gave; ValueError (one sentence) otherwise."""
    if relationship not in RELATIONSHIPS:
        raise ValueError(f"relationship {relationship!r:.40} is not one of {', '.join(RELATIONSHIPS)}")
    if not isinstance(text, str) or len(text) > TEXT_MAX or any(ord(c) < 32 for c in text):
        raise ValueError(f"the relationship's text must be one line of at most {TEXT_MAX} characters")
    if relationship == "other" and not text.strip():
        raise ValueError('say how they are related to the patient (relationship "other" needs the text)')
    return Answerer(str(relationship), text.strip())


def answerer_of(log: Iterable[Any]) -> Answerer | None:
    """The answerer a stored session's log records (entries with ``kind`` and ``detail``), or None."""
    detail = next((entry.detail for entry in log if entry.kind == KIND), None)
    if detail is None:
        return None
    relationship, _, text = detail.partition(": ")
    return Answerer(relationship, text) if relationship in RELATIONSHIPS else Answerer("other", detail)


def walk_up_instruments(instruments: Sequence[Questionnaire]) -> tuple[str, ...]:
    """The ids of the instruments a walk-up patient may start: those the patient answers."""
    return tuple(q.id for q in instruments if q.answered_by == PATIENT)

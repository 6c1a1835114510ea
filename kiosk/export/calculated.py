"""What format v2 adds to the FHIR export: the total's and subscales' SDC ``calculatedExpression``,
staff items (a choice or a number with its range and unit), and the subscales' values.

One FHIRPath per computed item, so that LHC-Forms (or any SDC form filler) computes from the
exported Questionnaire the total the kiosk computed: the instrument's own formula when it has
one, else the sum of the chosen options' weights; both only once every item has an answer, as the
kiosk interprets only complete results. A subscale is the sum of its items' weights once they are
all answered.
"""

from __future__ import annotations

from typing import Any

from kiosk.core.questionnaire import Item, Questionnaire, Subscale
from kiosk.export.result import TOTAL_LINK, Result

CALCULATED = "http://hl7.org/fhir/uv/sdc/StructureDefinition/sdc-questionnaire-calculatedExpression"
MIN_VALUE = "http://hl7.org/fhir/StructureDefinition/minValue"
MAX_VALUE = "http://hl7.org/fhir/StructureDefinition/maxValue"
UNIT = "http://hl7.org/fhir/StructureDefinition/questionnaire-unit"
UCUM = "http://unitsofmeasure.org"
#: who answers an item, on items staff answer (``staff``): never shown to the patient
ANSWERED_BY = "urn:barthel-kiosk:fhir:StructureDefinition:answered-by"


def _quoted(text: str) -> str:
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def _answered(link_ids: list[str]) -> str:
    """The response's answered items among ``link_ids``."""
    either = " or ".join(f"linkId = {_quoted(i)}" for i in link_ids)
    return f"%resource.item.where(({either}) and answer.exists())"


def total_expression(q: Questionnaire) -> str:
    """The total as FHIRPath: the formula or the sum of the answers' weights, and nothing while an
    item is unanswered. (A v1 instrument keeps the expression it always had.)"""
    computed = [TOTAL_LINK, *(s.id for s in q.subscales)]
    if q.formula is None and not q.subscales and all(i.options for i in q.items):
        answered = f"%resource.item.where(linkId != '{TOTAL_LINK}' and answer.exists())"
        return f"iif({answered}.count() = {len(q.items)}, {answered}.answer.value.weight().sum(), {{}})"
    every = _answered([i.id for i in q.items if i.id not in computed])
    value = f"({q.formula.expression})" if q.formula else f"{_answered([i.id for i in q.items if i.options])}"
    if q.formula is None:
        value += ".answer.value.weight().sum()"
    if any(i.instead_of for i in q.items):
        return f"iif({_complete(q)}, {value}, {{}})"
    return f"iif({every}.count() = {len(q.items)}, {value}, {{}})"


def _complete(q: Questionnaire) -> str:
    """Every item answered, an item answered ``instead_of`` others counting for them (and they
    for it), as FHIRPath."""

    def has(item_id: str) -> str:
        return f"%resource.item.where(linkId = {_quoted(item_id)} and answer.exists()).exists()"

    covered = {other for i in q.items for other in i.instead_of}
    clauses = []
    for item in q.items:
        if item.instead_of:
            others = " and ".join(has(o) for o in item.instead_of)
            clauses.append(f"({has(item.id)} or ({others}))")
        elif item.id not in covered:
            clauses.append(has(item.id))
    return " and ".join(clauses)


def subscale_expression(subscale: Subscale) -> str:
    """A subscale as FHIRPath: its items' weights added up once they are all answered."""
    answered = _answered(list(subscale.items))
    return f"iif({answered}.count() = {len(subscale.items)}, {answered}.answer.value.weight().sum(), {{}})"


def calculated(expression: str) -> dict[str, Any]:
    """The SDC calculatedExpression extension holding ``expression``."""
    return {"url": CALCULATED, "valueExpression": {"language": "text/fhirpath", "expression": expression}}


def entry_fields(item: Item) -> dict[str, Any]:
    """A number staff enter, as Questionnaire item fields: its type, range and unit."""
    assert item.entry is not None
    kind = item.entry.type
    bound = "valueInteger" if kind == "integer" else "valueDecimal"

    def number(value: float) -> float | int:
        return int(value) if kind == "integer" else value

    extension: list[dict[str, Any]] = [
        {"url": MIN_VALUE, bound: number(item.entry.min)},
        {"url": MAX_VALUE, bound: number(item.entry.max)},
    ]
    if item.entry.unit:
        extension.append({"url": UNIT, "valueCoding": {"system": UCUM, "code": item.entry.unit}})
    return {"type": kind, "extension": extension}


def staff_mark(item: Item) -> list[dict[str, Any]]:
    """The :data:`ANSWERED_BY` extension for a staff item (none for the patient's)."""
    return [{"url": ANSWERED_BY, "valueCode": item.answered_by}] if item.staff else []


def entry_answer(item: Item, value: float) -> dict[str, Any]:
    """A number staff entered, as a QuestionnaireResponse answer."""
    assert item.entry is not None
    return {"valueInteger": int(value)} if item.entry.type == "integer" else {"valueDecimal": value}


def subscale_code(q: Questionnaire, subscale: Subscale) -> dict[str, str]:
    """The subscale's code: its published one, else the kiosk's own per instrument."""
    if subscale.code is not None:
        coding = {"system": subscale.code.system, "code": subscale.code.code}
        return coding | ({"display": subscale.code.display} if subscale.code.display else {})
    return {"system": f"urn:barthel-kiosk:subscale:{q.id}", "code": subscale.id, "display": subscale.label["en"]}


def subscale_items(q: Questionnaire, r: Result, language: str) -> list[dict[str, Any]]:
    """The subscales whose items are all answered, as QuestionnaireResponse items."""
    return [
        {"linkId": s.id, "text": s.label[language], "answer": [{"valueInteger": r.score.subscales[s.id]}]}
        for s in q.subscales
        if s.id in r.score.subscales
    ]


def subscale_components(q: Questionnaire, r: Result, language: str) -> list[dict[str, Any]]:
    """The subscales as Observation components of the total (those with a value)."""
    return [
        {
            "code": {"coding": [subscale_code(q, s)], "text": s.label[language]},
            "valueQuantity": {
                "value": r.score.subscales[s.id],
                "unit": "{score}",
                "system": UCUM,
                "code": "{score}",
            },
        }
        for s in q.subscales
        if s.id in r.score.subscales
    ]

"""Scoring an instrument: its total, subscales and band, from the answers.

The total is the sum of the chosen options' points unless the instrument declares a formula: a
FHIRPath expression over the answers as a FHIR QuestionnaireResponse, in the kiosk's bounded
subset of it (:mod:`.formula`, ``docs/formulas.md``). FHIRPath because it is what FHIR SDC's
``calculatedExpression`` holds, so the exported Questionnaire makes LHC-Forms compute the same
total from the same words. The response the formula sees is :func:`response_items`' (the items'
``linkId`` and answers: a ``valueCoding`` per chosen option, ``valueInteger``/``valueDecimal``
per number staff entered), and ``weight()``/``ordinal()`` give a chosen option's points, as in
SDC. Pure: no I/O, no clock.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import field
from decimal import Decimal
from typing import Any, Protocol

from basis import record
from basis.errors import KioskError
from kiosk.core.questionnaire.formula import ITEM_WEIGHT, EvaluationError, compute
from kiosk.core.questionnaire.parts import Band, BandSet, Code, Entry, Option


class ScoringError(KioskError, ValueError):
    """A total formula gave no whole number in its declared range for some answers."""


class ScoredItem(Protocol):
    """What scoring reads of an item (:class:`~kiosk.core.questionnaire.model.Item` has it)."""

    @property
    def id(self) -> str: ...
    @property
    def options(self) -> tuple[Option, ...]: ...
    @property
    def entry(self) -> Entry | None: ...
    @property
    def staff(self) -> bool: ...
    @property
    def instead_of(self) -> tuple[str, ...]: ...
    def option(self, number: int) -> Option: ...


class Questionnaire(Protocol):
    """What scoring reads of an instrument (:class:`~kiosk.core.questionnaire.model.Questionnaire`
    has it): stated here, so scoring needs nothing of the model's module."""

    @property
    def id(self) -> str: ...
    @property
    def items(self) -> tuple[ScoredItem, ...]: ...
    @property
    def formula(self) -> Formula | None: ...
    @property
    def subscales(self) -> tuple[Subscale, ...]: ...
    @property
    def min_total(self) -> int: ...
    @property
    def max_total(self) -> int: ...
    def item(self, item_id: str) -> ScoredItem: ...


@record
class Formula:
    """A total computed by a FHIRPath expression over the QuestionnaireResponse, whose results
    lie from ``min`` to ``max`` (the range its bands must cover)."""

    expression: str
    min: int
    max: int


@record
class Subscale:
    """A sum of some items' points reported beside the total (exported with ``code`` when given)."""

    id: str
    label: Mapping[str, str]
    #: item ids, in questionnaire order
    items: tuple[str, ...]
    code: Code | None = None


@record
class Score:
    """The result of scoring a set of answers."""

    #: the total: the formula's result when complete; otherwise (and for a sum) the sum of the
    #: points of the answered items so far
    total: int
    #: every item answered (the patient's and the staff's)
    complete: bool
    #: the band of ``total`` when complete, else None (an incomplete total is not interpreted)
    band: Band | None
    #: item ids answered, in questionnaire order
    answered: tuple[str, ...]
    #: item ids not answered, in questionnaire order (staff items included)
    missing: tuple[str, ...]
    #: the highest possible total
    max_total: int
    #: the id of the band set ``band`` comes from
    band_set: str = ""
    #: the lowest possible total
    min_total: int = 0
    #: subscale id -> its sum, for each subscale whose items are all answered
    subscales: Mapping[str, int] = field(default_factory=dict)
    #: staff items still unanswered: the result stays incomplete until staff answer them
    awaiting_staff: tuple[str, ...] = ()
    #: why a complete set of answers has no total: its formula failed on them (``complete`` is
    #: then False, and no total is reported rather than a wrong one)
    problem: str = ""


def local_code(questionnaire_id: str, item_id: str, number: int) -> tuple[str, str]:
    """(system, code) of an option without a published code: the kiosk's own, per item."""
    return f"urn:barthel-kiosk:option:{questionnaire_id}:{item_id}", str(number)


def answer_code(questionnaire_id: str, item_id: str, option: Option) -> tuple[str, str]:
    """(system, code) a chosen option is answered with: its published code, else a local one."""
    if option.code is not None:
        return option.code.system, option.code.code
    return local_code(questionnaire_id, item_id, option.number)


def response_items(q: Questionnaire, options: Mapping[str, int], values: Mapping[str, float]) -> list[dict[str, Any]]:
    """The answered items as QuestionnaireResponse items (questionnaire order; unanswered left
    out, as SDC does): what a formula sees, and the core of what the FHIR export says."""
    items = []
    for item in q.items:
        if item.id in options:
            system, code = answer_code(q.id, item.id, item.option(options[item.id]))
            items.append({"linkId": item.id, "answer": [{"valueCoding": {"system": system, "code": code}}]})
        elif item.id in values and item.entry is not None:
            value = values[item.id]
            answer = {"valueInteger": int(value)} if item.entry.type == "integer" else {"valueDecimal": value}
            items.append({"linkId": item.id, "answer": [answer]})
    return items


def with_weights(q: Questionnaire, response: Mapping[str, Any]) -> dict[str, Any]:
    """A copy of a QuestionnaireResponse whose chosen Codings carry their option's points
    (itemWeight), looked up in ``q`` by item and code: what SDC's ``weight()`` reads from the
    Questionnaire, so a response exported without them scores as the kiosk scored it."""
    copied = copy.deepcopy(dict(response))
    choice = {item.id: item for item in q.items if item.options}
    for entry in copied.get("item", ()):
        item = choice.get(str(entry.get("linkId"))) if isinstance(entry, dict) else None
        if item is None:
            continue
        for answer in entry.get("answer", ()):
            coding = answer.get("valueCoding") if isinstance(answer, dict) else None
            if not isinstance(coding, dict):
                continue
            key = (coding.get("system"), coding.get("code"))
            option = next((o for o in item.options if answer_code(q.id, item.id, o) == key), None)
            if option is not None and option.points is not None:
                coding["extension"] = [
                    *coding.get("extension", []),
                    {"url": ITEM_WEIGHT, "valueDecimal": option.points},
                ]
    return copied


def evaluate(q: Questionnaire, expression: str, response: Mapping[str, Any]) -> list[Any]:
    """``expression`` evaluated on a QuestionnaireResponse of ``q`` (``%resource`` is the response;
    ``weight()`` gives a chosen option's points). Numbers come back as int where whole."""
    return run(expression, with_weights(q, {"resourceType": "QuestionnaireResponse", **response}))


def run(expression: str, resource: Mapping[str, Any]) -> list[Any]:
    """``expression`` evaluated on a resource whose chosen Codings already carry their weights,
    by :func:`~kiosk.core.questionnaire.formula.compute` (bounded; EvaluationError says why not)."""
    return compute(expression, resource)


def formula_total(q: Questionnaire, formula: Formula, response: Mapping[str, Any]) -> int:
    """The formula's total on a response; ScoringError unless it is one whole number from
    ``formula.min`` to ``formula.max``."""
    try:
        result = evaluate(q, formula.expression, response)
    except EvaluationError as exc:
        raise ScoringError(f"the total formula of {q.id} cannot be evaluated: {exc}") from None
    value = result[0] if len(result) == 1 else None
    if isinstance(value, bool) or not isinstance(value, (int, float, Decimal)) or value != int(value):
        raise ScoringError(f"the total formula of {q.id} gave {result!r}, not one whole number")
    if not formula.min <= value <= formula.max:
        raise ScoringError(
            f"the total formula of {q.id} gave {int(value)}, outside its declared {formula.min} to {formula.max}"
        )
    return int(value)


def excused_items(q: Questionnaire, answered: set[str]) -> set[str]:
    """The unanswered items a complete result does without: those an answered item stands in for
    (``instead_of``), and an item standing in for others that were all answered."""
    excused: set[str] = set()
    for item in q.items:
        if not item.instead_of:
            continue
        if item.id in answered:
            excused.update(item.instead_of)
        elif all(i in answered for i in item.instead_of):
            excused.add(item.id)
    return excused - answered


def compute_score(q: Questionnaire, options: Mapping[str, int], values: Mapping[str, float], bands: BandSet) -> Score:
    """The score of checked answers (see :meth:`Questionnaire.score_answers`)."""
    answered = tuple(i.id for i in q.items if i.id in options or i.id in values)
    excused = excused_items(q, set(answered))
    missing = tuple(i.id for i in q.items if i.id not in answered and i.id not in excused)
    points = {i: q.item(i).option(n).points or 0 for i, n in options.items()}
    complete = not missing
    total = sum(points.values())
    problem = ""
    if complete and q.formula is not None:
        try:
            total = formula_total(q, q.formula, {"item": response_items(q, options, values)})
        except ScoringError as exc:  # answers the file's check did not try: no total, never a crash
            complete, problem = False, str(exc)
    subscales = {s.id: sum(points[i] for i in s.items) for s in q.subscales if all(i in points for i in s.items)}
    staff = {i.id for i in q.items if i.staff}
    return Score(
        total=total,
        complete=complete,
        band=bands.band_for(total) if complete else None,
        answered=answered,
        missing=missing,
        max_total=q.max_total,
        band_set=bands.id,
        min_total=q.min_total,
        subscales=subscales,
        awaiting_staff=tuple(i for i in missing if i in staff),
        problem=problem,
    )

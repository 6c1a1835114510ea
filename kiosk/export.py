"""Export stored sessions: FHIR R4 Questionnaire / QuestionnaireResponse (JSON) and CSV.

Item scores ride on each answer option with the ``itemWeight`` extension (the weight belongs to
the item's option, never to a shared answer code), and the total is an SDC calculatedExpression
item. Totals are always recomputed from the answers' option numbers against the questionnaire;
a stored total or stored points are never trusted.
"""

from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kiosk.questionnaire import Questionnaire, Score
from kiosk.storage import PracticeRecord, StoredSession
from qos.files import write_error, write_private  # the one owner-only writer; exports use it from here too

ITEM_WEIGHT = "http://hl7.org/fhir/StructureDefinition/itemWeight"
CALCULATED = "http://hl7.org/fhir/uv/sdc/StructureDefinition/sdc-questionnaire-calculatedExpression"
PATIENT_SYSTEM = "urn:kiosk:patient"
TOTAL_LINK = "total"


class ExportError(ValueError):
    """A stored session does not fit the questionnaire (unknown item, option or points), or an
    export cannot be written."""


def questionnaire_url(q: Questionnaire) -> str:
    """The canonical URL the responses point at."""
    return f"urn:kiosk:questionnaire:{q.id}"


def _coding(code: Any, display: str) -> dict[str, str]:
    return {"system": code.system, "code": code.code, "display": display}


def _option_system(q: Questionnaire, item_id: str) -> str:
    return f"{questionnaire_url(q)}:{item_id}"


def fhir_questionnaire(q: Questionnaire, language: str = "en") -> dict[str, Any]:
    """The questionnaire as a FHIR R4 Questionnaire resource."""
    items = []
    for item in q.items:
        entry: dict[str, Any] = {"linkId": item.id, "text": item.text[language], "type": "choice", "required": True}
        if item.code:
            entry["code"] = [_coding(item.code, item.text[language])]
        entry["answerOption"] = [
            {
                "extension": [{"url": ITEM_WEIGHT, "valueDecimal": option.points}],
                "valueCoding": {"system": _option_system(q, item.id), "code": str(option.number),
                                "display": option.label_in(language)},
            }
            for option in item.options
        ]
        items.append(entry)
    total: dict[str, Any] = {
        "linkId": TOTAL_LINK, "text": "Total", "type": "integer", "readOnly": True,
        "extension": [{"url": CALCULATED, "valueExpression": {
            "language": "text/fhirpath",
            "expression": f"%resource.item.where(linkId != '{TOTAL_LINK}').answer.value.weight().sum()",
        }}],
    }
    if q.total_code:
        total["code"] = [_coding(q.total_code, "Total score")]
    items.append(total)
    resource: dict[str, Any] = {
        "resourceType": "Questionnaire", "id": q.id, "url": questionnaire_url(q), "version": q.version,
        "name": "".join(w.capitalize() for w in q.title["en"].split()), "title": q.title[language],
        "status": "draft", "language": language, "item": items,
    }
    if q.code:
        resource["code"] = [_coding(q.code, q.title["en"])]
    return resource


def rescore(q: Questionnaire, stored: StoredSession) -> Score:
    """The score recomputed from the stored option numbers (ExportError if they do not fit)."""
    points = {}
    for answer in stored.answers:
        try:
            option = q.item(answer.item_id).option(answer.option)
        except KeyError as exc:
            raise ExportError(f"session {stored.id}: {exc.args[0]}") from None
        if option.points != answer.points:
            raise ExportError(f"session {stored.id}: {answer.item_id} option {answer.option} is worth "
                              f"{option.points} points in {q.id}, but {answer.points} were stored")
        assert option.points is not None
        points[answer.item_id] = option.points
    return q.score(points)


#: what each kind of practice question checks, as a clinician reads it
PRACTICE_CHECKS = {"hear": "hearing", "read": "reading", "select": "selecting"}


@dataclass(frozen=True)
class PracticeOutcome:
    """How one practice question went, in a clinician's words: "hearing: wrong (chose Chair)"."""

    #: what it checks: "hearing", "reading" or "selecting"
    what: str
    #: "right", "wrong", "not answered" or "skipped"
    outcome: str
    #: the option chosen for a wrong answer ("chose Chair"), why it was skipped ("no voice out"), or ""
    detail: str = ""

    @property
    def result(self) -> str:
        """The outcome with its detail: "wrong (chose Chair)", "skipped (no voice out)", "right"."""
        return f"{self.outcome} ({self.detail})" if self.detail else self.outcome

    def __str__(self) -> str:
        return f"{self.what}: {self.result}"


def practice_outcome(q: Questionnaire, record: PracticeRecord, language: str) -> PracticeOutcome:
    """A stored practice record in a clinician's words (a wrong answer names the option chosen)."""
    what = PRACTICE_CHECKS.get(record.checks, record.checks)
    if record.outcome == "wrong":
        question = next((p for p in q.familiarisation if p.id == record.question_id), None)
        chosen = (question.option(record.option).label_in(language)
                  if question is not None and record.option is not None
                  and 1 <= record.option <= len(question.options) else f"option {record.option}")
        return PracticeOutcome(what, "wrong", f"chose {chosen}")
    if record.outcome == "skipped":
        return PracticeOutcome(what, "skipped", record.detail)
    return PracticeOutcome(what, record.outcome.replace("_", " "))


def practice_outcomes(q: Questionnaire, stored: StoredSession) -> list[PracticeOutcome]:
    """The session's practice questions in the order they happened (empty without familiarisation)."""
    return [practice_outcome(q, record, stored.language) for record in stored.practice]


def fhir_response(q: Questionnaire, stored: StoredSession) -> dict[str, Any]:
    """A stored session as a FHIR R4 QuestionnaireResponse (total recomputed)."""
    score = rescore(q, stored)
    language = stored.language
    answers = {a.item_id: a for a in stored.answers}
    items = []
    for item in q.items:
        entry: dict[str, Any] = {"linkId": item.id, "text": item.text[language]}
        if item.id in answers:
            option = item.option(answers[item.id].option)
            entry["answer"] = [{"valueCoding": {"system": _option_system(q, item.id), "code": str(option.number),
                                                "display": option.label_in(language)}}]
        items.append(entry)
    items.append({"linkId": TOTAL_LINK, "text": "Total", "answer": [{"valueInteger": score.total}]})
    patient = {"identifier": {"system": PATIENT_SYSTEM, "value": stored.patient_id}}
    source = patient | {"type": "Patient"} if stored.answered_by.value == "patient" else {
        "type": "RelatedPerson", "display": stored.answered_by.value}
    return {
        "resourceType": "QuestionnaireResponse", "id": stored.id,
        "questionnaire": f"{questionnaire_url(q)}|{q.version}",
        # a finished session is completed even with unanswered items (they carry no answer)
        "status": {"finished": "completed", "abandoned": "stopped"}.get(stored.status, "in-progress"),
        "subject": patient, "authored": stored.finished_at or stored.started_at, "source": source,
        "language": language, "item": items,
    }


#: ``band_set`` (total row only) names the band set the band comes from: "severe" is 21-60 in
#: Shah's set but 20-35 in the Spanish one. ``kind`` tells the rows apart: "practice" (one per
#: practice question, first, in the order asked; ``checks`` says what it checks), "item" (one per
#: questionnaire item, in order) and "total" (last). The first 13 columns are as they always were,
#: and practice rows carry no points, so a reader that keeps the item and total rows reads as before.
CSV_COLUMNS = ["session", "patient", "started_at", "status", "language", "item", "option", "label", "points",
               "attempt", "channel", "answered_by", "t", "band_set", "kind", "checks"]


def csv_text(q: Questionnaire, sessions: list[StoredSession]) -> str:
    """Per session: a row per practice question (``label`` its outcome: right, wrong (chose ...),
    not answered, skipped (why); never scored), a row per item (blank option when not answered),
    and a total row recomputed from the answers, with its band and the band set that gave it."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for stored in sessions:
        score = rescore(q, stored)
        answers = {a.item_id: a for a in stored.answers}
        head = [stored.id, stored.patient_id, stored.started_at, stored.status, stored.language]
        for record, outcome in zip(stored.practice, practice_outcomes(q, stored)):
            channel = record.channel.value if record.channel else ""
            writer.writerow(head + [record.question_id, record.option or "", outcome.result, "", "", channel,
                                    stored.answered_by.value, f"{record.t:g}", "", "practice", record.checks])
        for item in q.items:
            a = answers.get(item.id)
            if a is None:
                writer.writerow(head + [item.id, "", "not answered", "", "", "", "", "", "", "item", ""])
            else:
                label = item.option(a.option).label_in(stored.language)
                writer.writerow(head + [item.id, a.option, label, a.points, a.attempt, a.channel.value,
                                        a.answered_by.value, f"{a.t:g}", "", "item", ""])
        band = score.band.id if score.band else ("incomplete" if not score.complete else "")
        writer.writerow(head + [TOTAL_LINK, "", band, score.total, "", "", "", "", score.band_set, "total", ""])
    return out.getvalue()


def write_export(path: str | Path, text: str) -> None:
    """Write an export owner-only; ExportError ``cannot write PATH: reason`` when the path is unusable."""
    try:
        write_private(path, text)
    except OSError as exc:
        raise ExportError(write_error(path, exc)) from None


def write_json(path: str | Path, resource: dict[str, Any]) -> None:
    """Write a FHIR resource as JSON, owner-only (ExportError when the path is unusable)."""
    write_export(path, json.dumps(resource, indent=2, ensure_ascii=False) + "\n")

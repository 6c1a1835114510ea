"""Format v2 instruments exported as FHIR: the formula total and the subscales travel as SDC
``calculatedExpression``s that fhirpath.js (npm ``fhirpath``, run by node), fhirpathpy and
LHC-Forms in Chromium all evaluate to the total the kiosk computed; staff items are items of the
response; subscales are components of the total's Observation; everything is valid R4."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from kiosk.core.channels import Channel
from kiosk.core.questionnaire import evaluate
from kiosk.core.session import Answer, AnsweredBy
from kiosk.export import ExportSite, fhir_questionnaire, result
from kiosk.export.calculated import ANSWERED_BY, CALCULATED, MAX_VALUE, MIN_VALUE, UNIT
from kiosk.export.fhir import response_of
from kiosk.export.total import total_of
from kiosk.store.records import StoredSession
from tests.kiosk.core.instruments_v2 import GDS, MEASURED, MIXED, STAFFED, STOOD_IN, load
from tests.prerequisites import JS, ensure_npm_packages

from .standard import check_fhir

SITE = ExportSite(site="hosp-north", kiosk_id="ward3-bed2")


def stored(q, options: dict[str, int], language: str = "en", session: str = "s-1") -> StoredSession:
    """A finished session of ``q`` with these answers (item -> option number), as the store gives it."""
    answers = tuple(
        Answer(item, number, q.item(item).option(number).points, 1, Channel.TOUCH, AnsweredBy.PATIENT, float(n))
        for n, (item, number) in enumerate(options.items())
    )
    missing = tuple(i.id for i in q.items if i.id not in options and i.entry is None)
    return StoredSession(
        id=session,
        patient_id="P-0001",
        questionnaire_id=q.id,
        language=language,
        answered_by=AnsweredBy.PATIENT,
        timing={},
        started_at="2026-11-26T10:00:00Z",
        status="finished",
        finished_at="2026-11-26T10:05:00Z",
        answers=answers,
        not_answered=missing,
        trace=(),
        metrics=(),
        adaptations=(),
        log=(),
    )


def exported(q, options, values=None, language="en"):
    """(Questionnaire, response, Observation, Result) of one session, each checked as R4."""
    r = result(q, stored(q, options, language), values=values)
    questionnaire = fhir_questionnaire(q, language, SITE)
    response = response_of(q, r, SITE)
    observation = total_of(q, r, SITE, {"type": "QuestionnaireResponse", "reference": "QuestionnaireResponse/s-1"})
    for resource in (questionnaire, response, observation):
        if resource is not None:
            check_fhir(resource)
    return questionnaire, response, observation, r


def expressions(questionnaire) -> dict[str, str]:
    """linkId -> calculatedExpression of the Questionnaire's computed items."""
    return {
        i["linkId"]: e["valueExpression"]["expression"]
        for i in questionnaire["item"]
        for e in i.get("extension", [])
        if e["url"] == CALCULATED
    }


def fhirpath_js(expressions_: list[str], response, questionnaire) -> list[list]:
    """Each expression evaluated by fhirpath.js (node) on the response, %questionnaire given."""
    ensure_npm_packages(JS)
    node = shutil.which("node")
    if node is None:
        pytest.fail("node is not installed (fhirpath.js needs it): sudo apt-get install nodejs", pytrace=False)
    done = subprocess.run(
        [node, str(Path(JS) / "evaluate.mjs")],
        input=json.dumps({"expressions": expressions_, "resource": response, "questionnaire": questionnaire}),
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


STAFFED_ANSWERS = {"recall": 3, "orientation": 2, "judged": 2}


def test_a_formula_total_is_the_same_for_the_kiosk_fhirpath_js_and_fhirpathpy(tmp_path):
    q = load(tmp_path, STAFFED)
    for education, total in ((6, 3), (12, 4)):
        questionnaire, response, observation, r = exported(q, STAFFED_ANSWERS, {"education": education})
        assert (r.complete, r.score.total) == (True, total)
        items = {i["linkId"]: i for i in response["item"]}
        assert items["education"]["answer"] == [{"valueInteger": education}]
        assert items["total"]["answer"] == [{"valueInteger": total}]
        assert observation["valueQuantity"]["value"] == total
        expression = expressions(questionnaire)["total"]
        assert q.formula.expression in expression
        assert fhirpath_js([expression, q.formula.expression], response, questionnaire) == [[total], [total]]
        assert evaluate(q, expression, response) == [total]
        assert evaluate(q, q.formula.expression, response) == [total]


def test_staff_items_are_marked_and_a_number_keeps_its_range_and_unit(tmp_path):
    q = load(tmp_path, STAFFED)
    questionnaire, _, _, _ = exported(q, STAFFED_ANSWERS, {"education": 6})
    items = {i["linkId"]: i for i in questionnaire["item"]}
    education = items["education"]
    assert education["type"] == "integer" and "answerOption" not in education
    ext = {e["url"]: e for e in education["extension"]}
    assert ext[ANSWERED_BY]["valueCode"] == "staff"
    assert (ext[MIN_VALUE]["valueInteger"], ext[MAX_VALUE]["valueInteger"]) == (0, 30)
    assert ext[UNIT]["valueCoding"] == {"system": "http://unitsofmeasure.org", "code": "a"}
    assert {e["url"] for e in items["judged"]["extension"]} >= {ANSWERED_BY}
    assert ANSWERED_BY not in {e["url"] for e in items["recall"]["extension"]}


def test_a_result_awaiting_staff_says_so_and_has_no_total(tmp_path):
    q = load(tmp_path, STAFFED)
    questionnaire, response, observation, r = exported(q, {"recall": 3, "orientation": 2})
    assert not r.complete and r.awaiting_staff == ("education", "judged")
    assert r.pending == "incomplete until staff answer education, judged"
    assert observation is None and response["status"] == "in-progress"
    assert "total" not in {i["linkId"] for i in response["item"]}
    assert fhirpath_js([expressions(questionnaire)["total"]], response, questionnaire) == [[]]
    assert evaluate(q, expressions(questionnaire)["total"], response) == []


def test_subscales_are_calculated_items_and_observation_components(tmp_path):
    q = load(tmp_path, MIXED)
    answers = {"pain": 1, "steps": 6, "sleep": 2, "appetite": 1}  # -2 + 5, 2 + 0
    questionnaire, response, observation, r = exported(q, answers)
    assert (r.score.total, dict(r.score.subscales)) == (5, {"body": 3, "rest": 2})
    calc = expressions(questionnaire)
    js = fhirpath_js([calc["total"], calc["body"], calc["rest"]], response, questionnaire)
    assert js == [[5], [3], [2]]
    assert [evaluate(q, calc[k], response) for k in ("total", "body", "rest")] == [[5], [3], [2]]
    items = {i["linkId"]: i for i in response["item"]}
    assert items["body"]["answer"] == [{"valueInteger": 3}] and items["rest"]["answer"] == [{"valueInteger": 2}]
    components = {c["code"]["coding"][0]["code"]: c["valueQuantity"]["value"] for c in observation["component"]}
    assert components == {"body": 3, "rest": 2}
    assert observation["component"][0]["code"]["coding"][0]["system"] == "urn:test:sub"
    assert observation["component"][1]["code"]["coding"][0]["system"] == "urn:barthel-kiosk:subscale:mixed"
    # negative and zero points ride on the options as itemWeight and ordinalValue
    pain = next(i for i in questionnaire["item"] if i["linkId"] == "pain")
    assert [o["extension"][0]["valueDecimal"] for o in pain["answerOption"]] == [-2, 0, 3]
    assert [o["extension"][1]["valueDecimal"] for o in pain["answerOption"]] == [-2, 0, 3]


def test_yes_no_answers_are_loinc_yes_and_no_with_their_weights(tmp_path):
    q = load(tmp_path, GDS)
    questionnaire, response, observation, r = exported(q, {"satisfied": 2, "bored": 1, "helpless": 2}, language="es")
    assert r.score.total == 2 and observation["valueQuantity"]["value"] == 2
    satisfied = next(i for i in questionnaire["item"] if i["linkId"] == "satisfied")
    assert [o["valueCoding"] for o in satisfied["answerOption"]] == [
        {"system": "http://loinc.org", "code": "LA33-6", "display": "Yes"},
        {"system": "http://loinc.org", "code": "LA32-8", "display": "No"},
    ]
    assert [o["extension"][0]["valueDecimal"] for o in satisfied["answerOption"]] == [0, 1]
    total = expressions(questionnaire)["total"]
    assert fhirpath_js([total], response, questionnaire) == [[2]]
    assert evaluate(q, total, response) == [2]


@pytest.mark.parametrize(
    ("weight", "height", "total"),
    [(50.0, 170.0, 2), (60.5, 170.0, 3), (65.0, 170.0, 4), (80.0, 165.5, 5), (20.0, 220.0, 2)],
)
def test_a_formula_over_decimals_staff_measured_agrees_everywhere(tmp_path, weight, height, total):
    """BMI from weight (kg) and height (cm), as MNA-SF's F1: 17.3 -> 0, 20.9 -> 1, 22.5 -> 2, >= 23 -> 3."""
    q = load(tmp_path, MEASURED)
    questionnaire, response, observation, r = exported(q, {"intake": 3}, {"weight": weight, "height": height})
    assert (r.complete, r.score.total, observation["valueQuantity"]["value"]) == (True, total, total)
    items = {i["linkId"]: i["answer"] for i in response["item"]}
    assert items["weight"] == [{"valueDecimal": weight}] and items["height"] == [{"valueDecimal": height}]
    expression = expressions(questionnaire)["total"]
    assert fhirpath_js([expression], response, questionnaire) == [[total]]
    assert evaluate(q, expression, response) == [total]


@pytest.mark.parametrize(
    ("values", "total"),
    [({"calf": 33.0}, [5]), ({"weight": 50.0, "height": 170.0}, [2]), ({"weight": 50.0}, [])],
)
def test_a_stand_in_item_completes_the_total_everywhere(tmp_path, values, total):
    """The calf circumference instead of the weight and height (MNA-SF F2): the exported total is
    computed once either side is answered, by fhirpath.js as by the kiosk."""
    q = load(tmp_path, STOOD_IN)
    questionnaire, response, observation, r = exported(q, {"intake": 3}, values)
    assert r.complete == bool(total) and (r.score.total if r.complete else None) == (total or [None])[0]
    expression = expressions(questionnaire)["total"]
    assert fhirpath_js([expression], response, questionnaire) == [total]
    assert evaluate(q, expression, response) == total

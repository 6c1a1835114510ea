"""An item answered instead of others that cannot be (issue 35, part 3): the MNA-SF's calf
circumference when the patient cannot be weighed. Either side completes the result, the
formula is proved for either, and the exported calculatedExpression computes the same total."""

from __future__ import annotations

from kiosk.core.questionnaire import result_words
from kiosk.core.questionnaire.definition import canonical, questionnaire_from
from tests.kiosk.core.instruments_v2 import STAND_IN_FORMULA, STOOD_IN, load
from tests.kiosk.core.test_instruments_v2 import at, problems


def test_either_the_calf_or_the_weight_and_height_complete_the_result(tmp_path):
    q = load(tmp_path, STOOD_IN)
    assert q.item("calf").instead_of == ("weight", "height")
    bed_bound = q.score_answers({"intake": 3}, values={"calf": 33.0})
    assert (bed_bound.complete, bed_bound.total, bed_bound.band.id, bed_bound.missing) == (True, 5, "normal", ())
    weighed = q.score_answers({"intake": 2}, values={"weight": 50.0, "height": 170.0})  # BMI 17.3
    assert (weighed.complete, weighed.total, weighed.band.id) == (True, 1, "malnourished")
    both = q.score_answers({"intake": 1}, values={"weight": 80.0, "height": 170.0, "calf": 30.0})
    assert (both.complete, both.total) == (True, 0)  # the formula prefers the calf when both are there
    waiting = q.score_answers({"intake": 1}, values={"weight": 80.0})
    assert (waiting.complete, waiting.awaiting_staff) == (False, ("height", "calf"))
    assert result_words(q, waiting) == "No total yet: waiting for staff: height? (cm) or calf? (cm)"
    nothing = q.score_answers({"intake": 1})
    assert result_words(q, nothing) == "No total yet: waiting for staff: weight? (kg), height? (cm) or calf? (cm)"
    assert questionnaire_from(canonical(q)) == q


def test_a_formula_that_forgets_the_stand_in_is_refused_naming_the_case(tmp_path):
    forgets = "%resource.item.where(linkId = 'intake').answer.value.weight().sum() + " + (
        "(%resource.item.where(linkId = 'weight').answer.value / 100).floor()"
    )
    text = STOOD_IN.replace(STAND_IN_FORMULA, forgets)
    (problem,) = problems(tmp_path, text)
    assert problem == (
        f"{at(text, 'fhirpath:') + 10}: scoring.total.fhirpath: it gives 0 values, not one number "
        "when intake is option 1 (with calf answered instead of weight, height); it must give one whole number from 0 to 5"
    )


def test_instead_of_names_other_items_once_and_needs_a_formula(tmp_path):
    unknown = STOOD_IN.replace("instead_of: [weight, height]", "instead_of: [weight, heigth]")
    assert problems(tmp_path, unknown) == [
        f"{at(unknown, 'heigth')}: items[3].instead_of names 'heigth', which is not an item"
    ]
    itself = STOOD_IN.replace("instead_of: [weight, height]", "instead_of: [calf]")
    assert f"{at(itself, 'calf]')}: items[3].instead_of names itself" in problems(tmp_path, itself)
    summed = STOOD_IN.split("scoring:")[0] + STOOD_IN.split("max: 5\n", 1)[1]
    assert (
        f"{at(summed, 'instead_of')}: items[3].instead_of: an item answered instead of others needs a formula "
        "total, which says how either is scored"
    ) in problems(tmp_path, summed)

"""The kiosk's formula language for totals: hostile formulas are refused in one line each, by
`kiosk validate` and by loading alike, and a formula that reaches the kiosk or the station
anyway (a captured definition) gives no total and says why, never a hang or a traceback.

No timing asserts: what stops a formula is the budget's deterministic step counter, asserted here
through its messages and counts."""

from __future__ import annotations

from dataclasses import replace

import pytest
from fhirpathpy import evaluate as fhirpathpy_evaluate

from kiosk.commands.validate import main as validate_main
from kiosk.core.questionnaire import Formula
from kiosk.core.questionnaire.formula import (
    MAX_DEPTH,
    MAX_LENGTH,
    MAX_STEPS,
    Budget,
    EvaluationError,
    ItemAnswers,
    compute,
    prove,
)
from kiosk.core.questionnaire.formula.evaluation import ITEM_WEIGHT
from tests.kiosk.core.instruments_v2 import MEASURED, STAFFED, bands, choice, instrument, load, write
from tests.kiosk.core.test_instruments_v2 import at, problems

A = "%resource.item.where(linkId = '{}').answer.value"


def summed(*ids: str) -> str:
    return " + ".join(f"{A.format(i)}.weight()" for i in ids)


def with_formula(formula: str, low: int = 0, high: int = 4, items: str | None = None) -> str:
    """A two-item instrument (a: 0/1/2, b: 0/1/2) totalled by ``formula``."""
    body = items or choice("a", [0, 1, 2]) + choice("b", [0, 1, 2])
    ranges = bands(("all", low, high))
    return instrument(
        "hostile", body, ranges, f'scoring:\n  total:\n    fhirpath: "{formula}"\n    min: {low}\n    max: {high}\n'
    )


def only(tmp_path, text: str) -> str:
    (problem,) = problems(tmp_path, text)
    assert problem.startswith(f"{at(text, 'fhirpath:') + 10}: scoring.total.fhirpath"), problem
    return problem.split(": scoring.total.fhirpath", 1)[1]


# ---------------------------------------------------------------- refused by the language


@pytest.mark.parametrize(
    ("call", "why"),
    [
        ("today()", "today() is not allowed in a total: it reads the clock"),
        ("now()", "now() is not allowed in a total: it reads the clock"),
        ("timeOfDay()", "timeOfDay() is not allowed in a total: it reads the clock"),
        ("code.matches('(a+)+$')", "matches() is not allowed in a total: it runs a regular expression"),
        ("code.replaceMatches('(a|a)*b', 'x')", "replaceMatches() is not allowed in a total: it runs a regular"),
        ("repeat(item)", "repeat() is not allowed in a total: it iterates without a bound"),
        ("descendants()", "descendants() is not allowed in a total: it iterates without a bound"),
        ("aggregate($this, 0)", "aggregate() is not allowed in a total: it iterates without a bound"),
        ("trace('total')", "trace() is not allowed in a total: it prints to the kiosk's terminal"),
        ("defineVariable('x', 1)", "defineVariable() is not allowed in a total"),
    ],
)
def test_clock_regex_unbounded_iteration_and_trace_are_refused_where_they_are(tmp_path, call, why):
    formula = f"{summed('a', 'b')} + iif({A.format('a')}.{call}.exists(), 0, 0)"
    problem = only(tmp_path, with_formula(formula))
    name = call.split("(")[0].split(".")[-1]
    assert problem.startswith(f", at character {formula.index(name + '(') + 1}: {why}")


def test_a_twenty_thousand_term_sum_is_refused_by_its_length_before_it_is_read(tmp_path):
    formula = " + ".join(["1"] * 20_000)
    problem = only(tmp_path, with_formula(formula))
    assert (
        problem
        == f", at character 1: the formula is {len(formula):,} characters long; at most {MAX_LENGTH:,} are allowed"
    )


@pytest.mark.parametrize(
    ("shape", "why"),
    [
        ("(" * 150 + "1" + ")" * 150, f"the formula is nested more than {MAX_DEPTH} deep"),
        ("-" * 150 + "1", f"the formula is nested more than {MAX_DEPTH} deep"),
        ("1" + " + 1" * 150, f"the formula is nested more than {MAX_DEPTH} deep"),
        (" + ".join(["(" + " + ".join(["1"] * 55) + ")"] * 4), "the formula has more than 400 parts"),
        ("(" * 900 + "1" + ")" * 900, "the formula has more than 600 words and signs"),
    ],
)
def test_deep_nesting_is_refused_not_a_recursion_error(tmp_path, shape, why):
    assert why in only(tmp_path, with_formula(shape))
    with pytest.raises(EvaluationError, match=why):
        compute(shape, {"resourceType": "QuestionnaireResponse"})


def test_a_misspelled_item_inside_iif_is_an_error_with_a_suggestion(tmp_path):
    formula = f"{summed('a')} + iif({A.format('bb')}.weight() > 0, 2, 0)"
    problem = only(tmp_path, with_formula(formula))
    where = formula.index("'bb'") + 1
    assert problem == f", at character {where}: there is no item 'bb' (did you mean 'b'?)"


def test_a_huge_declared_max_is_refused_and_never_enumerated(tmp_path):
    text = with_formula(summed("a", "b"), 0, 999_999_999_999)
    found = problems(tmp_path, text)
    assert f"{at(text, 'max: 999') + 5}: scoring.total: max 999999999999 is beyond ±10,000, no score's range" in found


# ---------------------------------------------------------------- proved for every answer


def test_an_odd_sum_halved_is_refused_with_the_answers_that_break_it(tmp_path):
    problem = only(tmp_path, with_formula(f"({summed('a', 'b')}) / 2", 0, 2))
    assert problem == (
        ": it gives 0.5 when a is option 1, b is option 2; it must give one whole number from 0 to 2 "
        "(round(), floor() or div make one)"
    )


def test_a_catastrophic_regex_reached_only_in_a_mixed_answer_never_runs(tmp_path):
    # the old check tried every item at its first and at its last option only
    formula = f"iif({A.format('a')}.weight() = 1 and {A.format('b')}.code.matches('(x+x+)+y'), 1, 0)"
    assert "matches() is not allowed in a total" in only(tmp_path, with_formula(formula))


def test_a_range_the_formula_leaves_is_found_by_reasoning_over_decimals(tmp_path):
    from tests.kiosk.core.instruments_v2 import staff_input

    body = choice("intake", [0, 1]) + staff_input("weight", "decimal", 20, 250, "kg")
    rounded = with_formula(f"{A.format('weight')}.round()", 0, 300, body)
    assert problems(tmp_path, rounded) == []
    narrow = with_formula(f"{A.format('weight')}.round()", 0, 100, body)
    assert (
        only(tmp_path, narrow)
        == ": it can give from 20 to 250 when intake is option 1; it must give one whole number from 0 to 100"
    )
    thirds = with_formula(f"{A.format('weight')} / 3", 0, 100, body)
    assert only(tmp_path, thirds) == (
        ": it can give a number that is not whole when intake is option 1; "
        "it must give one whole number from 0 to 100 (round(), floor() or div make one)"
    )


def test_the_bmi_formula_over_staff_decimals_is_proved_by_ranges():
    q_items = [
        ItemAnswers("intake", options=(("s", "1", 0), ("s", "2", 1), ("s", "3", 2))),
        ItemAnswers("weight", entry=("decimal", 20, 250)),
        ItemAnswers("height", entry=("decimal", 100, 220)),
    ]
    from tests.kiosk.core.instruments_v2 import BMI_FORMULA

    assert prove(BMI_FORMULA, 0, 5, q_items) == []
    assert prove(BMI_FORMULA, 0, 4, q_items) == [(0, "it can give from 2 to 5 when intake is option 3")]


def test_validate_of_a_hostile_file_is_one_line_and_exit_1(tmp_path, capsys):
    path = write(tmp_path, with_formula(f"{summed('a', 'b')} + today().count()"))
    assert validate_main([str(path)]) == 1
    (line,) = capsys.readouterr().out.splitlines()
    assert line.startswith(f"{path}:") and "today() is not allowed in a total" in line


# ---------------------------------------------------------------- bounded evaluation


def sixty_items(tmp_path, formula: str):
    items = "".join(choice(f"i{n}", [0, 1]) for n in range(60))
    return with_formula(formula, 0, 60, items)


NESTED_PRODUCT = "%resource.item.where(%resource.item.where(%resource.item.where(%resource.item.exists()).exists()).exists()).count()"


def test_a_sixty_to_the_fourth_product_stops_at_the_budget(tmp_path):
    problem = only(tmp_path, sixty_items(tmp_path, NESTED_PRODUCT))
    assert problem == (
        f": it cannot be evaluated on every answer: it takes more than {MAX_STEPS:,} steps: simplify it; "
        "it must give one whole number from 0 to 60"
    )


def test_a_captured_hostile_formula_gives_no_total_and_says_why(tmp_path):
    # the station rebuilds instruments from captured definitions it did not validate: scoring
    # them goes through the same bounded evaluation
    q = load(tmp_path, sixty_items(tmp_path, summed("i0", "i1")))
    answers = {f"i{n}": 2 for n in range(60)}
    assert q.score_answers(answers).total == 2
    for formula, why in [
        (NESTED_PRODUCT, f"takes more than {MAX_STEPS:,} steps"),
        ("today().count()", "today() is not allowed in a total"),
        ("%resource.item.repeat(item).count()", "repeat() is not allowed in a total"),
        ("(" * 900 + "1" + ")" * 900, "more than 600 words and signs"),
        ("(" * 150 + "1" + ")" * 150, "nested more than"),
        (" + ".join(["1"] * 20_000), "characters long"),
        ("%resource.item.count() / 7", "not one whole number"),
    ]:
        score = replace(q, formula=Formula(formula, 0, 60)).score_answers(answers)
        assert (score.complete, score.band) == (False, None)
        assert why in score.problem


def test_the_budget_counts_steps_deterministically():
    response = {"resourceType": "QuestionnaireResponse", "item": [{"linkId": f"i{n}"} for n in range(60)]}
    first, second = Budget(), Budget()
    assert compute("%resource.item.where(linkId != 'x').count()", response, first) == [60]
    compute("%resource.item.where(linkId != 'x').count()", response, second)
    assert first.steps == second.steps < 1000
    small = Budget(500)
    with pytest.raises(EvaluationError, match="more than 500 steps"):
        compute(NESTED_PRODUCT, response, small)
    assert small.steps > 500


# ---------------------------------------------------------------- the same meaning as FHIRPath


def coded(code: str, points: int) -> dict:
    return {"valueCoding": {"system": "s", "code": code, "extension": [{"url": ITEM_WEIGHT, "valueDecimal": points}]}}


RESPONSE = {
    "resourceType": "QuestionnaireResponse",
    "item": [
        {"linkId": "a", "answer": [coded("1", 2)]},
        {"linkId": "b", "answer": [coded("2", 1)]},
        {"linkId": "w", "answer": [{"valueDecimal": 70.5}]},
        {"linkId": "n", "answer": [{"valueInteger": 7}]},
    ],
}


@pytest.mark.parametrize(
    "expression",
    [
        "1 + 2 * 3 - 4",
        "7 / 2",
        "7 div 2",
        "7 mod 3",
        "-3 + 1",
        "(7 / 2).floor() + (7 / 2).ceiling()",
        "(1 | 2 | 3).max() - (1 | 2 | 3).min()",
        "(1 | 2 | 3).sum()",
        "{}.sum()",
        "iif({}, 1, 2)",
        "iif(1 < 2 and 3 > 2, 'yes', 'no')",
        "true and {}",
        "false and {}",
        "true or {}",
        "{} + 1",
        "1 / 0",
        "%resource.item.count()",
        "%resource.item.where(linkId = 'a' or linkId = 'b').answer.value.weight().sum()",
        "%resource.item.where(linkId = 'w').answer.value / 2",
        "%resource.item.where(linkId = 'n').answer.value < 9",
        "%resource.item.where(linkId != 'a' and answer.exists()).count()",
        "%resource.item.where(linkId = 'a').answer.value.code = '1'",
        "%resource.item.first().linkId",
        "%resource.item.where(linkId = 'zz').exists().not()",
        "(%resource.item.where(linkId = 'w').answer.value * 10).truncate()",
    ],
)
def test_the_kiosk_computes_what_fhirpathpy_computes(expression):
    from fhirpathpy.models import models

    from kiosk.core.questionnaire.formula.evaluation import _plain, _weight

    weights = {"weight": {"fn": lambda found: [w for w in map(_weight, found) if w is not None], "arity": {0: []}}}
    theirs = fhirpathpy_evaluate(
        RESPONSE, expression, {"resource": RESPONSE}, models["r4"], options={"userInvocationTable": weights}
    )
    theirs = [_plain(v) for v in theirs]
    assert compute(expression, RESPONSE) == theirs


def test_the_formulas_of_the_test_instruments_still_validate(tmp_path):
    for text in (STAFFED, MEASURED):
        assert problems(tmp_path, text) == []


# ---------------------------------------------------------------- units


@pytest.mark.parametrize(
    ("unit", "why"),
    [
        ("kilos", "'kilos' is not a UCUM unit: write 'kg'"),
        ("years", "'years' is not a UCUM unit: write 'a'"),
        ("Kg", "'Kg' is not a UCUM unit: 'Kg' is not a unit the kiosk knows (did you mean 'kg'?)"),
        ("kg//m2", "'kg//m2' is not a UCUM unit: '/' needs a unit on each side (did you mean 'kg/m2'?)"),
        ("(cm", "'(cm' is not a UCUM unit: it does not follow UCUM's grammar (did you mean 'cm'?)"),
    ],
)
def test_a_unit_that_is_not_ucum_is_refused_with_what_to_write(tmp_path, unit, why):
    from tests.kiosk.core.instruments_v2 import staff_input

    body = choice("intake", [0, 1]) + staff_input("weight", "decimal", 20, 250, f"'{unit}'")
    text = with_formula(summed("intake"), 0, 1, body)
    assert problems(tmp_path, text) == [f"{at(text, 'unit: ') + 6}: items[1].input.unit: {why}"]


@pytest.mark.parametrize("unit", ["kg", "cm", "s", "a", "{score}", "kg/m2", "mm[Hg]", "{beats}/min", "10*3/uL", "mL"])
def test_ucum_units_and_compositions_are_accepted(tmp_path, unit):
    from tests.kiosk.core.instruments_v2 import staff_input

    body = choice("intake", [0, 1]) + staff_input("weight", "decimal", 20, 250, f"'{unit}'")
    assert problems(tmp_path, with_formula(summed("intake"), 0, 1, body)) == []


# ---------------------------------------------------------------- incomplete results in words


def test_an_incomplete_result_says_what_it_waits_for_in_the_items_words(tmp_path):
    from kiosk.core.questionnaire import result_words

    q = load(tmp_path, MEASURED)
    waiting = q.score_answers({"intake": 2})
    assert result_words(q, waiting) == "No total yet: waiting for staff: weight? (kg), height? (cm)"
    nothing = q.score_answers({}, values={"weight": 70.0})
    assert result_words(q, nothing) == "No total: not answered: intake?; waiting for staff: height? (cm)"
    done = q.score_answers({"intake": 3}, values={"weight": 70.0, "height": 170.0})
    assert result_words(q, done) == "Total 5 of 5; normal"
    broken = replace(q, formula=Formula("today().count()", 0, 5)).score_answers(
        {"intake": 3}, values={"weight": 70.0, "height": 170.0}
    )
    assert result_words(q, broken).startswith("No total: the total formula of measured cannot be evaluated: ")

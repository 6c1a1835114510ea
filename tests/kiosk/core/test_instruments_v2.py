"""Format v2 instruments: what they mean once loaded, how they score, and every refusal as one
``file:line:col`` line (the same from `kiosk validate` as from loading)."""

from __future__ import annotations

import pytest

from kiosk.commands.validate import main as validate_main
from kiosk.core.questionnaire import (
    QuestionnaireError,
    check_questionnaire_file,
    load_questionnaire,
)
from kiosk.core.questionnaire.definition import canonical, questionnaire_from
from tests.kiosk.core.instruments_v2 import (
    FORMULA,
    GDS,
    LAWTON,
    MIXED,
    STAFFED,
    bands,
    choice,
    instrument,
    load,
    staff_input,
    texts,
    write,
    yes_no,
)


def problems(tmp_path, text: str) -> list[str]:
    """Every problem of a file, as `kiosk validate` prints them (path stripped), checked to be
    what loading refuses the file with."""
    path = write(tmp_path, text)
    found = [str(p) for p in check_questionnaire_file(path)]
    if found:
        with pytest.raises(QuestionnaireError) as caught:
            load_questionnaire(path)
        assert [str(p) for p in caught.value.problems] == found
    return [line.removeprefix(f"{path}:") for line in found]


class Where(str):
    """'line:col'; adding n moves the column right."""

    def __add__(self, n):
        line, col = self.split(":")
        return Where(f"{line}:{int(col) + n}")


def at(text: str, needle: str, nth: int = 0) -> Where:
    """'line:col' of the nth occurrence of needle."""
    index = -1
    for _ in range(nth + 1):
        index = text.index(needle, index + 1)
    return Where(f"{text.count(chr(10), 0, index) + 1}:{index - text.rfind(chr(10), 0, index)}")


# ---------------------------------------------------------------- instruments that load


def test_a_lawton_like_instrument_shares_scores_and_has_five_levels(tmp_path):
    q = load(tmp_path, LAWTON)
    assert [len(i.options) for i in q.items] == [4, 5, 3]
    assert [o.points for o in q.item("housekeeping").options] == [1, 1, 1, 1, 0]
    assert (q.min_total, q.max_total) == (0, 3)
    score = q.score_answers({"telephone": 3, "housekeeping": 4, "laundry": 3})
    assert (score.total, score.complete, score.band.id) == (2, True, "high")
    assert q.reference == "A test instrument (no publication)"


def test_yes_no_items_take_their_words_and_loinc_codes_from_the_kiosk(tmp_path):
    q = load(tmp_path, GDS)
    yes, no = q.item("satisfied").options
    assert (yes.number, yes.label_in("en"), yes.label_in("es"), yes.code.code) == (1, "Yes", "Sí", "LA33-6")
    assert (no.number, no.label_in("en"), no.patient_label_in("es"), no.code.code) == (2, "No", "No", "LA32-8")
    assert "yes" in yes.synonyms_in("en") and "no" in no.synonyms_in("en")
    # reverse-scored: No scores on 'satisfied', Yes on the others
    assert (yes.points, no.points) == (0, 1)
    assert [o.points for o in q.item("bored").options] == [1, 0]
    score = q.score_answers({"satisfied": 2, "bored": 1, "helpless": 2})
    assert (score.total, score.band.id) == (2, "depressed")


def test_unquoted_yes_and_no_points_mean_what_they_say(tmp_path):
    q = load(tmp_path, GDS.replace('{"yes": 0, "no": 1}', "{yes: 0, no: 1}"))
    assert [o.points for o in q.item("satisfied").options] == [0, 1]


def test_translations_say_which_languages_are_validated(tmp_path):
    q = load(tmp_path, GDS)
    assert q.validated("en") and not q.validated("es")
    assert q.translations["es"].source == "our own"
    assert not load(tmp_path, LAWTON).validated("en")  # not listed: unvalidated


def test_negative_points_six_options_and_subscales(tmp_path):
    q = load(tmp_path, MIXED)
    assert [o.points for o in q.item("pain").options] == [-2, 0, 3]
    assert len(q.item("steps").options) == 6 and q.item("steps").option(6).points == 5
    assert (q.min_total, q.max_total) == (-2, 12)
    lowest = q.score_answers({"pain": 1, "steps": 1, "sleep": 1, "appetite": 1})
    assert (lowest.total, lowest.band.id, dict(lowest.subscales)) == (-2, "poor", {"body": -2, "rest": 0})
    partial = q.score_answers({"pain": 3, "steps": 6, "sleep": 2})
    assert (partial.complete, partial.band, dict(partial.subscales)) == (False, None, {"body": 8})
    assert [s.code.code if s.code else None for s in q.subscales] == ["body", None]


def test_a_formula_total_with_staff_items_is_incomplete_until_staff_answer(tmp_path):
    q = load(tmp_path, STAFFED)
    assert [i.id for i in q.patient_items] == ["recall", "orientation"]
    assert [i.id for i in q.staff_items] == ["education", "judged"]
    assert q.item("education").entry.unit == "a" and q.item("education").spoken == {}
    at_kiosk = q.score_answers({"recall": 3, "orientation": 2})
    assert (at_kiosk.complete, at_kiosk.band, at_kiosk.awaiting_staff) == (False, None, ("education", "judged"))
    # recall 2 + orientation 1 + judged 1, minus 1 for under 9 years of education
    done = q.score_answers({"recall": 3, "orientation": 2, "judged": 2}, values={"education": 6})
    assert (done.total, done.complete, done.band.id, done.awaiting_staff) == (3, True, "impaired", ())
    more = q.score_answers({"recall": 3, "orientation": 2, "judged": 2}, values={"education": 12})
    assert more.total == 4
    assert (q.min_total, q.max_total) == (-1, 5)
    with pytest.raises(ValueError, match="31 is not an integer from 0 to 30 for item 'education'"):
        q.score_answers({}, values={"education": 31})
    with pytest.raises(ValueError, match="item 'education' takes an entered value"):
        q.score_answers({"education": 1})


def test_points_scoring_still_works_for_sum_totals(tmp_path):
    q = load(tmp_path, LAWTON)
    assert q.score({"telephone": 1, "housekeeping": 0, "laundry": 1}).total == 2
    with pytest.raises(ValueError, match="5 points is not an option of item 'telephone'"):
        q.score({"telephone": 5})


@pytest.mark.parametrize("text", [LAWTON, GDS, MIXED, STAFFED])
def test_a_captured_definition_rebuilds_every_v2_feature(tmp_path, text):
    q = load(tmp_path, text)
    assert questionnaire_from(canonical(q)) == q


def test_validate_accepts_them_all(tmp_path, capsys):
    paths = [str(write(tmp_path, t, f"{n}.yaml")) for n, t in enumerate((LAWTON, GDS, MIXED, STAFFED))]
    assert validate_main(paths) == 0


# ---------------------------------------------------------------- refusals


def test_seven_options_and_one_option_are_refused(tmp_path):
    text = instrument("seven", choice("a", [0, 1, 2, 3, 4, 5, 6]) + choice("b", [0]), bands(("all", 0, 6)))
    assert problems(tmp_path, text) == [
        f"{at(text, '- points: 0')}: items[0].options has 7: at most 6 are allowed",
        f"{at(text, '- points: 0', 1)}: items[1].options has 1: at least 2 are allowed",
    ]


def test_a_formula_that_is_not_fhirpath_is_refused_where_it_is(tmp_path):
    text = STAFFED.replace("answer.value < 9", "answer.value <* 9")
    (problem,) = problems(tmp_path, text)
    character = FORMULA.index("< 9") + 2  # the stray "*" after "<", counted from 1
    assert problem == (
        f"{at(text, 'fhirpath:') + 10}: scoring.total.fhirpath, at character {character}: "
        "expected a value but found '*'"
    )


def test_a_formula_with_an_unknown_function_or_out_of_its_range_is_refused(tmp_path):
    text = STAFFED.replace(".weight().sum()", ".weight().total()")
    (problem,) = problems(tmp_path, text)
    assert problem.endswith(
        f"scoring.total.fhirpath, at character {FORMULA.index('sum()') + 1}: total() is not in the kiosk's "
        "formula language (it has abs, ceiling, count, empty, exists, first, floor, iif, last, max, min, not, "
        "ordinal, round, sum, truncate, weight, where)"
    )
    text = STAFFED.replace("max: 5\n", "max: 3\n").replace("impaired, min: 2, max: 5", "impaired, min: 2, max: 3")
    (problem,) = problems(tmp_path, text)
    assert problem.endswith(
        "scoring.total.fhirpath: it gives 4 when recall is option 2, orientation is option 3, education is 9, "
        "judged is option 2; it must give one whole number from -1 to 3"
    )


def test_a_formula_total_needs_its_range(tmp_path):
    text = STAFFED.replace("    min: -1\n    max: 5\n", "")
    assert problems(tmp_path, text) == [
        f"{at(text, 'fhirpath:')}: scoring.total is missing 'max'",
        f"{at(text, 'fhirpath:')}: scoring.total is missing 'min'",
    ]
    text = STAFFED.replace("  total:\n", "  total: product\n  totalx:\n")
    assert f"{at(text, 'product')}: scoring.total is 'sum' or a formula ({{fhirpath, min, max}}), not 'product'" in (
        problems(tmp_path, text)
    )


def test_band_gaps_are_judged_on_the_totals_the_points_reach(tmp_path):
    # Lawton-like totals are 0..3: a band set leaving 2 out is refused, whatever the step
    text = instrument(
        "gap", choice("a", [1, 1, 0]) + choice("b", [0, 1]) + choice("c", [0, 1]), bands(("lo", 0, 1), ("hi", 3, 3))
    )
    assert problems(tmp_path, text) == [
        f"{at(text, 'min: 3') + 5}: band set 'main': bands leave a gap before 3 (a total of 2 is in no band)"
    ]
    # negative totals too: -2 is reachable, so a set starting at 0 leaves it out
    text = instrument("neg", choice("a", [-2, 0, 3]), bands(("lo", 0, 1), ("hi", 2, 3)))
    assert problems(tmp_path, text) == [
        f"{at(text, 'min: 0') + 5}: band set 'main': bands leave a gap before 0 (a total of -2 is in no band)"
    ]
    # a formula total: every whole number of its range must be in a band
    text = STAFFED.replace("{id: intact, min: -1", "{id: intact, min: 0")
    assert problems(tmp_path, text) == [
        f"{at(text, 'min: 0') + 5}: band set 'main': bands leave a gap before 0 (a total of -1 is in no band)"
    ]


def test_who_answers_is_patient_or_staff(tmp_path):
    text = LAWTON.replace("  - id: laundry\n", "  - id: laundry\n    answered_by: nurse\n")
    assert problems(tmp_path, text) == [
        f"{at(text, 'nurse')}: items[2].answered_by: 'nurse' is not one of ['patient', 'staff']"
    ]


def test_a_staff_item_needs_options_or_an_input(tmp_path):
    text = STAFFED.replace("    input: {type: integer, min: 0, max: 30, unit: a}\n", "")
    assert problems(tmp_path, text) == [
        f"{at(text, 'id: education')}: items[2] needs 'options', 'answers: yes_no' or 'input' (a number staff enter)"
    ]


def test_an_input_is_for_staff_and_has_a_sensible_range(tmp_path):
    text = STAFFED.replace('    answered_by: staff\n    text: {en: "education?"', '    text: {en: "education?"')
    found = problems(tmp_path, text)
    assert f"{at(text, 'input:')}: items[2]: only staff enter numbers: add answered_by: staff" in found
    assert f"{at(text, 'id: education')}: items[2] is missing 'spoken' (what the kiosk says to the patient)" in found
    text = STAFFED.replace("min: 0, max: 30", "min: 40, max: 30")
    assert problems(tmp_path, text) == [f"{at(text, '40')}: items[2].input: min 40 is above max 30"]
    text = STAFFED.replace("type: integer", "type: fraction")
    assert problems(tmp_path, text) == [
        f"{at(text, 'fraction')}: items[2].input.type: 'fraction' is not one of ['integer', 'decimal']"
    ]


def test_an_item_has_one_kind_of_answer(tmp_path):
    text = GDS.replace("    answers: yes_no\n", "    answers: yes_no\n    input: {type: integer, min: 0, max: 1}\n", 1)
    found = problems(tmp_path, text)
    assert f"{at(text, 'input:')}: items[0] has both 'answers' and 'input': give one" in found


def test_yes_no_needs_its_points_and_only_it_has_item_points(tmp_path):
    text = GDS.replace('    points: {"yes": 0, "no": 1}\n', "", 1)
    assert problems(tmp_path, text) == [
        f'{at(text, "id: satisfied")}: items[0] has answers: yes_no but no points ({{"yes": N, "no": N}})'
    ]
    text = LAWTON.replace("  - id: laundry\n", '  - id: laundry\n    points: {"yes": 1, "no": 0}\n')
    assert problems(tmp_path, text) == [
        f"{at(text, 'points: {')}: 'points' on items[2] is for 'answers: yes_no' items; give each option its own points"
    ]
    text = GDS.replace("answers: yes_no", "answers: yes_maybe", 1)
    assert problems(tmp_path, text)[0] == f"{at(text, 'yes_maybe')}: items[0].answers: 'yes_no' was expected"


def test_subscales_name_existing_scored_items_once_with_an_id_of_their_own(tmp_path):
    text = MIXED.replace("items: [sleep, appetite]", "items: [sleep, sleep, nap]").replace("id: rest", "id: pain")
    assert problems(tmp_path, text) == [
        f"{at(text, 'id: pain') + 4}: subscale id 'pain' is already an item's: give it its own",
        f"{at(text, 'sleep, nap')}: subscale 'pain' lists item 'sleep' twice",
        f"{at(text, 'nap')}: subscale 'pain': there is no item 'nap'",
    ]
    text = STAFFED + "scoring_extra: 1\n"
    assert problems(tmp_path, text) == [f"{at(text, 'scoring_extra')}: unknown key 'scoring_extra'"]


def test_a_translation_must_be_of_a_listed_language(tmp_path):
    text = GDS.replace("  es: {source: our own", "  fr: {source: our own")
    assert problems(tmp_path, text) == [
        f"{at(text, 'fr: {source')}: a translation for 'fr', which is not in 'languages'"
    ]


def test_staff_input_and_yes_no_helpers_build_valid_items(tmp_path):
    text = instrument(
        "both",
        yes_no("q", 1, 0) + staff_input("weight", "decimal", 20, 250.5, "kg"),
        bands(("all", 0, 1)),
    )
    q = load(tmp_path, text)
    assert q.item("weight").entry.type == "decimal" and q.item("weight").entry.fits(72.4)
    assert q.score_answers({"q": 1}, values={"weight": 72.4}).total == 1
    assert texts("x") == '{en: "x", es: "x (es)"}'


def test_validate_prints_each_v2_problem_as_one_line_and_fails(tmp_path, capsys):
    judged = STAFFED.index("  - id: judged")
    text = STAFFED[:judged] + STAFFED[judged:].replace("answered_by: staff", "answered_by: nurse", 1)
    text = text.replace("answer.value < 9", "answer.value <* 9")
    path = write(tmp_path, text)
    assert validate_main([str(path)]) == 1
    first, second = capsys.readouterr().out.splitlines()
    character = FORMULA.index("< 9") + 2  # the stray "*" after "<", counted from 1
    assert first == (
        f"{path}:{at(text, 'fhirpath:') + 10}: scoring.total.fhirpath, at character {character}: "
        "expected a value but found '*'"
    )
    assert second == f"{path}:{at(text, 'nurse')}: items[3].answered_by: 'nurse' is not one of ['patient', 'staff']"


def test_a_formula_that_fails_on_some_answers_gives_no_total_and_says_why(tmp_path):
    # the file's check tries the formula on a few sample responses; answers it did not try may
    # still take it outside its range: then the result has no total (never a wrong one, never a crash)
    from dataclasses import replace

    from kiosk.core.questionnaire import Formula

    q = load(tmp_path, STAFFED)
    narrow = replace(q, formula=Formula(q.formula.expression, -1, 2))
    score = narrow.score_answers({"recall": 3, "orientation": 2, "judged": 2}, values={"education": 12})
    assert (score.complete, score.band, score.missing) == (False, None, ())
    assert "gave 4, outside its declared -1 to 2" in score.problem
    fine = narrow.score_answers({"recall": 1, "orientation": 1, "judged": 1}, values={"education": 12})
    assert (fine.complete, fine.total, fine.problem) == (True, 0, "")


def test_a_synonym_that_is_a_voice_command_is_refused(tmp_path):
    # "wait" pauses the session in English: as an answer's synonym the patient saying it would pause
    text = LAWTON.replace(
        '        label: {en: "telephone 1", es: "telephone 1 (es)"}\n',
        '        label: {en: "telephone 1", es: "telephone 1 (es)"}\n        synonyms: {en: [on my own, Wait]}\n',
    )
    assert problems(tmp_path, text) == [
        f"{at(text, 'Wait')}: the synonym 'Wait' is the kiosk's 'pause' command in 'en': "
        "a patient saying it would pause instead of answering"
    ]

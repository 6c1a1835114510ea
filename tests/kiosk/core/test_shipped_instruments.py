"""The instruments shipped with the kiosk score as published, say where they come from, and speak
to the patient in plain words: the Lawton IADL, the GDS-15 and SARC-F beside the Barthel.

The published facts checked here are restated from each file's own citation (``source:``)."""

from __future__ import annotations

import re

import pytest

from kiosk.core.questionnaire import bundled_path, check_questionnaire_file, load_questionnaire

SHIPPED = ("barthel", "lawton", "gds15", "sarc_f")
#: GDS-15 items where "No" is the answer in the direction of depression (Sheikh & Yesavage 1986)
GDS_NO_SCORES = (1, 5, 7, 11, 13)


def instrument(name: str):
    return load_questionnaire(bundled_path(f"{name}.yaml"))


def yes_no(item) -> dict[str, int]:
    """The points of an item's Yes (option 1) and No (option 2)."""
    return {"yes": item.option(1).points, "no": item.option(2).points}


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_instrument_is_valid_and_names_its_translations(name):
    assert check_questionnaire_file(bundled_path(f"{name}.yaml")) == []
    q = instrument(name)
    assert set(q.translations) == set(q.languages)
    assert all(t.source.strip() for t in q.translations.values())
    # only the published English originals are validated; the team's own wording never is
    assert [lang for lang in q.languages if q.validated(lang)] == ["en"]


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_instrument_cites_its_published_source(name):
    q = instrument(name)
    author = {"barthel": "Mahoney", "lawton": "Lawton", "gds15": "Sheikh", "sarc_f": "Malmstrom"}[name]
    assert author in q.reference and re.search(r"19\d\d|20\d\d", q.reference)


def test_the_barthel_and_the_gds15_speak_german():
    for name in ("barthel", "gds15"):
        q = instrument(name)
        assert "de" in q.languages
        assert all(item.text["de"].strip() and item.spoken["de"].strip() for item in q.items)
    assert instrument("barthel").item("feeding").option(3).patient_label_in("de") == "Ich esse ohne Hilfe"


def test_lawton_scores_0_to_8_with_shared_points_and_five_levels():
    q = instrument("lawton")
    assert [i.id for i in q.items] == [
        "telephone",
        "shopping",
        "food",
        "housekeeping",
        "laundry",
        "transportation",
        "medications",
        "finances",
    ]
    assert {i.id: [o.points for o in i.options] for i in q.items} == {
        "telephone": [1, 1, 1, 0],
        "shopping": [1, 0, 0, 0],
        "food": [1, 0, 0, 0],
        "housekeeping": [1, 1, 1, 1, 0],
        "laundry": [1, 1, 0],
        "transportation": [1, 1, 1, 0, 0],
        "medications": [1, 0, 0],
        "finances": [1, 1, 0],
    }
    assert (q.min_total, q.max_total) == (0, 8)
    # "answers but does not dial" is as independent as "looks up and dials" (both score 1)
    highest = q.score_answers({i.id: 1 for i in q.items})
    same = q.score_answers({**{i.id: 1 for i in q.items}, "telephone": 3, "housekeeping": 4})
    assert highest.total == same.total == 8 and highest.complete
    lowest = q.score_answers({i.id: len(i.options) for i in q.items})
    assert lowest.total == 0
    assert q.code is None and q.total_code is None  # no code we could confirm: none invented


def test_gds15_scores_no_on_items_1_5_7_11_13_and_yes_on_the_others():
    q = instrument("gds15")
    assert len(q.items) == 15 and (q.min_total, q.max_total) == (0, 15)
    for item in q.items:
        expected = {"yes": 0, "no": 1} if item.number in GDS_NO_SCORES else {"yes": 1, "no": 0}
        assert yes_no(item) == expected, item.id
        assert [o.code.code for o in item.options] == ["LA33-6", "LA32-8"]
    depressed = {i.id: (2 if i.number in GDS_NO_SCORES else 1) for i in q.items}
    assert q.score_answers(depressed).total == 15
    assert q.score_answers({i.id: 3 - n for i, n in zip(q.items, depressed.values())}).total == 0
    assert q.total_code is not None and q.total_code.code == "48545-8"


@pytest.mark.parametrize(
    "total,default,graded",
    [(0, "normal", "normal"), (4, "normal", "normal"), (5, "normal", "mild"), (6, "suggests_depression", "mild"),
     (8, "suggests_depression", "mild"), (9, "suggests_depression", "moderate"), (12, "suggests_depression", "severe"),
     (15, "suggests_depression", "severe")],
)  # fmt: skip
def test_gds15_bands_more_than_5_suggests_depression_and_the_graded_set(total, default, graded):
    q = instrument("gds15")
    assert q.band_for(total).id == default
    assert q.band_for(total, "graded").id == graded


def test_sarc_f_scores_0_to_10_and_4_or_more_suggests_sarcopenia():
    q = instrument("sarc_f")
    assert [[o.points for o in i.options] for i in q.items] == [[0, 1, 2]] * 5
    assert (q.min_total, q.max_total) == (0, 10)
    three = q.score_answers(
        {"strength": 2, "assistance_walking": 2, "rise_from_chair": 2, "climb_stairs": 1, "falls": 1}
    )
    four = q.score_answers(
        {"strength": 2, "assistance_walking": 2, "rise_from_chair": 2, "climb_stairs": 2, "falls": 1}
    )
    assert (three.total, three.band.id) == (3, "not_suggestive")
    assert (four.total, four.band.id) == (4, "suggests_sarcopenia")


#: clinical words a patient's screen or voice must not use (the clinical label keeps them)
CLINICAL = re.compile(
    r"depress|sarcop|incontin|IADL|instrumental|dependen|independen|dépendan|autonom|selbstständig|abhängig",
    re.IGNORECASE,
)


@pytest.mark.parametrize("name", ("lawton", "gds15", "sarc_f"))
def test_the_patient_hears_and_reads_no_clinical_terms(name):
    q = instrument(name)
    said = [q.message(m, lang) for m in q.messages for lang in q.languages]
    said += [q.title_for_patient(lang) for lang in q.languages]  # the welcome's and top bar's name
    for item in q.patient_items:
        for lang in q.languages:
            said += [item.patient_text_in(lang), item.spoken[lang]]
            said += [o.patient_label_in(lang) for o in item.options]
    assert [s for s in said if CLINICAL.search(s)] == []


@pytest.mark.parametrize(
    "name,count,time_frame",
    [("lawton", "eight", "these days"), ("gds15", "fifteen", "past week"), ("sarc_f", "five", "past year")],
)
def test_the_explanation_says_how_many_questions_and_the_time_frame(name, count, time_frame):
    q = instrument(name)
    explanation = q.message("explanation", "en")
    assert count in explanation and time_frame in explanation
    assert len(q.patient_items) == {"eight": 8, "fifteen": 15, "five": 5}[count]

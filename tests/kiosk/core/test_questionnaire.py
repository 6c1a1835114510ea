"""The bundled Barthel questionnaire, scoring, and `kiosk validate` on every kind of mistake."""

from __future__ import annotations

import json

import jsonschema
import pytest

from kiosk.commands.validate import main as validate_main
from kiosk.core.questionnaire import (
    QuestionnaireError,
    Timing,
    bundled_path,
    check_questionnaire_file,
    load_questionnaire,
)

Q = load_questionnaire()
TEXT = bundled_path().read_text(encoding="utf-8")


def test_the_bundled_file_has_the_ten_barthel_items_in_three_languages():
    assert [i.id for i in Q.items] == [
        "feeding",
        "bathing",
        "grooming",
        "dressing",
        "bowels",
        "bladder",
        "toilet",
        "transfers",
        "mobility",
        "stairs",
    ]
    assert Q.languages == ("en", "es", "fr")
    assert sorted(len(i.options) for i in Q.items) == [2, 2, 3, 3, 3, 3, 3, 3, 4, 4]
    for item in Q.items:
        for lang in Q.languages:
            assert item.text[lang] and item.spoken[lang]
            assert all(o.label_in(lang) and o.synonyms_in(lang) for o in item.options)
        assert [o.number for o in item.options] == list(range(1, len(item.options) + 1))
        assert item.code is not None and item.code.system == "http://loinc.org"
    assert Q.item("transfers").points == {0, 5, 10, 15}
    assert [b.id for b in Q.bands] == ["total", "severe", "moderate", "slight", "independent"]
    assert Q.timing == Timing(20, 5, 10, 5, 5, 10)
    assert [p.checks for p in Q.familiarisation] == ["hear", "read", "select"]


def test_the_selecting_check_asks_for_answer_number_3_on_screen_and_aloud():
    select = next(p for p in Q.familiarisation if p.checks == "select")
    assert select.expected == 3 and len(select.options) == 3
    for lang, three in (("en", "three"), ("es", "tres"), ("fr", "trois")):
        assert "3" in select.text[lang] and three in select.spoken[lang]
        assert all(o.label_in(lang) for o in select.options)


def test_a_practice_question_checking_anything_else_is_refused(tmp_path):
    path, text = broken(tmp_path, "    checks: select", "    checks: count")
    (problem,) = check_questionnaire_file(path)
    assert str(problem).startswith(f"{path}:{position(text, 'count')}: familiarisation[2].checks:")
    assert "'hear', 'read', 'select'" in problem.message


def test_the_loinc_codes_are_marked_for_verification():
    assert TEXT.count("verify before shipping") >= 12


def test_scoring_edge_cases():
    lowest = Q.score({i.id: 0 for i in Q.items})
    assert (lowest.total, lowest.complete, lowest.band.id) == (0, True, "total")
    highest = Q.score({i.id: i.max_points for i in Q.items})
    assert (highest.total, highest.band.id, highest.max_total) == (100, "independent", 100)
    partial = Q.score({"feeding": 10, "stairs": 5})
    assert (partial.total, partial.complete, partial.band) == (15, False, None)
    assert partial.missing == tuple(i.id for i in Q.items if i.id not in ("feeding", "stairs"))
    with pytest.raises(ValueError, match="7 points is not an option of item 'feeding'"):
        Q.score({"feeding": 7})
    with pytest.raises(ValueError, match="15 points is not an option of item 'stairs'"):
        Q.score({"stairs": 15})
    with pytest.raises(ValueError, match="unknown item 'walking'"):
        Q.score({"walking": 5})
    with pytest.raises(ValueError):
        Q.score({"bathing": True})


@pytest.mark.parametrize(
    ("total", "band"),
    [
        (20, "total"),
        (21, "severe"),
        (60, "severe"),
        (61, "moderate"),
        (90, "moderate"),
        (95, "slight"),
        (100, "independent"),
    ],
)
def test_bands_follow_shah(total, band):
    assert Q.band_for(total).id == band


@pytest.mark.parametrize(
    ("total", "band"),
    [
        (0, "total"),
        (15, "total"),
        (20, "severe"),
        (35, "severe"),
        (40, "moderate"),
        (55, "moderate"),
        (60, "mild"),
        (95, "mild"),
        (100, "independent"),
    ],
)
def test_the_spanish_band_set_follows_its_published_cut_offs(total, band):
    assert Q.band_for(total, "spanish").id == band
    assert Q.with_band_set("spanish").band_for(total).id == band


def test_shah_is_the_default_and_the_spanish_set_says_its_source_is_unconfirmed():
    assert Q.band_set == "shah" and "Shah" in Q.band_source
    assert set(Q.band_sets) == {"shah", "spanish"}
    assert "unconfirmed source" in Q.band_sets["spanish"].source
    assert "UNCONFIRMED SOURCE" in TEXT


def test_scoring_with_another_band_set():
    points = {i.id: i.max_points for i in Q.items} | {
        "feeding": 0,
        "bathing": 0,
        "grooming": 0,
        "stairs": 0,
        "transfers": 5,
    }
    shah, spanish = Q.score(points), Q.score(points, "spanish")
    assert shah.total == spanish.total == 60
    assert (shah.band.id, shah.band_set) == ("severe", "shah")
    assert (spanish.band.id, spanish.band_set) == ("mild", "spanish")
    chosen = Q.with_band_set("spanish")
    assert chosen.score(points) == spanish and chosen.bands == Q.band_sets["spanish"].bands
    assert Q.score(points) == shah  # choosing a set made a copy
    with pytest.raises(KeyError, match="no band set 'castilian' in barthel \\(it has shah, spanish\\)"):
        Q.with_band_set("castilian")
    with pytest.raises(KeyError):
        Q.score(points, "castilian")


def test_timing_overrides_are_checked():
    assert Q.timing.with_overrides({"attempt_window_s": 30}).attempt_window_s == 30
    with pytest.raises(ValueError, match="unknown timing setting 'window'"):
        Q.timing.with_overrides({"window": 3})
    with pytest.raises(ValueError, match="must be a number of seconds from 0 to 86400"):
        Q.timing.with_overrides({"closing_s": -1})


def test_the_schema_is_a_valid_json_schema_that_accepts_the_bundled_file():
    import yaml

    schema = json.loads(bundled_path("questionnaire.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(yaml.safe_load(TEXT), schema)


class Where(str):
    """'line:col'; adding n moves the column right (to point past a leading space)."""

    def __add__(self, n):
        line, col = self.split(":")
        return Where(f"{line}:{int(col) + n}")


def position(text: str, needle: str, nth: int = 0) -> Where:
    """'line:col' of the nth occurrence of needle."""
    index = -1
    for _ in range(nth + 1):
        index = text.index(needle, index + 1)
    line = text.count("\n", 0, index) + 1
    return Where(f"{line}:{index - text.rfind(chr(10), 0, index)}")


def broken(tmp_path, old: str, new: str, count: int = 1):
    assert old in TEXT, old
    text = TEXT.replace(old, new, count)
    path = tmp_path / "barthel.yaml"
    path.write_text(text, encoding="utf-8")
    return path, text


def test_duplicate_ids(tmp_path):
    path, text = broken(tmp_path, "  - id: bathing", "  - id: feeding")
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{position(text, 'feeding', 1)}: duplicate id 'feeding' (also used at items[0])"
    ]


def test_missing_translation(tmp_path):
    path, text = broken(
        tmp_path,
        "      fr: Comment faites-vous pour vous habiller, y compris les boutons, les fermetures et les lacets ?\n",
        "",
    )
    spoken = text.index("spoken:", text.index("id: dressing"))
    line = text.count("\n", 0, spoken) + 1
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{line + 1}:7: items[3].spoken has no 'fr' translation"
    ]


def test_option_without_points(tmp_path):
    path, text = broken(tmp_path, '      - points: 0\n        label: {en: "Unable"', '      - label: {en: "Unable"')
    where = position(text, 'label: {en: "Unable"')
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{where}: items[0].options[0] is missing 'points'"
    ]


def test_points_of_any_size_are_accepted_and_bands_judged_on_the_totals_they_reach(tmp_path):
    """Format v2 drops the multiple-of-5 rule: 12 points for transfers is a valid option, and
    the bands are then judged on the totals it gives (the highest is 97, not 100)."""
    path, text = broken(
        tmp_path,
        '      - points: 15\n        label: {en: "Independent"',
        '      - points: 12\n        label: {en: "Independent"',
    )
    messages = [p.message for p in check_questionnaire_file(path)]
    assert "band set 'shah': bands end at 100 but the highest possible total is 97" in messages
    assert not any("multiple of 5" in m for m in messages)


def test_unknown_keys(tmp_path):
    path, text = broken(tmp_path, "  - id: grooming\n", "  - id: grooming\n    colour: blue\n")
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{position(text, 'colour')}: unknown key 'colour' in items[2]"
    ]


def test_yaml_syntax(tmp_path):
    path, text = broken(tmp_path, "languages: [en, es, fr]", "languages: [en, es, fr")
    (problem,) = check_questionnaire_file(path)
    assert str(problem).startswith(f"{path}:") and "YAML syntax" in problem.message


def test_duplicate_keys_are_not_silently_merged(tmp_path):
    path, text = broken(tmp_path, "id: barthel\n", "id: barthel\nid: barthel2\n")
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{position(text, 'id: barthel2')}: duplicate key 'id'"
    ]


def test_bands_with_a_gap(tmp_path):
    path, text = broken(tmp_path, "          min: 61", "          min: 70")
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{position(text, ' 70') + 1}: band set 'shah': bands leave a gap before 70 "
        "(a total of 65 is in no band)"
    ]


def test_a_gap_no_total_can_fall_in_is_not_a_gap(tmp_path):
    """Totals go in steps of 5: Shah's 61 could be written 65 without leaving any total out."""
    path, _ = broken(tmp_path, "          min: 61", "          min: 65")
    assert check_questionnaire_file(path) == []


def test_overlapping_bands(tmp_path):
    path, text = broken(tmp_path, "          min: 40\n", "          min: 30\n")
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{position(text, ' 30') + 1}: band set 'spanish': bands 'severe' and 'moderate' overlap "
        "(30 to 35 are in both)"
    ]


def test_bands_that_stop_short_of_the_highest_total(tmp_path):
    path, text = broken(
        tmp_path, "          min: 100\n          max: 100\n", "          min: 96\n          max: 99\n", count=2
    )
    where = {name: position(text, "- id: total", nth) for nth, name in enumerate(("shah", "spanish"))}
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{where['shah']}: band set 'shah': bands end at 99 but the highest possible total is 100",
        f"{path}:{position(text, ' 96') + 1}: band set 'shah': bands 'slight' and 'independent' overlap "
        "(96 to 99 are in both)",
        f"{path}:{where['spanish']}: band set 'spanish': bands end at 99 but the highest possible total is 100",
    ]


def test_the_default_band_set_must_exist(tmp_path):
    path, text = broken(tmp_path, "  default: shah", "  default: barthel")
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{position(text, 'default: barthel') + 9}: the default band set 'barthel' is not one of the sets "
        "(shah, spanish)"
    ]


def test_bands_in_the_old_single_set_shape_are_refused_by_name(tmp_path):
    path, text = broken(tmp_path, "  default: shah\n  sets:\n", "  source: mine\n  ranges:\n")
    messages = [p.message for p in check_questionnaire_file(path)]
    assert "bands is missing 'sets'" in messages and "unknown key 'ranges' in bands" in messages


def test_every_problem_is_reported_at_once_and_loading_refuses_the_file(tmp_path, capsys):
    text = (
        TEXT.replace("  - id: bathing", "  - id: feeding")
        .replace("  - id: grooming\n", "  - id: grooming\n    colour: blue\n")
        .replace(
            '      - points: 5\n        label: {en: "Occasional accident"',
            '      - points: six\n        label: {en: "Occasional accident"',
            1,
        )
    )
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    assert validate_main([str(path)]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 3
    assert any("duplicate id" in line for line in lines) and any("colour" in line for line in lines)
    assert any("'six' is not of type 'integer'" in line for line in lines)
    with pytest.raises(QuestionnaireError) as caught:
        load_questionnaire(path)
    assert len(caught.value.problems) == 3 and "and 2 more problems" in str(caught.value)


def test_validate_accepts_the_bundled_file_and_reports_unreadable_ones(tmp_path, capsys):
    assert validate_main([str(bundled_path())]) == 0
    assert (
        validate_main([str(tmp_path / "missing.yaml")]) == 2
    )  # not a questionnaire at all, as opposed to one with problems (1)
    assert "missing.yaml:1:1: cannot read the file" in capsys.readouterr().out


def test_loading_a_missing_file_is_a_questionnaire_error(tmp_path):
    with pytest.raises(QuestionnaireError, match="missing.yaml:1:1: cannot read the file"):
        load_questionnaire(tmp_path / "missing.yaml")


def test_a_patient_wording_needs_every_language_and_only_text(tmp_path):
    path, text = broken(
        tmp_path,
        'patient: {en: "Sometimes", es: "A veces", fr: "Parfois"}',
        'patient: {en: "Sometimes", es: "A veces"}',
    )
    where = position(text, '{en: "Sometimes", es: "A veces"}')
    assert [str(p) for p in check_questionnaire_file(path)] == [
        f"{path}:{where}: items[4].options[1].patient has no 'fr' translation"
    ]
    path, text = broken(tmp_path, '    patient:\n      en: "How do you manage eating?"', '    patient:\n      en: ""')
    problems = [p.message for p in check_questionnaire_file(path)]
    assert len(problems) == 1 and "items[0].patient.en" in problems[0]


def test_without_a_patient_wording_the_screen_shows_the_clinical_one(tmp_path):
    path, _ = broken(tmp_path, '        patient: {en: "Sometimes", es: "A veces", fr: "Parfois"}\n', "")
    questionnaire = load_questionnaire(path)
    option = questionnaire.item("bowels").option(2)
    assert option.patient_label_in("en") == option.label_in("en") == "Occasional accident"
    assert questionnaire.item("bowels").option(3).patient_label_in("es") == "No, nunca"


def test_a_spoken_text_holds_no_mark_but_ways(tmp_path):
    """A clinician's typo in a mark ("{way}") would be read aloud to the patient."""
    path, text = broken(tmp_path, "number three. {ways}\n      es:", "number three. {way}\n      es:")
    (problem,) = check_questionnaire_file(path)
    line = text.count("\n", 0, text.index("{way}")) + 1
    assert str(problem).startswith(f"{path}:{line}:") and "{way} would be said aloud" in str(problem)
    assert check_questionnaire_file(broken(tmp_path, "Sí", "Sí")[0]) == []  # the shipped text is fine

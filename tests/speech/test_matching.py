"""Utterance → option or command, table-driven per language, on Barthel-shaped questions."""

from __future__ import annotations

import pytest

from kiosk.channels import Command
from kiosk.speech.matching import Matcher, OptionWords, normalise, spoken_label

#: the feeding item (3 options) in each language, with voice synonyms as the questionnaire gives them
FEEDING = {
    "en": [OptionWords("unable", ("cannot", "can't")),
           OptionWords("needs help (cutting, spreading) or modified diet", ("needs help", "some help")),
           OptionWords("independent", ("alone", "by myself"))],
    "es": [OptionWords("incapaz", ("no puedo",)),
           OptionWords("necesita ayuda (cortar, untar) o dieta modificada", ("necesita ayuda", "con ayuda")),
           OptionWords("independiente", ("solo", "sola"))],
    "fr": [OptionWords("incapable", ("je ne peux pas",)),
           OptionWords("a besoin d'aide (couper, tartiner) ou régime adapté", ("a besoin d'aide", "avec aide")),
           OptionWords("indépendant", ("seul", "seule", "indépendante"))],
}

#: transfers (4 options), where one option's words sit inside another's
TRANSFERS_EN = [OptionWords("unable, no sitting balance", ("unable",)),
                OptionWords("major help", ("a lot of help",)),
                OptionWords("minor help", ("a little help",)),
                OptionWords("independent")]

CASES = {
    "en": [
        ("independent", 3, None), ("Independent.", 3, None), ("I can do it by myself", 3, None),
        ("needs help", 2, None), ("unable", 1, None), ("I can't", 1, None),
        ("two", 2, None), ("number two", 2, None), ("the second", 2, None),
        ("the second one", 2, None), ("option 2", 2, None), ("3", 3, None), ("first", 1, None),
        ("repeat", None, Command.REPEAT), ("say that again", None, Command.REPEAT),
        ("pause", None, Command.PAUSE), ("continue", None, Command.RESUME),
        ("call the doctor", None, Command.CALL_DOCTOR), ("louder", None, Command.VOLUME_UP),
        ("quieter", None, Command.VOLUME_DOWN),
    ],
    "es": [
        ("independiente", 3, None), ("Independiente", 3, None), ("sola", 3, None),
        ("necesita ayuda", 2, None), ("incapaz", 1, None), ("no puedo", 1, None),
        ("dos", 2, None), ("la dos", 2, None), ("número dos", 2, None), ("numero dos", 2, None),
        ("la segunda", 2, None), ("opción 3", 3, None), ("la primera", 1, None), ("uno", 1, None),
        ("repite", None, Command.REPEAT), ("otra vez", None, Command.REPEAT),
        ("pausa", None, Command.PAUSE), ("continúa", None, Command.RESUME),
        ("llama al médico", None, Command.CALL_DOCTOR), ("LLAMA AL MEDICO", None, Command.CALL_DOCTOR),
        ("más alto", None, Command.VOLUME_UP), ("mas bajo", None, Command.VOLUME_DOWN),
    ],
    "fr": [
        ("indépendant", 3, None), ("independante", 3, None), ("seul", 3, None),
        ("a besoin d'aide", 2, None), ("incapable", 1, None), ("je ne peux pas", 1, None),
        ("deux", 2, None), ("numéro deux", 2, None), ("le deuxième", 2, None),
        ("la seconde", 2, None), ("option 2", 2, None), ("trois", 3, None), ("un", 1, None),
        ("le premier", 1, None), ("répétez", None, Command.REPEAT), ("pause", None, Command.PAUSE),
        ("continuez", None, Command.RESUME), ("appelez le médecin", None, Command.CALL_DOCTOR),
        ("plus fort", None, Command.VOLUME_UP), ("moins fort", None, Command.VOLUME_DOWN),
    ],
}


@pytest.mark.parametrize(
    "language,utterance,option,command",
    [(lang, u, o, c) for lang, rows in CASES.items() for u, o, c in rows],
)
def test_utterance_matches(language, utterance, option, command):
    match = Matcher(FEEDING[language], language).match(utterance, confidence=0.9)
    assert (match.option, match.command, match.reason) == (option, command, "")


NO_MATCH = [
    ("en", "banana", "not an answer"), ("en", "", "nothing recognisable"),
    ("en", "[unk]", "nothing recognisable"), ("en", "[unk] [unk]", "nothing recognisable"),
    ("en", "four", "no option 4"), ("en", "number nine", "no option 9"),
    ("en", "independent or needs help", "ambiguous"), ("en", "two three", "not an answer"),
    ("en", "the weather is nice", "not an answer"),
    ("es", "cinco", "no option 5"), ("es", "solo necesita ayuda", "ambiguous"),
    ("es", "hace buen tiempo", "not an answer"),
    ("fr", "quatre", "no option 4"), ("fr", "il fait beau", "not an answer"),
    ("fr", "seul avec aide", "ambiguous"),
]


@pytest.mark.parametrize("language,utterance,reason", NO_MATCH)
def test_no_match_says_why(language, utterance, reason):
    match = Matcher(FEEDING[language], language).match(utterance, confidence=0.9)
    assert not match.matched
    assert reason in match.reason


def test_unsure_recognition_is_not_an_answer():
    matcher = Matcher(FEEDING["en"], "en", min_confidence=0.6)
    assert matcher.match("independent", confidence=0.59).reason.startswith("unsure recognition")
    assert matcher.match("independent", confidence=0.6).option == 3
    assert matcher.match("independent", confidence=None).option == 3  # channels without a score


def test_longer_phrase_wins_over_a_phrase_inside_it():
    matcher = Matcher(TRANSFERS_EN, "en")
    assert matcher.match("minor help").option == 3
    assert matcher.match("major help").option == 2
    assert matcher.match("unable no sitting balance").option == 1
    assert matcher.match("four").option == 4


def test_phrases_cover_labels_synonyms_numbers_and_commands_once():
    phrases = Matcher(FEEDING["es"], "es").phrases()
    assert "necesita ayuda o dieta modificada" in phrases  # the parenthesised detail is not said
    assert {"independiente", "solo", "la dos", "número tres", "la segunda", "llama al médico"} <= set(phrases)
    assert "cuatro" not in phrases  # only numbers this question has
    assert len({normalise(p) for p in phrases}) == len(phrases)


@pytest.mark.parametrize("language", ["en", "es", "fr"])
def test_every_grammar_phrase_matches_something_or_is_ambiguous_by_design(language):
    """Everything the recogniser can hear for a question has a meaning for the matcher."""
    matcher = Matcher(FEEDING[language], language)
    for phrase in matcher.phrases():
        assert matcher.match(phrase).matched, phrase


def test_meaning_groups_phrases_by_what_they_select():
    """What the recognisers group grammar phrases by (confusable words, whole answers)."""
    matcher = Matcher(TRANSFERS_EN, "en")
    assert [matcher.meaning(p) for p in ("the first one", "one", "unable", "the third one", "minor help")] == \
        [1, 1, 1, 3, 3]
    assert matcher.meaning("call the nurse") == matcher.meaning("doctor") == Command.CALL_DOCTOR
    assert matcher.meaning("help") == "help"  # fits two options: it means only itself


def test_normalise_and_spoken_label():
    assert normalise("¿Número DOS?") == "numero dos"
    assert normalise("l'option") == "l option"
    assert spoken_label("independent (bath or shower, unsupervised)") == "independent"


def test_unknown_language_is_one_clear_error():
    with pytest.raises(ValueError, match="no speech vocabulary for language 'de'"):
        Matcher(FEEDING["en"], "de")


def test_every_label_and_synonym_of_the_bundled_questionnaire_selects_its_own_option():
    """A clinician editing barthel.yaml could give two options the same word; that would make
    a spoken answer ambiguous (never recorded). The bundled file has no such clash."""
    from kiosk.questionnaire import load_questionnaire

    questionnaire = load_questionnaire()
    clashes = []
    for question in (*questionnaire.items, *questionnaire.familiarisation):
        for language in questionnaire.languages:
            matcher = Matcher([OptionWords(o.label_in(language), o.synonyms_in(language))
                               for o in question.options], language)
            for option in question.options:
                for phrase in (option.label_in(language), *option.synonyms_in(language)):
                    if (got := matcher.match(phrase)).option != option.number:
                        clashes.append((question.id, language, phrase, got))
    assert clashes == []

"""Recognisers and grammars: dictionary checks, grammar formats, real decoding of espeak-ng audio."""

from __future__ import annotations

import json
import logging

import pytest

from kiosk.speech.asr import (
    AsrUnavailable,
    PocketSphinxRecogniser,
    Recognition,
    VoskRecogniser,
    accent_variants,
    vosk_recognition,
)
from kiosk.speech.audio import UtterancePipeline, feed_wav
from kiosk.speech.grammar import (
    Grammar,
    build_grammar,
    confusable_phrases,
    final_phrases,
    recogniser_words,
    to_jsgf,
    to_vosk,
)
from kiosk.speech.matching import Matcher, OptionWords


def test_build_grammar_leaves_out_unknown_words_and_says_why(caplog):
    known = {"needs", "help", "two", "doctor"}.__contains__
    with caplog.at_level(logging.INFO, logger="kiosk.speech.grammar"):
        grammar = build_grammar(["Needs help", "two", "zorblax two", "Doctor!", "two"], known, "test")
    assert grammar.phrases == ("needs help", "two", "doctor")
    assert grammar.dropped == (("zorblax two", "'zorblax' not in the test dictionary"),)
    assert "leaving out 'zorblax two'" in caplog.text


def test_grammar_formats():
    grammar = Grammar(("número dos", "l'option", "two"))
    assert to_jsgf(grammar) == (
        "#JSGF V1.0;\ngrammar answer;\n<phrase> = número dos | l'option | two ;\npublic <answer> = <phrase> ;\n"
    )
    assert json.loads(to_vosk(grammar)) == ["número dos", "l'option", "two", "[unk]"]
    full = build_grammar(
        ["two", "help", "repeat"],
        lambda w: True,
        "test",
        ["i need"],
        ["um", "what"],
        lambda p: "repeat" if p == "repeat" else 2,
    )
    assert to_jsgf(full) == (
        "#JSGF V1.0;\ngrammar answer;\n<lead> = i need ;\n<option> = two | help ;\n"
        "<other> = repeat ;\n<filler> = um | what ;\n"
        "public <answer> = /0.95/ ([<lead>] <option> | <other>) | /0.05/ <filler> ;\n"
    )
    assert json.loads(to_vosk(full)) == ["two", "help", "repeat", "i need two", "i need help", "um", "what", "[unk]"]
    assert full.core("i need help") == "help" and full.core("i need repeat") == "i need repeat"
    assert recogniser_words("Sube el volumen, ¿vale?") == ["sube", "el", "volumen", "vale"]
    with pytest.raises(ValueError, match="at least one phrase"):
        to_jsgf(Grammar(()))


def test_pocketsphinx_checks_its_real_dictionary():
    recogniser = PocketSphinxRecogniser("en")
    grammar = recogniser.set_grammar(["independent", "needs help", "independiente", "number two"])
    assert grammar.phrases == ("independent", "needs help", "number two")
    assert grammar.dropped[0][0] == "independiente"


def test_pocketsphinx_is_english_only():
    with pytest.raises(
        AsrUnavailable, match="pocketsphinx only ships English; install one with `kiosk models install fr`"
    ):
        PocketSphinxRecogniser("fr")


def test_pocketsphinx_needs_a_grammar_first():
    with pytest.raises(RuntimeError, match="set_grammar"):
        PocketSphinxRecogniser("en").accept(b"\0\0" * 160)


@pytest.mark.slow  # real audio (espeak-ng)
def test_pocketsphinx_decodes_speech_and_scores_it(spoken):
    recogniser = PocketSphinxRecogniser("en")
    recogniser.set_grammar(["unable", "needs help", "independent", "one", "two", "three", "repeat"])
    heard = []
    pipeline = UtterancePipeline(recogniser, heard.append)
    for text in ("independent", "the weather is nice today"):
        feed_wav(spoken(text), pipeline)
    answer, sentence = (u.result for u in heard)
    assert answer.text == "independent" and answer.confidence > 0.9
    # a sentence is forced onto the grammar too, but mostly into silence: low confidence
    assert sentence.confidence < 0.3
    assert recogniser.finish().text == ""  # nothing in progress


def test_vosk_results_are_combined_and_unknown_words_are_not_answers():
    """Vosk's JSON (as KaldiRecognizer.Result/FinalResult print it with SetWords(True))."""
    two = '{"result": [{"conf": 0.93, "end": 1.2, "start": 0.9, "word": "two"}], "text": "two"}'
    number = '{"result": [{"conf": 0.71, "end": 0.8, "start": 0.4, "word": "number"}], "text": "number"}'
    unk = (
        '{"result": [{"conf": 1.0, "end": 0.5, "start": 0.2, "word": "[unk]"}, '
        '{"conf": 0.98, "end": 1.0, "start": 0.6, "word": "independent"}], "text": "[unk] independent"}'
    )
    assert vosk_recognition([number, two]) == Recognition("number two", 0.71)
    assert vosk_recognition([two, '{"text": ""}']) == Recognition("two", 0.93)
    assert vosk_recognition([unk]) == Recognition("[unk] independent", 0.0)
    assert vosk_recognition(['{"text": ""}']) == Recognition("", 0.0)


def test_vosk_backend_reports_a_missing_model_clearly(tmp_path):
    with pytest.raises(AsrUnavailable, match=f"vosk model {tmp_path / 'none'} does not exist"):
        VoskRecogniser(tmp_path / "none", "es")


def test_confusable_phrases_only_where_the_partner_means_something_else():
    first_third = (frozenset({"first", "third"}),)
    three = ["the first one", "first", "the second one", "the third one", "one", "repeat"]
    meaning = {
        "the first one": 1,
        "first": 1,
        "one": 1,
        "the second one": 2,
        "the third one": 3,
        "repeat": "repeat",
    }.__getitem__
    assert confusable_phrases(three, meaning, first_third) == {"the first one", "first", "the third one"}
    two = [p for p in three if p != "the third one"]
    assert confusable_phrases(two, meaning, first_third) == frozenset()
    # both words selecting the same thing are not a risk
    assert confusable_phrases(["first", "third"], lambda p: 1, first_third) == frozenset()
    # without meanings every phrase means only itself
    assert confusable_phrases(["first", "third"], lambda p: p, first_third) == {"first", "third"}


@pytest.mark.slow  # real audio (espeak-ng)
def test_pocketsphinx_flags_first_and_third_as_confusable(spoken):
    """espeak-ng's "the first one" sounds like "the third one" to the wheel's model: with a third
    option the result is flagged confusable (the voice channel then always asks the patient),
    with two options it is an ordinary answer."""
    path = spoken("the first one")
    recogniser = PocketSphinxRecogniser("en")
    heard = []
    pipeline = UtterancePipeline(recogniser, heard.append)
    matchers = [Matcher([OptionWords(w) for w in ("unable", "needs help", "independent")[:n]], "en") for n in (3, 2)]
    for matcher in matchers:
        recogniser.set_grammar(matcher.phrases(), matcher.meaning)
        feed_wav(path, pipeline)
    with_third, with_two = (u.result for u in heard)
    assert with_third.confusable and matchers[0].match(with_third.text).option in (1, 3)
    assert not with_two.confusable
    assert matcher.match(with_two.text, with_two.confidence).option == 1


def test_accent_variants_drop_an_r_before_no_vowel():
    assert accent_variants("N AH M B ER") == ["N AH M B AH"]
    assert accent_variants("F AO R") == ["F AO"]
    assert accent_variants("W IY L CH EH R") == ["W IY L CH EH"]
    assert accent_variants("S T AA R T") == ["S T AA T"]
    # an r before a vowel is spoken; "first" keeps its vowel; nothing to change gives nothing
    assert accent_variants("S AA R IY") == accent_variants("F ER S T") == accent_variants("Y EH S") == []


def test_pocketsphinx_adds_accent_pronunciations_for_the_grammars_words():
    recogniser = PocketSphinxRecogniser("en")
    recogniser.set_grammar(["number one", "four", "yes"])
    lookup = recogniser._decoder.lookup_word
    assert lookup("number(2)") == "N AH M B AH" and lookup("four(2)") == "F AO"
    assert lookup("one(2)") == "W AA N" and lookup("yes(2)") is None
    recogniser.set_grammar(["number one"])  # added once, not again
    assert lookup("number(3)") is None


def test_final_phrases_are_those_nothing_of_another_meaning_continues():
    meaning = {
        "the second": 2,
        "the second one": 2,
        "help": 2,
        "help me up": 1,
        "one": 1,
        "repeat": "repeat",
        "repeat that": "repeat",
    }.__getitem__
    phrases = ["the second", "the second one", "help", "help me up", "one", "repeat", "repeat that"]
    assert final_phrases(phrases, meaning) == {
        "the second",
        "the second one",
        "help me up",
        "one",
        "repeat",
        "repeat that",
    }


@pytest.mark.slow  # real audio (espeak-ng)
def test_pocketsphinx_says_when_a_whole_answer_was_heard(spoken):
    """A whole answer ends after the short hangover, once the decoder has settled on a voice."""
    path = spoken("independent")
    recogniser = PocketSphinxRecogniser("en")
    matcher = Matcher([OptionWords(w) for w in ("unable", "needs help", "independent")], "en")
    recogniser.set_grammar(matcher.phrases(), matcher.meaning)
    heard = []
    pipeline = UtterancePipeline(recogniser, heard.append)
    feed_wav(path, pipeline)
    feed_wav(path, pipeline)
    first, second = heard
    assert not first.complete  # a fresh decoder: the long hangover
    assert second.complete and second.result.text == "independent" and second.result.confidence > 0.9
    assert second.endpoint - second.speech_end < first.endpoint - first.speech_end

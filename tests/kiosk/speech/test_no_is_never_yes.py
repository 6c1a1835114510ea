"""Never a wrong answer stored (issue 33, part 2): a spoken no, in any of the ways people say it,
is never taken as yes at "Is that right?". The rules of :class:`kiosk.speech.listening.Listening`
over many phrasings in the four languages, without audio; test_voice_safety.py hears some of
them end to end with espeak-ng and pocketsphinx."""

from __future__ import annotations

import pytest

from basis import record
from kiosk.core.session.words import CONFIRM_WORDS
from kiosk.speech.asr import Recognition
from kiosk.speech.audio import Utterance
from kiosk.speech.listening import YES_MIN_CONFIDENCE, Listening
from kiosk.speech.matching import Matcher, OptionWords, heard_negation
from kiosk.speech.voice import CONFIRM_BELOW, REPLY_MIN_ABOVE_ROOM_DB

#: how patients say no to "I heard: Independent. Is that right?", per language
NO_PHRASINGS = {
    "en": [
        "no",
        "no no",
        "no no no",
        "nope",
        "nah",
        "that's not what I said",
        "not what I said",
        "not really",
        "that's wrong",
        "no that's wrong",
        "no I said two",
        "no I said independent",
        "that's not right",
        "no it's not",
        "not at all",
        "wrong",
        "no it isn't",
    ],
    "es": [
        "no",
        "no no",
        "eso no es lo que dije",
        "no es lo que dije",
        "no dije eso",
        "para nada",
        "está mal",
        "no es correcto",
        "que no",
        "no, yo dije dos",
        "incorrecto",
    ],
    "fr": [
        "non",
        "non non",
        "ce n'est pas ce que j'ai dit",
        "pas vraiment",
        "non j'ai dit deux",
        "pas du tout",
        "c'est faux",
        "mais non",
        "c'est pas ça",
        "ce n'est pas ça",
    ],
    "de": [
        "nein",
        "nein nein",
        "das habe ich nicht gesagt",
        "nicht wirklich",
        "nein ich sagte zwei",
        "überhaupt nicht",
        "das stimmt nicht",
        "falsch",
        "eher nicht",
        "nee",
    ],
}
CASES = [(language, phrase) for language, phrases in NO_PHRASINGS.items() for phrase in phrases]
YES = {"en": "yes", "es": "sí", "fr": "oui", "de": "ja"}


def _confirm_options(language: str) -> list[OptionWords]:
    """The "Is that right?" prompt's options as the session builds them (Yes 1, No 2)."""
    return [OptionWords(label, tuple(words)) for label, words in CONFIRM_WORDS[language].values()]


def _listening(language: str, key: str = "feeding") -> Listening:
    listening = Listening(
        min_confidence=0.6, confirm_below=CONFIRM_BELOW, reply_min_above_room_db=REPLY_MIN_ABOVE_ROOM_DB
    )
    listening.set_question(_confirm_options(language), scored=False, welcome=False, key=key, confirming=True)
    assert listening.grammar(language)
    return listening


@record
class FreeHearing:
    """A recognition from a recogniser that also hears without the grammar: it fills the hook
    ``transcript`` (what the listening rules read besides ``Recognition``'s own fields)."""

    text: str
    confidence: float
    transcript: str
    confusable: bool = False


def _heard(text: str, confidence: float, transcript: str | None = None) -> Utterance:
    """An utterance the grammar heard as ``text``; ``transcript``: what a free hearing made of it."""
    result = Recognition(text, confidence) if transcript is None else FreeHearing(text, confidence, transcript)
    return Utterance(result, 0.0, 0.5, 0.8, 0.01)


@pytest.mark.parametrize("language,phrase", CASES)
def test_a_no_heard_as_said_is_no_or_nothing_never_yes(language, phrase):
    matcher = Matcher(_confirm_options(language), language)
    assert matcher.match(phrase).option != 1
    assert heard_negation(phrase, language)


@pytest.mark.parametrize("language,phrase", CASES)
def test_a_confident_yes_whose_free_hearing_is_a_no_is_never_taken(language, phrase):
    """The grammar forced the reply onto "yes" at 0.95, but the free transcript says no: not a
    yes the session may act on (the session asks for a press)."""
    heard = _listening(language).hear(_heard(YES[language], 0.95, transcript=phrase))
    assert isinstance(heard, str) or heard.option != 1 or heard.needs_confirmation


@pytest.mark.parametrize("language", NO_PHRASINGS)
def test_a_yes_needs_the_stricter_floor_or_a_second_hearing(language):
    listening = _listening(language)
    low = YES_MIN_CONFIDENCE - 0.15  # where "no no" was heard as yes (0.64-0.65)
    first = listening.hear(_heard(YES[language], low))
    assert (first.option, first.needs_confirmation) == (1, True)
    second = listening.hear(_heard(YES[language], low))  # said again (or the press prompt's yes)
    assert (second.option, second.needs_confirmation) == (1, False)
    sure = _listening(language).hear(_heard(YES[language], YES_MIN_CONFIDENCE + 0.05))
    assert (sure.option, sure.needs_confirmation) == (1, False)


def test_a_no_between_two_unsure_yeses_means_they_do_not_agree():
    listening = _listening("en")
    assert listening.hear(_heard("yes", 0.65)).needs_confirmation
    no = listening.hear(_heard("no", 0.62))  # a "no" declines at the matcher's own floor
    assert (no.option, no.needs_confirmation) == (2, False)
    assert listening.hear(_heard("yes", 0.65)).needs_confirmation


def test_a_second_hearing_counts_on_the_same_confirmation_only():
    listening = _listening("en", key="feeding")
    assert listening.hear(_heard("yes", 0.65)).needs_confirmation
    listening.set_question(
        _confirm_options("en"), scored=False, welcome=False, key="feeding", confirming=True, again=True
    )
    listening.grammar("en")  # "Is that right? Please press Yes or No": the same confirmation asked again
    assert not listening.hear(_heard("yes", 0.65)).needs_confirmation
    assert listening.hear(_heard("yes", 0.65)).needs_confirmation  # a fresh pair is needed again
    listening.set_question(_confirm_options("en"), scored=False, welcome=False, key="bathing", confirming=True)
    listening.grammar("en")
    assert listening.hear(_heard("yes", 0.65)).needs_confirmation
    listening.set_question(_confirm_options("en"), scored=False, welcome=False, key="bathing", confirming=True)
    listening.grammar("en")  # a fresh "Is that right?" on the same question: a fresh pair is needed
    assert listening.hear(_heard("yes", 0.65)).needs_confirmation


@pytest.mark.parametrize("language", NO_PHRASINGS)
def test_where_a_free_hearing_exists_it_must_also_be_a_yes(language):
    agree = _listening(language).hear(_heard(YES[language], 0.9, transcript=YES[language]))
    assert (agree.option, agree.needs_confirmation) == (1, False)
    mumble = _listening(language).hear(_heard(YES[language], 0.9, transcript="hmm"))
    assert (mumble.option, mumble.needs_confirmation) == (1, True)


def test_a_yes_to_an_ordinary_question_is_not_held_to_the_confirmation_rules():
    """A Yes/No item's own "yes" (the GDS) is an answer asked back anyway; only the reply to
    "Is that right?" stores anything."""
    listening = Listening(
        min_confidence=0.6, confirm_below=CONFIRM_BELOW, reply_min_above_room_db=REPLY_MIN_ABOVE_ROOM_DB
    )
    options = [OptionWords("Yes"), OptionWords("No")]
    listening.set_question(options, scored=False, welcome=False, key="gds_1", confirming=False)
    listening.grammar("en")
    heard = listening.hear(_heard("yes", 0.65))
    assert (heard.option, heard.needs_confirmation) == (1, False)

"""The call grammar in every language (issue 33, part 3): the ordinary ways of asking for a bit of
help answer a question and never call anyone, and the call phrases still call, on every item of
every shipped instrument; end to end with espeak-ng and pocketsphinx for English."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.core.channels import Command
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import DoctorCallAsked, DoctorCalled, Prompt
from kiosk.speech.matching import COMMAND_PHRASES, HELP_WORDS, Matcher, OptionWords, normalise, spoken_label

from .voice_kiosk import VoiceKiosk, backends

INSTRUMENTS = sorted((Path(__file__).parents[3] / "kiosk/core/questionnaire/instruments").glob("*.yaml"))
LANGUAGES = ("en", "es", "fr", "de")
#: the answers patients give to Barthel questions that the issue found turned into calls
HELP_SAID = {
    "en": ["I need a bit of help", "I need some help", "with help", "a little bit of help", "I need help"],
    "es": ["necesito un poco de ayuda", "necesito algo de ayuda", "con ayuda", "necesito ayuda"],
    "fr": ["j'ai besoin d'un peu d'aide", "avec de l'aide", "j'ai besoin d'aide"],
    "de": ["ich brauche ein bisschen hilfe", "ich brauche etwas hilfe", "mit hilfe", "ich brauche hilfe"],
}


def _questions():
    for path in INSTRUMENTS:
        questionnaire = load_questionnaire(path)
        for item in (*questionnaire.items, *questionnaire.familiarisation):
            for language in LANGUAGES:
                if language in questionnaire.languages:
                    words = [OptionWords(o.label_in(language), tuple(o.synonyms_in(language))) for o in item.options]
                    yield pytest.param(language, words, id=f"{questionnaire.id}-{item.id}-{language}")


@pytest.mark.parametrize("language,options", list(_questions()))
def test_asking_for_a_bit_of_help_never_calls_and_calling_still_does(language, options):
    matcher = Matcher(options, language)
    word = normalise(HELP_WORDS[language][0])  # "help": an option said so takes every way of asking
    chosen = [
        n for n, o in enumerate(options, 1) if word in {normalise(w) for w in (spoken_label(o.label), *o.synonyms)}
    ]
    for said in (*HELP_WORDS[language], *HELP_SAID[language]):
        match = matcher.match(said)
        assert match.command is not Command.CALL_DOCTOR, said
        if len(chosen) == 1:
            assert match.option == chosen[0], said
    for call in COMMAND_PHRASES[language][Command.CALL_DOCTOR]:
        assert matcher.match(call).command is Command.CALL_DOCTOR, call
    # each is in the recogniser's grammar, so it has somewhere to go but "I need a doctor"
    grammar = {normalise(p) for p in (*matcher.phrases(), *matcher.fillers())}
    for phrase in HELP_WORDS[language]:  # as a filler, or an answer (maybe after "i need")
        assert normalise(phrase) in grammar or matcher.match(phrase).option is not None, phrase


@pytest.mark.parametrize("backend", backends("en"))
def test_i_need_a_bit_of_help_is_an_answer_and_not_a_call(backend, spoken):
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("I need a bit of help"))
    assert not any(isinstance(e, (DoctorCallAsked, DoctorCalled)) for e in kiosk.events)
    (heard,) = kiosk.inputs
    assert (heard.option, heard.needs_confirmation) == (2, True)  # needs help: asked back
    assert [e for e in kiosk.events if isinstance(e, Prompt)][-1].kind == "confirm"


@pytest.mark.parametrize("backend", backends("en"))
def test_call_the_nurse_said_twice_calls(backend, spoken):
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("call the nurse"))
    assert [type(e) for e in kiosk.events if isinstance(e, (DoctorCallAsked, DoctorCalled))] == [DoctorCallAsked]
    assert [e for e in kiosk.events if isinstance(e, Prompt)][-1].kind == "call"
    kiosk.say(spoken("call the nurse"))
    assert kiosk.session.halted and any(isinstance(e, DoctorCalled) for e in kiosk.events)


@pytest.mark.parametrize("backend", backends("en"))
def test_no_to_shall_i_call_the_nurse_goes_back_to_the_question(backend, spoken):
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("i need a doctor"))
    assert any(isinstance(e, DoctorCallAsked) for e in kiosk.events)
    kiosk.say(spoken("no"))
    assert not kiosk.session.halted
    kiosk.answer(spoken("independent"), spoken)  # the question's grammar is back
    assert kiosk.session.answers["feeding"].option == 3

"""End to end with real audio: espeak-ng speaks an answer, the audio pipeline and a real
recogniser hear it under the question's grammar, and the real session records it as a voice answer.

Runs with pocketsphinx (bundled English model) everywhere, and with vosk when a model is
present (``KIOSK_VOSK_MODEL``, or one installed with ``kiosk models install``).
"""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import DoctorCallAsked, DoctorCalled, Paused, Phase, Prompt, Resumed
from kiosk.speech.asr import PocketSphinxRecogniser
from kiosk.speech.audio import feed_wav
from kiosk.speech.matching import OptionWords
from kiosk.speech.voice import VoiceChannel

from .voice_kiosk import VoiceKiosk, backends

ANSWERS_EN = [
    ("feeding", "independent", 3),
    ("feeding", "two", 2),
    ("feeding", "by myself", 3),
    ("dressing", "three", 3),
    ("bathing", "yes", 2),
    ("stairs", "needs help", 2),
    ("transfers", "four", 4),
]


@pytest.mark.parametrize("backend", backends("en"))
@pytest.mark.parametrize("item_id,utterance,option", ANSWERS_EN)
def test_spoken_answer_is_recorded_as_a_voice_answer(backend, spoken, item_id, utterance, option):
    kiosk = VoiceKiosk(backend)
    kiosk.to_question(item_id)
    kiosk.answer(spoken(utterance), spoken)
    answer = kiosk.session.answers[item_id]
    assert (answer.option, answer.channel) == (option, Channel.VOICE)
    recorded = [e for e in kiosk.events if type(e).__name__ == "AnswerRecorded" and e.item_id == item_id]
    assert recorded[0].detail == f"{utterance} (confirmed)"


ANSWERS_OTHER = [
    ("es", "feeding", "independiente", 3),
    ("es", "feeding", "dos", 2),
    ("es", "feeding", "la segunda", 2),
    ("fr", "feeding", "autonome", 3),
    ("fr", "feeding", "deux", 2),
    ("fr", "feeding", "le premier", 1),
]


@pytest.mark.parametrize(
    "language,item_id,utterance,option,backend",
    [
        pytest.param(lang, item, utt, opt, *backend.values, marks=backend.marks, id=f"{lang}-{utt}-{backend.id}")
        for lang, item, utt, opt in ANSWERS_OTHER
        for backend in backends(lang)
    ],
)
def test_spoken_answer_in_spanish_and_french(spoken, language, item_id, utterance, option, backend):
    kiosk = VoiceKiosk(backend, language=language)
    kiosk.to_question(item_id)
    kiosk.answer(spoken(utterance, language), spoken)
    answer = kiosk.session.answers[item_id]
    assert (answer.option, answer.channel) == (option, Channel.VOICE)


@pytest.mark.parametrize("backend", backends("en"))
def test_spoken_commands_reach_the_session(backend, spoken):
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("repeat"))
    assert any(isinstance(e, Prompt) and e.key == "feeding" and e.repeat for e in kiosk.events)
    # "stop", one of the pause words: pocketsphinx mishears espeak-ng's "pause" (see bench/asr.py)
    kiosk.say(spoken("stop"))
    assert any(isinstance(e, Paused) and e.channel is Channel.VOICE for e in kiosk.events)
    # while paused only commands are listened for: an answer is not taken, "continue" is
    kiosk.say(spoken("independent"))
    assert "feeding" not in kiosk.session.answers
    kiosk.say(spoken("continue"))
    assert any(isinstance(e, Resumed) for e in kiosk.events)
    kiosk.say(spoken("call the doctor"))  # asked back first: "Shall I call the nurse?"
    assert any(isinstance(e, DoctorCallAsked) for e in kiosk.events)
    assert not any(isinstance(e, DoctorCalled) for e in kiosk.events)
    kiosk.say(spoken("yes"))
    assert any(isinstance(e, DoctorCalled) and e.channel is Channel.VOICE for e in kiosk.events)


@pytest.mark.parametrize("backend", backends("en"))
def test_the_patient_starts_by_saying_the_language_then_im_ready(backend, spoken):
    """What the welcome and the explanation promise by voice works: "English" on the welcome,
    "I'm ready" under the explanation."""
    kiosk = VoiceKiosk(backend)
    kiosk.session.welcome()
    assert kiosk.session.listening
    kiosk.say(spoken("English"))
    assert kiosk.session.phase is Phase.EXPLANATION and kiosk.session.language == "en"
    assert kiosk.session.listening, "the explanation promises 'say I'm ready': the kiosk must listen"
    kiosk.say(spoken("I'm ready"))
    assert kiosk.session.phase is Phase.QUESTIONS
    assert [i.channel for i in kiosk.inputs] == [Channel.VOICE, Channel.VOICE]


@pytest.mark.parametrize("backend", backends("en"))
@pytest.mark.parametrize("said", ["stop", "doctor", "again"])
def test_before_the_test_short_command_words_do_nothing(backend, spoken, said):
    """On the welcome only "call the doctor" (whole phrases) is a command: "start" was heard as
    "stop", "doctor" or "again" by other voices, which paused, called the doctor or repeated."""
    kiosk = VoiceKiosk(backend)
    kiosk.session.welcome()
    kiosk.say(spoken(said))
    assert all(i.command is None for i in kiosk.inputs)
    assert not kiosk.session.paused and not kiosk.session.halted
    kiosk.say(spoken("call the nurse"))  # a whole phrase is still heard (the session decides)
    assert kiosk.inputs[-1].command is Command.CALL_DOCTOR


@pytest.mark.parametrize("backend", backends("en"))
def test_no_thats_wrong_in_the_thank_you_gap_takes_the_answer_back(backend, spoken):
    """Any answer (here a touch) can be taken back by voice for the thank-you gap; in the gap the
    question's own words mean nothing, and the doctor can still be called."""
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.session.handle(ChannelInput(Channel.TOUCH, option=2))
    assert kiosk.session.answers["feeding"].option == 2 and kiosk.session.listening
    kiosk.say(spoken("independent"))  # an answer word in the gap is not an answer
    assert not [i for i in kiosk.inputs if i.option is not None]
    kiosk.say(spoken("no that's wrong"))
    assert [i.command for i in kiosk.inputs] == [Command.UNDO]
    assert "feeding" not in kiosk.session.answers
    assert kiosk.session.current_item.id == "feeding" and kiosk.session.current_attempt is not None
    kiosk.say(spoken("independent"))  # asked again: the question's words are heard again
    assert kiosk.inputs[-1].option == 3


@pytest.mark.parametrize("backend", backends("en"))
@pytest.mark.parametrize("noise", ["the weather is nice today", "banana split"])
def test_other_speech_is_never_an_answer(backend, spoken, noise):
    """Other speech is not an answer; at worst the channel sends an option it is unsure of with
    needs_confirmation, which the session asks about before storing."""
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken(noise))
    sent = [i for i in kiosk.inputs if i.option is not None]
    assert all(i.needs_confirmation for i in sent)
    assert len(kiosk.unmatched) + len(sent) == 1


@pytest.mark.parametrize("backend", backends("en"))
def test_every_voice_answer_to_a_scored_question_asks_for_confirmation(backend, spoken):
    """Measured on voices other than the kiosk's own (bench/asr.py), no confidence made an
    unconfirmed voice answer safe enough: each one carries needs_confirmation; a practice
    question's or a confirmation's own answer does not."""
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("independent"))
    (answer,) = kiosk.inputs
    assert (answer.option, answer.needs_confirmation) == (3, True)
    kiosk.voice.set_question([OptionWords("Yes"), OptionWords("No")], "en")  # "Is that right?"
    kiosk.voice.listen(True)
    kiosk.say(spoken("yes"))
    assert (kiosk.inputs[-1].option, kiosk.inputs[-1].needs_confirmation) == (1, False)


def test_a_confusable_answer_is_always_confirmed_and_refused_where_it_cannot_be(spoken):
    """ "the first one" where "the third one" selects another option: asked back even by a channel
    told to confirm nothing, and not taken at all on a prompt whose answers are never confirmed."""
    inputs, unmatched = [], []
    voice = VoiceChannel(
        "en",
        recogniser_factory=PocketSphinxRecogniser,
        confirm_below=0.0,
        on_unmatched=lambda u, r: unmatched.append(r),
    )
    assert voice.attach(lambda i: inputs.append(i) if isinstance(i, ChannelInput) else None)
    voice.listen(True)
    options = [OptionWords(w) for w in ("unable", "needs help", "independent")]
    voice.set_question(options, "en", scored=True)
    feed_wav(spoken("the first one"), voice)
    (got,) = inputs
    assert got.option in (1, 3) and got.needs_confirmation
    voice.set_question(options, "en", scored=False)
    feed_wav(spoken("the first one"), voice)
    assert inputs == [got] and "confusable" in unmatched[-1]


@pytest.mark.parametrize("backend", backends("en"))
def test_an_option_declined_is_not_heard_again_on_that_question(backend, spoken):
    """The patient says No to "I heard: Independent": asked again, "independent" is no longer
    listened for on that question (the same mishearing is not offered twice); touch still
    chooses it, and the next question listens for its own words again."""
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("independent"))
    assert kiosk.inputs[-1].option == 3 and kiosk.inputs[-1].needs_confirmation
    kiosk.say(spoken("no"))
    assert kiosk.inputs[-1].option == 2  # No
    assert kiosk.session.current_item.id == "feeding" and "feeding" not in kiosk.session.answers
    sent = len(kiosk.inputs)
    kiosk.say(spoken("independent"))
    assert all(i.option != 3 for i in kiosk.inputs[sent:])
    for i in kiosk.inputs[sent:]:  # whatever else was heard was asked about: the patient says no
        if i.option is not None:
            kiosk.say(spoken("no"))
    kiosk.session.handle(ChannelInput(Channel.TOUCH, option=3))
    assert kiosk.session.answers["feeding"].option == 3
    while kiosk.session.current_item.id == "feeding" or not kiosk.session.listening:
        kiosk.clock.advance(0.5)
        kiosk.session.poll()
    assert kiosk.session.current_item.id == "bathing"  # Unable / Independent
    kiosk.say(spoken("independent"))
    assert kiosk.inputs[-1].option == 2


@pytest.mark.parametrize("backend", backends("en"))
def test_the_kiosks_own_voice_and_closed_attempts_are_not_heard(backend, spoken):
    kiosk = VoiceKiosk(backend)
    kiosk.session.start()
    kiosk.say(spoken("independent"))  # no question open yet: the session is not listening
    kiosk.to_question("feeding")
    kiosk.voice.set_muted(True)  # the kiosk reads the question aloud
    kiosk.say(spoken("independent"))
    assert kiosk.session.answers == {}
    kiosk.voice.set_muted(False)
    kiosk.answer(spoken("independent"), spoken)
    assert kiosk.session.answers["feeding"].option == 3

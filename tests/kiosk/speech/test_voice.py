"""End to end with real audio: espeak-ng speaks an answer, the audio pipeline and a real
recogniser hear it under the question's grammar, and the real session records it as a voice answer.

Runs with pocketsphinx (bundled English model) everywhere, and with vosk when a model is
present (``KIOSK_VOSK_MODEL``, or one installed with ``kiosk models install``).
"""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus, Command
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import DoctorCalled, ListeningChanged, Paused, Phase, Prompt, Resumed, Session
from kiosk.speech.asr import AsrUnavailable, PocketSphinxRecogniser, VoskRecogniser, open_recogniser
from kiosk.speech.audio import feed_wav, list_input_devices, resample
from kiosk.speech.matching import OptionWords
from kiosk.speech.models import find_model
from kiosk.speech.tts import Speaker
from kiosk.speech.voice import VoiceChannel
from kiosk.ui.widgets.channel_board import VOICE_IN, ChannelBoard

QUESTIONNAIRE = load_questionnaire()


def _backends(language: str):
    params = []
    if language == "en":
        params.append(pytest.param(lambda lang: PocketSphinxRecogniser(lang), id="pocketsphinx"))
    model = find_model(language)  # as the kiosk finds one: KIOSK_VOSK_MODEL, or installed
    params.append(
        pytest.param(
            lambda lang, model=model: VoskRecogniser(model, lang),
            id="vosk",
            marks=pytest.mark.skipif(
                model is None,
                reason=f"no vosk model for {language!r}: set "
                "KIOSK_VOSK_MODEL or run `kiosk models install` (none can be downloaded here)",
            ),
        )
    )
    return params


class _Kiosk:
    """The real session on a simulated clock, with a voice channel attached the way the app does."""

    def __init__(self, recogniser_factory, language: str = "en", app_style: bool = False, microphone=None) -> None:
        self.clock = SimClock()
        self.session = Session(
            QUESTIONNAIRE, clock=self.clock, engine=None, patient_id="P-0042", language=language, familiarisation=False
        )
        self.events: list[object] = []
        self.statuses: list[ChannelStatus] = []
        self.unmatched: list[tuple[str, str]] = []
        #: every answer or command the voice channel sent
        self.inputs: list[ChannelInput] = []
        self.voice = VoiceChannel(
            language,
            recogniser_factory=recogniser_factory,
            on_unmatched=lambda u, r: self.unmatched.append((u, r)),
            **({"microphone_factory": microphone} if microphone else {}),
        )
        self.session.subscribe(self.events.append)
        self.session.subscribe(self._app_forward if app_style else self.voice.on_session_event)
        if microphone is None:
            self.available = self.voice.attach(self._sink)
        else:
            self.voice.start(self._sink)

    def _app_forward(self, event: object) -> None:
        """What kiosk.ui.app does with session events for voice in."""
        if isinstance(event, Prompt):
            self.voice.expect(event)
        elif isinstance(event, ListeningChanged):
            self.voice.listen(event.listening)

    def _sink(self, item: ChannelInput | ChannelStatus) -> None:
        # the app's sink hops to the UI thread; here the test thread is that thread
        if isinstance(item, ChannelStatus):
            self.statuses.append(item)
        else:
            self.inputs.append(item)
            self.session.handle(item)

    def to_question(self, item_id: str) -> None:
        self.session.start()
        self.session.acknowledge()
        while (
            self.session.current_item is None or self.session.current_item.id != item_id or not self.session.listening
        ):
            if self.session.current_item is not None and self.session.listening:
                self.session.handle(ChannelInput(Channel.TOUCH, option=1))
            self.clock.advance(0.5)
            self.session.poll()

    def say(self, wav: Path) -> None:
        feed_wav(wav, self.voice)

    def answer(self, wav: Path, spoken) -> None:
        """Say an answer, and "yes" when the kiosk asks back "I heard ... Is that right?"."""
        self.say(wav)
        prompts = [e for e in self.events if isinstance(e, Prompt)]
        if prompts and prompts[-1].kind == "confirm":
            language = prompts[-1].language
            self.say(spoken({"en": "yes", "es": "sí", "fr": "oui"}[language], language))


ANSWERS_EN = [
    ("feeding", "independent", 3),
    ("feeding", "two", 2),
    ("feeding", "by myself", 3),
    ("dressing", "three", 3),
    ("bathing", "yes", 2),
    ("stairs", "needs help", 2),
    ("transfers", "four", 4),
]


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
@pytest.mark.parametrize("item_id,utterance,option", ANSWERS_EN)
def test_spoken_answer_is_recorded_as_a_voice_answer(backend, spoken, item_id, utterance, option):
    kiosk = _Kiosk(backend)
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


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize(
    "language,item_id,utterance,option,backend",
    [
        pytest.param(lang, item, utt, opt, *backend.values, marks=backend.marks, id=f"{lang}-{utt}-{backend.id}")
        for lang, item, utt, opt in ANSWERS_OTHER
        for backend in _backends(lang)
    ],
)
def test_spoken_answer_in_spanish_and_french(spoken, language, item_id, utterance, option, backend):
    kiosk = _Kiosk(backend, language=language)
    kiosk.to_question(item_id)
    kiosk.answer(spoken(utterance, language), spoken)
    answer = kiosk.session.answers[item_id]
    assert (answer.option, answer.channel) == (option, Channel.VOICE)


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
def test_spoken_commands_reach_the_session(backend, spoken):
    kiosk = _Kiosk(backend)
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
    kiosk.say(spoken("call the doctor"))
    assert any(isinstance(e, DoctorCalled) and e.channel is Channel.VOICE for e in kiosk.events)


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
def test_the_patient_starts_by_saying_the_language_then_im_ready(backend, spoken):
    """What the welcome and the explanation promise by voice works: "English" on the welcome,
    "I'm ready" under the explanation."""
    kiosk = _Kiosk(backend)
    kiosk.session.welcome()
    assert kiosk.session.listening
    kiosk.say(spoken("English"))
    assert kiosk.session.phase is Phase.EXPLANATION and kiosk.session.language == "en"
    assert kiosk.session.listening, "the explanation promises 'say I'm ready': the kiosk must listen"
    kiosk.say(spoken("I'm ready"))
    assert kiosk.session.phase is Phase.QUESTIONS
    assert [i.channel for i in kiosk.inputs] == [Channel.VOICE, Channel.VOICE]


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
@pytest.mark.parametrize("said", ["stop", "doctor", "again"])
def test_before_the_test_short_command_words_do_nothing(backend, spoken, said):
    """On the welcome only "call the doctor" (whole phrases) is a command: "start" was heard as
    "stop", "doctor" or "again" by other voices, which paused, called the doctor or repeated."""
    kiosk = _Kiosk(backend)
    kiosk.session.welcome()
    kiosk.say(spoken(said))
    assert all(i.command is None for i in kiosk.inputs)
    assert not kiosk.session.paused and not kiosk.session.halted
    kiosk.say(spoken("call the nurse"))  # a whole phrase is still heard (the session decides)
    assert kiosk.inputs[-1].command is Command.CALL_DOCTOR


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
def test_no_thats_wrong_in_the_thank_you_gap_takes_the_answer_back(backend, spoken):
    """Any answer (here a touch) can be taken back by voice for the thank-you gap; in the gap the
    question's own words mean nothing, and the doctor can still be called."""
    kiosk = _Kiosk(backend)
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


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
@pytest.mark.parametrize("noise", ["the weather is nice today", "banana split"])
def test_other_speech_is_never_an_answer(backend, spoken, noise):
    """Other speech is not an answer; at worst the channel sends an option it is unsure of with
    needs_confirmation, which the session asks about before storing."""
    kiosk = _Kiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken(noise))
    sent = [i for i in kiosk.inputs if i.option is not None]
    assert all(i.needs_confirmation for i in sent)
    assert len(kiosk.unmatched) + len(sent) == 1


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
def test_every_voice_answer_to_a_scored_question_asks_for_confirmation(backend, spoken):
    """Measured on voices other than the kiosk's own (bench/asr.py), no confidence made an
    unconfirmed voice answer safe enough: each one carries needs_confirmation; a practice
    question's or a confirmation's own answer does not."""
    kiosk = _Kiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("independent"))
    (answer,) = kiosk.inputs
    assert (answer.option, answer.needs_confirmation) == (3, True)
    kiosk.voice.set_question([OptionWords("Yes"), OptionWords("No")], "en")  # "Is that right?"
    kiosk.voice.listen(True)
    kiosk.say(spoken("yes"))
    assert (kiosk.inputs[-1].option, kiosk.inputs[-1].needs_confirmation) == (1, False)


@pytest.mark.slow  # real audio (espeak-ng)
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


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
def test_an_option_declined_is_not_heard_again_on_that_question(backend, spoken):
    """The patient says No to "I heard: Independent": asked again, "independent" is no longer
    listened for on that question (the same mishearing is not offered twice); touch still
    chooses it, and the next question listens for its own words again."""
    kiosk = _Kiosk(backend)
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


@pytest.mark.slow  # real audio (espeak-ng)
@pytest.mark.parametrize("backend", _backends("en"))
def test_the_kiosks_own_voice_and_closed_attempts_are_not_heard(backend, spoken):
    kiosk = _Kiosk(backend)
    kiosk.session.start()
    kiosk.say(spoken("independent"))  # no question open yet: the session is not listening
    kiosk.to_question("feeding")
    kiosk.voice.set_muted(True)  # the kiosk reads the question aloud
    kiosk.say(spoken("independent"))
    assert kiosk.session.answers == {}
    kiosk.voice.set_muted(False)
    kiosk.answer(spoken("independent"), spoken)
    assert kiosk.session.answers["feeding"].option == 3


def test_no_recogniser_for_the_language_turns_voice_off_and_the_session_goes_on(monkeypatch, tmp_path):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    kiosk = _Kiosk(open_recogniser, language="es")
    assert not kiosk.available
    loading, status = kiosk.statuses
    assert (loading.state, status.channel, status.state) == (ChannelState.CONNECTING, Channel.VOICE, ChannelState.OFF)
    assert "no speech model for language 'es'" in status.reason
    kiosk.to_question("bathing")  # answered feeding by touch on the way
    assert kiosk.session.answers["feeding"].channel is Channel.TOUCH


@pytest.mark.parametrize(
    "language,words", [("es", "respuestas habladas en español"), ("fr", "réponses parlées en français")]
)
def test_no_model_reason_is_shown_in_the_patients_language(monkeypatch, tmp_path, language, words):
    """The patient's screen says why voice is off in their language; the clinician still sees
    the technical reason with the command that fixes it."""
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    kiosk = _Kiosk(open_recogniser, language=language)
    board = ChannelBoard("espeak-ng")
    for status in kiosk.statuses:
        board.update(status)
    patient = next(line for line in board.lines(language) if not line.live and words in line.reason)
    assert "kiosk models" not in patient.reason
    clinician = [line.reason for line in board.lines("en", patient=False) if "kiosk models install" in line.reason]
    assert clinician == [
        f"voice answers off: no speech model for language {language!r}: pocketsphinx only "
        f"ships English; install one with `kiosk models install {language}`"
    ]


def test_no_microphone_turns_voice_off_with_a_reason():
    if any(d.usable for d in list_input_devices()):
        pytest.skip("this machine has a microphone")
    statuses = []
    voice = VoiceChannel("en")
    voice.start(statuses.append)
    voice.stop()
    assert statuses == [
        ChannelStatus(Channel.VOICE, ChannelState.OFF, source="voice", reason="voice answers off: no microphone found")
    ]


@pytest.mark.slow  # real audio (espeak-ng)
def test_language_change_follows_the_prompts(spoken):
    opened = []

    def factory(language):
        opened.append(language)
        if language != "en":
            raise AsrUnavailable(f"no model for {language}")
        return PocketSphinxRecogniser(language)

    kiosk = _Kiosk(factory)
    kiosk.to_question("feeding")
    kiosk.session.choose_language("fr")
    assert not kiosk.voice.wait_loaded()
    assert opened == ["en", "fr"]
    assert kiosk.statuses[-1].state is ChannelState.OFF


@pytest.mark.slow  # real audio (espeak-ng)
def test_the_kiosk_reading_options_aloud_into_its_own_microphone_records_nothing(spoken):
    """The speaker's start/end events mute voice in: its own "Independent" is not an answer."""
    kiosk = _Kiosk(lambda lang: PocketSphinxRecogniser(lang))
    kiosk.to_question("feeding")
    done = threading.Event()

    class EchoingPlayer:
        """No loudspeaker here: what would be played goes straight into the microphone path."""

        def play(self, samples, rate):
            kiosk.voice.feed(resample(samples, rate).tobytes() + bytes(32000))

        def stop(self):
            pass

    speaker = Speaker(
        on_speech=lambda s: (kiosk.voice.set_muted(s), None if s else done.set()), player_factory=EchoingPlayer
    )
    speaker.start()
    speaker.say("Independent", "en")
    assert done.wait(10)
    speaker.close()
    assert kiosk.session.answers == {}
    kiosk.answer(spoken("independent"), spoken)  # the patient, after the kiosk stopped talking
    assert kiosk.session.answers["feeding"].option == 3


@pytest.mark.slow  # real audio (espeak-ng)
def test_the_apps_calls_drive_the_channel(spoken):
    """The app forwards only Prompt (expect) and ListeningChanged (listen); that is enough."""
    kiosk = _Kiosk(lambda lang: PocketSphinxRecogniser(lang), app_style=True)
    kiosk.to_question("feeding")
    kiosk.answer(spoken("two"), spoken)
    assert kiosk.session.answers["feeding"].option == 2


class _WavMicrophone:
    """Stands in for the sound card (none here): a thread plays WAV files into the channel,
    the way MicrophoneStream's thread delivers recorded audio."""

    def __init__(self, consumer) -> None:
        self.consumer = consumer
        self.files: list[Path] = []
        self.thread: threading.Thread | None = None

    def start(self) -> None:
        def play() -> None:
            for path in self.files:
                feed_wav(path, self.consumer)

        self.thread = threading.Thread(target=play)

    def stop(self) -> None:
        pass


@pytest.mark.slow  # real audio (espeak-ng)
def test_started_channel_hears_its_microphone_thread_and_follows_language_changes(spoken, monkeypatch, tmp_path):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    microphones: list[_WavMicrophone] = []
    kiosk = _Kiosk(
        open_recogniser,
        language="es",
        microphone=lambda consumer: microphones.append(_WavMicrophone(consumer)) or microphones[-1],
    )
    assert not kiosk.voice.wait_loaded()
    (loading, off) = kiosk.statuses  # the microphone works; Spanish has no recogniser here
    assert off.state is ChannelState.OFF and "no speech model for language 'es'" in off.reason
    kiosk.to_question("bathing")
    kiosk.session.choose_language("en")  # the prompt comes again, in English
    assert kiosk.voice.wait_loaded()
    assert [(s.state, s.source, s.reason) for s in kiosk.statuses[2:]] == [
        (ChannelState.CONNECTING, "voice", "loading the speech model for 'en'"),
        (ChannelState.ON, "voice", "voice answers on: pocketsphinx"),
    ]
    (microphone,) = microphones
    microphone.files += [spoken("independent"), spoken("yes")]  # the answer, and yes to "Is that right?"
    microphone.thread.start()
    microphone.thread.join(timeout=30)
    assert kiosk.session.answers["bathing"].option == 2
    assert kiosk.session.answers["bathing"].channel is Channel.VOICE


def _no_models(monkeypatch, tmp_path) -> None:
    """A kiosk with no vosk model: English has pocketsphinx, Spanish nothing."""
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)


@pytest.mark.slow  # real audio (espeak-ng)
def test_a_language_without_a_model_turns_voice_in_off_on_the_channel_board(spoken, monkeypatch, tmp_path):
    _no_models(monkeypatch, tmp_path)
    kiosk = _Kiosk(open_recogniser, microphone=_WavMicrophone)
    assert kiosk.voice.wait_loaded()
    kiosk.to_question("feeding")
    kiosk.session.choose_language("es")
    assert not kiosk.voice.wait_loaded()
    board = ChannelBoard(Speaker.source)
    for status in kiosk.statuses:
        board.update(status)
    # one source: the latest status replaces the English ON instead of standing beside it
    assert {s.source for s in kiosk.statuses} == {"voice"}
    state, reason = board.state(VOICE_IN)
    assert state is ChannelState.OFF and "no speech model for language 'es'" in reason
    kiosk.say(spoken("independent"))  # nobody is listening any more
    assert kiosk.session.answers == {} and kiosk.unmatched == []


@pytest.mark.slow  # real audio (espeak-ng)
def test_models_load_off_the_thread_that_changes_language_and_a_late_one_is_not_installed(
    spoken, monkeypatch, tmp_path
):
    _no_models(monkeypatch, tmp_path)
    english_loading, english_loaded = threading.Event(), threading.Event()
    loads: list[tuple[str, threading.Thread]] = []

    def slow_english(language):
        loads.append((language, threading.current_thread()))
        if language == "en":  # a model that takes a while, still loading when the language changes
            english_loading.set()
            assert english_loaded.wait(10)
        return open_recogniser(language)

    kiosk = _Kiosk(slow_english, microphone=_WavMicrophone)  # start() does not wait for the model
    kiosk.to_question("feeding")
    assert english_loading.wait(10)
    kiosk.session.choose_language("es")  # returns at once, though English is still loading
    english_loaded.set()
    assert not kiosk.voice.wait_loaded()
    assert [language for language, _ in loads] == ["en", "es"]
    assert threading.current_thread() not in {thread for _, thread in loads}
    # the English recogniser arrived after Spanish was chosen: never installed, never ON
    assert [s.state for s in kiosk.statuses] == [ChannelState.CONNECTING, ChannelState.CONNECTING, ChannelState.OFF]
    kiosk.say(spoken("independent"))
    assert kiosk.session.answers == {}


def test_stop_while_the_microphone_opens_leaves_it_closed():
    class OpeningMicrophone:
        """A device that takes a while to open: the app stops the channel meanwhile."""

        def __init__(self, consumer) -> None:
            self.open = False

        def start(self) -> None:
            voice.stop()  # the kiosk quits while the device is opening
            self.open = True

        def stop(self) -> None:
            self.open = False

    microphones: list[OpeningMicrophone] = []
    voice = VoiceChannel(
        "en",
        recogniser_factory=PocketSphinxRecogniser,
        microphone_factory=lambda consumer: microphones.append(OpeningMicrophone(consumer)) or microphones[-1],
    )
    statuses: list[ChannelStatus] = []
    voice.start(statuses.append)
    (microphone,) = microphones
    assert not microphone.open
    assert statuses == []  # a stopped channel loads nothing and reports nothing


class _Recording(PocketSphinxRecogniser):
    """The real recogniser, noting whether each grammar's options are taken as heard."""

    def __init__(self, language: str) -> None:
        super().__init__(language)
        self.taken_as_heard: list[bool] = []

    def set_grammar(self, phrases, meaning=None, lead_ins=(), fillers=(), taken_as_heard=False):
        self.taken_as_heard.append(taken_as_heard)
        return super().set_grammar(phrases, meaning, lead_ins, fillers, taken_as_heard)


@pytest.mark.parametrize("confirm_below,scored_taken", [(1.01, False), (0.9, True)])
def test_options_acted_on_without_asking_back_are_marked_for_the_recogniser(confirm_below, scored_taken):
    """A confirmation's yes/no and the welcome's choice act as heard, so the recogniser is told
    to make its two hearings agree (pocketsphinx in background talk); a scored question's
    answers are asked back, unless the channel is set to take sure answers without asking."""
    recognisers: list[_Recording] = []
    channel = VoiceChannel(
        "en",
        recogniser_factory=lambda lang: recognisers.append(_Recording(lang)) or recognisers[-1],
        confirm_below=confirm_below,
    )
    assert channel.attach(lambda item: None)
    item = QUESTIONNAIRE.items[0]
    channel.set_question([OptionWords(o.label_in("en")) for o in item.options], "en", scored=True, key="q1")
    channel.set_question([OptionWords("Yes"), OptionWords("No")], "en")
    channel.set_question([OptionWords("English"), OptionWords("Español")], "en", welcome=True)
    assert recognisers[-1].taken_as_heard[-3:] == [scored_taken, True, True]
    channel.stop()

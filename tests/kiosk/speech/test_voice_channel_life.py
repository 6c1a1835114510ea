"""The voice channel's life: off with a reason when there is no microphone or speech model, models
loaded off the thread that changes language, the microphone's thread heard, the kiosk's own voice
not recorded, a clean stop, and what the recogniser is told about replies acted on at once. Real
audio (espeak-ng) through a real recogniser.
"""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.speech.asr import AsrUnavailable, PocketSphinxRecogniser, open_recogniser
from kiosk.speech.audio import feed_wav, list_input_devices, resample
from kiosk.speech.matching import OptionWords
from kiosk.speech.tts import Speaker
from kiosk.speech.voice import VoiceChannel
from kiosk.ui.widgets.channel_board import VOICE_IN, ChannelBoard

from .voice_kiosk import QUESTIONNAIRE, VoiceKiosk


def test_no_recogniser_for_the_language_turns_voice_off_and_the_session_goes_on(monkeypatch, tmp_path):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    kiosk = VoiceKiosk(open_recogniser, language="es")
    assert not kiosk.available
    loading, status = kiosk.statuses
    assert (loading.state, status.channel, status.state) == (ChannelState.CONNECTING, Channel.VOICE, ChannelState.OFF)
    assert "no speech model for language 'es'" in status.reason
    kiosk.to_question("bathing")  # answered feeding by touch on the way
    assert kiosk.session.answers["feeding"].channel is Channel.TOUCH


@pytest.mark.parametrize(
    "language,words",
    [
        ("es", "respuestas habladas en español"),
        ("fr", "réponses parlées en français"),
        ("de", "gesprochenen Antworten auf Deutsch"),
    ],
)
def test_no_model_reason_is_shown_in_the_patients_language(monkeypatch, tmp_path, language, words):
    """The patient's screen says why voice is off in their language; the clinician still sees
    the technical reason with the command that fixes it."""
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    kiosk = VoiceKiosk(open_recogniser, language=language)
    board = ChannelBoard("espeak-ng")
    for status in kiosk.statuses:
        board.update(status)
    patient = next(line for line in board.lines(language) if not line.live and words in line.reason)
    assert "kiosk models" not in patient.reason
    clinician = [line.reason for line in board.lines("en", patient=False) if "kiosk models install" in line.reason]
    assert clinician == [
        f"voice answers off: no speech model for language {language!r}: pocketsphinx only "
        f"ships English; install one with `kiosk models install {language}` "
        "(Whisper: turned off (KIOSK_WHISPER=off))"
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


def test_language_change_follows_the_prompts(spoken):
    opened = []

    def factory(language):
        opened.append(language)
        if language != "en":
            raise AsrUnavailable(f"no model for {language}")
        return PocketSphinxRecogniser(language)

    kiosk = VoiceKiosk(factory)
    kiosk.to_question("feeding")
    kiosk.session.choose_language("fr")
    assert not kiosk.voice.wait_loaded()
    assert opened == ["en", "fr"]
    assert kiosk.statuses[-1].state is ChannelState.OFF


def test_the_kiosk_reading_options_aloud_into_its_own_microphone_records_nothing(spoken):
    """The speaker's start/end events mute voice in: its own "Independent" is not an answer."""
    kiosk = VoiceKiosk(lambda lang: PocketSphinxRecogniser(lang))
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


def test_the_apps_calls_drive_the_channel(spoken):
    """The app forwards only Prompt (expect) and ListeningChanged (listen); that is enough."""
    kiosk = VoiceKiosk(lambda lang: PocketSphinxRecogniser(lang), app_style=True)
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


def test_started_channel_hears_its_microphone_thread_and_follows_language_changes(spoken, monkeypatch, tmp_path):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path))
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    microphones: list[_WavMicrophone] = []
    kiosk = VoiceKiosk(
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
        (
            ChannelState.ON,
            "voice",
            "voice answers on: pocketsphinx (Whisper unavailable: turned off (KIOSK_WHISPER=off))",
        ),
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
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)


def test_a_language_without_a_model_turns_voice_in_off_on_the_channel_board(spoken, monkeypatch, tmp_path):
    _no_models(monkeypatch, tmp_path)
    kiosk = VoiceKiosk(open_recogniser, microphone=_WavMicrophone)
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

    kiosk = VoiceKiosk(slow_english, microphone=_WavMicrophone)  # start() does not wait for the model
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

"""The voice channel: microphone → endpointer → recogniser → matcher → :class:`ChannelInput`.

:class:`VoiceChannel` is an :class:`~kiosk.channels.InputSource`. The app feeds it the session's
events on the UI thread (:meth:`VoiceChannel.on_session_event`): each ``Prompt`` with options
sets the grammar for that question in the prompt's language, ``ListeningChanged`` opens and
closes the microphone gate, and while the session is paused only commands are listened for, so
"continue" works. The kiosk's own voice mutes it (:meth:`VoiceChannel.set_muted`, wired to
:class:`kiosk.speech.tts.Speaker`'s ``on_speech``). Audio arrives on the microphone's thread;
answers and status changes go to the sink from that thread, as the channel contract says.

Without a microphone or a recogniser for the language, voice in reports
``ChannelStatus(VOICE, OFF, reason=...)`` and the session goes on with the other channels.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from kiosk.channels import Channel, ChannelInput, ChannelState, ChannelStatus, Sink
from kiosk.speech.asr import AsrUnavailable, Recogniser, open_recogniser
from kiosk.speech.audio import AudioUnavailable, MicrophoneStream, PcmConsumer, Utterance, UtterancePipeline
from kiosk.speech.matching import DEFAULT_MIN_CONFIDENCE, Matcher, OptionWords

log = logging.getLogger(__name__)


def option_words(options: Sequence[Any]) -> list[OptionWords]:
    """A prompt's options (anything with ``label`` and ``synonyms``, e.g. the session's
    ``PromptOption``) as the matcher takes them, in their order."""
    return [OptionWords(o.label, tuple(o.synonyms)) for o in sorted(options, key=lambda o: o.number)]


class VoiceChannel:
    """Voice answers and commands for the session, from a microphone (or any PCM feeder)."""

    name = "voice"

    def __init__(
        self,
        language: str = "en",
        *,
        vosk_model: str | Path | None = None,
        recogniser_factory: Callable[[str], Recogniser] | None = None,
        microphone_factory: Callable[[PcmConsumer], Any] = MicrophoneStream,
        min_confidence: float = DEFAULT_MIN_CONFIDENCE,
        on_unmatched: Callable[[str, str], None] = lambda utterance, reason: None,
    ) -> None:
        self.language = language
        #: language → recogniser; by default vosk with ``vosk_model`` (the config's) or an
        #: installed model, else pocketsphinx for English
        self._recogniser_factory = recogniser_factory or (lambda lang: open_recogniser(lang, vosk_model))
        self._microphone_factory = microphone_factory
        self.min_confidence = min_confidence
        #: called with (utterance, reason) when speech was heard but was not an answer
        self.on_unmatched = on_unmatched
        self._lock = threading.RLock()
        self._sink: Sink | None = None
        self._recogniser: Recogniser | None = None
        self._pipeline: UtterancePipeline | None = None
        self._microphone = None
        self._matcher: Matcher | None = None
        self._options: list[OptionWords] = []
        self._listening = self._speaking = self._paused = False

    # -- InputSource -------------------------------------------------------------------------

    def start(self, sink: Sink) -> None:
        """Open the microphone and load the recogniser; reports ON, or OFF with the reason.

        The microphone stays open when only the recogniser is missing: choosing a language
        that has one turns voice answers on.
        """
        self._sink = sink
        self._microphone = self._microphone_factory(self)
        try:
            self._microphone.start()
        except AudioUnavailable as exc:
            self._microphone = None
            self._status(ChannelState.OFF, "microphone", str(exc))
            return
        if self._open_recogniser(self.language):
            self._status(ChannelState.ON, self._recogniser.name)
            with self._lock:
                self._apply_grammar()

    def attach(self, sink: Sink) -> bool:
        """Like :meth:`start` without a microphone: audio comes from :meth:`feed` (WAV files,
        tests, the benchmark). Returns whether a recogniser is available."""
        self._sink = sink
        if not self._open_recogniser(self.language):
            return False
        with self._lock:
            self._apply_grammar()
        return True

    def stop(self) -> None:
        """Close the microphone; safe to call twice."""
        if self._microphone is not None:
            self._microphone.stop()
            self._microphone = None

    def feed(self, pcm: bytes) -> None:
        """16 kHz mono int16 audio into the pipeline (what the microphone thread does)."""
        with self._lock:
            if self._pipeline is not None:
                self._pipeline.feed(pcm)

    @property
    def pipeline(self) -> UtterancePipeline | None:
        """The audio pipeline, for :func:`kiosk.speech.audio.feed_wav`; None when voice in is off."""
        return self._pipeline

    # -- what the session and the voice out tell it (UI / TTS threads) ------------------------

    def on_session_event(self, event: Any) -> None:
        """Follow every session event: grammars, the listening gate, and pause (commands only)."""
        kind = type(event).__name__
        if kind == "Prompt":
            self.expect(event)
        elif kind == "ListeningChanged":
            self.listen(event.listening)
        elif kind == "Paused":
            self._set_paused(True)
        elif kind in ("Resumed", "Finished"):
            self._set_paused(False)

    def expect(self, prompt: Any) -> None:
        """A session ``Prompt``: a question's options become the grammar (messages change nothing)."""
        if prompt.options:
            self.set_question(option_words(prompt.options), prompt.language)

    def set_question(self, options: Sequence[OptionWords], language: str) -> None:
        """Listen for this question's answers (and the commands) in ``language``."""
        with self._lock:
            self._options = list(options)
            if language != self.language:
                self.language = language
                # before start() the language is only noted; a failure is reported once, not per question
                if self._sink is not None and self._open_recogniser(language) and self._microphone is not None:
                    self._status(ChannelState.ON, self._recogniser.name)
            self._apply_grammar()

    def listen(self, listening: bool) -> None:
        """Open or close the gate (the session's ``ListeningChanged``)."""
        with self._lock:
            self._listening = listening
            self._gate()

    def set_muted(self, speaking: bool) -> None:
        """The kiosk started (True) or stopped (False) talking: ``Speaker``'s ``on_speech``."""
        with self._lock:
            self._speaking = speaking
            self._gate()

    # -- internals ---------------------------------------------------------------------------

    def _set_paused(self, paused: bool) -> None:
        with self._lock:
            if paused != self._paused:
                self._paused = paused
                self._apply_grammar()
                self._gate()

    def _open_recogniser(self, language: str) -> bool:
        try:
            recogniser = self._recogniser_factory(language)
        except AsrUnavailable as exc:
            self._recogniser = self._pipeline = None
            self._status(ChannelState.OFF, "speech recognition", str(exc))
            return False
        with self._lock:
            self._recogniser = recogniser
            if self._pipeline is None:
                self._pipeline = UtterancePipeline(recogniser, self._on_utterance)
            else:
                self._pipeline.muted = True  # drop an utterance the old recogniser was hearing
                self._pipeline.recogniser = recogniser
            self._gate()
        return True

    def _apply_grammar(self) -> None:
        if self._recogniser is None or not (self._options or self._paused):
            return
        options = [] if self._paused else self._options
        self._matcher = Matcher(options, self.language, self.min_confidence)
        self._recogniser.set_grammar(self._matcher.phrases(), self._matcher.meaning)
        self._gate()

    def _gate(self) -> None:
        if self._pipeline is not None:
            wanted = (self._listening or self._paused) and self._matcher is not None
            self._pipeline.muted = self._speaking or not wanted

    def _on_utterance(self, utterance: Utterance) -> None:
        result = utterance.result
        match = self._matcher.match(result.text, result.confidence)
        if not match.matched:
            log.info("voice: %s", match.reason)
            self.on_unmatched(result.text, match.reason)
            return
        if self._sink is not None:
            self._sink(ChannelInput(Channel.VOICE, option=match.option, command=match.command,
                                    detail=result.text, confidence=round(result.confidence, 3)))

    def _status(self, state: ChannelState, source: str, reason: str = "") -> None:
        if self._sink is not None:
            self._sink(ChannelStatus(Channel.VOICE, state, source=source,
                                     reason=reason and f"voice answers off: {reason}"))

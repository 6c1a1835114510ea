"""The voice channel: microphone → endpointer → recogniser → matcher → :class:`ChannelInput`.

:class:`VoiceChannel` is an :class:`~kiosk.core.channels.InputSource`. The app feeds it the session's
events on the UI thread (:meth:`VoiceChannel.on_session_event`): each ``Prompt`` with options
sets the grammar for that question in the prompt's language, ``ListeningChanged`` opens and
closes the microphone gate, and while the session is paused only commands are listened for, so
"continue" works. The kiosk's own voice mutes it (:meth:`VoiceChannel.set_muted`, wired to
:class:`kiosk.speech.tts.Speaker`'s ``on_speech``). Audio arrives on the microphone's thread;
answers and status changes go to the sink from that thread, as the channel contract says.

Every answer to a scored question goes to the sink with ``needs_confirmation`` (see
:data:`CONFIRM_BELOW`): the session asks "I heard: X. Is that right?" with a Yes/No prompt,
whose options the matcher extends with the natural ways of saying them ("yes, that's right",
"no, that's wrong"); after an answer is stored (``AnswerRecorded``), until the next prompt,
only "no, that's wrong" / "change my answer" (``Command.UNDO``) and calling the doctor are
listened for: the thank-you gap in which the session lets any answer be taken back. A reply to
"Is that right?" spoken where the room was nearly as loud as the voice
(:data:`REPLY_MIN_ABOVE_ROOM_DB`) is sent as unsure: a "yes" then stores nothing and the session
asks for Yes or No to be pressed. A prompt
without points (a confirmation, the welcome's start / language
choice) is never itself confirmed.

What is listened for on each prompt, and what an utterance means there, is
:class:`kiosk.speech.listening.Listening`; this module is the audio, the threads and the status.

Speech models load on the channel's own loader thread (seconds for vosk), never on the thread
that changes the language; meanwhile voice in is CONNECTING and does not listen. Every status
carries the source ``"voice"``, the latest one being the truth. Without a microphone or a
recogniser for the language, voice in reports ``ChannelStatus(VOICE, OFF, "voice", reason=...)``
and the session goes on with the other channels.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from kiosk.core.channels import Channel, ChannelState, ChannelStatus, Sink
from kiosk.core.session import (
    AnswerNotConfirmed,
    AnswerRecorded,
    Finished,
    ListeningChanged,
    Paused,
    Prompt,
    Resumed,
    SessionEvent,
)
from kiosk.speech.listening import Listening
from kiosk.speech.matching import DEFAULT_MIN_CONFIDENCE, OptionWords

if TYPE_CHECKING:  # the recognisers and the audio pipeline (numpy) load on the channel's own threads
    from kiosk.speech.asr import Recogniser, Recognition
    from kiosk.speech.audio import Endpointer, PcmConsumer, Utterance, UtterancePipeline

log = logging.getLogger(__name__)

#: a scored answer heard with less confidence than this is confirmed before it is stored
#: ("I heard: Independent. Is that right?"). Above 1: every voice answer to a Barthel question
#: is confirmed, because even the surest unconfirmed answers were stored wrong far above the
#: 0.5 % limit (measured: bench/RESULTS.md, asr.py)
CONFIRM_BELOW = 1.01

#: a reply to "Is that right?" spoken less than this far above the room (dB, see
#: :attr:`kiosk.speech.audio.Utterance.above_room_db`) is sent as unsure, so a "yes" stores
#: nothing: the session asks the patient to press Yes or No (a "no" still declines). Where
#: people talk nearly as loud as the patient a "no" was now and then heard as "yes", and the
#: recogniser's confidence did not tell (docs/speech-tuning.md)
REPLY_MIN_ABOVE_ROOM_DB = 8.0

#: how long attach()/wait_loaded() wait for a speech model (a large vosk model takes seconds)
LOAD_TIMEOUT_S = 60.0


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
        microphone_factory: Callable[[PcmConsumer], Any] | None = None,
        min_confidence: float = DEFAULT_MIN_CONFIDENCE,
        confirm_below: float = CONFIRM_BELOW,
        on_unmatched: Callable[[str, str], None] = lambda utterance, reason: None,
        on_utterance: Callable[[Utterance], None] = lambda utterance: None,
        endpointer_factory: Callable[[], Endpointer] | None = None,
        reply_min_above_room_db: float = REPLY_MIN_ABOVE_ROOM_DB,
    ) -> None:
        self.language = language
        #: language → recogniser; by default vosk with ``vosk_model`` (the config's) or an
        #: installed model, else pocketsphinx for English
        self._recogniser_factory = recogniser_factory or partial(_open_recogniser, vosk_model=vosk_model)
        self._microphone_factory = microphone_factory
        #: what is listened for on the current prompt, and what an utterance means there
        self._heard = Listening(
            min_confidence=min_confidence,
            confirm_below=confirm_below,
            reply_min_above_room_db=reply_min_above_room_db,
        )
        #: called with (utterance, reason) when speech was heard but was not an answer
        self.on_unmatched = on_unmatched
        #: called with every utterance the endpointer closed (timings, cut-offs: for the bench)
        self.on_utterance = on_utterance
        self._endpointer_factory = endpointer_factory
        self._lock = threading.RLock()
        self._sink: Sink | None = None
        self._recogniser: Recogniser | None = None
        self._pipeline: UtterancePipeline | None = None
        self._microphone: Any = None  # a kiosk.speech.audio.MicrophoneStream, or what the factory made
        self._listening = self._speaking = False
        #: notified when the loader thread ends (see wait_loaded)
        self._loaded = threading.Condition(self._lock)
        #: whether audio can arrive (microphone open, or attached): language changes load models
        self._running = False
        #: stop() was called: a start() still opening the microphone closes it again
        self._stopped = False
        #: the language the loader thread is to load next, and that thread while it runs
        self._wanted: str | None = None
        self._loader: threading.Thread | None = None

    # -- InputSource -------------------------------------------------------------------------

    def start(self, sink: Sink) -> None:
        """Open the microphone, then load the recogniser on the channel's loader thread: reports
        CONNECTING while it loads, then ON, or OFF with the reason. Does not wait for the model.

        The microphone stays open when only the recogniser is missing: choosing a language
        that has one turns voice answers on.
        """
        with self._lock:
            if self._stopped:
                return
            self._sink = sink
        from kiosk.speech.audio import AudioUnavailable, MicrophoneStream

        microphone = (self._microphone_factory or MicrophoneStream)(self)
        try:
            microphone.start()
        except AudioUnavailable as exc:
            self._status(ChannelState.OFF, str(exc))
            return
        with self._lock:
            if not self._stopped:
                self._microphone = microphone
                self._running = True
                self._load(self.language)
                return
        # stop() came while the microphone was opening: nobody else will close it
        microphone.stop()

    def attach(self, sink: Sink, timeout: float = LOAD_TIMEOUT_S) -> bool:
        """Like :meth:`start` without a microphone: audio comes from :meth:`feed` (WAV files,
        tests, the benchmark). Waits for the recogniser; returns whether one is available."""
        with self._lock:
            self._sink = sink
            self._running = True
            self._load(self.language)
        return self.wait_loaded(timeout)

    def wait_loaded(self, timeout: float = LOAD_TIMEOUT_S) -> bool:
        """Wait until no recogniser is being loaded; returns whether voice in has one now."""
        with self._loaded:
            self._loaded.wait_for(lambda: self._loader is None, timeout)
            return self._recogniser is not None

    def stop(self) -> None:
        """Close the microphone, also one a concurrent :meth:`start` is still opening; safe to
        call twice. A model still loading is dropped when it arrives."""
        with self._lock:
            self._stopped = True
            self._running = False
            self._wanted = None
            microphone, self._microphone = self._microphone, None
        if microphone is not None:  # outside the lock: its thread may be in feed()
            microphone.stop()

    def feed(self, pcm: bytes) -> None:
        """16 kHz mono int16 audio into the pipeline (what the microphone thread does)."""
        with self._lock:
            if self._pipeline is not None:
                self._pipeline.feed(pcm)

    @property
    def in_speech(self) -> bool:
        """Whether the patient is speaking now (an utterance is open in the endpointer)."""
        with self._lock:
            return self._pipeline is not None and not self._pipeline.muted and self._pipeline.endpointer.in_speech

    # -- what the session and the voice out tell it (UI / TTS threads) ------------------------

    def on_session_event(self, event: SessionEvent) -> None:
        """Follow every session event: grammars, the listening gate, and pause (commands only).
        Dispatched by class, as :meth:`kiosk.ui.channels.KioskChannels.follow` does, so a
        renamed event is a type error, not a silently ignored string."""
        if isinstance(event, Prompt):
            self.expect(event)
        elif isinstance(event, ListeningChanged):
            self.listen(event.listening)
        elif isinstance(event, Paused):
            self._set_paused(True)
        elif isinstance(event, (Resumed, Finished)):
            self._set_paused(False)
        elif isinstance(event, AnswerRecorded):
            self.expect_undo()
        elif isinstance(event, AnswerNotConfirmed) and event.why in ("declined", "undone"):
            self.declined(event.item_id, event.option)

    def expect(self, prompt: Any) -> None:
        """A session ``Prompt``: a question's options become the grammar (messages change nothing)."""
        if prompt.options:
            scored = any(getattr(o, "points", None) is not None for o in prompt.options)
            self.set_question(
                option_words(prompt.options),
                prompt.language,
                scored=scored,
                welcome=getattr(prompt, "kind", "") in ("welcome", "message"),
                key=getattr(prompt, "key", None),
                # "Is that right?", and "Shall I call the nurse?": the same rules for a spoken yes
                confirming=getattr(prompt, "kind", "") in ("confirm", "call"),
                again=bool(getattr(prompt, "repeat", False)),
            )

    def set_question(
        self,
        options: Sequence[OptionWords],
        language: str,
        scored: bool = False,
        welcome: bool = False,
        key: str | None = None,
        confirming: bool = False,
        again: bool = False,
    ) -> None:
        """Listen for this question's answers (and the commands) in ``language``; answers to a
        ``scored`` question are confirmed unless heard with confidence (see :data:`CONFIRM_BELOW`).
        ``confirming``: the options reply to "Is that right?"; one spoken in a room nearly as
        loud as the voice is sent as unsure (see :data:`REPLY_MIN_ABOVE_ROOM_DB`).
        At the ``welcome`` (or the explanation) the only command is calling the doctor, in whole phrases.
        ``key`` names the question: asked again under the same key, the options the patient
        declined on it are not listened for (see :meth:`declined`). ``again``: the same prompt
        asked again (a "yes" heard unsure on it before counts as a first hearing)."""
        with self._lock:
            self._heard.set_question(
                options, scored=scored, welcome=welcome, key=key, confirming=confirming, again=again
            )
            if language != self.language:
                self.language = language
                # before start() the language is only noted; the model loads off the UI thread
                if self._running:
                    self._load(language)
            self._apply_grammar()

    def declined(self, key: str, option: int) -> None:
        """The patient said No to "I heard: <option>. Is that right?" on question ``key``: while
        that question is asked again, its words are left out of the grammar, so the recogniser
        does not offer the same mishearing twice (the model heard espeak-ng's "the first one" as
        "the third one" again and again for some voices; "sometimes" as "never"). The option
        can still be touched or chosen with the remote; the next question listens for all."""
        with self._lock:
            self._heard.declined(key, option)

    def expect_undo(self) -> None:
        """An answer was stored: until the next prompt only taking it back ("No, that's wrong",
        "change my answer") and calling the doctor are listened for. The answered question's own
        words would mean nothing in the thank-you gap."""
        with self._lock:
            self._heard.expect_undo()
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
            if self._heard.set_paused(paused):
                self._apply_grammar()
                self._gate()

    def _load(self, language: str) -> None:
        """(Lock held.) Have the loader thread load ``language``'s recogniser; until it is
        installed voice in does not listen, and its status says so."""
        self._recogniser = self._heard.matcher = None
        self._gate()
        self._wanted = language
        self._status(ChannelState.CONNECTING, f"loading the speech model for {language!r}")
        if self._loader is None:
            self._loader = threading.Thread(target=self._run_loader, name="kiosk-voice-model", daemon=True)
            self._loader.start()

    def _run_loader(self) -> None:
        """The loader thread: loads the wanted language's recogniser (seconds for vosk) and
        installs it only if that is still the language; ends when nothing more is wanted."""
        while True:
            with self._lock:
                language, self._wanted = self._wanted, None
                if language is None or self._stopped:
                    self._loader = None
                    self._loaded.notify_all()
                    return
            recogniser, failure, key = None, "", ""
            from kiosk.speech.asr import AsrUnavailable

            try:
                recogniser = self._recogniser_factory(language)
            except AsrUnavailable as exc:
                failure, key = str(exc), getattr(exc, "reason_key", "")
            except Exception as exc:  # a broken model must not leave voice in loading for ever
                log.exception("voice: loading the speech model for %r failed", language)
                failure = f"the speech model for {language!r} cannot be loaded ({exc})"
            with self._lock:
                if self._stopped or language != self.language:
                    continue  # superseded while it loaded: the newer language is wanted next
                if self._wanted == language:
                    self._wanted = None  # changed away and back while loading: this one is current
                if recogniser is None:
                    self._status(ChannelState.OFF, failure, key)
                else:
                    self._install(recogniser)

    def _install(self, recogniser: Recogniser) -> None:
        """(Lock held.) Make ``recogniser`` the one the audio reaches, with the current grammar."""
        self._recogniser = recogniser
        if self._pipeline is None:
            from kiosk.speech.audio import Endpointer, UtterancePipeline

            endpointer = (self._endpointer_factory or Endpointer)()
            self._pipeline = UtterancePipeline(recogniser, self._on_utterance, endpointer=endpointer)
        else:
            self._pipeline.muted = True  # drop an utterance the old recogniser was hearing
            self._pipeline.recogniser = recogniser
        self._apply_grammar()
        self._gate()
        fallback = getattr(recogniser, "fallback", "")
        self._status(ChannelState.ON, f"voice answers on: {recogniser.name}" + (f" ({fallback})" if fallback else ""))

    def _apply_grammar(self) -> None:
        """(Lock held.) Give the recogniser the current prompt's grammar, once there is one."""
        if self._recogniser is None:
            return
        phrases = self._heard.grammar(self.language)
        if phrases is None:
            return
        matcher = self._heard.matcher
        assert matcher is not None  # phrases come from a matcher
        self._recogniser.set_grammar(
            phrases, matcher.meaning, matcher.lead_ins(), matcher.fillers(), taken_as_heard=self._heard.taken_as_heard
        )
        self._gate()

    def _gate(self) -> None:
        if self._pipeline is not None:
            heard = self._heard
            wanted = (self._listening or heard.paused) and heard.matcher is not None and self._recogniser is not None
            self._pipeline.muted = self._speaking or not wanted

    def _on_utterance(self, utterance: Utterance) -> None:
        """(Lock held, microphone thread.) An utterance to the session, or to ``on_unmatched``."""
        self.on_utterance(utterance)
        heard = self._heard.hear(utterance)
        if isinstance(heard, str):
            log.info("voice: %s", heard)
            self.on_unmatched(cast("Recognition", utterance.result).text, heard)
        elif self._sink is not None:
            self._sink(heard)

    def _status(self, state: ChannelState, reason: str, reason_key: str = "") -> None:
        """Every status under the one source name, so the latest always wins on the channel
        board; what it is about (microphone, model, recogniser) is in the reason."""
        if self._sink is not None:
            if state is ChannelState.OFF:
                reason = f"voice answers off: {reason}"
            self._sink(ChannelStatus(Channel.VOICE, state, source=self.name, reason=reason, reason_key=reason_key))


def _open_recogniser(language: str, vosk_model: str | Path | None) -> Recogniser:
    """The default recogniser (vosk, else pocketsphinx), imported on the loader thread."""
    from kiosk.speech.asr import open_recogniser

    return open_recogniser(language, vosk_model)

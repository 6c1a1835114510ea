"""The kiosk's channels besides touch, and how they follow the session: what is said, what is
listened for, what a key means, which ways of answering the patient is offered.

:class:`KioskChannels` is plain: the app (:mod:`kiosk.ui.app`) starts the sources on worker
threads, hands their deliveries over to the UI thread and calls these methods there.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from kiosk.core.adaptation import VOICE_OFF
from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus, Command, InputSource
from kiosk.core.session import (
    AnswerRecorded,
    DoctorCalled,
    IgnoreReason,
    InputIgnored,
    ListeningChanged,
    Paused,
    Prompt,
    SessionEvent,
    Snapshot,
    VolumeChanged,
)
from kiosk.remote.buttons import KIOSK_KEY_BUTTONS
from kiosk.ui.screens.base import Ways, spoken_with_ways
from kiosk.ui.widgets.channel_board import CAMERA, REMOTE, VOICE_IN, VOICE_OUT, ChannelBoard

#: the source name the voice-out statuses carry when no speaker is wired
VOICE_OUT_SOURCE = "espeak-ng"


class KioskChannels:
    """``speaker`` is a ``kiosk.speech.tts.Speaker`` or None (voice out off); ``voice`` a
    ``kiosk.speech.voice.VoiceChannel`` (an input source that also follows the session's events)
    or None; ``sources`` the remotes' input sources; ``keyboard`` a ``kiosk.remote.KeyboardRemote``
    for remotes that type keys; ``statuses`` the channel states known before start-up, such as
    "voice in off: no microphone found". :attr:`board` keeps the latest status of each. ``poses``:
    the camera's landmarks for a Timed Up and Go (a :class:`kiosk.camera.feed.PoseFeed`, or an
    object with its ``into`` and ``clear``), None without a camera."""

    def __init__(
        self,
        speaker: Any = None,
        voice: Any = None,
        sources: Iterable[InputSource] = (),
        keyboard: Any = None,
        statuses: Iterable[ChannelStatus] = (),
        poses: Any = None,
    ) -> None:
        self.speaker, self.voice, self.sources, self.keyboard = speaker, voice, list(sources), keyboard
        self.poses = poses
        self.board = ChannelBoard(getattr(speaker, "source", VOICE_OUT_SOURCE))
        if speaker is None:
            self.board.update(ChannelStatus(Channel.VOICE, ChannelState.OFF, VOICE_OUT_SOURCE, "voice out turned off"))
        for status in statuses:
            self.board.update(status)
        #: a repeated prompt on its way through the speaker: "queued", then "speaking"
        self._repeat: str | None = None
        #: the patient pressed a number the question on screen does not have (a hint shows)
        self.no_such_option = False

    def input_sources(self) -> list[InputSource]:
        """Every source delivering inputs (the remotes, and voice in)."""
        return self.sources + ([self.voice] if self.voice is not None else [])

    def close(self) -> None:
        """Stop every source and the speaker (each stop is safe to call twice)."""
        for source in self.input_sources():
            source.stop()
        if self.speaker is not None:
            self.speaker.close()

    def on(self, indicator: str) -> bool:
        """The channel behind ``indicator`` (VOICE_IN, VOICE_OUT, REMOTE) is on."""
        return self.board.state(indicator)[0] is ChannelState.ON

    def camera_off(self) -> str | None:
        """Why the camera cannot time a Timed Up and Go now (None: it can)."""
        state, reason = self.board.state(CAMERA)
        if state is ChannelState.ON and self.poses is not None:
            return None
        return reason or ("the camera is not on" if state is not ChannelState.ON else "no landmarks reach the kiosk")

    def say(self, text: str, language: str) -> None:
        """Speak ``text`` (the kiosk's voice, when it has one)."""
        if self.speaker is not None:
            self.speaker.say(text, language)

    def about_voice(self, status: ChannelStatus) -> bool:
        """``status`` changes whether voice in or voice out is on."""
        return self.board.indicator(status) in (VOICE_IN, VOICE_OUT)

    def ways(self, snap: Snapshot) -> Ways:
        """The ways the patient can answer now, as the screens say them."""
        voice_in = self.on(VOICE_IN)
        return Ways(
            remote=self.on(REMOTE),
            voice=voice_in and not VOICE_OFF & snap.adaptations,
            listening=voice_in and self.board.listening,
            voice_out=self.on(VOICE_OUT),
        )

    def key_input(self, key: str) -> ChannelInput | None:
        """What a key pressed on a patient screen means (a keyboard remote's key, a number, a
        control letter), or None."""
        item = self.keyboard.translate(key) if self.keyboard is not None else None
        if item is None and key not in KIOSK_KEY_BUTTONS:  # "C" (or "shift+c") is C
            key = key.removeprefix("shift+").lower() if len(key.removeprefix("shift+")) == 1 else key
        if item is None and key in KIOSK_KEY_BUTTONS:
            meaning = KIOSK_KEY_BUTTONS[key]
            detail = f"key {key}"
            item = (
                ChannelInput(Channel.KEYBOARD, command=meaning, detail=detail)
                if isinstance(meaning, Command)
                else ChannelInput(Channel.KEYBOARD, option=meaning, detail=detail)
            )
        return item

    def follow(self, event: SessionEvent, ways: Callable[[], Ways]) -> None:
        """Carry out what a session event asks of the channels; ``ways()`` are said with a prompt."""
        if self.voice is not None:  # its grammar follows the prompts, its gate the listening state
            self.voice.on_session_event(event)
        if isinstance(event, Prompt):
            self._speak(event, ways)
        elif isinstance(event, ListeningChanged):
            self.board.listening = event.listening
        elif isinstance(event, InputIgnored):
            self.no_such_option = event.reason is IgnoreReason.NO_SUCH_OPTION
        if isinstance(event, (Prompt, AnswerRecorded)):  # the hint was about the question before
            self.no_such_option = False
        if isinstance(event, (AnswerRecorded, Paused, DoctorCalled)):
            if self.speaker is not None:
                self.speaker.stop_speaking()
        elif isinstance(event, VolumeChanged) and self.speaker is not None:
            (self.speaker.volume_up if event.step > 0 else self.speaker.volume_down)()

    def _speak(self, prompt: Prompt, ways: Callable[[], Ways]) -> None:
        if self.speaker is None or not prompt.spoken:
            return
        from kiosk.speech.tts import DEFAULT_RATE

        if prompt.repeat:  # asked again: what was still queued is superseded
            self.speaker.stop_speaking()
            self._repeat = "queued"
        self.speaker.rate = round(DEFAULT_RATE * prompt.speech_rate)
        self.speaker.say(spoken_with_ways(prompt.spoken, prompt.language, ways()), prompt.language)

    def speaking(self, speaking: bool) -> bool:
        """Voice out started or stopped talking; True once a repeated prompt has been said (the
        speaker works through its phrases in order, so the repeat is the phrase that starts after
        it was queued; a phrase cut short for it ends before)."""
        self.board.speaking = speaking
        if speaking and self._repeat == "queued":
            self._repeat = "speaking"
        elif not speaking and self._repeat == "speaking":
            self._repeat = None
            return True
        return False

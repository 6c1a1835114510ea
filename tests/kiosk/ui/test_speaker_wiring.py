"""The app wired to the real voice out: espeak-ng synthesises every prompt on the speaker's worker
thread; a recording player stands in for the sound card (none here). The bar shows "speaking",
a repeat is reported back to the session once spoken, and "I am having trouble hearing you" is
never said while voice in is off."""

from __future__ import annotations

import shutil
import threading

import pytest

from kiosk.core.channels import ChannelState
from kiosk.core.session import Prompt
from kiosk.speech.tts import Speaker
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.widgets.channel_board import VOICE_OUT

from .helpers import late_touch_answer, settle, start_in_english, until_thread

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng is not installed"),
]


class RecordingPlayer:
    """Stands in for the sound card: keeps how many phrases would have been played."""

    def __init__(self) -> None:
        self.played = 0
        self.lock = threading.Lock()

    def play(self, samples, rate) -> None:
        """Count the phrase; a real card would block for its duration."""
        with self.lock:
            self.played += 1

    def stop(self) -> None:
        """Nothing is playing."""


async def test_prompts_are_spoken_and_a_spoken_repeat_is_reported_to_the_session(ui_kiosk):
    player = RecordingPlayer()
    kiosk = ui_kiosk(familiarisation=False, speaker=Speaker(player_factory=lambda: player))
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await until_thread(lambda: kiosk.app.board.state(VOICE_OUT)[0] is ChannelState.ON, "the speaker's worker")
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        spoken = sum(1 for e in kiosk.controller.events if isinstance(e, Prompt) and e.spoken)
        await until_thread(
            lambda: player.played >= spoken, "the speaker's worker"
        )  # welcome, explanation, the first question

        def states() -> list[str]:
            return [e["set"]["TestState"] for e in kiosk.session.trace if "TestState" in e.get("set", {})]

        await pilot.press("r")  # repeat: TestState REPEATING until the repeat has been said
        await until_thread(lambda: states()[-2:] == ["REPEATING", "STARTED"], "the speaker's worker")
        assert player.played >= spoken + 1


class SaidSpeaker(Speaker):
    """The real espeak-ng speaker, keeping the words it was given."""

    def __init__(self, **options) -> None:
        super().__init__(**options)
        self.said: list[str] = []

    def say(self, text: str, language: str | None = None) -> None:
        self.said.append(text)
        super().say(text, language)


async def test_trouble_hearing_is_never_said_while_voice_in_is_off(ui_kiosk):
    player = RecordingPlayer()
    speaker = SaidSpeaker(player_factory=lambda: player)
    kiosk = ui_kiosk(familiarisation=False, speaker=speaker)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await until_thread(lambda: kiosk.app.board.state(VOICE_OUT)[0] is ChannelState.ON, "the speaker's worker")
        await start_in_english(kiosk, pilot)
        for _ in range(8):  # with voice in on, these late answers switch voice_off on
            await late_touch_answer(kiosk, pilot)
        prompts = [e for e in kiosk.controller.events if isinstance(e, Prompt) and e.spoken]
        assert not [p for p in prompts if p.key in ("voice_off", "voice_on")]  # the session never asked...
        # ...and the app gave the speaker every prompt it was given, and nothing else (not whether
        # each was played: a question still being synthesised when its answer came is dropped)
        assert len(speaker.said) == len(prompts)
        assert not [text for text in speaker.said if "trouble hearing" in text]


async def test_the_spoken_practice_promises_only_the_channels_that_are_on(ui_kiosk):
    """ "Please choose answer number three" goes on with the ways that work: with no remote and no
    voice in (this kiosk's channels), only touching it is said."""
    player = RecordingPlayer()
    speaker = SaidSpeaker(player_factory=lambda: player)
    kiosk = ui_kiosk(familiarisation=True, speaker=speaker)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await until_thread(lambda: kiosk.app.board.state(VOICE_OUT)[0] is ChannelState.ON, "the speaker's worker")
        await settle(pilot, lambda: kiosk.session.snapshot().phase.value == "welcome")
        await pilot.press("1")
        for _ in range(6):  # hear, read, select: answer each practice question as it comes
            practice = kiosk.session.snapshot().practice
            if practice is not None and practice.id == "practice_select":
                break
            if practice is not None and kiosk.session.current_attempt:
                await pilot.press(str(practice.expected))
            kiosk.to_next_deadline()
            await settle(pilot)
        assert kiosk.session.snapshot().practice.id == "practice_select"
    select = [text for text in speaker.said if text.startswith("Please choose answer number three")]
    assert select == ["Please choose answer number three. Touch it."]
    assert not [text for text in speaker.said if "{ways}" in text or "remote" in text]

"""Driving a kiosk through Pilot: waiting for the app to settle, moving through whole sessions."""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Awaitable, Callable

from textual.pilot import Pilot

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus
from kiosk.core.session import Phase

from .conftest import UiKiosk

#: event-loop turns to wait for something the app must do (a message from a thread, a new screen)
TURNS = 200
#: how long, at the least, before giving up on it: the channels' threads start after the first
#: frame and may wait for a core on a busy machine, which no count of quick turns waits for
PATIENCE_S = 30.0


async def settle(pilot: Pilot, until: Callable[[], bool] = lambda: True) -> None:
    """Let the app process its messages until ``until()`` holds: quick turns first, then short
    pauses that leave the machine to the app's threads, for at least :data:`PATIENCE_S`."""
    for _ in range(TURNS):
        await pilot.pause()
        if until():
            return
    deadline = time.monotonic() + PATIENCE_S
    while time.monotonic() < deadline:
        await pilot.pause(0.02)
        if until():
            return
    raise AssertionError("the app never reached the expected state")


def deliver_from_thread(kiosk: UiKiosk, item: ChannelInput | ChannelStatus) -> None:
    """Deliver an input the way a channel does: calling the app's sink from another thread."""
    thread = threading.Thread(target=kiosk.app.channel_sink, args=(item,))
    thread.start()
    thread.join(timeout=5)


def text_of(widget) -> str:
    """What a widget shows, as plain text."""
    return str(widget.render())


async def until_thread(condition: Callable[[], bool], what: str, patience_s: float = 30.0) -> None:
    """Wait, boundedly, for a real worker thread (a reader, espeak-ng, a recogniser) to make
    ``condition()`` hold; ``what`` names that thread in the failure."""
    deadline = time.monotonic() + patience_s
    while not condition():
        assert time.monotonic() < deadline, f"{what} never got there"
        await asyncio.sleep(0.01)


def screen_name(kiosk: UiKiosk) -> str:
    """The class name of the screen on top."""
    return type(kiosk.app.screen).__name__


async def start_in_english(kiosk: UiKiosk, pilot: Pilot) -> None:
    """Press 1 (English) on the welcome screen and get through practice and explanation by keys."""
    await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
    await pilot.press("1")
    await settle(pilot)
    while kiosk.session.phase is Phase.FAMILIARISATION:
        practice = kiosk.session.snapshot().practice
        if practice is not None and kiosk.session.current_attempt is not None:
            await pilot.press(str(practice.expected))
        else:
            kiosk.to_next_deadline()
        await settle(pilot)
    assert screen_name(kiosk) == "ExplanationScreen"
    await pilot.press("1")
    await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)


async def answer_every_question(kiosk: UiKiosk, pilot: Pilot, answer: Callable[[int, int], Awaitable[None]]) -> None:
    """For each of the ten questions: wait until it is open on screen, then ``answer(number, option)``
    with the last option (always allowed); finally wait for the summary."""
    for number in range(1, len(kiosk.questionnaire.items) + 1):
        kiosk.to_next_deadline()  # the gap before the question opens
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        assert kiosk.session.snapshot().number == number
        item = kiosk.session.current_item
        await answer(number, len(item.options))
        await settle(pilot, lambda: item.id in kiosk.session.answers)
    kiosk.to_next_deadline()  # closing
    await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")


async def late_touch_answer(kiosk: UiKiosk, pilot: Pilot) -> None:
    """A late touch answer (after the first attempt ran out) drags VoiceInteractionQuality down."""
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 2)
    kiosk.advance(3)
    item = kiosk.session.current_item
    await pilot.click("#answer-1")
    await settle(pilot, lambda: item.id in kiosk.session.answers)


async def start_with_voice_off(kiosk: UiKiosk, pilot: Pilot) -> None:
    """Start a kiosk whose voice in works (so "I am having trouble hearing you" is true) and answer
    late by touch until the voice_off adaptation switches on."""
    deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.ON, "voice in", "pocketsphinx"))
    await start_in_english(kiosk, pilot)
    for _ in range(8):
        await late_touch_answer(kiosk, pilot)
        if "voice_off" in kiosk.session.snapshot().adaptations:
            return
    raise AssertionError("voice_off never switched on")


def drawn_text(app) -> str:
    """The screen as the compositor draws it now, as plain text lines: what a patient would read
    (tests wait on this, not on the session's state, before they look or snapshot)."""
    import io

    from rich.console import Console

    width, height = app.size
    console = Console(
        width=width,
        height=height,
        file=io.StringIO(),
        record=True,
        legacy_windows=False,
        force_terminal=True,
        color_system=None,
    )
    console.print(app.screen._compositor.render_update(full=True, screen_stack=app._background_screens))
    return console.export_text()


async def until_drawn(pilot: Pilot, *texts: str) -> str:
    """Let the app process and draw until every one of ``texts`` is on screen; the drawn text."""
    shown = ""

    def check() -> bool:
        nonlocal shown
        shown = drawn_text(pilot.app)
        return all(text in shown for text in texts)

    for _ in range(TURNS):
        await pilot.pause()
        if check():
            return shown
    raise AssertionError(f"never drawn: {[t for t in texts if t not in shown]}\n{shown}")

"""The app only renders and forwards: what it shows comes from the session's decisions (attempts,
answer numbers before the questions, voice-in availability, the latest prompt, presence)."""

from __future__ import annotations

from textual.widgets import Label

from kiosk.app import KIOSK_SIZE
from kiosk.session import ATTEMPTS

from .helpers import settle, start_in_english


def _text(widget) -> str:
    return str(widget.render())


async def test_the_attempt_indicator_counts_up_to_the_sessions_attempts(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        for attempt in range(1, ATTEMPTS + 1):
            kiosk.to_next_deadline()  # the gap before the question, then each attempt's window
            await settle(pilot, lambda: kiosk.session.current_attempt == attempt)
            label = kiosk.app.screen.query_one("#attempt", Label)
            await settle(pilot, lambda: _text(label) == f"Attempt {attempt} of {ATTEMPTS}")

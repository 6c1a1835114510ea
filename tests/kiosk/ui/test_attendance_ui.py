"""What the patient sees when nobody is there (Textual Pilot, issues 34 and 36): one calm message
while away, never "Let us go on" with nobody there; after two unanswered questions in a row the
kiosk waits for a touch, and a touch goes on where the test was."""

from __future__ import annotations

from kiosk.core.channels import Presence, PresenceSource
from kiosk.core.session import AwayAlert, QuestionNotAnswered, Unattended
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.widgets.text import ui_text

from .helpers import deliver_from_thread, drawn_text, screen_name, settle, start_in_english

AWAY = ui_text("en", "person_lost")  # "The test is waiting for you. Please come back in front of the screen."
WAIT = ui_text("en", "unattended")  # "Are you still there? Touch the screen to go on."
GO_ON_LINE = "Let us go on to the next question."


def drawn(kiosk) -> str:
    """The screen's text with its line breaks and padding folded, as one line."""
    return " ".join(drawn_text(kiosk.app).replace("│", " ").split())


def camera(kiosk, seen: bool) -> None:
    """The camera's report, delivered from another thread as the camera channel does."""
    deliver_from_thread(kiosk, Presence(seen, PresenceSource.CAMERA, "test"))


async def test_away_during_the_go_on_gap_shows_one_calm_message(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, unattended_after=5)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        for _ in range(3):  # question 1, its attempt 2, not answered: "Let us go on to the next question."
            kiosk.to_next_deadline()
            await settle(pilot)
        await settle(pilot, lambda: GO_ON_LINE in drawn(kiosk))
        camera(kiosk, False)
        await settle(pilot, lambda: AWAY in drawn(kiosk))
        shown = drawn(kiosk)
        assert GO_ON_LINE not in shown and "Take your time" not in shown  # one message, not two at once
        kiosk.advance(3600)  # an hour away: the gap is frozen, the ward was alerted
        await settle(pilot, lambda: AWAY in drawn(kiosk))
        assert kiosk.session.snapshot().number == 1 and GO_ON_LINE not in drawn(kiosk)
        assert len([e for e in kiosk.controller.events if isinstance(e, AwayAlert)]) == 1
        camera(kiosk, True)
        await settle(pilot, lambda: AWAY not in drawn(kiosk))
        kiosk.to_next_deadline()
        await settle(pilot, lambda: "Question 2 of" in drawn(kiosk))  # the test goes on where it was


async def test_after_two_unanswered_questions_the_kiosk_waits_for_a_touch(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, unattended_after=2)  # the kiosk's default
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        for _ in range(6):  # the gap, question 1 (two attempts), the gap, question 2 (two attempts)
            kiosk.to_next_deadline()
            await settle(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "UnattendedScreen")
        await settle(pilot, lambda: WAIT in drawn(kiosk))
        assert GO_ON_LINE not in drawn(kiosk)
        assert kiosk.session.next_deadline() is None  # nothing more times out: it waits
        unanswered = [e.item_id for e in kiosk.controller.events if isinstance(e, QuestionNotAnswered)]
        assert unanswered == ["feeding", "bathing"]
        assert [e.count for e in kiosk.controller.events if isinstance(e, Unattended)] == [2]

        camera(kiosk, False)  # nobody in front of it either: still one message
        await settle(pilot, lambda: AWAY in drawn(kiosk))
        assert WAIT not in drawn(kiosk)
        camera(kiosk, True)
        await settle(pilot, lambda: WAIT in drawn(kiosk) and AWAY not in drawn(kiosk))

        await pilot.click("#go-on")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen" and "Question 3 of" in drawn(kiosk))
        assert kiosk.session.current_attempt == 1 and kiosk.session.answers == {}  # the touch answered nothing
        stored = kiosk.store.session(kiosk.session.id)
        assert [(e.kind, e.detail) for e in stored.log if e.kind.startswith("unattended")] == [
            ("unattended", "2"),
            ("unattended_ended", "touch"),
        ]


async def test_a_touch_anywhere_goes_on_and_a_key_does_too(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, unattended_after=1)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        for _ in range(3):
            kiosk.to_next_deadline()
            await settle(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "UnattendedScreen")
        await pilot.click("#unattended-text")
        await settle(pilot, lambda: "Question 2 of" in drawn(kiosk))
        for _ in range(2):
            kiosk.to_next_deadline()
            await settle(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "UnattendedScreen")
        await pilot.press("3")
        await settle(pilot, lambda: "Question 3 of" in drawn(kiosk))
        assert kiosk.session.answers == {}

"""The app only renders and forwards: what it shows comes from the session's decisions (attempts,
answer numbers before the questions, voice-in availability, the latest prompt, presence)."""

from __future__ import annotations

from textual.widgets import Label

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus
from kiosk.core.session import ATTEMPTS, AttemptTimedOut, Phase, Prompt
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.ui.widgets.bars import AdaptationBanner
from kiosk.ui.widgets.text import ui_text

from .conftest import UI_PIN
from .helpers import deliver_from_thread, screen_name, settle, start_in_english, start_with_voice_off, text_of


async def test_the_attempt_indicator_counts_up_to_the_sessions_attempts(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        for attempt in range(1, ATTEMPTS + 1):
            kiosk.to_next_deadline()  # the gap before the question, then each attempt's window
            await settle(pilot, lambda: kiosk.session.current_attempt == attempt)
            label = kiosk.app.screen.query_one("#attempt", Label)
            await settle(pilot, lambda: text_of(label) == f"Attempt {attempt} of {ATTEMPTS}")


async def test_number_keys_before_the_questions_start_in_that_language_and_acknowledge(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("2")  # the second start button: Spanish
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        assert kiosk.session.language == "es"
        deliver_from_thread(kiosk, ChannelInput(Channel.REMOTE, option=4, detail="BTN 4"))
        await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)
        assert kiosk.session.trace == [{"t": 0, "set": {"PersonDetected": True, "TestState": "STARTED"}}]
        assert kiosk.store.session(kiosk.session.id).language == "es"


async def test_voice_in_status_reaches_the_session_and_a_lost_microphone_lifts_voice_off(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_with_voice_off(kiosk, pilot)
        banner = kiosk.app.screen.query_one(AdaptationBanner)
        assert banner.display and "trouble hearing" in text_of(banner)
        deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.LOST, "voice in", "microphone unplugged"))
        await settle(pilot, lambda: "voice_off" not in kiosk.session.snapshot().adaptations)
        await settle(pilot, lambda: not kiosk.app.screen.query_one(AdaptationBanner).display)
        voice_prompts = [
            e.key for e in kiosk.controller.events if isinstance(e, Prompt) and e.key in ("voice_off", "voice_on")
        ]
        assert voice_prompts == ["voice_off"]  # no "I can hear you again" with the microphone gone
        stored = kiosk.store.session(kiosk.session.id)
        assert [(a.name, a.active, a.reason) for a in stored.adaptations][-1] == (
            "voice_off",
            False,
            "voice in is unavailable",
        )
        # "available" came before the start, when there was no stored session to log it in
        assert [e.detail for e in stored.log if e.kind == "voice_in"] == ["unavailable"]


async def _clinician_presses(kiosk, pilot, button: str) -> None:
    """Open the clinician screens behind the PIN, press ``button`` and get back to the patient."""
    await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
    await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
    await pilot.click(button)
    await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")


async def test_the_clinician_marks_the_patient_left_and_back_and_the_attempt_clock_follows(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    timing = kiosk.session.timing
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        left_with = 3.0
        assert left_with < timing.person_back_grace_s
        kiosk.advance(timing.attempt_window_s - left_with)

        await _clinician_presses(kiosk, pilot, "#person-lost")
        notice = ui_text("en", "person_lost")
        await settle(pilot, lambda: notice in text_of(kiosk.app.screen.query_one(AdaptationBanner)))
        kiosk.advance(10 * timing.attempt_window_s)  # far past the deadline: the clock is frozen
        await settle(pilot)
        assert not [e for e in kiosk.controller.events if isinstance(e, AttemptTimedOut)]
        assert kiosk.session.current_attempt == 1 and kiosk.session.remaining() == left_with
        assert notice in text_of(kiosk.app.screen.query_one(AdaptationBanner))

        await _clinician_presses(kiosk, pilot, "#person-back")
        await settle(pilot, lambda: not kiosk.app.screen.query_one(AdaptationBanner).display)
        # at least the grace is left; leaving the clinician screens also resumes the pause their
        # opening made, with its own grace
        grace = max(timing.person_back_grace_s, timing.resume_grace_s)
        assert kiosk.session.remaining() == grace
        kiosk.advance(grace - 0.1)
        await settle(pilot)
        assert kiosk.session.current_attempt == 1
        await pilot.press("2")  # the patient answers the attempt that was waiting for them
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        assert kiosk.session.answers["feeding"].attempt == 1

    presence = [
        e["set"]["PersonDetected"]
        for e in kiosk.store.session(kiosk.session.id).trace
        if "PersonDetected" in e.get("set", {})
    ]
    assert presence == [True, False, True]  # the start, the clinician's "left", then "back"

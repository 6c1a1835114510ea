"""Pause and resume, call doctor and the clinician's continue, attempts timing out on the simulated
clock, and a live adaptation reaching the screen -- all through the real app and session."""

from __future__ import annotations

import time

from textual.widgets import Label, Static

from kiosk.core.session import AttemptTimedOut, Phase, Prompt, QuestionNotAnswered
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.ui.widgets.bars import AdaptationBanner, VoiceAgainButton

from .conftest import UI_PIN
from .helpers import late_touch_answer, screen_name, settle, start_in_english, start_with_voice_off, text_of


async def _first_question(kiosk, pilot) -> None:
    await start_in_english(kiosk, pilot)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)


async def test_pause_freezes_the_attempt_and_continue_comes_back_to_the_question(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        kiosk.advance(120)  # far past the 20 s window: a paused attempt never times out
        await pilot.press("2")  # answers are not taken while paused
        await settle(pilot)
        assert screen_name(kiosk) == "PausedScreen" and kiosk.session.answers == {}
        await pilot.click("#resume")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert text_of(kiosk.app.screen.query_one("#attempt", Label)) == "Attempt 1 of 2"
        await pilot.press("2")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        assert kiosk.session.answers["feeding"].attempt == 1
        log = [e.kind for e in kiosk.store.session(kiosk.session.id).log]
        # the "2" while paused is logged (and, at the start, how the visit began, a walk-up, and
        # that this kiosk has no voice out)
        assert log[:6] == ["start", "visit", "voice_out", "pause", "input_ignored", "resume"]


async def test_call_doctor_halts_until_a_clinician_continues_behind_the_pin(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        await pilot.click("#call-doctor")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        await pilot.press("p", "2")  # other keys do nothing while halted (1 is "I am fine, carry on")
        await settle(pilot)
        assert kiosk.session.halted and kiosk.session.answers == {}

        await pilot.press(CLINICIAN_CHORD)
        await settle(pilot, lambda: screen_name(kiosk) == "PinScreen")
        await pilot.press("9", "9", "9", "9", "enter")
        await settle(pilot)
        assert screen_name(kiosk) == "PinScreen"
        assert text_of(kiosk.app.screen.query_one("#pin-error", Label)) == "Wrong PIN."
        assert text_of(kiosk.app.screen.query_one("#pin", Static)).strip() == ""  # the field is emptied
        await pilot.press(*UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        assert "waiting for a clinician" in text_of(kiosk.app.screen.query_one("#current", Static))
        await pilot.click("#continue")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert not kiosk.session.halted
        await pilot.press("3")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        kinds = [e.kind for e in kiosk.store.session(kiosk.session.id).log]
        assert kinds.index("call_doctor") < kinds.index("clinician_continue")


async def test_an_attempt_times_out_twice_and_the_next_question_comes(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        attempt = kiosk.app.screen.query_one("#attempt", Label)
        assert text_of(attempt) == "Attempt 1 of 2"
        kiosk.advance(19.9)
        await settle(pilot)
        assert text_of(attempt) == "Attempt 1 of 2"
        kiosk.advance(0.2)
        await settle(pilot, lambda: text_of(attempt) == "Attempt 2 of 2")
        kiosk.advance(20.1)
        await settle(pilot, lambda: any(isinstance(e, QuestionNotAnswered) for e in kiosk.controller.events))
        assert [e.attempt for e in kiosk.controller.events if isinstance(e, AttemptTimedOut)] == [1, 2]
        kiosk.to_next_deadline()
        await settle(pilot, lambda: text_of(kiosk.app.screen.query_one("#progress", Label)) == "Question 2 of 10")
        assert text_of(kiosk.app.screen.query_one("#attempt", Label)) == "Attempt 1 of 2"
        assert kiosk.store.session(kiosk.session.id).not_answered == ("feeding",)


async def test_the_voice_off_adaptation_appears_on_screen(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_with_voice_off(kiosk, pilot)
        banner = kiosk.app.screen.query_one(AdaptationBanner)
        # no remote is connected here: the notice offers touch only, never a remote it has not got
        assert banner.display and "Please touch your answer." in text_of(banner)
        assert "remote" not in text_of(banner)
        # it stays on the next question's screen too
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        assert kiosk.app.screen.query_one(AdaptationBanner).display
        assert kiosk.session.phase is Phase.QUESTIONS


async def test_the_patient_touches_answer_by_voice_again_and_the_kiosk_listens_again(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_with_voice_off(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        assert not kiosk.session.listening
        button = kiosk.app.screen.query_one(VoiceAgainButton)
        assert button.display and str(button.label) == "Answer by voice again"
        await pilot.click("#voice-again")
        await settle(pilot, lambda: kiosk.session.listening)
        assert "voice_off" not in kiosk.session.snapshot().adaptations
        assert not kiosk.app.screen.query_one(AdaptationBanner).display
        assert not kiosk.app.screen.query_one(VoiceAgainButton).display
        said = [e.key for e in kiosk.controller.events if isinstance(e, Prompt) and e.key in ("voice_off", "voice_on")]
        assert said == ["voice_off", "voice_on"]
        stored = kiosk.store.session(kiosk.session.id)
        assert [(a.name, a.active, a.reason) for a in stored.adaptations][-1] == (
            "voice_off",
            False,
            "the patient asked to answer by voice",
        )
        assert [e.kind for e in stored.log][-1:] == ["voice_requested"]


async def test_answer_by_voice_again_is_not_offered_over_the_paused_screen(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_with_voice_off(kiosk, pilot)
        assert kiosk.app.screen.query_one(VoiceAgainButton).display
        await pilot.press("p")  # while paused the way on is Continue, not a second big button
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        assert not kiosk.app.screen.query_one(VoiceAgainButton).display
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert kiosk.app.screen.query_one(VoiceAgainButton).display


async def test_no_trouble_hearing_notice_when_voice_in_never_ran(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)  # voice in is off: no microphone
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        for _ in range(8):  # with voice in on, voice_off comes within these (the test above)
            await late_touch_answer(kiosk, pilot)
        assert "voice_off" not in kiosk.session.snapshot().adaptations  # the session knows voice in is off
        assert "trouble hearing" not in text_of(kiosk.app.screen.query_one(AdaptationBanner))
        assert not kiosk.app.screen.query_one(VoiceAgainButton).display
        assert not [e for e in kiosk.controller.events if isinstance(e, Prompt) and e.key in ("voice_off", "voice_on")]
        assert "voice_off" not in {a.name for a in kiosk.store.session(kiosk.session.id).adaptations}


async def test_the_apps_own_timer_polls_the_session(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, poll_interval=0.01)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.clock.advance(kiosk.session.timing.between_questions_s)  # nobody polls but the timer
        deadline = time.monotonic() + 10
        while kiosk.session.current_attempt != 1:
            assert time.monotonic() < deadline, "the poll timer never fired"
            await pilot.pause(0.01)
        await settle(pilot, lambda: text_of(kiosk.app.screen.query_one("#progress", Label)) == "Question 1 of 10")

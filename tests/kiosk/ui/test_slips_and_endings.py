"""A patient's slips and the ends of a test, through the real app (Pilot), session and SQLite store:
an unsure answer asked back on screen, "Change my answer", "I'm fine, carry on" after an
accidental D, the waiting sign, the practice's kind words, and the end screen giving way to the
welcome for the next patient."""

from __future__ import annotations

from textual.widgets import Button, Static

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import Phase
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.widgets.change_answer import ChangeAnswerButton
from kiosk.ui.widgets.waiting_sign import WaitingSign

from .helpers import answer_every_question, deliver_from_thread, screen_name, settle, start_in_english, text_of


async def _first_question(kiosk, pilot) -> None:
    await start_in_english(kiosk, pilot)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)


def _stored(kiosk) -> list[tuple[str, int, Channel]]:
    return [(a.item_id, a.option, a.channel) for a in kiosk.store.session(kiosk.session.id).answers]


def _unsure(option: int, said: str) -> ChannelInput:
    return ChannelInput(Channel.VOICE, option=option, detail=said, confidence=0.5, needs_confirmation=True)


async def test_an_unsure_answer_is_asked_back_large_with_yes_and_no(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        deliver_from_thread(kiosk, _unsure(1, "unable"))
        await settle(pilot, lambda: bool(kiosk.app.screen.query("ConfirmPanel")))
        assert text_of(kiosk.app.screen.query_one("#confirm-question", Static)) == "I heard: Unable. Is that right?"
        assert not kiosk.app.screen.query("QuestionPanel") and _stored(kiosk) == []
        await pilot.click("#reply-2")  # No, by touch
        await settle(pilot, lambda: bool(kiosk.app.screen.query("QuestionPanel")))
        assert kiosk.session.current_attempt == 1 and _stored(kiosk) == []
        deliver_from_thread(kiosk, _unsure(3, "independent"))
        await settle(pilot, lambda: bool(kiosk.app.screen.query("ConfirmPanel")))
        await pilot.press("1")  # Yes, by key
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        assert _stored(kiosk) == [("feeding", 3, Channel.VOICE)]
        assert not kiosk.app.screen.query("ConfirmPanel")


async def test_change_my_answer_takes_back_any_answer_during_the_thank_you_gap(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        button = kiosk.app.screen.query_one(ChangeAnswerButton)
        assert not button.display  # nothing to change yet
        await pilot.press("1")
        await settle(pilot, lambda: button.display)
        assert str(button.label) == "C  Change my answer"
        await pilot.click("#change-answer")
        await settle(pilot, lambda: not button.display and kiosk.session.current_attempt == 1)
        assert _stored(kiosk) == [] and "feeding" not in kiosk.session.answers
        await pilot.press("3")
        await settle(pilot, lambda: _stored(kiosk) == [("feeding", 3, Channel.KEYBOARD)])
        await pilot.press("c")  # the C key does the same
        await settle(pilot, lambda: _stored(kiosk) == [])
        await pilot.click("#answer-2")
        await settle(pilot, lambda: _stored(kiosk) == [("feeding", 2, Channel.TOUCH)])
        deliver_from_thread(kiosk, ChannelInput(Channel.REMOTE, command=Command.UNDO, detail="key f22"))
        await settle(pilot, lambda: _stored(kiosk) == [])
        await pilot.press("2")
        await settle(pilot, lambda: button.display)
        kiosk.to_next_deadline()  # the gap is over: the next question, and the button goes
        await settle(pilot, lambda: kiosk.session.current_item.id == "bathing")
        assert not kiosk.app.screen.query_one(ChangeAnswerButton).display
        kinds = [e.kind for e in kiosk.store.session(kiosk.session.id).log]
        assert kinds.count("answer_withdrawn") == 3


async def test_im_fine_carry_on_after_an_accidental_d(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        await pilot.press("d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        assert str(kiosk.app.screen.query_one("#doctor-cancel", Button).label) == "1  I'm fine, carry on"
        await pilot.click("#doctor-cancel")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert not kiosk.session.halted and kiosk.session.current_attempt == 1
        await pilot.press("d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        await pilot.press("1")  # the key (or the remote's 1) does the same
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        log = [(e.kind, e.detail) for e in kiosk.store.session(kiosk.session.id).log]
        assert [entry for entry in log if entry[0] in ("call_doctor", "doctor_call_cancelled")] == [
            ("call_doctor", "keyboard"),
            ("doctor_call_cancelled", "touch"),
            ("call_doctor", "keyboard"),
            ("doctor_call_cancelled", "keyboard"),
        ]


async def test_the_waiting_sign_shows_while_an_answer_is_awaited_and_never_counts(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot)
        sign = kiosk.app.screen.query_one(WaitingSign)
        await settle(pilot, lambda: sign.display)
        first = text_of(sign)
        assert first.startswith("Take your time. I am waiting for your answer.")
        assert not any(c.isdigit() for c in first)
        kiosk.advance(1)
        await settle(pilot, lambda: text_of(sign) != first)  # the dot moves on, nothing else
        assert text_of(sign).startswith("Take your time.")
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        await pilot.press("2")
        await settle(pilot, lambda: not kiosk.app.screen.query_one(WaitingSign).display)  # the gap


async def test_practice_starts_with_its_introduction_and_each_answer_gets_a_kind_word(ui_kiosk):
    kiosk = ui_kiosk()
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "FamiliarisationScreen")
        line = kiosk.app.screen.query_one("#interlude", Static)
        assert text_of(line).startswith("First, a few practice questions") and line.display
        await pilot.press("2")  # not the expected answer: still a kind word
        await settle(
            pilot,
            lambda: text_of(kiosk.app.screen.query_one("#interlude", Static)).startswith(
                "That was not the answer I expected, but that is fine."
            ),
        )
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.snapshot().practice_number == 2)
        assert not kiosk.app.screen.query_one("#interlude", Static).display  # no introduction now


async def test_the_end_says_what_to_do_and_the_welcome_comes_back_for_the_next_patient(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, next_patient_after_s=60)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        first = kiosk.session
        await start_in_english(kiosk, pilot)

        async def by_key(number: int, option: int) -> None:
            await pilot.press(str(option))

        await answer_every_question(kiosk, pilot, by_key)
        texts = [text_of(s) for s in kiosk.app.screen.query(Static)]
        assert "Thank you, you are done. Please call the nurse." in texts
        assert not kiosk.app.screen.query("#summary-total")  # the score is for staff by default
        await pilot.press("1")  # nothing a patient presses starts someone else's test here
        await settle(pilot)
        assert kiosk.app.session is first
        kiosk.to_next_deadline()  # 60 s later
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        assert kiosk.app.session is not first and kiosk.app.session.phase is Phase.WELCOME
        assert kiosk.app.session.listening  # '…or say "English"'
        stored = kiosk.store.session(first.id)
        assert stored.status == "finished" and len(stored.answers) == 10  # kept for staff


async def test_a_site_may_show_the_patient_their_score(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, show_score=True)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)

        async def by_key(number: int, option: int) -> None:
            await pilot.press(str(option))

        await answer_every_question(kiosk, pilot, by_key)
        total = text_of(kiosk.app.screen.query_one("#summary-total", Static))
        assert "Total: 100 of 100" in total and "Independent" in total


async def test_an_incomplete_test_shows_no_total_to_the_patient_or_the_clinician(ui_kiosk):
    """Feeding gets no answer in either attempt: the end screen (with the site showing scores) and
    the clinician's detail say how many questions are unanswered, never a partial sum as a total."""
    from textual.widgets import Label

    from .test_clinician import _open_clinician

    kiosk = ui_kiosk(familiarisation=False, show_score=True)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()  # feeding opens
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        kiosk.to_next_deadline()  # attempt 1 runs out
        await settle(pilot, lambda: kiosk.session.current_attempt == 2)
        kiosk.to_next_deadline()  # attempt 2 runs out: not answered
        await settle(pilot, lambda: kiosk.session.current_attempt is None)
        for _ in range(len(kiosk.questionnaire.items) - 1):
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_attempt == 1)
            item = kiosk.session.current_item
            await pilot.press(str(len(item.options)))
            await settle(pilot, lambda: item.id in kiosk.session.answers)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")
        shown = text_of(kiosk.app.screen.query_one("#summary-total", Static))
        assert shown == "Questions not answered: 1" and "Total" not in shown
        await _open_clinician(kiosk, pilot)
        await pilot.press("enter")
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        line = text_of(kiosk.app.screen.query_one("#total", Label))
        assert line == "No total: not answered: Feeding: how do you manage eating? (the answered ones add up to 90)"

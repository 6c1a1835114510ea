"""Whole sessions through the real app (Pilot): answered by keys, by touch, by remote and by voice
messages delivered from another thread, with the answers checked in the SQLite store."""

from __future__ import annotations

import pytest
from textual.widgets import DataTable, Label, Static

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus
from kiosk.core.session import Phase
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE

from .conftest import UI_PIN
from .helpers import answer_every_question, deliver_from_thread, screen_name, settle, start_in_english, text_of


def _stored_channels(kiosk) -> set[str]:
    return {a.channel.value for a in kiosk.store.session(kiosk.session.id).answers}


async def test_a_whole_session_answered_with_the_number_keys(ui_kiosk):
    kiosk = ui_kiosk()
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)

        async def by_key(number: int, option: int) -> None:
            progress = kiosk.app.screen.query_one("#progress", Label)
            assert text_of(progress) == f"Question {number} of 10"
            await pilot.press(str(option))

        await answer_every_question(kiosk, pilot, by_key)
        stored = kiosk.store.session(kiosk.session.id)
        assert len(stored.answers) == 10 and {a.channel for a in stored.answers} == {Channel.KEYBOARD}
        # the end says what to do; the total is for staff unless the site shows it to the patient
        assert not kiosk.app.screen.query("#summary-total")
        assert kiosk.session.score().total == 100


async def test_a_whole_session_answered_by_touching_the_buttons(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.click("#language-es")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.click("#understood")
        await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)

        async def by_touch(number: int, option: int) -> None:
            assert text_of(kiosk.app.screen.query_one("#progress", Label)) == f"Pregunta {number} de 10"
            await pilot.click(f"#answer-{option}")

        await answer_every_question(kiosk, pilot, by_touch)
        assert _stored_channels(kiosk) == {"touch"}
        assert kiosk.store.session(kiosk.session.id).language == "es"


@pytest.mark.parametrize("channel, detail", [(Channel.REMOTE, "BTN {option}"), (Channel.VOICE, "number {option}")])
async def test_a_whole_session_answered_through_channel_messages_from_a_thread(ui_kiosk, channel, detail):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        # the remote's "1" picks the first language and starts, as its label says
        deliver_from_thread(kiosk, ChannelInput(channel, option=1, detail="start"))
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        deliver_from_thread(kiosk, ChannelInput(channel, option=1, detail="start"))
        await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)

        async def by_message(number: int, option: int) -> None:
            confidence = 0.9 if channel is Channel.VOICE else None
            deliver_from_thread(
                kiosk, ChannelInput(channel, option=option, detail=detail.format(option=option), confidence=confidence)
            )

        await answer_every_question(kiosk, pilot, by_message)
        assert _stored_channels(kiosk) == {channel.value}


async def test_a_remote_plugged_in_is_offered_to_the_patient_and_device_words_stay_off_their_screen(ui_kiosk):
    kiosk = ui_kiosk()
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        welcome = kiosk.app.screen.query_one("#welcome-en", Static)
        await settle(pilot, lambda: "Welcome." in text_of(welcome))
        assert "remote" not in text_of(welcome)
        deliver_from_thread(
            kiosk, ChannelStatus(Channel.REMOTE, ChannelState.ON, "serial", "connected to /dev/ttyUSB0")
        )
        await settle(pilot, lambda: "press its number on the remote" in text_of(welcome))
        assert "mando" in text_of(kiosk.app.screen.query_one("#welcome-es", Static))
        deliver_from_thread(kiosk, ChannelStatus(Channel.REMOTE, ChannelState.LOST, "serial", "unplugged"))
        await settle(pilot, lambda: "remote" not in text_of(welcome))
        shown = " ".join(text_of(w) for w in kiosk.app.screen.query(Static))
        for technical in ("/dev/", "unplugged", "microphone", "Remote:", "Listening:", "off"):
            assert technical not in shown
        # the clinician still learns why (their screen lists every channel with its reason)
        lines = {line.name: line for line in kiosk.app.board.lines("en")}
        assert lines["Remote"].reason == "unplugged" and lines["Listening"].reason == "no microphone found"


async def test_a_kiosk_restarted_mid_session_offers_the_test_to_staff_only_and_continues_it_there(ui_kiosk):
    first = ui_kiosk(familiarisation=False)
    async with first.app.run_test(size=KIOSK_SIZE) as pilot:  # the kiosk dies after three answers
        await settle(pilot, lambda: screen_name(first) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot)
        await pilot.press("1")
        for _ in range(3):
            first.to_next_deadline()
            await settle(pilot, lambda: first.session.current_attempt == 1)
            item = first.session.current_item
            await pilot.press("1")
            await settle(pilot, lambda: item.id in first.session.answers)

    again = ui_kiosk(familiarisation=False, session_id="5e55a0000002")
    async with again.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(again) == "WelcomeScreen")
        # the next visitor sees only the fresh start in their language: nobody else's test
        assert not again.app.screen.query("#resume-session")
        assert "P-TEST01" not in "".join(text_of(w) for w in again.app.screen.query(Static))
        assert again.app.screen.query_one("#language-en").display
        # staff, behind the PIN, see whose test it was, when, and how far it got
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(again) == "ClinicianHomeScreen")
        table = again.app.screen.query_one("#interrupted", DataTable)
        assert table.row_count == 1
        patient, started, progress, why, session_id = table.get_row_at(0)
        assert (patient, progress, session_id) == ("P-TEST01", "3 of 10 answered", first.session.id)
        assert started.startswith("2026-01-01 00:00") and "stopped" in why
        await pilot.click("#continue-test")
        await settle(pilot, lambda: again.app.session.id == first.session.id)
        await settle(pilot, lambda: screen_name(again) == "ExplanationScreen")
        await pilot.press("1")
        await settle(pilot, lambda: again.app.session.phase is Phase.QUESTIONS)
        again.to_next_deadline_of(again.app.session)
        await settle(pilot, lambda: again.app.session.current_attempt == 1)
        assert again.app.session.current_item.id == "dressing"
        assert text_of(again.app.screen.query_one("#progress", Label)) == "Question 4 of 10"
        await pilot.press("2")
        await settle(pilot, lambda: "dressing" in again.app.session.answers)
    stored = again.store.session(first.session.id)
    assert [a.item_id for a in stored.answers] == ["feeding", "bathing", "grooming", "dressing"]
    assert again.store.sessions()[0].id == first.session.id  # the fresh session was never stored
    assert len(again.store.sessions()) == 1


async def test_a_keypad_remote_typing_function_keys_answers_and_pauses_as_the_remote(ui_kiosk):
    from kiosk.remote import keyboard_remote

    kiosk = ui_kiosk(familiarisation=False, keyboard=keyboard_remote())  # the bundled F13-F21 keypad
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.press("f18")  # the keypad's pause button
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        await pilot.press("f18")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        await pilot.press("f14")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        answer = kiosk.session.answers["feeding"]
        assert (answer.option, answer.channel, answer.detail) == (2, Channel.REMOTE, "key f14 (keypad-f13)")


async def test_any_other_remote_button_on_the_welcome_screen_starts_in_the_language_shown(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, language="fr")
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        deliver_from_thread(kiosk, ChannelInput(Channel.REMOTE, option=5, detail="BTN 5"))  # four languages
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        assert kiosk.session.language == "fr"


async def test_every_question_shows_its_own_text_and_answers_with_none_marked(ui_kiosk):
    """Consecutive questions with as many answers reuse the answer buttons: none may keep the
    previous question's label or its marked answer."""
    from kiosk.ui.widgets.answer_button import AnswerButton

    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)

        async def check_then_answer(number: int, option: int) -> None:
            item = kiosk.session.current_item
            screen = kiosk.app.screen
            assert text_of(screen.query_one("#question", Static)) == item.patient_text_in("en")
            buttons = list(screen.query(AnswerButton))
            assert [(b.option, text_of(b.query_one(".label", Label))) for b in buttons] == [
                (o.number, o.patient_label_in("en")) for o in item.options
            ]
            assert not screen.query(".-chosen")
            await pilot.press(str(option))

        await answer_every_question(kiosk, pilot, check_then_answer)

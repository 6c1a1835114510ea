"""A call heard by voice through the real app: "Shall I call the nurse?" covers the question, and
Yes, No or the doctor's key answer it (issue 33, part 3)."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus, Command
from kiosk.ui.app import KIOSK_SIZE

from .helpers import deliver_from_thread, screen_name, settle, start_in_english, text_of

HEARD = ChannelInput(Channel.VOICE, command=Command.CALL_DOCTOR, detail="i need a doctor", confidence=0.92)


async def _asked(kiosk, pilot) -> None:
    deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.ON, "voice in", "pocketsphinx"))
    await start_in_english(kiosk, pilot)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)
    deliver_from_thread(kiosk, HEARD)
    await settle(pilot, lambda: screen_name(kiosk) == "CallConfirmScreen")


async def test_no_on_the_screen_goes_back_to_the_question_and_staff_see_it(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _asked(kiosk, pilot)
        assert text_of(kiosk.app.screen.query_one("#confirm-question")) == "Shall I call the nurse?"
        assert not kiosk.session.halted
        await pilot.click("#reply-2")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert not kiosk.session.halted and kiosk.session.current_attempt == 1
        kinds = [e.kind for e in kiosk.store.session(kiosk.session.id).log]
        assert "doctor_call_heard" in kinds and "doctor_call_declined" in kinds and "call_doctor" not in kinds
        await pilot.press("3")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)


@pytest.mark.parametrize("keys", [("1",), ("d",)])
async def test_yes_or_the_doctors_key_makes_the_call(ui_kiosk, keys):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _asked(kiosk, pilot)
        await pilot.press(*keys)
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        kinds = [e.kind for e in kiosk.store.session(kiosk.session.id).log]
        assert kinds.index("doctor_call_confirmed") < kinds.index("call_doctor")

"""The room through the real app (issue 33, part 5): speech the voice channel could not take,
reported from its own thread, steers the patient to touch, and the clinician screen says why."""

from __future__ import annotations

import threading

from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.room import STAFF_NOTICE
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.ui.widgets.bars import AdaptationBanner, VoiceAgainButton

from .conftest import UI_PIN
from .helpers import deliver_from_thread, screen_name, settle, start_in_english, text_of


def _unheard_from_thread(kiosk, reason: str) -> None:
    """What the voice channel's thread does with speech it could not take (its on_unmatched)."""
    thread = threading.Thread(target=kiosk.app.voice_unheard, args=("mumble", reason))
    thread.start()
    thread.join(timeout=5)


async def test_voice_failing_in_the_room_steers_to_touch_and_the_clinician_reads_why(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.ON, "voice in", "pocketsphinx"))
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1 and kiosk.session.listening)
        for reason in ("'banana' is not an answer", "nothing recognisable was said", "unsure recognition"):
            _unheard_from_thread(kiosk, reason)
        await settle(pilot, lambda: "voice_room" in kiosk.session.snapshot().adaptations)
        assert not kiosk.session.listening
        banner = kiosk.app.screen.query_one(AdaptationBanner)
        await settle(pilot, lambda: banner.display)
        assert "Please touch your answer." in text_of(banner)
        assert kiosk.app.screen.query_one(VoiceAgainButton).display  # the patient may try voice again
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        assert STAFF_NOTICE in text_of(kiosk.app.screen.query_one("#current"))

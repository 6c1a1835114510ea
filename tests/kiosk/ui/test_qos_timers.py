"""A QoS model's timer fires through the real app's poll while the patient does nothing: the
kiosk runs kiosk_pace (as with ``qos_model: kiosk_pace``), the patient pauses on the first question,
and a minute after it was asked the model's inactivity timer fires on the session's clock."""

from __future__ import annotations

from kiosk.core.session import Phase
from kiosk.ui.app import KIOSK_SIZE

from .helpers import screen_name, settle, start_in_english


async def test_the_inactivity_timer_fires_through_the_apps_poll_with_no_input(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, model="kiosk_pace")
    silence_s = kiosk.model.timers["Silence"].interval
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        asked = [e["t"] for e in kiosk.session.trace if "QuestionAsked" in e.get("emit", ())]
        assert len(asked) == 1
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        before = kiosk.session.metrics["Interaction"]
        published = len(kiosk.session.trace)
        # the attempt clock is stopped: the next thing due is the model's timer
        assert kiosk.session.next_deadline() == kiosk.session._origin + asked[0] + silence_s

        kiosk.to_next_deadline()  # the app's poll, and nothing else
        await settle(pilot)

        sample = kiosk.store.session(kiosk.session.id).metrics[-1]
        assert (sample.t, sample.fired) == (asked[0] + silence_s, ("Silent",))
        assert kiosk.session.metrics["Interaction"] < before
        assert len(kiosk.session.trace) == published
        assert screen_name(kiosk) == "PausedScreen" and kiosk.session.phase is Phase.QUESTIONS

"""A battery through the real app (Pilot): the Barthel, the rest screen, then a short second
instrument, with call-doctor on the rest screen and "change my answer" in the second; each
instrument stored as its own result, one trace for the visit."""

from __future__ import annotations

from textual.widgets import Label

from kiosk.config import InstrumentChoice
from kiosk.core.session import Phase
from kiosk.ui.app import KIOSK_SIZE
from tests.kiosk.battery_instruments import write_mini

from .helpers import drawn_text, screen_name, settle, start_in_english, text_of


async def _answer_all(kiosk, pilot, count: int) -> None:
    """Answer the running instrument's ``count`` questions with key 1, then wait for its end."""
    app = kiosk.app
    for number in range(1, count + 1):
        kiosk.to_next_deadline_of(app.session)
        await settle(pilot, lambda: app.session.current_attempt == 1)
        assert text_of(app.screen.query_one("#progress", Label)) == f"Question {number} of {count}"
        item = app.session.current_item
        await pilot.press("1")
        await settle(pilot, lambda: item.id in app.session.answers)
    kiosk.to_next_deadline_of(app.session)  # closing


async def test_a_battery_of_two_instruments_through_the_app(ui_kiosk, tmp_path):
    mini = write_mini(tmp_path)
    kiosk = ui_kiosk(instruments=(InstrumentChoice("barthel"), InstrumentChoice(str(mini), mini)))
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)  # the one familiarisation, then the Barthel
        first = app.session
        await _answer_all(kiosk, pilot, 10)
        await settle(pilot, lambda: screen_name(kiosk) == "RestScreen")
        second = app.session
        assert first.finished and second is not first and second.questionnaire.id == "mini"
        assert "Well done. Next: Two questions. Take a breath." in drawn_text(app)
        # between instruments the patient reads where the visit stands
        await settle(pilot, lambda: text_of(app.screen.query_one("#progress", Label)) == "Part 2 of 2 · Two questions")
        # call the doctor on the rest screen: the visit waits; the clinician lets it go on
        await pilot.press("d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        app.controller.clinician_continue()
        await settle(pilot, lambda: screen_name(kiosk) == "RestScreen")
        await pilot.click("#understood")  # Continue
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        assert text_of(app.screen.query_one("#progress", Label)) == "Part 2 of 2 · Two questions"
        await pilot.press("1")
        await settle(pilot, lambda: second.phase is Phase.QUESTIONS)
        # the first question, answered, then taken back and answered again
        kiosk.to_next_deadline_of(second)
        await settle(pilot, lambda: second.current_attempt == 1)
        await pilot.press("3")
        await settle(pilot, lambda: "feeding" in second.answers)
        await settle(pilot, lambda: bool(app.screen.query("#change-answer")))
        await pilot.click("#change-answer")
        await settle(pilot, lambda: "feeding" not in second.answers and second.current_attempt is not None)
        await pilot.press("1")
        await settle(pilot, lambda: "feeding" in second.answers)
        kiosk.to_next_deadline_of(second)
        await settle(pilot, lambda: second.current_attempt == 1)
        await pilot.press("2")
        await settle(pilot, lambda: "bathing" in second.answers)
        kiosk.to_next_deadline_of(second)
        await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")
        assert app.session is second  # after the last instrument the end screen stays
        assert "Two questions" in drawn_text(app)  # the end names the instrument just given

    one, two = kiosk.store.session(first.id), kiosk.store.session(second.id)
    assert (one.questionnaire_id, one.status, len(one.answers)) == ("barthel", "finished", 10)
    assert (two.questionnaire_id, two.status) == ("mini", "finished")
    assert [(a.item_id, a.option) for a in two.answers] == [("feeding", 1), ("bathing", 2)]
    assert one.patient_id == two.patient_id
    # one trace for the visit: the second session's contexts continue the first's in time
    assert two.trace[0]["t"] >= one.trace[-1]["t"]
    assert second.trace[: len(one.trace)] == [dict(e) for e in one.trace]

"""The kiosk's own screens with an instrument other than the Barthel (tests/instruments/mood4.yaml:
four items of 2 and 3 options, totals 0-25): the patient's end screen and the clinician's session
detail give its own total, maximum and band, name it, and list its own items (issue 26, part 5)."""

from __future__ import annotations

from textual.widgets import DataTable, Label, Static

from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from tests.instruments import MOOD4

from .conftest import UI_PIN
from .helpers import answer_every_question, screen_name, settle, start_in_english, text_of


async def test_the_end_screen_and_the_clinicians_detail_describe_the_instrument_that_ran(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, show_score=True, questionnaire=MOOD4)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)

        async def last_option(number: int, option: int) -> None:
            await pilot.press(str(option))

        await answer_every_question(kiosk, pilot, last_option)
        # No (5), No (0), No energy (10), No (5)
        total = text_of(kiosk.app.screen.query_one("#summary-total", Static))
        assert "Total: 20 of 25" in total and "Suggests depression" in total
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        sessions = kiosk.app.screen.query_one("#sessions", DataTable)
        assert sessions.get_row_at(0)[-1] == "mood4"  # the list names the instrument of each session
        await pilot.press("enter")
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        screen = kiosk.app.screen
        heading = text_of(screen.query_one("#detail-body .heading", Static))
        assert "Mood check (4 items)" in heading
        table = screen.query_one("#answers-table", DataTable)
        assert [table.get_row_at(i)[1] for i in range(table.row_count)] == ["satisfied", "bored", "energy", "hopeful"]
        assert table.get_row_at(2)[2:5] == ["3", "No energy", "10"]
        assert text_of(screen.query_one("#total", Label)) == "Total 20 of 25 (complete); Suggests depression"

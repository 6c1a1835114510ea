"""The clinician's side: a finished session's answers, total and band, the metrics plot, exports
(FHIR JSON, CSV, PNG) written owner-only, and the adaptation switch."""

from __future__ import annotations

import csv
import io
import json
import stat

from textual.widgets import DataTable, Label, Switch

from kiosk.core.session import AdaptationChanged
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.ui.widgets.metrics_plot import MetricsPlot
from tests.kiosk.export.standard import check_fhir

from .conftest import UI_PIN
from .helpers import answer_every_question, screen_name, settle, start_in_english, text_of


async def _open_clinician(kiosk, pilot) -> None:
    await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
    await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")


async def test_a_finished_session_shows_answers_total_plot_and_exports(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)

        async def first_option_then_last(number: int, option: int) -> None:
            await pilot.press("1" if number <= 2 else str(option))

        await answer_every_question(kiosk, pilot, first_option_then_last)
        await _open_clinician(kiosk, pilot)
        await pilot.press("enter")
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        screen = kiosk.app.screen
        table = screen.query_one("#answers-table", DataTable)
        assert table.row_count == 10
        assert table.get_row_at(0) == ["1", "feeding", "1", "Unable", "0", "1", "keyboard"]
        assert table.get_row_at(9)[:5] == ["10", "stairs", "3", "Independent", "10"]
        # feeding and bathing scored 0: 100 - 10 - 5
        assert text_of(screen.query_one("#total", Label)) == "Total 85 of 100 (complete); Moderate dependence"
        plot = screen.query_one(MetricsPlot)
        assert {name for name, (times, _) in plot.data.series.items() if times} == {
            "Performance",
            "Interaction",
            "VoiceInteractionQuality",
        }

        exports = kiosk.exports
        for button, name in [("#export-fhir", "fhir.json"), ("#export-csv", "csv"), ("#export-png", "metrics.png")]:
            await pilot.click(button)
            path = exports / f"session-{kiosk.session.id}.{name}"
            await settle(pilot, lambda: path.exists())
            assert str(path) in text_of(screen.query_one("#export-result", Label))
            assert stat.S_IMODE(path.stat().st_mode) == 0o600
        response = json.loads((exports / f"session-{kiosk.session.id}.fhir.json").read_text())
        check_fhir(response)  # valid R4 for the official schema and fhir.resources
        assert response["resourceType"] == "QuestionnaireResponse" and response["status"] == "completed"
        rows = list(csv.DictReader(io.StringIO((exports / f"session-{kiosk.session.id}.csv").read_text())))
        assert len(rows) == 11 and rows[-1]["points"] == "85"
        assert (exports / f"session-{kiosk.session.id}.metrics.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

        await pilot.press("escape")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await pilot.press("escape")
        await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")


async def test_the_clinician_switches_live_adaptation_off(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        await _open_clinician(kiosk, pilot)
        switch = kiosk.app.screen.query_one("#adaptation", Switch)
        assert switch.value
        await pilot.click("#adaptation")
        await settle(pilot, lambda: not kiosk.session.adaptation.enabled)
        await pilot.click("#back")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert not [e for e in kiosk.controller.events if isinstance(e, AdaptationChanged) and e.active]


async def test_a_new_patient_after_a_halted_session_abandons_it_and_welcomes_the_next(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.press("1", "d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        await _open_clinician(kiosk, pilot)
        await pilot.click("#new-session")
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        assert kiosk.app.session is not kiosk.session and kiosk.app.session.patient_id == "P-TEST02"
        await pilot.press("2")  # the next patient starts in Spanish, with the practice questions
        await settle(pilot, lambda: screen_name(kiosk) == "FamiliarisationScreen")
        assert kiosk.app.session.language == "es"
    statuses = {s.id: (s.status, s.answered) for s in kiosk.store.sessions()}
    assert statuses[kiosk.session.id] == ("abandoned", 1)  # the first answer stays stored
    assert statuses[kiosk.app.session.id] == ("running", 0)


async def test_opening_the_clinician_screens_pauses_the_session_and_leaving_resumes_it(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await _open_clinician(kiosk, pilot)
        assert kiosk.session.paused and kiosk.session.next_deadline() is None  # nothing times out unseen
        home = kiosk.app.screen
        assert "paused while you are here" in text_of(home.query_one("#current"))
        assert home.query_one("#continue").disabled  # leaving resumes; Continue is for a halt
        # the home follows the running session (its timer calls this every second)
        kiosk.controller.person_lost()
        home.refresh_session()
        assert "patient away" in text_of(home.query_one("#current"))
        # at 80x24 every button shown reads in full and the stored sessions show several rows
        # ("Continue this test" is not shown: there is no interrupted test)
        assert not home.query_one("#interrupted-actions").display
        for button in home.query("Button"):
            if button.id != "continue-test":
                assert button.region.width >= len(str(button.label)) + 2, button
        assert home.query_one("#sessions").region.height >= 4
        await pilot.press("escape")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert not kiosk.session.paused and kiosk.session.current_attempt == 1

        await pilot.press("p")  # paused by the patient: the clinician's visit leaves it paused
        await settle(pilot, lambda: kiosk.session.paused)
        await _open_clinician(kiosk, pilot)
        assert not kiosk.app.screen.query_one("#continue").disabled
        await pilot.press("escape")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        assert kiosk.session.paused


def test_the_plot_draws_each_metric_as_steps():
    from kiosk.ui.widgets.metrics_plot import steps

    assert steps([0.0, 2.0, 5.0], [0.5, 0.7, 0.4]) == ([0.0, 2.0, 2.0, 5.0, 5.0], [0.5, 0.5, 0.7, 0.7, 0.4])
    assert steps([], []) == ([], [])

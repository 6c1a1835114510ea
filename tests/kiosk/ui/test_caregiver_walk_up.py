"""A caregiver's instrument at the kiosk (Pilot): a walk-up visit never starts it; a walk-up patient
who presses Start on a kiosk that gives only such an instrument is told, calmly, who it is for."""

from __future__ import annotations

from kiosk.config import InstrumentChoice
from kiosk.core.answerers import RELATIONSHIPS, Answerer, answerer_of
from kiosk.core.session import Phase
from kiosk.core.visits import VisitDesk
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from tests.kiosk.battery_instruments import write_mini

from .conftest import UI_PIN
from .helpers import drawn_text, screen_name, settle

CALM = "These questions are for the person who looks after you. Please ask a member of staff."


def _carer(tmp_path):
    path = write_mini(tmp_path, id="carer")
    path.write_text("answered_by: caregiver\n" + path.read_text())
    return InstrumentChoice(str(path), path)


async def test_a_walk_up_visit_runs_only_the_patients_instruments(ui_kiosk, tmp_path):
    kiosk = ui_kiosk(instruments=(InstrumentChoice("barthel"), _carer(tmp_path)))
    session = kiosk.app.controller.session
    assert session.questionnaire.id == "barthel" and session.battery is None  # a visit of the Barthel alone


async def test_a_walk_up_patient_is_told_who_a_caregivers_instrument_is_for(ui_kiosk, tmp_path):
    kiosk = ui_kiosk(instruments=(_carer(tmp_path),))
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: CALM in drawn_text(app))
        assert screen_name(kiosk) == "WelcomeScreen" and kiosk.session.phase is Phase.WELCOME
        assert list(kiosk.store.sessions()) == []


async def test_staff_start_a_caregivers_visit_saying_who_answers(ui_kiosk, tmp_path):
    kiosk = ui_kiosk(instruments=(_carer(tmp_path),))
    app = kiosk.app
    app.controller.visits = VisitDesk(app.controller.fresh)  # as make_kiosk wires `kiosk run` (visits on)
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await pilot.click("#start-visit")
        await settle(pilot, lambda: screen_name(kiosk) == "StartVisitScreen")
        for key in ("id-key-N", "id-key-H", "id-key-C", "id-key-dash", "id-key-7", "id-key-0"):
            await pilot.click(f"#{key}")
        button = app.screen.query_one("#visit-relationship")
        for name in list(RELATIONSHIPS)[: list(RELATIONSHIPS).index("paid carer") + 1]:  # spouse, ..., paid carer
            await settle(pilot, lambda: not button.has_class("-active"))  # a press while it shows one is not one
            await pilot.click("#visit-relationship")
            await settle(pilot, lambda name=name: str(button.label) == f"Answering for the patient: {name}")
        await pilot.click("#start-visit-go")
        await settle(pilot, lambda: app.session.phase is not Phase.WELCOME)
        stored = kiosk.store.session(app.session.id)
        assert (stored.patient_id, stored.answered_by.value) == ("NHC-70", "caregiver")
        assert answerer_of(stored.log) == Answerer("paid carer")

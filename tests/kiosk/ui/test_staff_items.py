"""Staff items on the kiosk's clinician screen: after the visit, behind the PIN, staff enter the
weight (a number in its range) and choose the walking aid; until then the result says it is
waiting for staff. What they enter is stored as audited staff answers and counts in the total."""

from __future__ import annotations

import json

from textual.widgets import DataTable, Input, Label, Select

from kiosk.core.session import Phase
from kiosk.core.staff import STAFF_ANSWER
from kiosk.export import fhir_response, result
from kiosk.export.captured import questionnaire_of
from kiosk.ui.app import CLINICIAN_CHORD

from .conftest import UI_PIN
from .helpers import screen_name, settle, text_of
from .test_six_options import _kiosk, _stored, _to_steps


async def _finish_visit(kiosk, pilot) -> None:
    """The patient answers the two patient items (3 then 5); the summary shows."""
    await _to_steps(kiosk, pilot)
    await pilot.press("3")
    await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_item is not None and kiosk.session.current_item.id == "stairs")
    await pilot.press("5")
    await settle(pilot, lambda: _stored(kiosk, "stairs") is not None)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.phase is Phase.SUMMARY)


async def _open_detail(kiosk, pilot) -> None:
    await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
    await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
    await pilot.press("enter")
    await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")


async def _click(pilot, selector: str) -> None:
    """Scroll the clinician's page to ``selector`` (as staff would, with Down) and touch it."""
    widget = pilot.app.screen.query_one(selector)
    widget.scroll_visible(animate=False, immediate=True)
    await pilot.pause()
    await pilot.click(selector)


def _first_row(kiosk) -> list:
    return kiosk.app.screen.query_one("#sessions", DataTable).get_row_at(0)


def _total(kiosk) -> str:
    return text_of(kiosk.app.screen.query_one("#total", Label))


async def test_staff_enter_the_weight_and_the_aid_and_the_result_completes(ui_kiosk, tmp_path):
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=(100, 32)) as pilot:
        await _finish_visit(kiosk, pilot)
        assert not kiosk.session.snapshot().score.complete
        await _open_detail(kiosk, pilot)
        assert _total(kiosk) == "No total yet: waiting for staff: Weight (kg), Uses a walking aid"
        await pilot.press("escape")  # the list says it too, in the same words
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        row = kiosk.app.screen.query_one("#sessions", DataTable).get_row_at(0)
        assert row[4] == "No total yet: waiting for staff: Weight (kg), Uses a walking aid", row
        await pilot.press("enter")
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        # a weight out of range is refused in one sentence, and nothing is stored
        await _click(pilot, "#staff-value-weight")
        await pilot.press(*"300")
        await _click(pilot, "#staff-save-weight")
        problem = kiosk.app.screen.query_one("#staff-problem-weight", Label)
        await settle(pilot, lambda: "is not a number from 20 to 250 kg" in text_of(problem))
        assert not [e for e in kiosk.store.session(kiosk.session.id).log if e.kind == STAFF_ANSWER]
        field = kiosk.app.screen.query_one("#staff-value-weight", Input)
        field.value = ""
        await _click(pilot, "#staff-value-weight")
        await pilot.press(*"72,5")
        await _click(pilot, "#staff-save-weight")
        await settle(pilot, lambda: "72.5 kg" in text_of(kiosk.app.screen.query_one("#staff-now-weight", Label)))
        assert _total(kiosk) == "No total yet: waiting for staff: Uses a walking aid"
        select = kiosk.app.screen.query_one("#staff-choice-aid", Select)
        select.focus()
        await pilot.press("enter", "down", "down", "enter")
        await settle(pilot, lambda: select.value == 2)
        await _click(pilot, "#staff-save-aid")
        await settle(pilot, lambda: "An aid" in text_of(kiosk.app.screen.query_one("#staff-now-aid", Label)))
        # steps option 3 = 2 points, stairs option 5 = 3 points, aid 1 point
        assert _total(kiosk).startswith("Total 6 of 9 (complete)")
        await pilot.press("escape")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        # the list is drawn again on the way back: wait on what it shows, not on a refresh tick
        await settle(pilot, lambda: str(_first_row(kiosk)[4]).startswith("Total 6 of 9"))

    stored = kiosk.store.session(kiosk.session.id)
    aid = _stored(kiosk, "aid")
    assert (aid.option, aid.points, aid.answered_by.value) == (2, 1, "staff")
    audit = [json.loads(e.detail) for e in stored.log if e.kind == STAFF_ANSWER]
    assert [(a["item_id"], a["option"], a["value"]) for a in audit] == [("weight", None, 72.5), ("aid", 2, None)]
    q = questionnaire_of(stored, fallback=kiosk.questionnaire)
    exported = result(q, stored)
    assert exported.complete and exported.values == {"weight": 72.5} and exported.score.total == 6
    response = fhir_response(q, stored)
    weight = next(i for i in response["item"] if i["linkId"] == "weight")
    assert weight["answer"][0]["valueDecimal"] == 72.5

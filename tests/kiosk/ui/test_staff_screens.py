"""The staff screens by touch alone, at the served display's sizes and at 80x24: the PIN pad whole
with its way back, a time-out back to the patient (on the session's clock, moved by the test),
no selection left by the corner taps, and every control of the clinician screens reachable by
paging and tappable. Each waits on what is drawn."""

from __future__ import annotations

import pytest
from textual.widgets import Button, DataTable, Switch

from kiosk.core.pin import CORNER_TAPS
from kiosk.ui.app import CLINICIAN_IDLE_S, KIOSK_SIZE, PIN_IDLE_S

from .conftest import UI_PIN
from .fit import problems
from .helpers import screen_name, settle, start_in_english, until_drawn

#: 73x18 is a 1024x600 panel at 28 px, 91x24 about 1280x800 at 28 px
SIZES = [(100, 32), (91, 24), (80, 24), (73, 18), (64, 18)]


async def _tap_corner(pilot, times: int = CORNER_TAPS) -> None:
    for _ in range(times):
        await pilot.click(offset=(1, 0))


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
async def test_the_pin_pad_is_whole_with_its_way_back(ui_kiosk, size):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await _tap_corner(pilot)
        await until_drawn(pilot, "Clinician access", "Back to the patient", "OK", "⌫")
        assert not problems(kiosk.app.screen), problems(kiosk.app.screen)
        assert not kiosk.app.screen.get_selected_text()  # the taps selected nothing
        for key in kiosk.app.screen.query("#pin-keys Button").results(Button):
            assert key.region.height >= 2 and key.region.width >= 6, key  # a finger's target
        await pilot.click("#pin-back")
        await until_drawn(pilot, "1  English")


async def test_the_pin_pad_goes_back_to_the_patient_when_nobody_touches_it(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await _tap_corner(pilot)  # a patient's five taps
        await until_drawn(pilot, "Clinician access")
        assert kiosk.session.paused  # held while the pad is up
        kiosk.advance(PIN_IDLE_S - 1)
        await settle(pilot)
        assert screen_name(kiosk) == "PinScreen"
        await pilot.click("#key-1")  # a touch starts the wait again
        kiosk.advance(PIN_IDLE_S - 1)
        await settle(pilot)
        assert screen_name(kiosk) == "PinScreen"
        kiosk.advance(1)
        await until_drawn(pilot, "Someone has to feed me", "Attempt 1 of 2")
        assert screen_name(kiosk) == "QuestionScreen" and not kiosk.session.paused


async def test_the_clinician_screens_go_back_to_the_patient_after_five_idle_minutes(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await _tap_corner(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "PinScreen")
        for digit in UI_PIN:
            await pilot.click(f"#key-{digit}")
        await pilot.click("#key-ok")
        await until_drawn(pilot, "Stored sessions")
        kiosk.advance(CLINICIAN_IDLE_S - 1)
        await settle(pilot)
        assert screen_name(kiosk) == "ClinicianHomeScreen"
        kiosk.advance(1)
        await until_drawn(pilot, "1  English")


def _visible(widget, body) -> bool:
    """Wholly inside the scrolling body's visible part (so a finger can tap it)."""
    return body.region.contains_region(widget.region) and widget.region.height > 0


async def _reach(pilot, screen, selector: str, widget) -> None:
    """Page the body with the Down button until ``widget`` is wholly in view, or (one about as tall
    as the view) has shown each of its rows at some tap (at most 20 taps)."""
    body = screen.query_one(".staff-body")
    seen: set[int] = set()
    for _ in range(20):
        if _visible(widget, body):
            return
        view = body.region
        seen |= {y - widget.region.y for y in range(widget.region.y, widget.region.bottom) if view.y <= y < view.bottom}
        if seen >= set(range(widget.region.height)):
            return
        await pilot.click("#page-down")
        await settle(pilot)
    raise AssertionError(f"{selector} never came into view by paging")


async def _from_top(pilot, screen) -> None:
    body = screen.query_one(".staff-body")
    for _ in range(20):
        if body.scroll_y == 0:
            return
        await pilot.click("#page-up")
        await settle(pilot)


@pytest.mark.parametrize("size", [(80, 24), (73, 18), (64, 18)], ids=lambda s: f"{s[0]}x{s[1]}")
async def test_every_clinician_control_is_reached_and_tapped_by_touch(ui_kiosk, size):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=size) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.press("2")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        await pilot.press("d")  # the doctor called: Continue has something to do
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        await _tap_corner(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "PinScreen")
        for digit in UI_PIN:
            await pilot.click(f"#key-{digit}")
        await pilot.click("#key-ok")
        await until_drawn(pilot, "Back to the patient", "▼ Down")
        home = kiosk.app.screen
        controls = [
            w
            for w in home.query(".staff-body Button, .staff-body Switch, .staff-body DataTable")
            if w.display and w.parent.display
        ]
        assert {w.id for w in controls} >= {
            "continue",
            "adaptation",
            "new-session",
            "person-lost",
            "person-back",
            "quit-kiosk",
            "sessions",
        }
        for widget in controls:
            await _from_top(pilot, home)
            await _reach(pilot, home, widget.id, widget)
        # tapping them: the adaptation switch, then a stored session's row
        await _from_top(pilot, home)
        switch = home.query_one("#adaptation", Switch)
        await _reach(pilot, home, "adaptation", switch)
        await pilot.click("#adaptation")
        await settle(pilot, lambda: not kiosk.session.adaptation.enabled)
        table = home.query_one("#sessions", DataTable)
        await _reach(pilot, home, "sessions", table)
        await pilot.click("#sessions", offset=(2, 1))  # the first row, under the header
        await until_drawn(pilot, f"Session {kiosk.session.id}")
        detail = kiosk.app.screen
        assert screen_name(kiosk) == "SessionDetailScreen"
        for selector in ("#answers-table", "#events", "#metrics-plot"):
            await _reach(pilot, detail, selector, detail.query_one(selector))
        await until_drawn(pilot, "session time (s)")
        for button, name in (("#export-fhir", "fhir.json"), ("#export-csv", "csv"), ("#export-png", "metrics.png")):
            await pilot.click(button)
            path = kiosk.exports / f"session-{kiosk.session.id}.{name}"
            await settle(pilot, lambda: path.exists())
        await pilot.click("#back")
        await until_drawn(pilot, "Stored sessions")
        await pilot.click("#back")  # Back to the patient
        await until_drawn(pilot, "The doctor has been called")


async def test_continue_this_test_shows_only_with_an_interrupted_test_and_events_are_listed(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.press("d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        await pilot.press("1")  # I'm fine, carry on
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        await pilot.press("3")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        await _tap_corner(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "PinScreen")
        await pilot.press(*UI_PIN, "enter")
        shown = await until_drawn(pilot, "Interrupted tests: none.")
        assert "Continue this test" not in shown
        await pilot.press("enter")  # the stored session (the list has the keys)
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        detail = kiosk.app.screen
        await _reach(pilot, detail, "#events", detail.query_one("#events"))
        await until_drawn(pilot, "Doctor called (keyboard)", '"I\'m fine, carry on"')

"""Every answer of every shipped instrument, in every language, is shown whole on every display
the kiosk runs on: from the 57x15 cells an 800x480 panel's served page gets at its smallest text
(24 px in Chromium, measured by test_served_small_panel.py) and the kiosk's floor, through 64x18,
70x20 and 80x24 terminals, to a 100x32 kiosk. Each answer's button lies inside the screen, clear
of the top bar and the controls, and the text drawn in it is the answer's whole text (turning the
pages where the display needs them); the practice question that asks for "answer number 3" shows
answer 3. Below the floor the kiosk takes no patient and says why, to staff and to the station."""

from __future__ import annotations

import pytest

from kiosk.core.questionnaire import bundled_path, load_questionnaire
from kiosk.core.session import Phase
from kiosk.ui.app import CLINICIAN_CHORD
from kiosk.ui.floor import FLOOR

from .conftest import UI_PIN
from .helpers import drawn_text, screen_name, settle, start_in_english, until_drawn

#: the 800x480 panel's page in cells (Chromium, 24 px Roboto Mono: 14 x 32 px a cell)
PANEL_800X480 = (57, 15)
SIZES = [FLOOR, PANEL_800X480, (64, 18), (70, 20), (80, 24), (100, 32)]
INSTRUMENTS = ["barthel", "lawton", "sarc_f", "gds15"]
#: every (instrument, language) the kiosk ships
SHIPPED = [(name, lang) for name in INSTRUMENTS for lang in load_questionnaire(bundled_path(f"{name}.yaml")).languages]
#: the quick loop: the longest answers (Lawton's five-answer items, French the longest of all)
QUICK = {("lawton", "en"), ("lawton", "fr"), ("barthel", "fr")}


def _words(text: str) -> str:
    return " ".join(text.split())


def shown_whole(app, button) -> list[str]:
    """What is wrong with ``button`` as the patient sees it: outside the screen, under a bar, or
    its text not drawn whole inside it (empty: its whole text is in view)."""
    found = []
    screen = app.screen
    if not screen.region.contains_region(button.region):
        found.append(f"{button.id} at {button.region} is not inside the {screen.region.size} screen")
    for bar in screen.query("#topbar, #controls"):
        if bar.display and bar.region.overlaps(button.region):
            found.append(f"{button.id} at {button.region} is under {bar.id} at {bar.region}")
    label = button.query_one(".label")
    box = label.content_region.intersection(screen.region)
    lines = drawn_text(app).splitlines()[box.y : box.bottom]
    drawn = _words(" ".join(line[box.x : box.right] for line in lines))
    if drawn != _words(button.label):
        found.append(f"{button.id} should read {button.label!r}, the screen shows {drawn!r}")
    return found


async def _every_answer_in_view(kiosk, pilot, where: str) -> None:
    """Each page of the answers on screen: every answer shown lies whole in view; together the
    pages show every answer once."""
    seen: list[int] = []
    pages = 0
    while True:
        await settle(pilot)
        buttons = [b for b in kiosk.app.screen.query("AnswerButton") if b.display]
        for button in buttons:
            assert not shown_whole(kiosk.app, button), f"{where} at {kiosk.app.size}: {shown_whole(kiosk.app, button)}"
        seen += [b.option for b in buttons if b.id != "answer-more"]
        more = [b for b in buttons if b.id == "answer-more"]
        pages += 1
        if not more or pages > 6:
            break
        await pilot.click("#answer-more")
        if seen and seen[0] in [
            b.option for b in kiosk.app.screen.query("AnswerButton") if b.display and b.id != "answer-more"
        ]:
            break  # back on the first page
    item = kiosk.session.snapshot().item or kiosk.session.snapshot().practice
    assert sorted(seen) == list(range(1, len(item.options) + 1)), f"{where} at {kiosk.app.size}: pages showed {seen}"


def _matrix():
    for name, language in SHIPPED:
        for size in SIZES:
            quick = (name, language) in QUICK
            marks = () if quick else (pytest.mark.slow,)
            yield pytest.param(name, language, size, marks=marks, id=f"{name}-{language}-{size[0]}x{size[1]}")


@pytest.mark.parametrize("name,language,size", list(_matrix()))
async def test_every_answer_is_whole_on_screen(ui_kiosk, name, language, size):
    kiosk = ui_kiosk(familiarisation=True, questionnaire=bundled_path(f"{name}.yaml"))
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        assert kiosk.controller.out_of_order is None
        await pilot.press(str(kiosk.questionnaire.languages.index(language) + 1))
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)
        while kiosk.session.phase is Phase.FAMILIARISATION:
            practice = kiosk.session.snapshot().practice
            if practice is not None and kiosk.session.current_attempt == 1:
                await settle(pilot)
                # the practice names the answer to press: it is on screen, whole, without turning a page
                expected = kiosk.app.screen.query_one(f"#answer-{practice.expected}")
                assert expected.display and not shown_whole(kiosk.app, expected), shown_whole(kiosk.app, expected)
                await _every_answer_in_view(kiosk, pilot, practice.id)
                await pilot.press(str(practice.expected))
                await settle(pilot)
            else:
                kiosk.to_next_deadline()
                await settle(pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        for item in kiosk.questionnaire.items:
            if item.answered_by != "patient":
                continue
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_item == item and kiosk.session.current_attempt == 1)
            await _every_answer_in_view(kiosk, pilot, item.id)
            await pilot.press(str(len(item.options)))
            await settle(pilot, lambda: item.id in kiosk.session.answers)
            await settle(pilot)
            # the chosen answer stays in view through the thank-you gap, whatever page it is on
            chosen = kiosk.app.screen.query_one(f"#answer-{len(item.options)}")
            assert chosen.display and chosen.has_class("-chosen")
            assert not shown_whole(kiosk.app, chosen), shown_whole(kiosk.app, chosen)


class _Station:
    """Stands in for the station's client: keeps the last status the kiosk would send."""

    def __init__(self) -> None:
        self.status: dict = {}

    def set_status(self, status) -> None:
        self.status = dict(status)

    def start(self) -> None:
        """Nothing to start: no thread, no station."""

    stop = start


BELOW_FLOOR = (FLOOR[0] - 1, FLOOR[1] - 1)


async def test_below_the_floor_the_kiosk_takes_no_patient_and_tells_staff_why(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    station = kiosk.controller.sync = _Station()
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        await start_in_english(kiosk, pilot)
        running = kiosk.session
        await pilot.resize_terminal(*BELOW_FLOOR)
        await until_drawn(pilot, "This kiosk is not working")
        assert screen_name(kiosk) == "OutOfOrderScreen"
        reason = kiosk.controller.out_of_order
        assert reason is not None and f"{BELOW_FLOOR[0]}x{BELOW_FLOOR[1]}" in reason
        assert "display is too small" in station.status["out_of_order"]  # the ward tile says it
        for key in ("1", "2", "enter"):  # nothing starts a test
            await pilot.press(key)
        await settle(pilot)
        assert kiosk.app.session.phase is Phase.WELCOME and screen_name(kiosk) == "OutOfOrderScreen"
        kiosk.controller.keep_session()  # the lease round does not take the display's reason away
        assert kiosk.controller.out_of_order == reason
        assert running.id in [t.id for t in kiosk.controller.interrupted_tests()]  # for staff to continue

        kiosk.controller.sync = None  # the clinician screen would read the client's own state
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        text = str(kiosk.app.screen.query_one("#out-of-order-reason").render())
        assert "display is too small" in _words(text) and "large enough again" in _words(text)
        kiosk.app.close_clinician()

        kiosk.controller.sync = station
        await pilot.resize_terminal(*FLOOR)  # a display at the floor takes patients again
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        assert kiosk.controller.out_of_order is None and station.status["out_of_order"] is None
        await pilot.press("1")
        await settle(pilot, lambda: kiosk.app.session.phase is not Phase.WELCOME)


async def test_a_kiosk_started_on_a_too_small_display_never_shows_the_welcome(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=(FLOOR[0], FLOOR[1] - 1)) as pilot:
        await until_drawn(pilot, "This kiosk is not working")
        await pilot.press("1")
        await settle(pilot)
        assert screen_name(kiosk) == "OutOfOrderScreen" and kiosk.session.phase is Phase.WELCOME
        assert "display is too small" in kiosk.controller.out_of_order

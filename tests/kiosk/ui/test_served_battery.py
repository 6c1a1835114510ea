"""A battery on the served page: `kiosk serve` in a subprocess configured with two short
instruments, Debian's Chromium driven by Playwright, taps on the page through both instruments
and the rest screen between them, and one stored result per instrument in the SQLite database."""

from __future__ import annotations

from pathlib import Path

from kiosk.config import InstrumentChoice
from kiosk.core.session import Phase
from kiosk.ui.widgets.text import ui_text
from tests.kiosk.battery_instruments import write_mini

from .helpers import screen_name, settle
from .serving import ACTION_RGB, ANSWER_RGB, NEEDS_CHROMIUM, open_page, rows, serve, wait_until

FONT_SIZE = 20

pytestmark = NEEDS_CHROMIUM


def _finished(database: Path) -> list[tuple]:
    return rows(database, "SELECT questionnaire_id FROM sessions WHERE status = 'finished' ORDER BY started_at")


async def _tap_targets(ui_kiosk, instruments, size: tuple[int, int]) -> dict:
    """Where English, Start, answers 1 and 2 and the rest screen's Continue lie at this terminal
    size: the same app laid out by Textual headless, which lays out the served one too."""
    kiosk = ui_kiosk(familiarisation=False, instruments=instruments)
    app = kiosk.app
    async with app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        targets = {"english": app.screen.query_one("#language-en").region}
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        targets["start"] = app.screen.query_one("#understood").region
        await pilot.press("1")
        for number in (1, 2):
            kiosk.to_next_deadline_of(app.session)
            await settle(pilot, lambda: app.session.current_attempt == 1)
            targets[number] = app.screen.query_one(f"#answer-{number}").region
            await pilot.press(str(number))
            await settle(pilot, lambda: app.session.current_attempt is None)
        kiosk.to_next_deadline_of(app.session)
        await settle(pilot, lambda: screen_name(kiosk) == "RestScreen")
        targets["continue"] = app.screen.query_one("#understood").region
        await pilot.press("1")
        await settle(pilot, lambda: app.session.phase is Phase.EXPLANATION)
        assert app.screen.query_one("#understood").region == targets["start"]
        return targets


async def test_a_battery_on_the_served_page(tmp_path, ui_kiosk):
    site = tmp_path / "served"  # its own data directory: the headless layout run stores in tmp_path's
    site.mkdir()
    first, second = write_mini(site, id="mini"), write_mini(site, id="mini2", title="Two more")
    with serve(site, "instruments: [mini.yaml, mini2.yaml]\n") as served:
        database = served.database
        async with open_page(served, (1200, 780), FONT_SIZE) as kiosk_page:
            page, shows, tap = kiosk_page.page, kiosk_page.painted.shows, kiosk_page.tap_drawn
            chosen = (InstrumentChoice(str(first), first), InstrumentChoice(str(second), second))
            at = await _tap_targets(ui_kiosk, chosen, kiosk_page.size)

            async def answer_both(stored: int) -> None:
                for number in (1, 2):
                    await wait_until(page, shows(f"Question {number} of 2"), f"question {number}")
                    await tap(at[number], ANSWER_RGB, f"answer {number}")
                    want = stored + number
                    await wait_until(
                        page, lambda: len(rows(database, "SELECT 1 FROM answers")) == want, f"answer {want} stored"
                    )

            await wait_until(page, shows(ui_text("en", "choose_language")), "the welcome screen")
            await tap(at["english"], ACTION_RGB, "English")
            await tap(at["start"], ACTION_RGB, "Start")
            await answer_both(0)
            await wait_until(page, shows("Well done. Next: Two more."), "the rest screen")
            await wait_until(page, lambda: _finished(database) == [("mini",)], "the first result")
            await tap(at["continue"], ACTION_RGB, "Continue")
            await tap(at["start"], ACTION_RGB, "Start")
            await answer_both(2)
            await wait_until(page, lambda: len(_finished(database)) == 2, "the second result")
    assert _finished(database) == [("mini",), ("mini2",)]
    answers = rows(
        database, "SELECT s.questionnaire_id, a.item_id, a.option FROM answers a JOIN sessions s ON s.id = a.session_id"
    )
    assert sorted(answers) == [
        ("mini", "bathing", 2),
        ("mini", "feeding", 1),
        ("mini2", "bathing", 2),
        ("mini2", "feeding", 1),
    ]

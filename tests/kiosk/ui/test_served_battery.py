"""A battery on the served page: `kiosk serve` in a subprocess configured with two short
instruments, Debian's Chromium driven by Playwright, taps on the page through both instruments
and the rest screen between them, and one stored result per instrument in the SQLite database."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest

from kiosk.config import InstrumentChoice
from kiosk.core.session import Phase
from kiosk.ui.widgets.text import ui_text
from tests.kiosk.battery_instruments import write_mini

from .helpers import screen_name, settle
from .serving import (
    ACTION_RGB,
    ANSWER_RGB,
    CHROMIUM,
    CHROMIUM_ARGS,
    PATIENCE_S,
    TOKEN,
    Painted,
    serve,
    wait_until,
    wait_until_drawn,
)

FONT_SIZE = 20

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian's chromium is not installed (.ci/run installs it)"),
]


def _rows(database: Path, sql: str) -> list[tuple]:
    if not database.exists():
        return []
    with sqlite3.connect(f"file:{database}?mode=ro", uri=True) as db:
        try:
            return db.execute(sql).fetchall()
        except sqlite3.OperationalError:  # the schema is not there yet
            return []


def _finished(database: Path) -> list[tuple]:
    return _rows(database, "SELECT questionnaire_id FROM sessions WHERE status = 'finished' ORDER BY started_at")


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
    from playwright.async_api import async_playwright

    site = tmp_path / "served"  # its own data directory: the headless layout run stores in tmp_path's
    site.mkdir()
    first, second = write_mini(site, id="mini"), write_mini(site, id="mini2", title="Two more")
    with serve(site, "instruments: [mini.yaml, mini2.yaml]\n") as served:
        database = served.database
        async with async_playwright() as pw:
            browser = await pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
            try:
                page = await browser.new_page(viewport={"width": 1200, "height": 780})
                painted = Painted(page)
                await page.goto(served.url(f"/?token={TOKEN}&fontsize={FONT_SIZE}"))
                screen = page.locator(".xterm-screen")
                await screen.wait_for(timeout=PATIENCE_S * 1000)
                await page.wait_for_function(
                    "document.body.classList.contains('-first-byte')", timeout=PATIENCE_S * 1000
                )
                query = dict(part.split("=") for part in painted.sockets[0].url.split("?", 1)[1].split("&"))
                size = (int(query["width"]), int(query["height"]))
                chosen = (InstrumentChoice(str(first), first), InstrumentChoice(str(second), second))
                at = await _tap_targets(ui_kiosk, chosen, size)
                box = await screen.bounding_box()
                cell_w, cell_h = box["width"] / size[0], box["height"] / size[1]

                async def tap(region, rgb: tuple[int, int, int], what: str) -> None:
                    left, top = box["x"] + region.x * cell_w, box["y"] + region.y * cell_h
                    right, bottom = box["x"] + region.right * cell_w, box["y"] + region.bottom * cell_h
                    await wait_until_drawn(page, (left, top, right, bottom), cell_h, rgb, what)
                    await page.mouse.click((left + right) / 2, (top + bottom) / 2)

                async def answer_both(stored: int) -> None:
                    for number in (1, 2):
                        await wait_until(page, painted.shows(f"Question {number} of 2"), f"question {number}")
                        await tap(at[number], ANSWER_RGB, f"answer {number}")
                        want = stored + number
                        await wait_until(
                            page, lambda: len(_rows(database, "SELECT 1 FROM answers")) == want, f"answer {want} stored"
                        )

                await wait_until(page, painted.shows(ui_text("en", "choose_language")), "the welcome screen")
                await tap(at["english"], ACTION_RGB, "English")
                await tap(at["start"], ACTION_RGB, "Start")
                await answer_both(0)
                await wait_until(page, painted.shows("Well done. Next: Two more."), "the rest screen")
                await wait_until(page, lambda: _finished(database) == [("mini",)], "the first result")
                await tap(at["continue"], ACTION_RGB, "Continue")
                await tap(at["start"], ACTION_RGB, "Start")
                await answer_both(2)
                await wait_until(page, lambda: len(_finished(database)) == 2, "the second result")
            finally:
                await browser.close()
    assert _finished(database) == [("mini",), ("mini2",)]
    answers = _rows(
        database, "SELECT s.questionnaire_id, a.item_id, a.option FROM answers a JOIN sessions s ON s.id = a.session_id"
    )
    assert sorted(answers) == [
        ("mini", "bathing", 2),
        ("mini", "feeding", 1),
        ("mini2", "bathing", 2),
        ("mini2", "feeding", 1),
    ]

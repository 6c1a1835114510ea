"""End to end: `kiosk serve` in a subprocess, Debian's Chromium driven by Playwright, a tap on an
answer button's position in the terminal canvas, and the answer found in the SQLite database."""

from __future__ import annotations

import os
import sqlite3
from pathlib import Path

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Phase
from kiosk.ui.widgets.text import ui_text

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

#: the served page's font size: a touch display shows big cells
FONT_SIZE = 20
QUESTIONNAIRE = load_questionnaire()

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


def _answers(database: Path) -> list[tuple]:
    return _rows(database, "SELECT item_id, option, channel FROM answers")


def _first_words(text: str) -> str:
    """The start of a paragraph, short enough to be drawn on its first line."""
    return " ".join(text.split()[:4])


def _count(database: Path, table: str) -> int:
    return len(_rows(database, f"SELECT 1 FROM {table}"))


@pytest.fixture
def served_kiosk(tmp_path):
    """`kiosk serve` on a free localhost port with its own configuration and data directory."""
    with serve(tmp_path) as served:
        yield served


async def _tap_targets(ui_kiosk, size: tuple[int, int]) -> list:
    """Where English (welcome), Start (explanation) and answer 2 of the first question lie at this
    terminal size: the same app laid out by Textual headless, which lays out the served one too."""
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        targets = [kiosk.app.screen.query_one("#language-en").region]
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        targets.append(kiosk.app.screen.query_one("#understood").region)
        await pilot.press("1")
        await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        targets.append(kiosk.app.screen.query_one("#answer-2").region)
        return targets


async def test_a_tap_on_the_served_page_records_the_answer(served_kiosk, ui_kiosk):
    from playwright.async_api import async_playwright

    database = served_kiosk.database
    async with async_playwright() as pw:
        browser = await pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            page = await browser.new_page(viewport={"width": 1200, "height": 780})
            painted = Painted(page)
            sockets = painted.sockets
            # the device key once (as staff set the screen up), then the cookie opens the kiosk
            await page.goto(served_kiosk.url(f"/?token={TOKEN}&fontsize={FONT_SIZE}"))
            screen = page.locator(".xterm-screen")
            await screen.wait_for(timeout=PATIENCE_S * 1000)
            await page.wait_for_function("document.body.classList.contains('-first-byte')", timeout=PATIENCE_S * 1000)
            query = dict(part.split("=") for part in sockets[0].url.split("?", 1)[1].split("&"))
            size = (int(query["width"]), int(query["height"]))
            english, start, answer = await _tap_targets(ui_kiosk, size)
            box = await screen.bounding_box()
            cell_w, cell_h = box["width"] / size[0], box["height"] / size[1]

            async def tap(region, rgb: tuple[int, int, int], what: str) -> None:
                """Tap the middle of ``region`` once the page draws it there (as a patient would)."""
                left, top = box["x"] + region.x * cell_w, box["y"] + region.y * cell_h
                right, bottom = box["x"] + region.right * cell_w, box["y"] + region.bottom * cell_h
                await wait_until_drawn(page, (left, top, right, bottom), cell_h, rgb, what)
                await page.mouse.click((left + right) / 2, (top + bottom) / 2)

            shows = painted.shows

            await wait_until(page, shows(ui_text("en", "choose_language")), "the welcome screen")
            await tap(english, ACTION_RGB, "English")
            await wait_until(page, lambda: _count(database, "sessions"), "the session stored")  # start() stores it
            await wait_until(page, shows(_first_words(QUESTIONNAIRE.message("explanation", "en"))), "the explanation")
            await tap(start, ACTION_RGB, "Start")
            await wait_until(page, shows(QUESTIONNAIRE.items[0].patient_text_in("en")), "the first question")
            await tap(answer, ANSWER_RGB, "answer 2")
            await wait_until(page, lambda: _answers(database), "the answer stored")
            if os.environ.get("KIOSK_E2E_SCREENSHOT"):
                await page.screenshot(path=os.environ["KIOSK_E2E_SCREENSHOT"])
        finally:
            await browser.close()
    assert _answers(database) == [("feeding", 2, "touch")]

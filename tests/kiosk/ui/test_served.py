"""End to end: `kiosk serve` in a subprocess, Debian's Chromium driven by Playwright, a tap on an
answer button's position in the terminal canvas, and the answer found in the SQLite database."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Phase
from kiosk.ui.widgets.text import ui_text

from .helpers import screen_name, settle
from .serving import ACTION_RGB, ANSWER_RGB, NEEDS_CHROMIUM, answers, open_page, rows, serve, wait_until

#: the served page's font size: a touch display shows big cells
FONT_SIZE = 20
QUESTIONNAIRE = load_questionnaire()

pytestmark = NEEDS_CHROMIUM


def _first_words(text: str) -> str:
    """The start of a paragraph, short enough to be drawn on its first line."""
    return " ".join(text.split()[:4])


def _count(database: Path, table: str) -> int:
    return len(rows(database, f"SELECT 1 FROM {table}"))


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
    database = served_kiosk.database
    async with open_page(served_kiosk, (1200, 780), FONT_SIZE) as kiosk_page:
        page, shows = kiosk_page.page, kiosk_page.painted.shows
        english, start, answer = await _tap_targets(ui_kiosk, kiosk_page.size)
        await wait_until(page, shows(ui_text("en", "choose_language")), "the welcome screen")
        await kiosk_page.tap_drawn(english, ACTION_RGB, "English")
        await wait_until(page, lambda: _count(database, "sessions"), "the session stored")  # start() stores it
        await wait_until(page, shows(_first_words(QUESTIONNAIRE.message("explanation", "en"))), "the explanation")
        await kiosk_page.tap_drawn(start, ACTION_RGB, "Start")
        await wait_until(page, shows(QUESTIONNAIRE.items[0].patient_text_in("en")), "the first question")
        await kiosk_page.tap_drawn(answer, ANSWER_RGB, "answer 2")
        await wait_until(page, lambda: answers(database), "the answer stored")
        if os.environ.get("KIOSK_E2E_SCREENSHOT"):
            await page.screenshot(path=os.environ["KIOSK_E2E_SCREENSHOT"])
    assert answers(database) == [("feeding", 2, "touch")]

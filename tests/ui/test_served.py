"""End to end: `kiosk serve` in a subprocess, Debian's Chromium driven by Playwright, a tap on an
answer button's position in the terminal canvas, and the answer found in the SQLite database."""

from __future__ import annotations

import os
import socket
import sqlite3
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from kiosk.questionnaire import load_questionnaire
from kiosk.session import Phase
from kiosk.widgets.text import ui_text

from .helpers import screen_name, settle

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
                 "--disable-sync", "--no-first-run"]
#: the served page's font size: a touch display shows big cells
FONT_SIZE = 20
#: what the test waits for at most (server start, first paint, the answer reaching the database)
PATIENCE_S = 30.0
QUESTIONNAIRE = load_questionnaire()

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian's chromium is not installed (.ci/run installs it)"),
]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _wait_for_port(port: int, server: subprocess.Popen) -> None:
    deadline = time.monotonic() + PATIENCE_S
    while time.monotonic() < deadline:
        assert server.poll() is None, f"kiosk serve exited with {server.returncode}"
        with socket.socket() as probe:
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)  # polling a real server's start-up, not standing in for logic
    raise AssertionError(f"kiosk serve did not listen on port {port}")


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
    config = tmp_path / "config.yaml"
    config.write_text("familiarisation: false\nclinician_pin: \"2468\"\n"
                      "timing: {attempt_window_s: 300, between_questions_s: 0.5}\n")
    port = _free_port()
    env = dict(os.environ, KIOSK_CONFIG=str(config))
    server = subprocess.Popen(
        [sys.executable, "-m", "kiosk", "serve", "--port", str(port), "--data-dir", str(tmp_path / "data"),
         "--no-voice"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        _wait_for_port(port, server)
        yield port, tmp_path / "data" / "kiosk.sqlite3"
    finally:
        server.terminate()
        server.wait(timeout=PATIENCE_S)


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

    port, database = served_kiosk
    async with async_playwright() as pw:
        browser = await pw.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
        try:
            page = await browser.new_page(viewport={"width": 1200, "height": 780})
            sockets = []
            painted = bytearray()  # what the server sent the page to draw, so far

            def follow(ws) -> None:
                sockets.append(ws)
                ws.on("framereceived", lambda data: painted.extend(
                    data if isinstance(data, bytes) else data.encode()))

            page.on("websocket", follow)
            await page.goto(f"http://127.0.0.1:{port}/?fontsize={FONT_SIZE}")
            screen = page.locator(".xterm-screen")
            await screen.wait_for(timeout=PATIENCE_S * 1000)
            await page.wait_for_function("document.body.classList.contains('-first-byte')",
                                         timeout=PATIENCE_S * 1000)
            query = dict(part.split("=") for part in sockets[0].url.split("?", 1)[1].split("&"))
            size = (int(query["width"]), int(query["height"]))
            english, start, answer = await _tap_targets(ui_kiosk, size)
            box = await screen.bounding_box()
            cell_w, cell_h = box["width"] / size[0], box["height"] / size[1]

            async def tap(region) -> None:
                await page.mouse.click(box["x"] + (region.x + region.width / 2) * cell_w,
                                       box["y"] + (region.y + region.height / 2) * cell_h)

            async def wait_until(check, what: str) -> None:
                deadline = time.monotonic() + PATIENCE_S
                while not check():
                    assert time.monotonic() < deadline, f"never saw {what}"
                    await page.wait_for_timeout(50)  # lets Playwright deliver frames; bounded by PATIENCE_S

            def shows(text: str) -> Callable[[], bool]:
                """The server has sent the page ``text`` to draw: that screen is up in the app."""
                return lambda: text.encode() in painted

            await wait_until(shows(ui_text("en", "choose_language")), "the welcome screen")
            await tap(english)
            await wait_until(lambda: _count(database, "sessions"), "the session stored")  # start() stores it
            await wait_until(shows(_first_words(QUESTIONNAIRE.message("explanation", "en"))), "the explanation")
            await tap(start)
            await wait_until(shows(QUESTIONNAIRE.items[0].patient_text_in("en")), "the first question")
            await tap(answer)
            await wait_until(lambda: _answers(database), "the answer stored")
            if os.environ.get("KIOSK_E2E_SCREENSHOT"):
                await page.screenshot(path=os.environ["KIOSK_E2E_SCREENSHOT"])
        finally:
            await browser.close()
    assert _answers(database) == [("feeding", 2, "touch")]

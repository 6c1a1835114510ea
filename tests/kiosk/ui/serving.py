"""A real `kiosk serve` process for browser tests, and what its page was sent to draw."""

from __future__ import annotations

import io
import os
import socket
import sqlite3
import subprocess
import sys
import time
from collections.abc import AsyncIterator, Callable, Iterator
from contextlib import asynccontextmanager, contextmanager
from dataclasses import dataclass
from pathlib import Path

import pytest

from kiosk.ui.serve.guard import token_digest

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: what a test waits for at most (server start, first paint, an answer reaching the database)
PATIENCE_S = 30.0
#: the device key the served kiosks of the tests are set up with
TOKEN = "test-device-key-0123456789abcdefghijklmnop"
#: the marks of a test module that drives the served page in Chromium
NEEDS_CHROMIUM = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian's chromium is not installed (.ci/run installs it)"),
]


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@dataclass
class Served:
    """A running `kiosk serve`: its port, database and log."""

    port: int
    database: Path
    log: Path

    def url(self, path: str = "/", host: str = "127.0.0.1") -> str:
        return f"http://{host}:{self.port}{path}"


@contextmanager
def serve(tmp_path: Path, config: str = "", *, between_questions_s: float = 0.5) -> Iterator[Served]:
    """`kiosk serve` on a free localhost port, set up with :data:`TOKEN` and ``config`` lines
    (``between_questions_s``: the thank-you gap, long where a test looks at it). The site accepts
    every unvalidated translation, so the page offers every language the headless layout has."""
    path = tmp_path / "config.yaml"
    path.write_text(
        'familiarisation: false\nclinician_pin: "246813"\naccept_unvalidated_translations: true\n'
        f"timing: {{attempt_window_s: 300, between_questions_s: {between_questions_s}}}\n"
        f'serve_token_sha256: "{token_digest(TOKEN)}"\n' + config
    )
    port = free_port()
    log = tmp_path / "serve.log"
    with open(log, "wb") as output:  # a file, not a pipe nobody reads, which would fill and stall it
        server = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "kiosk",
                "serve",
                "--port",
                str(port),
                "--data-dir",
                str(tmp_path / "data"),
                "--no-voice",
            ],
            env=dict(os.environ, KIOSK_CONFIG=str(path)),
            stdout=output,
            stderr=subprocess.STDOUT,
        )
    try:
        deadline = time.monotonic() + PATIENCE_S
        while True:
            assert server.poll() is None, f"kiosk serve exited with {server.returncode}: {log.read_text()}"
            with socket.socket() as probe:
                if probe.connect_ex(("127.0.0.1", port)) == 0:
                    break
            assert time.monotonic() < deadline, f"kiosk serve did not listen on port {port}"
            time.sleep(0.1)  # polling a real server's start-up, not standing in for logic
        yield Served(port, tmp_path / "data" / "kiosk.sqlite3", log)
    finally:
        server.terminate()
        server.wait(timeout=PATIENCE_S)


class Painted:
    """Everything the server sent a page's websockets to draw, so far."""

    def __init__(self, page) -> None:
        self.sockets: list = []
        self.data = bytearray()
        page.on("websocket", self._follow)

    def _follow(self, ws) -> None:
        self.sockets.append(ws)
        ws.on("framereceived", lambda data: self.data.extend(data if isinstance(data, bytes) else data.encode()))

    def shows(self, text: str) -> Callable[[], bool]:
        """The server has sent the page ``text`` to draw: that screen is up in the app."""
        return lambda: text.encode() in self.data

    def since(self, offset: int, *texts: str) -> Callable[[], bool]:
        """The server has sent the page each of ``texts`` to draw after its first ``offset`` bytes."""
        return lambda: all(text.encode() in self.data[offset:] for text in texts)


async def wait_until(page, check: Callable[[], bool], what: str) -> None:
    """Let Playwright deliver frames until ``check()`` holds, at most :data:`PATIENCE_S`."""
    deadline = time.monotonic() + PATIENCE_S
    while not check():
        assert time.monotonic() < deadline, f"never saw {what}"
        await page.wait_for_timeout(50)  # lets Playwright deliver frames; bounded by PATIENCE_S


#: the backgrounds of what a patient taps on the page (kiosk.tcss), as RGB
ANSWER_RGB = (0xDC, 0xE6, 0xF5)
ACTION_RGB = (0x0B, 0x3D, 0x91)


async def drawn(
    page, left: float, top: float, right: float, bottom: float, cell_h: float, rgb: tuple[int, int, int]
) -> bool:
    """The page shows a button of colour ``rgb`` exactly over this box, as a patient sees it before
    they tap: its colour just inside the top and bottom rows, not in the row above (a button drawn a
    row off, or in a frame laid out before the screen settled, fails one of them). The mouse is
    moved off the box first, so a hover colour from the last tap does not hide the button."""
    from PIL import Image

    await page.mouse.move(1, 1)
    shot = Image.open(io.BytesIO(await page.screenshot())).convert("RGB")
    x = int(right) - 4  # the label's right padding: never a letter there

    def colour(y: float) -> tuple[int, int, int]:
        return shot.getpixel((x, min(max(int(y), 0), shot.height - 1)))

    return colour(top + 2) == rgb and colour(bottom - 2) == rgb and (top < cell_h or colour(top - cell_h / 2) != rgb)


async def wait_until_drawn(
    page, box: tuple[float, float, float, float], cell_h: float, rgb: tuple[int, int, int], what: str
) -> None:
    """Wait, at most :data:`PATIENCE_S`, until :func:`drawn` holds for ``box`` (left, top, right, bottom px)."""
    deadline = time.monotonic() + PATIENCE_S
    while not await drawn(page, *box, cell_h, rgb):
        assert time.monotonic() < deadline, f"never saw {what} drawn where the headless layout put it"
        await page.wait_for_timeout(50)  # lets the page draw; bounded by PATIENCE_S


class KioskPage:
    """A served kiosk open in Chromium: the page, what it was sent to draw, the terminal's size in
    cells as the page reported it to the server, and where that terminal lies on the page."""

    def __init__(self, page, painted: Painted, size: tuple[int, int], box: dict, requested: list[str]) -> None:
        self.page = page
        self.painted = painted
        self.size = size
        self.box = box
        #: every address the page asked for, in order
        self.requested = requested
        self.cell_w, self.cell_h = box["width"] / size[0], box["height"] / size[1]

    def pixels(self, region) -> tuple[float, float, float, float]:
        """Where a region of the terminal (in cells) is on the page: left, top, right, bottom px."""
        box = self.box
        return (
            box["x"] + region.x * self.cell_w,
            box["y"] + region.y * self.cell_h,
            box["x"] + region.right * self.cell_w,
            box["y"] + region.bottom * self.cell_h,
        )

    async def tap(self, region) -> int:
        """A tap on the middle of ``region``; returns how much the page had been sent to draw before it."""
        left, top, right, bottom = self.pixels(region)
        offset = len(self.painted.data)
        await self.page.mouse.click((left + right) / 2, (top + bottom) / 2)
        return offset

    async def tap_drawn(self, region, rgb: tuple[int, int, int], what: str) -> int:
        """:meth:`tap` once the page draws ``region`` as a button of colour ``rgb``, as a patient sees it."""
        await wait_until_drawn(self.page, self.pixels(region), self.cell_h, rgb, what)
        return await self.tap(region)


@asynccontextmanager
async def open_page(served: Served, viewport: tuple[int, int], fontsize: int | None) -> AsyncIterator[KioskPage]:
    """The served kiosk in Debian's Chromium at ``viewport`` (width, height px) and ``?fontsize=``
    (None: the page's default), once the page has drawn its first bytes."""
    from playwright.async_api import async_playwright

    async with async_playwright() as pw:
        browser = await pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            page = await browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
            requested: list[str] = []
            page.on("request", lambda request: requested.append(request.url))
            painted = Painted(page)
            # the device key once (as staff set the screen up), then the cookie opens the kiosk
            await page.goto(served.url(f"/?token={TOKEN}" + (f"&fontsize={fontsize}" if fontsize else "")))
            screen = page.locator(".xterm-screen")
            await screen.wait_for(timeout=PATIENCE_S * 1000)
            await page.wait_for_function("document.body.classList.contains('-first-byte')", timeout=PATIENCE_S * 1000)
            query = dict(part.split("=") for part in painted.sockets[0].url.split("?", 1)[1].split("&"))
            size = (int(query["width"]), int(query["height"]))
            yield KioskPage(page, painted, size, await screen.bounding_box(), requested)
        finally:
            await browser.close()


def rows(database: Path, sql: str) -> list[tuple]:
    """What ``sql`` reads from the served kiosk's database now: nothing before it has its schema."""
    if not database.exists():
        return []
    with sqlite3.connect(f"file:{database}?mode=ro", uri=True) as db:
        try:
            return db.execute(sql).fetchall()
        except sqlite3.OperationalError:  # the schema is not there yet
            return []


def answers(database: Path) -> list[tuple]:
    """The stored answers: item, option and channel."""
    return rows(database, "SELECT item_id, option, channel FROM answers")

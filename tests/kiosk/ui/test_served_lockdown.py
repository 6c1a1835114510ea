"""Kiosk lockdown on the served page, in Chromium against a real `kiosk serve`: Textual's quit,
interrupt and command-palette keys do nothing; five taps on the top-left corner open the PIN pad,
whose on-screen keys take the PIN by touch; Quit behind the PIN ends that kiosk."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.core.pin import CORNER_TAPS

from .helpers import screen_name, settle
from .serving import CHROMIUM, CHROMIUM_ARGS, PATIENCE_S, TOKEN, Painted, serve, wait_until

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="Debian's chromium is not installed (.ci/run installs it)"),
]

#: the served kiosk's PIN (tests/kiosk/ui/serving.py writes it into its configuration)
SERVED_PIN = "246813"


async def _pad_targets(ui_kiosk, size: tuple[int, int]) -> dict[str, object]:
    """Where the PIN pad's keys and the clinician's Quit lie at this terminal size: the same app
    laid out by Textual headless, which lays out the served one too."""
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        kiosk.app.action_clinician()
        await settle(pilot, lambda: screen_name(kiosk) == "PinScreen")
        targets = {f"key-{d}": kiosk.app.screen.query_one(f"#key-{d}").region for d in "0123456789"}
        targets["key-ok"] = kiosk.app.screen.query_one("#key-ok").region
        await pilot.press(*kiosk.app.pin_guard.secret, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        targets["quit"] = kiosk.app.screen.query_one("#quit-kiosk").region
        return targets


async def test_patient_keys_cannot_quit_and_staff_reach_the_pin_pad_by_touch(tmp_path, ui_kiosk):
    from playwright.async_api import async_playwright

    with serve(tmp_path) as served:
        async with async_playwright() as pw:
            browser = await pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
            try:
                page = await browser.new_page(viewport={"width": 1200, "height": 780})
                painted = Painted(page)
                await page.goto(served.url(f"/?token={TOKEN}&fontsize=20"))
                screen = page.locator(".xterm-screen")
                await screen.wait_for(timeout=PATIENCE_S * 1000)
                await wait_until(page, painted.shows("English"), "the welcome screen")
                query = dict(part.split("=") for part in painted.sockets[0].url.split("?", 1)[1].split("&"))
                size = (int(query["width"]), int(query["height"]))
                targets = await _pad_targets(ui_kiosk, size)
                box = await screen.bounding_box()
                cell_w, cell_h = box["width"] / size[0], box["height"] / size[1]

                async def tap_cell(x: float, y: float) -> None:
                    await page.mouse.click(box["x"] + x * cell_w, box["y"] + y * cell_h)

                async def tap(region) -> None:
                    await tap_cell(region.x + region.width / 2, region.y + region.height / 2)

                await screen.click(position={"x": box["width"] / 2, "y": 2})  # the terminal has the focus
                for key in ("Control+q", "Control+c", "Control+p", "Control+Backslash", "Escape"):
                    await page.keyboard.press(key)
                for _ in range(CORNER_TAPS):
                    await tap_cell(1.5, 0.5)
                await wait_until(page, painted.shows("Clinician access"), "the PIN pad")
                # the keys were handled before the taps: had one quit or opened the palette, it would show
                assert not painted.sockets[0].is_closed()
                assert b"Search for commands" not in painted.data

                for digit in SERVED_PIN:
                    await tap(targets[f"key-{digit}"])
                await tap(targets["key-ok"])
                await wait_until(page, painted.shows("Quit the kiosk"), "the clinician screen")
                await tap(targets["quit"])
                await wait_until(page, painted.sockets[0].is_closed, "the kiosk ending")
            finally:
                await browser.close()

"""The served kiosk by touch in real Chromium at 1024x600 (?fontsize=28), 1280x800 (?fontsize=28)
and 1920x1080 (the page's default): the chosen answer's words stay on screen, green and
uncovered, through the thank-you gap; the staff corner opens a PIN pad whose keys and "Back to the
patient" are drawn inside the viewport; the PIN is tapped in, a stored session is opened from the
clinician screen, exported, its plot paged into view, and both ways back are tapped. Where to tap
comes from the same app laid out by Textual at the terminal size the page reports (its "twin")."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from kiosk.ui.app import CLINICIAN_CHORD

from .conftest import UI_PIN, UiKiosk
from .helpers import screen_name, settle, until_drawn
from .serving import (
    ACTION_RGB,
    ANSWER_RGB,
    NEEDS_CHROMIUM,
    PATIENCE_S,
    answers,
    open_page,
    serve,
    wait_until,
    wait_until_drawn,
)

pytestmark = NEEDS_CHROMIUM

#: the served kiosk's PIN (tests/kiosk/ui/serving.py writes it into its configuration)
SERVED_PIN = "246813"
CHOSEN_RGB = (0x0B, 0x5D, 0x1E)
#: long enough to look at the gap on a busy machine (the first question waits as long)
GAP_S = 12


async def _twin(folder: Path, size: tuple[int, int]) -> dict:
    """Where things are at ``size``: the same app laid out headless through the same steps."""
    kiosk = UiKiosk(folder, familiarisation=False)
    where: dict = {}
    try:
        async with kiosk.app.run_test(size=size) as pilot:
            screen = lambda: kiosk.app.screen  # noqa: E731
            await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
            where["language"] = screen().query_one("#language-es").region
            await pilot.press("2")
            await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
            where["start"] = screen().query_one("#understood").region
            await pilot.press("1")
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_attempt == 1)
            await until_drawn(pilot, "Tienen que darme")
            where["answer"] = screen().query_one("#answer-2").region
            await pilot.press("2")
            await until_drawn(pilot, "Gracias. Siguiente pregunta")
            where["chosen_label"] = screen().query_one("#answer-2 .label").region
            where["change"] = screen().query_one("#change-answer").region
            await pilot.press(CLINICIAN_CHORD)
            await until_drawn(pilot, "Back to the patient")
            where["pin_back"] = screen().query_one("#pin-back").region
            where["keys"] = {b.id: b.region for b in screen().query("#pin-keys Button")}
            await pilot.press(*UI_PIN, "enter")
            await until_drawn(pilot, "Stored sessions", "▼ Down")
            # paged to the end (where the page is after enough taps on Down, whatever is above)
            body = screen().query_one(".staff-body")
            body.scroll_end(animate=False)
            await settle(pilot, lambda: body.scroll_y == body.max_scroll_y)
            await pilot.pause()
            where["sessions"] = screen().query_one("#sessions").region
            where["home_down"] = screen().query_one("#page-down").region
            where["back_to_patient"] = screen().query_one("#staff-nav #back").region
            await pilot.press("enter")
            await until_drawn(pilot, "Plot PNG")
            where["fhir"] = screen().query_one("#export-fhir").region
            where["down"] = screen().query_one("#page-down").region
            where["detail_back"] = screen().query_one("#staff-nav #back").region
    finally:
        kiosk.store.close()
    return where


async def _body_shot(page, box: tuple[float, float, float, float]) -> bytes:
    """The pixels of ``box`` on the page as drawn now."""
    left, top, right, bottom = box
    return await page.screenshot(clip={"x": left, "y": top, "width": right - left, "height": bottom - top})


async def _until_changed(page, box: tuple[float, float, float, float], before: bytes) -> None:
    """Wait (at most :data:`PATIENCE_S`) until ``box`` is drawn differently: the page scrolled (a
    second tap before that frame would let the app skip a position)."""
    import time

    deadline = time.monotonic() + PATIENCE_S
    while await _body_shot(page, box) == before:
        assert time.monotonic() < deadline, "the page never scrolled on Down"
        await page.wait_for_timeout(50)  # lets the page draw; bounded by PATIENCE_S


def _share(shot, box: tuple[float, float, float, float], rgb: tuple[int, int, int]) -> float:
    """The share of the pixels in ``box`` (left, top, right, bottom px) that are exactly ``rgb``."""
    left, top, right, bottom = (int(v) for v in box)
    pixels = [shot.getpixel((x, y)) for x in range(left + 2, right - 2, 3) for y in range(top + 2, bottom - 2, 3)]
    return sum(p == rgb for p in pixels) / max(1, len(pixels))


@pytest.mark.parametrize(
    "viewport,fontsize",
    [((1024, 600), 28), ((1280, 800), 28), ((1920, 1080), None)],
    ids=["1024x600-28px", "1280x800-28px", "1920x1080-default"],
)
async def test_the_gap_keeps_the_answer_in_view_and_staff_reach_everything_by_touch(
    tmp_path, tmp_path_factory, viewport, fontsize
):
    from PIL import Image

    width, height = viewport
    with serve(tmp_path, between_questions_s=GAP_S) as served:
        async with open_page(served, viewport, fontsize) as kiosk_page:
            page, painted, pixels = kiosk_page.page, kiosk_page.painted, kiosk_page.pixels
            box, cell_w, cell_h = kiosk_page.box, kiosk_page.cell_w, kiosk_page.cell_h
            since = painted.since
            where = await _twin(tmp_path_factory.mktemp("twin"), kiosk_page.size)

            async def tap(region, rgb: tuple[int, int, int] | None = None, what: str = "") -> int:
                """A tap wholly inside the viewport (once drawn in ``rgb``, when given)."""
                left, top, right, bottom = pixels(region)
                assert 0 <= left and right <= width and 0 <= top and bottom <= height, (
                    f"{region} is not wholly inside the {width}x{height} viewport"
                )
                return await (kiosk_page.tap(region) if rgb is None else kiosk_page.tap_drawn(region, rgb, what))

            # the patient: Spanish, Start, an answer; its words stay drawn through the gap
            await wait_until(page, painted.shows("Español"), "the welcome")
            await tap(where["language"], ACTION_RGB, "Español")
            await wait_until(page, painted.shows("Empezar"), "the explanation")
            await tap(where["start"], ACTION_RGB, "Empezar")
            await wait_until(page, painted.shows("Tienen que darme"), "the first question")
            tapped = await tap(where["answer"], ANSWER_RGB, "answer 2")
            await wait_until(
                page,
                since(tapped, "Gracias. Siguiente pregunta", "Cambiar mi respuesta", "cortar o untar"),
                "the gap with the chosen answer",
            )
            await page.mouse.move(1, 1)
            shot = Image.open(io.BytesIO(await page.screenshot())).convert("RGB")
            label = pixels(where["chosen_label"])
            green, white = _share(shot, label, CHOSEN_RGB), _share(shot, label, (255, 255, 255))
            # mostly the chosen green, with the words' white strokes in it (a few per cent of a
            # wide label's box at 1920 px), never the thanks' pale green or the button's purple
            assert green > 0.5 and white > 0.003, (
                f"the chosen answer's words are not drawn green and white at {label}: {green:.2f} {white:.2f}"
            )
            assert answers(served.database) == [("feeding", 2, "touch")]

            # staff: five taps on the corner, the PIN on the pad's keys, a stored session
            for _ in range(5):
                await page.mouse.click(box["x"] + cell_w / 2, box["y"] + cell_h / 2)
            await wait_until(page, painted.shows("Clinician access"), "the PIN pad")
            await wait_until_drawn(page, pixels(where["pin_back"]), cell_h, ACTION_RGB, "Back to the patient")
            for key in where["keys"].values():
                left, top, right, bottom = pixels(key)
                assert 0 <= left and right <= width and 0 <= top and bottom <= height, key
            for digit in SERVED_PIN:
                await tap(where["keys"][f"key-{digit}"])
            home = await tap(where["keys"]["key-ok"])
            await wait_until(page, since(home, "Stored sessions", "Back to the patient"), "the clinician home")
            for _ in range(8):  # Down to the end of the page: the stored sessions are last
                await tap(where["home_down"])
            # the cursor row is highlighted across its columns (the session id first): tap there
            first_row = where["sessions"]._replace(y=where["sessions"].y + 1, height=1, width=10)
            detail = await tap(first_row, ACTION_RGB, "the stored session's row")
            await wait_until(page, since(detail, "Plot PNG", "feeding"), "the session's page")
            exported = await tap(where["fhir"])
            await wait_until(page, since(exported, "FHIR QuestionnaireResponse written"), "the export")
            plot = since(exported, "VoiceInteractionQuality", "1.00", "0.50")  # its key and axis
            # the scrolling body only (above the export's result line and the buttons)
            body = pixels(where["fhir"]._replace(x=0, y=0, width=kiosk_page.size[0], height=where["fhir"].y - 1))
            for _ in range(12):  # page down to the plot, each page drawn before the next tap
                if plot():
                    break
                before = await _body_shot(page, body)
                await tap(where["down"])
                await _until_changed(page, body, before)
            assert plot(), "the plot was never paged into view"
            back = await tap(where["detail_back"])
            await wait_until(page, since(back, "Stored sessions"), "back on the clinician home")
            patient = await tap(where["back_to_patient"])
            await wait_until(page, since(patient, "Pregunta 1 de 10"), "back on the patient's screen")

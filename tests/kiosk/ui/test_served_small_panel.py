"""The served kiosk on an 800x480 panel (a 7-inch kiosk) in real Chromium: the page shrinks its
text to the 24 px floor and gives the kiosk 57x15 cells (what test_every_display.py lays out),
which is above the kiosk's floor, so it takes patients; a Lawton item whose five answers do not
fit at once is shown in pages, and on the real page "More answers" shows the rest, whose answer
a tap then stores."""

from __future__ import annotations

from kiosk.core.questionnaire import bundled_path
from kiosk.core.session import Phase
from kiosk.ui.floor import FLOOR

from .conftest import UiKiosk
from .helpers import screen_name, settle
from .serving import ACTION_RGB, ANSWER_RGB, NEEDS_CHROMIUM, answers, open_page, serve, wait_until
from .test_every_display import PANEL_800X480, shown_whole

pytestmark = NEEDS_CHROMIUM


async def _walk(folder, size: tuple[int, int]) -> list:
    """The same app laid out headless at ``size``: the taps up to the first item shown in pages
    (each ("name", region)), that item's id, and the regions of its page button and its last answer."""
    kiosk = UiKiosk(folder, familiarisation=False, questionnaire=bundled_path("lawton.yaml"))
    taps = []
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        taps.append(("language", kiosk.app.screen.query_one("#language-en").region, ACTION_RGB))
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        taps.append(("start", kiosk.app.screen.query_one("#understood").region, ACTION_RGB))
        await pilot.press("1")
        for item in kiosk.questionnaire.items:
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_item == item and kiosk.session.current_attempt == 1)
            await settle(pilot)
            opening = " ".join(item.patient_text_in("en").split()[:3])
            taps.append((f"{item.id} shown", None, opening))
            more = next(iter(kiosk.app.screen.query("#answer-more")), None)
            if more is not None and more.display:
                taps.append((item.id, more.region, ANSWER_RGB))
                await pilot.click("#answer-more")
                last = kiosk.app.screen.query_one(f"#answer-{len(item.options)}")
                await settle(pilot, lambda: last.display)
                assert not shown_whole(kiosk.app, last), shown_whole(kiosk.app, last)
                taps.append((f"{item.id} answer {len(item.options)}", last.region, ANSWER_RGB))
                return taps, item
            taps.append((item.id, kiosk.app.screen.query_one("#answer-1").region, ANSWER_RGB))
            await pilot.press("1")
            await settle(pilot, lambda: item.id in kiosk.session.answers)
        raise AssertionError(f"no Lawton item needed pages at {size}")
    assert kiosk.session.phase is Phase.QUESTIONS


async def test_an_800x480_panel_takes_patients_and_pages_the_long_answers(tmp_path, tmp_path_factory):
    with serve(tmp_path, "instruments: [lawton]\n") as served:
        async with open_page(served, (800, 480), None) as page:
            font_px = float(await page.page.evaluate("document.getElementById('terminal').dataset.fontSize"))
            assert font_px == 24 and page.size == PANEL_800X480
            assert page.size[0] >= FLOOR[0] and page.size[1] >= FLOOR[1]
            taps, paged = await _walk(tmp_path_factory.mktemp("layout"), page.size)
            await wait_until(page.page, page.painted.shows("English"), "the welcome")
            assert not page.painted.shows("not working")()
            tapped_at = 0
            for name, region, rgb in taps:
                if region is None:  # the question is on the page: its text came after the last tap
                    await wait_until(page.page, page.painted.since(tapped_at, rgb), name)
                    continue
                tapped_at = await page.tap_drawn(region, rgb, name)
                if name == paged.id:  # "More answers": the last answer's words come to the page
                    words = " ".join(paged.options[-1].patient_label_in("en").split()[:2])
                    await wait_until(page.page, page.painted.since(tapped_at, words), "the second page")
            stored = sum(1 for _, region, _ in taps if region is None)  # one answer an item shown
            await wait_until(page.page, lambda: len(answers(served.database)) == stored, "the answers stored")
            assert answers(served.database)[-1][:2] == (paged.id, len(paged.options))

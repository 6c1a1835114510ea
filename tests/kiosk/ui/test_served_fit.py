"""The served kiosk in real Chromium fits the display: at 1024x600 with ?fontsize=28, 1280x800
and 1920x1080 (no ?fontsize: the page's large default), every question in every language is
tapped through on the real page; each answer lies wholly inside the viewport and the text is at
least 24 px. Where the answers lie comes from the same app laid out by Textual at the terminal
size the page reports (as in test_served.py)."""

from __future__ import annotations

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Phase
from kiosk.ui.widgets.text import language_name

from .conftest import UiKiosk
from .fit import problems
from .helpers import screen_name, settle
from .serving import ACTION_RGB, ANSWER_RGB, NEEDS_CHROMIUM, answers, open_page, serve, wait_until

#: the smallest text the page may draw (px): what an 85-year-old can still read on the panel
MIN_TEXT_PX = 24

pytestmark = NEEDS_CHROMIUM
#: what the page may fetch: this machine only
LOCAL = ("http://127.0.0.1", "ws://127.0.0.1", "data:")


async def _layout(folder, size: tuple[int, int], language: str) -> list:
    """For the language button, Start and each question in turn: the regions to tap, and each
    question's answer regions, with the same app laid out headless at ``size`` (its own store in
    ``folder``: the served kiosk's database must hold only the taps)."""
    kiosk = UiKiosk(folder, familiarisation=False)
    number = kiosk.questionnaire.languages.index(language) + 1
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        steps = [("language", kiosk.app.screen.query_one(f"#language-{language}").region, [])]
        await pilot.press(str(number))
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        steps.append(("start", kiosk.app.screen.query_one("#understood").region, []))
        await pilot.press("1")
        for item in kiosk.questionnaire.items:
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_item == item and kiosk.session.current_attempt == 1)
            await settle(pilot)
            assert not problems(kiosk.app.screen), (item.id, problems(kiosk.app.screen))
            regions = [b.region for b in kiosk.app.screen.query("AnswerButton")]
            steps.append((item.id, regions[-1], regions))
            await pilot.press(str(len(item.options)))
            await settle(pilot, lambda: item.id in kiosk.session.answers)
        assert kiosk.session.phase in (Phase.QUESTIONS, Phase.SUMMARY)
    kiosk.store.close()
    return steps


def _opening(text: str, most: int = 40) -> str:
    """The question's first words, short enough to be drawn on one line, long enough to tell it
    from the question before ("Do you have accidents with your urine?" after "...stools?")."""
    words = text.split()
    kept = [words[0]]
    for word in words[1:]:
        if len(" ".join([*kept, word])) > most:
            break
        kept.append(word)
    return " ".join(kept)


@pytest.fixture
def served_kiosk(tmp_path):
    """`kiosk serve` on a free localhost port with its own configuration and data directory."""
    with serve(tmp_path) as served:
        yield served


@pytest.mark.parametrize(
    "viewport,fontsize",
    [((1024, 600), 28), ((1280, 800), 28), ((1920, 1080), None)],
    ids=["1024x600-28px", "1280x800-28px", "1920x1080-default"],
)
@pytest.mark.parametrize("language", ["en", "es", "fr"])
async def test_every_question_fits_the_served_page(served_kiosk, tmp_path_factory, viewport, fontsize, language):
    database = served_kiosk.database
    width, height = viewport
    async with open_page(served_kiosk, viewport, fontsize) as kiosk_page:
        page, since, box = kiosk_page.page, kiosk_page.painted.since, kiosk_page.box
        tapped_at = 0
        # the size the page gave xterm.js (it may shrink the asked size, never below the floor)
        font_px = float(await page.evaluate("document.getElementById('terminal').dataset.fontSize"))
        assert font_px >= MIN_TEXT_PX
        if fontsize is None:
            assert font_px >= 28, "without ?fontsize the page should still draw large text"
        assert box["x"] >= 0 and box["y"] >= 0
        assert box["x"] + box["width"] <= width and box["y"] + box["height"] <= height
        cell_h = kiosk_page.cell_h
        assert cell_h >= MIN_TEXT_PX, f"rows of {cell_h:.1f} px cannot hold {MIN_TEXT_PX} px text"
        steps = await _layout(tmp_path_factory.mktemp("layout"), kiosk_page.size, language)

        questionnaire = load_questionnaire()
        explanation = " ".join(questionnaire.message("explanation", language).split()[:3])
        answered = 0
        for name, target, regions in steps:
            for region in regions:
                left, top, right, bottom = kiosk_page.pixels(region)
                assert 0 <= left and right <= width and 0 <= top and bottom <= height, (
                    f"{name}: an answer at {left:.0f},{top:.0f}-{right:.0f},{bottom:.0f} px is not "
                    f"inside the {width}x{height} viewport"
                )
            if name == "language":  # the welcome is on the page
                await wait_until(page, since(0, language_name(language)), "the welcome")
            elif name == "start":  # the explanation is on the page
                await wait_until(page, since(tapped_at, explanation), "the explanation")
            elif regions:  # this question is open on the page: its text replaced the last one's
                text = _opening(questionnaire.item(name).patient_text_in(language))
                await wait_until(page, since(tapped_at, text), f"{name} on the page")
            # and what is tapped drawn where the headless app put it, as the patient sees it
            tapped_at = await kiosk_page.tap_drawn(target, ANSWER_RGB if regions else ACTION_RGB, f"{name}'s button")
            if regions:
                answered += 1
                await wait_until(page, lambda: len(answers(database)) == answered, f"{name} stored")
        assert [a[0] for a in answers(database)] == [s[0] for s in steps[2:]]
        outside = [url for url in kiosk_page.requested if not url.startswith(LOCAL)]
        assert outside == [], f"the page fetched from outside this machine: {outside}"

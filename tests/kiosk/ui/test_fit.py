"""Every patient screen, every question and every language fits the display without scrolling,
from a 100x32 kiosk down to an 80x24 terminal and the 73x18 a 1024x600 panel gets at a large font
(also 60x18, cramped), with the real app laid out by Textual at that size."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session import Phase

from .fit import problems
from .helpers import screen_name, settle

SIZES = [(100, 32), (80, 24), (73, 18), (60, 18)]


def _fits(kiosk, where: str) -> None:
    found = problems(kiosk.app.screen)
    assert not found, f"{where} at {kiosk.app.size}: " + "; ".join(found)


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", ["en", "es", "fr"])
async def test_every_screen_and_question_fits(ui_kiosk, size, language):
    kiosk = ui_kiosk(familiarisation=True)
    number = kiosk.questionnaire.languages.index(language) + 1
    async with kiosk.app.run_test(size=size) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        _fits(kiosk, "the welcome")
        await pilot.press(str(number))
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)
        seen = set()
        while kiosk.session.phase is Phase.FAMILIARISATION:  # the practice the kiosk asks here
            practice = kiosk.session.snapshot().practice
            if practice is not None and kiosk.session.current_attempt == 1 and practice.id not in seen:
                await settle(pilot, lambda: screen_name(kiosk) == "FamiliarisationScreen")
                await settle(pilot)
                _fits(kiosk, f"practice {practice.id}")
                seen.add(practice.id)
                await pilot.press(str(practice.expected))
                await settle(pilot)
            else:
                kiosk.to_next_deadline()
                await settle(pilot)
        assert seen, "no practice question was asked"
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        _fits(kiosk, "the explanation")
        await pilot.press("1")
        longest_item, longest = max(
            ((i, o.number) for i in kiosk.questionnaire.items for o in i.options),
            key=lambda io: len(io[0].option(io[1]).label_in(language)),
        )
        for item in kiosk.questionnaire.items:
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_item == item and kiosk.session.current_attempt == 1)
            await settle(pilot)
            _fits(kiosk, f"question {item.id}")
            if item.id == "transfers":  # the paused screen, over a four-answer question
                await pilot.press("p")
                await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
                _fits(kiosk, "the paused screen")
                await pilot.press("p")
                await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
            if item.id == longest_item.id:  # asked back, and asked to press, about the longest answer
                kiosk.controller.forward(
                    ChannelInput(Channel.VOICE, option=longest, detail="heard", confidence=0.9, needs_confirmation=True)
                )
                await settle(pilot, lambda: bool(kiosk.app.screen.query("ConfirmPanel")))
                _fits(kiosk, f"the question back on {item.id}")
                kiosk.controller.forward(
                    ChannelInput(Channel.VOICE, option=1, detail="yes", confidence=0.9, needs_confirmation=True)
                )
                plea = kiosk.questionnaire.message("confirm_answer_press", language).split("{")[0]
                await settle(pilot, lambda: plea in str(kiosk.app.screen.query_one("#confirm-question").render()))
                await settle(pilot)
                _fits(kiosk, f"the plea to press on {item.id}")
                await pilot.press("2")
                await settle(pilot, lambda: bool(kiosk.app.screen.query("QuestionPanel")))
            await pilot.press(str(len(item.options)))
            await settle(pilot, lambda: item.id in kiosk.session.answers)
            await settle(pilot)
            _fits(kiosk, f"question {item.id} answered")
        kiosk.to_next_deadline()
        await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")
        _fits(kiosk, "the summary")


async def test_answers_do_not_move_when_one_is_chosen(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await settle(pilot)
        before = [b.region for b in kiosk.app.screen.query("AnswerButton")]
        kiosk.controller.forward(ChannelInput(Channel.TOUCH, option=2, detail="screen"))
        await settle(pilot, lambda: kiosk.app.screen.query_one("#interlude").display)
        await settle(pilot)
        assert [b.region for b in kiosk.app.screen.query("AnswerButton")] == before
        assert kiosk.app.screen.query_one("#answer-2").has_class("-chosen")

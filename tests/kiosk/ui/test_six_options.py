"""Items with five or six answers: every answer reachable by touch, keys 1-6, voice and a
four-button remote (two pages: "4 More answers" / "4 Back"), on every display size; staff items
never reach the patient. A real kiosk (make_kiosk) on an instrument written in format v2."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus
from kiosk.core.session import Phase
from kiosk.remote.buttons import to_input
from kiosk.speech.matching import Matcher, OptionWords
from kiosk.ui.paging import RemotePager, shown

from .fit import problems
from .helpers import deliver_from_thread, drawn_text, screen_name, settle, until_drawn

#: a walking item with six levels, a staff-measured weight between, a five-answer item and a
#: staff choice
STEPS = [
    "Cannot walk",
    "Walks with two people",
    "Walks with one person",
    "Walks with a frame",
    "Walks with a stick",
    "Walks alone",
]
SIX = f"""\
id: walking
version: "1"
source: "A test instrument (no publication)"
title: {{en: Walking, es: Caminar, fr: Marcher}}
languages: [en, es, fr]
total_code: {{system: "urn:test:total", code: "walking", display: "Walking total"}}
timing: {{attempt_window_s: 20}}
bands:
  default: main
  sets:
    main:
      source: test cut-offs
      ranges:
        - {{id: low, min: 0, max: 4, label: {{en: Low, es: Bajo, fr: Bas}}}}
        - {{id: high, min: 5, max: 9, label: {{en: High, es: Alto, fr: Haut}}}}
items:
  - id: steps
    text: {{en: "How do you walk?", es: "¿Cómo camina?", fr: "Comment marchez-vous ?"}}
    spoken: {{en: "How do you walk?", es: "¿Cómo camina?", fr: "Comment marchez-vous ?"}}
    options:
{"".join(f'      - points: {n}{chr(10)}        label: {{en: "{t}", es: "{t} (es)", fr: "{t} (fr)"}}{chr(10)}' for n, t in enumerate(STEPS))}\
  - id: weight
    answered_by: staff
    text: {{en: "Weight", es: "Peso", fr: "Poids"}}
    input: {{type: decimal, min: 20, max: 250, unit: kg}}
  - id: stairs
    text: {{en: "How do you climb stairs?", es: "¿Escaleras?", fr: "Escaliers ?"}}
    spoken: {{en: "How do you climb stairs?", es: "¿Escaleras?", fr: "Escaliers ?"}}
    options:
{"".join(f'      - points: {min(n, 3)}{chr(10)}        label: {{en: "Stairs {n}", es: "Escaleras {n}", fr: "Escaliers {n}"}}{chr(10)}' for n in range(5))}
  - id: aid
    answered_by: staff
    text: {{en: "Uses a walking aid", es: "Usa ayuda", fr: "Utilise une aide"}}
    options:
      - {{points: 0, label: {{en: "No aid", es: "Sin ayuda", fr: "Sans aide"}}}}
      - {{points: 1, label: {{en: "An aid", es: "Con ayuda", fr: "Avec aide"}}}}
"""

SIZES = [(100, 32), (80, 24), (73, 18), (60, 18)]


def _kiosk(ui_kiosk, tmp_path: Path):
    path = tmp_path / "walking.yaml"
    path.write_text(SIX, encoding="utf-8")
    return ui_kiosk(familiarisation=False, questionnaire=path)


async def _to_steps(kiosk, pilot) -> None:
    """Start in English and wait for the six-answer item's attempt 1 on screen."""
    await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
    await pilot.press("1")
    await settle(pilot, lambda: kiosk.session.phase is not Phase.WELCOME)
    while kiosk.session.current_item is None:
        if screen_name(kiosk) == "ExplanationScreen":
            await pilot.press("1")
            await settle(pilot)
        kiosk.to_next_deadline()
        await settle(pilot)
    await settle(pilot, lambda: kiosk.session.current_item.id == "steps" and kiosk.session.current_attempt == 1)


def _remote_on(kiosk) -> None:
    deliver_from_thread(kiosk, ChannelStatus(Channel.REMOTE, ChannelState.ON, "serial", "connected to /dev/ttyUSB0"))


def _stored(kiosk, item_id: str):
    return {a.item_id: a for a in kiosk.store.session(kiosk.session.id).answers}.get(item_id)


def test_the_pager_maps_the_remotes_four_buttons_onto_six_answers():
    pager = RemotePager()
    key = ("steps", 1)
    assert pager.press(key, 6, 2) == 2
    assert pager.press(key, 6, 4) is None and pager.page(key) == 1
    assert pager.press(key, 6, 2) == 5
    assert pager.press(key, 6, 4) is None and pager.page(key) == 0  # "4 Back"
    pager.turn(key)
    assert pager.page(("steps", 2)) == 0  # asked again: the first page
    assert pager.press(key, 4, 4) == 4  # four answers are never paged
    assert [(s.number, s.option) for s in shown(1, 5)] == [(1, 4), (2, 5), (4, None)]


def test_six_is_a_word_the_voice_understands_on_a_six_answer_item():
    for language, six in (("en", "six"), ("es", "seis"), ("fr", "six")):
        matcher = Matcher([OptionWords(t) for t in STEPS], language)
        assert matcher.match(six, 0.95).option == 6


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
async def test_six_answers_all_show_and_a_touch_on_the_sixth_is_stored(ui_kiosk, tmp_path, size):
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=size) as pilot:
        await _to_steps(kiosk, pilot)
        await until_drawn(pilot, *STEPS)
        found = problems(kiosk.app.screen)
        assert not found, "; ".join(found)
        await pilot.click("#answer-6")
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        assert _stored(kiosk, "steps").option == 6 and _stored(kiosk, "steps").channel == "touch"


async def test_key_six_answers_the_sixth(ui_kiosk, tmp_path):
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        await _to_steps(kiosk, pilot)
        await pilot.press("6")
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        assert _stored(kiosk, "steps").option == 6 and _stored(kiosk, "steps").channel == "keyboard"


async def test_voice_six_answers_the_sixth(ui_kiosk, tmp_path):
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=(100, 32)) as pilot:
        await _to_steps(kiosk, pilot)
        deliver_from_thread(kiosk, ChannelInput(Channel.VOICE, option=6, detail="six", confidence=0.95))
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        assert _stored(kiosk, "steps").option == 6 and _stored(kiosk, "steps").channel == "voice"


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
async def test_a_four_button_remote_pages_to_the_fifth_answer(ui_kiosk, tmp_path, size):
    """With a remote, the screen shows 1-3 and "4 More answers"; 4 shows options 4-6 as 1-3 and
    "4 Back"; then 2 is option 5. Every page fits and never shows a number the remote lacks."""
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=size) as pilot:
        _remote_on(kiosk)
        await _to_steps(kiosk, pilot)
        first = await until_drawn(pilot, STEPS[0], STEPS[2], "More answers")
        assert STEPS[3] not in first and STEPS[5] not in first
        assert not kiosk.app.screen.query("#answer-5")
        assert not problems(kiosk.app.screen)
        deliver_from_thread(kiosk, to_input(4, "4"))
        second = await until_drawn(pilot, STEPS[3], STEPS[5], "Back")
        assert STEPS[0] not in second and "More answers" not in second
        assert [b.shows for b in kiosk.app.screen.query("AnswerButton")] == [1, 2, 3, 4]
        assert not problems(kiosk.app.screen)
        assert _stored(kiosk, "steps") is None  # turning the page answers nothing
        deliver_from_thread(kiosk, to_input(2, "2"))
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        assert _stored(kiosk, "steps").option == 5 and _stored(kiosk, "steps").channel == "remote"


async def test_back_returns_to_the_first_answers_and_a_touch_on_more_pages_too(ui_kiosk, tmp_path):
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        _remote_on(kiosk)
        await _to_steps(kiosk, pilot)
        await until_drawn(pilot, "More answers")
        await pilot.click("#answer-page")
        await until_drawn(pilot, STEPS[4], "Back")
        deliver_from_thread(kiosk, to_input(4, "4"))
        await until_drawn(pilot, STEPS[1], "More answers")
        deliver_from_thread(kiosk, to_input(1, "1"))
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        assert _stored(kiosk, "steps").option == 1


async def test_the_staff_item_is_never_asked_and_the_count_leaves_it_out(ui_kiosk, tmp_path):
    """After the six-answer item comes the five-answer one (the staff weight is skipped), as
    "Question 2 of 2"; the visit ends with the weight waiting for staff."""
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=(100, 32)) as pilot:
        await _to_steps(kiosk, pilot)
        await until_drawn(pilot, "Question 1 of 2")
        await pilot.press("3")
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        kiosk.to_next_deadline()
        await settle(
            pilot, lambda: kiosk.session.current_item is not None and kiosk.session.current_item.id == "stairs"
        )
        shown_now = await until_drawn(pilot, "Question 2 of 2", "Stairs 4")
        assert "Weight" not in shown_now
        await pilot.press("5")
        await settle(pilot, lambda: _stored(kiosk, "stairs") is not None)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.phase is Phase.SUMMARY)
        assert "weight" not in {a.item_id for a in kiosk.store.session(kiosk.session.id).answers}
        assert "Weight" not in drawn_text(kiosk.app)


async def test_with_pages_shown_keys_1_to_4_press_what_the_screen_shows(ui_kiosk, tmp_path):
    """While the pages are shown, the number pressed on the keyboard is the number on screen too:
    4 turns the page, 2 is then option 5; 5 and 6 stay options 5 and 6."""
    kiosk = _kiosk(ui_kiosk, tmp_path)
    async with kiosk.app.run_test(size=(80, 24)) as pilot:
        _remote_on(kiosk)
        await _to_steps(kiosk, pilot)
        await until_drawn(pilot, "More answers")
        await pilot.press("4")
        await until_drawn(pilot, STEPS[4], "Back")
        await pilot.press("2")
        await settle(pilot, lambda: _stored(kiosk, "steps") is not None)
        assert _stored(kiosk, "steps").option == 5 and _stored(kiosk, "steps").channel == "keyboard"
        kiosk.to_next_deadline()
        await settle(
            pilot, lambda: kiosk.session.current_item is not None and kiosk.session.current_item.id == "stairs"
        )
        await until_drawn(pilot, "Stairs 0", "More answers")
        await pilot.press("5")
        await settle(pilot, lambda: _stored(kiosk, "stairs") is not None)
        assert _stored(kiosk, "stairs").option == 5

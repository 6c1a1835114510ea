"""The shipped instruments beside the Barthel run through the real app with Textual's Pilot: the
patient reads the instrument's own questions and plain answers, and the summary's total is the
instrument's (the GDS-15 in German, SARC-F and the Lawton IADL in English)."""

from __future__ import annotations

import pytest

from kiosk.core.questionnaire import bundled_path
from kiosk.core.session import Phase

from .helpers import drawn_text, screen_name, settle, until_drawn


def _kiosk_with(monkeypatch, ui_kiosk, name: str, **options):
    """The UI test kiosk running the shipped ``name`` instead of the Barthel."""
    return ui_kiosk(familiarisation=False, questionnaire=bundled_path(f"{name}.yaml"), **options)


async def _start(kiosk, pilot, language_number: int, explanation: tuple[str, ...] = ()) -> None:
    """Choose the language by its number, read the explanation (``explanation`` drawn), start."""
    await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
    await pilot.press(str(language_number))
    await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
    await until_drawn(pilot, *explanation)
    await pilot.press("1")
    await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)


async def _answer_all(kiosk, pilot, choose, drawn: tuple[str, ...] = ()) -> None:
    """Each question: wait until it is open with its patient text (and ``drawn``) on screen, then
    press ``choose(item)``; finally wait for the summary."""
    for item in kiosk.questionnaire.items:
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        assert kiosk.session.current_item.id == item.id
        await until_drawn(pilot, item.patient_text_in(kiosk.session.language)[:30], *drawn)
        await pilot.press(str(choose(item)))
        await settle(pilot, lambda: item.id in kiosk.session.answers)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")


async def test_gds15_in_german_by_keys_scores_as_published(monkeypatch, ui_kiosk):
    kiosk = _kiosk_with(monkeypatch, ui_kiosk, "gds15", show_score=True)
    async with kiosk.app.run_test() as pilot:
        # how many questions, and about which time: the past week
        # the welcome and the questions name it in plain words, never "depression"
        await until_drawn(pilot, "Questions about how you feel")
        assert "epress" not in drawn_text(kiosk.app)
        await _start(kiosk, pilot, kiosk.questionnaire.languages.index("de") + 1, ("fünfzehn Fragen", "letzten Woche"))
        assert "epress" not in drawn_text(kiosk.app)
        # "Ja" to every question: one point on each item scored on Yes (10 of the 15)
        await _answer_all(kiosk, pilot, lambda item: 1, drawn=("Ja", "Nein"))
        # the end screen keeps the plain title, not the clinical one (the band is staff's words)
        await until_drawn(pilot, "Fragen zu Ihrem Befinden")
        assert kiosk.questionnaire.title["de"] not in drawn_text(kiosk.app)
    score = kiosk.session.score()
    assert (score.total, score.band.id) == (10, "suggests_depression")


async def test_sarc_f_by_keys_scores_as_published(monkeypatch, ui_kiosk):
    kiosk = _kiosk_with(monkeypatch, ui_kiosk, "sarc_f")
    async with kiosk.app.run_test() as pilot:
        await _start(kiosk, pilot, 1)
        # strength "a lot" (2), walking none (0), chair some (1), stairs some (1), falls none (0)
        chosen = {"strength": 3, "assistance_walking": 1, "rise_from_chair": 2, "climb_stairs": 2, "falls": 1}
        await _answer_all(kiosk, pilot, lambda item: chosen[item.id])
    score = kiosk.session.score()
    assert (score.total, score.band.id) == (4, "suggests_sarcopenia")


@pytest.mark.parametrize("option", [1, 4])
async def test_lawton_shared_scores_by_keys(monkeypatch, ui_kiosk, option):
    kiosk = _kiosk_with(monkeypatch, ui_kiosk, "lawton")
    async with kiosk.app.run_test() as pilot:
        await _start(kiosk, pilot, 1)
        # option 1 scores 1 everywhere; option 4 (or the last of a three-level item) scores 0
        # everywhere but housekeeping, where "needs help with all" still scores 1 (shared)
        await _answer_all(kiosk, pilot, lambda item: min(option, len(item.options)))
    assert kiosk.session.score().total == (8 if option == 1 else 1)

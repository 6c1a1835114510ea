"""Snapshots of every screen at the kiosk's size (`pytest --snapshot-update` after a deliberate
change, then look at the SVGs). Deterministic: a simulated clock, fixed session and patient ids,
no blinking cursor, no focus on the patient's screens, channel states given by the test."""

from __future__ import annotations

import pytest

from kiosk.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.channels import Channel, ChannelInput

from .conftest import UI_PIN
from .helpers import deliver_from_thread, screen_name, settle, start_in_english


async def _question(kiosk, pilot) -> None:
    await start_in_english(kiosk, pilot)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)


def test_welcome(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_familiarisation(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("3")  # Français
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_explanation(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("2")  # Español
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_before_the_first_question(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await start_in_english(kiosk, pilot)  # Start pressed; question 1 comes between_questions_s later
        await settle(pilot, lambda: kiosk.app.screen.query("#interlude") and kiosk.app.screen.query_one("#interlude").display)

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_question(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        kiosk.to_next_deadline()  # attempt 2 shows in the top bar
        await settle(pilot, lambda: kiosk.session.current_attempt == 2)

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_question_answered_by_the_remote(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        deliver_from_thread(kiosk, ChannelInput(Channel.REMOTE, option=2, detail="BTN 2"))
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_paused(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_doctor_called(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        await pilot.press("d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


async def _finish(kiosk, pilot) -> None:
    await _question(kiosk, pilot)
    for index in range(10):
        if index:
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        if index == 4:  # one question left unanswered: the summary says so
            kiosk.to_next_deadline()
            kiosk.to_next_deadline()
            continue
        item = kiosk.session.current_item
        await pilot.press(str(len(item.options) - index % 2))
        await settle(pilot, lambda: item.id in kiosk.session.answers)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")


def test_summary(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _finish(kiosk, pilot)

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_pin(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press(CLINICIAN_CHORD, "1", "2")
        await settle(pilot, lambda: screen_name(kiosk) == "PinScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_clinician_home(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        await pilot.press("d", CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_session_detail(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()  # with the practice questions: their outcomes are on the detail screen

    async def run_before(pilot) -> None:
        await _finish(kiosk, pilot)
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await pilot.press("enter")  # the session list has the focus; open its first row
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


# The same screens on smaller displays: an 80x24 terminal, the 73x18 a 1024x600 panel gets at a
# large font (the served page's floor of 24 px), and a cramped 60x18.
SMALL = [(80, 24), (73, 18), (60, 18)]


@pytest.mark.parametrize("size", SMALL, ids=lambda s: f"{s[0]}x{s[1]}")
def test_welcome_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)


@pytest.mark.parametrize("size", SMALL, ids=lambda s: f"{s[0]}x{s[1]}")
def test_four_answer_question_in_french_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk(familiarisation=False, language="fr")

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("3")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        while kiosk.session.current_item is None or kiosk.session.current_item.id != "transfers" \
                or kiosk.session.current_attempt != 1:
            if kiosk.session.current_attempt == 1:
                await pilot.press("1")
                await settle(pilot, lambda: kiosk.session.current_attempt is None)
            kiosk.to_next_deadline()
            await settle(pilot)

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)


@pytest.mark.parametrize("size", SMALL, ids=lambda s: f"{s[0]}x{s[1]}")
def test_explanation_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)


@pytest.mark.parametrize("size", [(80, 24)], ids=["80x24"])
def test_session_detail_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await _finish(kiosk, pilot)
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await pilot.press("enter")
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)

"""Snapshots of every screen at the kiosk's size (`pytest --snapshot-update` after a deliberate
change, then look at the SVGs). Deterministic: a simulated clock, fixed session and patient ids,
no blinking cursor, no focus on the patient's screens, channel states given by the test. Each
waits until what it shows is drawn (:func:`until_drawn`), never only until the session holds it:
on a busy machine the snapshot would otherwise catch the frame before."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE

from .conftest import UI_PIN
from .helpers import deliver_from_thread, screen_name, settle, start_in_english, until_drawn


async def _question(kiosk, pilot) -> None:
    await start_in_english(kiosk, pilot)
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)


def test_welcome(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await until_drawn(pilot, "3  Français", "4  Deutsch")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_familiarisation(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("3")  # Français
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)
        await until_drawn(pilot, "Essai 1 sur", "D'abord, quelques questions")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_explanation(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("2")  # Español
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await until_drawn(pilot, "Empezar")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_before_the_first_question(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await start_in_english(kiosk, pilot)  # Start pressed; question 1 comes between_questions_s later
        await until_drawn(pilot, "Thank you. Here is the first question…")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_question(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        kiosk.to_next_deadline()  # attempt 2 shows in the top bar
        await settle(pilot, lambda: kiosk.session.current_attempt == 2)
        await until_drawn(pilot, "Attempt 2 of 2")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_question_answered_by_the_remote(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        deliver_from_thread(kiosk, ChannelInput(Channel.REMOTE, option=2, detail="BTN 2"))
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        await until_drawn(pilot, "Thank you. Next question…", "C  Change my answer")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_paused(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        await until_drawn(pilot, "Paused", "P  Continue")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_doctor_called(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        await pilot.press("d")
        await settle(pilot, lambda: screen_name(kiosk) == "DoctorCalledScreen")
        await until_drawn(pilot, "The doctor has been called", "I'm fine, carry on")

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
    await until_drawn(pilot, "Thank you, you are done. Please call the nurse.")


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
        await until_drawn(pilot, "● ●", "Back to the patient")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_clinician_home(snap_compare, ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await _question(kiosk, pilot)
        await pilot.press("d", CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await until_drawn(pilot, "waiting for a clinician (doctor called)")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


def test_session_detail(snap_compare, ui_kiosk):
    kiosk = ui_kiosk()  # with the practice questions: their outcomes are on the detail screen

    async def run_before(pilot) -> None:
        await _finish(kiosk, pilot)
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await pilot.press("enter")  # the session list has the focus; open its first row
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        await until_drawn(pilot, "Session 5e55a0000001")

    assert snap_compare(kiosk.app, terminal_size=KIOSK_SIZE, run_before=run_before)


# The same screens on smaller displays: an 80x24 terminal, the 73x18 a 1024x600 panel gets at a
# large font (the served page's floor of 24 px), and a cramped 60x18.
SMALL = [(80, 24), (73, 18), (64, 18), (60, 18)]


@pytest.mark.parametrize("size", SMALL, ids=lambda s: f"{s[0]}x{s[1]}")
def test_welcome_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk()

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await until_drawn(pilot, "Français", "Deutsch")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)


@pytest.mark.parametrize("size", SMALL, ids=lambda s: f"{s[0]}x{s[1]}")
def test_four_answer_question_in_french_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk(familiarisation=False, language="fr")

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("3")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        while (
            kiosk.session.current_item is None
            or kiosk.session.current_item.id != "transfers"
            or kiosk.session.current_attempt != 1
        ):
            if kiosk.session.current_attempt == 1:
                await pilot.press("1")
                await settle(pilot, lambda: kiosk.session.current_attempt is None)
            kiosk.to_next_deadline()
            await settle(pilot)
        await until_drawn(pilot, "Tentative 1 sur 2")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)


@pytest.mark.parametrize("size", SMALL, ids=lambda s: f"{s[0]}x{s[1]}")
def test_explanation_small(snap_compare, ui_kiosk, size):
    kiosk = ui_kiosk(familiarisation=False)

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await until_drawn(pilot, "Start")

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
        await until_drawn(pilot, "Session 5e55a0000001")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)


@pytest.mark.parametrize("size", [KIOSK_SIZE, (80, 24), (64, 18)], ids=lambda s: f"{s[0]}x{s[1]}")
def test_thank_you_gap_in_spanish(snap_compare, ui_kiosk, size):
    """The chosen answer stays drawn, uncovered, beside the whole thanks and "Change my answer"."""
    kiosk = ui_kiosk(familiarisation=False, language="es")

    async def run_before(pilot) -> None:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("2")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.press("2")
        await until_drawn(pilot, "Gracias. Siguiente pregunta…", "C  Cambiar mi respuesta", "cortar o untar")

    assert snap_compare(kiosk.app, terminal_size=size, run_before=run_before)

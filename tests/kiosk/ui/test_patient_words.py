"""What the patient reads is true and plain: instructions built from the channels on at that
moment, in en/es/fr; no technical words; the controls' letters fit the language; small slips
(a number with no answer, Tab) get a gentle, visible response."""

from __future__ import annotations

from dataclasses import replace

import pytest
from textual.widgets import Button, Static

from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Phase
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.screens.base import PatientView, Ways, patient_notices
from kiosk.ui.screens.explanation import how_to_answer
from kiosk.ui.screens.paused import how_to_continue
from kiosk.ui.screens.welcome import welcome_line
from kiosk.ui.widgets.channel_board import ChannelBoard

from .helpers import deliver_from_thread, screen_name, settle, text_of

QUESTIONNAIRE = load_questionnaire()
TOUCH_ONLY, ALL = Ways(), Ways(remote=True, voice=True, listening=True, voice_out=True)


class _Snap:
    """The few snapshot fields the sentences read."""

    def __init__(self, language: str, adaptations=frozenset(), person_present: bool = True) -> None:
        self.language, self.adaptations, self.person_present = language, adaptations, person_present


def _view(language: str, ways: Ways, **snap) -> PatientView:
    # a stand-in with only the fields the words read, not a whole Snapshot
    return PatientView(_Snap(language, **snap), QUESTIONNAIRE, ways)  # type: ignore[arg-type]  # a stand-in


def test_how_to_answer_names_only_the_channels_that_are_on():
    assert how_to_answer(_view("en", TOUCH_ONLY)) == (
        "Answer by touching it on the screen. When you are ready, touch Start."
    )
    assert how_to_answer(_view("en", ALL)) == (
        "Answer by touching it on the screen, pressing its number on the remote or saying it. "
        'When you are ready, touch Start, press any number on the remote or say "I\'m ready".'
    )
    assert how_to_answer(_view("es", Ways(remote=True))) == (
        "Responda tocando la respuesta en la pantalla o pulsando su número en el mando. "
        "Cuando quiera, toque Empezar o pulse cualquier número en el mando."
    )
    assert how_to_answer(_view("fr", Ways(voice=True))) == (
        "Répondez en touchant la réponse sur l'écran ou en la disant à voix haute. "
        "Quand vous voulez, touchez Commencer ou dites commencer."
    )


@pytest.mark.parametrize("language", ["en", "es", "fr"])
def test_nothing_promises_a_channel_that_is_off(language):
    said = " ".join(
        [
            how_to_answer(_view(language, TOUCH_ONLY)),
            how_to_continue(_view(language, TOUCH_ONLY)),
            welcome_line(_view(language, TOUCH_ONLY), language),
        ]
    ).lower()
    for promise in ("remote", "mando", "télécommande", "say", "diga", "dites", "voix", "voz", "speak"):
        assert promise not in said


def test_the_welcome_promises_saying_the_language_only_while_it_listens():
    """The promise is the language's own name, which the recogniser hears on other voices (28 of
    32 "English", 6 of 8 "español", 8 of 8 "français"), not "start" (22 of 32)."""
    heard = Ways(voice=True, listening=False)
    assert "say" not in welcome_line(_view("en", heard), "en")
    listening = Ways(voice=True, listening=True)
    assert welcome_line(_view("en", listening), "en") == 'Welcome. Touch your language or say "English".'
    assert welcome_line(_view("en", listening), "es").endswith("o diga «español».")
    assert welcome_line(_view("en", listening), "fr").endswith("ou dites « français ».")
    # each language's line in that language, whatever language the session is in
    assert welcome_line(_view("en", TOUCH_ONLY), "es") == "Le damos la bienvenida. Elija su idioma, por favor."
    assert welcome_line(_view("es", TOUCH_ONLY), "fr") == "Bienvenue. Choisissez votre langue, s'il vous plaît."


def test_notices_never_mention_a_voice_that_is_off():
    slow = _view("en", TOUCH_ONLY, adaptations=frozenset({"slow_speech"}))
    assert patient_notices(slow) is None
    assert patient_notices(replace(slow, ways=ALL)) == "I am speaking more slowly now."
    voice_off = _view("fr", Ways(remote=True), adaptations=frozenset({"voice_off"}))
    assert patient_notices(voice_off) == (
        "J'ai du mal à vous entendre. S'il vous plaît, touchez votre réponse "
        "ou appuyez sur son numéro sur la télécommande."
    )


def test_the_clinicians_channel_words_agree_in_gender():
    board = ChannelBoard("espeak-ng")
    board.update(ChannelStatus(Channel.VOICE, ChannelState.OFF, "espeak-ng", "no espeak-ng"))
    board.update(ChannelStatus(Channel.REMOTE, ChannelState.OFF, "serial", "none"))
    es = {line.name: line.state for line in board.lines("es")}
    fr = {line.name: line.state for line in board.lines("fr")}
    assert (es["Voz"], es["Mando"], es["Pantalla"]) == ("apagada", "apagado", "activa")
    assert (fr["Voix"], fr["Télécommande"], fr["Écran"]) == ("coupée", "éteinte", "actif")


def test_patient_wording_is_plain_and_the_clinical_label_stays_for_clinicians():
    bowels = QUESTIONNAIRE.item("bowels")
    assert bowels.patient_text_in("en") == "Do you have accidents with your stools?"
    assert bowels.text["en"].startswith("Bowels")  # the clinical wording is kept for exports
    assert bowels.option(1).label_in("en") == "Incontinent or needs enemas"
    for language in QUESTIONNAIRE.languages:
        for item in QUESTIONNAIRE.items:
            shown = " ".join([item.patient_text_in(language), *(o.patient_label_in(language) for o in item.options)])
            for clinical in (
                "Bowels",
                "Transfers",
                "enema",
                "Incontinent",
                "Dependent",
                "Independent",
                "Deposición",
                "Traslado",
                "Incontinente",
                "Dependiente",
                "Independiente",
                "Transferts",
                "lavement",
                "Dépendant",
                "Autonome",
            ):
                assert clinical.lower() not in shown.lower(), (item.id, language, clinical)
        # answers in the first person throughout (no "Needs help" beside "I need help")
        for item in QUESTIONNAIRE.items:
            for option in item.options:
                assert not option.patient_label_in("en").startswith(("Needs", "Walks", "Unable")), option


async def _first_question(kiosk, pilot, language_key: str) -> None:
    """Choose the language by its number, start, and wait for question 1's first attempt."""
    await pilot.press(language_key)
    await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
    await pilot.press("1")
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)


async def test_spanish_controls_use_their_own_letters_and_repeat_needs_a_voice(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, language="es")
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot, "2")
        screen = kiosk.app.screen
        assert str(screen.query_one("#call-doctor", Button).label).startswith("M ")
        assert not screen.query_one("#repeat", Button).display  # no voice out: Repeat would do nothing
        deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.ON, "espeak-ng"))
        await settle(pilot, lambda: screen.query_one("#repeat", Button).display)
        await pilot.press("m")
        await settle(pilot, lambda: kiosk.session.halted)


async def test_a_number_with_no_answer_gets_a_gentle_hint_and_tab_does_not_choose(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot, "1")
        await pilot.press("4")  # feeding has three answers
        banner = kiosk.app.screen.query_one("#banner", Static)
        await settle(pilot, lambda: banner.display)
        assert text_of(banner) == "Please choose 1, 2 or 3."
        assert kiosk.session.answers == {}
        await pilot.press("tab")
        await settle(pilot)
        first, second = kiosk.app.screen.query_one("#answer-1"), kiosk.app.screen.query_one("#answer-2")
        assert first.has_focus and not first.has_class("-chosen")
        assert first.styles.background == second.styles.background  # focus is an outline, not a fill
        await pilot.press("2")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        await settle(pilot, lambda: not banner.display)


async def test_the_paused_screen_keeps_the_question_number(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _first_question(kiosk, pilot, "1")
        await pilot.press("p")
        await settle(pilot, lambda: screen_name(kiosk) == "PausedScreen")
        assert text_of(kiosk.app.screen.query_one("#progress")) == "Question 1 of 10"
        assert text_of(kiosk.app.screen.query_one("#paused-text")) == (
            "We are waiting for you. When you are ready, touch Continue."
        )
        assert kiosk.session.phase is Phase.QUESTIONS


def test_spoken_ways_follow_the_channels_in_every_language():
    from kiosk.ui.screens.base import spoken_with_ways

    said = next(p for p in QUESTIONNAIRE.familiarisation if p.id == "practice_select").spoken
    assert spoken_with_ways(said["en"], "en", ALL) == (
        "Please choose answer number three. Touch it, press its number on the remote or say its number."
    )
    assert spoken_with_ways(said["es"], "es", Ways(voice=True)) == (
        "Por favor, elija la respuesta número tres. Tóquela o diga su número."
    )
    assert spoken_with_ways(said["fr"], "fr", TOUCH_ONLY) == "Veuillez choisir la réponse numéro trois. Touchez-la."
    assert spoken_with_ways("Welcome.", "en", ALL) == "Welcome."

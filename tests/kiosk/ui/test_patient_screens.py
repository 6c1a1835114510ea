"""What a patient reads and sees (issue 23): notices only in their language's words, the chosen
answer readable through the whole thank-you gap with the thanks and "Change my answer" whole
beside it at every size, true instructions (any number starts, a capital C takes back, no hearing
promised without a voice), solid numbers, even language buttons, and a doctor-called screen that
counts no attempt. Each waits on what is drawn."""

from __future__ import annotations

import pytest
from textual.widgets import Button, Static

from kiosk.core.adaptation import KNOWN
from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Phase, Prompt
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.screens.base import PatientView, Ways, patient_notices
from kiosk.ui.widgets.answer_button import AnswerButton
from kiosk.ui.widgets.change_answer import ChangeAnswerButton

from .helpers import deliver_from_thread, drawn_text, screen_name, settle, until_drawn

QUESTIONNAIRE = load_questionnaire()
#: the terminal sizes the issue tried (and the 73x18 a 1024x600 panel gets at 28 px, and 60x18)
SIZES = [(100, 32), (80, 24), (73, 18), (64, 18), (60, 18)]
KEYS = {"en": "1", "es": "2", "fr": "3"}
THANKS = {"en": "Thank you. Next question…", "es": "Gracias. Siguiente pregunta…", "fr": "Merci. Question suivante…"}
KIND = {
    "en": "Take all the time you need.",
    "es": "Tómese todo el tiempo que necesite.",
    "fr": "Prenez tout le temps qu'il vous faut.",
}


class _Snap:
    def __init__(self, language: str, adaptations) -> None:
        self.language, self.adaptations, self.person_present = language, frozenset(adaptations), True


@pytest.mark.parametrize("language", ["en", "es", "fr"])
def test_no_adaptation_shows_its_policy_name(language):
    for name in KNOWN:
        view = PatientView(_Snap(language, {name}), QUESTIONNAIRE, Ways(remote=True, voice=True, voice_out=True))
        words = patient_notices(view) or ""
        assert "_" not in words and name.replace("_", " ") not in words, (name, words)
    assert patient_notices(PatientView(_Snap(language, {"longer_attempts"}), QUESTIONNAIRE)) == KIND[language]
    assert patient_notices(PatientView(_Snap(language, {"some_new_policy"}), QUESTIONNAIRE)) is None


async def _to_first_question(kiosk, pilot, language: str) -> None:
    await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
    await pilot.press(KEYS[language])
    await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
    await pilot.press("1")
    kiosk.to_next_deadline()
    await settle(pilot, lambda: kiosk.session.current_attempt == 1)


@pytest.mark.parametrize("language", ["es", "fr"])
async def test_longer_attempts_reads_kindly_and_the_end_screen_shows_no_notice(ui_kiosk, language):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _to_first_question(kiosk, pilot, language)
        while "longer_attempts" not in kiosk.session.snapshot().adaptations:  # a slow patient: no answers
            assert kiosk.session.phase is Phase.QUESTIONS, "longer attempts never switched on"
            kiosk.to_next_deadline()
            await settle(pilot)
        shown = await until_drawn(pilot, KIND[language])
        assert "longer" not in shown and "attempts" not in shown
        while kiosk.session.phase is not Phase.SUMMARY:
            kiosk.to_next_deadline()
            await settle(pilot)
        shown = await until_drawn(pilot, QUESTIONNAIRE.message("finished", language) or "")
        assert KIND[language] not in shown and not kiosk.app.screen.query_one("#banner").display


def _gap_problems(screen) -> list[str]:
    """What hides or cuts the chosen answer, the thanks or the button during the gap."""
    found = []
    chosen = next(b for b in screen.query(AnswerButton) if b.has_class("-chosen"))
    label = chosen.query_one(".label")
    for y in range(label.region.y, label.region.bottom):
        for x in range(label.region.x, label.region.right):
            widget, _ = screen.get_widget_at(x, y)
            if widget is not label:
                found.append(f"{widget!r} is drawn over the chosen answer at {x},{y}")
                break
    line = screen.query_one("#interlude", Static)
    wanted = line.get_content_height(line.size, screen.size, line.content_region.width)
    if wanted > line.content_region.height:
        found.append(f"the thanks need {wanted} rows and have {line.content_region.height}")
    button = screen.query_one(ChangeAnswerButton)
    if button.content_region.width < len(str(button.label)):
        found.append(f"'{button.label}' is cut at {button.region}")
    for answer in screen.query(AnswerButton):
        for other in (line, button):
            if answer.region.overlaps(other.region):
                found.append(f"{other!r} overlaps answer {answer.option}")
    return found


@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", ["en", "es", "fr"])
async def test_the_chosen_answer_stays_readable_through_the_gap(ui_kiosk, language, size):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=size) as pilot:
        await _to_first_question(kiosk, pilot, language)
        before = [b.region for b in kiosk.app.screen.query(AnswerButton)]
        await pilot.press("2")
        chosen = kiosk.session.current_item or kiosk.questionnaire.items[0]
        words = chosen.option(2).patient_label_in(language).split()
        shown = await until_drawn(pilot, THANKS[language].split()[0], "C ", *words)
        assert not _gap_problems(kiosk.app.screen), _gap_problems(kiosk.app.screen)
        assert [b.region for b in kiosk.app.screen.query(AnswerButton)] == before  # nothing moved
        assert " ".join(THANKS[language].split()[1:]) in " ".join(shown.split()) or size[0] < 70


async def test_the_last_thanks_are_whole_on_a_small_display(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=(64, 18)) as pilot:
        await _to_first_question(kiosk, pilot, "fr")
        for number in range(1, len(kiosk.questionnaire.items) + 1):
            if number > 1:
                kiosk.to_next_deadline()
                await settle(pilot, lambda: kiosk.session.current_attempt == 1)
            item = kiosk.session.current_item
            await pilot.press("1")
            await settle(pilot, lambda: item.id in kiosk.session.answers)
        await until_drawn(pilot, "C'était la dernière")
        assert not _gap_problems(kiosk.app.screen), _gap_problems(kiosk.app.screen)


async def test_any_number_starts_and_a_capital_c_takes_the_answer_back(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await until_drawn(pilot, "Start")
        await pilot.press("5")  # "press any number" under the explanation
        await settle(pilot, lambda: kiosk.session.phase is Phase.QUESTIONS)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.press("7")  # no such answer: a gentle word, nothing stored
        await until_drawn(pilot, "Please choose 1, 2 or 3.")
        await pilot.press("2")
        await until_drawn(pilot, "C  Change my answer")
        await pilot.press("C")
        await settle(pilot, lambda: "feeding" not in kiosk.session.answers and kiosk.session.current_attempt == 1)
        assert [e.kind for e in kiosk.store.session(kiosk.session.id).log].count("answer_withdrawn") == 1


async def test_the_practice_introduction_promises_hearing_only_with_a_voice(ui_kiosk):
    silent = ui_kiosk()  # no speaker
    async with silent.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(silent) == "WelcomeScreen")
        await pilot.press("1")
        shown = await until_drawn(pilot, "First, a few practice questions")
        assert "hear" not in shown.split("Practice 1 of")[1].split("P  Pause")[0]
    speaking = ui_kiosk(session_id="5e55a0000002")
    async with speaking.app.run_test(size=KIOSK_SIZE) as pilot:
        deliver_from_thread(speaking, ChannelStatus(Channel.VOICE, ChannelState.ON, "espeak-ng"))
        await settle(pilot, lambda: screen_name(speaking) == "WelcomeScreen")
        await pilot.press("1")
        await until_drawn(pilot, "check that you hear, read and choose well")


async def test_answer_numbers_are_solid_figures(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _to_first_question(kiosk, pilot, "en")
        shown = await until_drawn(pilot, "I eat without help")
        answers = shown.split("Someone has to feed me")[0] + shown.split("I eat without help")[0]
        assert "██████" in shown and not set("╺┓┃┻━┫┏┛┗╸") & set(answers)


@pytest.mark.parametrize("size", [KIOSK_SIZE, (80, 24), (64, 18)], ids=lambda s: f"{s[0]}x{s[1]}")
async def test_language_buttons_are_equal_with_their_labels_lined_up(ui_kiosk, size):
    kiosk = ui_kiosk()
    async with kiosk.app.run_test(size=size) as pilot:
        await until_drawn(pilot, "English", "Español", "Français")
        buttons = list(kiosk.app.screen.query("#languages Button").results(Button))
        assert len({(b.region.width, b.region.height) for b in buttons}) == 1
        # the label on the middle row; four languages on the shortest panel get two rows each (no
        # middle row: the label sits on the first of every button alike), never one
        assert buttons[0].region.height % 2 == 1 or (size[1] < 20 and buttons[0].region.height == 2)
        shown = drawn_text(kiosk.app).splitlines()
        columns = {
            line.index(name[0]) - 3 for line in shown for name in ("English", "Español", "Français") if name in line
        }
        assert len(columns) == 1, "the numbers do not line up"


async def test_the_doctor_called_screen_counts_no_attempt_and_the_next_attempt_is_asked(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _to_first_question(kiosk, pilot, "en")
        await pilot.press("d")
        shown = await until_drawn(pilot, "The doctor has been called")
        assert "Attempt" not in shown and "Question 1 of 10" in shown
        await pilot.press("1")  # "I'm fine, carry on"
        await until_drawn(pilot, "Attempt 1 of 2")
        seen = len(kiosk.controller.events)
        kiosk.to_next_deadline()
        await until_drawn(pilot, "Attempt 2 of 2", "Someone has to feed me")
        asked = [e for e in kiosk.controller.events[seen:] if isinstance(e, Prompt) and e.kind == "question"]
        assert asked and asked[0].key == "feeding" and asked[0].repeat  # asked again, as attempt 2


async def test_a_touched_answer_shows_no_focus_strip(ui_kiosk):
    """A touch chooses without focusing: the focus outline drew a light strip over the chosen
    answer's dark left edge."""
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await _to_first_question(kiosk, pilot, "en")
        await pilot.click("#answer-2")
        await until_drawn(pilot, "C  Change my answer")
        chosen = kiosk.app.screen.query_one("#answer-2", AnswerButton)
        assert chosen.has_class("-chosen") and kiosk.app.focused is not chosen
        assert chosen.styles.outline_left[0] in ("", "none")  # no outline over the edge

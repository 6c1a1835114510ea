"""What the session decides for the UI: the number of attempts, answer numbers on the welcome and
explanation screens, voice-in availability, and the latest prompt in the snapshot."""

from __future__ import annotations

from kiosk.channels import Channel, ChannelInput, Command
from kiosk.session import (
    ATTEMPTS,
    AttemptOpened,
    AttemptTimedOut,
    IgnoreReason,
    InputIgnored,
    LanguageChanged,
    Phase,
    Prompt,
    QuestionNotAnswered,
)

from .helpers import QUESTIONNAIRE, make_rig, started


def test_an_unanswered_question_is_asked_attempts_times_then_given_up():
    rig = started()
    window = rig.session.timing.attempt_window_s
    rig.run_until(25 + ATTEMPTS * window)
    feeding = [e for e in rig.of(AttemptOpened) if e.item_id == "feeding"]
    assert [e.attempt for e in feeding] == list(range(1, ATTEMPTS + 1))
    assert [e.attempt for e in rig.of(AttemptTimedOut)] == list(range(1, ATTEMPTS + 1))
    assert [(q.item_id, q.t) for q in rig.of(QuestionNotAnswered)] == [("feeding", 25 + ATTEMPTS * window)]
    # every attempt after the first asks the question again
    asked = [p for p in rig.of(Prompt) if p.key == "feeding"]
    assert [(p.attempt, p.repeat) for p in asked] == [(n, n > 1) for n in range(1, ATTEMPTS + 1)]


def _published(rig) -> list[tuple]:
    """Everything a rig's session published, comparable across sessions."""
    return [(type(e).__name__, vars(e)) for e in rig.events]


def test_a_number_on_the_welcome_screen_is_that_languages_start_button():
    by_hand = make_rig()
    by_hand.at(10)
    by_hand.session.choose_language("es")
    by_hand.session.start()
    by_number = make_rig()
    by_number.at(10)
    by_number.session.handle(ChannelInput(Channel.REMOTE, option=2))
    assert by_number.session.language == "es" and by_number.session.phase is Phase.EXPLANATION
    # the very same events and QoS batch as choosing the language and starting
    assert _published(by_number) == _published(by_hand)
    assert by_number.session.trace == [{"t": 10, "set": {"PersonDetected": True, "TestState": "STARTED"}}]
    assert not by_number.of(InputIgnored)


def test_a_number_beyond_the_languages_starts_in_the_language_shown():
    rig = make_rig(language="fr")
    rig.at(10)
    rig.session.handle(ChannelInput(Channel.REMOTE, option=len(QUESTIONNAIRE.languages) + 1))
    assert rig.session.language == "fr" and rig.session.phase is Phase.EXPLANATION
    assert not rig.of(LanguageChanged)
    assert rig.session.trace == [{"t": 10, "set": {"PersonDetected": True, "TestState": "STARTED"}}]


def test_a_number_under_the_explanation_acknowledges_it_unless_paused():
    rig = make_rig()
    rig.at(10)
    rig.session.start()
    rig.command(Command.PAUSE)
    rig.answer(3, Channel.KEYBOARD)
    assert rig.session.phase is Phase.EXPLANATION
    assert [e.reason for e in rig.of(InputIgnored)] == [IgnoreReason.PAUSED]
    rig.command(Command.PAUSE)  # resumes
    rig.answer(3, Channel.KEYBOARD)
    assert rig.session.phase is Phase.QUESTIONS
    rig.run_until(25)  # the first question opens after the usual gap; the "3" answered nothing
    assert rig.session.current_attempt == 1 and not rig.session.answers

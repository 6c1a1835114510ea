"""What the session decides for the UI: the number of attempts, answer numbers on the welcome and
explanation screens, voice-in availability, and the latest prompt in the snapshot."""

from __future__ import annotations

from kiosk.core.adaptation import Adaptation, load_policy
from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import (
    ATTEMPTS,
    AdaptationChanged,
    AttemptOpened,
    AttemptTimedOut,
    IgnoreReason,
    InputIgnored,
    LanguageChanged,
    Phase,
    Prompt,
    QuestionNotAnswered,
)
from kiosk.store.database import Store

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


def _late_touch_answers(rig, count: int) -> None:
    """Touch answers given only on attempt 2: VoiceInteractionQuality sinks with each."""
    for _ in range(count):
        rig.run_until(rig.session.now() + 15)  # the gap; attempt 1 opens
        rig.run_until(rig.session.now() + 30)  # attempt 1 runs out
        rig.at(rig.session.now() + 3)
        rig.answer(1, Channel.TOUCH)


def _voice_messages(rig) -> list[str]:
    return [p.key for p in rig.of(Prompt) if p.key in ("voice_off", "voice_on")]


def test_without_voice_in_the_voice_off_adaptation_neither_switches_on_nor_is_announced(tmp_path):
    store = Store.open(tmp_path)
    rig = started(adaptation=Adaptation(load_policy()), store=store)
    rig.session.set_voice_available(False)
    _late_touch_answers(rig, 6)
    rule = next(r for r in rig.session.adaptation.policy.rules if r.name == "voice_off")
    assert rig.session.metrics[rule.metric] < rule.below  # the evidence that would switch it on is there
    assert "voice_off" not in rig.session.snapshot().adaptations
    assert not [e for e in rig.of(AdaptationChanged) if e.name == "voice_off"]
    assert _voice_messages(rig) == []
    assert [a.name for a in store.session(rig.session.id).adaptations if a.name == "voice_off"] == []


def test_the_same_patient_with_voice_in_gets_voice_off_and_the_qos_trace_is_the_same():
    without = started(adaptation=Adaptation(load_policy()))
    without.session.set_voice_available(False)
    _late_touch_answers(without, 6)
    with_voice = started(adaptation=Adaptation(load_policy()))
    _late_touch_answers(with_voice, 6)  # available is the default
    assert "voice_off" in with_voice.session.snapshot().adaptations
    assert _voice_messages(with_voice) == ["voice_off"]
    assert with_voice.session.trace == without.session.trace  # availability never reaches the QoS engine


def test_voice_in_lost_while_voice_off_is_in_force_lifts_it_silently_and_truthfully(tmp_path):
    store = Store.open(tmp_path)
    rig = started(adaptation=Adaptation(load_policy()), store=store)
    _late_touch_answers(rig, 6)
    assert "voice_off" in rig.session.snapshot().adaptations
    rig.session.set_voice_available(False)  # the microphone was unplugged
    change = rig.of(AdaptationChanged)[-1]
    assert (change.name, change.active, change.reason) == ("voice_off", False, "voice in is unavailable")
    assert _voice_messages(rig) == ["voice_off"]  # no "I can hear you again"
    stored = store.session(rig.session.id)
    assert [(a.name, a.active, a.reason) for a in stored.adaptations if a.name == "voice_off"][-1] == (
        "voice_off",
        False,
        "voice in is unavailable",
    )
    assert [e.detail for e in stored.log if e.kind == "voice_in"] == ["unavailable"]
    # voice in back: voice_off needs fresh low readings after answers to come back
    rig.session.set_voice_available(True)
    assert "voice_off" not in rig.session.snapshot().adaptations
    _late_touch_answers(rig, 1)
    assert "voice_off" not in rig.session.snapshot().adaptations


def test_the_snapshot_carries_the_latest_prompt():
    rig = make_rig()
    assert rig.session.snapshot().prompt is None
    rig.at(10)
    rig.session.handle(ChannelInput(Channel.TOUCH, option=3))  # starts in French
    explanation = rig.session.snapshot().prompt
    assert (explanation.kind, explanation.key, explanation.language) == ("message", "explanation", "fr")
    assert explanation.text == QUESTIONNAIRE.message("explanation", "fr")
    rig.answer(1)
    rig.run_until(25)
    assert rig.session.snapshot().prompt == rig.of(Prompt)[-1]
    assert (rig.session.snapshot().prompt.key, rig.session.snapshot().prompt.attempt) == ("feeding", 1)
    rig.command(Command.PAUSE)
    assert rig.session.snapshot().prompt.key == "paused"
    rig.command(Command.PAUSE)  # resumes: the question is asked again
    prompt = rig.session.snapshot().prompt
    assert (prompt.kind, prompt.key, prompt.repeat) == ("question", "feeding", True)
    assert prompt is rig.of(Prompt)[-1]

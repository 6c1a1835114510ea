"""What the session decides for the UI: the number of attempts, answer numbers on the welcome and
explanation screens, voice-in availability, and the latest prompt in the snapshot."""

from __future__ import annotations

from kiosk.session import ATTEMPTS, AttemptOpened, AttemptTimedOut, Prompt, QuestionNotAnswered

from .helpers import started


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

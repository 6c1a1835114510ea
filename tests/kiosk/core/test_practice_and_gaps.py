"""Familiarisation without voice out (the hearing check is skipped), practice outcomes stored for
the clinician and never sent to QoS, and what the screen shows during every gap between questions.
Real session, real QoS engine, real SQLite store, simulated clock."""

from __future__ import annotations

from kiosk.core.channels import Channel
from kiosk.core.session import (
    AttemptOpened,
    Phase,
    PracticeAnswered,
    PracticeSkipped,
    Prompt,
    Session,
)
from kiosk.store.database import Store
from qos import Engine

from .helpers import MODEL, QUESTIONNAIRE, TIMING, make_rig, started


def _practice(store: Store, session_id: str) -> list[tuple]:
    return [
        (p.question_id, p.checks, p.outcome, p.option, p.channel, p.detail) for p in store.session(session_id).practice
    ]


def test_without_voice_out_the_hearing_check_is_skipped_logged_and_stored(tmp_path):
    store = Store.open(tmp_path)
    rig = make_rig(familiarisation=True, store=store)
    rig.session.set_voice_out_available(False)  # before start: e.g. espeak-ng is missing
    rig.at(5)
    rig.session.start()
    snap = rig.session.snapshot()
    assert snap.phase is Phase.FAMILIARISATION
    assert snap.practice.id == "practice_read" and (snap.practice_number, snap.practice_count) == (1, 2)
    assert [(e.question_id, e.checks, e.reason) for e in rig.of(PracticeSkipped)] == [
        ("practice_hear", "hear", "no voice out")
    ]
    assert "practice_hear" not in {p.key for p in rig.of(Prompt)}  # never shown nor spoken
    assert [e.item_id for e in rig.of(AttemptOpened)] == ["practice_read"]
    rig.at(7)
    rig.answer(1, Channel.TOUCH)
    rig.run_until(7 + TIMING["between_questions_s"])  # "Well done." first
    snap = rig.session.snapshot()
    assert snap.practice.id == "practice_select" and (snap.practice_number, snap.practice_count) == (2, 2)
    rig.at(30)
    rig.answer(3, Channel.REMOTE)  # "choose answer number 3"
    rig.run_until(30 + TIMING["between_questions_s"])
    assert rig.session.phase is Phase.EXPLANATION
    assert _practice(store, rig.session.id) == [
        ("practice_hear", "hear", "skipped", None, None, "no voice out"),
        ("practice_read", "read", "right", 1, Channel.TOUCH, ""),
        ("practice_select", "select", "right", 3, Channel.REMOTE, ""),
    ]
    log = [(e.kind, e.detail) for e in store.session(rig.session.id).log]
    assert ("practice_skipped", "practice_hear: no voice out") in log
    assert rig.session.trace == [{"t": 5, "set": {"PersonDetected": True, "TestState": "STARTED"}}]


def test_with_voice_out_every_practice_outcome_is_stored(tmp_path):
    store = Store.open(tmp_path)
    rig = make_rig(familiarisation=True, store=store)
    rig.at(5)
    rig.session.start()
    snap = rig.session.snapshot()
    assert snap.practice.id == "practice_hear" and (snap.practice_number, snap.practice_count) == (1, 3)
    rig.at(6)
    rig.answer(1, Channel.VOICE)  # "chair": the patient did not hear "apple"
    rig.run_until(6 + TIMING["between_questions_s"])  # a kind word first
    assert (rig.session.snapshot().practice_number, rig.session.snapshot().practice_count) == (2, 3)
    # the reading check gets no answer at all
    rig.run_until(6 + TIMING["between_questions_s"] + 2 * TIMING["attempt_window_s"])
    assert (rig.session.snapshot().practice.id, rig.session.snapshot().practice_number) == ("practice_select", 3)
    rig.at(rig.session.now() + 3)
    rig.answer(2, Channel.TOUCH)  # touched "green", not answer number 3
    rig.run_until(rig.session.now() + TIMING["between_questions_s"])
    assert rig.session.phase is Phase.EXPLANATION
    assert [(p.question_id, p.option, p.correct) for p in rig.of(PracticeAnswered)] == [
        ("practice_hear", 1, False),
        ("practice_read", None, False),
        ("practice_select", 2, False),
    ]
    assert _practice(store, rig.session.id) == [
        ("practice_hear", "hear", "wrong", 1, Channel.VOICE, ""),
        ("practice_read", "read", "not_answered", None, None, ""),
        ("practice_select", "select", "wrong", 2, Channel.TOUCH, ""),
    ]
    assert not rig.of(PracticeSkipped)


def test_voice_out_lost_during_the_hearing_check_skips_it_and_its_return_does_not_ask_it_again(tmp_path):
    store = Store.open(tmp_path)
    rig = make_rig(familiarisation=True, store=store)
    rig.at(5)
    rig.session.start()
    assert rig.session.snapshot().practice.id == "practice_hear"
    rig.at(8)
    rig.session.set_voice_out_available(False)  # espeak-ng failed while saying the word
    snap = rig.session.snapshot()
    assert snap.practice.id == "practice_read" and snap.attempt == 1
    assert (snap.practice_number, snap.practice_count) == (2, 3)  # the hearing check was shown
    assert rig.session.remaining() == TIMING["attempt_window_s"]
    rig.session.set_voice_out_available(True)
    assert rig.session.snapshot().practice.id == "practice_read"
    rig.answer(1)
    rig.run_until(rig.session.now() + TIMING["between_questions_s"])
    assert rig.session.snapshot().practice.id == "practice_select"
    assert [p[2] for p in _practice(store, rig.session.id)] == ["skipped", "right"]
    log = [(e.kind, e.detail) for e in store.session(rig.session.id).log]
    assert [d for k, d in log if k == "voice_out"] == ["unavailable", "available"]
    assert [e.question_id for e in rig.of(PracticeSkipped)] == ["practice_hear"]


def test_practice_with_or_without_voice_out_leaves_the_qos_trace_unchanged():
    def run(voice_out: bool) -> Session:
        rig = make_rig(familiarisation=True)
        rig.session.set_voice_out_available(voice_out)
        rig.at(5)
        rig.session.start()
        while rig.session.phase is Phase.FAMILIARISATION:
            rig.answer(rig.session.snapshot().practice.expected)
            rig.run_until(rig.session.now() + TIMING["between_questions_s"])  # the kind word
        rig.at(100)  # the same moment in both runs, however long the practice took
        rig.session.acknowledge()
        for _ in QUESTIONNAIRE.items:
            rig.run_until(rig.session.clock.now() + TIMING["between_questions_s"])
            rig.at(rig.session.now() + 4)
            rig.answer(1, Channel.REMOTE)
        rig.run_until(rig.session.now() + TIMING["closing_s"])
        assert rig.session.finished
        return rig.session

    with_voice, without = run(True), run(False)
    assert with_voice.trace == without.trace
    assert with_voice.metrics == without.metrics


def test_every_gap_between_questions_says_what_to_show_meanwhile():
    rig = started()  # acknowledged at 10; feeding opens at 25
    snap = rig.session.snapshot()
    assert (snap.phase, snap.item, snap.interlude) == (Phase.QUESTIONS, None, "first_question")
    rig.run_until(25)
    assert rig.session.snapshot().interlude is None and rig.session.current_attempt == 1
    rig.at(27)
    rig.answer(2)
    snap = rig.session.snapshot()
    assert (snap.item.id, snap.answers["feeding"].option, snap.interlude) == ("feeding", 2, "next_question")
    rig.session.pause()  # the gap freezes, and still knows what it is waiting for
    assert rig.session.snapshot().interlude == "next_question"
    rig.session.resume()
    rig.run_until(42)
    assert rig.session.snapshot().interlude is None and rig.session.current_item.id == "bathing"
    rig.run_until(42 + 2 * TIMING["attempt_window_s"])  # bathing is not answered
    snap = rig.session.snapshot()
    assert (snap.item.id, snap.interlude) == ("bathing", "not_answered")
    while not rig.session.finished:
        rig.run_until(rig.session.now() + TIMING["between_questions_s"])
        rig.answer(1)
        if rig.session.current_item.id == QUESTIONNAIRE.items[-1].id:
            assert rig.session.snapshot().interlude == "last_question"
            rig.run_until(rig.session.now() + TIMING["closing_s"])
    assert rig.session.snapshot().interlude is None


def test_a_continued_session_waits_for_its_next_question_not_its_first(tmp_path):
    store = Store.open(tmp_path)
    first = started(store=store)
    first.run_until(25)
    first.answer(3)
    stored = store.session(first.session.id)  # the kiosk stopped here
    again = Session.from_stored(
        QUESTIONNAIRE, stored, clock=first.clock, engine=Engine(MODEL), store=store, timing=TIMING
    )
    again.start()
    again.acknowledge()
    assert again.snapshot().interlude == "next_question"

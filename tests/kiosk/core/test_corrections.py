"""No silent wrong answers: an unsure answer is asked back before it is stored, and the last answer
can be taken back during its thank-you gap. Real session, real QoS engine, real SQLite store, on
a simulated clock (feeding opens at t=25 with the test-bench timing)."""

from __future__ import annotations

import json

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.clock import SimClock
from kiosk.core.session import (
    AnswerNotConfirmed,
    AnswerRecorded,
    AnswerWithdrawn,
    AttemptOpened,
    ConfirmationAsked,
    IgnoreReason,
    InputIgnored,
    ListeningChanged,
    Prompt,
    QuestionNotAnswered,
    Session,
)
from kiosk.store.database import Store
from qos import Engine

from .helpers import MODEL, QUESTIONNAIRE, TIMING, Rig, started


def unsure(option: int, said: str = "independent") -> ChannelInput:
    """A voice answer the recogniser was not sure of."""
    return ChannelInput(Channel.VOICE, option=option, detail=said, confidence=0.55, needs_confirmation=True)


def stored_rig(tmp_path, **kwargs) -> tuple[Rig, Store]:
    store = Store.open(tmp_path / "data")
    rig = started(store=store, **kwargs)
    rig.run_until(25)
    return rig, store


def contexts_after(rig: Rig, t: float) -> list[dict]:
    return [e for e in rig.session.trace if e["t"] >= t]


def test_an_unsure_voice_answer_is_not_stored_but_asked_back_with_yes_and_no(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.at(30)
    rig.session.handle(unsure(3))
    assert not rig.of(AnswerRecorded) and "feeding" not in rig.session.answers
    assert store.session(rig.session.id).answers == ()
    asked = rig.of(ConfirmationAsked)[-1]
    assert (asked.item_id, asked.option, asked.attempt, asked.channel) == ("feeding", 3, 1, Channel.VOICE)
    prompt = rig.of(Prompt)[-1]
    assert prompt.kind == "confirm" and prompt.key == "feeding" and prompt.attempt == 1
    assert prompt.text == "I heard: Independent. Is that right?" == prompt.spoken
    assert [(o.number, o.label) for o in prompt.options] == [(1, "Yes"), (2, "No")]
    assert "that's right" in prompt.options[0].synonyms and "that's wrong" in prompt.options[1].synonyms
    snap = rig.session.snapshot()
    assert snap.confirming == 3 and snap.attempt == 1 and rig.session.listening
    assert contexts_after(rig, 26) == []  # nothing reaches the QoS engine until it is confirmed
    rig.session.handle(ChannelInput(Channel.KEYBOARD, option=4))  # no option 4 on Yes/No
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.NO_SUCH_OPTION
    assert rig.session.snapshot().confirming == 3


def test_yes_stores_the_answer_on_the_attempt_it_was_given_in(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.run_until(25 + TIMING["attempt_window_s"])  # attempt 1 timed out
    rig.at(60)
    rig.session.handle(unsure(2, "with help"))
    rig.at(64)
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="screen"))
    recorded = rig.of(AnswerRecorded)[-1]
    assert (recorded.item_id, recorded.option, recorded.attempt, recorded.channel) == ("feeding", 2, 2, Channel.VOICE)
    stored = store.session(rig.session.id)
    assert [(a.item_id, a.option, a.attempt, a.channel) for a in stored.answers] == [("feeding", 2, 2, Channel.VOICE)]
    # the answer counts on the attempt it was confirmed in, with the channel that gave it
    assert contexts_after(rig, 60) == [
        {"t": 64, "set": {"SecondAttemptAnswered": True, "UserInteraction": "VOICE_RECOGNITION"}}
    ]
    assert ("answer_confirmed", "feeding option 2 by touch 'screen'") in [(e.kind, e.detail) for e in stored.log]
    assert rig.session.snapshot().can_undo


def test_no_asks_the_question_again_in_the_same_attempt(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.at(53)  # 2 s left of attempt 1
    rig.session.handle(unsure(1, "unable"))
    rig.at(58)  # the confirmation stops the attempt clock: attempt 1 did not time out
    assert rig.session.current_attempt == 1
    rig.session.handle(ChannelInput(Channel.VOICE, option=2, detail="no that's wrong"))
    assert rig.of(AnswerNotConfirmed)[-1].why == "declined"
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.key, prompt.attempt, prompt.repeat) == ("question", "feeding", 1, True)
    assert rig.session.remaining() == TIMING["resume_grace_s"]  # at least the grace to answer again
    assert rig.session.listening
    rig.at(63)
    rig.answer(3)
    assert [(a.option, a.attempt, a.channel) for a in store.session(rig.session.id).answers] == [(3, 1, Channel.TOUCH)]
    assert contexts_after(rig, 26) == [
        {"t": 63, "set": {"FirstAttemptAnswered": True, "UserInteraction": "TOUCH_SCREEN"}}
    ]


def test_a_confirmation_without_reply_never_stores_the_answer(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.at(30)
    rig.session.handle(unsure(3))
    rig.run_until(30 + QUESTIONNAIRE.timing.confirm_window_s)
    assert rig.of(AnswerNotConfirmed)[-1].why == "timed_out"
    assert store.session(rig.session.id).answers == () and not rig.session.answers
    # the attempt ends as if it had timed out, and attempt 2 opens
    assert contexts_after(rig, 26) == [{"t": 40, "set": {"FirstAttemptAnswered": False}}]
    assert rig.of(AttemptOpened)[-1].attempt == 2 and rig.session.snapshot().confirming is None
    rig.session.handle(unsure(3))
    rig.run_until(rig.session.now() + QUESTIONNAIRE.timing.confirm_window_s)
    assert [e.item_id for e in rig.of(QuestionNotAnswered)] == ["feeding"]
    assert store.session(rig.session.id).not_answered == ("feeding",)


def test_an_unsure_yes_does_not_confirm_an_unsure_answer(tmp_path):
    """An unsure "yes" (the voice channel's, spoken in a room nearly as loud as the patient) is
    asked again with the plea to press Yes or No, and the whole window again to do it."""
    rig, store = stored_rig(tmp_path)
    rig.at(30)
    rig.session.handle(unsure(3))
    rig.at(38)
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="yes", confidence=0.9, needs_confirmation=True))
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.UNSURE_REPLY
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.repeat) == ("confirm", True)
    assert (
        prompt.text
        == ("I could not hear you clearly. I heard: Independent. Is that right? Please press Yes or No.")
        == prompt.spoken
    )
    assert rig.session.snapshot().confirming == 3
    assert store.session(rig.session.id).answers == ()
    # the 10 s window would have ended at 40: pressing takes longer than saying yes
    rig.run_until(38 + QUESTIONNAIRE.timing.confirm_window_s - 0.5)
    assert not rig.of(AnswerNotConfirmed) and rig.session.snapshot().confirming == 3
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="touch"))
    (answer,) = store.session(rig.session.id).answers
    assert (answer.option, answer.channel, answer.attempt) == (3, Channel.VOICE, 1)


def test_the_plea_to_press_is_in_the_patients_language_and_a_spoken_no_still_declines(tmp_path):
    rig, store = stored_rig(tmp_path, language="fr")
    rig.at(30)
    rig.session.handle(unsure(3, "autonome"))
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="oui", confidence=0.9, needs_confirmation=True))
    assert rig.of(Prompt)[-1].text == (
        "Je ne vous ai pas bien entendu. J'ai compris : Autonome. Est-ce bien cela ? "
        "Appuyez sur Oui ou Non, s'il vous plaît."
    )
    rig.session.handle(ChannelInput(Channel.VOICE, option=2, detail="non", confidence=0.9, needs_confirmation=True))
    assert rig.of(AnswerNotConfirmed)[-1].why == "declined"
    assert rig.session.snapshot().confirming is None and store.session(rig.session.id).answers == ()
    # heard again, it is asked back in the usual words: the plea was for that one reply
    rig.session.handle(unsure(3, "autonome"))
    assert rig.of(Prompt)[-1].text == "J'ai compris : Autonome. Est-ce bien cela ?"


def test_the_question_back_is_in_the_patients_language_and_survives_pause_and_language_change(tmp_path):
    rig, _ = stored_rig(tmp_path, language="es")
    rig.at(30)
    rig.session.handle(unsure(3, "independiente"))
    prompt = rig.of(Prompt)[-1]
    assert prompt.text == "He entendido: Independiente. ¿Es correcto?"
    assert [o.label for o in prompt.options] == ["Sí", "No"] and "es correcto" in prompt.options[0].synonyms
    rig.session.pause()
    assert not rig.session.listening
    rig.at(100)  # the confirmation's clock is stopped too
    rig.session.resume()
    again = rig.of(Prompt)[-1]
    assert (again.kind, again.repeat, again.language) == ("confirm", True, "es")
    rig.session.choose_language("fr")
    assert rig.of(Prompt)[-1].text == "J'ai compris : Autonome. Est-ce bien cela ?"
    assert [o.label for o in rig.of(Prompt)[-1].options] == ["Oui", "Non"]
    rig.session.handle(ChannelInput(Channel.REMOTE, option=1, detail="BTN 1"))
    assert rig.session.answers["feeding"].option == 3


def test_undo_takes_back_the_last_answer_whatever_channel_gave_it(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.at(30)
    rig.answer(1, Channel.REMOTE)
    assert rig.session.snapshot().can_undo
    assert [a.option for a in store.session(rig.session.id).answers] == [1]  # committed when given
    rig.at(33)
    rig.session.handle(ChannelInput(Channel.VOICE, command=Command.UNDO, detail="no that's wrong"))
    withdrawn = rig.of(AnswerWithdrawn)[-1]
    assert (withdrawn.item_id, withdrawn.option, withdrawn.channel, withdrawn.by) == (
        "feeding",
        1,
        Channel.REMOTE,
        Channel.VOICE,
    )
    stored = store.session(rig.session.id)
    assert stored.answers == () and "feeding" not in rig.session.answers
    [entry] = [e for e in stored.log if e.kind == "answer_withdrawn"]
    detail = json.loads(entry.detail)
    assert detail["item"] == "feeding" and detail["withdrawn"]["option"] == 1
    assert detail["withdrawn"]["channel"] == "remote" and "voice" in detail["reason"]
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.key, prompt.repeat) == ("question", "feeding", True)
    assert rig.session.current_attempt == 1 and rig.session.remaining() == TIMING["attempt_window_s"]
    assert not rig.session.snapshot().can_undo
    rig.at(40)
    rig.answer(3, Channel.TOUCH)
    assert [(a.option, a.attempt) for a in store.session(rig.session.id).answers] == [(3, 1)]
    assert rig.session.score().total == 10
    # the withdrawn answer's contexts stay; the undo is a question asked again; the corrected
    # answer adds only its channel (attempt contexts are once per question)
    assert contexts_after(rig, 26) == [
        {"t": 30, "set": {"FirstAttemptAnswered": True, "UserInteraction": "REMOTE_CONTROL"}},
        {"t": 33, "set": {"TestState": "REPEATING"}},
        {"t": 40, "set": {"TestState": "STARTED", "UserInteraction": "TOUCH_SCREEN"}},
    ]


def test_undo_works_only_while_an_answer_can_still_be_changed(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.session.handle(ChannelInput(Channel.KEYBOARD, command=Command.UNDO, detail="key c"))
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.NOTHING_TO_UNDO  # nothing answered yet
    rig.at(30)
    rig.answer(2)
    rig.session.pause()
    rig.command(Command.UNDO)
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.PAUSED
    assert not rig.session.snapshot().can_undo
    rig.session.resume()
    rig.run_until(30 + TIMING["between_questions_s"])  # the gap is over: bathing is open
    rig.command(Command.UNDO)
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.NOTHING_TO_UNDO
    assert rig.session.answers["feeding"].option == 2
    rig.session.handle(unsure(1, "dependent"))
    rig.command(Command.UNDO)  # while asked back, undo is "No"
    assert rig.of(AnswerNotConfirmed)[-1].why == "undone"
    assert [a.item_id for a in store.session(rig.session.id).answers] == ["feeding"]


def test_a_correction_not_given_in_time_leaves_the_question_unanswered(tmp_path):
    rig, store = stored_rig(tmp_path)
    rig.at(30)
    rig.answer(2)
    rig.at(31)
    rig.command(Command.UNDO)
    rig.run_until(31 + TIMING["attempt_window_s"])
    assert [e.item_id for e in rig.of(QuestionNotAnswered)] == ["feeding"]
    stored = store.session(rig.session.id)
    assert stored.answers == () and stored.not_answered == ("feeding",)
    assert all("FirstAttemptAnswered" not in e.get("set", {}) for e in contexts_after(rig, 31))
    assert rig.of(AttemptOpened)[-1].item_id == "feeding"  # no second attempt after a correction


def test_the_last_answer_can_be_changed_before_the_summary_and_a_restart_asks_it_again(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = started(store=store)
    for _ in QUESTIONNAIRE.items:
        rig.run_until(rig.session.next_deadline() - rig.session._origin)  # open the next item
        rig.answer(1)
    assert rig.session.snapshot().interlude == "last_question" and rig.session.snapshot().can_undo
    rig.command(Command.UNDO)
    assert rig.of(AnswerWithdrawn)[-1].item_id == "stairs" and not rig.session.finished
    # the kiosk stops here: the withdrawn answer is not in the store, so stairs is asked again
    stored = store.session(rig.session.id)
    assert "stairs" not in {a.item_id for a in stored.answers}
    again = Session.from_stored(
        QUESTIONNAIRE, stored, clock=SimClock(), engine=Engine(MODEL), store=store, timing=TIMING
    )
    again.start()
    again.acknowledge()
    again.clock.advance(TIMING["between_questions_s"])
    again.poll()
    assert again.current_item.id == "stairs"


def test_listening_stays_on_while_the_answer_is_asked_back():
    rig = started()
    rig.run_until(25)
    rig.at(30)
    rig.session.handle(unsure(3))
    rig.at(32)
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="yes"))
    # on under the explanation ("I'm ready") until acknowledged at 10, then from Q1 at 25 through
    # "Is that right?", and after Yes at 32 through the thank-you gap ("No, that's wrong")
    assert [(e.t, e.listening) for e in rig.of(ListeningChanged)] == [(10, True), (10, False), (25, True)]
    assert rig.session.listening and rig.session.snapshot().can_undo

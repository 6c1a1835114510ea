"""The session state machine on a simulated clock, with the real QoS engine."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import (
    AnswerRecorded,
    AttemptOpened,
    AttemptTimedOut,
    DoctorCalled,
    DoctorContinued,
    Finished,
    IgnoreReason,
    InputIgnored,
    ListeningChanged,
    MetricsUpdated,
    Paused,
    Phase,
    PhaseChanged,
    PracticeAnswered,
    Prompt,
    QuestionNotAnswered,
    Resumed,
    VolumeChanged,
)
from kiosk.store.database import Store

from .helpers import QUESTIONNAIRE, TIMING, make_rig, started


def test_plain_flow_asks_every_item_in_order_and_scores_the_answers():
    rig = started()
    rig.run_until(25)
    for k, item in enumerate(QUESTIONNAIRE.items):
        opened = rig.of(AttemptOpened)[-1]
        assert (opened.item_id, opened.attempt) == (item.id, 1)
        assert rig.session.snapshot().number == k + 1
        rig.at(opened.t + 3)
        rig.answer(len(item.options), Channel.REMOTE)
        rig.run_until(rig.session.now() + 15)
    rig.run_until(rig.session.now() + 5)
    assert rig.session.phase is Phase.SUMMARY
    (finished,) = rig.of(Finished)
    assert finished.score.total == 100 and finished.score.complete and finished.score.band.id == "independent"
    assert [p.phase for p in rig.of(PhaseChanged)] == [Phase.EXPLANATION, Phase.QUESTIONS, Phase.SUMMARY]


def test_the_first_answer_of_an_attempt_wins_and_a_simultaneous_one_is_ignored():
    rig = started()
    rig.at(30)
    rig.answer(1, Channel.REMOTE)
    rig.answer(3, Channel.TOUCH)  # same instant, another channel
    (answer,) = rig.of(AnswerRecorded)
    assert (answer.option, answer.channel) == (1, Channel.REMOTE)
    (ignored,) = rig.of(InputIgnored)
    assert ignored.reason is IgnoreReason.ALREADY_ANSWERED and ignored.input.channel is Channel.TOUCH
    assert rig.session.answers["feeding"].option == 1
    # exactly one QoS batch for that instant, with the winning channel
    assert [e for e in rig.session.trace if e["t"] == 30] == [
        {"t": 30, "set": {"FirstAttemptAnswered": True, "UserInteraction": "REMOTE_CONTROL"}}
    ]


def test_an_answer_exactly_at_the_deadline_is_accepted_one_later_goes_to_attempt_two():
    rig = started()
    rig.at(55)  # attempt 1 opened at 25 with a 30 s window: 55 is its last instant
    rig.answer(2)
    assert rig.of(AnswerRecorded)[0].attempt == 1
    assert not rig.of(AttemptTimedOut)

    rig = started()
    rig.at(55.5)
    assert [(e.attempt, e.t) for e in rig.of(AttemptTimedOut)] == [(1, 55)]
    rig.answer(2)
    assert rig.of(AnswerRecorded)[0].attempt == 2
    assert rig.session.trace[1:] == [
        {"t": 55, "set": {"FirstAttemptAnswered": False}},
        {"t": 55.5, "set": {"SecondAttemptAnswered": True, "UserInteraction": "TOUCH_SCREEN"}},
    ]


def test_two_time_outs_make_the_question_not_answered_and_the_next_opens_after_the_gap():
    rig = started()
    rig.run_until(85)
    assert [(e.attempt, e.t) for e in rig.of(AttemptTimedOut)] == [(1, 55), (2, 85)]
    (qna,) = rig.of(QuestionNotAnswered)
    assert (qna.item_id, qna.t) == ("feeding", 85)
    rig.run_until(100)
    assert [(e.item_id, e.attempt, e.t) for e in rig.of(AttemptOpened)][-1] == ("bathing", 1, 100)
    # attempt 2 repeats the prompt
    prompts = [p for p in rig.of(Prompt) if p.kind == "question"]
    assert [(p.key, p.repeat) for p in prompts] == [("feeding", False), ("feeding", True), ("bathing", False)]


def test_a_late_poll_fires_time_outs_at_their_due_time():
    rig = started()
    rig.clock.set(rig.session._origin + 200)  # the UI's timer was starved
    rig.session.poll()
    assert [e.t for e in rig.of(AttemptTimedOut)][:2] == [55, 85]
    assert [e["t"] for e in rig.session.trace[1:4]] == [55, 85, 130]


def test_pause_freezes_the_attempt_clock_and_resume_leaves_the_grace_period():
    rig = started()
    rig.at(30)
    rig.session.pause(Channel.TOUCH)
    assert rig.session.paused and rig.session.next_deadline() is None
    assert rig.of(Paused)[-1].channel is Channel.TOUCH
    rig.at(500)
    assert not rig.of(AttemptTimedOut)
    assert rig.session.remaining() == 25
    rig.answer(1)
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.PAUSED
    rig.session.resume()
    assert rig.of(Resumed)[-1].deadline == 525  # 25 s were left, more than the 10 s grace
    rig.run_until(525)
    assert rig.of(AttemptTimedOut)[-1].t == 525
    assert [e["set"]["TestState"] for e in rig.session.trace if "TestState" in e.get("set", {})] == [
        "STARTED",
        "PAUSED",
        "RESTARTED",
    ]


def test_pause_at_the_deadline_comes_before_the_time_out_and_resume_gives_the_grace():
    rig = started()
    rig.at(55)
    rig.command(Command.PAUSE)
    rig.at(75)
    rig.command(Command.PAUSE)  # the remote's single pause button toggles
    assert not rig.session.paused
    assert rig.of(Resumed)[-1].deadline == 85
    rig.at(85)
    rig.answer(1)
    assert rig.of(AnswerRecorded)[-1].attempt == 1


def test_call_doctor_halts_until_a_clinician_continues():
    rig = started()
    rig.at(40)
    rig.command(Command.CALL_DOCTOR, Channel.REMOTE)
    assert rig.session.halted and rig.of(DoctorCalled)[-1].channel is Channel.REMOTE
    rig.at(1000)
    rig.answer(2)
    rig.session.resume()
    rig.command(Command.CALL_DOCTOR)
    reasons = [e.reason for e in rig.of(InputIgnored)]
    assert reasons == [IgnoreReason.DOCTOR_CALLED, IgnoreReason.NOT_PAUSED, IgnoreReason.ALREADY_CALLED]
    assert not rig.of(AnswerRecorded) and not rig.of(AttemptTimedOut)
    rig.session.clinician_continue()
    assert rig.of(DoctorContinued)[-1].deadline == 1015  # 15 s were left
    assert rig.session.trace[1:] == [
        {"t": 40, "emit": ["CallingDoctor"]},
        {"t": 1000, "set": {"TestState": "RESTARTED"}},
    ]


def test_clinician_continue_after_doctor_called_at_the_deadline_leaves_the_grace():
    rig = started()
    rig.at(55)
    rig.session.call_doctor()
    rig.at(75)
    rig.session.clinician_continue()
    rig.run_until(85)
    assert [(e.attempt, e.t) for e in rig.of(AttemptTimedOut)] == [(1, 85)]


def test_person_lost_freezes_and_person_back_leaves_at_least_five_seconds():
    rig = started()
    rig.at(53)
    rig.session.person_lost()
    assert not rig.session.listening
    rig.at(300)
    rig.session.person_back()
    assert rig.session.remaining() == 5  # 2 s were left; the grace is 5 s
    rig.run_until(305)
    assert rig.of(AttemptTimedOut)[-1].t == 305
    assert rig.session.trace[1:3] == [
        {"t": 53, "set": {"PersonDetected": False}},
        {"t": 300, "set": {"PersonDetected": True}},
    ]


def test_repeat_publishes_repeating_and_started_once_the_prompt_is_delivered():
    rig = started()
    rig.at(50)
    rig.command(Command.REPEAT, Channel.VOICE)
    prompt = rig.of(Prompt)[-1]
    assert (prompt.key, prompt.repeat) == ("feeding", True)
    assert rig.session.remaining() == 10  # hearing it again leaves at least the grace period
    rig.at(52)
    rig.session.prompt_delivered()
    assert rig.session.trace[1:] == [
        {"t": 50, "set": {"TestState": "REPEATING"}},
        {"t": 52, "set": {"TestState": "STARTED"}},
    ]


def test_without_a_delivery_report_started_rides_with_the_next_batch():
    rig = started()
    rig.at(50)
    rig.session.repeat()
    rig.at(54)
    rig.answer(3, Channel.VOICE)
    assert rig.session.trace[-1] == {
        "t": 54,
        "set": {"TestState": "STARTED", "FirstAttemptAnswered": True, "UserInteraction": "VOICE_RECOGNITION"},
    }


def test_keyboard_answers_count_as_the_touch_panel():
    rig = started()
    rig.at(30)
    rig.answer(1, Channel.KEYBOARD)
    assert rig.session.trace[-1]["set"]["UserInteraction"] == "TOUCH_SCREEN"
    assert rig.of(AnswerRecorded)[-1].channel is Channel.KEYBOARD


def test_every_qos_batch_goes_through_the_real_engine():
    rig = started()
    rig.at(30)
    rig.answer(3, Channel.VOICE)
    updates = rig.of(MetricsUpdated)
    assert [u.t for u in updates] == [10, 30]
    assert updates[0].fired == ("O2", "O8")
    assert updates[1].fired == ("O2", "O7", "O13")
    assert updates[1].metrics["VoiceInteractionQuality"] > 0.5 == QUESTIONNAIRE.timing.attempt_window_s / 40
    assert rig.session.metrics == updates[1].metrics


def test_prompts_carry_the_options_with_their_voice_synonyms_in_the_language():
    rig = started(language="es")
    rig.run_until(25)
    prompt = [p for p in rig.of(Prompt) if p.kind == "question"][0]
    assert prompt.language == "es" and prompt.text.startswith("Comida")
    assert [o.number for o in prompt.options] == [1, 2, 3]
    assert "independiente" in prompt.options[2].synonyms and prompt.options[2].points == 10
    rig.session.choose_language("fr")
    again = rig.of(Prompt)[-1]
    assert again.language == "fr" and again.key == "feeding" and again.options[2].label == "Autonome"
    rig.session.choose_language("pt")
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.UNKNOWN_LANGUAGE


def test_listening_follows_open_attempts_and_freezes():
    rig = started()
    rig.at(30)
    rig.session.pause()
    rig.at(40)
    rig.session.resume()
    rig.answer(1)
    # the explanation at 10 listens for "I'm ready" until acknowledged at once; the answer at 40
    # leaves it on through the thank-you gap, in which "No, that's wrong" takes it back
    assert [(e.t, e.listening) for e in rig.of(ListeningChanged)] == [
        (10, True),
        (10, False),
        (25, True),
        (30, False),
        (40, True),
    ]


def test_the_thank_you_gap_listens_until_the_next_question_or_the_end():
    rig = started()
    for number in range(1, len(QUESTIONNAIRE.items) + 1):
        rig.run_until(rig.session.next_deadline())
        assert rig.session.current_attempt == 1 and rig.session.listening
        rig.answer(1)
        assert rig.session.listening, f"the gap after question {number} listens for 'No, that's wrong'"
    rig.run_until(rig.session.next_deadline())  # the closing gap ends: the summary hears nothing
    assert rig.session.phase is Phase.SUMMARY and not rig.session.listening
    assert rig.of(ListeningChanged)[-1].listening is False


def test_familiarisation_answers_are_checked_but_never_sent_to_qos():
    rig = make_rig(familiarisation=True)
    rig.at(5)
    rig.session.start()
    assert rig.session.phase is Phase.FAMILIARISATION
    assert rig.session.snapshot().practice.id == "practice_hear"
    rig.at(8)
    rig.answer(2, Channel.VOICE)
    rig.run_until(8 + TIMING["between_questions_s"])  # each practice answer gets a kind word first
    rig.at(24)
    rig.answer(2, Channel.TOUCH)  # the reading check expects "yes", option 1
    rig.run_until(24 + TIMING["between_questions_s"])
    assert rig.session.snapshot().practice.id == "practice_select"
    rig.at(40)
    rig.answer(3, Channel.REMOTE)  # "choose answer number 3"
    rig.run_until(40 + TIMING["between_questions_s"])
    assert [(p.question_id, p.correct) for p in rig.of(PracticeAnswered)] == [
        ("practice_hear", True),
        ("practice_read", False),
        ("practice_select", True),
    ]
    assert rig.session.phase is Phase.EXPLANATION
    assert rig.session.trace == [{"t": 5, "set": {"PersonDetected": True, "TestState": "STARTED"}}]
    assert not rig.session.answers


def test_inputs_outside_an_open_attempt_are_ignored_with_a_reason():
    rig = make_rig()
    rig.session.pause()  # on the welcome screen (a number there starts: see test_session_ui_inputs)
    rig.at(10)
    rig.session.start()
    rig.session.acknowledge()
    rig.answer(5)  # feeding opens at 25; before that nothing is open
    rig.run_until(25)
    rig.answer(4)  # feeding has 3 options
    assert [e.reason for e in rig.of(InputIgnored)] == [
        IgnoreReason.NOT_STARTED,
        IgnoreReason.NO_OPEN_ATTEMPT,
        IgnoreReason.NO_SUCH_OPTION,
    ]


def test_volume_commands_become_events():
    rig = started()
    rig.command(Command.VOLUME_UP, Channel.REMOTE)
    rig.command(Command.VOLUME_DOWN, Channel.REMOTE)
    assert [e.step for e in rig.of(VolumeChanged)] == [1, -1]


def test_listeners_may_call_back_into_the_session_and_still_see_events_in_order():
    rig = make_rig()
    seen: list[str] = []

    def on_event(event):
        seen.append(type(event).__name__)
        if isinstance(event, PhaseChanged) and event.phase is Phase.EXPLANATION:
            rig.session.acknowledge()

    rig.session.subscribe(on_event)
    rig.at(10)
    rig.session.start()
    # the nested acknowledge's events come after those of start, not in the middle of them
    assert seen[:5] == ["PhaseChanged", "Prompt", "ListeningChanged", "MetricsUpdated", "PhaseChanged"]
    assert rig.session.phase is Phase.QUESTIONS


def test_a_session_needs_a_known_language_and_a_patient_id():
    with pytest.raises(ValueError, match="language 'pt'"):
        make_rig(language="pt")
    with pytest.raises(ValueError, match="pseudonymous"):
        from kiosk.core.clock import SimClock
        from kiosk.core.session import Session

        Session(QUESTIONNAIRE, clock=SimClock(), engine=None, patient_id="")


def test_without_an_engine_the_trace_is_still_kept():
    rig = started(engine=False)
    rig.at(30)
    rig.answer(1)
    assert not rig.of(MetricsUpdated)
    assert rig.session.trace[-1]["set"]["FirstAttemptAnswered"] is True


def test_channel_input_contract_is_respected():
    with pytest.raises(ValueError):
        ChannelInput(Channel.TOUCH)


def test_two_operations_at_one_instant_are_recorded_as_the_engine_saw_them():
    from qos import Engine, Trace, TraceEvent

    from .helpers import MODEL

    rig = started()
    rig.at(40)
    rig.session.pause()
    rig.session.resume()  # same tick: the first batch already went to the engine
    rig.session.person_lost()
    assert [e["t"] for e in rig.session.trace[-3:]] == [40, 40.001, 40.002]
    # a replay of the recorded trace gives every live update exactly
    live = [(u.t, dict(u.metrics), u.fired) for u in rig.of(MetricsUpdated)]
    trace = Trace("clarc", [TraceEvent(e["t"], e.get("set", {}), e.get("emit", [])) for e in rig.session.trace])
    engine = Engine(MODEL)
    replayed = [(t, engine.update(t, set=v, emit=em)) for t, v, em in trace.batches()]
    assert [(t, r.metrics, tuple(r.fired)) for t, r in replayed] == live


def test_abandon_marks_a_started_unfinished_session_and_logs_why(tmp_path):
    store = Store.open(tmp_path)
    rig = started(store=store)
    rig.at(30)
    rig.answer(1)
    assert rig.session.abandon()
    stored = store.session(rig.session.id)
    assert stored.status == "abandoned" and len(stored.answers) == 1  # the answer stays
    assert [(e.kind, e.detail) for e in stored.log][-1] == ("abandoned", "a new session was started")
    assert store.unfinished_sessions() == []
    store.close()


def test_abandon_leaves_a_session_on_the_welcome_screen_or_finished_as_it_is(tmp_path):
    store = Store.open(tmp_path)
    waiting = make_rig(store=store)
    assert not waiting.session.abandon()
    assert store.sessions() == []  # never started, so never stored
    rig = started(store=store)
    for _ in QUESTIONNAIRE.items:
        rig.run_until(rig.session.next_deadline() - rig.session._origin)  # open the next item
        rig.answer(1)
    rig.run_until(rig.session.now() + 20)
    assert rig.session.finished
    assert not rig.session.abandon()
    stored = store.session(rig.session.id)
    assert stored.status == "finished" and "abandoned" not in [e.kind for e in stored.log]
    store.close()

"""Time passes for the QoS engine inside a session: a model's timers fire at their own time on the
session's clock, through ``poll()``, while the patient does nothing; what they publish is handled
as an update's results (metrics, MetricsUpdated, adaptation, the store); and the session's trace
replays to exactly the metrics the session saw."""

from __future__ import annotations

from kiosk.core.adaptation import Adaptation, load_policy
from kiosk.core.clock import SimClock
from kiosk.core.qos_model import load_kiosk_model
from kiosk.core.session import SAME_INSTANT_STEP_S, AdaptationChanged, MetricsUpdated, Session
from kiosk.store.database import Store
from qos import Engine
from tests.kiosk.core.helpers import QUESTIONNAIRE, TIMING, Rig, started

PACE = load_kiosk_model("kiosk_pace")
#: the inactivity timer of kiosk_pace: started when a question is asked, stopped by an answer
SILENCE_S = PACE.timers["Silence"].interval

#: slow speech as soon as Interaction falls below 0.3 once (the bundled policy waits for two)
POLICY = """\
rules:
  - {name: slow_speech, metric: Interaction, below: 0.3, count: 1, count_on: updates, recover_above: 0.5,
     speech_rate: 0.85}
"""


def pace_rig(**kwargs) -> Rig:
    clock = SimClock()
    session = Session(
        QUESTIONNAIRE,
        clock=clock,
        engine=Engine(PACE),
        patient_id="T-PACE1",
        timing=TIMING,
        familiarisation=False,
        **kwargs,
    )
    rig = Rig(session, clock)
    session.subscribe(rig.events.append)
    return rig


def asked_first_question(rig: Rig) -> float:
    """Start, acknowledge, and let time run until the first question is asked; its session time."""
    rig.at(10)
    rig.session.start()
    rig.session.acknowledge()
    while not any("QuestionAsked" in event.get("emit", ()) for event in rig.session.trace):
        rig.clock.set(rig.session.next_deadline())
        rig.session.poll()
    return rig.session.trace[-1]["t"]


def replayed(trace: list[dict]) -> list[tuple[float, dict, tuple]]:
    """What a fresh engine does with the trace: every batch, its own timer batches included."""
    engine = Engine(PACE)
    results: list = []
    engine.subscribe(results.append)
    for event in trace:
        engine.update(event["t"], set=event.get("set", {}), emit=event.get("emit", []))
    return [(r.t, r.metrics, tuple(r.fired)) for r in results]


def test_the_inactivity_timer_fires_through_poll_while_nothing_happens(tmp_path):
    policy = tmp_path / "policy.yaml"
    policy.write_text(POLICY)
    store = Store.open(tmp_path / "data")
    rig = pace_rig(store=store, adaptation=Adaptation(load_policy(policy, model=PACE)))
    asked = asked_first_question(rig)
    rig.at(asked + 5)
    rig.session.person_lost()  # the attempt clock stops: only the model's timer is left running
    due = asked + SILENCE_S
    assert rig.session.next_deadline() == rig.session._origin + due  # clock time of `due`
    published, metrics_before = len(rig.session.trace), len(rig.of(MetricsUpdated))

    rig.clock.set(rig.session.next_deadline())
    rig.session.poll()  # no input at all: only time passing

    (silence,) = rig.of(MetricsUpdated)[metrics_before:]
    assert (silence.t, silence.timers, silence.fired, dict(silence.set), silence.emit) == (
        due,
        ("Silence",),
        ("Silent",),
        {},
        (),
    )
    assert silence.metrics["Interaction"] < rig.of(MetricsUpdated)[metrics_before - 1].metrics["Interaction"]
    assert rig.session.metrics == dict(silence.metrics)
    assert len(rig.session.trace) == published, "a timer is the model's own: nothing is added to the trace"
    # the adaptation policy hears of it like of any update
    (change,) = rig.of(AdaptationChanged)
    assert (change.t, change.name, change.active) == (due, "slow_speech", True)
    stored = store.session(rig.session.id)
    assert [(m.t, m.fired) for m in stored.metrics][-1] == (due, ("Silent",))
    assert [(a.t, a.name) for a in stored.adaptations] == [(due, "slow_speech")]
    assert ("qos_timers", "Silence") in [(entry.kind, entry.detail) for entry in stored.log]

    # the patient is back at that very instant: recorded just after the timer's batch, so that a
    # replay does not merge the two
    rig.session.person_back()
    assert rig.session.trace[-1] == {"t": round(due + SAME_INSTANT_STEP_S, 6), "set": {"PersonDetected": True}}
    rig.at(due + 3)
    rig.answer(1)
    seen = [(m.t, dict(m.metrics), m.fired) for m in rig.of(MetricsUpdated)]
    assert replayed(rig.session.trace) == seen
    assert [(m.t, dict(m.metrics), m.fired) for m in store.session(rig.session.id).metrics] == seen
    store.close()


def test_an_answer_stops_the_timer_and_nothing_fires_later():
    rig = pace_rig()
    asked = asked_first_question(rig)
    rig.at(asked + 4)
    rig.answer(2)
    rig.run_until(asked + 3 * SILENCE_S)  # the next questions go unanswered: both attempts time out
    asks = [e["t"] for e in rig.session.trace if "QuestionAsked" in e.get("emit", ())]
    timer_batches = [m.t for m in rig.of(MetricsUpdated) if m.timers]
    assert asked + SILENCE_S not in timer_batches, "the answer stopped the first question's silence"
    assert timer_batches and all(t - SILENCE_S in asks for t in timer_batches)
    assert replayed(rig.session.trace) == [(m.t, dict(m.metrics), m.fired) for m in rig.of(MetricsUpdated)]


def test_clarc_sessions_wait_for_their_own_time_outs_only():
    """CLARC has no timers: the engine never wakes the session, and no QuestionAsked is published."""
    rig = started()
    rig.session.person_lost()
    assert rig.session.next_deadline() is None
    assert not any(m.timers for m in rig.of(MetricsUpdated))
    assert all("QuestionAsked" not in e.get("emit", ()) for e in rig.session.trace)


def test_a_continued_session_does_not_run_the_models_timers_again(tmp_path):
    """The kiosk stops after the timer fired, with no context since: the continued session's engine
    is brought to the stored metrics' time, so Silent is stored once and the trace still replays."""
    store = Store.open(tmp_path / "data")
    rig = pace_rig(store=store)
    asked = asked_first_question(rig)
    rig.at(asked + 5)
    rig.session.person_lost()
    rig.clock.set(rig.session.next_deadline())
    rig.session.poll()
    stored = store.session(rig.session.id)
    assert stored.metrics[-1].fired == ("Silent",) and stored.trace[-1]["t"] < stored.metrics[-1].t

    again = Session.from_stored(
        QUESTIONNAIRE, stored, clock=SimClock(), engine=Engine(PACE), store=store, timing=TIMING
    )
    again.clock.advance(2 * SILENCE_S)  # the continued session waits on the welcome screen a while
    again.poll()
    again.start()
    again.acknowledge()
    again.clock.advance(TIMING["between_questions_s"])
    again.poll()
    assert again.current_item.id == QUESTIONNAIRE.items[0].id
    metrics = store.session(again.id).metrics
    assert [m.fired for m in metrics].count(("Silent",)) == 1
    assert replayed(again.trace) == [(m.t, dict(m.metrics), m.fired) for m in metrics]
    store.close()


def test_time_stops_passing_for_the_model_once_the_test_is_over():
    rig = pace_rig()
    asked_first_question(rig)
    for _ in QUESTIONNAIRE.items:
        while rig.session.current_attempt is None:
            rig.clock.set(rig.session.next_deadline())
            rig.session.poll()
        rig.answer(1)
    rig.run_until(rig.session.now() + 60)
    assert rig.session.finished
    assert rig.session.next_deadline() is None  # nothing wakes a finished kiosk for the model's sake
    count = len(rig.of(MetricsUpdated))
    rig.clock.advance(24 * 3600)
    rig.session.poll()
    assert len(rig.of(MetricsUpdated)) == count

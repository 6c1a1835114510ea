"""The engine API and the reasoner's maths (reference doc §4)."""

from __future__ import annotations

import math
import random

import pytest

from qos import ContextError, Engine, load_model, parse_model
from qos.reasoner import PropertyBelief

CLARC = load_model("clarc")


def naive_metric(prior: float, survival: float, firings: list[tuple[float, float]], t: float) -> float:
    """The paper's formula as printed: prior odds times the product of p_t/q_t."""
    odds = prior / (1 - prior)
    for fired_at, lr in firings:
        p, q = 1 / (1 + lr), lr / (1 + lr)
        fade = math.exp(-2 * (1 / survival) * (t - fired_at))
        odds *= (0.5 + (p - 0.5) * fade) / (0.5 + (q - 0.5) * fade)
    return odds / (1 + odds)


def test_model_exposes_properties_contexts_and_observations():
    assert list(CLARC.properties) == ["Performance", "Interaction", "VoiceInteractionQuality"]
    assert CLARC.properties["Performance"].survival == 6000.0
    assert CLARC.contexts["TestState"].literals == ("IDLE", "STARTED", "PAUSED", "RESTARTED", "REPEATING", "FINISHED")
    assert CLARC.contexts["CallingDoctor"].kind == "eventtype"
    assert list(CLARC.observations) == [f"O{n}" for n in range(1, 15)]
    assert CLARC.observations["O9"].likelihood_ratio == pytest.approx(10.0)


def test_update_returns_metrics_and_fired_observations_in_number_order():
    engine = Engine(CLARC)
    first = engine.update(10, set={"PersonDetected": True})
    assert first.t == 10 and first.fired == ["O2", "O8"]
    assert first.metrics["Performance"] == pytest.approx(1 / (1 + 0.7))
    assert first.metrics["VoiceInteractionQuality"] == 0.5
    result = engine.update(20, set={"SecondAttemptAnswered": False}, emit=["CallingDoctor"])
    assert result.fired == ["O5", "O9", "O10"]


def test_metrics_decay_towards_the_reference_with_time():
    engine = Engine(CLARC)
    engine.update(0, set={"FirstAttemptAnswered": True})
    at = [engine.metrics(t)["Performance"] for t in (0, 600, 6000, 60000, 600000)]
    assert at == sorted(at, reverse=True)
    assert at[2] == pytest.approx(naive_metric(0.5, 6000, [(0, 0.7)], 6000))
    assert at[-1] == pytest.approx(0.5, abs=1e-12)


def test_reasoner_matches_the_papers_product_formula_over_a_long_random_run():
    rng = random.Random(7)
    prop = parse_model("roqme M\nproperty P reference 0.3 survival 10min\n").properties["P"]
    belief, firings, t = PropertyBelief(prop), [], 0.0
    for _ in range(3000):
        t += rng.expovariate(1 / 20)
        lr = rng.choice([0.1, 0.3, 0.5, 0.7, 0.9, 1 / 0.1, 1 / 0.3, 1 / 0.7])
        belief.add(t, lr)
        firings.append((t, lr))
        if rng.random() < 0.1:
            check = t + rng.uniform(0, 300)
            assert belief.metric(check) == pytest.approx(naive_metric(0.3, 600, firings, check), rel=1e-9, abs=1e-12)
    # folding keeps only the last few minutes of firings on their own
    assert belief.live_firings < 60


def test_long_runs_keep_a_bounded_state():
    engine = Engine(CLARC)
    for minute in range(10 * 60):
        engine.update(minute * 60, set={"FirstAttemptAnswered": minute % 3 != 0}, emit=["CallingDoctor"])
    assert max(engine.live_firings.values()) < 60


def test_reference_is_clamped_and_no_survival_means_no_decay():
    model = parse_model(
        "roqme M\nproperty Hi reference 1\nproperty Lo reference 0\ncontext B : boolean\n"
        "observation O1 : B undermines Hi veryhigh\nobservation O2 : B reinforces Lo veryhigh\n"
    )
    engine = Engine(model)
    assert engine.metrics(0) == {"Hi": 0.99, "Lo": 0.01}
    after = engine.update(0, set={"B": True}).metrics
    assert after["Hi"] == pytest.approx(0.99 * 0.1 / (0.99 * 0.1 + 0.01 * 1))  # odds 99 × LR 0.1
    assert engine.metrics(10**9) == after


BAD_BATCHES = [
    (dict(set={"Nope": True}), "context 'Nope' is not in model CLARC"),
    (dict(set={"PersonDetected": "yes"}), "context PersonDetected is boolean, got 'yes' (str)"),
    (dict(set={"PersonDetected": 1}), "context PersonDetected is boolean, got 1 (int)"),
    (
        dict(set={"TestState": "STOPPED"}),
        "context TestState has no literal 'STOPPED' (expected one of IDLE, STARTED, PAUSED, RESTARTED, REPEATING, FINISHED)",
    ),
    (
        dict(set={"TestState": "UserInteraction::PAUSED"}),
        "context TestState is of type TestState, got 'UserInteraction::PAUSED'",
    ),
    (
        dict(set={"TestState": 3}),
        "context TestState is an enum of IDLE, STARTED, PAUSED, RESTARTED, REPEATING, FINISHED; got 3 (int)",
    ),
    (dict(set={"CallingDoctor": True}), "context CallingDoctor is an eventtype: emit it, do not set it"),
    (dict(emit=["PersonDetected"]), "context PersonDetected is boolean, not an eventtype: set it, do not emit it"),
    (dict(emit="CallingDoctor"), "'emit' must be a list of eventtype names, not 'CallingDoctor' (str)"),
    (
        dict(set=[("PersonDetected", True)]),
        "'set' must map context names to values, not [('PersonDetected', True)] (list)",
    ),
]


@pytest.mark.parametrize(("batch", "message"), BAD_BATCHES)
def test_a_bad_batch_is_rejected_whole_and_changes_nothing(batch, message):
    engine = Engine(CLARC)
    engine.update(5, set={"PersonDetected": True})
    before = (engine.t, engine.contexts, engine.metrics(5))
    seen = []
    engine.subscribe(seen.append)
    # the valid part of the batch is not applied either
    with pytest.raises(ContextError) as caught:
        engine.update(
            6,
            set={"FirstAttemptAnswered": True, **batch.get("set", {})}
            if isinstance(batch.get("set", {}), dict)
            else batch["set"],
            emit=batch.get("emit"),
        )
    assert str(caught.value) == message
    assert isinstance(caught.value, ValueError)
    assert (engine.t, engine.contexts, engine.metrics(5)) == before and seen == []
    assert engine.update(6, set={"FirstAttemptAnswered": True}).fired == ["O2", "O7"]


def test_time_must_not_go_backwards_nor_be_a_non_number():
    engine = Engine(CLARC)
    engine.update(10, set={"PersonDetected": True})
    with pytest.raises(ContextError, match=r"^time 9 s is before the previous update at 10 s$"):
        engine.update(9, set={"PersonDetected": True})
    with pytest.raises(ContextError, match=r"^time 5 s is before the last update at 10 s$"):
        engine.metrics(5)
    with pytest.raises(ContextError, match=r"^time must be a finite number of seconds, not nan \(float\)$"):
        engine.update(float("nan"))
    with pytest.raises(ContextError, match=r"^time must be a finite number of seconds, not '11' \(str\)$"):
        engine.update("11")
    assert engine.t == 10


def test_subscribers_get_every_result_until_they_unsubscribe():
    engine = Engine(CLARC)
    seen = []
    unsubscribe = engine.subscribe(seen.append)
    result = engine.update(1, set={"UserInteraction": "VOICE_RECOGNITION"})
    unsubscribe()
    engine.update(2, set={"UserInteraction": "TOUCH_SCREEN"})
    unsubscribe()  # twice is harmless
    assert seen == [result] and result.fired == ["O13"] and result.set == {"UserInteraction": "VOICE_RECOGNITION"}


def test_engines_of_one_model_are_independent():
    first, second = Engine(CLARC), Engine(CLARC)
    first.update(1, set={"PersonDetected": False})
    assert second.update(1, set={"PersonDetected": False}).fired == ["O6", "O11"]


def _clarc_batches():
    from hypothesis import strategies as st

    values = {
        name: (st.booleans() if context.kind == "boolean" else st.sampled_from(context.literals))
        for name, context in CLARC.contexts.items()
        if context.kind != "eventtype"
    }
    batch = st.tuples(
        st.floats(0, 60), st.dictionaries(st.sampled_from(sorted(values)), st.none(), max_size=4), st.booleans()
    )
    return st.lists(batch, max_size=25).flatmap(
        lambda batches: st.tuples(
            *[st.fixed_dictionaries({name: values[name] for name in chosen}) for _, chosen, _ in batches]
        ).map(lambda sets: [(gap, chosen, doctor) for (gap, _, doctor), chosen in zip(batches, sets)])
    )


def test_any_valid_session_keeps_metrics_in_range_and_replays_identically():
    from hypothesis import given, settings

    from qos import TraceRecorder, replay

    @settings(max_examples=60, deadline=None)
    @given(_clarc_batches())
    def check(batches):
        engine = Engine(CLARC)
        recorder = TraceRecorder(engine, "clarc")
        t, fired = 0.0, []
        for gap, values, doctor in batches:
            t += gap
            result = engine.update(t, set=values, emit=["CallingDoctor"] if doctor else [])
            assert all(0.0 <= value <= 1.0 for value in result.metrics.values())
            assert result.fired == sorted(result.fired, key=lambda name: int(name[1:]))
            if result.fired:
                fired.append(result.fired)
        if recorder.events and len({event.t for event in recorder.events}) == len(recorder.events):
            assert [entry["observations"] for entry in replay(recorder.trace)["fired"]] == fired

    check()

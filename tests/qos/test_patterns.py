"""Pattern semantics, operator by operator (as documented in qos.patterns)."""

from __future__ import annotations

import pytest

from qos import Engine, parse_model

HEAD = (
    "roqme M\nproperty P\ncontext B : boolean\ncontext C : boolean\ncontext N : number\n"
    "context E : eventtype\ncontext S : enum {ON, OFF, IDLE}\n"
)


def fires(pattern: str, batches: list[dict]) -> list[int]:
    """Indexes of the batches in which `observation O : pattern` fires (emit via the key 'emit')."""
    engine = Engine(parse_model(HEAD + f"observation O : {pattern} reinforces P high\n", "m.roqme"))
    fired = []
    for index, batch in enumerate(batches):
        batch = dict(batch)
        emit = batch.pop("emit", [])
        if engine.update(index, set=batch, emit=emit).fired:
            fired.append(index)
    return fired


def test_update_of_a_variable_fires_on_every_update_even_unchanged():
    assert fires("update(N)", [{"N": 1}, {"N": 1}, {"B": True}, {"N": 2}]) == [0, 1, 3]


def test_update_of_an_expression_fires_only_when_its_value_changes():
    assert fires("update(N > 2)", [{"N": 1}, {"N": 2}, {"N": 3}, {"N": 5}, {"N": 0}]) == [0, 2, 4]


def test_event_when_of_a_variable_fires_on_every_update_to_true():
    assert fires("eventWhen(B)", [{"B": True}, {"B": True}, {"B": False}, {"C": True}, {"B": True}]) == [0, 1, 4]


def test_event_when_of_an_expression_fires_when_it_becomes_true():
    batches = [{"S": "ON"}, {"S": "ON"}, {"S": "OFF"}, {"S": "ON"}]
    assert fires("eventWhen(S = S::ON)", batches) == [0, 3]


def test_bare_variables_and_expressions_as_patterns():
    assert fires("B", [{"B": True}, {"B": True}, {"B": False}]) == [0, 1]
    assert fires("S", [{"S": "ON"}, {"S": "ON"}, {"N": 1}]) == [0, 1]
    assert fires("E", [{"emit": ["E"]}, {"B": True}, {"emit": ["E"]}]) == [0, 2]
    assert fires("!B", [{"B": True}, {"B": False}, {"B": False}, {"B": True}, {"B": False}]) == [1, 4]


def test_updated_to_false_idiom_fires_on_every_update_to_false():
    batches = [{"B": False}, {"B": False}, {"B": True}, {"B": False}]
    assert fires("update(B) while(!B)", batches) == [0, 1, 3]


def test_undefined_contexts_make_expressions_neither_true_nor_changing():
    # C never set: B & C is undefined, so it never becomes true; B | C is true as soon as B is
    assert fires("eventWhen(B & C)", [{"B": True}, {"B": True}]) == []
    assert fires("eventWhen(B | C)", [{"B": True}, {"B": True}]) == [0]
    assert fires("eventWhen(N / 0 > 1)", [{"N": 3}, {"N": 4}]) == []


def test_arithmetic_and_comparisons():
    batches = [{"N": 1}, {"N": 4}, {"N": 2.5}, {"N": -3}]
    assert fires("eventWhen(N * 2 - 1 >= 4)", batches) == [1]  # still true at 2.5: no change
    assert fires("update(N) while(N * 2 - 1 >= 4)", batches) == [1, 2]
    assert fires("eventWhen(-N = 3)", batches) == [3]
    assert fires("eventWhen(N != 4 & N < 2)", batches) == [0, 3]


def test_or_fires_once_per_batch_when_either_occurs():
    batches = [{"B": True}, {"C": True}, {"B": True, "C": True}, {"N": 1}]
    assert fires("B or C", batches) == [0, 1, 2]


def test_and_needs_both_in_any_order_then_rearms():
    batches = [{"B": True}, {"B": True}, {"C": True}, {"C": True}, {"B": True, "C": True}]
    assert fires("B and C", batches) == [2, 4]


def test_followed_by_needs_the_second_in_a_later_batch():
    assert fires("B -> C", [{"B": True, "C": True}, {"N": 1}, {"C": True}, {"C": True}]) == [2]
    assert fires("B -> C", [{"C": True}, {"B": True}, {"B": True}, {"C": True}]) == [3]


def test_while_guard_filters_and_clears_progress():
    assert fires("update(N) while(B)", [{"N": 1}, {"B": True}, {"N": 2}, {"B": False, "N": 3}]) == [2]
    # the guard fails in batch 2, so the B seen in batch 1 no longer counts
    batches = [{"C": True}, {"B": True}, {"C": False}, {"C": True}, {"emit": ["E"]}, {"B": True}, {"emit": ["E"]}]
    assert fires("(B -> E) while(C)", batches) == [6]


def test_repeat_counts_batches_and_restarts():
    batches = [{"B": True}, {"B": True}, {"B": True}, {"B": True}, {"B": True}, {"B": True}]
    assert fires("B repeat(3)", batches) == [2, 5]
    # several occurrences in one batch count once
    assert fires("(B or C) repeat(2)", [{"B": True, "C": True}, {"C": True}]) == [1]


def test_once_fires_a_single_time_for_the_life_of_the_engine():
    assert fires("once B", [{"B": True}, {"B": True}, {"B": True}]) == [0]
    assert fires("once (B repeat(2))", [{"B": True}] * 5) == [1]


def test_precedence_postfix_binds_tighter_than_or_and_followed_by_loosest():
    # `update(B) while(!B) or C` is `(update(B) while(!B)) or C`
    assert fires("update(B) while(!B) or C", [{"B": False}, {"C": True}, {"B": True}]) == [0, 1]
    # `B -> C or E` is `B -> (C or E)`
    assert fires("B -> C or E", [{"B": True}, {"emit": ["E"]}]) == [1]


def test_an_observation_fires_at_most_once_per_batch_and_each_call_is_a_batch():
    model = parse_model(HEAD + "observation O : B or update(B) or eventWhen(B = true) reinforces P high\n")
    engine = Engine(model)
    assert engine.update(0, set={"B": True}).fired == ["O"]
    assert engine.update(0, set={"B": True}).fired == ["O"]  # same time, new call: a new batch


def test_enum_literals_of_named_types():
    model = parse_model(
        "roqme M\nproperty P\ntype Level : enum {LOW, HIGH}\ncontext L : Level\n"
        "observation O : eventWhen(L = Level::HIGH) reinforces P\n"
    )
    engine = Engine(model)
    assert model.contexts["L"].literals == ("LOW", "HIGH")
    assert engine.update(1, set={"L": "LOW"}).fired == []
    assert engine.update(2, set={"L": "Level::HIGH"}).fired == ["O"]


@pytest.mark.parametrize(
    ("batches", "expected"),
    [
        ([{"FirstAttemptAnswered": False}, {"FirstAttemptAnswered": False}], [["O6", "O11"], ["O6", "O11"]]),
        (
            [{"PersonDetected": True}, {"PersonDetected": False}, {"PersonDetected": False}],
            [["O2", "O8"], ["O6", "O11"], []],
        ),
        (
            [{"TestState": "PAUSED"}, {"TestState": "RESTARTED"}, {"TestState": "RESTARTED"}],
            [["O4", "O11"], ["O3", "O12"], []],
        ),
    ],
)
def test_clarc_reads_updated_to_per_update_and_becomes_per_change(batches, expected):
    from qos import load_model

    engine = Engine(load_model("clarc"))
    assert [engine.update(i, set=batch).fired for i, batch in enumerate(batches)] == expected

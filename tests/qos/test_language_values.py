"""RoQME values with their run-time meaning: derived contexts, variables, parameters, data types,
arithmetic, collections, conditionals, aggregates, period and reading a belief (see qos.streams)."""

from __future__ import annotations

import pytest

from qos import ContextError, ModelError, parse_model

from .language import HEAD, engine_for, run, times


def test_a_derived_context_is_recomputed_and_updated_whenever_what_it_reads_is():
    body = "context Slow : boolean := N > 15\nobservation O : Slow reinforces P\nobservation U : update(Slow) reinforces P\n"
    fired = run(body, [(0, {"N": 20}), (1, {"N": 30}), (2, {"B": True}), (3, {"N": 5})])
    assert times(fired, "O") == [0, 1]  # every update of Slow to true (a bare boolean)
    assert times(fired, "U") == [0, 1, 3]  # not at 2: B is not read by Slow
    engine = engine_for("context Twice : number := N * 2\nobservation O : B reinforces P\n")
    engine.update(0, set={"N": 4})
    assert engine.contexts["Twice"] == 8


def test_a_derived_eventtype_occurs_with_its_pattern_and_an_enum_literal_filters_updates():
    body = (
        "context On : eventtype := S::ON\ncontext Seq : eventtype := E -> On\n"
        "observation O : On reinforces P\nobservation Q : Seq reinforces P\n"
    )
    fired = run(body, [(0, {"S": "ON"}), (1, {"S": "ON"}), (2, {"S": "OFF"}, ["E"]), (3, {"S": "ON"})])
    assert times(fired, "O") == [0, 1, 3]  # every update of S to ON, even unchanged
    assert times(fired, "Q") == [3]


def test_derived_contexts_cannot_be_set_and_must_match_their_type():
    engine = engine_for("context Slow : boolean := N > 15\nobservation O : Slow reinforces P\n")
    with pytest.raises(ContextError, match="context Slow is derived: the engine computes it"):
        engine.update(0, set={"Slow": True})
    with pytest.raises(ModelError, match=r"m\.roqme:8:24: the definition of X is number, not boolean"):
        parse_model(HEAD + "context X : boolean := N + 1\n", "m.roqme")
    with pytest.raises(ModelError, match="a pattern defines an eventtype context; X is boolean"):
        parse_model(HEAD + "context X : boolean := B -> C\n", "m.roqme")


def test_a_var_is_set_by_actions_after_the_batch_and_read_in_conditions():
    body = (
        "var answers : number := 0\nobservation Count : B { sets answers := answers + 1 }\n"
        "observation O : update(B) while(answers >= 2) reinforces P\n"
    )
    fired = run(body, [(t, {"B": True}) for t in range(4)])
    # the third update sees the two counted before it; the count of a batch lands after it
    assert times(fired, "O") == [2, 3]
    with pytest.raises(ModelError, match="sets L, which is a parameter, a constant: only a var can be set"):
        parse_model(HEAD + "param L : number default 1\nobservation O : B sets L := 2\n", "m.roqme")


def test_a_var_defined_by_an_expression_follows_what_it_reads_without_occurring():
    engine = engine_for("var doubled : number := N * 2\nobservation O : B reinforces P\n")
    engine.update(0, set={"N": 3})
    assert engine.variables == {"doubled": 6}
    with pytest.raises(ModelError, match="a number value cannot stand as a pattern"):
        parse_model(HEAD + "var v : number := N * 2\nobservation O : v reinforces P\n", "m.roqme")


def test_a_parameter_has_its_default_or_the_callers_value():
    body = "param Limit : number lower 0 default 15\nobservation O : eventWhen(N > Limit) reinforces P\n"
    assert times(run(body, [(0, {"N": 10}), (1, {"N": 20})])) == [1]
    assert times(run(body, [(0, {"N": 10}), (1, {"N": 20})], params={"Limit": 5})) == [0]
    with pytest.raises(ContextError, match="-1 is below the lower bound 0"):
        engine_for(body, params={"Limit": -1})
    with pytest.raises(ModelError, match=r"m\.roqme:8:35: the default: 20 is above the upper bound 10 of L"):
        parse_model(HEAD + "param L : number upper 10 default 20\n", "m.roqme")


def test_types_with_bounds_units_and_arrays_check_what_the_kiosk_sets():
    head = (
        HEAD + 'type Seconds : number lower 0 upper 600 unit "s"\ncontext T : Seconds\ncontext L : time\n'
        "context Pair : number[2]\ncontext Modes : enum[3] {VOICE, TOUCH}\n"
    )
    model = parse_model(head + "observation O : B reinforces P\n", "m.roqme")
    assert (model.types["Seconds"].unit, model.contexts["L"].spec.unit) == ("s", "s")
    engine = engine_for("observation O : B reinforces P\n", head)
    engine.update(0, set={"T": 600, "Pair": [1, 2], "Modes": ["VOICE", "TOUCH", "VOICE"]})
    with pytest.raises(ContextError, match="context T: 601 is above the upper bound 600"):
        engine.update(1, set={"T": 601})
    with pytest.raises(ContextError, match="context Pair is an array of at most 2 values"):
        engine.update(1, set={"Pair": [1, 2, 3]})
    with pytest.raises(ContextError, match=r"context Modes\[2\] has no literal 'EYES'"):
        engine.update(1, set={"Modes": ["VOICE", "EYES"]})


def test_arithmetic_functions_and_the_conditional():
    body = (
        "observation O : eventWhen(pow(N, 2) = 9 & sqrt(N * 3) = 3 & abs(-N) = 3 & exp(0) = 1) reinforces P\n"
        "observation Q : eventWhen((N > 2 ? N : 0) + 1 = 4) reinforces P\n"
        "observation R : eventWhen(sqrt(N) > 0) reinforces P\n"
        "observation U : eventWhen(N > 2 meters & N < 1 minutes) reinforces P\n"
    )
    fired = run(body, [(0, {"N": 1}), (1, {"N": 3}), (2, {"N": -4})])
    assert times(fired, "O") == [1] and times(fired, "Q") == [1]
    assert times(fired, "U") == [1]  # a unit-measured value is its number; a time is in seconds
    assert times(fired, "R") == [0]  # sqrt(-4) is undefined: never true, never "changes"


def test_collection_functions_on_array_contexts():
    head = HEAD + "context A : number[3]\n"
    body = (
        "observation O : eventWhen(A'size = 3 & A'first = 1 & A'last = 3 & A'at(2) = 2 & A'includes(3)) "
        "reinforces P\nobservation Empty : eventWhen(isEmpty(A)) reinforces P\n"
        "observation Out : eventWhen(A'at(4) = 0 | at(A, 1.5) = 0) reinforces P\n"
    )
    fired = run(body, [(0, {"A": []}), (1, {"A": [1, 2, 3]}), (2, {"A": [3, 2]})], head=head)
    assert times(fired, "O") == [1] and times(fired, "Empty") == [0]
    assert times(fired, "Out") == []  # at counts from 1; outside the array it is undefined


def test_aggregates_over_the_last_n_updates():
    body = (
        "context Slowest : number := N'max(3)\ncontext Fastest : number := min(N, 3)\n"
        "context Mean : number := N'avg(3)\ncontext Total : number := sum(N, 3)\ncontext Seen : number := N'count(3)\n"
        "observation O : B reinforces P\n"
    )
    engine = engine_for(body)
    for t, value in enumerate([20, 18, 16, 4]):
        engine.update(t, set={"N": value})
    assert {name: engine.contexts[name] for name in ("Slowest", "Fastest", "Mean", "Total", "Seen")} == {
        "Slowest": 18,
        "Fastest": 4,
        "Mean": pytest.approx(38 / 3),
        "Total": 38,
        "Seen": 3,
    }


def test_the_last_three_answers_each_took_longer_than_15_seconds():
    body = "context SlowStreak : boolean := N'min(3) > 15 & N'count(3) = 3\nobservation O : SlowStreak reinforces P\n"
    fired = run(body, [(t, {"N": n}) for t, n in enumerate([20, 30, 16, 17, 5, 40, 41, 42])])
    assert times(fired) == [2, 3, 7]


def test_unbounded_aggregates_a_where_condition_and_count_of_an_eventtype():
    body = (
        "context All : number := N'avg\ncontext Positive : number := sum(N, 10, N > 0)\n"
        "context Events : number := E'count\nobservation O : B reinforces P\n"
    )
    engine = engine_for(body)
    for t, value in enumerate([4, -2, 10]):
        engine.update(t, set={"N": value}, emit=["E"])
    assert (engine.contexts["All"], engine.contexts["Positive"], engine.contexts["Events"]) == (4, 14, 3)


def test_trends_over_a_window():
    body = (
        "context Up : boolean := N'increasing(3)\ncontext Down : boolean := decreasing(N, 3)\n"
        "context Flat : boolean := stable(N, 3)\nobservation O : Up reinforces P\n"
    )
    engine = engine_for(body)
    engine.update(0, set={"N": 1})
    assert "Up" not in engine.contexts  # one update: no trend yet
    for t, value in enumerate([2, 3], start=1):
        engine.update(t, set={"N": value})
    assert (engine.contexts["Up"], engine.contexts["Down"], engine.contexts["Flat"]) == (True, False, False)
    engine.update(3, set={"N": 3})
    assert engine.contexts["Up"] is False


def test_a_time_window_aggregate_is_produced_at_the_end_of_each_batch_even_when_nothing_happens():
    body = (
        "context PerMinute : number := count(E, 1 minutes)\n"
        "observation Busy : update(PerMinute) while(PerMinute >= 2) reinforces P\n"
        "observation Any : update(PerMinute) reinforces P\n"
    )
    fired = run(body, [(10, {}, ["E"]), (20, {}, ["E"]), (75, {}, ["E"]), (200, {}, ["E"])], until=300)
    # batches [10, 70): 2 events, produced at 70; [70, 130): 1, at 130; [130, 190) empty: nothing, and
    # the next batch starts with the event at 200: [200, 260), produced at 260
    assert times(fired, "Any") == [70, 130, 260]
    assert times(fired, "Busy") == [70]


def test_period_of_a_context_and_of_a_sequence():
    body = (
        "context Held : number := period(S)\ncontext AnswerTime : number := period(E -> B)\n"
        "observation O : B reinforces P\n"
    )
    engine = engine_for(body)
    engine.update(0, set={"S": "ON"})
    engine.update(5, set={"S": "ON"})
    engine.update(8, set={"S": "OFF"}, emit=["E"])
    assert engine.contexts["Held"] == 3  # since the previous update of S, whose value differed
    engine.update(20, set={"B": True})
    assert engine.contexts["AnswerTime"] == 12


def test_a_belief_is_read_as_a_number_and_belief_is_a_propertys_own_in_its_output():
    body = (
        "property Shown : number := belief * 100\nobservation Down : E undermines P veryhigh\n"
        "observation O : update(N) while(P < 0.2) reinforces Shown\n"
    )
    engine = engine_for(body)
    assert engine.update(0, set={"N": 1}).fired == []
    engine.update(1, emit=["E"])
    result = engine.update(2, set={"N": 1})
    assert result.fired == ["O"]
    assert result.outputs["Shown"] == pytest.approx(100 * result.metrics["Shown"])
    with pytest.raises(ModelError, match="'belief' is the property's own belief"):
        parse_model(HEAD + "observation O : eventWhen(belief > 1) reinforces P\n", "m.roqme")


def test_array_and_enum_parameters_and_variables():
    body = (
        "param Pair : number[2] lower 0 default [1, 2]\nparam Mode : enum {CALM, BRISK} default Mode::CALM\n"
        "var Level : enum {LOW, HIGH} := Level::LOW\n"
        "observation O : update(N) while(Pair'includes(N) & Mode = Mode::BRISK) { sets Level := Level::HIGH }\n"
    )
    engine = engine_for(body, params={"Pair": [3], "Mode": "BRISK"})
    assert engine.variables == {"Pair": (3.0,), "Mode": "BRISK", "Level": "LOW"}
    engine.update(0, set={"N": 3})
    assert engine.variables["Level"] == "HIGH"
    with pytest.raises(ContextError, match=r"parameter Pair\[1\]: -3 is below the lower bound 0"):
        engine_for(body, params={"Pair": [-3]})

"""RoQME event operators, action blocks, timers and declarations with their run-time meaning."""

from __future__ import annotations

from datetime import UTC, datetime

import pytest

from qos import ContextError, ModelError, TraceError, load_model, parse_model, replay

from .language import HEAD, engine_for, run, times


def test_and_not_occurs_unless_the_excluded_pattern_came_first_and_then_starts_again():
    batches = [(0, {"B": True}), (1, {"C": True}), (2, {"B": True}), (3, {"B": True, "C": True}), (4, {"B": True})]
    assert times(run("observation O : B and not C reinforces P\n", batches)) == [0, 2, 4]
    # in a sequence, the excluded pattern after the first step sends the whole pattern back to the start
    batches = [(0, {}, ["E"]), (1, {"C": True}), (2, {"B": True}), (3, {}, ["E"]), (4, {"B": True})]
    assert times(run("observation O : E -> (B and not C) reinforces P\n", batches)) == [4]


def test_not_alone_is_refused():
    with pytest.raises(ModelError, match=r"m\.roqme:8:17: 'not p' never occurs on its own"):
        parse_model(HEAD + "observation O : not B reinforces P\n", "m.roqme")


def test_range_occurs_on_the_nth_to_mth_occurrence_over_the_engines_life():
    fired = run("observation O : B range(2, 3) reinforces P\n", [(t, {"B": True}) for t in range(6)])
    assert times(fired) == [1, 2]


def test_roqme_precedence_postfix_operators_take_the_whole_sequence():
    # RoQME: `E -> B while(C)` is `(E -> B) while(C)`: C must hold when the sequence completes... and at E
    batches = [(0, {"C": False}, ["E"]), (1, {"B": True, "C": True}), (2, {}, ["E"]), (3, {"B": True})]
    assert times(run("observation O : E -> B while(C) reinforces P\n", batches)) == [3]
    assert times(
        run(
            "observation O : once E -> B reinforces P\n",
            [(0, {}, ["E"]), (1, {"B": True}), (2, {}, ["E"]), (3, {"B": True})],
        )
    ) == [1]


def test_an_action_block_runs_every_action_with_its_own_strength_and_survival():
    body = (
        "property Q survival 100 minutes\nbeliefvar F reference 0.2\n"
        "observation O : B { reinforces P high survival 1 minutes; undermines Q medium; reinforces F veryhigh }\n"
        "observation Clear : E clears P\n"
    )
    engine = engine_for(body)
    result = engine.update(0, set={"B": True})
    assert result.metrics["P"] == pytest.approx(1 / 1.3)  # LR 0.3
    assert result.metrics["Q"] == pytest.approx(1 / 3)  # medium: LR 0.5, undermining 2
    assert result.beliefs == {"F": pytest.approx(0.2 / (0.2 + 0.8 * 0.1))} and "F" not in result.metrics
    # a one-minute survival fades far faster than the property's own (none: it would never fade)
    assert engine.metrics(600)["P"] == pytest.approx(0.5, abs=1e-6)
    assert engine.metrics(600)["Q"] < 0.4
    assert engine.update(700, emit=["E"]).metrics["P"] == 0.5


def test_time_words_and_medium_strength():
    model = parse_model(
        "roqme M\nproperty A survival 2 hours\nproperty B survival 1 day\nproperty C survival 90 seconds\n"
        "property D survival 250 milliseconds\nproperty E survival 3 minute\ncontext X : eventtype\n"
        "observation O : X reinforces A medium\n",
        "m.roqme",
    )
    assert [model.properties[name].survival for name in "ABCDE"] == [7200, 86400, 90, 0.25, 180]
    assert model.observations["O"].likelihood_ratio == 0.5


def test_an_interval_timer_fires_on_the_engines_clock_before_a_later_update():
    engine = engine_for("timer T := 10 seconds\nobservation O : T reinforces P\n")
    seen = []
    engine.subscribe(lambda result: seen.append((result.t, result.timers, result.fired, result.set)))
    engine.update(25, set={"B": True})  # timers due at 10 and 20 run first, each in its own batch
    assert seen == [(10, ["T"], ["O"], {}), (20, ["T"], ["O"], {}), (25, [], [], {"B": True})]
    assert [result.t for result in engine.advance(40)] == [30, 40]
    assert engine.next_due() == 50


def test_onetime_offset_and_paused_timers_with_starts_stops_resumes():
    body = (
        "timer Idle := 60 seconds onetime paused\ntimer Late := 10 seconds offset 5 seconds onetime\n"
        "observation Ask : E starts Idle\nobservation Hold : B stops Idle\nobservation Go : C resumes Idle\n"
        "observation O : Idle reinforces P\nobservation L : Late reinforces P\n"
    )
    fired = run(body, [(100, {}, ["E"]), (130, {"B": True}), (200, {"C": True}), (300, {}, ["E"])], until=1000)
    assert times(fired, "L") == [15]  # 10 s + the 5 s offset, once
    # started at 100, stopped at 130 with 30 s left, resumed at 200: due at 230; restarted at 300: 360
    assert times(fired, "O") == [230, 360]


def test_a_timer_due_at_an_update_joins_its_batch():
    engine = engine_for("timer T := 10 seconds\nobservation O : T and B reinforces P\n")
    result = engine.update(10, set={"B": True})
    assert (result.timers, result.fired) == (["T"], ["O"])


def test_a_scheduled_timer_fires_at_calendar_times_from_the_origin():
    origin = datetime(2026, 11, 23, 8, 0, tzinfo=UTC).timestamp()  # a Monday
    body = (
        'timer Morning := schedule("30, 9, *, *, [1, 2]")\ntimer Often := schedule("*/20, *, *, *, *")\n'
        "observation O : Morning reinforces P\nobservation F : Often reinforces P\n"
    )
    fired = run(body, [], until=2 * 86400, origin=origin)
    assert times(fired, "O") == [5400, 5400 + 86400]  # 09:30 on Monday and Tuesday
    assert times(fired, "F")[:3] == [1200, 2400, 3600]
    with pytest.raises(ModelError, match=r"bad schedule: hours go from 0 to 23, not 25"):
        parse_model(HEAD + 'timer T := schedule("0, 25, *, *, *")\n', "m.roqme")


def test_timers_are_patterns_not_values():
    with pytest.raises(ModelError, match="T is a timer and has no value: use it as a pattern"):
        parse_model(HEAD + "timer T := 1 minutes\nobservation O : eventWhen(T) reinforces P\n", "m.roqme")
    with pytest.raises(ModelError, match=r"m\.roqme:8:7: timer T needs a definition"):
        parse_model(HEAD + "timer T onetime\n", "m.roqme")


def test_descriptions_are_attached_to_what_they_precede():
    model = parse_model(
        "/** The kiosk's pace.\n *  Second line. */\nroqme M\n/** how well it goes */\nproperty P\n"
        "/* an ordinary comment */\ncontext B : boolean\n/** slow */ observation O : B reinforces P\n",
        "m.roqme",
    )
    assert model.description == "The kiosk's pace.\nSecond line."
    assert (model.properties["P"].description, model.contexts["B"].description) == ("how well it goes", None)
    assert model.observations["O"].description == "slow"


def test_import_merges_another_model_and_reports_errors_in_that_file(tmp_path):
    (tmp_path / "base.roqme").write_text("roqme Base\nproperty P\ncontext B : boolean\n", encoding="utf-8")
    (tmp_path / "top.roqme").write_text(
        'roqme Top\nimport "base.roqme"\nobservation O : B reinforces P\n', encoding="utf-8"
    )
    model = load_model(tmp_path / "top.roqme")
    assert (model.name, list(model.properties), list(model.observations)) == ("Top", ["P"], ["O"])
    (tmp_path / "base.roqme").write_text("roqme Base\nproperty P\ncontext B : bool\n", encoding="utf-8")
    with pytest.raises(ModelError, match=r"^base\.roqme:3:13: unknown type bool"):
        load_model(tmp_path / "top.roqme")
    (tmp_path / "base.roqme").write_text('import "top.roqme"\nproperty P\n', encoding="utf-8")
    with pytest.raises(ModelError, match=r"^base\.roqme:1:8: import cycle: top\.roqme imports this model back"):
        load_model(tmp_path / "top.roqme")


def test_a_bad_batch_changes_nothing_not_even_the_timers():
    engine = engine_for("timer T := 10 seconds\nobservation O : T reinforces P\n")
    with pytest.raises(Exception, match="context 'X' is not in model M"):
        engine.update(50, set={"X": 1})
    assert engine.t is None and engine.next_due() is None


def test_a_jump_that_would_fire_a_timer_too_often_is_refused_before_anything_runs(tmp_path):
    engine = engine_for("timer T := 1 seconds\nobservation O : T reinforces P\n")
    with pytest.raises(ContextError, match="time 1e\\+07 s is too far ahead: the timers would fire about"):
        engine.update(1e7, set={"B": True})
    assert engine.t is None
    (tmp_path / "m.roqme").write_text(
        "roqme M\nproperty P\ntimer T := 1 milliseconds\nobservation O : T reinforces P\n", encoding="utf-8"
    )
    (tmp_path / "t.yaml").write_text("model: m.roqme\nevents:\n  - {t: 5000, set: {}}\n", encoding="utf-8")
    with pytest.raises(TraceError, match="the model's timers would fire about 5,000,000 times over the trace's 5000 s"):
        replay(tmp_path / "t.yaml")


def test_postfix_forms_of_update_event_when_and_period():
    body = (
        "observation O : N'update reinforces P\nobservation Q : B'eventWhen reinforces P\n"
        "observation R : N'period > 1 reinforces P\n"
    )
    fired = run(body, [(0, {"N": 1}), (1, {"B": True}), (5, {"N": 2}), (6, {"N": 2})])
    assert (times(fired, "O"), times(fired, "Q"), times(fired, "R")) == ([0, 5, 6], [1], [5])
    with pytest.raises(ModelError, match=r"m\.roqme:8:17: the pattern operator 'update' cannot be used in a value"):
        parse_model(HEAD + "observation O : N'update > 1 reinforces P\n", "m.roqme")


def test_timers_start_with_the_session_so_a_recorded_trace_replays_them_exactly(tmp_path):
    from qos import Engine, TraceRecorder, dump_trace

    model_path = tmp_path / "m.roqme"
    model_path.write_text(
        HEAD + "timer T := 10 seconds\nobservation O : T reinforces P\nobservation Q : B reinforces P\n",
        encoding="utf-8",
    )
    live = Engine(load_model(model_path))
    recorder = TraceRecorder(live, "m.roqme")
    live_fired = []
    live.subscribe(
        lambda result: live_fired.append({"t": result.t, "observations": result.fired}) if result.fired else None
    )
    live.update(3.5, set={"B": True})  # the patient starts a few seconds into the session
    live.update(27, set={"B": True})
    assert [entry["t"] for entry in live_fired] == [3.5, 10, 20, 27]
    assert [event.t for event in recorder.trace.events] == [3.5, 27]  # timer batches are not recorded
    dump_trace(recorder.trace, tmp_path / "t.yaml")
    assert replay(tmp_path / "t.yaml")["fired"] == live_fired


def test_a_traces_origin_places_scheduled_timers_on_the_calendar(tmp_path):
    (tmp_path / "m.roqme").write_text(
        HEAD + 'timer Nine := schedule("0, 9, *, *, *")\nobservation O : Nine reinforces P\n', encoding="utf-8"
    )
    trace = "model: m.roqme\norigin: {origin}\nevents:\n  - {{t: 7200, set: {{B: true}}}}\n"
    (tmp_path / "t.yaml").write_text(trace.format(origin="2026-11-23T08:00:00Z"), encoding="utf-8")
    assert replay(tmp_path / "t.yaml")["fired"] == [{"t": 3600, "observations": ["O"]}]  # 09:00
    (tmp_path / "t.yaml").write_text(trace.format(origin="tomorrow"), encoding="utf-8")
    with pytest.raises(TraceError, match="'origin' must be a date and time such as 2026-11-23T09:00:00Z"):
        replay(tmp_path / "t.yaml")


def test_imports_nested_without_end_are_one_line(tmp_path):
    for level in range(60):
        (tmp_path / f"m{level}.roqme").write_text(f'import "m{level + 1}.roqme"\nproperty P{level}\n', encoding="utf-8")
    (tmp_path / "m60.roqme").write_text("property Last\n", encoding="utf-8")
    with pytest.raises(ModelError, match=r"^m31\.roqme:1:8: imports nest more than 32 models deep"):
        load_model(tmp_path / "m0.roqme")

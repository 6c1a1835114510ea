"""Context traces: loading, checking, writing back, recording, replaying."""

from __future__ import annotations

import json
import stat

import pytest

from qos import Engine, Trace, TraceError, TraceEvent, TraceRecorder, dump_trace, load_model, load_trace, replay

MALFORMED = [
    (
        "model: clarc\nevents:\n  - {t: 10, set: {PersonDetected: true}\n",
        "t.yaml:4:1: YAML syntax: expected ',' or '}', but got '<stream end>'",
    ),
    ("- just a list\n", "t.yaml: a trace must be a mapping with 'model' and 'events'"),
    ("model: clarc\nevents: {}\n", "t.yaml: 'events' must be a list, not {}"),
    ("model: 3\nevents: []\n", "t.yaml: 'model' must name a bundled model or a .roqme file, not 3"),
    (
        "model: clarc\nevents: []\nsession: 4\n",
        "t.yaml: unknown key 'session' (a trace has model, events, description and origin)",
    ),
    (
        "model: clarc\nevents:\n  - 10\n",
        "t.yaml: events[0]: an event must be a mapping with t and set and/or emit, not 10",
    ),
    ("model: clarc\nevents:\n  - {set: {PersonDetected: true}}\n", "t.yaml: events[0]: missing time 't'"),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {PersonDetected: true}}\n  - {t: -5, set: {PersonDetected: true}}\n",
        "t.yaml: events[1]: time t must not be negative, got -5",
    ),
    (
        "model: clarc\nevents:\n  - {t: soon, set: {PersonDetected: true}}\n",
        "t.yaml: events[0]: time t must be a number of seconds, not 'soon'",
    ),
    ("model: clarc\nevents:\n  - {t: 1}\n", "t.yaml: events[0]: an event needs 'set' or 'emit'"),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {PersonDetected: true}, when: now}\n",
        "t.yaml: events[0]: unknown key 'when' (an event has t, set and emit)",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, set: [PersonDetected]}\n",
        "t.yaml: events[0]: 'set' must map context names to values, not ['PersonDetected']",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, emit: CallingDoctor}\n",
        "t.yaml: events[0]: 'emit' must be a list of eventtype names, not 'CallingDoctor'",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {PersonDetected: true}}\n  - {t: 2, set: {Mood: happy}}\n",
        "t.yaml: events[1]: context 'Mood' is not in model CLARC",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {PersonDetected: 'yes'}}\n",
        "t.yaml: events[0]: context PersonDetected is boolean, got 'yes' (str)",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {UserInteraction: KEYBOARD}}\n",
        "t.yaml: events[0]: context UserInteraction has no literal 'KEYBOARD' "
        "(expected one of VOICE_RECOGNITION, TOUCH_SCREEN, REMOTE_CONTROL)",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {CallingDoctor: true}}\n",
        "t.yaml: events[0]: context CallingDoctor is an eventtype: emit it, do not set it",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, emit: [TestState]}\n",
        "t.yaml: events[0]: context TestState is enum, not an eventtype: set it, do not emit it",
    ),
    (
        "model: clarc\nevents:\n  - {t: 1, set: {PersonDetected: true}}\n  - {t: 1.0, set: {PersonDetected: false}}\n",
        "t.yaml: events[1]: events[0] already sets PersonDetected at t=1.0; one batch can set a context only once",
    ),
]


@pytest.mark.parametrize(("text", "message"), MALFORMED, ids=[f"case{i}" for i in range(len(MALFORMED))])
def test_malformed_trace_is_rejected_with_its_message(tmp_path, monkeypatch, text, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.yaml").write_text(text, encoding="utf-8")
    with pytest.raises(TraceError) as caught:
        load_trace("t.yaml")
    assert str(caught.value) == message


def test_malformed_json_trace_and_missing_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.json").write_text('{"model": "clarc", "events": [}', encoding="utf-8")
    with pytest.raises(TraceError, match=r"^t\.json:1:31: JSON syntax: Expecting value$"):
        load_trace("t.json")
    with pytest.raises(TraceError, match=r"^gone\.yaml:1:1: cannot read the file: No such file or directory$"):
        load_trace("gone.yaml")


def test_trace_with_an_unknown_model_names_it(tmp_path):
    (tmp_path / "t.yaml").write_text("model: nope\nevents: []\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"no bundled model named 'nope'"):
        load_trace(tmp_path / "t.yaml")


def test_a_model_path_is_relative_to_the_trace(tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "tiny.roqme").write_text(
        "roqme Tiny\nproperty P\ncontext B : boolean\nobservation O : B reinforces P veryhigh\n", encoding="utf-8"
    )
    (tmp_path / "t.yaml").write_text(
        "model: models/tiny.roqme\nevents:\n  - {t: 2, set: {B: true}}\n", encoding="utf-8"
    )
    result = replay(tmp_path / "t.yaml")
    assert result["fired"] == [{"t": 2, "observations": ["O"]}]
    assert result["metrics"]["P"]["last"] == pytest.approx(1 / 1.1)  # no survival: no decay


def test_events_are_sorted_and_equal_times_form_one_batch(tmp_path):
    (tmp_path / "t.yaml").write_text(
        "model: clarc\nevents:\n"
        "  - {t: 20, set: {UserInteraction: VOICE_RECOGNITION}}\n"
        "  - {t: 10, set: {PersonDetected: true}}\n"
        "  - {t: 20, set: {FirstAttemptAnswered: true}, emit: [CallingDoctor]}\n",
        encoding="utf-8",
    )
    result = replay(tmp_path / "t.yaml")
    assert result["fired"] == [
        {"t": 10, "observations": ["O2", "O8"]},
        {"t": 20, "observations": ["O2", "O5", "O7", "O9", "O13"]},
    ]


def test_statistics_sample_every_period_up_to_the_last_event():
    trace = Trace("clarc", [TraceEvent(2, {"PersonDetected": True}), TraceEvent(4, {"PersonDetected": False})])
    engine = Engine(load_model("clarc"))
    expected = [0.5, 0.5]
    engine.update(2, set={"PersonDetected": True})
    expected += [engine.metrics(t)["Interaction"] for t in (2, 3)]
    engine.update(4, set={"PersonDetected": False})
    expected.append(engine.metrics(4)["Interaction"])
    stats = replay(trace)["metrics"]["Interaction"]
    mean = sum(expected) / 5
    assert stats == pytest.approx(
        {
            "min": min(expected),
            "max": max(expected),
            "avg": mean,
            "last": expected[-1],
            "sd": (sum((v - mean) ** 2 for v in expected) / 5) ** 0.5,
        }
    )
    # a 2 s period samples t = 0, 2, 4 only
    assert replay(trace, sample_period=2)["metrics"]["Interaction"]["avg"] == pytest.approx(
        (expected[0] + expected[2] + expected[4]) / 3
    )
    # an event between two samples is still applied, and sampled at its own time
    late = Trace("clarc", [TraceEvent(2.5, {"PersonDetected": True})])
    engine = Engine(load_model("clarc"))
    assert replay(late)["fired"] == [{"t": 2.5, "observations": ["O2", "O8"]}]
    assert (
        replay(late)["metrics"]["Interaction"]["last"]
        == engine.update(2.5, set={"PersonDetected": True}).metrics["Interaction"]
    )
    with pytest.raises(ValueError, match="sample period must be a positive"):
        replay(trace, sample_period=0)


def test_trace_writes_back_as_it_reads(tmp_path):
    original = load_trace("recordings/testbench/barthel5.yaml")
    (tmp_path / "copy.json").write_text("{}")
    (tmp_path / "copy.json").chmod(0o644)  # an old world-readable file is replaced owner-only
    for name in ("copy.yaml", "copy.json"):
        dump_trace(original, tmp_path / name, header="copied")
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o600
        again = load_trace(tmp_path / name)
        assert (again.model, again.description) == (original.model, original.description)
        assert [e.to_dict() for e in again.events] == [e.to_dict() for e in original.events]
    assert (tmp_path / "copy.yaml").read_text(encoding="utf-8").startswith("# copied\nmodel: clarc\n")
    assert json.loads((tmp_path / "copy.json").read_text(encoding="utf-8"))["events"][14] == {
        "t": 445,
        "emit": ["CallingDoctor"],
    }


def test_a_recorded_session_replays_to_the_same_results(tmp_path):
    engine = Engine(load_model("clarc"))
    recorder = TraceRecorder(engine, "clarc")
    live = []
    engine.subscribe(lambda result: live.append(result.fired))
    source = load_trace("recordings/testbench/barthel6.yaml")
    for t, values, emitted in source.batches():
        engine.update(t, set=values, emit=emitted)
    recorder.stop()
    engine.update(10_000, set={"PersonDetected": True})
    dump_trace(recorder.trace, tmp_path / "rec.yaml")
    recorded = load_trace(tmp_path / "rec.yaml")
    assert len(recorded.events) == len(source.batches())
    assert replay(recorded) == replay(source)
    assert [entry["observations"] for entry in replay(recorded)["fired"]] == [fired for fired in live[:-1] if fired]


def test_a_trace_from_recorded_events_keeps_whole_times_whole():
    from qos.trace import seconds

    assert (seconds(10.0), type(seconds(10.0)), seconds(2.5)) == (10, int, 2.5)
    trace = Trace.from_events(
        "clarc",
        [{"t": 10.0, "set": {"PersonDetected": True}}, {"t": 12.25, "emit": ["CallingDoctor"]}],
        description="session S",
    )
    assert (trace.model, trace.description) == ("clarc", "session S")
    assert [e.to_dict() for e in trace.events] == [
        {"t": 10, "set": {"PersonDetected": True}},
        {"t": 12.25, "emit": ["CallingDoctor"]},
    ]
    assert type(trace.events[0].t) is int

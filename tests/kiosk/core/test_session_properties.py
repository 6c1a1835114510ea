"""Property-based: any sequence of patient inputs, incidents and waiting keeps the session sane."""

from __future__ import annotations

import os

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import AnswerRecorded, AnswerWithdrawn, Finished, MetricsUpdated, Phase
from qos import Engine, Trace, TraceEvent

from .helpers import MODEL, make_rig

#: raise for a longer hunt: SESSION_PROPERTY_EXAMPLES=3000 uv run pytest tests/kiosk/core/test_session_properties.py
EXAMPLES = int(os.environ.get("SESSION_PROPERTY_EXAMPLES", "150"))

channels = st.sampled_from(list(Channel))
actions = st.one_of(
    st.tuples(st.just("wait"), st.floats(min_value=0, max_value=45, allow_nan=False)),
    st.tuples(st.just("answer"), st.tuples(channels, st.integers(min_value=1, max_value=4))),
    st.tuples(st.just("command"), st.tuples(channels, st.sampled_from(list(Command)))),
    st.tuples(
        st.just("call"),
        st.sampled_from(
            [
                "person_lost",
                "person_back",
                "clinician_continue",
                "prompt_delivered",
                "acknowledge",
                "skip_familiarisation",
                "start",
                "request_voice",
            ]
        ),
    ),
    st.tuples(st.just("language"), st.sampled_from(["en", "es", "fr", "de"])),
    # a speaker or microphone that comes and goes (the app's channel statuses)
    st.tuples(st.just("voice_out"), st.booleans()),
    st.tuples(st.just("voice_in"), st.booleans()),
)


def step(rig, action) -> None:
    kind, arg = action
    if kind == "wait":
        rig.at(rig.session.now() + arg)
    elif kind == "answer":
        rig.session.handle(ChannelInput(arg[0], option=arg[1]))
    elif kind == "command":
        rig.session.handle(ChannelInput(arg[0], command=arg[1]))
    elif kind == "call":
        getattr(rig.session, arg)()
    elif kind == "voice_out":
        rig.session.set_voice_out_available(arg)
        rig.voice_out = arg
    elif kind == "voice_in":
        rig.session.set_voice_available(arg)
    else:
        rig.session.choose_language(arg)
    snap = rig.session.snapshot()
    # a gap's line only between questions (or a practice answer's kind word); "Practice k of n"
    # always makes sense
    assert snap.interlude is None or (snap.phase in (Phase.QUESTIONS, Phase.FAMILIARISATION) and snap.attempt is None)
    assert (snap.practice_number is None) == (snap.practice is None)
    assert snap.practice_number is None or 1 <= snap.practice_number <= snap.practice_count
    if not getattr(rig, "voice_out", True):  # nothing to hear: no hearing check on screen
        assert snap.practice is None or snap.practice.checks != "hear"


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(actions, max_size=60), st.booleans())
def test_any_input_sequence_keeps_the_session_consistent_and_it_can_always_finish(sequence, practice):
    rig = make_rig(familiarisation=practice, timing={"attempt_window_s": 20, "between_questions_s": 2})
    for action in sequence:
        step(rig, action)
    # whatever happened, a clinician and a patient who comes back can always bring it to an end
    for call in ("start", "person_back", "clinician_continue", "resume", "skip_familiarisation", "acknowledge"):
        getattr(rig.session, call)()
    for _ in range(200):
        if rig.session.finished:
            break
        if rig.session.phase is Phase.EXPLANATION:
            rig.session.acknowledge()
        deadline = rig.session.next_deadline()
        assert deadline is not None, f"stuck in {rig.session.snapshot()}"
        rig.clock.set(deadline)
        rig.session.poll()
    assert rig.session.finished

    recorded = rig.of(AnswerRecorded)
    assert len(recorded) <= 10 + len(rig.of(AnswerWithdrawn))
    standing: dict[str, AnswerRecorded] = {}  # an answer taken back ("Change my answer") no longer counts
    for event in rig.events:
        if isinstance(event, AnswerRecorded):
            assert event.item_id not in standing  # one standing answer per item
            standing[event.item_id] = event
        elif isinstance(event, AnswerWithdrawn):
            del standing[event.item_id]
    answers = list(standing.values())
    (finished,) = rig.of(Finished)
    assert finished.score.total == sum(a.points for a in answers)
    assert set(finished.score.answered) == {a.item_id for a in answers}

    times = [e["t"] for e in rig.session.trace]
    assert times == sorted(times) and len(set(times)) == len(times)
    trace = Trace("clarc", [TraceEvent(e["t"], e.get("set", {}), e.get("emit", [])) for e in rig.session.trace])
    trace.check(MODEL)
    engine = Engine(MODEL)
    replayed = [(float(t), engine.update(t, set=v, emit=em)) for t, v, em in trace.batches()]
    assert [(t, r.metrics, tuple(r.fired)) for t, r in replayed] == [
        (u.t, dict(u.metrics), u.fired) for u in rig.of(MetricsUpdated)
    ]

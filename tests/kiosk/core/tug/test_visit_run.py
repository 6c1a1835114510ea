"""The Timed Up and Go as the kiosk runs it in a visit (pure, on a simulated clock): the set-up's
whole-body checks before staff confirm, the live phases, the run ending once the patient sat back,
staff's decision, the stopwatch only without a camera, and a skip with its reason."""

from __future__ import annotations

import pytest

from kiosk.core.clock import SimClock
from kiosk.core.tug.families import generate
from kiosk.core.tug.step import TugStage, TugStepError
from kiosk.core.tug.visit import TugRun
from kiosk.core.words import load_words


def make(camera: str | None = None) -> tuple[TugRun, SimClock, list]:
    clock, published = SimClock(), []
    run = TugRun(
        clock, lambda t, v: published.append(dict(v)), walk_up=False, language="es", part=(2, 3), camera=camera
    )
    return run, clock, published


def test_a_run_timed_by_the_camera_from_set_up_to_decision():
    sequence, truth = generate("normal", 3)
    run, clock, published = make()
    frames = iter(sequence.frames)
    first = next(frames)
    clock.set(first.t)
    run.frame(first.t, first.landmarks, sequence.width, sequence.height)
    with pytest.raises(TugStepError, match="at the chair and at the 3 m line first"):
        run.confirm_staff("nurse-7")
    assert run.check_spot("chair") == "" and run.check_spot("line") == ""
    run.confirm_staff("nurse-7")
    go_t = truth.onset_t - 0.5
    lives = []
    for frame in frames:
        if run.stage is TugStage.READY and frame.t >= go_t:
            clock.set(go_t)
            run.go()
        clock.set(frame.t)
        run.frame(frame.t, frame.landmarks, sequence.width, sequence.height)
        lives.append(run.live)
        if run.poll():
            break
    assert run.stage is TugStage.ANALYSED and run.step.analysis.valid
    lives.append(run.live)
    assert [k for i, k in enumerate(lives) if i == 0 or lives[i - 1] != k] == ["ready", "seated", "up", "back", "over"]
    assert {"PersonGetsUp": True, "PersonIsSeated": False} in published
    words = run.words(load_words()["es"].screen)
    assert words["part"] == "Parte 2 de 3" and words["phase"].startswith("Gracias")
    result = run.decide("accepted", " dr-3 ", get_up_go=1, walking_aid="none")
    assert (result.method, result.decided_by, result.get_up_go) == ("camera", "dr-3", 1)
    assert result.total_s == pytest.approx(truth.seated_t - go_t, abs=0.3)


def test_without_a_camera_only_a_stopwatch_time_or_a_rejection():
    run, clock, _ = make(camera="no camera found")
    assert run.set_up and run.framing == "no camera: no camera found"
    run.confirm_staff("nurse-7")
    run.go()
    clock.advance(11.0)
    assert not run.poll()  # nothing seen: staff end it
    run.finish()
    with pytest.raises(TugStepError, match="no camera timed this test"):
        run.decide("accepted", "dr-3")
    result = run.decide("stopwatch", "dr-3", stopwatch_s=11.2)
    assert (result.total_s, result.method, result.camera_total_s) == (11.2, "stopwatch", None)


def test_a_skip_says_who_and_why_and_times_nothing():
    run, _, _ = make(camera="no camera found")
    with pytest.raises(TugStepError, match="who skips it and why"):
        run.skip("nurse-7", " ")
    result = run.skip("nurse-7", "patient in a wheelchair")
    assert (result.decision, result.total_s, result.reasons) == (
        "rejected",
        None,
        ("skipped: patient in a wheelchair",),
    )
    assert run.stage is TugStage.DONE


def test_never_at_a_walk_up_visit():
    with pytest.raises(TugStepError, match="walk-up"):
        TugRun(SimClock(), lambda t, v: None, walk_up=True, language="en", part=(1, 2), camera=None)

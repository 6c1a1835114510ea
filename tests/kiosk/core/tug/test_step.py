"""The Timed Up and Go step on the simulated clock: generated sequences with known times fed frame
by frame, the contexts it publishes, staff's confirmation and decision, the threshold's wording."""

from __future__ import annotations

from dataclasses import replace

import pytest

from kiosk.core.clock import SimClock
from kiosk.core.tug.families import generate
from kiosk.core.tug.step import TugSettings, TugStep, TugStepError
from tests.kiosk.core.tug.stepping import go_of, run


@pytest.mark.parametrize(("family", "seed"), [("normal", 1), ("frail", 2), ("walking_aid", 3)])
def test_a_generated_patient_is_timed_and_the_contexts_follow_the_course(family: str, seed: int) -> None:
    sequence, truth = generate(family, seed)
    assert truth.onset_t is not None and truth.seated_t is not None
    go_t = go_of(sequence, truth.onset_t)
    step, published, clock = run(sequence, go_t)
    analysis = step.analysis
    assert analysis is not None and analysis.valid, analysis and analysis.reasons
    assert analysis.total_s == pytest.approx(truth.seated_t - go_t, abs=0.3)
    names = [(name, value) for _, values in published for name, value in values.items()]
    assert names[:4] == [
        ("PersonIsNextToChair", True),
        ("PersonIsSeated", True),
        ("PersonGetsUp", True),
        ("PersonIsSeated", False),
    ]
    times: dict[tuple[str, bool], float] = {}  # the first time of each
    for t, values in published:
        for name, value in values.items():
            times.setdefault((name, value), t)
    assert truth.onset_t < times["PersonGetsUp", True] < truth.phases["walk_out"][1]
    assert times["PersonIsSeated", True] == go_t
    assert truth.seated_t <= times["PersonGetsUp", False] < truth.seated_t + 1.5
    assert names[4:] == [("PersonGetsUp", False), ("PersonIsSeated", True)]
    clock.advance(5)
    result = step.decide("accepted", "dr-lee")
    assert published[-1] == (clock.now(), {"Scored": True})
    assert result.total_s == analysis.total_s and result.method == "camera"
    assert result.confirmed_by == "nurse-7" and result.decided_by == "dr-lee"
    assert [p.name for p in result.phases] == ["sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit"]
    assert result.turn_seen and not result.body_cut_off and result.person_share > 0.9
    assert result.landmarks is None  # kept only where the site turns it on


def test_legs_cut_off_give_no_time_and_staff_enter_a_stopwatch_time() -> None:
    sequence, truth = generate("legs_cut", 4)
    step, published, _ = run(sequence, 1.0)
    assert ("PersonIsNextToChair", True) not in [(n, v) for _, vs in published for n, v in vs.items()]
    assert step.framing.startswith("not the whole body")
    with pytest.raises(TugStepError, match="no valid time"):
        step.decide("accepted", "dr-lee")
    result = step.decide("stopwatch", "dr-lee", stopwatch_s=14.2)
    assert result.method == "stopwatch" and result.total_s == 14.2 and result.body_cut_off
    assert result.camera_total_s is None and result.reasons
    assert result.wording() == "14.2 s, above the site's threshold (13.5 s)."


def test_rejected_publishes_scored_false_and_the_site_threshold_and_landmarks_apply() -> None:
    sequence, truth = generate("normal", 5)
    assert truth.onset_t is not None
    step, published, _ = run(sequence, go_of(sequence, truth.onset_t), TugSettings(threshold_s=30, keep_landmarks=True))
    step.rate(get_up_go=2, walking_aid="stick")
    result = step.decide("rejected", "dr-lee")
    assert published[-1][1] == {"Scored": False}
    assert result.total_s is None and result.above_threshold is None and result.wording() == "No time taken (rejected)."
    assert result.get_up_go == 2 and result.walking_aid == "stick"
    go_t = go_of(sequence, truth.onset_t)
    kept = [f for f in sequence.frames if f.t >= go_t - 2.0]  # from the seated rest before Go
    assert result.landmarks is not None and result.landmarks.frames == tuple(kept)
    camera = result.camera_total_s
    assert camera is not None and camera < 30
    assert replace(result, total_s=camera).wording() == f"{camera:.1f} s, not above the site's threshold (30 s)."


def test_the_step_refuses_out_of_order_and_walk_up() -> None:
    clock = SimClock()
    with pytest.raises(TugStepError, match="walk-up"):
        TugStep(clock, lambda t, v: None, walk_up=True)
    step = TugStep(clock, lambda t, v: None, walk_up=False)
    with pytest.raises(TugStepError, match="confirmation first"):
        step.go()
    with pytest.raises(TugStepError, match="who confirms"):
        step.confirm_staff(" ")
    step.confirm_staff("nurse-7")
    with pytest.raises(TugStepError, match="not started"):
        step.finish()
    with pytest.raises(TugStepError, match="1 to 5"):
        step.rate(get_up_go=6)
    with pytest.raises(TugStepError, match="walking aid"):
        step.rate(walking_aid="wheelchair")


POSITIVES = ("normal", "frail", "hesitant", "fps15", "fps60", "noisy", "mirrored", "walking_aid")


@pytest.mark.parametrize("family", [*POSITIVES, "never_stands", "stands_no_walk", "leaves_frame", "legs_cut"])
def test_gets_up_and_seated_again_follow_every_family(family: str) -> None:
    """One rise after the onset and before the walk out, one sit after the true landing; none for a
    patient who never stands or whose legs are out of the picture (seeds 0-2 each)."""
    for seed in range(3):
        sequence, truth = generate(family, seed)
        go_t = go_of(sequence, truth.onset_t) if truth.onset_t is not None else sequence.go_t or 1.0
        step, published, _ = run(sequence, go_t)
        gets_up = [(t, values["PersonGetsUp"]) for t, values in published if "PersonGetsUp" in values]
        if family in POSITIVES:
            assert truth.onset_t is not None and truth.seated_t is not None
            [(up_t, up), (down_t, down)] = gets_up
            assert up and not down, (family, seed)
            assert truth.onset_t < up_t < truth.phases["walk_out"][1], (family, seed)
            assert truth.seated_t <= down_t < truth.seated_t + 1.5, (family, seed)
        elif family in ("never_stands", "legs_cut"):
            assert gets_up == [], (family, seed)
        elif family == "stands_no_walk":
            assert [up for _, up in gets_up] == [True, False], (family, seed)
        else:  # leaves_frame: up, never seen seated again
            assert [up for _, up in gets_up] == [True], (family, seed)


def test_a_long_set_up_with_the_patient_walking_about_does_not_move_the_time() -> None:
    """Staff set the camera up for 20 s while the patient walks to the chair: only the seated rest
    before "Go" is analysed with the test."""
    walking, _ = generate("normal", 8)
    sequence, truth = generate("normal", 9)
    assert truth.onset_t is not None and truth.seated_t is not None
    middle = [f for f in walking.frames if 4.0 <= f.t < 24.0]  # up and walking
    shift = 21.0
    before = [replace(f, t=f.t - 4.0) for f in middle]
    after = [replace(f, t=f.t + shift) for f in sequence.frames]
    long = replace(sequence, frames=(*before, *after))
    go_t = go_of(sequence, truth.onset_t) + shift
    step, _, _ = run(long, go_t)
    analysis = step.analysis
    assert analysis is not None and analysis.valid, analysis and analysis.reasons
    assert analysis.total_s == pytest.approx(truth.seated_t + shift - go_t, abs=0.3)

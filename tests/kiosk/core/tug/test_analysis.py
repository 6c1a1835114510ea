"""The Timed Up and Go read from landmarks: generated courses of every family are timed, from any
camera place, and the negatives are refused with the reason a clinician would give.

How close the times are is the bench's question (bench/tug.py); here, what a user notices: a valid
result, its phases in order, the reasons."""

from __future__ import annotations

from dataclasses import replace

import pytest

from kiosk.core.tug import PHASES, analyse
from kiosk.core.tug.families import POSITIVE, generate


@pytest.mark.parametrize("family", POSITIVE)
@pytest.mark.parametrize("seed", [1, 2])
def test_a_generated_course_is_timed_with_its_five_phases_in_order(family, seed):
    sequence, truth = generate(family, seed)
    result = analyse(sequence)
    assert result.valid, (truth.view, result.reasons)
    assert [p.name for p in result.phases] == list(PHASES)
    assert all(p.end_t > p.start_t for p in result.phases)
    assert result.phases[0].start_t == result.onset_t and result.phases[-1].end_t == result.seated_t
    assert result.total_s == pytest.approx(truth.total_s, abs=1.0)
    start = truth.go_t if truth.go_t is not None else result.onset_t
    assert result.total_s == pytest.approx(result.seated_t - start)
    assert result.quality["turn_seen"] and result.quality["returned_to_chair"]


@pytest.mark.parametrize(
    ("family", "reason"),
    [
        ("never_stands", "the patient never stands up"),
        ("stands_no_walk", "the patient stands but does not walk out"),
        ("legs_cut", "legs cut off"),
    ],
)
@pytest.mark.parametrize("seed", [0, 4])
def test_a_negative_is_refused_with_its_reason(family, reason, seed):
    sequence, _ = generate(family, seed)
    result = analyse(sequence)
    assert not result.valid and result.total_s is None
    assert any(reason in text for text in result.reasons), result.reasons


def test_a_patient_who_walks_out_of_the_picture_is_refused():
    sequence, _ = generate("leaves_frame", 0)
    result = analyse(sequence)
    assert not result.valid
    assert any("too few frames with a person" in r or "left the picture" in r for r in result.reasons)


def test_a_course_cut_short_before_sitting_is_not_timed():
    sequence, truth = generate("normal", 5)
    cut = replace(sequence, frames=tuple(f for f in sequence.frames if f.t < truth.phases["walk_back"][1]))
    result = analyse(cut)
    assert not result.valid and "not seated again when the sequence ends" in result.reasons


def test_frames_without_a_person_are_refused_as_too_few():
    sequence, _ = generate("normal", 6)
    empty = replace(sequence, frames=tuple(replace(f, landmarks=None) for f in sequence.frames))
    result = analyse(empty)
    assert not result.valid and result.reasons[0].startswith("too few frames with a person (0 of")


def test_the_same_file_gives_the_same_result():
    sequence, _ = generate("noisy", 7)
    assert analyse(sequence).as_json() == analyse(sequence).as_json()


def test_the_json_form_has_the_fields_outside_checks_read():
    sequence, _ = generate("normal", 8)
    data = analyse(sequence).as_json()
    assert {"valid", "total_s", "onset_t", "seated_t", "phases", "reasons"} <= set(data)
    assert set(data["phases"]) == set(PHASES)
    assert set(data["phases"]["turn"]) == {"start_t", "end_t", "duration_s"}

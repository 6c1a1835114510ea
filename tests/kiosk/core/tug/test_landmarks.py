"""The pose-landmarks/1 file: what outside checks write is read exactly, and anything else is one
message naming the file and line."""

from __future__ import annotations

import json

import pytest

from kiosk.core.tug import PoseFileError, parse_pose_text
from kiosk.core.tug.families import generate
from kiosk.core.tug.landmarks import NAMES, dump_pose_lines

POINT = [0.5, 0.5, 0.0, 0.9]
HEADER = '{"format": "pose-landmarks/1", "fps": 30, "width": 640, "height": 480, "go_t": 0.5}'


def frame(t: float, points=None) -> str:
    return json.dumps({"t": t, "landmarks": points})


def test_a_file_as_the_issue_writes_it_is_read_whole():
    text = "\n".join([HEADER, frame(0.0, [POINT] * 33), frame(0.033), frame(0.066, [POINT] * 33)]) + "\n"
    sequence = parse_pose_text(text, "walk.jsonl")
    assert (sequence.fps, sequence.width, sequence.height, sequence.go_t) == (30.0, 640, 480, 0.5)
    assert [f.t for f in sequence.frames] == [0.0, 0.033, 0.066]
    assert sequence.frames[1].landmarks is None
    assert sequence.frames[2].landmarks[32] == (0.5, 0.5, 0.0, 0.9)


def test_go_t_is_optional_and_the_names_are_mediapipes_order():
    sequence = parse_pose_text(HEADER.replace(', "go_t": 0.5', "") + "\n" + frame(0.0), "a.jsonl")
    assert sequence.go_t is None
    assert (NAMES[0], NAMES[11], NAMES[23], NAMES[29], NAMES[32]) == (
        "nose",
        "left_shoulder",
        "left_hip",
        "left_heel",
        "right_foot_index",
    )


def test_a_generated_sequence_goes_through_the_text_unchanged_to_five_decimals():
    sequence, _ = generate("normal", 3)
    again = parse_pose_text("\n".join(dump_pose_lines(sequence)), "round.jsonl")
    assert len(again.frames) == len(sequence.frames) and again.go_t == pytest.approx(sequence.go_t, abs=1e-4)
    for before, after in zip(sequence.frames[::50], again.frames[::50]):
        assert (before.landmarks is None) == (after.landmarks is None)
        if before.landmarks is not None:
            assert after.landmarks[25] == pytest.approx(before.landmarks[25], abs=1e-5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "bad.jsonl:1: empty"),
        ('{"format": "pose-landmarks/2", "fps": 30, "width": 1, "height": 1}', "bad.jsonl:1: the header must be"),
        ('{"format": "pose-landmarks/1", "fps": 30, "width": 640}', 'bad.jsonl:1: the header has no "height"'),
        ('{"format": "pose-landmarks/1", "fps": 0, "width": 640, "height": 480}', 'bad.jsonl:1: "fps" must be'),
        (HEADER, "bad.jsonl:1: the file has a header but no frames"),
        (HEADER + "\n" + frame(0.0, [POINT] * 32), 'bad.jsonl:2: "landmarks" must be null or 33 points, found 32'),
        (HEADER + "\n" + frame(0.0) + "\n" + frame(0.0), "bad.jsonl:3: t 0 is not after the line before (0)"),
        (
            HEADER + "\n" + frame(0.0, [POINT] * 20 + [[0.5, "x", 0, 1]] + [POINT] * 12),
            "bad.jsonl:2: landmark 20 (right_index) must be a number",
        ),
        (
            HEADER + "\n" + frame(0.0, [POINT] * 20 + [[0.5, 0.5, 0]] + [POINT] * 12),
            "bad.jsonl:2: landmark 20 (right_index) must be [x, y, z, visibility]",
        ),
        (HEADER + '\n{"t": 0, "landmarks": [}', "bad.jsonl:2: column"),
        (HEADER + '\n{"t": NaN, "landmarks": null}', "bad.jsonl:2: column"),
        (
            HEADER + '\n{"time": 0, "landmarks": null}',
            'bad.jsonl:2: a frame must be an object with "t" and "landmarks"',
        ),
    ],
)
def test_a_bad_file_is_one_message_naming_the_line(text, message):
    with pytest.raises(PoseFileError) as raised:
        parse_pose_text(text, "bad.jsonl")
    assert str(raised.value).startswith(message), str(raised.value)

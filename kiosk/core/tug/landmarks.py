"""The pose-landmarks/1 file: a camera's view of a Timed Up and Go as JSON Lines, without the frames.

Line 1 is the header ``{"format": "pose-landmarks/1", "fps": F, "width": W, "height": H, "go_t": T}``
(``go_t`` optional: when the kiosk said "Go", in seconds on the file's clock). Every further line is
one frame, ``{"t": seconds, "landmarks": null | [[x, y, z, visibility] x 33]}``, in MediaPipe Pose's
landmark order (:data:`NAMES`): x and y normalised to the image (0 = left, top), z relative depth
(0 where unknown), ``null`` when no person was found. Outside checks read and write it exactly, so
:func:`parse_pose_text` refuses anything else with one message naming the line.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import field
from typing import Any

from basis import record
from basis.errors import KioskError
from fileio.bounded import BadFile, load_json

FORMAT = "pose-landmarks/1"

#: MediaPipe Pose's 33 landmarks, in its order (Google's model card; /work reference tug.md)
NAMES = (
    "nose",
    "left_eye_inner",
    "left_eye",
    "left_eye_outer",
    "right_eye_inner",
    "right_eye",
    "right_eye_outer",
    "left_ear",
    "right_ear",
    "mouth_left",
    "mouth_right",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
    "left_pinky",
    "right_pinky",
    "left_index",
    "right_index",
    "left_thumb",
    "right_thumb",
    "left_hip",
    "right_hip",
    "left_knee",
    "right_knee",
    "left_ankle",
    "right_ankle",
    "left_heel",
    "right_heel",
    "left_foot_index",
    "right_foot_index",
)
INDEX = {name: number for number, name in enumerate(NAMES)}
COUNT = len(NAMES)

#: one landmark: (x, y, z, visibility)
Landmark = tuple[float, float, float, float]


@record
class PoseFrame:
    """One frame: its time on the file's clock and the 33 landmarks, or None when nobody was seen."""

    t: float
    landmarks: tuple[Landmark, ...] | None


@record
class PoseSequence:
    """A whole file: the header's values and the frames in time order."""

    fps: float
    width: int
    height: int
    go_t: float | None
    frames: tuple[PoseFrame, ...] = field(repr=False)


class PoseFileError(KioskError, ValueError):
    """A pose-landmarks file cannot be read; the message names the file and line."""


def parse_pose_text(text: str, name: str) -> PoseSequence:
    """The sequence a pose-landmarks/1 text holds; :class:`PoseFileError` naming ``name`` and the line
    for anything else (bad JSON, wrong header, 32 landmarks, times going back, x not a number)."""
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise PoseFileError(f"{name}:1: empty; expected the header line {{'format': '{FORMAT}', ...}}")
    header = _json_line(lines[0], name, 1)
    fps, width, height, go_t = _header(header, name)
    frames: list[PoseFrame] = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        frame = _frame(_json_line(line, name, number), name, number)
        if frames and frame.t <= frames[-1].t:
            raise PoseFileError(f"{name}:{number}: t {frame.t:g} is not after the line before ({frames[-1].t:g})")
        frames.append(frame)
    if not frames:
        raise PoseFileError(f"{name}:1: the file has a header but no frames")
    return PoseSequence(fps=fps, width=width, height=height, go_t=go_t, frames=tuple(frames))


def dump_pose_lines(sequence: PoseSequence) -> Iterable[str]:
    """The file's lines (without line breaks), header first; numbers rounded to 5 decimals."""
    header: dict[str, Any] = {"format": FORMAT, "fps": sequence.fps, "width": sequence.width}
    header["height"] = sequence.height
    if sequence.go_t is not None:
        header["go_t"] = round(sequence.go_t, 4)
    yield json.dumps(header)
    for frame in sequence.frames:
        points = None if frame.landmarks is None else [[round(v, 5) for v in point] for point in frame.landmarks]
        yield json.dumps({"t": round(frame.t, 4), "landmarks": points}, separators=(",", ":"))


def _json_line(line: str, name: str, number: int) -> Any:
    """One line's value. The common case goes straight through :func:`json.loads` (refusing NaN,
    infinity and duplicate keys; a frame line is flat, so nesting cannot run deep); a line it
    refuses is read again by :func:`fileio.bounded.load_json` for the column and the problem."""
    try:
        return json.loads(line, parse_constant=_refuse, object_pairs_hook=_unique)
    except (ValueError, RecursionError):
        pass
    try:
        load_json(line, name)
    except BadFile as error:
        problem = error.problem
        raise PoseFileError(f"{name}:{number}: column {problem.column}: {problem.message}") from None
    raise PoseFileError(f"{name}:{number}: not a JSON object this format knows")


def _refuse(text: str) -> None:
    raise ValueError(f"{text} is not a finite number")


def _unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    found = dict(pairs)
    if len(found) != len(pairs):
        raise ValueError("duplicate key")
    return found


def _number(value: Any, what: str, name: str, number: int) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise PoseFileError(f"{name}:{number}: {what} must be a number, not {json.dumps(value)[:40]}")
    return float(value)


def _header(header: Any, name: str) -> tuple[float, int, int, float | None]:
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise PoseFileError(f'{name}:1: the header must be an object with "format": "{FORMAT}"')
    for key in ("fps", "width", "height"):
        if key not in header:
            raise PoseFileError(f'{name}:1: the header has no "{key}"')
    fps = _number(header["fps"], '"fps"', name, 1)
    width = _number(header["width"], '"width"', name, 1)
    height = _number(header["height"], '"height"', name, 1)
    if fps <= 0 or width < 1 or height < 1 or width != int(width) or height != int(height):
        raise PoseFileError(f'{name}:1: "fps" must be above 0 and "width", "height" whole numbers of pixels')
    go = header.get("go_t")
    go_t = None if go is None else _number(go, '"go_t"', name, 1)
    return fps, int(width), int(height), go_t


def _frame(data: Any, name: str, number: int) -> PoseFrame:
    if not isinstance(data, dict) or "t" not in data or "landmarks" not in data:
        raise PoseFileError(f'{name}:{number}: a frame must be an object with "t" and "landmarks"')
    t = _number(data["t"], '"t"', name, number)
    points = data["landmarks"]
    if points is None:
        return PoseFrame(t=t, landmarks=None)
    if not isinstance(points, list) or len(points) != COUNT:
        size = len(points) if isinstance(points, list) else "not a list"
        raise PoseFileError(f'{name}:{number}: "landmarks" must be null or {COUNT} points, found {size}')
    return PoseFrame(t=t, landmarks=tuple(_point(point, index, name, number) for index, point in enumerate(points)))


def _point(point: Any, index: int, name: str, number: int) -> Landmark:
    if type(point) is not list or len(point) != 4:
        raise PoseFileError(f"{name}:{number}: landmark {index} ({NAMES[index]}) must be [x, y, z, visibility]")
    x, y, z, visibility = point
    # the common case in one test (floats and ints, not bools; a huge literal parses as infinity)
    if {type(x), type(y), type(z), type(visibility)} <= _NUMBERS and math.isfinite(x + y + z + visibility):
        return (float(x), float(y), float(z), float(visibility))
    x, y, z, visibility = (_number(v, f"landmark {index} ({NAMES[index]})", name, number) for v in point)
    return (x, y, z, visibility)


_NUMBERS = {float, int}


def sequence_from_frames(
    frames: Sequence[PoseFrame], *, fps: float, width: int, height: int, go_t: float | None = None
) -> PoseSequence:
    """A sequence built in memory (the camera channel's recorder, the generator)."""
    return PoseSequence(fps=fps, width=width, height=height, go_t=go_t, frames=tuple(frames))

"""The Timed Up and Go read from pose landmarks: when the patient moved, stood, turned and sat.

:func:`analyse` takes a :class:`~kiosk.core.tug.landmarks.PoseSequence` and returns a
:class:`TugAnalysis`: valid with a total time and five phases, or not valid with the reasons. It
prefers refusing to guessing: every check that a wrong time would fail (seated at both ends, stood,
walked out and back to the chair, a turn seen, the whole body seen, phase durations a person can
have) must pass, so a time more than a few tenths off is flagged rather than reported.

Definitions (docs/tug.md): ``onset_t`` is the start of the movement that leads to standing (the
trunk or hips leaving the seated rest; pauses under 3 s in a hesitant start belong to it);
``seated_t`` is when the hips are back at seat height; the total runs from ``go_t`` when the file
has it, else from ``onset_t``. Pure and deterministic: the same file gives the same result.
"""

from __future__ import annotations

import math
from dataclasses import field
from typing import Any

import numpy as np

from basis import record
from kiosk.core.tug.landmarks import PoseSequence
from kiosk.core.tug.phases import Course, walk_course
from kiosk.core.tug.signals import Signals, body_signals, crossing, fill_gaps, gaps, index_at, smooth

PHASES = ("sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit")

#: frames with a person below this share: too little seen to time anything
MIN_PERSON_SHARE = 0.6
#: frames with a person whose knees, ankles and heels are seen, below this share: legs cut off
MIN_LEGS_SHARE = 0.6
#: a run without a person (or without the legs) longer than this, during the test: left the frame
MAX_GAP_S = 1.0
#: the seated rest read before the movement (seconds)
REST_S = 1.0
#: standing is at least this much higher, in torso lengths of hip height over the ankles, than sitting
MIN_RISE = 0.35
#: the smallest movement that starts the test: a share of the rise, and shoulders moved (torso lengths)
ONSET_LEVEL = 0.12
ONSET_MOVED = 0.08
ONSET_LEAN = 0.2
#: a movement this large for half a second (a share of the smallest that starts the test) before
#: the start: unclear start
STIRRED = 0.35
#: ...and where it began: back down to the rest's level plus this share of that smallest movement
ONSET_FLOOR = 0.3
#: seated again: the hips within this share of the rise (or three times the rest's noise) of the seat
SEATED_LEVEL = 0.03
#: seated again: the hips' height over the ankles at the end within this of the start (torso lengths;
#: standing is about 0.65 higher)
SAME_SEAT = 0.3
LANDED_SPEED = 0.2
#: pauses shorter than this between tries of a hesitant start belong to the movement
HESITATION_S = 3.0
#: a plausible total (seconds) and sit-to-stand (seconds)
TOTAL_RANGE = (3.0, 180.0)
SIT_TO_STAND_RANGE = (0.3, 10.0)


@record
class Phase:
    """One phase of the course, on the file's clock."""

    name: str
    start_t: float
    end_t: float

    @property
    def duration_s(self) -> float:
        return self.end_t - self.start_t


@record
class TugAnalysis:
    """What one sequence shows: the total and phases when ``valid``, else ``reasons``."""

    valid: bool
    total_s: float | None
    onset_t: float | None
    seated_t: float | None
    go_t: float | None
    phases: tuple[Phase, ...] = ()
    reasons: tuple[str, ...] = ()
    #: measurement quality, stored with a result: person_share, legs_share, turn_seen, returned
    quality: dict[str, Any] = field(default_factory=dict)

    def as_json(self) -> dict[str, Any]:
        """The object ``kiosk tug analyse --json`` prints (times rounded to milliseconds)."""
        return {
            "valid": self.valid,
            "total_s": _ms(self.total_s),
            "onset_t": _ms(self.onset_t),
            "seated_t": _ms(self.seated_t),
            "go_t": _ms(self.go_t),
            "phases": {
                p.name: {"start_t": _ms(p.start_t), "end_t": _ms(p.end_t), "duration_s": _ms(p.duration_s)}
                for p in self.phases
            },
            "reasons": list(self.reasons),
            "quality": self.quality,
        }


def _ms(value: float | None) -> float | None:
    return None if value is None else round(value, 3)


class _Refused(Exception):
    """A check failed that leaves nothing more to measure."""


def analyse(sequence: PoseSequence) -> TugAnalysis:
    """The Timed Up and Go that ``sequence`` shows, or why it shows none (see the module's doc)."""
    signals = body_signals(sequence)
    quality: dict[str, Any] = {"frames": len(signals.t)}
    found: dict[str, float] = {}
    reasons: list[str] = []
    try:
        _measure(sequence, signals, quality, found, reasons)
    except _Refused as refused:
        reasons.append(str(refused))
    onset, seated = found.get("onset_t"), found.get("seated_t")
    phases = _phases(found)
    if not reasons:
        reasons += _implausible(phases, sequence.go_t, onset, seated)
    total = None
    if not reasons and seated is not None and onset is not None:
        total = seated - (sequence.go_t if sequence.go_t is not None else onset)
    return TugAnalysis(
        valid=not reasons,
        total_s=total,
        onset_t=onset,
        seated_t=seated,
        go_t=sequence.go_t,
        phases=phases,
        reasons=tuple(reasons),
        quality=quality,
    )


def _measure(
    sequence: PoseSequence, s: Signals, quality: dict[str, Any], found: dict[str, float], reasons: list[str]
) -> None:
    t = s.t
    if not len(t):
        quality.update(person_share=0.0, legs_share=0.0)
        raise _Refused("no frames: the camera saw nothing of the test")
    fps = 1.0 / float(np.median(np.diff(t))) if len(t) > 1 else sequence.fps
    people = int(s.person.sum())
    quality["person_share"] = round(people / len(t), 3)
    quality["legs_share"] = round(float(s.legs.sum()) / max(people, 1), 3)
    if people < max(10, 2 * fps) or quality["person_share"] < MIN_PERSON_SHARE:
        raise _Refused(f"too few frames with a person ({people} of {len(t)})")
    if quality["legs_share"] < MIN_LEGS_SHARE:
        raise _Refused(
            f"legs cut off or hidden: knees, ankles and heels seen in {quality['legs_share']:.0%} of the frames "
            "with a person; the whole body must be in the picture"
        )
    people_at = np.flatnonzero(s.person)
    for where, a, b in (("start", people_at[0], people_at[0]), ("end", people_at[-1], people_at[-1])):
        a, b = min(a, index_at(t, t[a] - REST_S)), max(b, index_at(t, t[b] + REST_S))
        if s.legs[a : b + 1].mean() < 0.5:
            raise _Refused(f"legs cut off or hidden at the chair at the {where}; the whole body must be in the picture")

    lift = smooth(fill_gaps(t, s.lift), max(3, round(0.2 * fps)) | 1)
    seen = np.flatnonzero(s.legs)
    first, last = int(seen[0]), int(seen[-1])
    rest_until = t[first] + REST_S
    if sequence.go_t is not None:  # no one rises within 0.2 s of Go: a short rest before it is rest
        rest_until = max(t[first] + 0.3, min(rest_until, sequence.go_t + 0.2))
    start = _posture(t, s, lift, first, index_at(t, rest_until), 1, fps)
    if start is None:
        raise _Refused("the patient never stands up")
    end = _posture(t, s, lift, max(first, index_at(t, t[last] - REST_S)), last, -1, fps)
    if end is None or abs(end.seated - start.seated) > SAME_SEAT:
        raise _Refused("not seated again when the sequence ends")
    up = crossing(t, start.level, 0.5, first, 1)
    down = crossing(t, end.level, 0.5, last, -1)
    if up is None or down is None or down <= up:
        raise _Refused("the patient never stands up")
    for gap_start, gap_end in gaps(t, s.legs):
        if gap_end - gap_start > MAX_GAP_S and gap_end > up - 2.0 and gap_start < down + 2.0:
            raise _Refused(f"the patient left the picture from t={gap_start:.2f} to t={gap_end:.2f} s")

    found["onset_t"], stirred = _onset(t, s, start, first, up, fps)
    if stirred is not None and sequence.go_t is None:
        raise _Refused(f"the start is unclear: the patient moved at t={stirred:.2f} s before the rise (no go_t)")
    if t[last] - down < 0.6:
        raise _Refused("the sequence ends before the patient sits still")
    seated_t = crossing(t, end.level, max(3 * end.noise, SEATED_LEVEL), index_at(t, down), 1)
    if seated_t is None:
        raise _Refused("the patient does not sit still at the end")
    found["seated_t"] = _landing(t, end.level, down, seated_t)
    stood = crossing(t, start.level, 0.85, index_at(t, up), 1)
    sat = crossing(t, end.level, 0.85, index_at(t, down), -1)
    found["stood_t"] = stood if stood is not None else up
    found["sit_start_t"] = sat if sat is not None else down
    course = walk_course(t, s, found["stood_t"], found["sit_start_t"], fps, (start.rest, end.rest))
    quality.update(course.quality())
    _course_checks(course, found, reasons)


@record
class _Posture:
    """The hips' height over the ankles at one end of the sequence, scaled by the torso seen there
    (seated at rest), and ``level``: 0 at that seated height, 1 at the standing height nearest it."""

    seated: float
    noise: float
    level: np.ndarray
    rest: tuple[int, int]
    torso: float


def _posture(t: np.ndarray, s: Signals, lift: np.ndarray, a: int, b: int, way: int, fps: float) -> _Posture | None:
    """The posture read from the rest ``a``..``b`` (the start when ``way`` is 1, the end when -1);
    None when the patient never stands a clear :data:`MIN_RISE` higher than that rest."""
    torso = float(np.nanmedian(s.torso[a : b + 1]))
    rise = lift / torso
    seated = float(np.median(rise[a : b + 1]))
    noise = float(1.4826 * np.median(np.abs(rise[a : b + 1] - seated)))
    clear = np.flatnonzero(s.legs & (rise >= seated + MIN_RISE))
    if len(clear) == 0:
        return None
    # standing: the highest hips within 1.5 s after the rise (or before the descent), near the chair
    mark = int(clear[0] if way == 1 else clear[-1])
    other = index_at(t, t[mark] + 1.5 * way)
    lo, hi = min(mark, other), max(mark, other)
    standing = float(np.max(rise[lo : hi + 1]))
    scale = standing - seated
    return _Posture(seated=seated, noise=noise / scale, level=(rise - seated) / scale, rest=(a, b), torso=torso)


def _landing(t: np.ndarray, level: np.ndarray, down: float, near: float) -> float:
    """When the hips stop on the seat: the descent's speed falling below :data:`LANDED_SPEED` of its
    peak, within half a second of ``near`` (the hips near the seat's height; a slow descent gets
    there before it lands, a noisy one crosses its wider band early)."""
    speed = -np.gradient(level, t)
    a, b = index_at(t, down - 1.0), index_at(t, near + 0.5)
    peak = a + int(np.argmax(speed[a : b + 1]))
    landed = crossing(t, speed, LANDED_SPEED * float(speed[peak]), peak, 1)
    if landed is None or not near - 0.5 <= landed <= near + 0.5:
        return near
    return landed


def _onset(t: np.ndarray, s: Signals, start: _Posture, first: int, up: float, fps: float) -> tuple[float, float | None]:
    """The start of the movement that leads to standing (hips rising or the trunk leaving its rest),
    and when an earlier movement short of it was seen (None if none)."""
    rest_end = start.rest[1]
    shoulder = np.stack([fill_gaps(t, s.shoulder[:, k]) for k in range(2)], axis=1)
    rest_shoulder = np.median(shoulder[first : rest_end + 1], axis=0)
    moved = np.hypot(*(shoulder - rest_shoulder).T) / start.torso
    moved = smooth(moved, max(3, round(0.1 * fps)) | 1)
    rest_moved = moved[first : rest_end + 1]
    moved_noise = float(1.4826 * np.median(np.abs(rest_moved - np.median(rest_moved))))
    lean = smooth(fill_gaps(t, s.lean), max(3, round(0.3 * fps)) | 1)
    rest_lean = lean[first : rest_end + 1]
    lean_noise = float(1.4826 * np.median(np.abs(rest_lean - np.median(rest_lean))))
    motion = np.maximum.reduce(
        [
            start.level / max(4 * start.noise, ONSET_LEVEL),
            (moved - np.median(rest_moved)) / max(4 * moved_noise, ONSET_MOVED),
            (lean - np.median(rest_lean)) / max(4 * lean_noise, ONSET_LEAN),
        ]
    )
    # a clear movement first (above the rest's slow drift), then back to where it began: the last
    # moment, within 1.5 s before, that the signal was as low as at rest
    onset = crossing(t, motion, 1.0, index_at(t, up), -1)
    while onset is not None:
        earlier = index_at(t, onset)
        before = np.flatnonzero((motion[:earlier] > 1.0) & (t[:earlier] >= onset - HESITATION_S))
        if len(before) == 0 or before[-1] <= rest_end:
            break
        onset = crossing(t, motion, 1.0, int(before[-1]), -1)
    if onset is not None:
        clear = index_at(t, onset) + 1
        floor = max(float(np.median(motion[first : rest_end + 1])), 0.0) + ONSET_FLOOR
        quiet = crossing(t, motion, floor, clear, -1)
        if quiet is not None and quiet >= onset - 1.5:
            onset = quiet
    if onset is None:
        return float(t[first]), None
    # an earlier movement that did not lead to standing: the start cannot be told without Go
    # (held for half a second: a try a frontal view barely sees lasts that long, the rest's jitter
    # does not; the smoothing spreads the rise itself back, hence a second clear of it)
    sustained = smooth(motion, max(3, round(0.5 * fps)) | 1)
    early = np.flatnonzero((sustained > STIRRED) & (t > t[rest_end] + 0.25) & (t < onset - 1.0))
    return onset, float(t[early[0]]) if len(early) else None


def _course_checks(course: Course, found: dict[str, float], reasons: list[str]) -> None:
    if not course.walked:
        reasons.append("the patient stands but does not walk out")
        return
    found.update(course.times)
    if not course.returned:
        reasons.append("the patient does not come back to the chair")
    if not course.turn_seen:
        reasons.append("no turn seen at the far end")


def _phases(found: dict[str, float]) -> tuple[Phase, ...]:
    keys = ("onset_t", "stood_t", "turn_start_t", "turn_end_t", "back_t", "seated_t")
    if not all(key in found for key in keys):
        return ()
    return tuple(Phase(name, found[a], found[b]) for name, a, b in zip(PHASES, keys[:-1], keys[1:]))


def _implausible(phases: tuple[Phase, ...], go_t: float | None, onset: float | None, seated: float | None) -> list[str]:
    if not phases or onset is None or seated is None:
        return ["the phases of the course could not be told apart"]
    problems = [f"phase {p.name} ends before it starts" for p in phases if p.duration_s <= 0]
    sts = phases[0].duration_s
    if not SIT_TO_STAND_RANGE[0] <= sts <= SIT_TO_STAND_RANGE[1]:
        problems.append(f"a sit-to-stand of {sts:.2f} s is not plausible")
    start = go_t if go_t is not None else onset
    total = seated - start
    if not (TOTAL_RANGE[0] <= total <= TOTAL_RANGE[1]) or math.isnan(total):
        problems.append(f"a total of {total:.2f} s is not plausible")
    if go_t is not None and onset < go_t - 1.0:
        problems.append(f"the patient started {go_t - onset:.1f} s before Go")
    return problems

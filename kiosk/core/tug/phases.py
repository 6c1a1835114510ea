"""The walk between standing up and sitting down: out, turn, back, and whether it was seen whole.

The hips' place on the floor is read in torso lengths: across the image (a side view sees the
walk there) and away from the camera (a frontal view sees the body shrink and grow); their distance
from where the patient stood up covers both and an oblique view between. The far turn is where that
distance peaks; it was seen when the shoulders' width in the picture changes there (a body turning
shows its shoulders edge-on at some moment from any side) or their left-right order flips.
"""

from __future__ import annotations

import numpy as np

from basis import record
from kiosk.core.tug.signals import Signals, crossing, fill_gaps, index_at, smooth

#: a walk out shorter than this, in torso lengths (3 m is about six), is no walk
MIN_WALK = 2.5
#: back at the chair: ending within this share of the farthest distance from where the patient stood
RETURN_SHARE = 0.3
#: the turn starts and ends where the walking speed falls below this share of its peak
TURN_SPEED_SHARE = 0.3
#: a change of the shoulders' width (torso lengths) that shows a turn
TURN_WIDTH_CHANGE = 0.25


@record
class Course:
    """What the standing part of the sequence shows."""

    walked: bool
    returned: bool
    turn_seen: bool
    farthest: float
    times: dict[str, float]

    def quality(self) -> dict[str, object]:
        return {"turn_seen": self.turn_seen, "returned_to_chair": self.returned, "walked": round(self.farthest, 2)}


def walk_course(
    t: np.ndarray, s: Signals, stood: float, sitting: float, fps: float, rests: tuple[tuple[int, int], ...]
) -> Course:
    """The course between ``stood`` (standing reached) and ``sitting`` (the descent begins);
    ``rests`` are the frame ranges of the seated rest before and after (where the chair is)."""
    window = max(3, round(0.4 * fps)) | 1
    across = smooth(fill_gaps(t, s.across), window)
    depth = smooth(fill_gaps(t, s.depth), window)
    a, b = index_at(t, stood), index_at(t, sitting)
    if b - a < 3:
        return Course(walked=False, returned=False, turn_seen=False, farthest=0.0, times={})
    # the chair, seen from the seated rests (upright: a trunk leaning toward the camera looks short,
    # and so farther away, while the patient rises and sits)
    chairs = [np.array([np.median(across[i : j + 1]), np.median(depth[i : j + 1])]) for i, j in rests]
    distance = np.hypot(across - chairs[0][0], depth - chairs[0][1])
    inner_a, inner_b = index_at(t, stood + 0.5), index_at(t, sitting - 0.5)
    if inner_b - inner_a < 3:
        return Course(walked=False, returned=False, turn_seen=False, farthest=0.0, times={})
    far = inner_a + int(np.argmax(distance[inner_a : inner_b + 1]))
    farthest = float(distance[far])
    if farthest < MIN_WALK or far in (inner_a, inner_b):
        return Course(walked=False, returned=False, turn_seen=False, farthest=farthest, times={})
    same_chair = float(np.hypot(*(chairs[1] - chairs[0]))) <= max(1.0, RETURN_SHARE * farthest)
    returned = same_chair and float(distance[inner_b]) <= 1.5 * RETURN_SHARE * farthest

    speed = np.gradient(distance, t)
    out_peak = float(np.max(speed[a : far + 1]))
    back_peak = float(-np.min(speed[far : b + 1]))
    turn_start = crossing(t, speed, TURN_SPEED_SHARE * out_peak, far, -1) or float(t[far])
    turn_end = crossing(t, -speed, TURN_SPEED_SHARE * back_peak, far, 1) or float(t[far])
    back = crossing(t, -speed, TURN_SPEED_SHARE * back_peak, b, -1) or sitting
    times = {"turn_start_t": turn_start, "turn_end_t": turn_end, "back_t": min(back, sitting)}
    seen = _turn_seen(t, s, fps, (a, index_at(t, turn_start), index_at(t, turn_end), b))
    return Course(walked=True, returned=returned, turn_seen=seen, farthest=farthest, times=times)


def _turn_seen(t: np.ndarray, s: Signals, fps: float, marks: tuple[int, int, int, int]) -> bool:
    a, turn_a, turn_b, b = marks
    window = max(3, round(0.3 * fps)) | 1
    dx = smooth(fill_gaps(t, s.shoulder_dx), window)
    dz = smooth(fill_gaps(t, s.shoulder_dz), window)
    if not np.isfinite(dx).any():
        return False
    walking = np.concatenate([np.abs(dx[a : turn_a + 1]), np.abs(dx[turn_b : b + 1])])
    pad = round(0.5 * fps)
    turning = np.abs(dx[max(a, turn_a - pad) : min(b, turn_b + pad) + 1])
    if len(walking) and len(turning):
        usual = float(np.median(walking))
        if float(np.max(np.abs(turning - usual))) >= TURN_WIDTH_CHANGE:
            return True
    for side in (dx, dz):
        out, back = np.median(side[a : turn_a + 1]), np.median(side[turn_b : b + 1])
        if np.isfinite(out) and np.isfinite(back) and out * back < 0 and min(abs(out), abs(back)) >= 0.15:
            return True
    return False

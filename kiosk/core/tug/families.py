"""Synthetic Timed Up and Go sequences with known times, by family, for tests and the accuracy bench.

:func:`generate` (family, seed) gives a pose-landmarks sequence and its :class:`Truth`. Every draw
varies the person (1.50-1.90 m, build), the pace, the camera (side, frontal or oblique; 0.8-1.4 m
high; 55-75 degree lens; 640x480 or 1280x720; either walking direction) so that the analysis is not
tuned to one set-up. Families: normal, frail, hesitant, fps15, fps60, noisy, mirrored (the image
flipped, as a mirrored webcam gives it), walking_aid; negatives (the analysis must refuse them):
never_stands, stands_no_walk, leaves_frame, legs_cut. Pure and deterministic per seed.
"""

from __future__ import annotations

import math

import numpy as np

from basis import record
from kiosk.core.tug.body import Build, Camera, axes, skeleton
from kiosk.core.tug.landmarks import INDEX, PoseFrame, PoseSequence
from kiosk.core.tug.synth import Gait, Move, Timeline, render

POSITIVE = ("normal", "frail", "hesitant", "fps15", "fps60", "noisy", "mirrored", "walking_aid")
NEGATIVE = ("never_stands", "stands_no_walk", "leaves_frame", "legs_cut")
FAMILIES = POSITIVE + NEGATIVE
#: the true onset is when the trunk has leant 5 % of its way (1-3 degrees), the first movement a
#: person marking a video by hand sees (a minimum-jerk start is flat): this share of the lean's time
VISIBLE = 0.1893
_LOWER = [INDEX[f"{side}_{part}"] for side in ("left", "right") for part in ("knee", "ankle", "heel", "foot_index")]


@record
class Truth:
    """What a generated sequence shows: None times for the negatives."""

    family: str
    onset_t: float | None
    seated_t: float | None
    go_t: float | None
    phases: dict[str, tuple[float, float]]
    view: str

    @property
    def total_s(self) -> float | None:
        if self.seated_t is None or self.onset_t is None:
            return None
        return self.seated_t - (self.go_t if self.go_t is not None else self.onset_t)


def generate(family: str, seed: int) -> tuple[PoseSequence, Truth]:
    """One sequence of ``family`` (see :data:`FAMILIES`) drawn with ``seed``."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; one of {', '.join(FAMILIES)}")
    rng = np.random.default_rng([seed, FAMILIES.index(family)])
    slow = family in ("frail", "walking_aid")
    build = Build.of_height(rng.uniform(1.5, 1.9), rng.uniform(0.9, 1.1))
    facing = 0.0 if rng.random() < 0.5 else math.pi
    forward, _ = axes(facing)
    seat_h = 0.285 * build.height * rng.uniform(0.95, 1.1) + 0.05 * build.height
    feet_at = forward[[0, 2]] * build.thigh * 0.95
    far = forward[[0, 2]] * (3.2 if family != "leaves_frame" else 8.5)
    timeline = Timeline(start={"x": 0.0, "z": 0.0, "h": seat_h, "facing": facing, "lean": 0.0, "step": 0.0})
    timeline.add(Move("rest", rng.uniform(1.2, 2.5), planted=True))
    gait = _gait(rng, family)
    onset = _sit_to_stand(timeline, rng, family, build, feet_at, slow)
    stood = timeline.end
    if family == "stands_no_walk":
        timeline.add(Move("stand", rng.uniform(3.0, 6.0), {"step": (0.15, 0, 0.2)}))
    elif family != "never_stands":
        _course(timeline, rng, gait, feet_at, far, facing, slow, family == "leaves_frame")
    seated = None
    if family not in ("never_stands", "leaves_frame"):
        _sit_down(timeline, rng, seat_h, slow, build)
        seated = timeline.landing("sit")
    timeline.add(Move("rest", rng.uniform(1.0, 2.5), planted=True))
    fps = {"fps15": 15.0, "fps60": 60.0}.get(family, float(rng.choice([25.0, 30.0])))
    times = np.arange(0.0, timeline.end, 1.0 / fps)
    poses = render(timeline, build, gait, times, feet_at, facing)
    camera, view = _camera(rng, family, facing, build)
    go_t = max(0.05, onset - rng.uniform(0.25, 0.9)) if rng.random() < 0.6 and onset is not None else None
    frames = _frames(rng, family, camera, build, times, poses)
    sequence = PoseSequence(fps=fps, width=camera.width, height=camera.height, go_t=go_t, frames=frames)
    phases: dict[str, tuple[float, float]] = {}
    if seated is not None and "turn_start" in timeline.marks:
        m = timeline.marks
        phases = {
            "sit_to_stand": (onset, stood),
            "walk_out": (stood, m["turn_start"]),
            "turn": (m["turn_start"], m["turn_end"]),
            "walk_back": (m["turn_end"], m["back"]),
            "turn_and_sit": (m["back"], seated),
        }
    ok = family in POSITIVE
    truth = Truth(
        family=family,
        onset_t=onset if ok else None,
        seated_t=seated if ok else None,
        go_t=go_t,
        phases=phases,
        view=view,
    )
    return sequence, truth


def _gait(rng: np.random.Generator, family: str) -> Gait:
    if family == "walking_aid":
        return Gait(cadence=rng.uniform(1.1, 1.5), stride=rng.uniform(0.25, 0.4), lift=0.04, swing=0.0, aid=True)
    if family == "frail":
        return Gait(cadence=rng.uniform(1.2, 1.6), stride=rng.uniform(0.3, 0.45), lift=0.05, swing=0.15)
    return Gait(cadence=rng.uniform(1.7, 2.1), stride=rng.uniform(0.55, 0.75), lift=0.1, swing=0.35)


def _sit_to_stand(
    timeline: Timeline, rng: np.random.Generator, family: str, build: Build, feet_at: np.ndarray, slow: bool
) -> float:
    """Adds the hesitant tries (if any) and the rise; returns when the movement began."""
    tries = {"hesitant": int(rng.integers(1, 3)), "never_stands": int(rng.integers(1, 4))}.get(family, 0)
    seat_h = timeline.start["h"]
    onset = None
    for _ in range(tries):
        lean = rng.uniform(0.3, 0.6)
        lift = rng.uniform(0.0, 0.06) * build.height
        duration = rng.uniform(0.8, 1.5)
        begins = timeline.add(Move("try", duration, {"lean": (lean, 0, 0.5), "h": (seat_h + lift, 0.4, 0.7)}, True))
        onset = begins + VISIBLE * 0.5 * duration if onset is None else onset
        timeline.add(Move("back", rng.uniform(0.6, 1.2), {"lean": (0.0, 0, 1), "h": (seat_h, 0, 0.6)}, True))
        timeline.add(Move("pause", rng.uniform(0.4, 1.5), planted=True))
    if family == "never_stands":
        return timeline.end
    duration = rng.uniform(2.0, 4.0) if slow else rng.uniform(0.9, 1.6)
    lean = rng.uniform(0.6, 0.9) if slow else rng.uniform(0.4, 0.7)
    stand_h = 0.525 * build.height
    # the rise: trunk forward, then hips up and over the feet; the trunk comes upright after
    rise = {
        "lean": (lean, 0.0, 0.75),
        "h": (stand_h, 0.5, 1.0),
        "x": (float(feet_at[0]), 0.4, 1.0),
        "z": (float(feet_at[1]), 0.4, 1.0),
    }
    begins = timeline.add(Move("rise", duration * 0.6, rise, planted=True))
    onset = begins + VISIBLE * 0.45 * duration if onset is None else onset
    timeline.add(Move("upright", duration * 0.4, {"lean": (0.0, 0.0, 1.0)}, planted=True))
    return onset


def _course(
    timeline: Timeline,
    rng: np.random.Generator,
    gait: Gait,
    feet_at: np.ndarray,
    far: np.ndarray,
    facing: float,
    slow: bool,
    away: bool,
) -> None:
    speed = rng.uniform(0.35, 0.7) if slow else rng.uniform(0.95, 1.4)
    if rng.random() < 0.5:
        timeline.add(Move("pause", rng.uniform(0.1, 1.0 if slow else 0.4)))
    distance = float(np.hypot(*(far - feet_at)))
    walk = {"x": (float(far[0]), 0.0, 1.0), "z": (float(far[1]), 0.0, 1.0), "step": (1.0, 0.0, 0.2)}
    timeline.marks["turn_start"] = timeline.add(Move("out", distance / speed, walk)) + distance / speed
    if away:
        timeline.add(Move("gone", rng.uniform(3.0, 6.0)))
        return
    turn = rng.uniform(2.0, 4.0) if slow else rng.uniform(0.9, 1.6)
    way = math.pi if rng.random() < 0.5 else -math.pi
    timeline.add(Move("turn", turn, {"facing": (facing + way, 0, 1), "step": (0.35, 0, 0.3)}))
    timeline.marks["turn_end"] = timeline.end
    back = {"x": (float(feet_at[0]), 0.0, 1.0), "z": (float(feet_at[1]), 0.0, 1.0), "step": (1.0, 0.0, 0.2)}
    timeline.add(Move("back", distance / speed * rng.uniform(0.95, 1.1), back))
    timeline.marks["back"] = timeline.end
    turn = rng.uniform(1.8, 3.5) if slow else rng.uniform(0.9, 1.5)
    timeline.add(
        Move(
            "turn2",
            turn,
            {"facing": (facing + way + (math.pi if way < 0 else -math.pi), 0, 1), "step": (0.0, 0.5, 1.0)},
        )
    )


def _sit_down(timeline: Timeline, rng: np.random.Generator, seat_h: float, slow: bool, build: Build) -> None:
    duration = rng.uniform(2.0, 3.5) if slow else rng.uniform(1.0, 1.6)
    lean = rng.uniform(0.5, 0.8) if slow else rng.uniform(0.35, 0.6)
    targets = {
        "h": (seat_h - 0.03 * build.height, 0.0, 0.85),
        "x": (0.0, 0.0, 0.8),
        "z": (0.0, 0.0, 0.8),
        "lean": (lean, 0.0, 0.5),
        "step": (0.0, 0.0, 0.1),
    }
    timeline.add(Move("sit", duration, targets, planted=True, floor=seat_h))
    timeline.add(Move("settle", rng.uniform(0.4, 0.8), {"lean": (0.0, 0.0, 1.0)}, planted=True, floor=seat_h))


def _camera(rng: np.random.Generator, family: str, facing: float, build: Build) -> tuple[Camera, str]:
    views = ("side", "frontal", "oblique") if family != "leaves_frame" else ("side", "oblique")
    view = str(rng.choice(views))
    forward, left = axes(facing)
    middle = forward * 1.6
    width, height = (640, 480) if rng.random() < 0.5 else (1280, 720)
    fov = math.radians(rng.uniform(55, 75))
    vertical = 2 * math.atan(math.tan(fov / 2) * height / width)
    # far enough that the whole person fits, aimed at mid-height (with a slight tilt either way)
    needed = 0.62 * build.height / math.tan(vertical / 2)
    if view == "frontal":
        nearest = max(rng.uniform(2.5, 4.0), needed)
        spot = forward * (3.2 + nearest) + left * rng.uniform(-0.4, 0.4)
        target = np.zeros(3)
    else:
        angle = math.radians(rng.uniform(25, 60) if view == "oblique" else 90) * (1 if rng.random() < 0.5 else -1)
        reach = max(rng.uniform(3.8, 5.5) if view == "side" else rng.uniform(4.5, 6.5), needed + 1.0)
        nearest = reach - (1.0 if view == "side" else 0.0)
        spot = middle + reach * (forward * math.cos(angle) + left * math.sin(angle))
        target = middle
    to_target = target - spot
    yaw = math.atan2(to_target[2], to_target[0])
    high = rng.uniform(0.8, 1.4)
    pitch = math.atan2(high - 0.5 * build.height, nearest) + rng.uniform(-0.03, 0.03)
    position = np.array([spot[0], high, spot[2]])
    return Camera(position=position, yaw=yaw, pitch=pitch, fov=fov, width=width, height=height), view


def _frames(
    rng: np.random.Generator, family: str, camera: Camera, build: Build, times: np.ndarray, poses: list
) -> tuple[PoseFrame, ...]:
    noisy = family == "noisy"
    # landmark jitter in pixels of a 640-wide picture (MediaPipe's on a still person is 1-3 px there)
    pixel = (rng.uniform(3.0, 6.0) if noisy else rng.uniform(0.8, 2.0)) * camera.width / 640
    drop = 0.06 if noisy else 0.005
    has_z = rng.random() < 0.7
    crop = None
    if family == "legs_cut":  # the picture's lower edge between the seated hips and knees
        first = camera.project(skeleton(build, poses[0]))
        hip_y, knee_y = first[INDEX["left_hip"], 1], first[[INDEX["left_knee"], INDEX["right_knee"]], 1].max()
        crop = hip_y + rng.uniform(0.3, 0.7) * (knee_y - hip_y) + 0.02
    frames = []
    wobble = np.zeros((33, 2))
    for t, pose in zip(times, poses):
        world = skeleton(build, pose)
        seen = camera.project(world)
        depth = camera.depth(world)
        wobble = 0.9 * wobble + rng.normal(0, pixel * 0.2, (33, 2))  # slow drift, about half the jitter
        seen[:, 0] += (rng.normal(0, pixel, 33) + wobble[:, 0]) / camera.width
        seen[:, 1] += (rng.normal(0, pixel, 33) + wobble[:, 1]) / camera.height
        if noisy and rng.random() < 0.04:
            jump = rng.choice(33, size=int(rng.integers(1, 6)), replace=False)
            seen[jump, :2] += rng.normal(0, 40, (len(jump), 2)) / np.array([camera.width, camera.height])
        if family == "mirrored":
            seen[:, 0] = 1.0 - seen[:, 0]
        if crop is not None:
            # zoomed onto the upper body: what was at ``bottom`` of the picture is now its lower edge
            seen[:, 1] = seen[:, 1] / crop
            seen[:, 0] = 0.5 + (seen[:, 0] - 0.5) / crop
        visibility = rng.uniform(0.9, 0.999, 33)
        hips_depth = (depth[INDEX["left_hip"]] + depth[INDEX["right_hip"]]) / 2
        visibility[depth > hips_depth + 0.07] = rng.uniform(0.45, 0.9, int(np.sum(depth > hips_depth + 0.07)))
        if family == "walking_aid":
            visibility[_LOWER] *= rng.uniform(0.55, 1.0, len(_LOWER))
        outside = (seen[:, 0] < 0) | (seen[:, 0] > 1) | (seen[:, 1] < 0) | (seen[:, 1] > 1)
        visibility[outside] = rng.uniform(0.02, 0.3, int(outside.sum()))
        hips = seen[[INDEX["left_hip"], INDEX["right_hip"]], :2].mean(axis=0)
        gone = not (0 <= hips[0] <= 1 and 0 <= hips[1] <= 1)
        if crop is not None and not gone:
            visibility[[INDEX["left_hip"], INDEX["right_hip"]]] = rng.uniform(0.95, 0.99, 2)
        if gone or rng.random() < drop:
            frames.append(PoseFrame(t=float(t), landmarks=None))
            continue
        z = seen[:, 2] + rng.normal(0, 0.02, 33) if has_z else np.zeros(33)
        points = tuple((float(seen[i, 0]), float(seen[i, 1]), float(z[i]), float(visibility[i])) for i in range(33))
        frames.append(PoseFrame(t=round(float(t), 4), landmarks=points))
    return tuple(frames)

"""Scripted movements of the body model: a timeline of moves, rendered to world poses with known times.

A :class:`Timeline` is a list of :class:`Move` s; each move takes some channels of the body (hips on
the floor ``x``, ``z``, hip height ``h``, ``facing``, trunk ``lean``, stepping ``step``) from where
the last move left them to new values along minimum-jerk curves (Flash & Hogan 1985), each over its
own share of the move. The sit-down move aims a little below the seat and stops at it, so the hips
land with some speed as a person's do; the moment they land is the true ``seated_t``. Pure numpy;
the families and the camera are in :mod:`kiosk.core.tug.families`.
"""

from __future__ import annotations

import math
from dataclasses import field

import numpy as np

from basis import record
from kiosk.core.tug.body import Build, Pose, axes

CHANNELS = ("x", "z", "h", "facing", "lean", "step")


def min_jerk(share: float) -> float:
    """The minimum-jerk path from 0 to 1 at ``share`` of the way (clipped to [0, 1])."""
    s = min(1.0, max(0.0, share))
    return s * s * s * (10 - 15 * s + 6 * s * s)


@record
class Move:
    """One movement: ``duration`` seconds, each named channel going to its value over the share
    (start, end) of the move; ``planted``: feet on their chair-front marks (else walking feet);
    ``floor``: the hips stop at this height (the seat) on their way down."""

    label: str
    duration: float
    targets: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    planted: bool = False
    floor: float | None = None


@record
class Timeline:
    """Moves from a starting state; ``marks`` collects named true times as moves are added."""

    start: dict[str, float]
    moves: list[Move] = field(default_factory=list)
    marks: dict[str, float] = field(default_factory=dict)

    @property
    def end(self) -> float:
        return sum(move.duration for move in self.moves)

    def add(self, move: Move) -> float:
        """Append ``move``; returns the time it starts."""
        begins = self.end
        self.moves.append(move)
        return begins

    def state(self, t: float) -> tuple[dict[str, float], Move]:
        """The channels at time ``t`` and the move under way."""
        values = dict(self.start)
        began = 0.0
        for move in self.moves:
            if t < began + move.duration or move is self.moves[-1]:
                share = (t - began) / move.duration if move.duration > 0 else 1.0
                now = dict(values)
                for name, (target, a, b) in move.targets.items():
                    now[name] = values[name] + (target - values[name]) * min_jerk((share - a) / max(b - a, 1e-9))
                if move.floor is not None:
                    now["h"] = max(now["h"], move.floor)
                return now, move
            for name, (target, _, _) in move.targets.items():
                values[name] = target
            if move.floor is not None:
                values["h"] = max(values["h"], move.floor)
            began += move.duration
        return values, self.moves[-1]

    def landing(self, label: str) -> float:
        """When the hips reach the floor of the move called ``label`` (1 ms resolution)."""
        began = 0.0
        for move in self.moves:
            if move.label == label and move.floor is not None:
                for step in range(int(move.duration * 1000) + 1):
                    t = began + step / 1000
                    if self.state(t)[0]["h"] <= move.floor + 1e-9:
                        return t
            began += move.duration
        raise ValueError(f"no move {label!r} with a floor")


@record
class Gait:
    """How the person walks: steps a second, step length (m), foot lift (m), arm swing (rad), aid."""

    cadence: float
    stride: float
    lift: float
    swing: float
    aid: bool = False


def render(
    timeline: Timeline, build: Build, gait: Gait, times: np.ndarray, feet_at: np.ndarray, seated_facing: float
) -> list[Pose]:
    """The body's pose at each of ``times``; ``feet_at`` is the chair-front point (x, z) where the
    feet rest while planted."""
    poses: list[Pose] = []
    phase, last = 0.0, 0.0
    ankle_height = 0.039 * build.height
    for t in times:
        values, move = timeline.state(float(t))
        phase += math.pi * gait.cadence * values["step"] * (float(t) - last)
        last = float(t)
        hips = np.array([values["x"], values["h"], values["z"]])
        if move.planted:
            forward, left = axes(seated_facing)
            base = np.array([feet_at[0], ankle_height, feet_at[1]])
            ankles = (base + left * build.hip_width / 2, base - left * build.hip_width / 2)
        else:
            forward, left = axes(values["facing"])
            ankles = tuple(
                np.array([values["x"], ankle_height, values["z"]])
                + way * left * build.hip_width / 2
                + forward * 0.5 * gait.stride * values["step"] * math.sin(phase + shift)
                + np.array([0.0, gait.lift * values["step"] * max(0.0, math.cos(phase + shift)), 0.0])
                for way, shift in ((1, 0.0), (-1, math.pi))
            )
        bob = 0.012 * build.height * values["step"] * abs(math.sin(phase))
        hips = hips - np.array([0.0, bob, 0.0])
        swing = gait.swing * values["step"] * math.sin(phase + math.pi)
        poses.append(
            Pose(
                hips=hips,
                facing=values["facing"],
                lean=values["lean"],
                ankles=(ankles[0], ankles[1]),
                swing=swing,
                aid=gait.aid and not move.planted,
            )
        )
    return poses

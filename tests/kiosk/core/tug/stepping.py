"""Running a Timed Up and Go step over a landmark sequence on a simulated clock (tests' helper)."""

from __future__ import annotations

from typing import Any

from kiosk.core.clock import SimClock
from kiosk.core.tug.landmarks import PoseSequence
from kiosk.core.tug.step import TugSettings, TugStage, TugStep


def run(
    sequence: PoseSequence, go_t: float, settings: TugSettings | None = None
) -> tuple[TugStep, list[tuple[float, dict[str, Any]]], SimClock]:
    """Feed ``sequence`` through a step on a simulated clock, staff confirming at once and "Go" at ``go_t``."""
    clock = SimClock()
    published: list[tuple[float, dict[str, Any]]] = []
    step = TugStep(clock, lambda t, values: published.append((t, dict(values))), walk_up=False, settings=settings)
    step.confirm_staff("nurse-7")
    for frame in sequence.frames:
        if step.stage is TugStage.READY and frame.t >= go_t:
            clock.set(go_t)
            step.go()
        clock.set(frame.t)
        step.frame(frame.t, frame.landmarks, sequence.width, sequence.height)
    step.finish()
    return step, published, clock


def go_of(sequence: PoseSequence, onset: float) -> float:
    return sequence.go_t if sequence.go_t is not None else onset - 0.5

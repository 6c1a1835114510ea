"""From the camera's thread to a Timed Up and Go step: ``on_pose`` readings queued, drained on the
thread that owns the step (the UI's), since the step, like all of ``kiosk.core``, has no locks.

The camera's frame times and the kiosk's :class:`~kiosk.core.clock.SystemClock` are both
``time.monotonic``, so a step's "Go" and the frames share one clock.
"""

from __future__ import annotations

import threading
from collections import deque

from kiosk.camera.channel import PoseReading
from kiosk.core.tug.step import TugStep

#: readings kept at most (a minute at 30 fps): a step not drained must not grow without bound
MAX_READINGS = 1800


class PoseFeed:
    """An ``on_pose`` listener (camera thread) whose readings :meth:`into` hands to a step."""

    def __init__(self, max_readings: int = MAX_READINGS) -> None:
        self._readings: deque[PoseReading] = deque(maxlen=max_readings)
        self._lock = threading.Lock()

    def __call__(self, reading: PoseReading) -> None:
        with self._lock:
            self._readings.append(reading)

    def clear(self) -> None:
        """Drop the readings not handed over (no test is under way: nothing keeps them)."""
        with self._lock:
            self._readings.clear()

    def into(self, step: TugStep, before: float | None = None) -> int:
        """Feed the readings so far (only those earlier than ``before`` when given; the rest wait)
        to ``step``, oldest first; returns how many."""
        with self._lock:
            taken = []
            while self._readings and (before is None or self._readings[0].t < before):
                taken.append(self._readings.popleft())
        for reading in taken:
            step.frame(reading.t, reading.landmarks, reading.width, reading.height)
        return len(taken)

"""Where the session core gets its time from.

The session never calls ``time`` itself: it is handed a :class:`Clock`. The kiosk uses
:class:`SystemClock`; tests and scripted replays use :class:`SimClock`, which only moves when told
to, so a 20-minute session replays in milliseconds and never sleeps.
"""

from __future__ import annotations

import time
from datetime import UTC, datetime, timedelta
from typing import Protocol


class Clock(Protocol):
    """A source of time for the session core."""

    def now(self) -> float:
        """Monotonic seconds; only differences between two readings mean anything."""

    def wall(self) -> datetime:
        """The current date and time in UTC, for stored records."""


class SystemClock:
    """The real clock: ``time.monotonic`` for durations, the system time for records."""

    def now(self) -> float:
        """Monotonic seconds from ``time.monotonic``."""
        return time.monotonic()

    def wall(self) -> datetime:
        """The system's current UTC time."""
        return datetime.now(UTC)


#: the date a simulated clock's zero corresponds to, so replays store reproducible timestamps
SIM_EPOCH = datetime(2026, 1, 1, tzinfo=UTC)


class SimClock:
    """A simulated clock that moves only when :meth:`advance` or :meth:`set` is called."""

    def __init__(self, start: float = 0.0, epoch: datetime = SIM_EPOCH) -> None:
        self._now = float(start)
        self._epoch = epoch

    def now(self) -> float:
        """The simulated time in seconds."""
        return self._now

    def wall(self) -> datetime:
        """The epoch plus the simulated time."""
        return self._epoch + timedelta(seconds=self._now)

    def advance(self, seconds: float) -> None:
        """Move the clock forward by ``seconds`` (never backwards)."""
        if seconds < 0:
            raise ValueError(f"a clock cannot go back in time (advance by {seconds})")
        self._now += seconds

    def set(self, t: float) -> None:
        """Move the clock to time ``t``, which must not be earlier than now."""
        if t < self._now:
            raise ValueError(f"a clock cannot go back in time (from {self._now} to {t})")
        self._now = float(t)

"""Timers on the engine's clock: ``timer T := 1 minutes`` (Esper ``timer:interval``) and
``timer T := schedule("…")`` (Esper ``timer:at``).

Nothing here reads the wall clock: a timer's due time is computed from the times the engine is given,
so a replay fires every timer at the same instants however fast it runs.

Meaning (as the engine runs it):

* an interval timer fires ``interval`` seconds after it starts, then every ``interval`` seconds;
  ``onetime`` fires once and stops; ``offset d`` delays every firing by d (so the first one comes
  ``interval + d`` after the start);
* a schedule fires at every calendar instant its fields match (shifted by ``offset``); engine time t is
  the calendar time ``origin + t`` seconds since 1970-01-01 UTC (``Engine(origin=…)``);
* a timer starts with the engine unless declared ``paused``; ``starts T`` restarts it from the action's
  time, ``stops T`` halts it keeping what was left of its interval, ``resumes T`` goes on from there
  (a timer never started is started).

Schedule strings follow Esper's ``timer:at`` parameters: ``"minutes, hours, days of month, months,
days of week[, seconds]"``; each field is ``*``, ``*/n`` (every n), a number, ``a:b`` (a range) or a
list in brackets ``[0, 30]``. Days of week count from 0 = Sunday. A missing seconds field means 0.
"""

from __future__ import annotations

import re
from datetime import UTC, datetime, timedelta

from basis.errors import KioskError
from qos.model import Schedule, Timer

_FIELDS = (
    ("minutes", 0, 59),
    ("hours", 0, 23),
    ("days", 1, 31),
    ("months", 1, 12),
    ("weekdays", 0, 6),
    ("seconds", 0, 59),
)
#: how far ahead a schedule is searched (a schedule matching nothing in 8 years never fires: Feb 30)
_HORIZON_DAYS = 8 * 366


class ScheduleError(KioskError, ValueError):
    """A schedule string that does not say when to fire."""


def _split(text: str) -> list[str]:
    fields, depth, current = [], 0, ""
    for char in text:
        depth += char == "["
        depth -= char == "]"
        if char == "," and depth == 0:
            fields.append(current.strip())
            current = ""
        else:
            current += char
    fields.append(current.strip())
    return fields


def _field(text: str, name: str, low: int, high: int) -> frozenset[int]:
    items = _split(text[1:-1]) if text.startswith("[") and text.endswith("]") else [text]
    values: set[int] = set()
    for item in items:
        if item == "*":
            values.update(range(low, high + 1))
        elif match := re.fullmatch(r"\*/(\d+)", item):
            step = int(match[1])
            if step < 1:
                raise ScheduleError(f"the step of {name} must be at least 1")
            values.update(range(low, high + 1, step))
        elif match := re.fullmatch(r"(\d+)(?::(\d+))?", item):
            first, last = int(match[1]), int(match[2] or match[1])
            if not (low <= first <= last <= high):
                raise ScheduleError(f"{name} go from {low} to {high}, not {item}")
            values.update(range(first, last + 1))
        else:
            raise ScheduleError(f"cannot read {item!r} as {name} (*, */n, n, a:b or [a, b])")
    return frozenset(values)


def parse_schedule(text: str) -> Schedule:
    """Read an Esper ``timer:at`` schedule; raises :class:`ScheduleError` saying what is wrong."""
    fields = _split(text)
    if len(fields) not in (5, 6) or not all(fields):
        raise ScheduleError(
            f"expected 5 or 6 comma-separated fields (minutes, hours, days, months, weekdays"
            f"[, seconds]), found {len(fields)}"
        )
    if len(fields) == 5:
        fields.append("0")
    sets = [_field(text, name, low, high) for text, (name, low, high) in zip(fields, _FIELDS)]
    return Schedule(text, *sets)


def next_match(schedule: Schedule, after: float, origin: float) -> float | None:
    """Engine time of the first instant strictly after ``after`` the schedule matches (None: never, or
    beyond the calendar's year 9999)."""
    try:
        return _next_match(schedule, after, origin)
    except (OverflowError, ValueError, OSError):
        return None


def _next_match(schedule: Schedule, after: float, origin: float) -> float | None:
    moment = datetime.fromtimestamp(origin + after, UTC).replace(microsecond=0) + timedelta(seconds=1)
    day = moment.replace(hour=0, minute=0, second=0)
    for _ in range(_HORIZON_DAYS):
        if day.month in schedule.months and day.day in schedule.days and (day.weekday() + 1) % 7 in schedule.weekdays:
            for hour in sorted(schedule.hours):
                for minute in sorted(schedule.minutes):
                    for second in sorted(schedule.seconds):
                        candidate = day.replace(hour=hour, minute=minute, second=second)
                        if candidate >= moment:
                            return candidate.timestamp() - origin
        day += timedelta(days=1)
    return None


class TimerClock:
    """One timer's run-time state: whether it runs and when it is next due."""

    def __init__(self, timer: Timer, origin: float):
        self.timer = timer
        self.origin = origin
        #: engine time of the next firing; None while stopped
        self.due: float | None = None
        #: what was left of the interval when it was stopped
        self.remaining: float | None = None

    def _first_after(self, t: float) -> float | None:
        timer = self.timer
        if timer.schedule is not None:
            match = next_match(timer.schedule, t - timer.offset, self.origin)
            return None if match is None else match + timer.offset
        assert timer.interval is not None  # a timer without a schedule has an interval (the parser checks)
        return t + timer.interval + timer.offset

    def start(self, t: float) -> None:
        """(Re)start from time t."""
        self.due, self.remaining = self._first_after(t), None

    def stop(self, t: float) -> None:
        """Halt, keeping what is left until the next firing."""
        if self.due is not None:
            self.remaining, self.due = max(self.due - t, 0.0), None

    def resume(self, t: float) -> None:
        """Go on after a stop; a timer never started (or a schedule) starts."""
        if self.due is not None:
            return
        if self.remaining is not None and self.timer.schedule is None:
            self.due, self.remaining = t + self.remaining, None
        else:
            self.start(t)

    def firings_until(self, t: float) -> float:
        """How many times the timer would fire up to t at most (to refuse a jump that would take ages)."""
        if self.due is None or self.due > t:
            return 0
        if self.timer.onetime:
            return 1
        schedule = self.timer.schedule
        spacing = self.timer.interval or (1.0 if schedule is not None and len(schedule.seconds) > 1 else 60.0)
        return (t - self.due) / spacing + 1

    def fired(self) -> None:
        """The timer fired at its due time: plan the next firing."""
        timer, at = self.timer, self.due
        assert at is not None  # fired only when due
        if timer.onetime:
            self.due = None
        elif timer.schedule is not None:
            match = next_match(timer.schedule, at - timer.offset, self.origin)
            self.due = None if match is None else match + timer.offset
        else:
            assert timer.interval is not None  # neither one-time nor scheduled: periodic
            self.due = at + timer.interval

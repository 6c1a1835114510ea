"""The attempt clock: the session's one pending time-out and the freezes that stop it.

Nothing happens on its own: a driver calls ``Session.poll`` once the clock reaches
:meth:`AttemptClock.next_deadline`, and every operation first lets due time-outs fire (each at its
own due time, not at the time of the call). Pause, call-doctor and person lost freeze the clock;
once the last freeze is lifted an open attempt gets at least the largest grace any of them asked
for. Beside it runs one *watch*, a time-out no freeze stops (how long the patient has been away).
"""

from __future__ import annotations

from collections.abc import Iterator
from collections.abc import Set as AbstractSet

from basis import record
from kiosk.core.clock import Clock


@record(frozen=False)
class Timer:
    """The one pending time-out: ``due`` (clock time) while running, ``remaining`` while frozen."""

    #: "open" (next attempt 1), "attempt" (window ends), "finish" (the summary), and the others
    #: the session schedules (see ``Router.fire`` in :mod:`kiosk.core.session.routing`)
    kind: str
    due: float | None
    remaining: float = 0.0


class AttemptClock:
    """Session time and its single time-out. ``origin`` is the clock time of session time 0."""

    def __init__(self, clock: Clock, origin: float) -> None:
        self.clock = clock
        self.origin = origin
        self.timer: Timer | None = None
        #: why the clock is stopped ("paused", "doctor", "away", ...); empty while it runs
        self.freezes: set[str] = set()
        self._grace = 0.0
        #: the watch: (kind, clock time due), a time-out that runs while the clock is frozen
        self.watch: tuple[str, float] | None = None

    def t(self, clock_time: float) -> float:
        """Session time of a clock time."""
        return clock_time - self.origin

    def now(self) -> float:
        """Session time now."""
        return self.t(self.clock.now())

    @property
    def kind(self) -> str | None:
        """The pending time-out's kind, or None."""
        return self.timer.kind if self.timer is not None else None

    @property
    def frozen(self) -> bool:
        """Whether anything stops the clock."""
        return bool(self.freezes)

    @property
    def paused(self) -> bool:
        """Stopped by the patient's pause."""
        return "paused" in self.freezes

    @property
    def halted(self) -> bool:
        """Stopped by a call for the doctor, until a clinician (or the patient) carries on."""
        return "doctor" in self.freezes

    def set(self, kind: str, start_t: float, seconds: float) -> None:
        """Replace the pending time-out by one ``seconds`` after session time ``start_t``."""
        if self.freezes:
            self.timer = Timer(kind, None, seconds)
        else:
            self.timer = Timer(kind, self.origin + start_t + seconds)

    def cancel(self) -> None:
        """Drop the pending time-out."""
        self.timer = None

    def watch_for(self, kind: str, start_t: float, seconds: float) -> None:
        """Set the watch: ``kind`` falls due ``seconds`` after session time ``start_t``, frozen or not."""
        self.watch = (kind, self.origin + start_t + seconds)

    def unwatch(self, kind: str) -> None:
        """Drop the watch if it is of ``kind``."""
        if self.watch is not None and self.watch[0] == kind:
            self.watch = None

    def take(self) -> tuple[str, float] | None:
        """Drop the pending time-out and return its kind and the seconds it had left, to be put
        back with :meth:`set` (a question interrupted by "Shall I call the nurse?"); None if none."""
        timer, self.timer = self.timer, None
        if timer is None:
            return None
        return timer.kind, timer.remaining if timer.due is None else max(0.0, timer.due - self.clock.now())

    def due(self, now: float, inclusive: bool) -> Iterator[tuple[str, float]]:
        """Take the time-outs due by clock time ``now`` in order, as (kind, session time due): the
        pending time-out and the watch, the earlier first (the time-out first at one instant).

        The caller acts on each before the next is looked at (acting may set another timer).
        """

        def ripe(due: float) -> bool:
            return due < now or (inclusive and due == now)

        while True:
            timer_due = self.timer.due if self.timer is not None else None
            watch_due = self.watch[1] if self.watch is not None else None
            if timer_due is not None and ripe(timer_due) and (watch_due is None or timer_due <= watch_due):
                assert self.timer is not None
                kind, self.timer = self.timer.kind, None
                yield kind, self.t(timer_due)
            elif watch_due is not None and ripe(watch_due):
                assert self.watch is not None
                kind, self.watch = self.watch[0], None
                yield kind, self.t(watch_due)
            else:
                return

    def freeze(self, reason: str) -> None:
        """Stop the clock for ``reason`` (the first freeze keeps what was left)."""
        if not self.freezes and self.timer is not None and self.timer.due is not None:
            self.timer.remaining = max(0.0, self.timer.due - self.clock.now())
            self.timer.due = None
        self.freezes.add(reason)

    def unfreeze(self, reasons: AbstractSet[str], grace: float) -> bool:
        """Lift freezes; once none is left the attempt gets at least the largest grace seen.

        False if none of ``reasons`` was in force (nothing changed).
        """
        if not reasons & self.freezes:
            return False
        self.freezes -= reasons
        self._grace = max(self._grace, grace)
        if not self.freezes:
            if self.timer is not None and self.timer.due is None:
                remaining = self.timer.remaining
                if self.timer.kind == "attempt":
                    remaining = max(remaining, self._grace)
                self.timer.due = self.clock.now() + remaining
            self._grace = 0.0
        return True

    def at_least(self, seconds: float) -> None:
        """Leave at least ``seconds`` on a running time-out (hearing a question again takes time)."""
        if self.timer is not None and self.timer.due is not None:
            self.timer.due = max(self.timer.due, self.clock.now() + seconds)

    def attempt_remaining(self) -> float | None:
        """Seconds left on an attempt window (frozen or running), or None if none is pending."""
        if self.timer is None or self.timer.kind != "attempt":
            return None
        if self.timer.due is None:
            return self.timer.remaining
        return max(0.0, self.timer.due - self.clock.now())

    def attempt_deadline(self) -> float | None:
        """Session time a running attempt window ends, or None."""
        if self.timer is not None and self.timer.kind == "attempt" and self.timer.due is not None:
            return self.t(self.timer.due)
        return None

    def next_deadline(self) -> float | None:
        """Clock time of the next time-out (or the watch), or None if none is running."""
        dues = [self.timer.due if self.timer is not None else None, self.watch[1] if self.watch is not None else None]
        return min((d for d in dues if d is not None), default=None)

"""Person seen / not seen, debounced: what the camera tells the session about presence.

A patient who bends for a moment or a frame the model misses must not count as leaving, and a
passer-by glimpsed for a frame must not count as the patient back. :class:`Presence` changes state
only after ``away_s`` without a person (or ``back_s`` with one), on the frames' own clock (the
camera's timestamps, or a replay's): no timers, no threads.
"""

from __future__ import annotations

#: seconds without a person before the patient counts as away
AWAY_S = 3.0
#: seconds with a person before the patient counts as back
BACK_S = 1.0


class Presence:
    """Feed it every frame's (time, person found); it returns True / False when presence changes."""

    def __init__(self, *, away_s: float = AWAY_S, back_s: float = BACK_S, present: bool | None = None) -> None:
        self.away_s, self.back_s = away_s, back_s
        #: the debounced state; None until the first decision
        self.present: bool | None = present
        self._since: float | None = None  # when the frames began to disagree with the state

    def feed(self, t: float, seen: bool) -> bool | None:
        """The new state if this frame changes it, else None."""
        if seen == self.present:
            self._since = None
            return None
        if self._since is None:
            self._since = t
        if t - self._since >= (self.back_s if seen else self.away_s):
            self.present, self._since = seen, None
            return seen
        return None

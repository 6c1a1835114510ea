"""Attendance: whether someone is there to answer, and what the kiosk does when nobody is.

* Presence (:class:`~kiosk.core.channels.Presence`, from the camera or from staff's "Patient
  away"/"back"): a person not seen publishes ``PersonDetected: false`` and freezes the attempt
  clock, so no attempt times out while the patient is away; seen again, ``PersonDetected: true``
  and the attempt goes on with the time it had left (at least ``person_back_grace_s``). Only a
  change is published; a report that changes nothing is logged as ignored.
* Away too long: ``away_alert_after_s`` after the patient left (the site's setting; the clock is
  frozen, so a *watch* counts it) the session logs ``away_alert``, an alert row for the ward.
* Unattended: after ``unattended_after`` scored questions in a row went unanswered (both attempts
  ran out) the session logs ``unattended`` (an alert row) and waits for a touch ("Are you still
  there? Touch the screen to go on.") instead of asking the next question. A touch, a key or the
  remote goes on (never a voice: talk in the room is no proof anyone is at the screen); the ward's
  "Continue" is logged and the kiosk still waits for that touch.

Why here and not in :mod:`.incidents`: these are about whether anyone is at the kiosk at all,
and each has a site setting (:class:`Watching`); pause and call-doctor are the patient's own doing.
"""

from __future__ import annotations

from collections.abc import Callable

from basis import record
from kiosk.core.channels import Channel, ChannelInput, Presence, PresenceSource
from kiosk.core.session.events import (
    AwayAlert,
    IgnoreReason,
    PersonBack,
    PersonLost,
    Unattended,
    UnattendedEnded,
)
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock

#: the watch's kind while the patient is away (see ``Router.fire``)
AWAY_ALERT = "away_alert"


@record
class Watching:
    """What a site sets about a patient who is not there (``kiosk.config``: ``away_alert_after_s``,
    ``unattended_after``). ``None`` switches either off, as a session made without it has them."""

    #: seconds away before the ward is alerted
    away_alert_after_s: float | None = 60.0
    #: unanswered questions in a row before the kiosk waits for a touch (and alerts the ward)
    unattended_after: int | None = 2


class Attendance:
    """Presence reports, the away alert and the wait for a touch. ``go_on(t)`` opens the next
    question (or the summary) once someone touched; ``ask_again(t)`` asks an open question again."""

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        watching: Watching | None,
        go_on: Callable[[float], None],
        ask_again: Callable[[float], None],
    ) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self.watching = watching or Watching(None, None)
        self._go_on = go_on
        self._ask_again = ask_again

    # -- presence ---------------------------------------------------------------------------------

    def presence(self, t: float, report: Presence) -> None:
        """A presence source's report (published only when it changes something)."""
        if report.seen:
            self.back(t, report.source, report.detail)
        else:
            self.lost(t, report.source, report.detail)

    def lost(self, t: float, source: PresenceSource, detail: str = "") -> None:
        """The patient is not in front of the kiosk: the clock stops; the away alert is set."""
        state, out = self.state, self.out
        if not state.person_present:
            out.ignore(t, None, IgnoreReason.PERSON_ALREADY_LOST, f"person_lost ({source.value})")
            return
        state.person_present = False
        if not state.started():
            return
        out.context(t, {"PersonDetected": False})
        out.log(t, "person_lost", _said(source, detail))
        self.timers.freeze("away")
        self.prompts.update_listening(t)
        after = self.watching.away_alert_after_s
        if after is not None:
            self.timers.watch_for(AWAY_ALERT, t, after)
        out.emit(PersonLost(t, source))

    def back(self, t: float, source: PresenceSource, detail: str = "") -> None:
        """The patient is back: the attempt goes on with what it had left (at least the grace)."""
        state, out, timers = self.state, self.out, self.timers
        if state.person_present:
            out.ignore(t, None, IgnoreReason.PERSON_NOT_LOST, f"person_back ({source.value})")
            return
        state.person_present = True
        timers.unwatch(AWAY_ALERT)
        if not state.started():
            return
        out.context(t, {"PersonDetected": True})
        out.log(t, "person_back", _said(source, detail))
        if timers.unfreeze({"away"}, state.timing.person_back_grace_s):
            self.prompts.update_listening(t)
        out.emit(PersonBack(t, timers.attempt_deadline(), source))
        if state.unattended and not timers.frozen:
            self.prompts.unattended(t)  # still waiting for a touch: say so again to whoever came
        else:
            self._ask_again(t)

    def away_too_long(self, t: float) -> None:
        """The watch ran out while the patient was away: alert the ward (once per absence)."""
        after = self.watching.away_alert_after_s
        if self.state.person_present or not self.state.started() or after is None:
            return
        self.out.log(t, "away_alert", f"{after:g}")
        self.out.emit(AwayAlert(t, after))

    # -- unattended ---------------------------------------------------------------------------------

    def not_answered(self, t: float) -> bool:
        """A scored question went unanswered: True when that makes the kiosk wait for a touch
        (the caller then neither says "Let us go on" nor opens the next question)."""
        state = self.state
        state.not_answered_run += 1
        limit = self.watching.unattended_after
        if not limit or state.not_answered_run < limit:
            return False
        state.unattended = True
        self.out.log(t, "unattended", str(state.not_answered_run))
        self.out.emit(Unattended(t, state.not_answered_run))
        self.prompts.unattended(t)
        self.prompts.update_listening(t)
        return True

    def touched(self, t: float, event: ChannelInput) -> None:
        """An input while the kiosk waits for a touch: a touch, key or remote goes on; a voice does not."""
        if event.channel is Channel.VOICE:
            self.out.ignore(t, event, IgnoreReason.WAITING_FOR_TOUCH)
            return
        if self.timers.paused:
            self.out.ignore(t, event, IgnoreReason.PAUSED)
            return
        state = self.state
        state.unattended = False
        state.not_answered_run = 0
        self.out.log(t, "unattended_ended", event.channel.value)
        self.out.emit(UnattendedEnded(t, event.channel))
        self._go_on(t)

    def staff_continue(self, t: float) -> None:
        """Staff's "Continue" while the kiosk waits for a touch: logged; it still waits, so the test
        never asks on with nobody there."""
        self.out.log(t, "continue_waits_for_touch")


def _said(source: PresenceSource, detail: str) -> str:
    """The log's detail: the source, and what it said ("camera: no person in 15 frames")."""
    return f"{source.value}: {detail}" if detail else source.value

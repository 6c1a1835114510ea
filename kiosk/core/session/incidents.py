"""Incidents: what interrupts the questions and how the session comes back from it.

* Pause freezes the attempt clock; on resume at least ``resume_grace_s`` is left.
* Call-doctor halts the session (answers are ignored) until :meth:`Incidents.clinician_continue`,
  or until the patient says "I'm fine, carry on" (:meth:`Incidents.cancel_doctor`: the
  button, or 1 on the keys or the remote -- never by voice, as a misheard phrase must not call
  off help); then at least ``resume_grace_s`` is left. The cancel is logged
  (``doctor_call_cancelled``) and published, so staff see the call was called off.

After each, an open question is asked again (or, while the kiosk waits for a touch after questions
in a row went unanswered, that wait is said again). Presence is :mod:`.attendance`'s.
"""

from __future__ import annotations

from collections.abc import Callable

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session.events import (
    DoctorCallCancelled,
    DoctorCalled,
    DoctorContinued,
    IgnoreReason,
    Paused,
    Phase,
    Resumed,
)
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock


class Incidents:
    """Pause, call-doctor and presence: each freezes or frees the attempt clock."""

    def __init__(self, state: SessionState, timers: AttemptClock, out: Outputs, prompts: Prompts) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts

    def clinician_continue(self, t: float, waiting_for_touch: Callable[[float], None]) -> None:
        """A clinician continues a halted (or paused) session; at least ``resume_grace_s`` left.
        While the kiosk waits for a touch (and nothing else stops it) ``waiting_for_touch(t)``
        is told instead: the test goes on only with someone at the screen."""
        timers, out = self.timers, self.out
        if self.state.unattended and self.state.started() and not (timers.halted or timers.paused):
            waiting_for_touch(t)
            return
        if not self.state.started() or not (timers.halted or timers.paused):
            out.ignore(t, None, IgnoreReason.NOT_HALTED, "clinician_continue")
            return
        was_halted = timers.halted
        out.context(t, {"TestState": "RESTARTED"})
        out.log(t, "clinician_continue")
        self._unfreeze({"doctor", "paused"}, self.state.timing.resume_grace_s)
        deadline = timers.attempt_deadline()
        out.emit(DoctorContinued(t, deadline) if was_halted else Resumed(t, deadline))
        self._ask_again(t)

    def _freeze(self, reason: str) -> None:
        self.timers.freeze(reason)
        self.prompts.update_listening(self.timers.now())

    def _unfreeze(self, reasons: set[str], grace: float) -> None:
        if self.timers.unfreeze(reasons, grace):
            self.prompts.update_listening(self.timers.now())

    def _not_running(self) -> IgnoreReason:
        return IgnoreReason.NOT_STARTED if self.state.phase is Phase.WELCOME else IgnoreReason.FINISHED

    def pause(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        """Pause (the Pause button); the attempt clock stops."""
        if not self.state.started():
            self.out.ignore(t, event, self._not_running(), "pause")
            return
        if self.timers.halted:
            self.out.ignore(t, event, IgnoreReason.DOCTOR_CALLED, "pause")
            return
        if self.timers.paused:
            return
        self.out.context(t, {"TestState": "PAUSED"})
        self.out.log(t, "pause", channel.value if channel else "")
        self._freeze("paused")
        self.out.emit(Paused(t, channel))
        self.prompts.message(t, "paused")

    def resume(self, t: float, event: ChannelInput | None = None) -> None:
        """End a pause; the attempt has at least ``resume_grace_s`` left."""
        if not self.timers.paused:
            self.out.ignore(t, event, IgnoreReason.NOT_PAUSED, "resume")
            return
        if self.timers.halted:
            self.out.ignore(t, event, IgnoreReason.DOCTOR_CALLED, "resume")
            return
        self.out.context(t, {"TestState": "RESTARTED"})
        self.out.log(t, "resume")
        self._unfreeze({"paused"}, self.state.timing.resume_grace_s)
        self.out.emit(Resumed(t, self.timers.attempt_deadline()))
        self._ask_again(t)

    def call_doctor(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        """Call the doctor: the session halts until a clinician continues it."""
        if not self.state.started():
            self.out.ignore(t, event, self._not_running(), "call_doctor")
            return
        if self.timers.halted:
            self.out.ignore(t, event, IgnoreReason.ALREADY_CALLED, "call_doctor")
            return
        self.out.context(t, emit=["CallingDoctor"])
        self.out.log(t, "call_doctor", channel.value if channel else "")
        self._freeze("doctor")
        self.out.emit(DoctorCalled(t, channel))
        self.prompts.message(t, "doctor_called")

    def doctor_reply(self, t: float, event: ChannelInput) -> None:
        """An answer number while the doctor is called: 1 is "I'm fine, carry on" (not by voice)."""
        if event.option == 1 and event.channel is not Channel.VOICE:
            self.cancel_doctor(t, event.channel, event)
        else:
            self.out.ignore(t, event, IgnoreReason.DOCTOR_CALLED)

    def cancel_doctor(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        """The patient says "I'm fine, carry on": the test goes on (a pause from before stays)."""
        if not self.timers.halted:
            self.out.ignore(t, event, IgnoreReason.NOT_HALTED, "cancel_doctor_call")
            return
        self.out.context(t, {"TestState": "RESTARTED"})
        self.out.log(t, "doctor_call_cancelled", channel.value if channel else "")
        self._unfreeze({"doctor"}, self.state.timing.resume_grace_s)
        self.out.emit(DoctorCallCancelled(t, channel, self.timers.attempt_deadline()))
        if self.timers.paused:  # called from the paused screen: back to it
            self.prompts.message(t, "paused")
        else:
            self._ask_again(t)

    def _ask_again(self, t: float) -> None:
        """After a freeze ends, an open question is asked again (or the wait for a touch said again)."""
        if self.timers.frozen:
            return
        if self.state.current_attempt is not None:
            self.prompts.ask(t, repeat=True)
        elif self.state.unattended:
            self.prompts.unattended(t)

    def ask_again(self, t: float) -> None:
        """Ask an open question again once nothing stops the clock (for the other steps)."""
        self._ask_again(t)

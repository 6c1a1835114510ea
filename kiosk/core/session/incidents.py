"""Incidents: what interrupts the questions and how the session comes back from it.

* Pause freezes the attempt clock; on resume at least ``resume_grace_s`` is left.
* Call-doctor halts the session (answers are ignored) until :meth:`Incidents.clinician_continue`,
  or until the patient says "I'm fine, carry on" (:meth:`Incidents.cancel_doctor_call`: the
  button, or 1 on the keys or the remote -- never by voice, as a misheard phrase must not call
  off help); then at least ``resume_grace_s`` is left. The cancel is logged
  (``doctor_call_cancelled``) and published, so staff see the call was called off.
* Person lost freezes the clock; person back leaves at least ``person_back_grace_s``.

After each, an open question is asked again.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session.events import (
    DoctorCallCancelled,
    DoctorCalled,
    DoctorContinued,
    IgnoreReason,
    Paused,
    PersonBack,
    PersonLost,
    Phase,
    Resumed,
)
from kiosk.core.session.publishing import Operation

if TYPE_CHECKING:
    from kiosk.core.session.core import Session


class Incidents:
    """Pause, call-doctor and presence (a mixin of :class:`~kiosk.core.session.Session`)."""

    @property
    def paused(self: Session) -> bool:
        """Paused by the patient."""
        return "paused" in self._timers.freezes

    @property
    def halted(self: Session) -> bool:
        """Waiting for a clinician after call-doctor."""
        return "doctor" in self._timers.freezes

    def pause(self: Session, channel: Channel | None = None) -> None:
        """Pause (the Pause button); the attempt clock stops."""
        with Operation(self) as t:
            self._pause(t, channel)

    def resume(self: Session) -> None:
        """End a pause; the attempt has at least ``resume_grace_s`` left."""
        with Operation(self) as t:
            self._resume(t)

    def call_doctor(self: Session, channel: Channel | None = None) -> None:
        """Call the doctor: the session halts until :meth:`clinician_continue`."""
        with Operation(self) as t:
            self._call_doctor(t, channel)

    def clinician_continue(self: Session) -> None:
        """A clinician continues a halted (or paused) session; at least ``resume_grace_s`` left."""
        with Operation(self) as t:
            if not self._started() or not (self.halted or self.paused):
                self._ignore(t, None, IgnoreReason.NOT_HALTED, "clinician_continue")
                return
            was_halted = self.halted
            self._context(t, {"TestState": "RESTARTED"})
            self._log(t, "clinician_continue")
            self._unfreeze({"doctor", "paused"}, self.timing.resume_grace_s)
            deadline = self._timers.attempt_deadline()
            self._emit(DoctorContinued(t, deadline) if was_halted else Resumed(t, deadline))
            self._reprompt_after_freeze(t)

    def cancel_doctor_call(self: Session, channel: Channel | None = None) -> None:
        """The patient says "I'm fine, carry on" after calling the doctor: the test goes on (a
        pause from before the call stays); at least ``resume_grace_s`` left."""
        with Operation(self) as t:
            self._cancel_doctor(t, channel)

    def person_lost(self: Session) -> None:
        """The presence source (or the clinician) says the patient left; the clock stops."""
        with Operation(self) as t:
            if not self._person_present:
                self._ignore(t, None, IgnoreReason.PERSON_ALREADY_LOST, "person_lost")
                return
            self._person_present = False
            if not self._started():
                return
            self._context(t, {"PersonDetected": False})
            self._log(t, "person_lost")
            self._freeze("away")
            self._emit(PersonLost(t))

    def person_back(self: Session) -> None:
        """The patient is back; the attempt has at least ``person_back_grace_s`` left."""
        with Operation(self) as t:
            if self._person_present:
                self._ignore(t, None, IgnoreReason.PERSON_NOT_LOST, "person_back")
                return
            self._person_present = True
            if not self._started():
                return
            self._context(t, {"PersonDetected": True})
            self._log(t, "person_back")
            self._unfreeze({"away"}, self.timing.person_back_grace_s)
            self._emit(PersonBack(t, self._timers.attempt_deadline()))
            self._reprompt_after_freeze(t)

    def _freeze(self: Session, reason: str) -> None:
        self._timers.freeze(reason)
        self._update_listening(self._timers.now())

    def _unfreeze(self: Session, reasons: set[str], grace: float) -> None:
        if self._timers.unfreeze(reasons, grace):
            self._update_listening(self._timers.now())

    def _pause(self: Session, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        if not self._started():
            self._ignore(
                t, event, IgnoreReason.NOT_STARTED if self._phase is Phase.WELCOME else IgnoreReason.FINISHED, "pause"
            )
            return
        if self.halted:
            self._ignore(t, event, IgnoreReason.DOCTOR_CALLED, "pause")
            return
        if self.paused:
            return
        self._context(t, {"TestState": "PAUSED"})
        self._log(t, "pause", channel.value if channel else "")
        self._freeze("paused")
        self._emit(Paused(t, channel))
        self._message(t, "paused")

    def _resume(self: Session, t: float, event: ChannelInput | None = None) -> None:
        if not self.paused:
            self._ignore(t, event, IgnoreReason.NOT_PAUSED, "resume")
            return
        if self.halted:
            self._ignore(t, event, IgnoreReason.DOCTOR_CALLED, "resume")
            return
        self._context(t, {"TestState": "RESTARTED"})
        self._log(t, "resume")
        self._unfreeze({"paused"}, self.timing.resume_grace_s)
        self._emit(Resumed(t, self._timers.attempt_deadline()))
        self._reprompt_after_freeze(t)

    def _call_doctor(self: Session, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        if not self._started():
            self._ignore(
                t,
                event,
                IgnoreReason.NOT_STARTED if self._phase is Phase.WELCOME else IgnoreReason.FINISHED,
                "call_doctor",
            )
            return
        if self.halted:
            self._ignore(t, event, IgnoreReason.ALREADY_CALLED, "call_doctor")
            return
        self._context(t, emit=["CallingDoctor"])
        self._log(t, "call_doctor", channel.value if channel else "")
        self._freeze("doctor")
        self._emit(DoctorCalled(t, channel))
        self._message(t, "doctor_called")

    def _doctor_reply(self: Session, t: float, event: ChannelInput) -> None:
        """An answer number while the doctor is called: 1 is "I'm fine, carry on" (not by voice)."""
        if event.option == 1 and event.channel is not Channel.VOICE:
            self._cancel_doctor(t, event.channel, event)
        else:
            self._ignore(t, event, IgnoreReason.DOCTOR_CALLED)

    def _cancel_doctor(self: Session, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        if not self.halted:
            self._ignore(t, event, IgnoreReason.NOT_HALTED, "cancel_doctor_call")
            return
        self._context(t, {"TestState": "RESTARTED"})
        self._log(t, "doctor_call_cancelled", channel.value if channel else "")
        self._unfreeze({"doctor"}, self.timing.resume_grace_s)
        self._emit(DoctorCallCancelled(t, channel, self._timers.attempt_deadline()))
        if self.paused:  # called from the paused screen: back to it
            self._message(t, "paused")
        else:
            self._reprompt_after_freeze(t)

    def _reprompt_after_freeze(self: Session, t: float) -> None:
        if not self._timers.frozen and self.current_attempt is not None:
            self._prompt_question(t, repeat=True)

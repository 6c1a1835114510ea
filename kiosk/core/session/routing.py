"""Where each input and each time-out goes: the one place that knows every step of a session.

The steps never call one another through it; only :class:`~kiosk.core.session.Session` calls it,
inside an operation."""

from __future__ import annotations

from kiosk.core.channels import ChannelInput, Command, Presence
from kiosk.core.session.attendance import AWAY_ALERT, Attendance
from kiosk.core.session.calls import CallConfirmation
from kiosk.core.session.corrections import Corrections
from kiosk.core.session.events import IgnoreReason, Phase, VolumeChanged
from kiosk.core.session.incidents import Incidents
from kiosk.core.session.opening import Opening
from kiosk.core.session.practice import Practice
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import USER_INTERACTION, Outputs
from kiosk.core.session.questions import QuestionFlow
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock


class Router:
    """Routes a channel input or a due time-out to the step that handles it."""

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        opening: Opening,
        flow: QuestionFlow,
        corrections: Corrections,
        practice: Practice,
        incidents: Incidents,
        attendance: Attendance,
        calls: CallConfirmation,
    ) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self.opening = opening
        self.flow = flow
        self.corrections = corrections
        self.practice = practice
        self.incidents = incidents
        self.attendance = attendance
        self.calls = calls

    def fire(self, kind: str, t: float) -> None:
        """A time-out of ``kind`` fell due at session time ``t``."""
        if kind == "open":
            self.flow.open_next_item(t)
        elif kind == "attempt":
            self.flow.attempt_timed_out(t)
        elif kind == "confirm":
            self.corrections.not_confirmed(t, "timed_out")
        elif kind == "call":
            self.calls.timed_out(t)
        elif kind == "practice":
            self.practice.next(t)
        elif kind == "finish":
            self.flow.finish(t)
        elif kind == "next_patient":
            self.flow.next_patient(t)
        elif kind == AWAY_ALERT:
            self.attendance.away_too_long(t)
        self.prompts.update_listening(t)  # a gap that ended stops listening for "No, that's wrong"

    def input(self, t: float, event: ChannelInput | Presence) -> None:
        """An input from a channel (see ``Session.handle`` for what each number means where)."""
        phase = self.state.phase
        if isinstance(event, Presence):
            self.attendance.presence(t, event)
        elif event.channel not in USER_INTERACTION:
            self.out.ignore(t, event, IgnoreReason.NOT_AN_INPUT_CHANNEL)
        elif self.state.call is not None and event.command not in (Command.VOLUME_UP, Command.VOLUME_DOWN):
            self._calling(t, event)
        elif event.command is not None:
            self._command(t, event)
        elif phase is Phase.WELCOME:
            self.opening.start_by_number(t, event)
        elif self.timers.halted:
            self.incidents.doctor_reply(t, event)
        elif self.state.unattended:
            self.attendance.touched(t, event)
        elif phase in (Phase.EXPLANATION, Phase.REST) and not self.timers.paused:
            self.opening.acknowledge(t)
        else:
            self._answer(t, event)

    def _calling(self, t: float, event: ChannelInput) -> None:
        """An input while "Shall I call the nurse?" is asked: Yes or No, the call again, or
        "repeat"; anything else waits until it is answered."""
        if event.option is not None:
            self.calls.reply(t, event)
        elif event.command is Command.CALL_DOCTOR:
            self.calls.call(t, event)
        elif event.command is Command.REPEAT:
            self.calls.repeat(t)
        else:
            self.out.ignore(t, event, IgnoreReason.CALL_ASKED)

    def _answer(self, t: float, event: ChannelInput) -> None:
        """An answer option while the questions (or practice) run."""
        reason = self.flow.answer_blocked(event)
        if reason is not None:
            self.out.ignore(t, event, reason)
            return
        open_ = self.state.open
        assert open_ is not None and event.option is not None
        if open_.unconfirmed is not None:
            self.corrections.reply(t, event)
        elif open_.practice:
            self.practice.answered(t, event)
        elif event.needs_confirmation:
            self.corrections.ask(t, event)
        else:
            self.flow.record_answer(t, event.option, event.channel, event.detail)

    def _command(self, t: float, event: ChannelInput) -> None:
        command = event.command
        if command is Command.PAUSE:
            # the remote has one pause button: pressing it while paused resumes
            if self.timers.paused:
                self.incidents.resume(t, event)
            else:
                self.incidents.pause(t, event.channel, event)
        elif command is Command.RESUME:
            self.incidents.resume(t, event)
        elif command is Command.CALL_DOCTOR:
            self.calls.call(t, event)  # by voice asked back first; pressed, at once
        elif command is Command.REPEAT:
            self.flow.repeat(t, event.channel, event)
        elif command is Command.UNDO:
            self.corrections.undo(t, event)
        elif command in (Command.VOLUME_UP, Command.VOLUME_DOWN):
            self.out.emit(VolumeChanged(t, 1 if command is Command.VOLUME_UP else -1))

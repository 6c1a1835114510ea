"""Never a false call: a call for the doctor heard by voice is asked back before it is made.

A pressed call (the D key, the button, the remote) is made at once, as ever. A call heard by voice
is not: the kiosk asks "Shall I call the nurse?" (a ``Prompt`` of kind "call", options Yes 1 and
No 2, by touch, keys, the remote or voice) and the question on screen waits, its clock stopped:

* Yes makes the call; a spoken "yes" too unsure to act on asks for Yes or No to be pressed;
* a second hearing of the call ("call the nurse" said twice), or the doctor's key, makes it;
* No, or no reply within ``confirm_window_s``, makes none: what was on screen is asked again.

Each outcome is in the session log for staff (``doctor_call_heard``, then
``doctor_call_confirmed`` -- followed by the usual ``call_doctor`` alert --, ``doctor_call_declined``
or ``doctor_call_unanswered``) and published (:class:`DoctorCallAsked`, :class:`DoctorCalled`,
:class:`DoctorCallNotConfirmed`). Where voice is failing (voice_off, or no voice in) the question
asks for a press from the start. Why: "I need a bit of help" was heard as "I need a doctor" at
0.91-0.94 and acted on at once, and with people talking nearby 25 of 597 utterances ended in a
call (issue 33).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session.events import DoctorCallAsked, DoctorCallNotConfirmed, IgnoreReason, Prompt, PromptOption
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import HeardCall, SessionState
from kiosk.core.session.timers import AttemptClock
from kiosk.core.session.words import CALL_CONFIRM, CONFIRM_WORDS

#: the question's options: what 1 and 2 mean on the keys and the remote while it is asked
YES, NO = 1, 2


class CallConfirmation:
    """Asks back a call for the doctor heard by voice.

    ``call_doctor(t, channel, event)`` makes the call (``Incidents.call_doctor``), which also
    refuses one before the test or while the doctor is already called.
    """

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        call_doctor: Callable[[float, Channel | None, ChannelInput | None], None],
        heard: Callable[[float, bool], None] = lambda t, worked: None,
    ) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self._call_doctor = call_doctor
        #: a voice hearing's outcome, for the room's measure (kiosk.core.room)
        self._heard = heard

    def call(self, t: float, event: ChannelInput) -> None:
        """A call for the doctor: by voice asked back (the second hearing makes it); any other
        channel makes it at once."""
        state = self.state
        if state.call is not None:
            how = "heard again" if event.channel is Channel.VOICE else f"{event.channel.value} {event.detail}".strip()
            self._make(t, event, how)
        elif event.channel is Channel.VOICE and state.started() and not self.timers.halted:
            self._ask(t, event)
        else:
            self._call_doctor(t, event.channel, event)

    def reply(self, t: float, event: ChannelInput) -> None:
        """An answer number while "Shall I call the nurse?" is asked: 1 Yes, 2 No."""
        call = self.state.call
        assert call is not None
        if event.channel is Channel.VOICE and self.state.voice_off():
            self.out.ignore(t, event, IgnoreReason.VOICE_OFF)
        elif event.option == NO:
            self._not_made(t, "declined", event.channel)
        elif event.option != YES:
            self.out.ignore(t, event, IgnoreReason.NO_SUCH_OPTION)
        elif event.needs_confirmation:
            self.out.ignore(t, event, IgnoreReason.UNSURE_REPLY)
            call.press = True
            self.timers.at_least(self.state.timing.confirm_window_s)
            self._publish(t, repeat=True)
        else:
            self._make(t, event, f"yes by {event.channel.value}")

    def timed_out(self, t: float) -> None:
        """Nobody replied to "Shall I call the nurse?" in time: no call, the question goes on."""
        self._not_made(t, "unanswered", None)

    def repeat(self, t: float) -> None:
        """Ask "Shall I call the nurse?" again (the patient asked to hear it again)."""
        self._publish(t, repeat=True)

    def _ask(self, t: float, event: ChannelInput) -> None:
        state = self.state
        window = state.timing.confirm_window_s
        state.call = HeardCall(event.detail, event.confidence, self.timers.take())
        self.timers.set("call", t, window)
        confidence = f" (confidence {event.confidence:.2f})" if event.confidence is not None else ""
        self.out.log(t, "doctor_call_heard", f"voice {event.detail!r}{confidence}: asked before calling")
        due = self.timers.next_deadline()
        deadline = self.timers.t(due) if due is not None else None
        self.out.emit(DoctorCallAsked(t, event.detail, event.confidence, deadline))
        self._publish(t, repeat=False)
        self.prompts.update_listening(t)

    def _publish(self, t: float, repeat: bool) -> None:
        """Publish "Shall I call the nurse?" (kept on the call, not as the latest prompt: the screen
        under it keeps what it shows)."""
        state = self.state
        call = state.call
        assert call is not None
        lang = state.language
        asking, pressing = CALL_CONFIRM.get(lang, CALL_CONFIRM["en"])
        voice_failing = state.voice_off() or not state.voice_available
        call.text = pressing if call.press or voice_failing else asking
        words = CONFIRM_WORDS.get(lang, CONFIRM_WORDS["en"])
        options = tuple(PromptOption(number, label, synonyms, None) for number, (label, synonyms) in words.items())
        call.prompt = Prompt(
            t, "call", "call_doctor", call.text, call.text, lang, options, repeat, None, state.speech_rate()
        )
        self.out.emit(call.prompt)

    def _make(self, t: float, event: ChannelInput, how: str) -> None:
        call = self._end(t)
        self.out.log(t, "doctor_call_confirmed", f"voice {call.detail!r}: {how}")
        self._heard(t, True)
        self._call_doctor(t, Channel.VOICE, event)

    def _not_made(self, t: float, why: str, channel: Channel | None) -> None:
        call = self._end(t)
        by = f" by {channel.value}" if channel is not None else ""
        self.out.log(t, f"doctor_call_{why}", f"voice {call.detail!r}: not called{by}")
        self.out.emit(DoctorCallNotConfirmed(t, why, channel))
        self._heard(t, False)
        if self.state.prompt is not None:  # what was on screen is asked again (the voice's grammar too)
            self.prompts.publish(replace(self.state.prompt, t=t, repeat=True))
        self.prompts.update_listening(t)

    def _end(self, t: float) -> HeardCall:
        """The question is answered: the time-out it interrupted is put back (an attempt keeps
        at least ``resume_grace_s``)."""
        state = self.state
        call, state.call = state.call, None
        assert call is not None
        self.timers.cancel()
        if call.pending is not None:
            kind, left = call.pending
            if kind == "attempt":
                left = max(left, state.timing.resume_grace_s)
            self.timers.set(kind, t, left)
        return call

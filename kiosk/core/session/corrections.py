"""No silent wrong answers: confirm an unsure answer before storing it, take back the last one.

* An answer whose channel is not sure (``ChannelInput.needs_confirmation``, set by the voice
  channel) is not stored. The session asks back in the patient's language ("I heard:
  Independent. Is that right?"), a ``Prompt`` of kind "confirm" whose options are Yes (1) and
  No (2), so it can be answered by voice, touch, keys or the remote. The attempt clock stops
  meanwhile; the confirmation has ``confirm_window_s``.

  - Yes stores the answer, on the attempt it was given in (with the channel that gave it).
    An unsure "yes" never confirms: the question "Is that right?" is asked again, now asking
    the patient to press Yes or No (``confirm_answer_press``), with the whole window again to
    do it. The voice channel sends a spoken reply as unsure where the room was nearly as loud
    as the patient's voice (:data:`kiosk.speech.voice.REPLY_MIN_ABOVE_ROOM_DB`).
  - No (or the undo command) asks the question again in the same attempt, with what was left
    of its window (at least ``resume_grace_s``).
  - No reply stores nothing: the attempt ends as if it had timed out.

* For the thank-you gap after any stored answer (``between_questions_s``, and ``closing_s``
  after the last one) the answer can be taken back (``Command.UNDO``: "Change my answer", the
  C key, "No, that's wrong"), whatever channel gave it. It is withdrawn from the store (the
  store logs what was withdrawn) and the question is asked again for a full window; a new
  answer is stored as usual, none leaves the question unanswered.

QoS: an answer's attempt context (``FirstAttemptAnswered``/``SecondAttemptAnswered: true``) and
``UserInteraction`` are published when the answer is stored -- for a confirmed answer, at the
confirmation. Contexts once published stay (the engine and the stored trace only go forward):
an undo publishes ``TestState: REPEATING`` (the question is asked again), and the answer that
replaces the withdrawn one publishes only ``UserInteraction`` (attempt contexts are once per
question). See docs/qos-model.md, "How the kiosk publishes contexts".
"""

from __future__ import annotations

from collections.abc import Callable

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session.events import AnswerNotConfirmed, AnswerWithdrawn, ConfirmationAsked, IgnoreReason
from kiosk.core.session.ports import SessionStore
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState, Unconfirmed
from kiosk.core.session.timers import AttemptClock

__all__ = ["NO", "YES", "Corrections", "Unconfirmed"]

#: the confirmation's options: what 1 and 2 mean on the keys and the remote while it is asked
YES, NO = 1, 2


class Corrections:
    """Confirmation and undo of scored answers.

    ``record_answer(t, option, channel, detail)`` stores a confirmed answer; ``time_out(t)`` ends
    the open attempt as if its window had run out (no reply to "Is that right?").
    """

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        store: SessionStore | None,
        record_answer: Callable[[float, int, Channel, str], None],
        time_out: Callable[[float], None],
        heard: Callable[[float, bool], None] = lambda t, worked: None,
    ) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self.store = store
        self._record_answer = record_answer
        self._time_out = time_out
        #: a voice hearing's outcome, for the room's measure (kiosk.core.room)
        self._heard = heard

    def can_undo(self) -> bool:
        """The thank-you gap after a stored answer is running (and nothing stops the clock)."""
        return self.state.can_undo(self.timers.kind)

    def ask(self, t: float, event: ChannelInput) -> None:
        """An unsure answer: ask "Is that right?" before storing it."""
        state = self.state
        open_ = state.open
        assert open_ is not None and event.option is not None
        item = state.questionnaire.items[open_.index]
        remaining = self.timers.attempt_remaining() or 0.0
        open_.unconfirmed = Unconfirmed(event.option, event.channel, event.detail, event.confidence, remaining)
        window = state.timing.confirm_window_s
        self.timers.set("confirm", t, window)
        confidence = f", confidence {event.confidence:.2f}" if event.confidence is not None else ""
        self.out.log(
            t,
            "confirmation_asked",
            f"{item.id} option {event.option} ({event.channel.value} {event.detail!r}{confidence})",
        )
        self.out.emit(
            ConfirmationAsked(t, item.id, item.number, event.option, open_.attempt, event.channel, t + window)
        )
        self.prompts.ask(t, repeat=False)
        self.prompts.update_listening(t)

    def reply(self, t: float, event: ChannelInput) -> None:
        """Yes or No (an option 1 or 2 already checked) to the answer waiting for confirmation."""
        state = self.state
        open_ = state.open
        assert open_ is not None and open_.unconfirmed is not None
        pending = open_.unconfirmed
        if event.option != YES:
            self.not_confirmed(t, "declined")
            return
        if event.needs_confirmation:
            self.out.ignore(t, event, IgnoreReason.UNSURE_REPLY)
            self._heard(t, False)  # a "yes" too unsure to act on
            pending.press = True
            # finding and pressing the button takes longer than saying yes
            self.timers.at_least(state.timing.confirm_window_s)
            self.prompts.ask(t, repeat=True)
            return
        open_.unconfirmed = None
        item = state.questionnaire.items[open_.index]
        self.out.log(
            t, "answer_confirmed", f"{item.id} option {pending.option} by {event.channel.value} {event.detail!r}"
        )
        self._record_answer(t, pending.option, pending.channel, f"{pending.detail} (confirmed)")

    def not_confirmed(self, t: float, why: str) -> None:
        """The answer waiting for confirmation is dropped: asked again, or (timed out) the attempt ends."""
        state = self.state
        open_ = state.open
        assert open_ is not None and open_.unconfirmed is not None
        pending, open_.unconfirmed = open_.unconfirmed, None
        item = state.questionnaire.items[open_.index]
        self.out.log(t, "answer_not_confirmed", f"{item.id} option {pending.option}: {why}")
        self.out.emit(AnswerNotConfirmed(t, item.id, item.number, pending.option, open_.attempt, why))
        if pending.channel is Channel.VOICE:  # misheard, or nobody could answer what was heard
            self._heard(t, False)
        if why == "timed_out":
            self._time_out(t)
            return
        self.timers.set("attempt", t, max(pending.remaining, state.timing.resume_grace_s))
        self.prompts.ask(t, repeat=True)
        self.prompts.update_listening(t)

    def undo(self, t: float, event: ChannelInput) -> None:
        """Take back the answer waiting for confirmation, or the last one stored during its gap."""
        state = self.state
        timers = self.timers
        reason = IgnoreReason.DOCTOR_CALLED if timers.halted else IgnoreReason.PAUSED if timers.paused else None
        open_ = state.open
        if reason is None and open_ is not None and open_.unconfirmed is not None:
            self.not_confirmed(t, "undone")
            return
        if reason is None and not self.can_undo():
            reason = IgnoreReason.NOTHING_TO_UNDO
        if reason is not None:
            self.out.ignore(t, event, reason, "undo")
            return
        assert open_ is not None
        item = state.questionnaire.items[open_.index]
        answer = state.answers.pop(item.id)
        if answer.channel is Channel.VOICE:  # a voice answer stored wrong
            self._heard(t, False)
        if self.store is not None and state.stored:
            self.store.withdraw_answer(
                state.id,
                item_id=item.id,
                t=t,
                at=self.out.wall(t),
                reason=f"undo by {event.channel.value} {event.detail!r}",
            )
        self.out.context(t, {"TestState": "REPEATING"})
        open_.outcome = None
        open_.correcting = True
        window = state.attempt_window()
        timers.set("attempt", t, window)
        self.out.emit(
            AnswerWithdrawn(
                t,
                item.id,
                item.number,
                answer.option,
                answer.points,
                answer.attempt,
                answer.channel,
                event.channel,
                t + window,
            )
        )
        self.prompts.ask(t, repeat=True)
        self.prompts.update_listening(t)

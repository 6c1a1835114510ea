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

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session.events import (
    AnswerNotConfirmed,
    AnswerWithdrawn,
    ConfirmationAsked,
    IgnoreReason,
    Phase,
    Prompt,
    PromptOption,
)
from kiosk.core.session.words import CONFIRM_WORDS

if TYPE_CHECKING:
    from kiosk.core.session.core import Session

#: the confirmation's options: what 1 and 2 mean on the keys and the remote while it is asked
YES, NO = 1, 2


@dataclass
class Unconfirmed:
    """An answer heard but not stored yet, waiting for Yes or No."""

    option: int
    channel: Channel
    detail: str
    confidence: float | None
    #: what was left of the attempt's window when the confirmation was asked
    remaining: float
    #: a "yes" came too unsure to store the answer: the patient is asked to press Yes or No
    press: bool = False


class Corrections:
    """Confirmation and undo (a mixin of :class:`~kiosk.core.session.Session`)."""

    def _can_undo(self: Session) -> bool:
        """The thank-you gap after a stored answer is running (and nothing stops the clock)."""
        open_ = self._open
        return (
            self._phase is Phase.QUESTIONS
            and open_ is not None
            and not open_.practice
            and open_.outcome == "answered"
            and self._timers.kind in ("open", "finish")
            and self.questionnaire.items[open_.index].id in self._answers
        )

    def _ask_confirmation(self: Session, t: float, event: ChannelInput) -> None:
        open_ = self._open
        assert open_ is not None and event.option is not None
        item = self.questionnaire.items[open_.index]
        remaining = self._timers.attempt_remaining() or 0.0
        open_.unconfirmed = Unconfirmed(event.option, event.channel, event.detail, event.confidence, remaining)
        self._timers.set("confirm", t, self.timing.confirm_window_s)
        confidence = f", confidence {event.confidence:.2f}" if event.confidence is not None else ""
        self._log(
            t,
            "confirmation_asked",
            f"{item.id} option {event.option} ({event.channel.value} {event.detail!r}{confidence})",
        )
        self._emit(
            ConfirmationAsked(
                t, item.id, item.number, event.option, open_.attempt, event.channel, t + self.timing.confirm_window_s
            )
        )
        self._prompt_question(t, repeat=False)
        self._update_listening(t)

    def _confirmation_reply(self: Session, t: float, event: ChannelInput) -> None:
        """Yes or No (an option 1 or 2 already checked) to the answer waiting for confirmation."""
        open_ = self._open
        assert open_ is not None and open_.unconfirmed is not None
        pending = open_.unconfirmed
        if event.option != YES:
            self._not_confirmed(t, "declined")
            return
        if event.needs_confirmation:
            self._ignore(t, event, IgnoreReason.UNSURE_REPLY)
            pending.press = True
            # finding and pressing the button takes longer than saying yes
            self._timers.at_least(self.timing.confirm_window_s)
            self._prompt_question(t, repeat=True)
            return
        open_.unconfirmed = None
        item = self.questionnaire.items[open_.index]
        self._log(t, "answer_confirmed", f"{item.id} option {pending.option} by {event.channel.value} {event.detail!r}")
        self._record_answer(t, pending.option, pending.channel, f"{pending.detail} (confirmed)")

    def _not_confirmed(self: Session, t: float, why: str) -> None:
        """The answer waiting for confirmation is dropped: asked again, or (timed out) the attempt ends."""
        open_ = self._open
        assert open_ is not None and open_.unconfirmed is not None
        pending, open_.unconfirmed = open_.unconfirmed, None
        item = self.questionnaire.items[open_.index]
        self._log(t, "answer_not_confirmed", f"{item.id} option {pending.option}: {why}")
        self._emit(AnswerNotConfirmed(t, item.id, item.number, pending.option, open_.attempt, why))
        if why == "timed_out":
            self._attempt_timed_out(t)
            return
        self._timers.set("attempt", t, max(pending.remaining, self.timing.resume_grace_s))
        self._prompt_question(t, repeat=True)
        self._update_listening(t)

    def _undo(self: Session, t: float, event: ChannelInput) -> None:
        """Take back the answer waiting for confirmation, or the last one stored during its gap."""
        reason = IgnoreReason.DOCTOR_CALLED if self.halted else IgnoreReason.PAUSED if self.paused else None
        open_ = self._open
        if reason is None and open_ is not None and open_.unconfirmed is not None:
            self._not_confirmed(t, "undone")
            return
        if reason is None and not self._can_undo():
            reason = IgnoreReason.NOTHING_TO_UNDO
        if reason is not None:
            self._ignore(t, event, reason, "undo")
            return
        assert open_ is not None
        item = self.questionnaire.items[open_.index]
        answer = self._answers.pop(item.id)
        if self.store is not None and self._stored:
            self.store.withdraw_answer(
                self.id,
                item_id=item.id,
                t=t,
                at=self._wall(t),
                reason=f"undo by {event.channel.value} {event.detail!r}",
            )
        self._context(t, {"TestState": "REPEATING"})
        open_.outcome = None
        open_.correcting = True
        window = self._attempt_window()
        self._timers.set("attempt", t, window)
        self._emit(
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
        self._prompt_question(t, repeat=True)
        self._update_listening(t)

    def _confirmation_prompt(self: Session, t: float, repeat: bool) -> Prompt:
        """ "I heard: <option>. Is that right?" with the options Yes and No, in the patient's language."""
        open_ = self._open
        assert open_ is not None and open_.unconfirmed is not None
        lang = self._language
        item = self.questionnaire.items[open_.index]
        heard = item.option(open_.unconfirmed.option).label_in(lang)
        template = (
            (open_.unconfirmed.press and self.questionnaire.message("confirm_answer_press", lang))
            or self.questionnaire.message("confirm_answer", lang)
            or "{answer}?"
        )
        text = template.replace("{answer}", heard)
        words: Mapping[int, tuple[str, tuple[str, ...]]] = CONFIRM_WORDS.get(lang, CONFIRM_WORDS["en"])
        options = tuple(PromptOption(number, label, synonyms, None) for number, (label, synonyms) in words.items())
        return Prompt(t, "confirm", item.id, text, text, lang, options, repeat, open_.attempt, self._speech_rate())

"""The questions: open an attempt, take an answer, time out, go on to the next, finish.

Each question: attempt 1 (prompt; wait ``attempt_window_s``) -> attempt 2 (prompt repeated; wait)
-> not answered, next question. The first answer of an attempt wins; a later one is ignored. After
an answer or an unanswered question the next attempt 1 opens ``between_questions_s`` later; after
the last question FINISHED comes ``closing_s`` later.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.questionnaire import Item, PracticeQuestion
from kiosk.core.session.corrections import Unconfirmed
from kiosk.core.session.events import (
    ATTEMPTS,
    AnswerRecorded,
    AttemptOpened,
    AttemptTimedOut,
    Finished,
    IgnoreReason,
    NextPatient,
    Phase,
    QuestionNotAnswered,
    VolumeChanged,
)
from kiosk.core.session.publishing import QUESTION_ASKED, USER_INTERACTION
from kiosk.core.session.snapshot import Answer

if TYPE_CHECKING:
    from kiosk.core.session.core import Session


@dataclass
class OpenQuestion:
    """The question currently on screen: a scored item or a practice question."""

    practice: bool
    index: int
    attempt: int = 0
    #: None while open; "answered" or "not_answered" once over (it stays on screen until the next)
    outcome: str | None = None
    #: an answer heard but waiting for Yes or No before it is stored
    unconfirmed: Unconfirmed | None = None
    #: asked again after its answer was taken back: the new answer publishes no attempt context,
    #: and no answer in time leaves the question unanswered
    correcting: bool = False
    #: practice: the message that answered it ("practice_right"/"practice_wrong"), shown meanwhile
    feedback: str | None = None


class QuestionFlow:
    """Attempts, answers and time-outs (a mixin of :class:`~kiosk.core.session.Session`)."""

    def _fire(self: Session, kind: str, t: float) -> None:
        """A time-out of ``kind`` fell due at session time ``t``."""
        if kind == "open":
            index = self._next_item_index()
            assert index is not None
            self._open_question(t, practice=False, index=index)
        elif kind == "attempt":
            self._attempt_timed_out(t)
        elif kind == "confirm":
            self._not_confirmed(t, "timed_out")
        elif kind == "practice":
            self._next_practice(t)
        elif kind == "finish":
            self._finish(t)
        elif kind == "next_patient":
            self._log(t, "next_patient", "the end screen was shown long enough")
            self._emit(NextPatient(t))
        self._update_listening(t)  # a gap that ended stops listening for "No, that's wrong"

    def _schedule_next_item(self: Session, t: float, after: float) -> None:
        if self._next_item_index() is not None:
            self._timers.set("open", t, after)
        else:
            self._timers.set("finish", t, self.timing.closing_s)

    def _next_item_index(self: Session) -> int | None:
        done = set(self._answers) | set(self._not_answered)
        return next((i for i, item in enumerate(self.questionnaire.items) if item.id not in done), None)

    def _open_question(self: Session, t: float, *, practice: bool, index: int) -> None:
        self._open = OpenQuestion(practice=practice, index=index)
        if not practice:
            self._emit_if_modelled(t, QUESTION_ASKED)
        self._open_attempt(t, 1)

    def _open_attempt(self: Session, t: float, attempt: int) -> None:
        assert self._open is not None
        self._open.attempt = attempt
        window = self._attempt_window()
        self._timers.set("attempt", t, window)
        key, number = self._open_key()
        self._prompt_question(t, repeat=attempt > 1)
        self._emit(AttemptOpened(t, key, number, attempt, t + window, self._open.practice))
        self._update_listening(t)

    def _open_key(self: Session) -> tuple[str, int]:
        assert self._open is not None
        if self._open.practice:
            return self.questionnaire.familiarisation[self._open.index].id, self._open.index + 1
        item = self.questionnaire.items[self._open.index]
        return item.id, item.number

    def _question(self: Session) -> Item | PracticeQuestion:
        assert self._open is not None
        if self._open.practice:
            return self.questionnaire.familiarisation[self._open.index]
        return self.questionnaire.items[self._open.index]

    def _attempt_timed_out(self: Session, t: float) -> None:
        assert self._open is not None
        attempt = self._open.attempt
        key, number = self._open_key()
        if not (self._open.practice or self._open.correcting):
            name = "FirstAttemptAnswered" if attempt == 1 else "SecondAttemptAnswered"
            self._context(t, {name: False})
        self._log(t, "attempt_timed_out", f"{key} attempt {attempt}")
        self._emit(AttemptTimedOut(t, key, number, attempt, self._open.practice))
        if attempt < ATTEMPTS and not self._open.correcting:
            self._open_attempt(t, attempt + 1)
            return
        self._open.outcome = "not_answered"
        if self._open.practice:
            self._practice_not_answered(t)
            return
        self._not_answered.append(key)
        if self.store is not None:
            self.store.record_not_answered(self.id, item_id=key, t=t, at=self._wall(t))
        self._emit(QuestionNotAnswered(t, key, number))
        self._message(t, "not_answered")
        self._update_listening(t)
        self._schedule_next_item(t, self.timing.between_questions_s)

    def _answer(self: Session, t: float, event: ChannelInput) -> None:
        reason = self._answer_blocked(event)
        if reason is not None:
            self._ignore(t, event, reason)
            return
        assert self._open is not None and event.option is not None
        open_ = self._open
        if open_.unconfirmed is not None:
            self._confirmation_reply(t, event)
        elif open_.practice:
            open_.outcome = "answered"
            self._timers.cancel()
            self._practice_answered(t, event)
        elif event.needs_confirmation:
            self._ask_confirmation(t, event)
        else:
            self._record_answer(t, event.option, event.channel, event.detail)

    def _record_answer(self: Session, t: float, number: int, channel: Channel, detail: str) -> None:
        """Store option ``number`` as the open item's answer on its attempt, publish it, go on."""
        open_ = self._open
        assert open_ is not None
        attempt = open_.attempt
        open_.outcome = "answered"
        self._timers.cancel()
        item = self.questionnaire.items[open_.index]
        option = item.option(number)
        assert option.points is not None
        answer = Answer(item.id, option.number, option.points, attempt, channel, self._answered_by, t, detail)
        if self.store is not None:  # committed before anything else learns of it (crash safety)
            self.store.record_answer(
                self.id,
                item_id=item.id,
                option=option.number,
                points=option.points,
                attempt=attempt,
                channel=channel.value,
                answered_by=self._answered_by.value,
                t=t,
                at=self._wall(t),
                detail=detail,
            )
        self._answers[item.id] = answer
        contexts: dict[str, object] = {}
        if not open_.correcting:  # attempt contexts are once per question
            contexts["FirstAttemptAnswered" if attempt == 1 else "SecondAttemptAnswered"] = True
        contexts["UserInteraction"] = USER_INTERACTION[channel]
        self._context(t, contexts)
        self._emit(
            AnswerRecorded(
                t, item.id, item.number, option.number, option.points, attempt, channel, self._answered_by, detail
            )
        )
        self._schedule_next_item(t, self.timing.between_questions_s)
        self._update_listening(t)  # on through the thank-you gap: "No, that's wrong" takes it back

    def _answer_blocked(self: Session, event: ChannelInput) -> IgnoreReason | None:
        if self._phase is Phase.SUMMARY:
            return IgnoreReason.FINISHED
        if self.halted:
            return IgnoreReason.DOCTOR_CALLED
        if self.paused:
            return IgnoreReason.PAUSED
        if self._open is None:
            return IgnoreReason.NO_OPEN_ATTEMPT
        if self._open.outcome == "answered":
            return IgnoreReason.ALREADY_ANSWERED
        if self._open.outcome is not None:
            return IgnoreReason.NO_OPEN_ATTEMPT
        if event.channel is Channel.VOICE and "voice_off" in self._active_adaptations():
            return IgnoreReason.VOICE_OFF
        choices = 2 if self._open.unconfirmed is not None else len(self._question().options)  # Yes/No
        if event.option is None or event.option > choices:
            return IgnoreReason.NO_SUCH_OPTION
        return None

    def _command(self: Session, t: float, event: ChannelInput) -> None:
        command = event.command
        if command is Command.PAUSE:
            # the remote has one pause button: pressing it while paused resumes
            if self.paused:
                self._resume(t, event)
            else:
                self._pause(t, event.channel, event)
        elif command is Command.RESUME:
            self._resume(t, event)
        elif command is Command.CALL_DOCTOR:
            self._call_doctor(t, event.channel, event)
        elif command is Command.REPEAT:
            self._repeat(t, event.channel, event)
        elif command is Command.UNDO:
            self._undo(t, event)
        elif command in (Command.VOLUME_UP, Command.VOLUME_DOWN):
            self._emit(VolumeChanged(t, 1 if command is Command.VOLUME_UP else -1))

    def _repeat(self: Session, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        reason = None
        if self.halted:
            reason = IgnoreReason.DOCTOR_CALLED
        elif self.paused:
            reason = IgnoreReason.PAUSED
        elif self.current_attempt is None:
            reason = IgnoreReason.NO_OPEN_ATTEMPT
        if reason is not None:
            self._ignore(t, event, reason, "repeat")
            return
        assert self._open is not None
        if not self._open.practice:
            self._context(t, {"TestState": "REPEATING"})
        self._log(t, "repeat", channel.value if channel else "")
        # hearing the question again takes time: leave at least the resume grace to answer
        self._timers.at_least(self.timing.resume_grace_s)
        self._prompt_question(t, repeat=True)

    def _finish(self: Session, t: float) -> None:
        self._context(t, {"TestState": "FINISHED"})
        score = self.score()
        self._score = score
        if self.store is not None:
            self.store.finish_session(
                self.id,
                finished_at=self._wall(t),
                total=score.total,
                complete=score.complete,
                band=score.band.id if score.band else None,
            )
        self._set_phase(t, Phase.SUMMARY)
        self._message(t, "finished")
        self._update_listening(t)
        self._emit(Finished(t, score))
        if self.next_patient_after_s is not None:
            self._timers.set("next_patient", t, self.next_patient_after_s)

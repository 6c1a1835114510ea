"""The questions: open an attempt, take an answer, time out, go on to the next, finish.

Each question: attempt 1 (prompt; wait ``attempt_window_s``) -> attempt 2 (prompt repeated; wait)
-> not answered, next question. The first answer of an attempt wins; a later one is ignored. After
an answer or an unanswered question the next attempt 1 opens ``between_questions_s`` later; after
the last question FINISHED comes ``closing_s`` later.
"""

from __future__ import annotations

from collections.abc import Callable

from kiosk.core.channels import Channel, ChannelInput
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
)
from kiosk.core.session.ports import SessionStore
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import QUESTION_ASKED, USER_INTERACTION, Outputs
from kiosk.core.session.snapshot import Answer
from kiosk.core.session.state import OpenQuestion, SessionState
from kiosk.core.session.timers import AttemptClock


class QuestionFlow:
    """Attempts, answers and time-outs of the scored questions (and the attempts of practice ones).

    ``practice_not_answered(t)`` is called when both attempts at a practice question ran out;
    ``next_patient_after_s``: how long the end screen stays before NextPatient (None: it stays).
    """

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        store: SessionStore | None,
        next_patient_after_s: float | None,
        practice_not_answered: Callable[[float], None],
        unattended: Callable[[float], bool] = lambda t: False,
        heard: Callable[[float, bool], None] = lambda t, worked: None,
    ) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self.store = store
        self.next_patient_after_s = next_patient_after_s
        self._practice_not_answered = practice_not_answered
        self._unattended = unattended
        #: a voice hearing's outcome, for the room's measure (kiosk.core.room)
        self._heard = heard

    def schedule_next_item(self, t: float, after: float) -> None:
        """The next unanswered item opens ``after`` seconds from ``t``; with none left, the summary."""
        if self.state.next_item_index() is not None:
            self.timers.set("open", t, after)
        else:
            self.timers.set("finish", t, self.state.timing.closing_s)

    def go_on(self, t: float) -> None:
        """Open the next question at once (with none left, the summary): someone touched the
        screen while the kiosk waited for a touch."""
        if self.state.next_item_index() is not None:
            self.open_next_item(t)
        else:
            self.finish(t)

    def open_next_item(self, t: float) -> None:
        index = self.state.next_item_index()
        assert index is not None
        self.open_question(t, practice=False, index=index)

    def open_question(self, t: float, *, practice: bool, index: int) -> None:
        self.state.open = OpenQuestion(practice=practice, index=index)
        if not practice:
            self.out.emit_if_modelled(t, QUESTION_ASKED)
        self._open_attempt(t, 1)

    def _open_attempt(self, t: float, attempt: int) -> None:
        open_ = self.state.open
        assert open_ is not None
        open_.attempt = attempt
        window = self.state.attempt_window()
        self.timers.set("attempt", t, window)
        key, number = self.state.open_key()
        self.prompts.ask(t, repeat=attempt > 1)
        self.out.emit(AttemptOpened(t, key, number, attempt, t + window, open_.practice))
        self.prompts.update_listening(t)

    def attempt_timed_out(self, t: float) -> None:
        state, out = self.state, self.out
        open_ = state.open
        assert open_ is not None
        attempt = open_.attempt
        key, number = state.open_key()
        if not (open_.practice or open_.correcting):
            name = "FirstAttemptAnswered" if attempt == 1 else "SecondAttemptAnswered"
            out.context(t, {name: False})
        out.log(t, "attempt_timed_out", f"{key} attempt {attempt}")
        out.emit(AttemptTimedOut(t, key, number, attempt, open_.practice))
        if attempt < ATTEMPTS and not open_.correcting:
            self._open_attempt(t, attempt + 1)
            return
        open_.outcome = "not_answered"
        if open_.practice:
            self._practice_not_answered(t)
            return
        state.not_answered.append(key)
        if self.store is not None:
            self.store.record_not_answered(state.id, item_id=key, t=t, at=out.wall(t))
        out.emit(QuestionNotAnswered(t, key, number))
        if self._unattended(t):  # nobody answers: wait for a touch, say no "Let us go on"
            return
        self.prompts.message(t, "not_answered")
        self.prompts.update_listening(t)
        self.schedule_next_item(t, state.timing.between_questions_s)

    def record_answer(self, t: float, number: int, channel: Channel, detail: str) -> None:
        """Store option ``number`` as the open item's answer on its attempt, publish it, go on."""
        state = self.state
        open_ = state.open
        assert open_ is not None
        attempt = open_.attempt
        open_.outcome = "answered"
        self.timers.cancel()
        item = state.questionnaire.items[open_.index]
        option = item.option(number)
        assert option.points is not None
        by = state.answered_by
        answer = Answer(item.id, option.number, option.points, attempt, channel, by, t, detail)
        if self.store is not None:  # committed before anything else learns of it (crash safety)
            self.store.record_answer(
                state.id,
                item_id=item.id,
                option=option.number,
                points=option.points,
                attempt=attempt,
                channel=channel.value,
                answered_by=by.value,
                t=t,
                at=self.out.wall(t),
                detail=detail,
            )
        state.answers[item.id] = answer
        state.not_answered_run = 0
        contexts: dict[str, object] = {}
        if not open_.correcting:  # attempt contexts are once per question
            contexts["FirstAttemptAnswered" if attempt == 1 else "SecondAttemptAnswered"] = True
        contexts["UserInteraction"] = USER_INTERACTION[channel]
        self.out.context(t, contexts)
        self.out.emit(
            AnswerRecorded(t, item.id, item.number, option.number, option.points, attempt, channel, by, detail)
        )
        if channel is Channel.VOICE:
            self._heard(t, True)
        self.schedule_next_item(t, state.timing.between_questions_s)
        self.prompts.update_listening(t)  # on through the thank-you gap: "No, that's wrong" takes it back

    def answer_blocked(self, event: ChannelInput) -> IgnoreReason | None:
        """Why an answer option cannot be taken now, or None if it can."""
        state = self.state
        if state.phase is Phase.SUMMARY:
            return IgnoreReason.FINISHED
        if self.timers.halted:
            return IgnoreReason.DOCTOR_CALLED
        if self.timers.paused:
            return IgnoreReason.PAUSED
        if state.open is None:
            return IgnoreReason.NO_OPEN_ATTEMPT
        if state.open.outcome == "answered":
            return IgnoreReason.ALREADY_ANSWERED
        if state.open.outcome is not None:
            return IgnoreReason.NO_OPEN_ATTEMPT
        if event.channel is Channel.VOICE and state.voice_off():
            return IgnoreReason.VOICE_OFF
        choices = 2 if state.open.unconfirmed is not None else len(state.question().options)  # Yes/No
        if event.option is None or event.option > choices:
            return IgnoreReason.NO_SUCH_OPTION
        return None

    def repeat(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        """Ask the open question again (TestState REPEATING)."""
        reason = None
        if self.timers.halted:
            reason = IgnoreReason.DOCTOR_CALLED
        elif self.timers.paused:
            reason = IgnoreReason.PAUSED
        elif self.state.current_attempt is None:
            reason = IgnoreReason.NO_OPEN_ATTEMPT
        if reason is not None:
            self.out.ignore(t, event, reason, "repeat")
            return
        assert self.state.open is not None
        if not self.state.open.practice:
            self.out.context(t, {"TestState": "REPEATING"})
        self.out.log(t, "repeat", channel.value if channel else "")
        # hearing the question again takes time: leave at least the resume grace to answer
        self.timers.at_least(self.state.timing.resume_grace_s)
        self.prompts.ask(t, repeat=True)

    def finish(self, t: float) -> None:
        state = self.state
        self.out.context(t, {"TestState": "FINISHED"})
        score = state.questionnaire.score_answers({i: a.option for i, a in state.answers.items()})
        state.score = score
        if self.store is not None:
            self.store.finish_session(
                state.id,
                finished_at=self.out.wall(t),
                total=score.total,
                complete=score.complete,
                band=score.band.id if score.band else None,
            )
        self.prompts.set_phase(t, Phase.SUMMARY)
        self.prompts.message(t, "finished")
        self.prompts.update_listening(t)
        self.out.emit(Finished(t, score))
        if self.next_patient_after_s is not None:
            self.timers.set("next_patient", t, self.next_patient_after_s)

    def next_patient(self, t: float) -> None:
        """The end screen was shown long enough: the kiosk may make way for the next patient."""
        self.out.log(t, "next_patient", "the end screen was shown long enough")
        self.out.emit(NextPatient(t))

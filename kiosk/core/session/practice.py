"""Familiarisation: the practice questions before the scored ones (hear, read, select).

Each answer gets a short, kind word ("Well done.") that stays for the thank-you gap
(``between_questions_s``) before the next practice question. Practice answers are stored for the
clinician but never reach the QoS engine; they are never asked back for confirmation (nothing
scored depends on them). Practice questions
that check hearing are skipped while voice out is unavailable: asking "which word did you hear?"
when nothing was said only upsets the patient.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.questionnaire import PracticeQuestion
from kiosk.core.session.events import PracticeAnswered, PracticeSkipped
from kiosk.core.session.ports import SessionStore
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock


class Practice:
    """The familiarisation steps. ``open_question(t, practice=True, index=i)`` asks practice question i."""

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        out: Outputs,
        prompts: Prompts,
        *,
        store: SessionStore | None,
        open_question: Callable[..., None],
    ) -> None:
        self.state = state
        self.timers = timers
        self.out = out
        self.prompts = prompts
        self.store = store
        self._open_question = open_question

    def skip(self, t: float) -> None:
        """Leave the practice questions for the explanation."""
        self.state.open = None
        self.timers.cancel()
        self.prompts.to_explanation(t)

    def voice_out_changed(self, t: float) -> None:
        """Voice out was lost or came back (already in the state): an open hearing check is
        skipped at once, and an answered one's feedback gap ends."""
        state = self.state
        open_ = state.open
        if open_ is not None and open_.practice:
            question = state.questionnaire.familiarisation[open_.index]
            if (reason := state.practice_skip_reason(question)) is not None:
                self.timers.cancel()
                if state.current_attempt is not None:
                    self._skip(t, question, reason, shown=True)
                # an answered hearing check's feedback gap ends at once too: without voice out
                # it must not stay on screen (its outcome is already stored)
                self.open(t, open_.index + 1)

    def progress(self) -> dict[str, Any]:
        """The open practice question's place among those asked (or still to ask) on this kiosk."""
        state = self.state
        if state.open is None or not state.open.practice:
            return {}
        current = state.open.index
        asked = [
            i
            for i, question in enumerate(state.questionnaire.familiarisation)
            if question.id not in state.practice_unasked
            and (i <= current or state.practice_skip_reason(question) is None)
        ]
        return {"practice_number": asked.index(current) + 1, "practice_count": len(asked)}

    def next(self, t: float) -> None:
        """The feedback gap is over: the next practice question."""
        assert self.state.open is not None
        self.open(t, self.state.open.index + 1)

    def open(self, t: float, index: int) -> None:
        """Ask the first practice question from ``index`` on that can be asked here (skipping the
        others, logged and stored); after the last, the explanation."""
        state = self.state
        questions = state.questionnaire.familiarisation
        while index < len(questions) and (reason := state.practice_skip_reason(questions[index])) is not None:
            self._skip(t, questions[index], reason)
            index += 1
        if index < len(questions):
            self._open_question(t, practice=True, index=index)
        else:
            self.skip(t)

    def _skip(self, t: float, question: PracticeQuestion, reason: str, shown: bool = False) -> None:
        """Leave ``question`` out (logged, stored and published); one never ``shown`` is not
        counted in "Practice k of n"."""
        if not shown:
            self.state.practice_unasked.add(question.id)
        self.out.log(t, "practice_skipped", f"{question.id}: {reason}")
        self._record(t, question, "skipped", detail=reason)
        self.out.emit(PracticeSkipped(t, question.id, question.checks, reason))

    def answered(self, t: float, event: ChannelInput) -> None:
        """The open practice question got ``event``: stored, told right or wrong, the next asked."""
        open_ = self.state.open
        assert open_ is not None and event.option is not None
        open_.outcome = "answered"
        open_.chosen = event.option
        self.timers.cancel()
        question = self.state.questionnaire.familiarisation[open_.index]
        correct = event.option == question.expected
        self._record(
            t,
            question,
            "right" if correct else "wrong",
            option=event.option,
            channel=event.channel,
            detail=event.detail,
        )
        self.out.emit(PracticeAnswered(t, question.id, event.option, correct, event.channel))
        open_.feedback = "practice_right" if correct else "practice_wrong"
        self.prompts.message(t, open_.feedback)
        # the kind word stays on screen (and is said) before the next practice question
        self.timers.set("practice", t, self.state.timing.between_questions_s)
        self.prompts.update_listening(t)

    def not_answered(self, t: float) -> None:
        """Both attempts at the open practice question timed out."""
        assert self.state.open is not None
        question = self.state.questionnaire.familiarisation[self.state.open.index]
        self._record(t, question, "not_answered")
        self.out.emit(PracticeAnswered(t, question.id, None, False, None))
        self.next(t)

    def _record(
        self,
        t: float,
        question: PracticeQuestion,
        outcome: str,
        *,
        option: int | None = None,
        channel: Channel | None = None,
        detail: str = "",
    ) -> None:
        """Store a practice question's outcome ("right", "wrong", "not_answered" or "skipped") for
        the clinician; practice never reaches the QoS engine."""
        state = self.state
        if self.store is not None and state.stored:
            self.store.record_practice(
                state.id,
                question_id=question.id,
                checks=question.checks,
                outcome=outcome,
                option=option,
                channel=channel.value if channel else None,
                t=t,
                at=self.out.wall(t),
                detail=detail,
            )

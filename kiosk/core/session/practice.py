"""Familiarisation: the practice questions before the scored ones (hear, read, select).

Each answer gets a short, kind word ("Well done.") that stays for the thank-you gap
(``between_questions_s``) before the next practice question. Practice answers are stored for the
clinician but never reach the QoS engine; they are never asked back for confirmation (nothing
scored depends on them). Practice questions
that check hearing are skipped while voice out is unavailable: asking "which word did you hear?"
when nothing was said only upsets the patient.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.questionnaire import PracticeQuestion
from kiosk.core.session.events import Phase, PracticeAnswered, PracticeSkipped
from kiosk.core.session.publishing import Operation

if TYPE_CHECKING:
    from kiosk.core.session.core import Session


class Practice:
    """The familiarisation steps (a mixin of :class:`~kiosk.core.session.Session`)."""

    def skip_familiarisation(self: Session) -> None:
        """Leave the practice questions (a clinician's or the patient's choice)."""
        with Operation(self) as t:
            if self._phase is Phase.FAMILIARISATION:
                self._open = None
                self._timers.cancel()
                self._to_explanation(t)

    def set_voice_out_available(self: Session, available: bool) -> None:
        """Whether voice out works on this kiosk (the UI knows it from the voice-out channel's status).

        Assumed True until told otherwise, like :meth:`set_voice_available`. While False, practice
        questions that check hearing are skipped (logged and stored as skipped, published as
        :class:`PracticeSkipped`). One open when voice out is lost is skipped at once; one skipped
        is not asked again when voice out comes back. QoS contexts are not affected.
        """
        with Operation(self) as t:
            if available == self._voice_out_available:
                return
            self._voice_out_available = available
            self._log(t, "voice_out", "available" if available else "unavailable")
            open_ = self._open
            if open_ is not None and open_.practice:
                question = self.questionnaire.familiarisation[open_.index]
                if (reason := self._practice_skip_reason(question)) is not None:
                    self._timers.cancel()
                    if self.current_attempt is not None:
                        self._skip_practice(t, question, reason, shown=True)
                    # an answered hearing check's feedback gap ends at once too: without voice out
                    # it must not stay on screen (its outcome is already stored)
                    self._open_practice(t, open_.index + 1)

    def _practice_progress(self: Session) -> dict[str, Any]:
        """The open practice question's place among those asked (or still to ask) on this kiosk."""
        if self._open is None or not self._open.practice:
            return {}
        current = self._open.index
        asked = [
            i
            for i, question in enumerate(self.questionnaire.familiarisation)
            if question.id not in self._practice_unasked
            and (i <= current or self._practice_skip_reason(question) is None)
        ]
        return {"practice_number": asked.index(current) + 1, "practice_count": len(asked)}

    def _next_practice(self: Session, t: float) -> None:
        assert self._open is not None
        self._open_practice(t, self._open.index + 1)

    def _open_practice(self: Session, t: float, index: int) -> None:
        """Ask the first practice question from ``index`` on that can be asked here (skipping the
        others, logged and stored); after the last, the explanation."""
        questions = self.questionnaire.familiarisation
        while index < len(questions) and (reason := self._practice_skip_reason(questions[index])) is not None:
            self._skip_practice(t, questions[index], reason)
            index += 1
        if index < len(questions):
            self._open_question(t, practice=True, index=index)
        else:
            self._open = None
            self._timers.cancel()
            self._to_explanation(t)

    def _skip_practice(self: Session, t: float, question: PracticeQuestion, reason: str, shown: bool = False) -> None:
        """Leave ``question`` out (logged, stored and published); one never ``shown`` is not
        counted in "Practice k of n"."""
        if not shown:
            self._practice_unasked.add(question.id)
        self._log(t, "practice_skipped", f"{question.id}: {reason}")
        self._record_practice(t, question, "skipped", detail=reason)
        self._emit(PracticeSkipped(t, question.id, question.checks, reason))

    def _practice_skip_reason(self: Session, question: PracticeQuestion) -> str | None:
        """Why ``question`` cannot be asked on this kiosk now, or None if it can."""
        if question.checks == "hear" and not self._voice_out_available:
            return "no voice out"
        return None

    def _practice_answered(self: Session, t: float, event: ChannelInput) -> None:
        """The open practice question got ``event``: stored, told right or wrong, the next asked."""
        assert self._open is not None and event.option is not None
        question = self.questionnaire.familiarisation[self._open.index]
        correct = event.option == question.expected
        self._record_practice(
            t,
            question,
            "right" if correct else "wrong",
            option=event.option,
            channel=event.channel,
            detail=event.detail,
        )
        self._emit(PracticeAnswered(t, question.id, event.option, correct, event.channel))
        self._open.feedback = "practice_right" if correct else "practice_wrong"
        self._message(t, self._open.feedback)
        # the kind word stays on screen (and is said) before the next practice question
        self._timers.set("practice", t, self.timing.between_questions_s)
        self._update_listening(t)

    def _practice_not_answered(self: Session, t: float) -> None:
        """Both attempts at the open practice question timed out."""
        assert self._open is not None
        question = self.questionnaire.familiarisation[self._open.index]
        self._record_practice(t, question, "not_answered")
        self._emit(PracticeAnswered(t, question.id, None, False, None))
        self._next_practice(t)

    def _record_practice(
        self: Session,
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
        if self.store is not None and self._stored:
            self.store.record_practice(
                self.id,
                question_id=question.id,
                checks=question.checks,
                outcome=outcome,
                option=option,
                channel=channel.value if channel else None,
                t=t,
                at=self._wall(t),
                detail=detail,
            )

"""The steps before the questions: the welcome, the start (the session is created in the store
then), the choice of language and the explanation the patient acknowledges."""

from __future__ import annotations

from collections.abc import Callable

from kiosk.core.answerers import KIND as ANSWERER
from kiosk.core.answerers import Answerer
from kiosk.core.channels import ChannelInput
from kiosk.core.clock import Clock
from kiosk.core.questionnaire import PATIENT
from kiosk.core.questionnaire.definition import canonical
from kiosk.core.session.events import AnsweredBy, IgnoreReason, LanguageChanged, Phase, Prompt
from kiosk.core.session.ports import SessionStore
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Outputs
from kiosk.core.session.state import SessionState
from kiosk.core.session.words import CAREGIVER_ONLY_TEXT
from kiosk.core.visits import WALK_UP


class Opening:
    """Welcome, start, language and explanation.

    ``visit`` says how the visit began and ``answerer`` how the person answering is related to the
    patient (both logged at the start); ``open_practice(t, 0)`` asks the
    first practice question; ``schedule_next_item(t, after)`` sets the first question's gap.
    """

    def __init__(
        self,
        state: SessionState,
        out: Outputs,
        prompts: Prompts,
        *,
        clock: Clock,
        store: SessionStore | None,
        visit: str | None,
        battery: str | None = None,
        answerer: Answerer | None = None,
        open_practice: Callable[[float, int], None],
        schedule_next_item: Callable[[float, float], None],
    ) -> None:
        self.state = state
        self.out = out
        self.prompts = prompts
        self.clock = clock
        self.store = store
        self.visit = visit
        self.battery = battery
        self.answerer = answerer
        self._open_practice = open_practice
        self._schedule_next_item = schedule_next_item

    def welcome(self, t: float) -> None:
        """Publish the welcome as a prompt whose options are the languages, and listen for them."""
        if self.state.phase is Phase.WELCOME:
            self.state.greeted = True
            self.prompts.publish(self.prompts.welcome(t))
            self.prompts.update_listening(t)

    def start(self, t: float, answered_by: AnsweredBy | str | None) -> None:
        """The patient started: stored (unless resuming), published, then practice or the explanation."""
        state, out = self.state, self.out
        if state.phase is not Phase.WELCOME:
            out.ignore(t, None, IgnoreReason.FINISHED if state.finished else IgnoreReason.NO_OPEN_ATTEMPT, "start")
            return
        if state.questionnaire.answered_by != PATIENT and self.visit == WALK_UP:
            out.ignore(t, None, IgnoreReason.NOT_STARTED, "start: not by a walk-up patient")
            text = CAREGIVER_ONLY_TEXT[state.language]  # in calm words: it is for the person who cares for them
            self.prompts.publish(Prompt(t, "message", "caregiver_only", text, text, state.language))
            return
        if answered_by is not None:
            state.answered_by = AnsweredBy(answered_by)
        if state.questionnaire.answered_by == "caregiver" and state.answered_by is AnsweredBy.PATIENT:
            state.answered_by = AnsweredBy.CAREGIVER  # about the patient, answered by who looks after them
        if self.store is not None and not state.resuming:
            self.store.create_session(
                session_id=state.id,
                patient_id=state.patient_id,
                questionnaire_id=state.questionnaire.id,
                language=state.language,
                answered_by=state.answered_by.value,
                started_at=self.clock.wall().isoformat(),
                timing=vars(state.timing),
                definition=canonical(state.questionnaire),  # what describes this session from now on
            )
            state.stored = True
        state.person_present = True
        out.context(t, {"PersonDetected": True, "TestState": "RESTARTED" if state.resuming else "STARTED"})
        out.log(t, "start", f"answered by {state.answered_by.value}")
        if self.visit and not state.resuming:
            out.log(t, "visit", self.visit)
        if self.battery and not state.resuming:
            out.log(t, "battery", self.battery)
        if self.answerer is not None and state.answered_by is not AnsweredBy.PATIENT and not state.resuming:
            out.log(t, ANSWERER, self.answerer.detail)
        if not state.voice_out_available:  # said before the start, when nothing was stored yet
            out.log(t, "voice_out", "unavailable")
        if state.rest:
            self.prompts.set_phase(t, Phase.REST)
            self.prompts.publish(self.prompts.rest(t))
            self.prompts.update_listening(t)
        elif state.familiarisation:
            self.prompts.set_phase(t, Phase.FAMILIARISATION)
            self.prompts.message(t, "familiarisation")
            self._open_practice(t, 0)
        else:
            self.prompts.to_explanation(t)

    def choose_language(self, t: float, language: str) -> None:
        """Switch the language of prompts; the current prompt is given again in it."""
        state = self.state
        if language not in state.questionnaire.languages:
            self.out.ignore(t, None, IgnoreReason.UNKNOWN_LANGUAGE, f"choose_language {language}")
            return
        if language == state.language:
            return
        state.language = language
        self.out.log(t, "language", language)
        self.out.emit(LanguageChanged(t, language))
        if state.phase is Phase.WELCOME and state.greeted:
            self.prompts.publish(self.prompts.welcome(t))
        elif state.phase is Phase.WELCOME:
            self.prompts.message(t, "welcome")
        elif state.phase is Phase.EXPLANATION:
            self.prompts.publish(self.prompts.explanation(t))
        elif state.phase is Phase.REST:
            self.prompts.publish(self.prompts.rest(t))
        elif state.current_attempt is not None:
            self.prompts.ask(t, repeat=False)

    def start_by_number(self, t: float, event: ChannelInput) -> None:
        """An answer number on the welcome screen: the n-th language's start button (any other
        number starts in the language shown)."""
        assert event.option is not None
        languages = self.state.questionnaire.languages
        if event.option <= len(languages):
            self.choose_language(t, languages[event.option - 1])
        self.start(t, None)

    def acknowledge(self, t: float) -> None:
        """The patient acknowledged the explanation; the first question comes after the gap. On
        the rest screen between two instruments, Continue shows the next one's explanation."""
        if self.state.phase is Phase.REST:
            self.prompts.to_explanation(t)
            return
        if self.state.phase is not Phase.EXPLANATION:
            self.out.ignore(t, None, IgnoreReason.NO_OPEN_ATTEMPT, "acknowledge")
            return
        self.prompts.set_phase(t, Phase.QUESTIONS)
        self._schedule_next_item(t, self.state.timing.between_questions_s)
        self.prompts.update_listening(t)  # not in the gap before the first question

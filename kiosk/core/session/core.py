"""The :class:`Session`: its state, what it shows of it, and the steps before the questions.

The question flow, incidents (pause, call-doctor, presence), practice, live adaptation,
publishing and the attempt clock live in their own modules of this package; :class:`Session`
puts them together over one shared state."""

from __future__ import annotations

import uuid
from collections.abc import Mapping
from typing import Any

from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.clock import Clock
from kiosk.core.questionnaire import Item, Questionnaire, Score, Timing
from kiosk.core.questionnaire.definition import canonical
from kiosk.core.session.corrections import Corrections
from kiosk.core.session.events import (
    AnsweredBy,
    IgnoreReason,
    LanguageChanged,
    Phase,
    Prompt,
    PromptOption,
    SessionEvent,
)
from kiosk.core.session.incidents import Incidents
from kiosk.core.session.live import LiveAdaptation
from kiosk.core.session.ports import QosEngine, SessionStore
from kiosk.core.session.practice import Practice
from kiosk.core.session.publishing import Batch, Listener, Operation, Publisher
from kiosk.core.session.questions import OpenQuestion, QuestionFlow
from kiosk.core.session.snapshot import Answer, Snapshot
from kiosk.core.session.timers import AttemptClock
from kiosk.core.session.words import LANGUAGE_NAMES, OWN_NAME, START_LABEL, START_WORDS


class Session(QuestionFlow, Corrections, Incidents, Practice, LiveAdaptation, Publisher):
    """One administration of a questionnaire. See the package docstring for the rules.

    ``engine`` is a ``qos.Engine`` (``None``: no QoS, contexts are still kept in :attr:`trace`).
    ``store`` commits every answer as it happens (``None``: nothing is stored).
    ``timing`` overrides the questionnaire's timing values. ``adaptation`` is a
    :class:`kiosk.core.adaptation.Adaptation` (``None``: no live adaptation).
    ``next_patient_after_s``: how long the end screen stays before :class:`NextPatient` is
    published (``None``: it stays).
    ``session_id``, ``t_offset``, ``resume_answers`` and ``resume_not_answered`` are for
    :meth:`from_stored` (continuing a stored session); other callers leave them alone.
    ``visit`` says how the visit began (``kiosk.core.visits``: an order, staff, a walk-up); it is
    logged at the start, in the start's transaction, so the result is always marked.
    """

    def __init__(
        self,
        questionnaire: Questionnaire,
        *,
        clock: Clock,
        engine: QosEngine | None,
        patient_id: str,
        store: SessionStore | None = None,
        language: str = "en",
        answered_by: AnsweredBy | str = AnsweredBy.PATIENT,
        timing: Mapping[str, float] | Timing | None = None,
        adaptation: Any = None,
        familiarisation: bool = True,
        next_patient_after_s: float | None = None,
        session_id: str | None = None,
        t_offset: float = 0.0,
        resume_answers: Mapping[str, Answer] | None = None,
        resume_not_answered: tuple[str, ...] = (),
        visit: str | None = None,
    ) -> None:
        if language not in questionnaire.languages:
            raise ValueError(f"language {language!r} is not one of {', '.join(questionnaire.languages)}")
        if not patient_id:
            raise ValueError("a session needs a pseudonymous patient id")
        self.questionnaire = questionnaire
        self.clock = clock
        self.engine = engine
        self.store = store
        self.patient_id = patient_id
        self.id = session_id or uuid.uuid4().hex[:12]
        self.timing = timing if isinstance(timing, Timing) else questionnaire.timing.with_overrides(timing)
        self.adaptation = adaptation
        self.next_patient_after_s = next_patient_after_s
        #: how this visit began, logged as it starts ("order ID", "staff", "walk-up"; see kiosk.core.visits)
        self.visit = visit
        self._language = language
        self._answered_by = AnsweredBy(answered_by)
        self._familiarisation = familiarisation and bool(questionnaire.familiarisation)
        self._timers = AttemptClock(clock, clock.now() - t_offset)
        self._resuming = resume_answers is not None
        self._stored = self._resuming and store is not None
        self._phase = Phase.WELCOME
        #: the welcome prompt was published (see welcome()): listen for "start" until started
        self._greeted = False
        self._open: OpenQuestion | None = None
        self._answers: dict[str, Answer] = dict(resume_answers or {})
        self._not_answered: list[str] = list(resume_not_answered)
        self._person_present = True
        #: whether voice in works on this kiosk (see set_voice_available)
        self._voice_available = True
        #: whether voice out works on this kiosk (see set_voice_out_available)
        self._voice_out_available = True
        #: ids of the practice questions skipped before they were shown (see set_voice_out_available)
        self._practice_unasked: set[str] = set()
        self._prompt: Prompt | None = None
        self._repeating = False
        self._listening = False
        self._score: Score | None = None
        #: every context batch published, as trace events ({"t":..., "set":..., "emit":...})
        self.trace: list[dict[str, Any]] = []
        #: the latest metrics from the QoS engine
        self.metrics: dict[str, float] = {}
        self._batch: Batch | None = None
        #: batches the engine ran since the session last looked (see Publisher._take_qos_results)
        self._qos_results: list[Any] = []
        #: time of the latest batch the engine ran on its own (timers, time windows)
        self._timed_t = -1.0
        if engine is not None:
            engine.subscribe(self._qos_results.append)
        self._listeners: list[Listener] = []
        self._queue: list[SessionEvent] = []
        self._depth = 0
        self._dispatching = False

    # -- construction from a stored, unfinished session -----------------------------------------

    @classmethod
    def from_stored(
        cls,
        questionnaire: Questionnaire,
        stored: Any,
        *,
        clock: Clock,
        engine: QosEngine | None,
        store: SessionStore | None,
        **kwargs: Any,
    ) -> Session:
        """A session continuing a stored unfinished one (``kiosk.store.database.StoredSession``).

        The QoS engine is brought back to where it was by replaying the stored context trace;
        session time continues from the last recorded context. After :meth:`start` (published as
        ``PersonDetected: true, TestState: RESTARTED``) and the explanation, the session asks
        the first item that has neither an answer nor a "not answered" record.
        """
        for event in stored.trace:
            if engine is not None:
                engine.update(event["t"], set=event.get("set") or {}, emit=list(event.get("emit") or []))
        last = max((e["t"] for e in stored.trace), default=0.0)
        # the model's timers that fired after the last context (stored as metrics) are not run twice
        last_timed = max((m.t for m in stored.metrics), default=last)
        if engine is not None and last_timed > last:
            engine.advance(last_timed)
        session = cls(
            questionnaire,
            clock=clock,
            engine=engine,
            store=store,
            patient_id=stored.patient_id,
            language=stored.language,
            answered_by=stored.answered_by,
            session_id=stored.id,
            # the crash took some time: resumed batches come a second after the stored ones
            t_offset=max(last, last_timed) + 1.0,
            resume_answers={a.item_id: a for a in stored.answers},
            resume_not_answered=tuple(stored.not_answered),
            familiarisation=False,
            **kwargs,
        )
        session.trace = [dict(e) for e in stored.trace]
        if session.adaptation is not None:
            # a crash must not undo the clinician's switch or listen again to a patient it stopped hearing
            active: dict[str, bool] = {}
            for record in stored.adaptations:
                active[record.name] = record.active
            switches = [entry.detail for entry in stored.log if entry.kind == "adaptation_enabled"]
            enabled = switches[-1] == "on" if switches else session.adaptation.enabled
            session.adaptation.restore((name for name, on in active.items() if on), enabled)
        return session

    # -- read-only state ---------------------------------------------------------------------------

    @property
    def _origin(self) -> float:
        """Clock time of session time 0 (tests drive the simulated clock in session time)."""
        return self._timers.origin

    @property
    def phase(self) -> Phase:
        """The current phase."""
        return self._phase

    @property
    def language(self) -> str:
        """The language of prompts."""
        return self._language

    @property
    def answered_by(self) -> AnsweredBy:
        """Who gives the answers."""
        return self._answered_by

    @property
    def answers(self) -> Mapping[str, Answer]:
        """Recorded answers by item id."""
        return dict(self._answers)

    @property
    def listening(self) -> bool:
        """Whether voice answers are wanted right now."""
        return self._listening

    @property
    def finished(self) -> bool:
        """The session reached the summary."""
        return self._phase is Phase.SUMMARY

    @property
    def current_item(self) -> Item | None:
        """The scored item on screen: the one being asked, or the one just answered until the next
        opens (None outside the questions phase and during closing)."""
        if self._open and not self._open.practice:
            return self.questionnaire.items[self._open.index]
        return None

    @property
    def current_attempt(self) -> int | None:
        """The open attempt's number (1 to :data:`ATTEMPTS`), else None."""
        return self._open.attempt if self._open and self._open.outcome is None else None

    def now(self) -> float:
        """Session time in seconds (the time the QoS engine and the trace use)."""
        return self._timers.now()

    def remaining(self) -> float | None:
        """Seconds left on the open attempt, or None when no attempt is open."""
        return self._timers.attempt_remaining() if self.current_attempt is not None else None

    def next_deadline(self) -> float | None:
        """Clock time (``clock.now()`` scale) of the next time-out, or None if none is running.

        A driver calls :meth:`poll` once the clock has reached it. The QoS model's timers and
        time windows count too: time passes for the engine on every operation and poll.
        """
        deadlines = [d for d in (self._timers.next_deadline(), self._qos_deadline()) if d is not None]
        return min(deadlines, default=None)

    def score(self) -> Score:
        """The score of the answers recorded so far, recomputed from them."""
        return self.questionnaire.score({i: a.points for i, a in self._answers.items()})

    def snapshot(self) -> Snapshot:
        """A frozen picture of the session for a screen to render."""
        practice = None
        if self._open and self._open.practice:
            practice = self.questionnaire.familiarisation[self._open.index]
        item = self.current_item
        return Snapshot(
            phase=self._phase,
            language=self._language,
            item=item,
            number=item.number if item else None,
            count=len(self.questionnaire.items),
            practice=practice,
            attempt=self.current_attempt,
            remaining=self.remaining(),
            paused=self.paused,
            halted=self.halted,
            person_present=self._person_present,
            listening=self._listening,
            adaptations=self._active_adaptations(),
            speech_rate=self._speech_rate(),
            answers=dict(self._answers),
            not_answered=tuple(self._not_answered),
            score=self._score,
            prompt=self._prompt,
            interlude=self._interlude(),
            **self._practice_progress(),
            confirming=self._open.unconfirmed.option if self._open and self._open.unconfirmed else None,
            can_undo=self._can_undo() and not self._timers.frozen,
        )

    def _interlude(self) -> str | None:
        """What to show while the next question (or the summary) is being waited for."""
        kind = self._timers.kind
        if self._phase is Phase.FAMILIARISATION and kind == "practice" and self._open is not None:
            return self._open.feedback  # "Well done." stays while the next practice question waits
        if self._phase is not Phase.QUESTIONS or kind is None:
            return None
        if kind == "finish":
            return "last_question"
        if kind != "open":
            return None
        if self._open is not None and self._open.outcome == "not_answered":
            return "not_answered"
        if self._open is None and not (self._answers or self._not_answered):
            return "first_question"
        return "next_question"

    # -- inputs ------------------------------------------------------------------------------------

    def welcome(self) -> None:
        """The welcome is on screen: publish it as a prompt whose options are the languages to start
        in (say a language's name, "start", or its number) and listen for them."""
        with Operation(self) as t:
            if self._phase is Phase.WELCOME:
                self._greeted = True
                self._publish_prompt(self._welcome_prompt(t))
                self._update_listening(t)

    def start(self, answered_by: AnsweredBy | str | None = None) -> None:
        """The patient started at the welcome screen (publishes PersonDetected and TestState)."""
        with Operation(self) as t:
            self._start(t, answered_by)

    def choose_language(self, language: str) -> None:
        """Switch the language of prompts; the current prompt is given again in it."""
        with Operation(self) as t:
            self._choose_language(t, language)

    def acknowledge(self) -> None:
        """The patient acknowledged the explanation; the first question comes next."""
        with Operation(self) as t:
            self._acknowledge(t)

    def handle(self, event: ChannelInput) -> None:
        """An input from a channel: an answer option or a command.

        An answer number means what the screen says: on the welcome screen option n starts in the
        questionnaire's n-th language (a higher number starts in the current language, as "press
        any button" promises); under the explanation any number acknowledges it (unless paused);
        after call-doctor 1 is "I'm fine, carry on"; while "Is that right?" is asked 1 is Yes and
        2 is No.
        """
        with Operation(self) as t:
            if event.command is not None:
                self._command(t, event)
            elif self._phase is Phase.WELCOME:
                self._start_by_number(t, event)
            elif self.halted:
                self._doctor_reply(t, event)
            elif self._phase is Phase.EXPLANATION and not self.paused:
                self._acknowledge(t)
            else:
                self._answer(t, event)

    def repeat(self, channel: Channel | None = None) -> None:
        """The patient asked to hear the question again (TestState REPEATING)."""
        with Operation(self) as t:
            self._repeat(t, channel)

    def prompt_delivered(self) -> None:
        """The voice out finished speaking a repeated prompt: TestState goes back to STARTED."""
        with Operation(self) as t:
            if self._repeating:
                self._repeating = False
                self._context(t, {"TestState": "STARTED"})

    def abandon(self, reason: str = "a new session was started") -> bool:
        """The clinician starts over for the next patient (or staff end the test from the ward
        station; ``reason`` says which): a started, unfinished session is logged and marked
        abandoned in the store (its answers stay) so a restart does not offer to resume it. True
        if it was abandoned; a session still on the welcome screen or finished is left as it is.
        """
        with Operation(self) as t:
            if self.phase is Phase.WELCOME or self.finished:
                return False
            self._log(t, "abandoned", reason)
            if self.store is not None:
                self.store.abandon(self.id)
            return True

    def poll(self) -> None:
        """Let every time-out due by now happen (call at or after :meth:`next_deadline`)."""
        with Operation(self, inclusive=True):
            pass

    # -- internals: the steps before the questions ------------------------------------------------

    def _start(self, t: float, answered_by: AnsweredBy | str | None) -> None:
        if self._phase is not Phase.WELCOME:
            self._ignore(t, None, IgnoreReason.FINISHED if self.finished else IgnoreReason.NO_OPEN_ATTEMPT, "start")
            return
        if answered_by is not None:
            self._answered_by = AnsweredBy(answered_by)
        if self.store is not None and not self._resuming:
            self.store.create_session(
                session_id=self.id,
                patient_id=self.patient_id,
                questionnaire_id=self.questionnaire.id,
                language=self._language,
                answered_by=self._answered_by.value,
                started_at=self.clock.wall().isoformat(),
                timing=vars(self.timing),
                definition=canonical(self.questionnaire),  # what describes this session from now on
            )
            self._stored = True
        self._person_present = True
        state = "RESTARTED" if self._resuming else "STARTED"
        self._context(t, {"PersonDetected": True, "TestState": state})
        self._log(t, "start", f"answered by {self._answered_by.value}")
        if self.visit and not self._resuming:
            self._log(t, "visit", self.visit)
        if not self._voice_out_available:  # said before the start, when nothing was stored yet
            self._log(t, "voice_out", "unavailable")
        if self._familiarisation:
            self._set_phase(t, Phase.FAMILIARISATION)
            self._message(t, "familiarisation")
            self._open_practice(t, 0)
        else:
            self._to_explanation(t)

    def _choose_language(self, t: float, language: str) -> None:
        if language not in self.questionnaire.languages:
            self._ignore(t, None, IgnoreReason.UNKNOWN_LANGUAGE, f"choose_language {language}")
            return
        if language == self._language:
            return
        self._language = language
        self._log(t, "language", language)
        self._emit(LanguageChanged(t, language))
        if self._phase is Phase.WELCOME and self._greeted:
            self._publish_prompt(self._welcome_prompt(t))
        elif self._phase is Phase.WELCOME:
            self._message(t, "welcome")
        elif self._phase is Phase.EXPLANATION:
            self._publish_prompt(self._explanation_prompt(t))
        elif self.current_attempt is not None:
            self._prompt_question(t, repeat=False)

    def _start_by_number(self, t: float, event: ChannelInput) -> None:
        """An answer number on the welcome screen: the n-th language's start button (any other
        number starts in the language shown)."""
        assert event.option is not None
        languages = self.questionnaire.languages
        if event.option <= len(languages):
            self._choose_language(t, languages[event.option - 1])
        self._start(t, None)

    def _welcome_prompt(self, t: float) -> Prompt:
        """The welcome message with one option per language: its own name, what it is called in
        the prompt's language, and (for the language shown) the words for "start"."""
        lang = self._language
        text = self.questionnaire.message("welcome", lang)
        options = tuple(
            PromptOption(
                number,
                OWN_NAME.get(language, language),
                (
                    *LANGUAGE_NAMES.get(lang, {}).get(language, ()),
                    *(START_WORDS.get(lang, ()) if language == lang else ()),
                ),
                None,
            )
            for number, language in enumerate(self.questionnaire.languages, start=1)
        )
        return Prompt(t, "welcome", "welcome", text, text, lang, options, speech_rate=self._speech_rate())

    def _acknowledge(self, t: float) -> None:
        if self._phase is not Phase.EXPLANATION:
            self._ignore(t, None, IgnoreReason.NO_OPEN_ATTEMPT, "acknowledge")
            return
        self._set_phase(t, Phase.QUESTIONS)
        self._schedule_next_item(t, after=self.timing.between_questions_s)
        self._update_listening(t)  # not in the gap before the first question

    def _explanation_prompt(self, t: float) -> Prompt:
        """The explanation, with one option: Start, and the words for it ("I'm ready"), which the
        voice channel listens for while it is on screen."""
        lang = self._language
        text = self.questionnaire.message("explanation", lang)
        options = (PromptOption(1, START_LABEL.get(lang, "Start"), tuple(START_WORDS.get(lang, ())), None),)
        return Prompt(t, "message", "explanation", text, text, lang, options, speech_rate=self._speech_rate())

    def _to_explanation(self, t: float) -> None:
        self._set_phase(t, Phase.EXPLANATION)
        self._publish_prompt(self._explanation_prompt(t))
        self._update_listening(t)

    def _started(self) -> bool:
        return self._phase not in (Phase.WELCOME, Phase.SUMMARY)

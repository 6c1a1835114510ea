"""The Barthel session state machine: pure Python, injected clock, no Textual.

One :class:`Session` administers one questionnaire to one patient. It runs identically under the
Textual UI, in scripted replays (``kiosk replay``) and in tests, because everything it needs comes
in from outside:

* time from a :class:`~kiosk.clock.Clock`; nothing happens on its own -- a driver calls
  :meth:`Session.poll` at (or after) :meth:`Session.next_deadline` to let time-outs happen;
* patient input as :class:`~kiosk.channels.ChannelInput` through :meth:`Session.handle`, and the
  other inputs (start, presence, clinician) as methods;
* the QoS engine (``qos.Engine``) it tells about contexts, exactly as the CLARC context table says;
* an optional store (``kiosk.storage.Store``) that commits every answer as it happens.

Everything the session does is published to listeners (:meth:`Session.subscribe`) as small frozen
dataclass events (:class:`Prompt`, :class:`AttemptOpened`, :class:`AnswerRecorded`, ...), after the
operation that caused them has finished, in order.

Flow: WELCOME --start()--> FAMILIARISATION (practice questions, optional) --> EXPLANATION
--acknowledge()--> QUESTIONS --> SUMMARY. Each question: attempt 1 (prompt; wait
``attempt_window_s``) -> attempt 2 (prompt repeated; wait) -> not answered, next question.

Timing rules (all values from :class:`~kiosk.questionnaire.Timing`):

* The first answer of an attempt wins; a later one for the same attempt is ignored (and published
  as :class:`InputIgnored`).
* An input at time t is handled before a time-out due at t: an attempt's window includes its end.
* Pause freezes the attempt clock; on resume at least ``resume_grace_s`` is left. Call-doctor halts
  the session (answers are ignored) until :meth:`Session.clinician_continue`; then at least
  ``resume_grace_s`` is left. Person lost freezes the clock; person back leaves at least
  ``person_back_grace_s``. The gap between questions and the closing delay freeze likewise.
* After an answer or an unanswered question the next attempt 1 opens ``between_questions_s``
  later; after the last question FINISHED comes ``closing_s`` later.
* While a gap runs, :attr:`Snapshot.interlude` names what to show meanwhile ("next question...").
* Practice questions that check hearing are skipped while voice out is unavailable
  (:meth:`Session.set_voice_out_available`); practice outcomes are stored for the clinician.
* An answer while the patient is reported lost is still taken (a touch proves someone is there);
  PersonDetected stays the presence source's business, and the next question waits for it.

QoS contexts (one batch per instant; practice answers are never published):
start -> ``PersonDetected: true, TestState: STARTED``; answer on attempt 1 ->
``FirstAttemptAnswered: true, UserInteraction: <channel>``; attempt 1 timed out ->
``FirstAttemptAnswered: false``; attempt 2 likewise with ``SecondAttemptAnswered``; pause ->
``TestState: PAUSED``; resume and clinician continue -> ``TestState: RESTARTED``; call doctor ->
``emit: [CallingDoctor]``; repeat -> ``TestState: REPEATING`` (back to ``STARTED`` with the next
batch, or when :meth:`Session.prompt_delivered` says the repeated prompt was spoken); person
lost/back -> ``PersonDetected: false/true``; finish -> ``TestState: FINISHED``.
The keyboard maps to ``TOUCH_SCREEN``: the on-screen number keys are on the same kiosk panel as
the touchscreen, and the CLARC model has no keyboard literal.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from datetime import timedelta
from enum import Enum
from typing import Any, Protocol

from kiosk.channels import Channel, ChannelInput, Command
from kiosk.clock import Clock
from kiosk.questionnaire import Item, PracticeQuestion, Questionnaire, Score, Timing

# ---------------------------------------------------------------------------------------------
# Vocabulary


class Phase(str, Enum):
    """Where the session is."""

    WELCOME = "welcome"
    FAMILIARISATION = "familiarisation"
    EXPLANATION = "explanation"
    QUESTIONS = "questions"
    SUMMARY = "summary"


class AnsweredBy(str, Enum):
    """Who gives the answers; the Barthel index accepts self-report and a proxy's report."""

    PATIENT = "patient"
    RELATIVE = "relative"
    CAREGIVER = "caregiver"


class IgnoreReason(str, Enum):
    """Why an input did not change anything (published with :class:`InputIgnored`)."""

    NOT_STARTED = "not_started"  # a command on the welcome screen (a number there starts)
    FINISHED = "finished"  # the session is over
    NO_OPEN_ATTEMPT = "no_open_attempt"  # between questions, closing, explanation
    ALREADY_ANSWERED = "already_answered"  # another answer already won this attempt
    NO_SUCH_OPTION = "no_such_option"  # e.g. button 4 on a question with 3 options
    PAUSED = "paused"
    DOCTOR_CALLED = "doctor_called"  # halted until a clinician continues
    VOICE_OFF = "voice_off"  # live adaptation stopped listening for speech
    NOT_PAUSED = "not_paused"  # resume without a pause
    ALREADY_CALLED = "already_called"  # call-doctor while already waiting for the doctor
    NOT_HALTED = "not_halted"  # clinician continue with no doctor called
    PERSON_ALREADY_LOST = "person_already_lost"
    PERSON_NOT_LOST = "person_not_lost"
    UNKNOWN_LANGUAGE = "unknown_language"


#: attempts per question: the question is asked, then asked again, then it is not answered. Fixed
#: by the CLARC model, whose contexts are FirstAttemptAnswered and SecondAttemptAnswered.
ATTEMPTS = 2

#: how much later a second context batch at the same instant is recorded (see ``Session._flush``)
SAME_INSTANT_STEP_S = 0.001

#: the CLARC model's UserInteraction literal for each channel (keyboard: see module docstring)
USER_INTERACTION: Mapping[Channel, str] = {
    Channel.VOICE: "VOICE_RECOGNITION",
    Channel.TOUCH: "TOUCH_SCREEN",
    Channel.REMOTE: "REMOTE_CONTROL",
    Channel.KEYBOARD: "TOUCH_SCREEN",
}


class QosEngine(Protocol):
    """What the session needs of ``qos.Engine``."""

    def update(self, t: float, set: Mapping[str, Any] | None = None, emit: list[str] | None = None) -> Any:
        """Apply one batch of context changes at ``t``; the result has ``.metrics`` and ``.fired``."""


class SessionStore(Protocol):
    """What the session needs of ``kiosk.storage.Store`` (each call commits before returning)."""

    def create_session(self, *, session_id: str, patient_id: str, questionnaire_id: str, language: str,
                       answered_by: str, started_at: str, timing: Mapping[str, float]) -> None: ...
    def record_answer(self, session_id: str, *, item_id: str, option: int, points: int, attempt: int,
                      channel: str, answered_by: str, t: float, at: str, detail: str = "") -> None: ...
    def record_not_answered(self, session_id: str, *, item_id: str, t: float, at: str) -> None: ...
    def record_practice(self, session_id: str, *, question_id: str, checks: str, outcome: str, option: int | None,
                        channel: str | None, t: float, at: str, detail: str = "") -> None: ...
    def record_context(self, session_id: str, *, t: float, set: Mapping[str, Any], emit: list[str]) -> None: ...
    def record_metrics(self, session_id: str, *, t: float, metrics: Mapping[str, float], fired: list[str]) -> None: ...
    def record_adaptation(self, session_id: str, *, t: float, name: str, active: bool, reason: str) -> None: ...
    def record_event(self, session_id: str, *, t: float, kind: str, detail: str = "") -> None: ...
    def finish_session(self, session_id: str, *, finished_at: str, total: int, complete: bool,
                       band: str | None) -> None: ...
    def transaction(self) -> AbstractContextManager[None]: ...


# ---------------------------------------------------------------------------------------------
# Events published to listeners. ``t`` is seconds since the session was created (the QoS time).


@dataclass(frozen=True)
class SessionEvent:
    """Base of everything a session publishes."""

    t: float


@dataclass(frozen=True)
class PhaseChanged(SessionEvent):
    """The session moved to another phase (the UI shows another screen)."""

    phase: Phase
    previous: Phase


@dataclass(frozen=True)
class LanguageChanged(SessionEvent):
    """The patient chose another language; prompts from now on use it."""

    language: str


@dataclass(frozen=True)
class PromptOption:
    """An answer option as a prompt presents it: the voice grammar is built from these."""

    number: int
    label: str
    #: extra words the patient may say for this option, in the prompt's language
    synonyms: tuple[str, ...]
    #: points scored (None for practice questions)
    points: int | None


@dataclass(frozen=True)
class Prompt(SessionEvent):
    """Something to show and say now: a question, a practice question or a message.

    ``kind`` is "question", "practice" or "message"; ``key`` is the item id, the practice
    question id or the message name ("welcome", "explanation", "paused", "voice_off", ...).
    """

    kind: str
    key: str
    text: str
    spoken: str
    language: str
    options: tuple[PromptOption, ...] = ()
    #: the question is being asked again (attempt 2, or the patient asked to repeat)
    repeat: bool = False
    attempt: int | None = None
    #: speech rate factor for the voice out (1.0 normal; live adaptation may slow it down)
    speech_rate: float = 1.0


@dataclass(frozen=True)
class AttemptOpened(SessionEvent):
    """An attempt at a question is open for answers until ``deadline`` (session time)."""

    item_id: str
    #: 1-based position of the question (for "Question 3 of 10"); 0-based never leaks out
    number: int
    attempt: int
    deadline: float
    practice: bool = False


@dataclass(frozen=True)
class AnswerRecorded(SessionEvent):
    """An answer was accepted (and, with a store, committed) for a scored item."""

    item_id: str
    number: int
    option: int
    points: int
    attempt: int
    channel: Channel
    answered_by: AnsweredBy
    detail: str = ""


@dataclass(frozen=True)
class PracticeAnswered(SessionEvent):
    """A familiarisation question got an answer (``option`` None: it got none)."""

    question_id: str
    option: int | None
    correct: bool
    channel: Channel | None


@dataclass(frozen=True)
class PracticeSkipped(SessionEvent):
    """A familiarisation question was not asked, e.g. a hearing check while voice out is off."""

    question_id: str
    #: what it would have checked: "hear", "read" or "select"
    checks: str
    reason: str


@dataclass(frozen=True)
class AttemptTimedOut(SessionEvent):
    """An attempt's window ended without an answer."""

    item_id: str
    number: int
    attempt: int
    practice: bool = False


@dataclass(frozen=True)
class QuestionNotAnswered(SessionEvent):
    """Both attempts timed out; the session goes on to the next question."""

    item_id: str
    number: int


@dataclass(frozen=True)
class Paused(SessionEvent):
    """The patient paused the session; the attempt clock is frozen."""

    channel: Channel | None


@dataclass(frozen=True)
class Resumed(SessionEvent):
    """The session goes on after a pause; ``deadline`` is the open attempt's new deadline, if any."""

    deadline: float | None


@dataclass(frozen=True)
class DoctorCalled(SessionEvent):
    """The patient called the doctor; the session is halted until a clinician continues it."""

    channel: Channel | None


@dataclass(frozen=True)
class DoctorContinued(SessionEvent):
    """A clinician continued a halted session."""

    deadline: float | None


@dataclass(frozen=True)
class PersonLost(SessionEvent):
    """The patient is no longer in front of the kiosk; the attempt clock is frozen."""


@dataclass(frozen=True)
class PersonBack(SessionEvent):
    """The patient is back; ``deadline`` is the open attempt's new deadline, if any."""

    deadline: float | None


@dataclass(frozen=True)
class InputIgnored(SessionEvent):
    """An input changed nothing; logged so a clinician can see what happened."""

    input: ChannelInput | None
    reason: IgnoreReason
    #: what was attempted when ``input`` is None (e.g. "resume", "clinician_continue")
    action: str = ""


@dataclass(frozen=True)
class ListeningChanged(SessionEvent):
    """Whether the voice channel should listen for answers now."""

    listening: bool


@dataclass(frozen=True)
class VolumeChanged(SessionEvent):
    """The patient asked for louder (+1) or quieter (-1) speech."""

    step: int


@dataclass(frozen=True)
class AdaptationChanged(SessionEvent):
    """Live adaptation switched something on or off (e.g. "voice_off", "slow_speech")."""

    name: str
    active: bool
    reason: str


@dataclass(frozen=True)
class MetricsUpdated(SessionEvent):
    """The QoS engine took a batch of contexts; its metrics and fired observations after it."""

    metrics: Mapping[str, float]
    fired: tuple[str, ...]
    set: Mapping[str, Any]
    emit: tuple[str, ...]


@dataclass(frozen=True)
class Finished(SessionEvent):
    """The questionnaire is over; the score is recomputed from the recorded answers."""

    score: Score


# ---------------------------------------------------------------------------------------------
# State the UI renders


@dataclass(frozen=True)
class Answer:
    """A recorded answer to a scored item."""

    item_id: str
    option: int
    points: int
    attempt: int
    channel: Channel
    answered_by: AnsweredBy
    t: float
    detail: str = ""


@dataclass(frozen=True)
class Snapshot:
    """Everything a screen needs to draw the session at one moment."""

    phase: Phase
    language: str
    #: the scored item being asked (None outside questions or between them)
    item: Item | None
    #: 1-based number of that item, and how many there are ("Question k of n")
    number: int | None
    count: int
    #: the practice question being asked during familiarisation
    practice: PracticeQuestion | None
    attempt: int | None
    #: seconds left on the open attempt (frozen while paused, halted or the person is away)
    remaining: float | None
    paused: bool
    halted: bool
    person_present: bool
    listening: bool
    adaptations: frozenset[str]
    speech_rate: float
    answers: Mapping[str, Answer]
    not_answered: tuple[str, ...]
    score: Score | None
    #: the latest prompt published (question, practice or message; None before the first), so a
    #: screen rebuilt later can show what was last said without having kept the event
    prompt: Prompt | None = None
    #: during the gap before a question (or the summary) opens, the message to show meanwhile so
    #: the screen is never empty: "first_question", "next_question", "not_answered" or
    #: "last_question" (a questionnaire message name, or a screen word); None outside a gap
    interlude: str | None = None
    #: "Practice k of n" during familiarisation, counting only the practice questions asked here
    #: (a hearing check skipped without voice out is not counted); None outside a practice question
    practice_number: int | None = None
    practice_count: int = 0


# ---------------------------------------------------------------------------------------------
# The session


@dataclass
class _Timer:
    """The one pending time-out: ``due`` (clock time) while running, ``remaining`` while frozen."""

    kind: str  # "open" (next attempt 1), "attempt" (window ends), "finish"
    due: float | None
    remaining: float = 0.0


@dataclass
class _Open:
    """The question currently on screen: a scored item or a practice question."""

    practice: bool
    index: int
    attempt: int = 0
    #: None while open; "answered" or "not_answered" once over (it stays on screen until the next)
    outcome: str | None = None


@dataclass
class _Batch:
    t: float
    set: dict[str, Any] = field(default_factory=dict)
    emit: list[str] = field(default_factory=list)


Listener = Callable[[SessionEvent], None]


class Session:
    """One administration of a questionnaire. See the module docstring for the rules.

    ``engine`` is a ``qos.Engine`` (``None``: no QoS, contexts are still kept in :attr:`trace`).
    ``store`` commits every answer as it happens (``None``: nothing is stored).
    ``timing`` overrides the questionnaire's timing values. ``adaptation`` is a
    :class:`kiosk.adaptation.Adaptation` (``None``: no live adaptation).
    ``session_id``, ``t_offset``, ``resume_answers`` and ``resume_not_answered`` are for
    :meth:`from_stored` (continuing a stored session); other callers leave them alone.
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
        session_id: str | None = None,
        t_offset: float = 0.0,
        resume_answers: Mapping[str, Answer] | None = None,
        resume_not_answered: tuple[str, ...] = (),
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
        self._language = language
        self._answered_by = AnsweredBy(answered_by)
        self._familiarisation = familiarisation and bool(questionnaire.familiarisation)
        self._origin = clock.now() - t_offset
        self._resuming = resume_answers is not None
        self._stored = self._resuming and store is not None
        self._phase = Phase.WELCOME
        self._open: _Open | None = None
        self._timer: _Timer | None = None
        self._freezes: set[str] = set()
        self._grace = 0.0
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
        self._batch: _Batch | None = None
        self._listeners: list[Listener] = []
        self._queue: list[SessionEvent] = []
        self._depth = 0
        self._dispatching = False

    # -- construction from a stored, unfinished session -----------------------------------------

    @classmethod
    def from_stored(cls, questionnaire: Questionnaire, stored: Any, *, clock: Clock, engine: QosEngine | None,
               store: SessionStore | None, **kwargs: Any) -> Session:
        """A session continuing a stored unfinished one (``kiosk.storage.StoredSession``).

        The QoS engine is brought back to where it was by replaying the stored context trace;
        session time continues from the last recorded context. After :meth:`start` (published as
        ``PersonDetected: true, TestState: RESTARTED``) and the explanation, the session asks
        the first item that has neither an answer nor a "not answered" record.
        """
        for event in stored.trace:
            if engine is not None:
                engine.update(event["t"], set=event.get("set") or {}, emit=list(event.get("emit") or []))
        session = cls(
            questionnaire, clock=clock, engine=engine, store=store, patient_id=stored.patient_id,
            language=stored.language, answered_by=stored.answered_by, session_id=stored.id,
            # the crash took some time: resumed batches come a second after the stored ones
            t_offset=max((e["t"] for e in stored.trace), default=0.0) + 1.0,
            resume_answers={a.item_id: a for a in stored.answers},
            resume_not_answered=tuple(stored.not_answered), familiarisation=False, **kwargs,
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

    # -- listeners --------------------------------------------------------------------------------

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(event)`` for every event from now on; returns a function to unsubscribe.

        Listeners run on the thread that called the session, after the operation that caused
        the event has completed; they may call the session again.
        """
        self._listeners.append(listener)
        return lambda: self._listeners.remove(listener) if listener in self._listeners else None

    # -- read-only state ---------------------------------------------------------------------------

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
    def paused(self) -> bool:
        """Paused by the patient."""
        return "paused" in self._freezes

    @property
    def halted(self) -> bool:
        """Waiting for a clinician after call-doctor."""
        return "doctor" in self._freezes

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
        return self.clock.now() - self._origin

    def remaining(self) -> float | None:
        """Seconds left on the open attempt, or None when no attempt is open."""
        if self.current_attempt is None or self._timer is None or self._timer.kind != "attempt":
            return None
        if self._timer.due is None:
            return self._timer.remaining
        return max(0.0, self._timer.due - self.clock.now())

    def next_deadline(self) -> float | None:
        """Clock time (``clock.now()`` scale) of the next time-out, or None if none is running.

        A driver calls :meth:`poll` once the clock has reached it.
        """
        return self._timer.due if self._timer is not None else None

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
            phase=self._phase, language=self._language, item=item,
            number=item.number if item else None, count=len(self.questionnaire.items),
            practice=practice, attempt=self.current_attempt, remaining=self.remaining(),
            paused=self.paused, halted=self.halted, person_present=self._person_present,
            listening=self._listening, adaptations=self._active_adaptations(),
            speech_rate=self._speech_rate(), answers=dict(self._answers),
            not_answered=tuple(self._not_answered), score=self._score, prompt=self._prompt,
            interlude=self._interlude(), **self._practice_progress(),
        )

    def _practice_progress(self) -> dict[str, Any]:
        """The open practice question's place among those asked (or still to ask) on this kiosk."""
        if self._open is None or not self._open.practice:
            return {}
        current = self._open.index
        asked = [i for i, question in enumerate(self.questionnaire.familiarisation)
                 if question.id not in self._practice_unasked
                 and (i <= current or self._practice_skip_reason(question) is None)]
        return {"practice_number": asked.index(current) + 1, "practice_count": len(asked)}

    def _interlude(self) -> str | None:
        """What to show while the next question (or the summary) is being waited for."""
        if self._phase is not Phase.QUESTIONS or self._timer is None:
            return None
        if self._timer.kind == "finish":
            return "last_question"
        if self._timer.kind != "open":
            return None
        if self._open is not None and self._open.outcome == "not_answered":
            return "not_answered"
        if self._open is None and not (self._answers or self._not_answered):
            return "first_question"
        return "next_question"

    # -- inputs ------------------------------------------------------------------------------------

    def start(self, answered_by: AnsweredBy | str | None = None) -> None:
        """The patient started at the welcome screen (publishes PersonDetected and TestState)."""
        with _Op(self) as t:
            self._start(t, answered_by)

    def choose_language(self, language: str) -> None:
        """Switch the language of prompts; the current prompt is given again in it."""
        with _Op(self) as t:
            self._choose_language(t, language)

    def skip_familiarisation(self) -> None:
        """Leave the practice questions (a clinician's or the patient's choice)."""
        with _Op(self) as t:
            if self._phase is Phase.FAMILIARISATION:
                self._open = None
                self._timer = None
                self._to_explanation(t)

    def acknowledge(self) -> None:
        """The patient acknowledged the explanation; the first question comes next."""
        with _Op(self) as t:
            self._acknowledge(t)

    def handle(self, event: ChannelInput) -> None:
        """An input from a channel: an answer option or a command.

        Before the questions an answer number means what the screen says: on the welcome screen
        option n starts in the questionnaire's n-th language (a higher number starts in the current
        language, as "press any button" promises); under the explanation any number acknowledges
        it (unless paused or halted).
        """
        with _Op(self) as t:
            if event.command is not None:
                self._command(t, event)
            elif self._phase is Phase.WELCOME:
                self._start_by_number(t, event)
            elif self._phase is Phase.EXPLANATION and not (self.paused or self.halted):
                self._acknowledge(t)
            else:
                self._answer(t, event)

    def pause(self, channel: Channel | None = None) -> None:
        """Pause (the Pause button); the attempt clock stops."""
        with _Op(self) as t:
            self._pause(t, channel)

    def resume(self) -> None:
        """End a pause; the attempt has at least ``resume_grace_s`` left."""
        with _Op(self) as t:
            self._resume(t)

    def call_doctor(self, channel: Channel | None = None) -> None:
        """Call the doctor: the session halts until :meth:`clinician_continue`."""
        with _Op(self) as t:
            self._call_doctor(t, channel)

    def clinician_continue(self) -> None:
        """A clinician continues a halted (or paused) session; at least ``resume_grace_s`` left."""
        with _Op(self) as t:
            if not self._started() or not (self.halted or self.paused):
                self._ignore(t, None, IgnoreReason.NOT_HALTED, "clinician_continue")
                return
            was_halted = self.halted
            self._context(t, {"TestState": "RESTARTED"})
            self._log(t, "clinician_continue")
            self._unfreeze({"doctor", "paused"}, self.timing.resume_grace_s)
            self._emit(DoctorContinued(t, self._deadline_t()) if was_halted else Resumed(t, self._deadline_t()))
            self._reprompt_after_freeze(t)

    def repeat(self, channel: Channel | None = None) -> None:
        """The patient asked to hear the question again (TestState REPEATING)."""
        with _Op(self) as t:
            self._repeat(t, channel)

    def prompt_delivered(self) -> None:
        """The voice out finished speaking a repeated prompt: TestState goes back to STARTED."""
        with _Op(self) as t:
            if self._repeating:
                self._repeating = False
                self._context(t, {"TestState": "STARTED"})

    def person_lost(self) -> None:
        """The presence source (or the clinician) says the patient left; the clock stops."""
        with _Op(self) as t:
            if not self._person_present:
                self._ignore(t, None, IgnoreReason.PERSON_ALREADY_LOST, "person_lost")
                return
            self._person_present = False
            if not self._started():
                return
            self._context(t, {"PersonDetected": False})
            self._log(t, "person_lost")
            self._freeze("away")
            self._emit(PersonLost(t))

    def person_back(self) -> None:
        """The patient is back; the attempt has at least ``person_back_grace_s`` left."""
        with _Op(self) as t:
            if self._person_present:
                self._ignore(t, None, IgnoreReason.PERSON_NOT_LOST, "person_back")
                return
            self._person_present = True
            if not self._started():
                return
            self._context(t, {"PersonDetected": True})
            self._log(t, "person_back")
            self._unfreeze({"away"}, self.timing.person_back_grace_s)
            self._emit(PersonBack(t, self._deadline_t()))
            self._reprompt_after_freeze(t)

    def abandon(self) -> bool:
        """The clinician starts over for the next patient: a started, unfinished session is logged
        and marked abandoned in the store (its answers stay) so a restart does not offer to resume
        it. True if it was abandoned; a session still on the welcome screen or finished is left as it is.
        """
        with _Op(self) as t:
            if self.phase is Phase.WELCOME or self.finished:
                return False
            self._log(t, "abandoned", "a new session was started")
            if self.store is not None:
                self.store.abandon(self.id)
            return True

    def request_voice(self) -> None:
        """The patient asks to answer by voice again (lifts a voice-off adaptation; logged)."""
        with _Op(self) as t:
            if self.adaptation is None:
                return
            changes = self.adaptation.patient_requests_voice()
            if changes:
                self._log(t, "voice_requested", "the patient asked to answer by voice again")
            for change in changes:
                self._apply_adaptation(t, change)

    def set_voice_available(self, available: bool) -> None:
        """Whether voice in works on this kiosk (the UI knows it from the voice-in channel's status).

        Assumed True until told otherwise, so sessions without a UI (replays, tests) behave as
        the policy says. While False, the voice_off adaptation is neither switched on nor
        announced -- "I am having trouble hearing you" is untrue when voice in is not running --
        and one in force is lifted (recorded with that reason) without a voice_on message. The
        QoS contexts and the listening state are not affected.
        """
        with _Op(self) as t:
            if available == self._voice_available:
                return
            self._voice_available = available
            self._log(t, "voice_in", "available" if available else "unavailable")
            if self.adaptation is not None:
                for change in self.adaptation.hold("voice_off", not available, "voice in is unavailable"):
                    self._apply_adaptation(t, change)

    def set_voice_out_available(self, available: bool) -> None:
        """Whether voice out works on this kiosk (the UI knows it from the voice-out channel's status).

        Assumed True until told otherwise, like :meth:`set_voice_available`. While False, practice
        questions that check hearing are skipped (logged and stored as skipped, published as
        :class:`PracticeSkipped`): asking "which word did you hear?" when nothing was said only
        upsets the patient. One open when voice out is lost is skipped at once; one skipped is not
        asked again when voice out comes back. QoS contexts are not affected.
        """
        with _Op(self) as t:
            if available == self._voice_out_available:
                return
            self._voice_out_available = available
            self._log(t, "voice_out", "available" if available else "unavailable")
            open_ = self._open
            if open_ is not None and open_.practice and self.current_attempt is not None:
                question = self.questionnaire.familiarisation[open_.index]
                if (reason := self._practice_skip_reason(question)) is not None:
                    self._timer = None
                    self._skip_practice(t, question, reason, shown=True)
                    self._open_practice(t, open_.index + 1)

    def set_adaptation_enabled(self, enabled: bool) -> None:
        """The clinician turns live adaptation on or off (off lifts every active adaptation)."""
        with _Op(self) as t:
            if self.adaptation is not None:
                self._log(t, "adaptation_enabled", "on" if enabled else "off")
                for change in self.adaptation.set_enabled(enabled):
                    self._apply_adaptation(t, change)

    def poll(self) -> None:
        """Let every time-out due by now happen (call at or after :meth:`next_deadline`)."""
        with _Op(self, inclusive=True):
            pass

    # -- internals: the steps before the questions ------------------------------------------------

    def _start(self, t: float, answered_by: AnsweredBy | str | None) -> None:
        if self._phase is not Phase.WELCOME:
            self._ignore(t, None, IgnoreReason.FINISHED if self.finished else IgnoreReason.NO_OPEN_ATTEMPT,
                         "start")
            return
        if answered_by is not None:
            self._answered_by = AnsweredBy(answered_by)
        if self.store is not None and not self._resuming:
            self.store.create_session(
                session_id=self.id, patient_id=self.patient_id, questionnaire_id=self.questionnaire.id,
                language=self._language, answered_by=self._answered_by.value,
                started_at=self.clock.wall().isoformat(), timing=vars(self.timing),
            )
            self._stored = True
        self._person_present = True
        state = "RESTARTED" if self._resuming else "STARTED"
        self._context(t, {"PersonDetected": True, "TestState": state})
        self._log(t, "start", f"answered by {self._answered_by.value}")
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
        if self._phase is Phase.WELCOME:
            self._message(t, "welcome")
        elif self._phase is Phase.EXPLANATION:
            self._message(t, "explanation")
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

    def _acknowledge(self, t: float) -> None:
        if self._phase is not Phase.EXPLANATION:
            self._ignore(t, None, IgnoreReason.NO_OPEN_ATTEMPT, "acknowledge")
            return
        self._set_phase(t, Phase.QUESTIONS)
        self._schedule_next_item(t, after=self.timing.between_questions_s)

    # -- internals: time ---------------------------------------------------------------------------

    def _t(self, clock_time: float) -> float:
        return clock_time - self._origin

    def _advance(self, now: float, inclusive: bool) -> None:
        """Fire due timers in time order; each fires at its own due time, not at ``now``."""
        while self._timer is not None and self._timer.due is not None and (
            self._timer.due < now or (inclusive and self._timer.due == now)
        ):
            timer, self._timer = self._timer, None
            self._fire(timer.kind, self._t(timer.due))

    def _freeze(self, reason: str) -> None:
        if not self._freezes and self._timer is not None and self._timer.due is not None:
            self._timer.remaining = max(0.0, self._timer.due - self.clock.now())
            self._timer.due = None
        self._freezes.add(reason)
        self._update_listening(self._t(self.clock.now()))

    def _unfreeze(self, reasons: set[str], grace: float) -> None:
        """Lift freezes; once none is left the attempt gets at least the largest grace seen."""
        if not reasons & self._freezes:
            return
        self._freezes -= reasons
        self._grace = max(self._grace, grace)
        if not self._freezes:
            if self._timer is not None and self._timer.due is None:
                remaining = self._timer.remaining
                if self._timer.kind == "attempt":
                    remaining = max(remaining, self._grace)
                self._timer.due = self.clock.now() + remaining
            self._grace = 0.0
        self._update_listening(self._t(self.clock.now()))

    def _deadline_t(self) -> float | None:
        if self._timer is not None and self._timer.kind == "attempt" and self._timer.due is not None:
            return self._t(self._timer.due)
        return None

    def _set_timer(self, kind: str, start_t: float, seconds: float) -> None:
        due = self._origin + start_t + seconds
        if self._freezes:
            self._timer = _Timer(kind, None, seconds)
        else:
            self._timer = _Timer(kind, due)

    def _started(self) -> bool:
        return self._phase not in (Phase.WELCOME, Phase.SUMMARY)

    # -- internals: flow ---------------------------------------------------------------------------

    def _fire(self, kind: str, t: float) -> None:
        if kind == "open":
            index = self._next_item_index()
            assert index is not None
            self._open = _Open(practice=False, index=index)
            self._open_attempt(t, 1)
        elif kind == "attempt":
            self._attempt_timed_out(t)
        elif kind == "finish":
            self._finish(t)

    def _to_explanation(self, t: float) -> None:
        self._set_phase(t, Phase.EXPLANATION)
        self._message(t, "explanation")
        self._update_listening(t)

    def _schedule_next_item(self, t: float, after: float) -> None:
        if self._next_item_index() is not None:
            self._set_timer("open", t, after)
        else:
            self._set_timer("finish", t, self.timing.closing_s)

    def _next_item_index(self) -> int | None:
        done = set(self._answers) | set(self._not_answered)
        return next((i for i, item in enumerate(self.questionnaire.items) if item.id not in done), None)

    def _open_attempt(self, t: float, attempt: int) -> None:
        assert self._open is not None
        self._open.attempt = attempt
        self._set_timer("attempt", t, self.timing.attempt_window_s)
        key, number = self._open_key()
        self._prompt_question(t, repeat=attempt > 1)
        self._emit(AttemptOpened(t, key, number, attempt, t + self.timing.attempt_window_s, self._open.practice))
        self._update_listening(t)

    def _open_key(self) -> tuple[str, int]:
        assert self._open is not None
        if self._open.practice:
            return self.questionnaire.familiarisation[self._open.index].id, self._open.index + 1
        item = self.questionnaire.items[self._open.index]
        return item.id, item.number

    def _attempt_timed_out(self, t: float) -> None:
        assert self._open is not None
        attempt = self._open.attempt
        key, number = self._open_key()
        if not self._open.practice:
            name = "FirstAttemptAnswered" if attempt == 1 else "SecondAttemptAnswered"
            self._context(t, {name: False})
        self._log(t, "attempt_timed_out", f"{key} attempt {attempt}")
        self._emit(AttemptTimedOut(t, key, number, attempt, self._open.practice))
        if attempt < ATTEMPTS:
            self._open_attempt(t, attempt + 1)
            return
        self._open.outcome = "not_answered"
        if self._open.practice:
            question = self.questionnaire.familiarisation[self._open.index]
            self._record_practice(t, question, "not_answered")
            self._emit(PracticeAnswered(t, key, None, False, None))
            self._next_practice(t)
            return
        self._not_answered.append(key)
        if self.store is not None:
            self.store.record_not_answered(self.id, item_id=key, t=t, at=self._wall(t))
        self._emit(QuestionNotAnswered(t, key, number))
        self._message(t, "not_answered")
        self._update_listening(t)
        self._schedule_next_item(t, self.timing.between_questions_s)

    def _next_practice(self, t: float) -> None:
        assert self._open is not None
        self._open_practice(t, self._open.index + 1)

    def _open_practice(self, t: float, index: int) -> None:
        """Ask the first practice question from ``index`` on that can be asked here (skipping the
        others, logged and stored); after the last, the explanation."""
        questions = self.questionnaire.familiarisation
        while index < len(questions) and (reason := self._practice_skip_reason(questions[index])) is not None:
            self._skip_practice(t, questions[index], reason)
            index += 1
        if index < len(questions):
            self._open = _Open(practice=True, index=index)
            self._open_attempt(t, 1)
        else:
            self._open = None
            self._timer = None
            self._to_explanation(t)

    def _skip_practice(self, t: float, question: PracticeQuestion, reason: str, shown: bool = False) -> None:
        """Leave ``question`` out (logged, stored and published); one never ``shown`` is not
        counted in "Practice k of n"."""
        if not shown:
            self._practice_unasked.add(question.id)
        self._log(t, "practice_skipped", f"{question.id}: {reason}")
        self._record_practice(t, question, "skipped", detail=reason)
        self._emit(PracticeSkipped(t, question.id, question.checks, reason))

    def _practice_skip_reason(self, question: PracticeQuestion) -> str | None:
        """Why ``question`` cannot be asked on this kiosk now, or None if it can."""
        if question.checks == "hear" and not self._voice_out_available:
            return "no voice out"
        return None

    def _record_practice(self, t: float, question: PracticeQuestion, outcome: str, *, option: int | None = None,
                         channel: Channel | None = None, detail: str = "") -> None:
        """Store a practice question's outcome ("right", "wrong", "not_answered" or "skipped") for
        the clinician; practice never reaches the QoS engine."""
        if self.store is not None and self._stored:
            self.store.record_practice(self.id, question_id=question.id, checks=question.checks, outcome=outcome,
                                       option=option, channel=channel.value if channel else None, t=t, at=self._wall(t),
                                       detail=detail)

    def _answer(self, t: float, event: ChannelInput) -> None:
        reason = self._answer_blocked(event)
        if reason is not None:
            self._ignore(t, event, reason)
            return
        assert self._open is not None and event.option is not None
        open_ = self._open
        attempt = open_.attempt
        open_.outcome = "answered"
        self._timer = None
        if open_.practice:
            question = self.questionnaire.familiarisation[open_.index]
            correct = event.option == question.expected
            self._record_practice(t, question, "right" if correct else "wrong", option=event.option,
                                  channel=event.channel, detail=event.detail)
            self._emit(PracticeAnswered(t, question.id, event.option, correct, event.channel))
            self._message(t, "practice_right" if correct else "practice_wrong")
            self._next_practice(t)
            return
        item = self.questionnaire.items[open_.index]
        option = item.option(event.option)
        assert option.points is not None
        answer = Answer(item.id, option.number, option.points, attempt, event.channel, self._answered_by, t,
                        event.detail)
        if self.store is not None:  # committed before anything else learns of it (crash safety)
            self.store.record_answer(
                self.id, item_id=item.id, option=option.number, points=option.points, attempt=attempt,
                channel=event.channel.value, answered_by=self._answered_by.value, t=t, at=self._wall(t),
                detail=event.detail,
            )
        self._answers[item.id] = answer
        name = "FirstAttemptAnswered" if attempt == 1 else "SecondAttemptAnswered"
        self._context(t, {name: True, "UserInteraction": USER_INTERACTION[event.channel]})
        self._emit(AnswerRecorded(t, item.id, item.number, option.number, option.points, attempt,
                                  event.channel, self._answered_by, event.detail))
        self._update_listening(t)
        self._schedule_next_item(t, self.timing.between_questions_s)

    def _answer_blocked(self, event: ChannelInput) -> IgnoreReason | None:
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
        key = self._open
        question: Item | PracticeQuestion = (self.questionnaire.familiarisation[key.index] if key.practice
                                             else self.questionnaire.items[key.index])
        if event.option is None or event.option > len(question.options):
            return IgnoreReason.NO_SUCH_OPTION
        return None

    def _command(self, t: float, event: ChannelInput) -> None:
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
        elif command in (Command.VOLUME_UP, Command.VOLUME_DOWN):
            self._emit(VolumeChanged(t, 1 if command is Command.VOLUME_UP else -1))

    def _pause(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        if not self._started():
            self._ignore(t, event, IgnoreReason.NOT_STARTED if self._phase is Phase.WELCOME else IgnoreReason.FINISHED,
                         "pause")
            return
        if self.halted:
            self._ignore(t, event, IgnoreReason.DOCTOR_CALLED, "pause")
            return
        if self.paused:
            return
        self._context(t, {"TestState": "PAUSED"})
        self._log(t, "pause", channel.value if channel else "")
        self._freeze("paused")
        self._emit(Paused(t, channel))
        self._message(t, "paused")

    def _resume(self, t: float, event: ChannelInput | None = None) -> None:
        if not self.paused:
            self._ignore(t, event, IgnoreReason.NOT_PAUSED, "resume")
            return
        if self.halted:
            self._ignore(t, event, IgnoreReason.DOCTOR_CALLED, "resume")
            return
        self._context(t, {"TestState": "RESTARTED"})
        self._log(t, "resume")
        self._unfreeze({"paused"}, self.timing.resume_grace_s)
        self._emit(Resumed(t, self._deadline_t()))
        self._reprompt_after_freeze(t)

    def _call_doctor(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
        if not self._started():
            self._ignore(t, event, IgnoreReason.NOT_STARTED if self._phase is Phase.WELCOME else IgnoreReason.FINISHED,
                         "call_doctor")
            return
        if self.halted:
            self._ignore(t, event, IgnoreReason.ALREADY_CALLED, "call_doctor")
            return
        self._context(t, emit=["CallingDoctor"])
        self._log(t, "call_doctor", channel.value if channel else "")
        self._freeze("doctor")
        self._emit(DoctorCalled(t, channel))
        self._message(t, "doctor_called")

    def _repeat(self, t: float, channel: Channel | None, event: ChannelInput | None = None) -> None:
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
        if self._timer is not None and self._timer.due is not None:
            self._timer.due = max(self._timer.due, self.clock.now() + self.timing.resume_grace_s)
        self._prompt_question(t, repeat=True)

    def _reprompt_after_freeze(self, t: float) -> None:
        if not self._freezes and self.current_attempt is not None:
            self._prompt_question(t, repeat=True)

    def _finish(self, t: float) -> None:
        self._context(t, {"TestState": "FINISHED"})
        score = self.score()
        self._score = score
        if self.store is not None:
            self.store.finish_session(self.id, finished_at=self._wall(t), total=score.total,
                                      complete=score.complete, band=score.band.id if score.band else None)
        self._set_phase(t, Phase.SUMMARY)
        self._message(t, "finished")
        self._update_listening(t)
        self._emit(Finished(t, score))

    # -- internals: output ---------------------------------------------------------------------

    def _set_phase(self, t: float, phase: Phase) -> None:
        previous, self._phase = self._phase, phase
        self._emit(PhaseChanged(t, phase, previous))

    def _message(self, t: float, name: str) -> None:
        text = self.questionnaire.message(name, self._language)
        if text:
            self._publish_prompt(Prompt(t, "message", name, text, text, self._language,
                                        speech_rate=self._speech_rate()))

    def _prompt_question(self, t: float, repeat: bool) -> None:
        assert self._open is not None
        lang = self._language
        question: Item | PracticeQuestion = (self.questionnaire.familiarisation[self._open.index]
                                             if self._open.practice else self.questionnaire.items[self._open.index])
        options = tuple(PromptOption(o.number, o.label_in(lang), o.synonyms_in(lang), o.points)
                        for o in question.options)
        spoken = question.spoken[lang]
        if repeat and self.questionnaire.message("repeat", lang):
            spoken = f"{self.questionnaire.message('repeat', lang)} {spoken}"
        self._publish_prompt(Prompt(t, "practice" if self._open.practice else "question", question.id,
                                    question.text[lang], spoken, lang, options, repeat, self._open.attempt,
                                    self._speech_rate()))

    def _publish_prompt(self, prompt: Prompt) -> None:
        self._prompt = prompt
        self._emit(prompt)

    def _update_listening(self, t: float) -> None:
        listening = (self.current_attempt is not None and not self._freezes
                     and "voice_off" not in self._active_adaptations())
        if listening != self._listening:
            self._listening = listening
            self._emit(ListeningChanged(t, listening))

    def _active_adaptations(self) -> frozenset[str]:
        return frozenset(self.adaptation.active) if self.adaptation is not None else frozenset()

    def _speech_rate(self) -> float:
        return self.adaptation.speech_rate if self.adaptation is not None else 1.0

    def _apply_adaptation(self, t: float, change: Any) -> None:
        """Publish and store one adaptation change and act on it (voice on/off, slower speech)."""
        if self.store is not None:
            self.store.record_adaptation(self.id, t=t, name=change.name, active=change.active, reason=change.reason)
        self._emit(AdaptationChanged(t, change.name, change.active, change.reason))
        if change.name == "voice_off":
            if self._voice_available:  # hearing the patient again means nothing without voice in
                self._message(t, "voice_off" if change.active else "voice_on")
            self._update_listening(t)
        elif change.name == "slow_speech" and change.active and self.current_attempt is not None:
            self._prompt_question(t, repeat=True)

    def _ignore(self, t: float, event: ChannelInput | None, reason: IgnoreReason, action: str = "") -> None:
        what = f"{event.channel.value} {event.option or event.command.value}" if event else action  # type: ignore[union-attr]
        self._log(t, "input_ignored", f"{what}: {reason.value}")
        self._emit(InputIgnored(t, event, reason, action))

    def _log(self, t: float, kind: str, detail: str = "") -> None:
        """Add a line to the stored session log (only once the session exists in the store)."""
        if self.store is not None and self._stored:
            self.store.record_event(self.id, t=t, kind=kind, detail=detail)

    def _wall(self, t: float) -> str:
        """The wall-clock time (ISO 8601, UTC) of session time ``t``."""
        return (self.clock.wall() - timedelta(seconds=self.now() - t)).isoformat()

    def _emit(self, event: SessionEvent) -> None:
        self._queue.append(event)

    def _context(self, t: float, set: Mapping[str, Any] | None = None, emit: list[str] | None = None) -> None:
        """Add context changes to the batch of instant ``t`` (one engine update per instant)."""
        if self._batch is not None and self._batch.t != t:
            self._flush()
        if self._batch is None:
            self._batch = _Batch(t)
        if self._repeating and "TestState" not in (set or {}):
            # the repeated prompt is over once anything else happens
            self._batch.set["TestState"] = "STARTED"
            self._repeating = False
        elif set and "TestState" in set:
            self._repeating = set["TestState"] == "REPEATING"
        self._batch.set.update(set or {})
        self._batch.emit.extend(e for e in emit or [] if e not in self._batch.emit)

    def _flush(self) -> None:
        batch, self._batch = self._batch, None
        if batch is None:
            return
        if self.trace and batch.t <= self.trace[-1]["t"]:
            # Two operations at one instant (say pause and resume in the same tick) cannot share a
            # batch once the first went to the engine; a replay would merge them and fire
            # observations differently. Recording the second a millisecond later keeps the trace
            # exactly what the engine saw.
            batch.t = round(self.trace[-1]["t"] + SAME_INSTANT_STEP_S, 6)
        event: dict[str, Any] = {"t": batch.t}
        if batch.set:
            event["set"] = dict(batch.set)
        if batch.emit:
            event["emit"] = list(batch.emit)
        self.trace.append(event)
        if self.store is not None:
            self.store.record_context(self.id, t=batch.t, set=batch.set, emit=batch.emit)
        if self.engine is None:
            return
        result = self.engine.update(batch.t, set=dict(batch.set), emit=list(batch.emit))
        self.metrics = dict(result.metrics)
        fired = tuple(result.fired)
        if self.store is not None:
            self.store.record_metrics(self.id, t=batch.t, metrics=self.metrics, fired=list(fired))
        self._emit(MetricsUpdated(batch.t, dict(self.metrics), fired, dict(batch.set), tuple(batch.emit)))
        if self.adaptation is not None:
            for change in self.adaptation.observe(self.metrics, answered=_is_answer(batch.set)):
                self._apply_adaptation(batch.t, change)


def _is_answer(contexts: Mapping[str, Any]) -> bool:
    return contexts.get("FirstAttemptAnswered") is True or contexts.get("SecondAttemptAnswered") is True


class _Op:
    """One public operation: catch up on time-outs, act, then flush QoS and publish events.

    The outermost operation is one store transaction, committed before listeners hear of it: a
    crash keeps an answer together with its QoS context batch and metrics, or neither.
    """

    def __init__(self, session: Session, inclusive: bool = False) -> None:
        self.s = session
        self.inclusive = inclusive
        self._transaction: AbstractContextManager[None] | None = None

    def __enter__(self) -> float:
        s = self.s
        s._depth += 1
        if s._depth == 1 and s.store is not None:
            self._transaction = s.store.transaction()
            self._transaction.__enter__()
        now = s.clock.now()
        s._advance(now, self.inclusive)
        return s._t(now)

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        s = self.s
        s._depth -= 1
        if s._depth:
            return
        try:
            if exc_type is None:
                s._flush()
        finally:
            if self._transaction is not None:
                self._transaction.__exit__(None, None, None)
        if exc_type is not None:
            return
        if s._dispatching:
            return
        s._dispatching = True
        try:
            while s._queue:
                event = s._queue.pop(0)
                for listener in list(s._listeners):
                    listener(event)
        finally:
            s._dispatching = False

"""The :class:`Session`: a small owner of collaborators, each given what it needs when made.

:class:`~kiosk.core.session.state.SessionState` holds what the session is and knows;
:class:`~kiosk.core.session.timers.AttemptClock` its one time-out; :class:`~kiosk.core.session.publishing.Outputs`
its listeners, QoS batches, trace and log; :class:`~kiosk.core.session.prompts.Prompts` what it
shows and says. The steps (:class:`~kiosk.core.session.opening.Opening`,
:class:`~kiosk.core.session.questions.QuestionFlow`, :class:`~kiosk.core.session.corrections.Corrections`,
:class:`~kiosk.core.session.practice.Practice`, :class:`~kiosk.core.session.incidents.Incidents`,
:class:`~kiosk.core.session.live.LiveAdaptation`) act on those; none knows :class:`Session`.
The session brackets every public call in one operation; :class:`~kiosk.core.session.routing.Router`
sends each input and time-out to the step that handles it."""

from __future__ import annotations

import uuid
from collections.abc import Callable, Mapping
from typing import Any

from kiosk.core.answerers import Answerer
from kiosk.core.channels import Channel, ChannelInput, Command, Presence, PresenceSource
from kiosk.core.clock import Clock
from kiosk.core.questionnaire import Item, Questionnaire, Score, Timing
from kiosk.core.room import RoomHearing
from kiosk.core.session.attendance import Attendance, Watching
from kiosk.core.session.calls import CallConfirmation
from kiosk.core.session.corrections import Corrections
from kiosk.core.session.events import AnsweredBy, Phase
from kiosk.core.session.incidents import Incidents
from kiosk.core.session.live import LiveAdaptation
from kiosk.core.session.opening import Opening
from kiosk.core.session.picture import picture
from kiosk.core.session.ports import QosEngine, SessionStore
from kiosk.core.session.practice import Practice
from kiosk.core.session.prompts import Prompts
from kiosk.core.session.publishing import Listener, Operation, Outputs
from kiosk.core.session.questions import QuestionFlow
from kiosk.core.session.resume import replay_into, restore_adaptation
from kiosk.core.session.routing import Router
from kiosk.core.session.snapshot import Answer, Snapshot
from kiosk.core.session.state import BatteryPlace, SessionState
from kiosk.core.session.timers import AttemptClock


class Session:
    """One administration of a questionnaire. See the package docstring for the rules.

    ``engine`` is a ``qos.Engine`` (``None``: no QoS, contexts are still kept in :attr:`trace`).
    ``store`` commits every answer as it happens (``None``: nothing is stored).
    ``timing`` overrides the questionnaire's timing values. ``adaptation`` is a
    :class:`kiosk.core.adaptation.Adaptation` (``None``: no live adaptation).
    ``next_patient_after_s``: how long the end screen stays before :class:`NextPatient` is
    published (``None``: it stays).
    ``session_id``, ``t_offset``, ``resume_answers`` and ``resume_not_answered`` are for
    :meth:`from_stored` (continuing a stored session); other callers leave them alone.
    ``battery`` says where the session stands in a battery of instruments (see
    :mod:`kiosk.core.session.battery`); a later instrument starts with the rest screen.
    ``visit`` says how the visit began (``kiosk.core.visits``: an order, staff, a walk-up); it is
    logged at the start, in the start's transaction, so the result is always marked; so is ``answerer``
    (:class:`kiosk.core.answerers.Answerer`), when someone other than the patient answers.
    ``watching`` is what the site sets about a patient who is not there (:class:`Watching`: the
    away alert, the wait for a touch after unanswered questions); ``None``: neither.
    ``room`` (:class:`kiosk.core.room.RoomHearing`, shared by a kiosk's sessions) is how well voice
    is heard where the kiosk stands; its voice hearings feed it (None: not measured).
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
        battery: BatteryPlace | None = None,
        watching: Watching | None = None,
        room: RoomHearing | None = None,
        answerer: Answerer | None = None,
    ) -> None:
        if language not in questionnaire.languages:
            raise ValueError(f"language {language!r} is not one of {', '.join(questionnaire.languages)}")
        if not patient_id:
            raise ValueError("a session needs a pseudonymous patient id")
        self.questionnaire = questionnaire
        self.clock = clock
        self.engine = engine
        self.store = store
        resuming = resume_answers is not None
        self.state = state = SessionState(
            questionnaire=questionnaire,
            timing=timing if isinstance(timing, Timing) else questionnaire.timing.with_overrides(timing),
            id=session_id or uuid.uuid4().hex[:12],
            patient_id=patient_id,
            adaptation=adaptation,
            language=language,
            answered_by=AnsweredBy(answered_by),
            familiarisation=familiarisation and bool(questionnaire.familiarisation),
            resuming=resuming,
            stored=resuming and store is not None,
            answers=dict(resume_answers or {}),
            not_answered=list(resume_not_answered),
            rest=battery is not None and battery.index > 0 and not resuming,
        )
        #: where this session stands in its visit's battery (None: a visit of one instrument)
        self.battery = battery
        self.timers = timers = AttemptClock(clock, clock.now() - t_offset)
        self.out = out = Outputs(state, timers, engine=engine, store=store, on_metrics=self._metrics_updated)
        self.prompts = prompts = Prompts(state, timers, out)
        self.live = live = LiveAdaptation(state, timers, out, prompts, store=store, room=room)
        self.incidents = incidents = Incidents(state, timers, out, prompts)
        steps = (state, timers, out, prompts)
        self.calls = CallConfirmation(*steps, call_doctor=self.incidents.call_doctor, heard=live.hearing)
        self.flow = flow = QuestionFlow(
            *steps,
            store=store,
            next_patient_after_s=next_patient_after_s,
            practice_not_answered=self._practice_not_answered,
            unattended=self._not_answered,
            heard=live.hearing,
        )
        self.attendance = Attendance(
            state, timers, out, prompts, watching=watching, go_on=flow.go_on, ask_again=incidents.ask_again
        )
        self.corrections = Corrections(
            *steps, store=store, record_answer=flow.record_answer, time_out=flow.attempt_timed_out, heard=live.hearing
        )
        self.practice = practice = Practice(state, timers, out, prompts, store=store, open_question=flow.open_question)
        self.opening = opening = Opening(
            state,
            out,
            prompts,
            clock=clock,
            store=store,
            visit=visit,
            battery=battery.detail() if battery is not None else None,
            answerer=answerer,
            open_practice=practice.open,
            schedule_next_item=flow.schedule_next_item,
        )
        self.router = Router(
            state,
            timers,
            out,
            prompts,
            opening=opening,
            flow=flow,
            corrections=self.corrections,
            practice=practice,
            incidents=self.incidents,
            attendance=self.attendance,
            calls=self.calls,
        )

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
        session = cls(questionnaire, clock=clock, engine=engine, store=store, **replay_into(engine, stored), **kwargs)
        session.out.trace = [dict(e) for e in stored.trace]
        restore_adaptation(session.adaptation, stored)
        return session

    # -- read-only state ---------------------------------------------------------------------------

    @property
    def id(self) -> str:
        """The session's id (in the store, on the station)."""
        return self.state.id

    @property
    def patient_id(self) -> str:
        """The patient's pseudonymous id."""
        return self.state.patient_id

    @property
    def timing(self) -> Timing:
        """The timing values in force."""
        return self.state.timing

    @property
    def adaptation(self) -> Any:
        """The live adaptation policy (``kiosk.core.adaptation.Adaptation``), or None."""
        return self.state.adaptation

    @property
    def visit(self) -> str | None:
        """How this visit began, logged as it starts ("order ID", "staff", "walk-up"; see kiosk.core.visits)."""
        return self.opening.visit

    @property
    def next_patient_after_s(self) -> float | None:
        """How long the end screen stays before NextPatient (None: it stays)."""
        return self.flow.next_patient_after_s

    @property
    def trace(self) -> list[dict[str, Any]]:
        """Every context batch published, as trace events ({"t":..., "set":..., "emit":...})."""
        return self.out.trace

    @property
    def metrics(self) -> dict[str, float]:
        """The latest metrics from the QoS engine."""
        return self.out.metrics

    @property
    def _origin(self) -> float:
        """Clock time of session time 0 (tests drive the simulated clock in session time)."""
        return self.timers.origin

    @property
    def phase(self) -> Phase:
        """The current phase."""
        return self.state.phase

    @property
    def language(self) -> str:
        """The language of prompts."""
        return self.state.language

    @property
    def answered_by(self) -> AnsweredBy:
        """Who gives the answers."""
        return self.state.answered_by

    @property
    def answers(self) -> Mapping[str, Answer]:
        """Recorded answers by item id."""
        return dict(self.state.answers)

    @property
    def listening(self) -> bool:
        """Whether voice answers are wanted right now."""
        return self.state.listening

    @property
    def finished(self) -> bool:
        """The session reached the summary."""
        return self.state.finished

    @property
    def paused(self) -> bool:
        """Paused by the patient."""
        return self.timers.paused

    @property
    def halted(self) -> bool:
        """Waiting for a clinician after call-doctor."""
        return self.timers.halted

    @property
    def current_item(self) -> Item | None:
        """The scored item on screen: the one being asked, or the one just answered until the next
        opens (None outside the questions phase and during closing)."""
        return self.state.current_item

    @property
    def current_attempt(self) -> int | None:
        """The open attempt's number (1 to :data:`ATTEMPTS`), else None."""
        return self.state.current_attempt

    def now(self) -> float:
        """Session time in seconds (the time the QoS engine and the trace use)."""
        return self.timers.now()

    def remaining(self) -> float | None:
        """Seconds left on the open attempt, or None when no attempt is open."""
        return self.timers.attempt_remaining() if self.current_attempt is not None else None

    def next_deadline(self) -> float | None:
        """Clock time (``clock.now()`` scale) of the next time-out, or None if none is running.

        A driver calls :meth:`poll` once the clock has reached it. The QoS model's timers and
        time windows count too: time passes for the engine on every operation and poll.
        """
        deadlines = [d for d in (self.timers.next_deadline(), self.out.qos_deadline()) if d is not None]
        return min(deadlines, default=None)

    def score(self) -> Score:
        """The score of the answers recorded so far, recomputed from them."""
        return self.questionnaire.score_answers({i: a.option for i, a in self.state.answers.items()})

    def snapshot(self) -> Snapshot:
        """A frozen picture of the session for a screen to render."""
        return picture(
            self.state,
            self.timers,
            progress=self.practice.progress(),
            can_undo=self.corrections.can_undo(),
            part=(self.battery.index + 1, len(self.battery.instruments)) if self.battery is not None else None,
        )

    # -- inputs ------------------------------------------------------------------------------------

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(event)`` for every event from now on; returns a function to unsubscribe.

        Listeners run on the thread that called the session, after the operation that caused
        the event has completed; they may call the session again.
        """
        return self.out.subscribe(listener)

    def welcome(self) -> None:
        """The welcome is on screen: publish it as a prompt whose options are the languages to start
        in (say a language's name, "start", or its number) and listen for them."""
        with self._operation() as t:
            self.opening.welcome(t)

    def start(self, answered_by: AnsweredBy | str | None = None) -> None:
        """The patient started at the welcome screen (publishes PersonDetected and TestState)."""
        with self._operation() as t:
            self.opening.start(t, answered_by)

    def choose_language(self, language: str) -> None:
        """Switch the language of prompts; the current prompt is given again in it."""
        with self._operation() as t:
            self.opening.choose_language(t, language)

    def acknowledge(self) -> None:
        """The patient acknowledged the explanation; the first question comes next."""
        with self._operation() as t:
            self.opening.acknowledge(t)

    def handle(self, event: ChannelInput | Presence) -> None:
        """An input from a channel: an answer option or a command, or a presence report
        (:class:`~kiosk.core.channels.Presence`, from the camera or staff; see :mod:`.attendance`).

        An answer number means what the screen says: on the welcome screen option n starts in the
        questionnaire's n-th language (a higher number starts in the current language, as "press
        any button" promises); under the explanation any number acknowledges it (unless paused);
        after call-doctor 1 is "I'm fine, carry on"; while "Is that right?" is asked 1 is Yes and
        2 is No. While the kiosk waits for a touch (questions in a row unanswered) a number by
        touch, key or remote goes on to the next question.
        """
        with self._operation() as t:
            self.router.input(t, event)

    def repeat(self, channel: Channel | None = None) -> None:
        """The patient asked to hear the question again (TestState REPEATING)."""
        with self._operation() as t:
            self.flow.repeat(t, channel)

    def prompt_delivered(self) -> None:
        """The voice out finished speaking a repeated prompt: TestState goes back to STARTED."""
        with self._operation() as t:
            if self.state.repeating:
                self.state.repeating = False
                self.out.context(t, {"TestState": "STARTED"})

    def abandon(self, reason: str = "a new session was started") -> bool:
        """The clinician starts over for the next patient (or staff end the test from the ward
        station; ``reason`` says which): a started, unfinished session is logged and marked
        abandoned in the store (its answers stay) so a restart does not offer to resume it. True
        if it was abandoned; a session still on the welcome screen or finished is left as it is.
        """
        with self._operation() as t:
            if self.phase is Phase.WELCOME or self.finished:
                return False
            self.out.log(t, "abandoned", reason)
            if self.store is not None:
                self.store.abandon(self.id)
            return True

    def poll(self) -> None:
        """Let every time-out due by now happen (call at or after :meth:`next_deadline`)."""
        with self._operation(inclusive=True):
            pass

    def pause(self, channel: Channel | None = None) -> None:
        """Pause (the Pause button); the attempt clock stops."""
        with self._operation() as t:
            self.incidents.pause(t, channel)

    def resume(self) -> None:
        """End a pause; the attempt has at least ``resume_grace_s`` left."""
        with self._operation() as t:
            self.incidents.resume(t)

    def call_doctor(self, channel: Channel | None = None) -> None:
        """Call the doctor: the session halts until :meth:`clinician_continue` (a call by voice
        comes through :meth:`handle`, and is asked back: :mod:`kiosk.core.session.calls`)."""
        with self._operation() as t:
            if self.state.call is not None:  # pressed while "Shall I call the nurse?" is asked
                self.calls.call(t, ChannelInput(channel or Channel.TOUCH, command=Command.CALL_DOCTOR))
            else:
                self.incidents.call_doctor(t, channel)

    def clinician_continue(self) -> None:
        """A clinician continues a halted (or paused) session; at least ``resume_grace_s`` left.
        While the kiosk waits for a touch it is logged and the kiosk keeps waiting for it."""
        with self._operation() as t:
            self.incidents.clinician_continue(t, self.attendance.staff_continue)

    def cancel_doctor_call(self, channel: Channel | None = None) -> None:
        """The patient says "I'm fine, carry on" after calling the doctor: the test goes on (a
        pause from before the call stays); at least ``resume_grace_s`` left."""
        with self._operation() as t:
            self.incidents.cancel_doctor(t, channel)

    def person_lost(self, detail: str = "") -> None:
        """Staff say the patient left ("Patient away"): ``handle(Presence(False, STAFF, detail))``."""
        self.handle(Presence(False, PresenceSource.STAFF, detail))

    def person_back(self, detail: str = "") -> None:
        """Staff say the patient is back: ``handle(Presence(True, STAFF, detail))``; the attempt has
        at least ``person_back_grace_s`` left."""
        self.handle(Presence(True, PresenceSource.STAFF, detail))

    def skip_familiarisation(self) -> None:
        """Leave the practice questions (a clinician's or the patient's choice)."""
        with self._operation() as t:
            if self.phase is Phase.FAMILIARISATION:
                self.practice.skip(t)

    def set_voice_out_available(self, available: bool) -> None:
        """Whether voice out works on this kiosk (the UI knows it from the voice-out channel's status).

        Assumed True until told otherwise, like :meth:`set_voice_available`. While False, practice
        questions that check hearing are skipped (logged and stored as skipped, published as
        :class:`PracticeSkipped`). One open when voice out is lost is skipped at once; one skipped
        is not asked again when voice out comes back. QoS contexts are not affected.
        """
        with self._operation() as t:
            if available == self.state.voice_out_available:
                return
            self.state.voice_out_available = available
            self.out.log(t, "voice_out", "available" if available else "unavailable")
            self.practice.voice_out_changed(t)

    def request_voice(self) -> None:
        """The patient asks to answer by voice again (lifts a voice-off adaptation; logged)."""
        with self._operation() as t:
            self.live.request_voice(t)

    def set_voice_available(self, available: bool) -> None:
        """Whether voice in works on this kiosk (the UI knows it from the voice-in channel's status).

        Assumed True until told otherwise, so sessions without a UI (replays, tests) behave as
        the policy says. While False, the voice_off adaptation is neither switched on nor
        announced -- "I am having trouble hearing you" is untrue when voice in is not running --
        and one in force is lifted (recorded with that reason) without a voice_on message. The
        QoS contexts and the listening state are not affected.
        """
        with self._operation() as t:
            self.live.set_voice_available(t, available)

    def voice_unheard(self, reason: str) -> None:
        """The voice channel heard speech it could not take (``reason``, its words): counted
        against how well voice is heard in this room (:mod:`kiosk.core.room`)."""
        with self._operation() as t:
            if self.state.started():
                self.live.hearing(t, False)

    def set_adaptation_enabled(self, enabled: bool) -> None:
        """The clinician turns live adaptation on or off (off lifts every active adaptation)."""
        with self._operation() as t:
            self.live.set_enabled(t, enabled)

    def _operation(self, inclusive: bool = False) -> Operation:
        return self.out.operation(self.router.fire, inclusive)

    def _practice_not_answered(self, t: float) -> None:
        self.practice.not_answered(t)

    def _not_answered(self, t: float) -> bool:
        return self.attendance.not_answered(t)

    def _metrics_updated(self, t: float, metrics: Mapping[str, float], answered: bool) -> None:
        self.live.observe(t, metrics, answered)

"""Running a script: the real session and QoS engine on a simulated clock, driven step by step.

The driver arms each step once what it is counted from has happened and checks that what the
script declared really happened under the session's rules.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import field, replace
from functools import partial
from typing import Any

from basis import record
from fileio.bounded import BadFile
from kiosk.commands.replay.script import ANY, COMMANDS, UNSURE_CONFIDENCE, BatteryScript, Script, ScriptError, Step
from kiosk.core.channels import Channel, ChannelInput, Command, Presence
from kiosk.core.clock import SimClock
from kiosk.core.qos_model import DEFAULT_MODEL
from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from kiosk.core.room import RoomHearing
from kiosk.core.session import (
    AdaptationChanged,
    AnswerRecorded,
    AttemptOpened,
    AttemptTimedOut,
    AwayAlert,
    InputIgnored,
    Phase,
    PhaseChanged,
    QuestionNotAnswered,
    Session,
    SessionEvent,
    Unattended,
)
from qos.errors import QosError
from qos.trace import seconds


@record(frozen=False)
class ReplayResult:
    """What a replay produced: the finished session, its context trace and the QoS statistics."""

    script: Script
    session: Session
    #: the session's context trace, as ``qos.Trace``
    trace: Any
    #: ``qos.replay`` of that trace: {"metrics": {...}, "fired": [...]}
    qos: dict[str, Any]
    #: simulated seconds from the session's creation to its end
    simulated_s: float
    events: list[SessionEvent] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """The result as JSON-ready data (what ``kiosk replay --json`` prints)."""
        score = self.session.score()
        return {
            "script": self.script.source,
            "instrument": self.session.questionnaire.id,
            "patient": self.script.patient,
            "language": self.script.language,
            "answered_by": self.script.answered_by,
            "score": {
                "total": score.total,
                "complete": score.complete,
                "max_total": score.max_total,
                "band": score.band.id if score.band else None,
            },
            "answers": [
                {
                    "item": a.item_id,
                    "option": a.option,
                    "points": a.points,
                    "attempt": a.attempt,
                    "channel": a.channel.value,
                    "t": _num(a.t),
                }
                for a in sorted(self.session.answers.values(), key=lambda a: a.t)
            ],
            "not_answered": list(self.session.snapshot().not_answered),
            "adaptations": [
                {"t": _num(e.t), "name": e.name, "active": e.active, "reason": e.reason}
                for e in self.events
                if isinstance(e, AdaptationChanged)
            ],
            "alerts": [
                {"t": _num(e.t), "kind": "away" if isinstance(e, AwayAlert) else "unattended"}
                for e in self.events
                if isinstance(e, (AwayAlert, Unattended))
            ],
            "qos": self.qos,
            "simulated_s": _num(self.simulated_s),
        }


def _num(value: float) -> float | int:
    return round(seconds(value), 6)


class _Driver:
    """Arms each step once what it is counted from has happened, and checks what happened."""

    def __init__(self, script: Script, session: Session, clock: SimClock) -> None:
        self.script = script
        self.session = session
        self.clock = clock
        self.armed: list[tuple[float, int, Callable[[], None]]] = []
        self.seq = 0
        self.errors: list[str] = []
        self.opened: dict[tuple[int, int], float] = {}
        self.next_step = [0] * len(script.questions)
        self.last_time: list[float | None] = [None] * len(script.questions)
        self.waiting = [False] * len(script.questions)
        #: per question, the attempt an ``attempt: any`` answer was armed in (stale once it timed out)
        self.armed_in: list[int | None] = [None] * len(script.questions)
        self.events: list[SessionEvent] = []
        #: the questions whose go_on was used (the kiosk waited after them)
        self.went_on: set[int] = set()
        #: the question whose unanswered end made the kiosk wait for a touch
        self._last_unanswered: int | None = None
        #: item number -> the script's question for it (staff items are never asked, nor scripted)
        asked = [item for item in session.questionnaire.items if not item.staff]
        self._question_of = {item.number: i for i, item in enumerate(asked)}
        session.subscribe(self._on_event)

    def arm(self, due: float, action: Callable[[], None]) -> None:
        self.seq += 1
        self.armed.append((due, self.seq, action))

    # events

    def _on_event(self, event: SessionEvent) -> None:
        self.events.append(event)
        now = self.clock.now()
        if isinstance(event, PhaseChanged) and event.phase is Phase.EXPLANATION:
            self.arm(now + self.script.acknowledge_after, self.session.acknowledge)
        elif isinstance(event, PhaseChanged) and event.phase is Phase.REST:  # a battery's next instrument
            self.arm(now + self.script.rest_after, self.session.acknowledge)
        elif isinstance(event, AttemptOpened) and event.practice:
            if self.script.practice is not None and event.attempt == 1 and event.number <= len(self.script.practice):
                step = self.script.practice[event.number - 1]
                self.arm(now + step.after, partial(self._give_answer, step, None))
        elif isinstance(event, AttemptOpened):
            index = self._question_of[event.number]
            self.opened[(index, event.attempt)] = now
            self._try_arm(index)
        elif isinstance(event, AttemptTimedOut) and not event.practice:
            index = self._question_of[event.number]
            question = self.script.questions[index]
            pending = question.steps[self.next_step[index] :]
            if pending and pending[0].attempt == ANY:  # too slow for this attempt: again on the next
                self.waiting[index] = False
                self.armed_in[index] = None
            elif pending and pending[0].kind == "answer" and pending[0].attempt == event.attempt:
                self.errors.append(
                    f"{pending[0].where}: the answer declared on attempt {event.attempt} "
                    f"({pending[0].after:g} s after it opened) never happened: attempt {event.attempt} "
                    f"timed out at t={_num(event.t)} s under the session's rules"
                )
        elif isinstance(event, Unattended) and self._last_unanswered is not None:
            self._unattended(self._last_unanswered, now)
        elif isinstance(event, (AnswerRecorded, QuestionNotAnswered)):
            index = self._question_of[event.number]
            if isinstance(event, QuestionNotAnswered):
                self._last_unanswered = index
            question = self.script.questions[index]
            pending = question.steps[self.next_step[index] :]
            if (
                isinstance(event, QuestionNotAnswered)
                and question.attempt == ANY
                and pending
                and pending[0].kind == "answer"
            ):
                self.next_step[index] = len(question.steps)  # never fast enough: not answered
            elif pending and not (isinstance(event, AnswerRecorded) and pending[0].kind == "undo"):
                self.errors.append(
                    f"{pending[0].where}: the declared {pending[0].kind} never happened: "
                    f"question {event.number} ({question.item.id}) ended at t={_num(event.t)} s"
                )
            elif isinstance(event, QuestionNotAnswered) and question.attempt not in (None, ANY):
                self.errors.append(
                    f"{question.where}: declared answered on attempt {question.attempt} "
                    f"but the question was not answered"
                )

    def _unattended(self, index: int, now: float) -> None:
        """The kiosk waits for a touch after question ``index``: the script's go_on touches (a slow
        patient's ``attempt: any`` question: at once, as they are there)."""
        question = self.script.questions[index]
        if question.go_on is not None and question.go_on.channel is not None:
            self.went_on.add(index)
            touch = ChannelInput(question.go_on.channel, option=1, detail="script")
            self.arm(now + question.go_on.after, partial(self.session.handle, touch))
        elif question.attempt == ANY:
            self.arm(now, partial(self.session.handle, ChannelInput(Channel.TOUCH, option=1, detail="script")))

    def _try_arm(self, index: int) -> None:
        question = self.script.questions[index]
        k = self.next_step[index]
        if self.waiting[index] or k >= len(question.steps):
            return
        step = question.steps[k]
        base = self.last_time[index]
        if step.attempt == ANY and step.kind == "answer":
            attempt = self.session.current_attempt
            if attempt is None or (index, attempt) not in self.opened:
                return  # armed once an attempt of this question opens
            self.armed_in[index] = attempt
            base = self.opened[(index, attempt)]
        elif step.attempt is not None and step.attempt != ANY:
            opened = self.opened.get((index, step.attempt))
            if opened is None:
                return  # armed once that attempt opens
            base = opened if base is None else max(base, opened)
        if base is None:
            return
        self.waiting[index] = True
        armed_in = self.armed_in[index]
        self.arm(base + step.after, lambda: self._run_step(index, step, armed_in))

    def _run_step(self, index: int, step: Step, armed_in: int | None = None) -> None:
        if step.attempt == ANY and step.kind == "answer" and self.armed_in[index] != armed_in:
            return  # the attempt it was waiting in timed out first
        self.waiting[index] = False
        self.next_step[index] += 1
        self.last_time[index] = self.clock.now()
        if step.kind in ("answer", "then"):
            self._give_answer(step, index)
        elif step.kind == "confirm":
            if self.session.snapshot().confirming is None:
                self.errors.append(f"{step.where}: the reply to 'Is that right?' came when nothing was asked back")
            else:
                self._give_answer(step, index, check=False)
        elif step.kind == "undo":
            assert step.channel is not None
            undo = ChannelInput(step.channel, command=Command.UNDO, detail=step.say or "script")
            self.session.handle(undo)
            if any(isinstance(e, InputIgnored) and e.input is undo for e in self.events):
                self.errors.append(
                    f"{step.where}: the undo came too late: the answer could no longer be changed "
                    f"at t={_num(self.session.now())} s"
                )
        elif step.kind in COMMANDS:
            assert step.channel is not None
            self.session.handle(ChannelInput(step.channel, command=COMMANDS[step.kind], detail="script"))
        elif step.kind == "continue":
            self.session.clinician_continue()
        elif step.kind in ("person_lost", "person_back"):
            self.session.handle(Presence(step.kind == "person_back", step.source, "script"))
        elif step.kind == "unheard":
            self.session.voice_unheard("the script: speech the voice channel could not take")
        self._try_arm(index)

    def _give_answer(self, step: Step, index: int | None, check: bool = True) -> None:
        assert step.channel is not None and step.option is not None
        if index is not None and check:
            item = self.session.current_item
            attempt = self.session.current_attempt
            if (
                (attempt is None if step.attempt == ANY else attempt != step.attempt)
                or item is None
                or self._question_of.get(item.number) != index
            ):
                state = (
                    f"question {item.number} attempt {self.session.current_attempt}"
                    if item
                    else f"phase {self.session.phase.value}"
                )
                self.errors.append(
                    f"{step.where}: the answer declared on attempt {step.attempt} came when the session was at {state}"
                )
                return
        given = ChannelInput(
            step.channel,
            option=step.option,
            detail=step.say or "script",
            confidence=UNSURE_CONFIDENCE if step.unsure else None,
            needs_confirmation=step.unsure,
        )
        self.session.handle(given)
        ignored = [e for e in self.events if isinstance(e, InputIgnored) and e.input is given]
        if ignored:
            what = "practice answer" if index is None else f"answer declared on attempt {step.attempt}"
            self.errors.append(
                f"{step.where}: the session ignored the {what} ({ignored[0].reason.value}) "
                f"at t={_num(self.session.now())} s"
            )

    # the loop

    def run(self) -> None:
        self.arm(self.script.start_at, lambda: self.session.start(self.script.answered_by))
        for _ in range(100_000):  # a bound, so a script/session bug cannot loop forever
            if self.errors:
                raise ScriptError(self.errors[0])
            if self.session.finished:
                self._check_go_on()
                return
            self.armed.sort()
            deadline = self.session.next_deadline()
            # an input at the same instant as a time-out goes first (the window includes its end)
            if self.armed and (deadline is None or self.armed[0][0] <= deadline):
                due, _, action = self.armed.pop(0)
                self.clock.set(max(due, self.clock.now()))
                action()
            elif deadline is not None:
                self.clock.set(max(deadline, self.clock.now()))
                self.session.poll()
            else:
                raise ScriptError(
                    f"{self.script.source}: the script ends while the session waits "
                    f"({self._waiting_for()}) at t={_num(self.session.now())} s"
                )
        raise ScriptError(f"{self.script.source}: the replay did not finish")

    def _check_go_on(self) -> None:
        for index, question in enumerate(self.script.questions):
            if question.go_on is not None and index not in self.went_on:
                raise ScriptError(
                    f"{question.go_on.where}: the kiosk never waited for a touch after this question "
                    "(go_on): fewer questions in a row went unanswered than unattended_after"
                )

    def _waiting_for(self) -> str:
        s = self.session
        if s.snapshot().unattended:
            where = self.script.questions[self._last_unanswered].where if self._last_unanswered is not None else ""
            return f"waiting for a touch after questions in a row went unanswered: give go_on at {where}"
        if s.halted:
            return "doctor called, no clinician continue"
        if s.paused:
            return "paused, never resumed"
        if not s.snapshot().person_present:
            return "person lost, never back"
        return f"phase {s.phase.value}"


def run_script(
    script: Script,
    questionnaire: Questionnaire | None = None,
    *,
    store: Any = None,
    model: str = DEFAULT_MODEL,
    policy: Any = None,
    visit: str | None = None,
) -> ReplayResult:
    """Run a script through a real Session and QoS engine on a simulated clock, adapting by
    ``policy`` (default: the bundled adaptation policy) when the script turns adaptation on.

    ``model`` is the QoS model (a bundled name or a .roqme path, as ``qos_model:`` in the
    configuration); its timers fire on the simulated clock while nothing happens, as at the kiosk.
    ``visit`` is the session's ``visit`` log entry (``kiosk.core.visits``), e.g. the order it runs.
    """
    from kiosk.core.adaptation import Adaptation, load_policy
    from kiosk.core.qos_model import load_kiosk_model
    from qos import Engine, Trace, replay

    questionnaire = questionnaire or load_questionnaire()
    reference, loaded = model, load_kiosk_model(model)
    clock = SimClock()
    session = Session(
        questionnaire,
        clock=clock,
        engine=Engine(loaded),
        store=store,
        patient_id=script.patient,
        language=script.language,
        answered_by=script.answered_by,
        timing=script.timing,
        adaptation=Adaptation(policy or load_policy(model=loaded)) if script.adaptation else None,
        familiarisation=script.practice is not None,
        visit=visit,
        watching=script.watching,
        room=RoomHearing(),  # a replay stands in a room of its own, heard from scratch
    )
    driver = _Driver(script, session, clock)
    try:
        driver.run()
        trace = Trace.from_events(reference, session.trace)
        summary = replay(trace, model=loaded)
    except KeyboardInterrupt:
        if store is not None:
            # Ctrl-C mid-script: the half-replayed patient is closed, never left for anyone to resume
            store.abandon(session.id)
        raise
    except (ScriptError, QosError, BadFile) as exc:
        if store is not None:
            # a scripted patient that went wrong must not be offered for resuming at the kiosk
            store.abandon(session.id)
        if isinstance(exc, ScriptError):
            raise
        # the session ran, but its QoS replay is refused (a session of weeks at 1 s samples)
        raise ScriptError(f"{script.source}:1:1: the simulated session cannot be replayed: {exc}") from None
    return ReplayResult(script, session, trace, summary, session.now(), driver.events)


def run_battery(
    script: BatteryScript,
    *,
    models: Mapping[str, str | None] | None = None,
    store: Any = None,
    model: str = DEFAULT_MODEL,
    policy: Any = None,
    visit: str | None = None,
) -> list[ReplayResult]:
    """Run a battery script as the kiosk runs a battery (:class:`kiosk.core.session.battery.Battery`):
    each instrument's session after the previous one finished, on one simulated clock, one
    engine and trace per QoS model. One :class:`ReplayResult` per instrument, whose ``trace`` and
    ``qos`` are the visit's up to that instrument's end. ``models``: an instrument id's own QoS
    model (a bundled name or a .roqme path; missing or None: ``model``)."""
    from kiosk.core.adaptation import Adaptation, load_policy
    from kiosk.core.qos_model import load_kiosk_model
    from kiosk.core.session.battery import Battery, Instrument
    from qos import Engine, Trace, replay

    own = dict(models or {})
    loaded = {name: load_kiosk_model(name) for name in {model, *(m for m in own.values() if m)}}
    first = script.scripts[0]
    clock = SimClock()
    battery = Battery(
        [Instrument(q, own.get(q.id)) for q in script.instruments],
        make_engine=lambda name: Engine(loaded[str(name or model)]),
        shared={
            "clock": clock,
            "store": store,
            "timing": first.timing,
            "adaptation": Adaptation(policy or load_policy(model=loaded[model])) if first.adaptation else None,
            "watching": first.watching,
            "room": RoomHearing(),
        },
    )
    results: list[ReplayResult] = []
    session: Session | None = None
    for index, part in enumerate(script.scripts):
        if session is None:
            session = battery.first(
                patient_id=part.patient,
                language=part.language,
                answered_by=part.answered_by,
                familiarisation=part.practice is not None,
                visit=visit,
            )
        else:
            session = battery.after(session)
            assert session is not None
            part = replace(part, start_at=clock.now())  # the kiosk starts the next one at once
        driver = _Driver(part, session, clock)
        name = own.get(part_id := script.instruments[index].id) or model
        try:
            driver.run()
            trace = Trace.from_events(name, list(session.trace))
            summary = replay(trace, model=loaded[name])
        except (ScriptError, QosError, BadFile) as exc:
            if store is not None:
                store.abandon(session.id)
            if isinstance(exc, ScriptError):
                raise
            raise ScriptError(f"{script.source}:1:1: the simulated {part_id} cannot be replayed: {exc}") from None
        results.append(ReplayResult(part, session, trace, summary, session.now(), driver.events))
    return results

"""Scripted patients: run the real session core on a simulated clock (`kiosk replay FILE`).

A script (``recordings/patients/*.yaml``, format in ``recordings/patients/README.md``) says what a
simulated patient does: when they start, what they answer on which attempt and through which
channel, and the incidents (pause/resume, call doctor/continue, person lost/back, repeat). The
driver here feeds those inputs to a real :class:`~kiosk.core.session.Session` with a real QoS engine,
lets the session's own time-outs happen on a :class:`~kiosk.core.clock.SimClock`, and checks that what
the script declared really happened under the session's rules -- an answer declared on attempt 1
that would arrive after attempt 1 timed out is an error, not a silently different session.

Times in a script are relative: an action happens ``after`` seconds counted from the later of
the opening of the attempt it names and the previous action of the same question.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from fileio.bounded import BadFile
from fileio.positions import Problem, describe, parse_file, schema_problems
from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.clock import SimClock
from kiosk.core.qos_model import DEFAULT_MODEL
from kiosk.core.questionnaire import Item, PracticeQuestion, Questionnaire, QuestionnaireError, load_questionnaire
from kiosk.core.session import (
    AnswerRecorded,
    AttemptOpened,
    AttemptTimedOut,
    InputIgnored,
    Phase,
    PhaseChanged,
    QuestionNotAnswered,
    Session,
    SessionEvent,
)
from kiosk.store.lease import SessionTaken
from qos.errors import QosError
from qos.trace import seconds

#: ``attempt: any``: the patient answers ``after`` seconds into whichever attempt lets them (a slow
#: patient: too slow for a window, they start again on the next); not answered if none does
ANY = 0
#: the confidence a scripted unsure voice answer (``unsure: true``) is heard with
UNSURE_CONFIDENCE = 0.5

#: incidents that are commands a patient gives through a channel
_COMMANDS = {
    "pause": Command.PAUSE,
    "resume": Command.RESUME,
    "call_doctor": Command.CALL_DOCTOR,
    "repeat": Command.REPEAT,
}


class ScriptError(ValueError):
    """A script is malformed, or declares something that does not happen under the session's rules."""


def _script_error(problems: list[Problem]) -> ScriptError:
    """One message: the first problem in file order, and how many more there are."""
    first = min(problems, key=lambda p: (p.line, p.column))
    more = f" (and {len(problems) - 1} more problems)" if len(problems) > 1 else ""
    return ScriptError(f"{first}{more}")


@cache
def _schema() -> dict[str, Any]:
    return json.loads(resources.files("kiosk.commands").joinpath("patient.schema.json").read_text(encoding="utf-8"))


# ---------------------------------------------------------------------------------------------
# The script


@dataclass(frozen=True)
class Step:
    """One timed action of a script: an answer, an incident, or a practice answer."""

    #: "answer", "practice", "confirm" (Yes/No to "Is that right?"), "undo", "then" (the answer
    #: after a No or an undo) or the incident ("pause", "continue", ...)
    kind: str
    #: the attempt this step is counted from (None: from the previous step of its question;
    #: :data:`ANY`: from whichever attempt is open)
    attempt: int | None
    after: float
    channel: Channel | None = None
    option: int | None = None
    say: str | None = None
    #: a voice answer the recogniser was not sure of (the session asks it back)
    unsure: bool = False
    #: where it is written, for messages: "file:line:col: questions[2].incidents[0]"
    where: str = ""


@dataclass(frozen=True)
class Question:
    """What the patient does on one question: incidents, then an answer (or none)."""

    item: Item
    #: 1, 2, or None when the patient never answers
    attempt: int | None
    steps: tuple[Step, ...]
    where: str


@dataclass(frozen=True)
class Script:
    """A validated scripted patient."""

    source: str
    patient: str
    description: str
    language: str
    answered_by: str
    adaptation: bool
    start_at: float
    acknowledge_after: float
    timing: dict[str, float]
    practice: tuple[Step, ...] | None
    questions: tuple[Question, ...]


def load_script(path: str | Path, questionnaire: Questionnaire | None = None) -> Script:
    """Read and check a scripted patient; :class:`ScriptError` lists every problem with its position."""
    questionnaire = questionnaire or load_questionnaire()
    name = str(path)
    data, positions, problems = parse_file(path)
    if positions is None or not isinstance(data, dict):
        problems = problems or [Problem(name, 1, 1, "a script is a mapping (patient:, questions:, ...)")]
        raise _script_error(problems)

    def where(p: tuple[Any, ...], key: bool = False) -> str:
        line, col = positions.of(p, key=key)
        return f"{name}:{line}:{col}"

    def add(p: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(p, key=key)
        problems.append(Problem(name, line, col, message))

    schema_problems(data, _schema(), positions, add)
    if problems:
        raise _script_error(problems)

    language = data.get("language", "en")
    if language not in questionnaire.languages:
        add(("language",), f"language {language!r} is not one of {', '.join(questionnaire.languages)}")
    try:
        questionnaire.timing.with_overrides(data.get("timing"))
    except ValueError as exc:
        add(("timing",), str(exc))
    if len(data["questions"]) != len(questionnaire.items):
        add(
            ("questions",),
            f"the script has {len(data['questions'])} questions; the questionnaire has {len(questionnaire.items)}",
        )
    if problems:
        raise _script_error(problems)

    def answer_step(
        p: tuple[Any, ...], entry: dict[str, Any], question: Item | PracticeQuestion, kind: str, attempt: int | None
    ) -> Step | None:
        if "option" in entry and "say" in entry:
            add(p, f"{describe(p)} gives both 'option' and 'say'; give one")
            return None
        if "option" not in entry and "say" not in entry:
            add(p, f"{describe(p)} answers on attempt {attempt} but gives no 'option' or 'say'")
            return None
        if "channel" not in entry:
            add(p, f"{describe(p)} answers but gives no 'channel'")
            return None
        channel = Channel(entry["channel"])
        option = entry.get("option")
        if option is not None and option > len(question.options):
            add(p + ("option",), f"{question.id!r} has {len(question.options)} options, not {option}")
            return None
        if "say" in entry:
            if channel is not Channel.VOICE:
                add(p + ("say",), f"'say' needs channel voice, not {channel.value}")
                return None
            option = _match(question, language, entry["say"])
            if isinstance(option, str):
                add(p + ("say",), option)
                return None
        if entry.get("unsure") and channel is not Channel.VOICE:
            add(p + ("unsure",), f"only a voice answer can be unsure, not a {channel.value} one")
            return None
        return Step(
            kind,
            attempt,
            float(entry.get("after", 0)),
            channel,
            option,
            entry.get("say"),
            bool(entry.get("unsure")),
            where(p),
        )

    def corrections(p: tuple[Any, ...], entry: dict[str, Any], item: Item, attempt: int) -> list[Step]:
        """The steps after an answer: Yes/No to an unsure one, an undo, the answer that follows."""
        steps: list[Step] = []
        declined = False
        if entry.get("unsure") and "confirm" not in entry:
            add(p + ("unsure",), f"{describe(p)} is unsure: say what the patient replies (confirm:)", key=True)
        if "confirm" in entry:
            reply = entry["confirm"]
            if not entry.get("unsure"):
                add(p + ("confirm",), "only an unsure answer (unsure: true) is asked back", key=True)
            channel = Channel(reply.get("channel", "voice"))
            option = reply.get("option")
            if "say" in reply:
                option = _match_reply(language, reply["say"])
                if isinstance(option, str):
                    add(p + ("confirm", "say"), option)
                    return steps
            steps.append(
                Step(
                    "confirm",
                    None,
                    float(reply.get("after", 0)),
                    channel,
                    option,
                    reply.get("say"),
                    where=where(p + ("confirm",)),
                )
            )
            declined = option == 2
        if "undo" in entry:
            if declined:
                add(p + ("undo",), "a declined answer was never stored: there is nothing to undo", key=True)
            undo = entry["undo"]
            steps.append(
                Step(
                    "undo",
                    None,
                    float(undo.get("after", 0)),
                    Channel(undo.get("channel", "touch")),
                    say=undo.get("say"),
                    where=where(p + ("undo",)),
                )
            )
        if "then" in entry:
            if not (declined or "undo" in entry):
                add(p + ("then",), "'then' is the answer after a No (confirm) or an undo", key=True)
            elif (step := answer_step(p + ("then",), entry["then"], item, "then", attempt)) is not None:
                steps.append(step)
        elif declined or "undo" in entry:
            add(p, f"{describe(p)} takes its answer back: say what the patient answers next (then:)")
        return steps

    practice: tuple[Step, ...] | None = None
    if isinstance(data.get("familiarisation"), list):
        steps = []
        entries = data["familiarisation"]
        if len(entries) != len(questionnaire.familiarisation):
            add(
                ("familiarisation",),
                f"the script answers {len(entries)} practice questions; "
                f"the questionnaire has {len(questionnaire.familiarisation)}",
            )
        for i, (entry, pq) in enumerate(zip(entries, questionnaire.familiarisation)):
            step = answer_step(("familiarisation", i), entry, pq, "practice", 1)
            if step:
                steps.append(step)
        practice = tuple(steps)

    questions = []
    for i, (entry, item) in enumerate(zip(data["questions"], questionnaire.items)):
        p = ("questions", i)
        if "item" in entry and entry["item"] != item.id:
            add(p + ("item",), f"question {i + 1} of the questionnaire is {item.id!r}, not {entry['item']!r}")
        attempt = {"none": None, "any": ANY}.get(entry["attempt"], entry["attempt"])
        steps = []
        for j, incident in enumerate(entry.get("incidents", [])):
            ip = p + ("incidents", j)
            if "channel" in incident and incident["do"] not in _COMMANDS:
                add(ip + ("channel",), f"{incident['do']!r} is not given through a channel")
            anchor = incident.get("attempt", 1 if j == 0 else None)
            channel = Channel(incident.get("channel", "touch"))
            steps.append(Step(incident["do"], anchor, float(incident.get("after", 0)), channel, where=where(ip)))
        if attempt is None:
            for key in ("option", "say", "channel", "after", "unsure", "confirm", "undo", "then"):
                if key in entry:
                    add(p + (key,), f"{describe(p)} is not answered (attempt: none) but gives {key!r}", key=True)
        else:
            step = answer_step(p, entry, item, "answer", attempt)
            if step:
                steps.append(step)
                steps += corrections(p, entry, item, attempt)
        questions.append(Question(item, attempt, tuple(steps), where(p)))
    if problems:
        raise _script_error(problems)
    return Script(
        source=name,
        patient=data["patient"],
        description=data.get("description", ""),
        language=language,
        answered_by=data.get("answered_by", "patient"),
        adaptation=data.get("adaptation", True),
        start_at=float(data.get("start_at", 0)),
        acknowledge_after=float(data.get("acknowledge_after", 0)),
        timing=dict(data.get("timing", {})),
        practice=practice,
        questions=tuple(questions),
    )


def _match_reply(language: str, utterance: str) -> int | str:
    """Yes (1) or No (2), as the voice channel would hear ``utterance`` asked "Is that right?"."""
    from kiosk.core.session.words import CONFIRM_WORDS
    from kiosk.speech.matching import Matcher, OptionWords

    words = CONFIRM_WORDS.get(language, CONFIRM_WORDS["en"])
    match = Matcher([OptionWords(label, synonyms) for label, synonyms in words.values()], language).match(utterance)
    if match.option is None:
        return f"{utterance!r} is not a yes or a no: {match.reason or 'a command'}"
    return match.option


def _match(question: Item | PracticeQuestion, language: str, utterance: str) -> int | str:
    """The option an utterance selects, with the speech helper's matcher; a message if none."""
    from kiosk.speech.matching import Matcher, OptionWords

    matcher = Matcher([OptionWords(o.label_in(language), o.synonyms_in(language)) for o in question.options], language)
    match = matcher.match(utterance)
    if match.option is None:
        return f"on {question.id!r}, {match.reason or repr(utterance) + ' is a command, not an answer'}"
    return match.option


# ---------------------------------------------------------------------------------------------
# Running a script


@dataclass
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
                if type(e).__name__ == "AdaptationChanged"
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
        elif isinstance(event, AttemptOpened) and event.practice:
            if self.script.practice is not None and event.attempt == 1 and event.number <= len(self.script.practice):
                step = self.script.practice[event.number - 1]
                self.arm(now + step.after, lambda s=step: self._give_answer(s, None))
        elif isinstance(event, AttemptOpened):
            index = event.number - 1
            self.opened[(index, event.attempt)] = now
            self._try_arm(index)
        elif isinstance(event, AttemptTimedOut) and not event.practice:
            index = event.number - 1
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
        elif isinstance(event, (AnswerRecorded, QuestionNotAnswered)):
            index = event.number - 1
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
        elif step.kind in _COMMANDS:
            assert step.channel is not None
            self.session.handle(ChannelInput(step.channel, command=_COMMANDS[step.kind], detail="script"))
        elif step.kind == "continue":
            self.session.clinician_continue()
        elif step.kind == "person_lost":
            self.session.person_lost()
        elif step.kind == "person_back":
            self.session.person_back()
        self._try_arm(index)

    def _give_answer(self, step: Step, index: int | None, check: bool = True) -> None:
        assert step.channel is not None and step.option is not None
        if index is not None and check:
            item = self.session.current_item
            attempt = self.session.current_attempt
            if (
                (attempt is None if step.attempt == ANY else attempt != step.attempt)
                or item is None
                or item.number != index + 1
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

    def _waiting_for(self) -> str:
        s = self.session
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
    reference, model = model, load_kiosk_model(model)
    clock = SimClock()
    session = Session(
        questionnaire,
        clock=clock,
        engine=Engine(model),
        store=store,
        patient_id=script.patient,
        language=script.language,
        answered_by=script.answered_by,
        timing=script.timing,
        adaptation=Adaptation(policy or load_policy(model=model)) if script.adaptation else None,
        familiarisation=script.practice is not None,
        visit=visit,
    )
    driver = _Driver(script, session, clock)
    try:
        driver.run()
        trace = Trace.from_events(reference, session.trace)
        summary = replay(trace, model=model)
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


def _print_human(result: ReplayResult) -> None:
    data = result.to_dict()
    score = data["score"]
    band = f", {score['band']}" if score["band"] else ""
    status = "complete" if score["complete"] else f"incomplete ({len(data['not_answered'])} not answered)"
    print(f"{data['script']}: patient {data['patient']} ({data['language']}, answered by {data['answered_by']})")
    print(f"score {score['total']}/{score['max_total']} {status}{band}; simulated {data['simulated_s']} s")
    for answer in data["answers"]:
        print(
            f"  {answer['item']:<10} option {answer['option']}  {answer['points']:>2} points  "
            f"attempt {answer['attempt']}  {answer['channel']:<8} t={answer['t']}"
        )
    for item in data["not_answered"]:
        print(f"  {item:<10} not answered")
    for adaptation in data["adaptations"]:
        state = "on" if adaptation["active"] else "off"
        print(f"  adaptation {adaptation['name']} {state} at t={adaptation['t']}: {adaptation['reason']}")
    print("QoS        min     max     avg     sd      last")
    for name, stats in data["qos"]["metrics"].items():
        print(f"  {name:<24} " + " ".join(f"{stats[k]:.4f}" for k in ("min", "max", "avg", "sd", "last")))


class _NoOrder(Exception):
    """The station did not give the ordered visit (message says why)."""


def _take_order(code: str, config: Any, questionnaire: Questionnaire) -> Any:
    """The ordered visit whose code staff gave, started at the configured station."""
    if config.station is None:
        raise _NoOrder("--order-code needs a station in the configuration (station: {url, token, kiosk_id})")
    from kiosk.sync.http import Station, Unreachable
    from kiosk.sync.orders import OrderRefused, start_order

    try:
        return start_order(
            Station(config.station.url, config.station.token),
            code,
            instruments=[questionnaire.id],
            languages=list(questionnaire.languages),
        )
    except (OrderRefused, Unreachable) as exc:
        raise _NoOrder(f"the visit with code {code} was not started: {exc}") from None


def main(argv: list[str]) -> int:
    """`kiosk replay FILE... [--json] [--trace OUT] [--data-dir DIR]`; exit 0, or 2 on a bad script."""
    parser = argparse.ArgumentParser(
        prog="kiosk replay",
        description="Run scripted patients through the real session core and QoS engine on a simulated clock.",
    )
    parser.add_argument("files", nargs="+", metavar="FILE", help="scripted patient YAML file(s)")
    parser.add_argument("--json", action="store_true", help="print one JSON object per script")
    parser.add_argument("--trace", metavar="OUT", help="write the context trace (one script only)")
    parser.add_argument(
        "--data-dir",
        metavar="DIR",
        help="also store the replayed sessions in this data directory (see `kiosk results`)",
    )
    parser.add_argument(
        "--config",
        metavar="FILE",
        help="configuration file (default: $KIOSK_CONFIG or the user's): its questionnaire, "
        "band set, adaptation policy and QoS model are the ones replayed, as at the kiosk",
    )
    parser.add_argument(
        "--station-wait",
        metavar="S",
        type=float,
        default=30.0,
        help="with a station configured, how long to try delivering the stored sessions to it "
        "before exiting (default 30; what is left goes with the next kiosk run)",
    )
    parser.add_argument(
        "--order-code",
        metavar="CODE",
        help="run the script as the visit ordered for this kiosk whose code the station shows "
        "(one script; needs --data-dir and a station): its patient and language are the order's",
    )
    args = parser.parse_args(argv)
    if args.trace and len(args.files) != 1:
        parser.error("--trace takes one script")
    if args.order_code and (len(args.files) != 1 or not args.data_dir):
        parser.error("--order-code takes one script and --data-dir")
    from kiosk.config import ConfigError, configured_questionnaire, load_config
    from kiosk.core.adaptation import PolicyError, load_policy
    from kiosk.core.qos_model import load_kiosk_model

    try:
        config = load_config(args.config)
        questionnaire = configured_questionnaire(config)
        policy = load_policy(config.adaptation_policy, model=load_kiosk_model(config.qos_model))
    except QuestionnaireError as exc:
        print(f"kiosk replay: the questionnaire is invalid: {exc}", file=sys.stderr)
        return 2
    except (ConfigError, PolicyError, QosError, BadFile) as exc:
        print(f"kiosk replay: {exc}", file=sys.stderr)
        return 2
    store = None
    if args.data_dir:
        from kiosk.store.database import StorageError, Store

        try:
            # scripted patients: never offered to anyone; queued for the station when there is one
            from kiosk.export import export_identity, site_from_config
            from kiosk.export.opening import in_force_of

            store = Store.open(
                args.data_dir,
                simulated=True,
                outbox=config.station is not None,
                export=export_identity(site_from_config(config)),
                in_force=lambda: in_force_of(config),
            )
        except StorageError as exc:
            print(f"kiosk replay: {exc}", file=sys.stderr)
            return 2
    results = []
    try:
        order = _take_order(args.order_code, config, questionnaire) if args.order_code else None
        for file in args.files:
            script = load_script(file, questionnaire)
            if order is not None:  # the ordered patient, language and answerer, never the script's own
                script = replace(
                    script, patient=order.patient_id, language=order.language, answered_by=order.answered_by
                )
            results.append(
                run_script(
                    script,
                    questionnaire,
                    store=store,
                    model=config.qos_model,
                    policy=policy,
                    visit=order.visit if order is not None else None,
                )
            )
    except ScriptError as exc:
        print(exc, file=sys.stderr)
        return 2
    except _NoOrder as exc:
        print(f"kiosk replay: {exc}", file=sys.stderr)
        return 2
    except SessionTaken as exc:  # another kiosk on this data directory took the session over
        print(f"kiosk replay: {exc}", file=sys.stderr)
        return 2
    finally:
        if store is not None:
            store.close()
    if store is not None and config.station is not None:
        from kiosk.sync import deliver_pending

        unsent = deliver_pending(store.path, config.station, max(0.0, args.station_wait))
        if unsent:
            print(f"kiosk replay: {unsent}", file=sys.stderr)
    if args.trace:
        from fileio.bounded import write_error
        from qos import dump_trace

        try:
            dump_trace(results[0].trace, args.trace, header=f"context trace of {results[0].script.source}")
        except OSError as exc:
            print(f"kiosk replay: {write_error(args.trace, exc)}", file=sys.stderr)
            return 2
    for result in results:
        if args.json:
            print(json.dumps(result.to_dict(), ensure_ascii=False))
        else:
            _print_human(result)
    return 0

"""Scripted patients: the script format, read and checked against the questionnaire.

Every problem is reported with its ``file:line:col``; a script that loads is one the driver can run.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import replace
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from basis import record
from basis.errors import KioskError
from fileio.positions import Problem, describe, parse_file, schema_problems
from kiosk.core.channels import Channel, Command, PresenceSource
from kiosk.core.questionnaire import Item, PracticeQuestion, Questionnaire, load_questionnaire
from kiosk.core.session import Watching

#: ``attempt: any``: the patient answers ``after`` seconds into whichever attempt lets them (a slow
#: patient: too slow for a window, they start again on the next); not answered if none does
ANY = 0
#: the confidence a scripted unsure voice answer (``unsure: true``) is heard with
UNSURE_CONFIDENCE = 0.5

#: incidents that are commands a patient gives through a channel
COMMANDS = {
    "pause": Command.PAUSE,
    "resume": Command.RESUME,
    "call_doctor": Command.CALL_DOCTOR,
    "repeat": Command.REPEAT,
}


class ScriptError(KioskError, ValueError):
    """A script is malformed, or declares something that does not happen under the session's rules."""


def _script_error(problems: list[Problem]) -> ScriptError:
    """One message: the first problem in file order, and how many more there are."""
    first = min(problems, key=lambda p: (p.line, p.column))
    more = f" (and {len(problems) - 1} more problems)" if len(problems) > 1 else ""
    return ScriptError(f"{first}{more}")


@cache
def _schema() -> dict[str, Any]:
    return json.loads(resources.files("kiosk.commands").joinpath("patient.schema.json").read_text(encoding="utf-8"))


@record
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
    #: who reports a person_lost/person_back incident
    source: PresenceSource = PresenceSource.CAMERA


@record
class Question:
    """What the patient does on one question: incidents, then an answer (or none)."""

    item: Item
    #: 1, 2, or None when the patient never answers
    attempt: int | None
    steps: tuple[Step, ...]
    where: str
    #: the touch that goes on when the kiosk waits after this unanswered question (``go_on:``)
    go_on: Step | None = None


@record
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
    #: seconds on the rest screen before Continue (a battery's later instruments)
    rest_after: float = 0.0
    #: the site's settings about a patient who is not there (the kiosk's defaults unless given)
    watching: Watching = Watching()


@record
class BatteryScript:
    """A scripted patient answering a battery: one :class:`Script` per instrument, in order."""

    source: str
    scripts: tuple[Script, ...]
    #: each instrument's questionnaire, in the same order
    instruments: tuple[Questionnaire, ...]


class _Within:
    """Positions of an instrument's entry in a battery script: the entry's own keys are under
    ``instruments[index]``, the visit's (patient, language, timing...) at the top."""

    def __init__(self, positions: Any, index: int, own: set[str]) -> None:
        self.positions, self.index, self.own = positions, index, own

    def of(self, path: tuple[Any, ...], key: bool = False) -> tuple[int, int]:
        if path and path[0] in self.own:
            return self.positions.of(("instruments", self.index, *path), key=key)
        return self.positions.of(path if path else ("instruments", self.index), key=key)


def is_battery_script(path: str | Path) -> bool:
    """The file is a battery script (``instruments:``); False for anything else (bad files too:
    :func:`load_script` then says what is wrong)."""
    data, _, problems = parse_file(path)
    return not problems and isinstance(data, dict) and "instruments" in data


def load_battery_script(path: str | Path, instruments: Mapping[str, Questionnaire] | None = None) -> BatteryScript:
    """Read and check a battery script. Each ``instruments:`` entry names an instrument by ``id``
    (one of ``instruments``, the configuration's, else a shipped one) or ``file`` (relative to the
    script) and gives its answers as a one-instrument script does; the visit's keys (patient,
    language, timing, ...) are at the top. :class:`ScriptError` names every problem's position."""
    from kiosk.core.questionnaire import QuestionnaireError
    from kiosk.core.questionnaire.loading import bundled_path

    name = str(path)
    data, positions, problems = parse_file(path)
    if positions is None or not isinstance(data, dict):
        raise _script_error(problems or [Problem(name, 1, 1, "a script is a mapping (patient:, instruments:, ...)")])

    def add(p: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(p, key=key)
        problems.append(Problem(name, line, col, message))

    schema_problems(data, _schema(), positions, add)
    if "questions" in data or "familiarisation" in data:
        add(
            ("questions" if "questions" in data else "familiarisation",),
            "a battery script gives questions per instrument",
            key=True,
        )
    if problems:
        raise _script_error(problems)
    known = dict(instruments or {})
    shared = {k: v for k, v in data.items() if k != "instruments"}
    scripts: list[Script] = []
    found: list[Questionnaire] = []
    for index, entry in enumerate(data["instruments"]):
        where = ("instruments", index)
        if ("id" in entry) == ("file" in entry):
            add(where, f"{describe(where)} names its instrument by id or by file (one of them)")
            continue
        try:
            if "id" in entry and entry["id"] in known:
                questionnaire = known[entry["id"]]
            elif "id" in entry and bundled_path(f"{entry['id']}.yaml").is_file():
                questionnaire = load_questionnaire(bundled_path(f"{entry['id']}.yaml"))
            elif "id" in entry:
                add(where + ("id",), f"no instrument {entry['id']!r} in the configuration or shipped with the kiosk")
                continue
            else:
                questionnaire = load_questionnaire(Path(path).parent / entry["file"])
        except QuestionnaireError as exc:
            add(where + ("id" if "id" in entry else "file",), f"the instrument is invalid: {exc}")
            continue
        if questionnaire.id in (q.id for q in found):
            add(where, f"{questionnaire.id!r} is answered twice in one visit")
            continue
        if index > 0 and isinstance(entry.get("familiarisation"), list):
            add(where + ("familiarisation",), "only the first instrument has practice questions", key=True)
            continue
        own = {k: v for k, v in entry.items() if k not in ("id", "file", "rest_after")}
        merged = {**shared, **own}
        try:
            script = _build(merged, _Within(positions, index, set(own)), name, questionnaire, [])
            script = replace(script, rest_after=float(entry.get("rest_after", 0)))
        except ScriptError as exc:
            problems.append(_parse_problem(str(exc), name))
            continue
        scripts.append(script)
        found.append(questionnaire)
    if problems:
        raise _script_error(problems)
    return BatteryScript(name, tuple(scripts), tuple(found))


def _parse_problem(message: str, name: str) -> Problem:
    """A ScriptError's first problem back as a Problem (its position leads the message)."""
    rest = message[len(name) + 1 :] if message.startswith(name + ":") else message
    line, _, rest = rest.partition(":")
    col, _, text = rest.partition(":")
    if line.isdigit() and col.isdigit():
        return Problem(name, int(line), int(col), text.strip())
    return Problem(name, 1, 1, message)


def load_script(path: str | Path, questionnaire: Questionnaire | None = None) -> Script:
    """Read and check a scripted patient; :class:`ScriptError` lists every problem with its position."""
    questionnaire = questionnaire or load_questionnaire()
    name = str(path)
    data, positions, problems = parse_file(path)
    if positions is None or not isinstance(data, dict):
        problems = problems or [Problem(name, 1, 1, "a script is a mapping (patient:, questions:, ...)")]
        raise _script_error(problems)
    if "instruments" in data:
        line, col = positions.of(("instruments",), key=True)
        raise _script_error(
            [Problem(name, line, col, "a battery script: replay it with `kiosk replay` (load_battery_script)")]
        )
    return _build(data, positions, name, questionnaire, problems)


def _build(
    data: dict[str, Any], positions: Any, name: str, questionnaire: Questionnaire, problems: list[Problem]
) -> Script:
    """The script ``data`` describes for ``questionnaire`` (positions for the messages)."""

    def where(p: tuple[Any, ...], key: bool = False) -> str:
        line, col = positions.of(p, key=key)
        return f"{name}:{line}:{col}"

    def add(p: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(p, key=key)
        problems.append(Problem(name, line, col, message))

    schema_problems(data, _schema(), positions, add)
    if "questions" not in data and not problems:
        add((), "the script is missing 'questions'")
    if problems:
        raise _script_error(problems)

    language = data.get("language", "en")
    if language not in questionnaire.languages:
        add(("language",), f"language {language!r} is not one of {', '.join(questionnaire.languages)}")
    try:
        questionnaire.timing.with_overrides(data.get("timing"))
    except ValueError as exc:
        add(("timing",), str(exc))
    # staff items (answered_by: staff) are never asked: a script answers the patient's items only
    asked = [item for item in questionnaire.items if not item.staff]
    if len(data["questions"]) != len(asked):
        add(
            ("questions",),
            f"the script has {len(data['questions'])} questions; the questionnaire has {len(asked)}",
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
    for i, (entry, item) in enumerate(zip(data["questions"], asked)):
        p = ("questions", i)
        if "item" in entry and entry["item"] != item.id:
            add(p + ("item",), f"question {i + 1} of the questionnaire is {item.id!r}, not {entry['item']!r}")
        attempt = {"none": None, "any": ANY}.get(entry["attempt"], entry["attempt"])
        steps = []
        for j, incident in enumerate(entry.get("incidents", [])):
            ip = p + ("incidents", j)
            if "channel" in incident and incident["do"] not in COMMANDS:
                add(ip + ("channel",), f"{incident['do']!r} is not given through a channel")
            if "source" in incident and incident["do"] not in ("person_lost", "person_back"):
                add(ip + ("source",), f"{incident['do']!r} has no presence source")
            anchor = incident.get("attempt", 1 if j == 0 else None)
            channel = Channel(incident.get("channel", "touch"))
            source = PresenceSource(incident.get("source", "camera"))
            steps.append(
                Step(incident["do"], anchor, float(incident.get("after", 0)), channel, where=where(ip), source=source)
            )
        go_on = None
        if attempt is None:
            for key in ("option", "say", "channel", "after", "unsure", "confirm", "undo", "then"):
                if key in entry:
                    add(p + (key,), f"{describe(p)} is not answered (attempt: none) but gives {key!r}", key=True)
        elif "go_on" in entry and attempt != ANY:
            add(p + ("go_on",), f"{describe(p)} is answered: the kiosk never waits after it", key=True)
        if "go_on" in entry:
            touch = entry["go_on"]
            channel = Channel(touch.get("channel", "touch"))
            go_on = Step("go_on", None, float(touch.get("after", 0)), channel, 1, where=where(p + ("go_on",)))
        if attempt is not None:
            step = answer_step(p, entry, item, "answer", attempt)
            if step:
                steps.append(step)
                steps += corrections(p, entry, item, attempt)
        questions.append(Question(item, attempt, tuple(steps), where(p), go_on))
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
        watching=Watching(
            _setting(data.get("away_alert_after_s", Watching().away_alert_after_s), float),
            _setting(data.get("unattended_after", Watching().unattended_after), int),
        ),
    )


def _setting(value: Any, kind: type) -> Any:
    """A watching setting as the session takes it: ``off`` is None."""
    return None if value is False or value in ("off", None) else kind(value)


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

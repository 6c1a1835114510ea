"""The questionnaire: YAML file -> validated, immutable dataclasses; scoring and interpretation.

Clinicians edit ``kiosk/questionnaires/barthel.yaml`` by hand, so loading is strict: every problem
(YAML syntax, unknown keys, missing translations, duplicate ids, points that are not multiples of 5,
bands with gaps...) is collected with its ``file:line:col`` position and reported together, and
nothing is half-loaded. The structural rules live in ``questionnaire.schema.json`` (which editors
can also use while typing); the rules a JSON Schema cannot express (translations for the declared
languages, unique ids, band coverage) are checked here.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema
import yaml

#: where the bundled questionnaire and its schema live
_PACKAGE_DIR = "kiosk.questionnaires"
DEFAULT_FILE = "barthel.yaml"
SCHEMA_FILE = "questionnaire.schema.json"


# --------------------------------------------------------------------------------------------
# Errors with positions


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a questionnaire file, at a 1-based line and column."""

    file: str
    line: int
    column: int
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.message}"


class QuestionnaireError(ValueError):
    """A questionnaire file is unusable; ``problems`` lists every reason with its position."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problems
        first = str(problems[0]) if problems else "invalid questionnaire"
        more = f" (and {len(problems) - 1} more problems)" if len(problems) > 1 else ""
        super().__init__(first + more)


# --------------------------------------------------------------------------------------------
# The model


@dataclass(frozen=True)
class Code:
    """A coding for export, e.g. a LOINC code."""

    system: str
    code: str


@dataclass(frozen=True)
class Option:
    """One answer option of a question. ``number`` is its 1-based position (button and remote)."""

    number: int
    label: Mapping[str, str]
    synonyms: Mapping[str, tuple[str, ...]]
    #: points scored (None for practice questions, which are not scored)
    points: int | None = None

    def label_in(self, language: str) -> str:
        """The option's label in ``language``."""
        return self.label[language]

    def synonyms_in(self, language: str) -> tuple[str, ...]:
        """Extra words a patient may say for this option in ``language`` (may be empty)."""
        return self.synonyms.get(language, ())


@dataclass(frozen=True)
class Item:
    """One scored Barthel item (feeding, bathing, ...)."""

    id: str
    #: 1-based position in the questionnaire
    number: int
    text: Mapping[str, str]
    spoken: Mapping[str, str]
    options: tuple[Option, ...]
    code: Code | None = None

    def option(self, number: int) -> Option:
        """The option with this 1-based number; ``KeyError`` if there is none."""
        if 1 <= number <= len(self.options):
            return self.options[number - 1]
        raise KeyError(f"item {self.id!r} has no option {number} (it has {len(self.options)})")

    @property
    def points(self) -> frozenset[int]:
        """The points this item's options can score."""
        return frozenset(o.points for o in self.options if o.points is not None)

    @property
    def max_points(self) -> int:
        """The most this item can score."""
        return max(self.points)


@dataclass(frozen=True)
class PracticeQuestion:
    """A familiarisation question checking the patient can hear, read or select. Not scored."""

    id: str
    #: what it checks: "hear", "read" or "select"
    checks: str
    text: Mapping[str, str]
    spoken: Mapping[str, str]
    options: tuple[Option, ...]
    #: the option number a patient who understood would choose
    expected: int

    def option(self, number: int) -> Option:
        """The option with this 1-based number; ``KeyError`` if there is none."""
        if 1 <= number <= len(self.options):
            return self.options[number - 1]
        raise KeyError(f"practice question {self.id!r} has no option {number}")


@dataclass(frozen=True)
class Band:
    """An interpretation band: totals from ``min`` to ``max`` inclusive."""

    id: str
    min: int
    max: int
    label: Mapping[str, str]


@dataclass(frozen=True)
class Timing:
    """How long the session waits, in seconds. Defaults come from the questionnaire file."""

    #: each of the two attempts of a question waits this long for an answer
    attempt_window_s: float = 20.0
    #: after an answer or an unanswered question, before the next question's attempt 1 opens
    between_questions_s: float = 2.0
    #: after pause/resume or call-doctor/continue, the attempt has at least this long left
    resume_grace_s: float = 10.0
    #: after the patient comes back, the attempt has at least this long left
    person_back_grace_s: float = 5.0
    #: after the last question, before FINISHED and the summary
    closing_s: float = 5.0

    def with_overrides(self, overrides: Mapping[str, Any] | None) -> Timing:
        """A copy with some values replaced; unknown names or negative values raise ValueError."""
        if not overrides:
            return self
        known = {f.name for f in fields(self)}
        changes: dict[str, float] = {}
        for name, value in overrides.items():
            if name not in known:
                raise ValueError(f"unknown timing setting {name!r} (known: {', '.join(sorted(known))})")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or value < 0:
                raise ValueError(f"timing setting {name!r} must be a number of seconds >= 0, got {value!r}")
            changes[name] = float(value)
        if changes.get("attempt_window_s", self.attempt_window_s) <= 0:
            raise ValueError("timing setting 'attempt_window_s' must be more than 0 seconds")
        return replace(self, **changes)


@dataclass(frozen=True)
class Score:
    """The result of scoring a set of item answers."""

    #: sum of the points of the answered items
    total: int
    #: every item answered
    complete: bool
    #: the band of ``total`` when complete, else None (an incomplete total is not interpreted)
    band: Band | None
    #: item ids answered, in questionnaire order
    answered: tuple[str, ...]
    #: item ids not answered, in questionnaire order
    missing: tuple[str, ...]
    #: the highest possible total
    max_total: int


@dataclass(frozen=True)
class Questionnaire:
    """A validated questionnaire. Build it with :func:`load_questionnaire`."""

    id: str
    version: str
    title: Mapping[str, str]
    languages: tuple[str, ...]
    items: tuple[Item, ...]
    bands: tuple[Band, ...]
    band_source: str
    messages: Mapping[str, Mapping[str, str]]
    familiarisation: tuple[PracticeQuestion, ...]
    timing: Timing
    code: Code | None = None
    total_code: Code | None = None
    #: where it was loaded from (for messages and records)
    source: str = field(default="", compare=False)

    def item(self, item_id: str) -> Item:
        """The item with this id; ``KeyError`` if unknown."""
        for item in self.items:
            if item.id == item_id:
                return item
        raise KeyError(f"unknown item {item_id!r}")

    def message(self, name: str, language: str) -> str:
        """A message (welcome, explanation, paused...) in ``language``; '' if the file has none."""
        return self.messages.get(name, {}).get(language, "")

    def band_for(self, total: int) -> Band | None:
        """The band containing ``total``."""
        for band in self.bands:
            if band.min <= total <= band.max:
                return band
        return None

    def score(self, points: Mapping[str, int]) -> Score:
        """Score answers given as item id -> points.

        Raises ValueError for an unknown item or points that are not one of that item's options.
        Missing items make the score incomplete (and leave it without a band); they never count
        as 0 silently.
        """
        known = {item.id: item for item in self.items}
        for item_id, value in points.items():
            if item_id not in known:
                raise ValueError(f"unknown item {item_id!r}")
            item = known[item_id]
            if isinstance(value, bool) or value not in item.points:
                allowed = ", ".join(str(p) for p in sorted(item.points))
                raise ValueError(f"{value!r} points is not an option of item {item_id!r} (options: {allowed})")
        answered = tuple(i.id for i in self.items if i.id in points)
        missing = tuple(i.id for i in self.items if i.id not in points)
        total = sum(int(points[i]) for i in answered)
        complete = not missing
        return Score(
            total=total,
            complete=complete,
            band=self.band_for(total) if complete else None,
            answered=answered,
            missing=missing,
            max_total=sum(i.max_points for i in self.items),
        )


# --------------------------------------------------------------------------------------------
# Loading


def bundled_path(name: str = DEFAULT_FILE) -> Path:
    """Path of a file shipped in ``kiosk/questionnaires``."""
    return Path(str(resources.files(_PACKAGE_DIR).joinpath(name)))


@cache
def _schema() -> dict[str, Any]:
    return json.loads(bundled_path(SCHEMA_FILE).read_text(encoding="utf-8"))


def load_questionnaire(path: str | Path | None = None) -> Questionnaire:
    """Load and validate a questionnaire (default: the bundled Barthel file).

    Raises :class:`QuestionnaireError` listing every problem, or ``OSError`` if unreadable.
    """
    file = Path(path) if path is not None else bundled_path()
    text = file.read_text(encoding="utf-8")
    data, problems = check_questionnaire_text(text, str(path if path is not None else file))
    if problems:
        raise QuestionnaireError(problems)
    return _build(data, str(file))


def check_questionnaire_file(path: str | Path) -> list[Problem]:
    """Every problem in a questionnaire file (empty if it is valid). Unreadable: one problem."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        return [Problem(str(path), 1, 1, f"cannot read the file: {reason}")]
    return check_questionnaire_text(text, str(path))[1]


class _Positions:
    """Maps a path inside the YAML document (keys and indexes) to where it was written."""

    def __init__(self, root: yaml.Node) -> None:
        self._marks: dict[tuple[Any, ...], tuple[int, int]] = {}
        self._key_marks: dict[tuple[Any, ...], tuple[int, int]] = {}
        self.duplicate_keys: list[tuple[tuple[Any, ...], str, tuple[int, int]]] = []
        self._walk(root, ())

    @staticmethod
    def _mark(node: yaml.Node) -> tuple[int, int]:
        return node.start_mark.line + 1, node.start_mark.column + 1

    def _walk(self, node: yaml.Node, path: tuple[Any, ...]) -> None:
        self._marks[path] = self._mark(node)
        if isinstance(node, yaml.MappingNode):
            seen: set[str] = set()
            for key_node, value_node in node.value:
                key = key_node.value
                if key in seen:
                    self.duplicate_keys.append((path, key, self._mark(key_node)))
                seen.add(key)
                self._key_marks[path + (key,)] = self._mark(key_node)
                self._walk(value_node, path + (key,))
        elif isinstance(node, yaml.SequenceNode):
            for index, child in enumerate(node.value):
                self._walk(child, path + (index,))

    def of(self, path: tuple[Any, ...], *, key: bool = False) -> tuple[int, int]:
        """Position of the value at ``path`` (or of its key), falling back to the nearest parent."""
        if key and path in self._key_marks:
            return self._key_marks[path]
        while path not in self._marks and path:
            path = path[:-1]
        return self._marks.get(path, (1, 1))


def _describe(path: tuple[Any, ...]) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if i else str(p)) for i, p in enumerate(path))


def check_questionnaire_text(text: str, filename: str) -> tuple[Any, list[Problem]]:
    """Parse and check questionnaire YAML; returns (data, problems). Data is None on a syntax error."""
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None, [Problem(filename, 1, 1, "the file is empty")]
        data = loader.construct_document(node)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        return None, [Problem(filename, line, col, f"YAML syntax: {exc.problem or exc.context}")]
    except yaml.YAMLError as exc:
        return None, [Problem(filename, 1, 1, f"YAML syntax: {exc}")]
    finally:
        loader.dispose()

    positions = _Positions(node)
    problems: list[Problem] = []

    def add(path: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(path, key=key)
        problems.append(Problem(filename, line, col, message))

    for path, key, (line, col) in positions.duplicate_keys:
        where = f" in {_describe(path)}" if path else ""
        problems.append(Problem(filename, line, col, f"duplicate key {key!r}{where}"))

    validator = jsonschema.Draft202012Validator(_schema())
    for error in validator.iter_errors(data):
        path = tuple(error.absolute_path)
        if error.validator == "additionalProperties":
            extra = sorted(set(error.instance) - set(error.schema.get("properties", {})))
            for name in extra:
                add(path + (name,), f"unknown key {name!r}" + (f" in {_describe(path)}" if path else ""), key=True)
            continue
        if error.validator == "required":
            missing = error.message.split("'")[1] if "'" in error.message else error.message
            add(path, f"{_describe(path) or 'the file'} is missing {missing!r}")
            continue
        if error.validator == "multipleOf":
            add(path, f"{_describe(path)}: points must be a multiple of 5, got {error.instance!r}")
            continue
        add(path, f"{_describe(path) or 'the file'}: {error.message}")

    if isinstance(data, dict) and not problems:
        _check_semantics(data, add)
    problems.sort(key=lambda p: (p.line, p.column, p.message))
    return data, problems


def _check_semantics(data: dict[str, Any], add: Callable[..., None]) -> None:
    """Rules a JSON Schema cannot say: translations, unique ids, distinct points, band coverage.

    Only run on a file that already matches the schema, so the structure can be trusted here.
    """
    languages: list[str] = data["languages"]
    if len(set(languages)) != len(languages):
        add(("languages",), "a language is listed twice in 'languages'")

    def texts(path: tuple[Any, ...], value: Mapping[str, Any]) -> None:
        for lang in languages:
            if lang not in value:
                add(path, f"{_describe(path)} has no {lang!r} translation")
        for lang in value:
            if lang not in languages:
                add(path + (lang,), f"{_describe(path)} has a {lang!r} text but {lang!r} is not in 'languages'", key=True)

    for key in ("title",):
        texts((key,), data[key])
    for name, value in data.get("messages", {}).items():
        texts(("messages", name), value)

    def options(path: tuple[Any, ...], opts: list[dict[str, Any]], scored: bool) -> None:
        for i, option in enumerate(opts):
            texts(path + (i, "label"), option["label"])
            for lang in option.get("synonyms", {}):
                if lang not in languages:
                    add(path + (i, "synonyms", lang), f"synonyms in {lang!r}, which is not in 'languages'", key=True)
            if scored and "points" not in option:
                add(path + (i,), f"{_describe(path + (i,))} has no points")
        if scored:
            seen: set[int] = set()
            for i, option in enumerate(opts):
                if option.get("points") in seen:
                    add(path + (i, "points"), f"two options of {_describe(path[:-1])} score {option['points']} points")
                seen.add(option.get("points"))

    ids: dict[str, tuple[Any, ...]] = {}
    for section in ("items", "familiarisation"):
        for i, entry in enumerate(data.get(section, [])):
            path = (section, i)
            if entry["id"] in ids:
                add(path + ("id",), f"duplicate id {entry['id']!r} (also used at {_describe(ids[entry['id']])})")
            else:
                ids[entry["id"]] = path
            texts(path + ("text",), entry["text"])
            texts(path + ("spoken",), entry["spoken"])
            options(path + ("options",), entry["options"], scored=section == "items")
            if section == "familiarisation" and entry["expected"] > len(entry["options"]):
                add(path + ("expected",), f"expected option {entry['expected']} but there are only {len(entry['options'])} options")

    bands = data["bands"]["ranges"]
    band_ids: set[str] = set()
    for i, band in enumerate(bands):
        texts(("bands", "ranges", i, "label"), band["label"])
        if band["id"] in band_ids:
            add(("bands", "ranges", i, "id"), f"duplicate band id {band['id']!r}")
        band_ids.add(band["id"])
        if band["min"] > band["max"]:
            add(("bands", "ranges", i), f"band {band['id']!r} has min {band['min']} above max {band['max']}")
    top = sum(max((o.get("points", 0) for o in item["options"]), default=0) for item in data["items"])
    expected_low = 0
    for i, band in sorted(enumerate(bands), key=lambda ib: ib[1]["min"]):
        if band["min"] != expected_low:
            kind = "a gap" if band["min"] > expected_low else "an overlap"
            add(("bands", "ranges", i, "min"), f"bands leave {kind} before {band['min']} (expected the next band to start at {expected_low})")
        expected_low = band["max"] + 1
    if bands and expected_low != top + 1:
        add(("bands", "ranges"), f"bands end at {expected_low - 1} but the highest possible total is {top}")


def _build(data: dict[str, Any], source: str) -> Questionnaire:
    def code(value: Mapping[str, str] | None) -> Code | None:
        return Code(value["system"], value["code"]) if value else None

    def opts(values: list[dict[str, Any]]) -> tuple[Option, ...]:
        return tuple(
            Option(
                number=i,
                label=dict(v["label"]),
                synonyms={lang: tuple(words) for lang, words in v.get("synonyms", {}).items()},
                points=v.get("points"),
            )
            for i, v in enumerate(values, start=1)
        )

    items = tuple(
        Item(id=v["id"], number=n, text=dict(v["text"]), spoken=dict(v["spoken"]),
             options=opts(v["options"]), code=code(v.get("code")))
        for n, v in enumerate(data["items"], start=1)
    )
    practice = tuple(
        PracticeQuestion(id=v["id"], checks=v["checks"], text=dict(v["text"]), spoken=dict(v["spoken"]),
                         options=opts(v["options"]), expected=v["expected"])
        for v in data.get("familiarisation", [])
    )
    bands = tuple(Band(id=b["id"], min=b["min"], max=b["max"], label=dict(b["label"]))
                  for b in sorted(data["bands"]["ranges"], key=lambda b: b["min"]))
    return Questionnaire(
        id=data["id"],
        version=str(data.get("version", "")),
        title=dict(data["title"]),
        languages=tuple(data["languages"]),
        items=items,
        bands=bands,
        band_source=data["bands"].get("source", ""),
        messages={k: dict(v) for k, v in data.get("messages", {}).items()},
        familiarisation=practice,
        timing=Timing().with_overrides(data.get("timing")),
        code=code(data.get("code")),
        total_code=code(data.get("total_code")),
        source=source,
    )


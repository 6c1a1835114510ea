"""The questionnaire: YAML file -> validated, immutable dataclasses; scoring and interpretation.

Clinicians edit ``kiosk/core/questionnaire/instruments/barthel.yaml`` by hand, so loading is strict: every problem
(YAML syntax, unknown keys, missing translations, duplicate ids, points that are not multiples of 5,
bands with gaps...) is collected with its ``file:line:col`` position and reported together, and
nothing is half-loaded. The structural rules live in ``questionnaire.schema.json`` (which editors
can also use while typing); the rules a JSON Schema cannot express (translations for the declared
languages, unique ids, band coverage) are checked here.

Interpretation bands come as named band sets (Shah 1989, a Spanish clinical-practice set...), one
of them the file's default. A kiosk may choose another (``bands:`` in its config,
:meth:`Questionnaire.with_band_set`); scoring then uses that set everywhere.
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from fileio.positions import Positions, Problem, describe, parse, parse_file, schema_problems
from kiosk.core.words import languages

#: where the bundled questionnaire and its schema live
_PACKAGE_DIR = "kiosk.core.questionnaire.instruments"
DEFAULT_FILE = "barthel.yaml"
SCHEMA_FILE = "questionnaire.schema.json"
#: the languages the kiosk's own screens are written in (a words file each, kiosk/core/words): a
#: questionnaire in another language would start a session its screens cannot show
SCREEN_LANGUAGES = languages()
#: the longest a timing setting may be: a day (a longer wait is a typo, and no session lasts it)
MAX_TIMING_S = 86400.0


# --------------------------------------------------------------------------------------------
# Errors with positions


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
    #: the code system's own display for the code (LOINC's), exported as ``Coding.display``
    display: str = ""


@dataclass(frozen=True)
class Option:
    """One answer option of a question. ``number`` is its 1-based position (button and remote)."""

    number: int
    label: Mapping[str, str]
    synonyms: Mapping[str, tuple[str, ...]]
    #: points scored (None for practice questions, which are not scored)
    points: int | None = None
    #: the patient's wording, when it differs from the clinical ``label`` (empty: the label)
    patient: Mapping[str, str] = field(default_factory=dict)
    #: a published answer code (LOINC LA...) for export; None: exports use a local code
    code: Code | None = None

    def label_in(self, language: str) -> str:
        """The option's clinical label in ``language`` (clinicians' screens, exports)."""
        return self.label[language]

    def patient_label_in(self, language: str) -> str:
        """The option as the patient's screen shows it in ``language``."""
        return self.patient.get(language) or self.label[language]

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
    #: the question as the patient's screen shows it, when it differs from ``text`` (clinical)
    patient: Mapping[str, str] = field(default_factory=dict)

    def option(self, number: int) -> Option:
        """The option with this 1-based number; ``KeyError`` if there is none."""
        if 1 <= number <= len(self.options):
            return self.options[number - 1]
        raise KeyError(f"item {self.id!r} has no option {number} (it has {len(self.options)})")

    def patient_text_in(self, language: str) -> str:
        """The question as the patient's screen shows it in ``language``."""
        return self.patient.get(language) or self.text[language]

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

    def patient_text_in(self, language: str) -> str:
        """The question as the screen shows it (practice questions have one wording)."""
        return self.text[language]

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
class BandSet:
    """A named set of interpretation bands covering every possible total, with its source."""

    id: str
    #: where the cut-offs come from (a citation, or a warning that the source is unconfirmed)
    source: str
    #: in ascending order of totals
    bands: tuple[Band, ...]

    def band_for(self, total: int) -> Band | None:
        """The band containing ``total`` (None outside every band)."""
        for band in self.bands:
            if band.min <= total <= band.max:
                return band
        return None


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
    #: how long "I heard: ... Is that right?" waits for Yes or No; no reply stores nothing and
    #: ends the attempt as if it had timed out
    confirm_window_s: float = 10.0

    def with_overrides(self, overrides: Mapping[str, Any] | None) -> Timing:
        """A copy with some values replaced; unknown names or negative values raise ValueError."""
        if not overrides:
            return self
        known = {f.name for f in fields(self)}
        changes: dict[str, float] = {}
        for name, value in overrides.items():
            if name not in known:
                raise ValueError(f"unknown timing setting {name!r} (known: {', '.join(sorted(known))})")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= MAX_TIMING_S:
                raise ValueError(
                    f"timing setting {name!r} must be a number of seconds from 0 to "
                    f"{MAX_TIMING_S:g} (a day), got {value!r}"
                )
            changes[name] = float(value)
        for name in ("attempt_window_s", "confirm_window_s"):
            if changes.get(name, getattr(self, name)) <= 0:
                raise ValueError(f"timing setting {name!r} must be more than 0 seconds")
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
    #: the id of the band set ``band`` comes from
    band_set: str = ""


@dataclass(frozen=True)
class Questionnaire:
    """A validated questionnaire. Build it with :func:`load_questionnaire`."""

    id: str
    version: str
    title: Mapping[str, str]
    languages: tuple[str, ...]
    items: tuple[Item, ...]
    #: every band set of the file, by id
    band_sets: Mapping[str, BandSet]
    #: the band set scoring uses: the file's default unless :meth:`with_band_set` chose another
    band_set: str
    messages: Mapping[str, Mapping[str, str]]
    familiarisation: tuple[PracticeQuestion, ...]
    timing: Timing
    code: Code | None = None
    total_code: Code | None = None
    #: where it was loaded from (for messages and records)
    source: str = field(default="", compare=False)
    #: SHA-256 of the file's content (as parsed: comments and layout do not count), so exports
    #: can tell two edits of the same questionnaire apart
    digest: str = ""

    def item(self, item_id: str) -> Item:
        """The item with this id; ``KeyError`` if unknown."""
        for item in self.items:
            if item.id == item_id:
                return item
        raise KeyError(f"unknown item {item_id!r}")

    def message(self, name: str, language: str) -> str:
        """A message (welcome, explanation, paused...) in ``language``; '' if the file has none."""
        return self.messages.get(name, {}).get(language, "")

    @property
    def bands(self) -> tuple[Band, ...]:
        """The bands scoring uses (those of :attr:`band_set`)."""
        return self.band_sets[self.band_set].bands

    @property
    def band_source(self) -> str:
        """Where the bands scoring uses come from."""
        return self.band_sets[self.band_set].source

    def bands_named(self, band_set: str | None = None) -> BandSet:
        """The band set with this id (None: the one scoring uses); ``KeyError`` naming the sets."""
        name = self.band_set if band_set is None else band_set
        if name not in self.band_sets:
            raise KeyError(f"no band set {name!r} in {self.id} (it has {', '.join(self.band_sets)})")
        return self.band_sets[name]

    def with_band_set(self, band_set: str) -> Questionnaire:
        """A copy that scores with another of its band sets; ``KeyError`` if there is none of that id."""
        return replace(self, band_set=self.bands_named(band_set).id)

    def band_for(self, total: int, band_set: str | None = None) -> Band | None:
        """The band containing ``total`` in ``band_set`` (None: the set scoring uses)."""
        return self.bands_named(band_set).band_for(total)

    def score(self, points: Mapping[str, int], band_set: str | None = None) -> Score:
        """Score answers given as item id -> points, interpreted with ``band_set`` (None: the set
        scoring uses, normally the file's default).

        Raises ValueError for an unknown item or points that are not one of that item's options,
        KeyError for an unknown band set. Missing items make the score incomplete (and leave it
        without a band); they never count as 0 silently.
        """
        bands = self.bands_named(band_set)
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
            band=bands.band_for(total) if complete else None,
            answered=answered,
            missing=missing,
            max_total=sum(i.max_points for i in self.items),
            band_set=bands.id,
        )


# --------------------------------------------------------------------------------------------
# Loading


def bundled_path(name: str = DEFAULT_FILE) -> Path:
    """Path of a file shipped in ``kiosk/core/questionnaire/instruments``."""
    return Path(str(resources.files(_PACKAGE_DIR).joinpath(name)))


@cache
def _schema() -> dict[str, Any]:
    return json.loads(bundled_path(SCHEMA_FILE).read_text(encoding="utf-8"))


def load_questionnaire(path: str | Path | None = None) -> Questionnaire:
    """Load and validate a questionnaire (default: the bundled Barthel file).

    Raises :class:`QuestionnaireError` listing every problem (an unreadable file is one problem).
    """
    file = Path(path) if path is not None else bundled_path()
    name = str(path if path is not None else file)
    data, problems = _check(parse_file(file, name), name)
    if problems:
        raise QuestionnaireError(problems)
    return _build(data, str(file))


def check_questionnaire_file(path: str | Path) -> list[Problem]:
    """Every problem in a questionnaire file (empty if it is valid): the checks :func:`load_questionnaire`
    makes, so a file this accepts is one the kiosk runs. Unreadable: one problem."""
    return check_questionnaire(path)[1]


def check_questionnaire(path: str | Path) -> tuple[bool, list[Problem]]:
    """(readable, every problem) of a questionnaire file; ``readable`` is False when the file could
    not be read as YAML at all (then its one problem says why)."""
    parsed = parse_file(path)
    return parsed[1] is not None, _check(parsed, str(path))[1]


def check_questionnaire_text(text: str, filename: str) -> tuple[Any, list[Problem]]:
    """Parse and check questionnaire YAML; returns (data, problems). Data is None on a syntax error."""
    return _check(parse(text, filename), filename)


def _check(parsed: tuple[Any, Positions | None, list[Problem]], filename: str) -> tuple[Any, list[Problem]]:
    data, positions, problems = parsed
    if positions is None:
        return None, problems

    def add(path: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(path, key=key)
        problems.append(Problem(filename, line, col, message))

    schema_problems(data, _schema(), positions, add)
    if isinstance(data, dict):
        _check_semantics(data, add)
    problems.sort(key=lambda p: (p.line, p.column, p.message))
    return data, problems


def _check_semantics(data: dict[str, Any], add: Callable[..., None]) -> None:
    """Rules a JSON Schema cannot say: translations, unique ids, distinct points, band coverage.

    Runs even when the schema found problems, so every error is reported in one go; parts with
    the wrong shape (already reported by the schema) are skipped.
    """

    def dicts(value: Any) -> list[tuple[int, dict[str, Any]]]:
        return [(i, v) for i, v in enumerate(value) if isinstance(v, dict)] if isinstance(value, list) else []

    languages = (
        [x for x in data.get("languages", []) if isinstance(x, str)] if isinstance(data.get("languages"), list) else []
    )
    if len(set(languages)) != len(languages):
        add(("languages",), "a language is listed twice in 'languages'")
    for i, lang in enumerate(languages):
        if lang not in SCREEN_LANGUAGES:
            add(
                ("languages", i),
                f"language {lang!r}: the kiosk's screens have text in {', '.join(SCREEN_LANGUAGES)} only",
            )

    def texts(path: tuple[Any, ...], value: Any) -> None:
        if not isinstance(value, dict):
            return
        for lang in languages:
            if lang not in value:
                add(path, f"{describe(path)} has no {lang!r} translation")
        for lang, text in value.items():
            if languages and lang not in languages:
                add(
                    path + (lang,), f"{describe(path)} has a {lang!r} text but {lang!r} is not in 'languages'", key=True
                )
            if isinstance(text, str) and text and not text.strip():  # "" is the schema's to report
                add(path + (lang,), f"{describe(path)} in {lang!r} is blank: write the words")

    texts(("title",), data.get("title"))
    messages = data.get("messages")
    for name, value in messages.items() if isinstance(messages, dict) else ():
        texts(("messages", name), value)

    def options(path: tuple[Any, ...], value: Any, scored: bool) -> None:
        seen: set[Any] = set()
        codes: set[tuple[Any, Any]] = set()
        for i, option in dicts(value):
            texts(path + (i, "label"), option.get("label"))
            texts(path + (i, "patient"), option.get("patient"))
            synonyms = option.get("synonyms")
            for lang, words in synonyms.items() if isinstance(synonyms, dict) else ():
                if languages and lang not in languages:
                    add(path + (i, "synonyms", lang), f"synonyms in {lang!r}, which is not in 'languages'", key=True)
                for n, word in enumerate(words if isinstance(words, list) else ()):
                    if isinstance(word, str) and word and not word.strip():
                        add(path + (i, "synonyms", lang, n), f"a synonym in {lang!r} is blank: write the words")
            answer_code = option.get("code")
            if isinstance(answer_code, dict):
                key = (answer_code.get("system"), answer_code.get("code"))
                if key in codes:
                    add(path + (i, "code"), f"two options of {describe(path[:-1])} have the answer code {key[1]!r}")
                codes.add(key)
            points = option.get("points")
            if scored and isinstance(points, int):
                if points in seen:
                    add(path + (i, "points"), f"two options of {describe(path[:-1])} score {points} points")
                seen.add(points)

    _check_displays(data, dicts, add)
    ids: dict[str, tuple[Any, ...]] = {}
    for section in ("items", "familiarisation"):
        for i, entry in dicts(data.get(section)):
            path = (section, i)
            entry_id = entry.get("id")
            if isinstance(entry_id, str) and entry_id in ids:
                add(path + ("id",), f"duplicate id {entry_id!r} (also used at {describe(ids[entry_id])})")
            elif isinstance(entry_id, str):
                ids[entry_id] = path
            texts(path + ("text",), entry.get("text"))
            texts(path + ("patient",), entry.get("patient"))
            texts(path + ("spoken",), entry.get("spoken"))
            spoken = entry.get("spoken")
            for lang, said in spoken.items() if isinstance(spoken, dict) else ():
                for mark in re.findall(r"\{[^}]*\}", said) if isinstance(said, str) else ():
                    if mark != "{ways}":
                        add(
                            path + ("spoken", lang),
                            f"{mark} would be said aloud: the only mark a spoken "
                            "text may hold is {ways} (how to answer)",
                        )
            options(path + ("options",), entry.get("options"), scored=section == "items")
            expected, opts = entry.get("expected"), entry.get("options")
            if (
                section == "familiarisation"
                and isinstance(expected, int)
                and isinstance(opts, list)
                and expected > len(opts)
            ):
                add(path + ("expected",), f"expected option {expected} but there are only {len(opts)} options")

    _check_bands(data, dicts, texts, add)


def _check_displays(
    data: dict[str, Any], dicts: Callable[[Any], list[tuple[int, dict[str, Any]]]], add: Callable[..., None]
) -> None:
    """One code, one display: a code system gives a code one display, so two places of the
    file giving one code two displays is a mistake (an export would say both)."""
    first: dict[tuple[Any, Any], tuple[str, tuple[Any, ...]]] = {}
    places: list[tuple[tuple[Any, ...], Any]] = [
        (("code",), data.get("code")),
        (("total_code",), data.get("total_code")),
    ]
    for i, item in dicts(data.get("items")):
        places.append((("items", i, "code"), item.get("code")))
        places += [(("items", i, "options", j, "code"), option.get("code")) for j, option in dicts(item.get("options"))]
    for path, code in places:
        if not isinstance(code, dict) or not isinstance(code.get("display"), str):
            continue
        key = (code.get("system"), code.get("code"))
        if key in first and first[key][0] != code["display"]:
            add(
                path + ("display",),
                f"code {key[1]!r} has the display {code['display']!r} here but "
                f"{first[key][0]!r} at {describe(first[key][1])}: one code, one display",
            )
        first.setdefault(key, (code["display"], path))


def _reachable_totals(items: list[tuple[int, dict[str, Any]]]) -> set[int] | None:
    """Every total a patient can score (one option's points per item), or None when some points
    are not whole multiples of 5: the schema reports those, and bands judged against totals that
    the corrected file cannot reach would only bury that one mistake under others."""
    totals = {0}
    for _, item in items:
        options = item.get("options")
        points = {o.get("points") for o in options if isinstance(o, dict)} if isinstance(options, list) else set()
        if not all(isinstance(p, int) and not isinstance(p, bool) and p >= 0 and p % 5 == 0 for p in points):
            return None
        if points:
            totals = {t + p for t in totals for p in points}
    return totals


def _check_bands(
    data: dict[str, Any],
    dicts: Callable[[Any], list[tuple[int, dict[str, Any]]]],
    texts: Callable[[tuple[Any, ...], Any], None],
    add: Callable[..., None],
) -> None:
    """Each band set: labels translated, unique band ids, no two bands sharing a total, every total
    a patient can reach in a band, and the last band ending at the highest possible total; the
    default names one of the sets.

    Gaps are judged on reachable totals: with points in steps of 5, "20-35, 40-55" (as published)
    leaves no total out, so it is not a gap."""
    block = data.get("bands")
    if not isinstance(block, dict):
        return
    sets = block.get("sets") if isinstance(block.get("sets"), dict) else {}
    default = block.get("default")
    if isinstance(default, str) and sets and default not in sets:
        add(("bands", "default"), f"the default band set {default!r} is not one of the sets ({', '.join(sets)})")
    items = dicts(data.get("items"))
    # no items: the schema says so, and every band would only repeat it as "ends above 0"
    reachable = _reachable_totals(items) if items else None
    for name, band_set in sets.items():
        path = ("bands", "sets", name, "ranges")
        bands = dicts(band_set.get("ranges")) if isinstance(band_set, dict) else []
        band_ids: set[Any] = set()
        for i, band in bands:
            texts(path + (i, "label"), band.get("label"))
            if band.get("id") in band_ids:
                add(path + (i, "id"), f"band set {name!r}: duplicate band id {band['id']!r}")
            band_ids.add(band.get("id"))
        if (
            reachable is None
            or not bands
            or not all(isinstance(b.get("min"), int) and isinstance(b.get("max"), int) for _, b in bands)
        ):
            continue
        for i, band in bands:
            if band["min"] > band["max"]:
                add(
                    path + (i,),
                    f"band set {name!r}: band {band.get('id')!r} has min {band['min']} above max {band['max']}",
                )
        ordered = sorted(bands, key=lambda ib: (ib[1]["min"], ib[1]["max"]))
        below = -1  # the highest total covered so far
        previous: dict[str, Any] | None = None
        for i, band in ordered:
            if previous is not None and band["min"] <= below:
                add(
                    path + (i, "min"),
                    f"band set {name!r}: bands {previous.get('id')!r} and {band.get('id')!r} "
                    f"overlap ({band['min']} to {min(below, band['max'])} are in both)",
                )
            elif missed := sorted(t for t in reachable if below < t < band["min"]):
                add(
                    path + (i, "min"),
                    f"band set {name!r}: bands leave a gap before {band['min']} (a total of {missed[0]} is in no band)",
                )
            if band["max"] > below:
                below, previous = band["max"], band
        if below != max(reachable):
            add(path, f"band set {name!r}: bands end at {below} but the highest possible total is {max(reachable)}")


def _build(data: dict[str, Any], source: str) -> Questionnaire:
    def code(value: Mapping[str, str] | None) -> Code | None:
        return Code(value["system"], value["code"], value.get("display", "")) if value else None

    def opts(values: list[dict[str, Any]]) -> tuple[Option, ...]:
        return tuple(
            Option(
                number=i,
                label=dict(v["label"]),
                synonyms={lang: tuple(words) for lang, words in v.get("synonyms", {}).items()},
                points=v.get("points"),
                patient=dict(v.get("patient", {})),
                code=code(v.get("code")),
            )
            for i, v in enumerate(values, start=1)
        )

    items = tuple(
        Item(
            id=v["id"],
            number=n,
            text=dict(v["text"]),
            spoken=dict(v["spoken"]),
            options=opts(v["options"]),
            code=code(v.get("code")),
            patient=dict(v.get("patient", {})),
        )
        for n, v in enumerate(data["items"], start=1)
    )
    practice = tuple(
        PracticeQuestion(
            id=v["id"],
            checks=v["checks"],
            text=dict(v["text"]),
            spoken=dict(v["spoken"]),
            options=opts(v["options"]),
            expected=v["expected"],
        )
        for v in data.get("familiarisation", [])
    )
    band_sets = {
        name: BandSet(
            id=name,
            source=v.get("source", ""),
            bands=tuple(
                Band(id=b["id"], min=b["min"], max=b["max"], label=dict(b["label"]))
                for b in sorted(v["ranges"], key=lambda b: b["min"])
            ),
        )
        for name, v in data["bands"]["sets"].items()
    }
    return Questionnaire(
        id=data["id"],
        version=str(data.get("version", "")),
        title=dict(data["title"]),
        languages=tuple(data["languages"]),
        items=items,
        band_sets=band_sets,
        band_set=data["bands"]["default"],
        messages={k: dict(v) for k, v in data.get("messages", {}).items()},
        familiarisation=practice,
        timing=Timing().with_overrides(data.get("timing")),
        code=code(data.get("code")),
        total_code=code(data.get("total_code")),
        source=source,
        digest=hashlib.sha256(json.dumps(data, sort_keys=True, ensure_ascii=False).encode()).hexdigest(),
    )

"""The kiosk's own words, one file per language: ``kiosk/core/words/<code>.yaml``.

A file names its language (code, own name, espeak-ng voice) and holds the words of the kiosk's
screens, of the prompts the session builds itself, of what the voice channel understands, and the
exports' own labels. The questionnaire's texts are not here: they are the instrument's translation,
in its YAML. The kiosk's languages are the files present, so adding a language is adding a file.

``en.yaml`` is the template: every file has exactly its keys (those outside the screen texts are
fixed by :data:`SHAPE`), each screen text with the same ``{placeholders}``. A file that differs is
refused with every difference as one ``file:line:col`` problem, and nothing is half-loaded: one bad
file and :func:`load_words` loads none. Pure (``fileio`` only), so every layer reads its words here.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import field
from functools import cache
from pathlib import Path
from types import MappingProxyType
from typing import Any, TypeVar

from basis import record
from basis.errors import KioskError
from fileio.positions import Positions, Problem, describe, parse_file
from kiosk.core.words.placeholders import fill as fill  # the one way words are filled in
from kiosk.core.words.placeholders import placeholders

#: where the kiosk's words files are
WORDS_DIR = Path(__file__).resolve().parent
#: the language whose file every other is checked against, and that screens fall back to
TEMPLATE = "en"
#: a words file is named by its language's code, as BCP 47 writes it (en, es, pt-BR)
LANGUAGE_CODE = re.compile(r"[a-z]{2,3}(-[A-Za-z0-9]{2,8})*")

#: the spoken commands (``kiosk.core.channels.Command``'s values), in the order grammars list them
COMMANDS = ("repeat", "pause", "resume", "call_doctor", "volume_up", "volume_down", "undo")

# The kinds of value a words file holds (see SHAPE)
TEXT = "text"  # a non-empty string
WORDS = "words"  # a non-empty list of non-empty strings
WORDS_OR_NONE = "words_or_none"  # a list of non-empty strings, possibly empty
NUMBERS = "numbers"  # a list of WORDS, one per number from one up, as long as en.yaml's
NUMBER_FORMS = "number_forms"  # WORDS each with one placeholder, {n} (a cardinal) or {o} (an ordinal)
BY_LANGUAGE = "by_language"  # a mapping of language codes (with a words file) to WORDS
SCREEN = "screen"  # a mapping with en.yaml's screen keys, each a SCREEN_TEXT
SCREEN_TEXT = "screen_text"  # a TEXT with the placeholders of en.yaml's text of the same key

#: what every words file holds, section by section (the screen texts' keys are en.yaml's own)
SHAPE: Mapping[str, Any] = {
    "language": {"code": TEXT, "name": TEXT, "voice": TEXT},
    "screen": SCREEN,
    "prompts": {
        "yes_label": TEXT,
        "yes_words": WORDS,
        "no_label": TEXT,
        "no_words": WORDS,
        "start_words": WORDS,
        "language_names": BY_LANGUAGE,
    },
    "speech": {
        "cardinals": NUMBERS,
        "ordinals": NUMBERS,
        "number_forms": NUMBER_FORMS,
        "number_fillers": WORDS_OR_NONE,
        "after_number": WORDS_OR_NONE,
        "commands": dict.fromkeys(COMMANDS, WORDS),
        "yes_words": WORDS,
        "no_words": WORDS,
        "names": WORDS,
        "start_words": WORDS,
        "lead_ins": WORDS_OR_NONE,
        "fillers": WORDS_OR_NONE,
        "negations": WORDS,
        "help_words": WORDS,
    },
    "export": {"total_score": TEXT},
    "answers": {
        "yes_label": TEXT,
        "yes_patient": TEXT,
        "yes_words": WORDS,
        "no_label": TEXT,
        "no_patient": TEXT,
        "no_words": WORDS,
    },
}

_KIND_WORDS = {
    TEXT: "text",
    SCREEN_TEXT: "text",
    WORDS: "a list of words, at least one",
    WORDS_OR_NONE: "a list of words (or [])",
    NUMBER_FORMS: "a list of words, at least one",
    NUMBERS: "a list with a list of words for each number",
    BY_LANGUAGE: "a mapping of language codes to lists of words",
}


@record
class Words:
    """One language's words, as its file holds them (lists as tuples, sections as read-only maps).

    ``prompts`` and ``speech`` are keyed as in :data:`SHAPE`; ``screen`` as en.yaml's screen texts.
    """

    code: str
    name: str
    voice: str
    screen: Mapping[str, str]
    prompts: Mapping[str, Any]
    speech: Mapping[str, Any]
    export: Mapping[str, str]
    #: the options of an instrument's yes/no items (``answers: yes_no``): label, patient's wording, synonyms
    answers: Mapping[str, Any] = field(default_factory=dict)


class WordsError(KioskError, ValueError):
    """The words files cannot be used; ``problems`` lists every reason with its position."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problems
        more = f" (and {len(problems) - 1} more problems)" if len(problems) > 1 else ""
        super().__init__(str(problems[0]) + more)


def language_files(directory: str | Path | None = None) -> dict[str, Path]:
    """Language code → words file, for every ``<code>.yaml`` in ``directory`` (default: the
    kiosk's own), by code."""
    files = sorted(Path(WORDS_DIR if directory is None else directory).glob("*.yaml"))
    return {path.stem: path for path in files if LANGUAGE_CODE.fullmatch(path.stem)}


#: a site's folder of words files in use (:func:`use_site_words`): its languages join the kiosk's
_site: list[Path] = []


@cache
def languages() -> tuple[str, ...]:
    """The kiosk's languages: the codes of its words files and of the site's in use (a listing;
    the files are read on first use)."""
    return tuple(language_files()) + tuple(language_files(_site[0]) if _site else ())


class _Languages(Sequence[str]):
    """:func:`languages` at each use, so a site's words that join after import are counted."""

    def __getitem__(self, index: Any) -> Any:
        return languages()[index]

    def __len__(self) -> int:
        return len(languages())

    def __repr__(self) -> str:
        return repr(languages())


#: the kiosk's languages, read at each use (see :func:`use_site_words`)
LANGUAGES: Sequence[str] = _Languages()


def use_site_words(directory: Path | None) -> None:
    """Make a site's words files (checked by :func:`check_site_words`) the kiosk's languages beside
    its own, or none with None; every table is read again on its next use."""
    if _site == ([directory] if directory else []):
        return
    _site[:] = [directory] if directory else []
    languages.cache_clear()
    _kiosk_words.cache_clear()
    Table.generation += 1


def check_site_words(directory: Path) -> tuple[dict[str, Path], list[Problem], bool]:
    """(code -> file, every problem, whether every file could be read as YAML) of a site's words
    files: new languages only, each checked against the kiosk's ``en.yaml`` as its own files are."""
    shipped = language_files()
    problems: list[Problem] = []
    for path in sorted(set(directory.glob("*.yaml")) - set(language_files(directory).values())):
        problems.append(
            Problem(str(path), 1, 1, f"{path.name!r} is not named by a language code (en.yaml, pt-BR.yaml)")
        )
    mine = {code: path for code, path in language_files(directory).items()}
    for code in sorted(mine.keys() & shipped.keys()):
        problems.append(
            Problem(str(mine.pop(code)), 1, 1, f"the kiosk ships {code}.yaml: a site's words files add new languages")
        )
    template, positions, found = parse_file(shipped[TEMPLATE])
    readable = not found
    good: dict[str, Path] = {}
    for code, path in mine.items():
        data, positions, found = parse_file(path)
        problems += found
        readable = readable and not found
        if positions is None:
            continue
        checked = _Check(str(path), positions, template, set(shipped) | set(mine)).problems(data, code)
        problems += checked
        if not found and not checked:
            good[code] = path
    return good, problems, readable


def check_words(directory: str | Path | None = None) -> tuple[dict[str, Words], list[Problem], bool]:
    """Read every words file of ``directory`` (default: the kiosk's own): (words by language,
    problems, whether every file could be parsed as YAML). The words are those of the files
    without a problem."""
    data, problems, readable = _check_files(Path(WORDS_DIR if directory is None else directory))
    return {code: _words(code, one) for code, one in data.items()}, problems, readable


def _check_files(directory: Path) -> tuple[dict[str, Any], list[Problem], bool]:
    """:func:`check_words` with each good file's data as parsed (plain dicts and lists, picklable)."""
    problems: list[Problem] = []
    paths = language_files(directory)
    for path in sorted(set(directory.glob("*.yaml")) - set(paths.values())):
        problems.append(
            Problem(str(path), 1, 1, f"{path.name!r} is not named by a language code (en.yaml, pt-BR.yaml)")
        )
    if TEMPLATE not in paths:
        where = str(directory / f"{TEMPLATE}.yaml")
        return {}, [*problems, Problem(where, 1, 1, "missing: every language's words file is checked against it")], True
    parsed: dict[str, tuple[Any, Positions]] = {}
    readable = True
    for code, path in paths.items():
        data, positions, found = parse_file(path)
        problems += found
        readable = readable and not found
        if positions is not None:
            parsed[code] = (data, positions)
    if TEMPLATE not in parsed:
        return {}, problems, readable
    template = parsed[TEMPLATE][0]
    good = {}
    checked = {}
    for code, (data, positions) in parsed.items():
        checked[code] = _Check(str(paths[code]), positions, template, set(paths)).problems(data, code)
    _blame_the_template(checked, parsed[TEMPLATE][1], str(paths[TEMPLATE]))
    for code, found in checked.items():
        problems += found
        if not found:
            good[code] = parsed[code][0]
    return good, problems, readable


def _blame_the_template(checked: dict[str, list[Problem]], positions: Positions, template: str) -> None:
    """A screen key every other language has but en.yaml lacks was deleted from en.yaml: one
    problem there, not an "unknown key" in each of the others."""
    others = [code for code in checked if code != TEMPLATE]
    unknown = re.compile(r"unknown key '(screen\.[^']+)' \(en\.yaml has no such key\)")
    keys = [{m.group(1) for p in checked[code] if (m := unknown.fullmatch(p.message))} for code in others]
    for key in sorted(set.intersection(*keys) if len(others) > 1 else set()):
        for code in others:
            checked[code] = [p for p in checked[code] if p.message != f"unknown key {key!r} (en.yaml has no such key)"]
        line, column = positions.of(("screen",), key=True)
        checked[TEMPLATE].append(
            Problem(template, line, column, f"missing {key!r} (every other language has it, and the screens need it)")
        )


def load_words(directory: str | Path | None = None) -> dict[str, Words]:
    """Every language's words, from ``directory`` (default: the kiosk's own, read once).

    Raises :class:`WordsError` with every problem of every file when any file has one.
    """
    if directory is None:
        return dict(_kiosk_words())
    words, problems, _ = check_words(directory)
    if problems:
        raise WordsError(problems)
    return words


@cache
def _kiosk_words() -> dict[str, Words]:
    words = {code: _words(code, data) for code, data in kept_data(Path(WORDS_DIR)).items()}
    if _site:
        good, problems, _ = check_site_words(_site[0])
        if problems:
            raise WordsError(problems)
        words |= {code: _words(code, parse_file(path)[0]) for code, path in good.items()}
    return words


#: the cache folder's name under <user cache dir>/kiosk (see :func:`kept_data`)
KEPT = "words"


def kept_data(directory: Path) -> dict[str, Any]:
    """The data of ``directory``'s words files, checked; kept between starts (:func:`fileio.cache.keep`,
    keyed by every words file's content, this package's and :mod:`fileio`'s code and the Python),
    since composing and checking seven YAML files is about 0.02 s of every start. Files with a
    problem are never kept: they are read, and :class:`WordsError` raised, every time."""
    import sys

    import fileio
    from fileio.cache import code_digest, digest, keep, kept

    try:
        files = sorted(directory.glob("*.yaml"))
        code = [code_digest(folder) for folder in (Path(__file__).parent, Path(fileio.__file__).parent)]
        key = digest(KEPT, str(directory), sys.version, *code, *map(str, files))
    except OSError:  # what cannot be read is the check's to report
        key, files = "", []
    found = kept(KEPT, key) if key else None
    if isinstance(found, dict):
        return found
    data, problems, _ = _check_files(directory)
    if problems:
        raise WordsError(problems)
    if key:
        keep(KEPT, key, data, files)
    return data


T = TypeVar("T")


class Table(Mapping[str, T]):
    """One thing from every language's words, by language code (``VOICES["es"]``), read from the
    kiosk's words files on first use, so importing a module with tables reads no file."""

    #: bumped when the site's words change (:func:`use_site_words`): every table reads again
    generation = 0

    def __init__(self, pick: Callable[[Words], T]) -> None:
        self._pick = pick
        self._values: dict[str, T] | None = None
        self._generation = Table.generation

    def _all(self) -> dict[str, T]:
        if self._values is None or self._generation != Table.generation:
            self._values = {code: self._pick(words) for code, words in load_words().items()}
            self._generation = Table.generation
        return self._values

    def __getitem__(self, language: str) -> T:
        return self._all()[language]

    def __iter__(self) -> Iterator[str]:
        return iter(self._all())

    def __len__(self) -> int:
        return len(self._all())

    def __repr__(self) -> str:
        return f"Table({self._all()!r})"


def _frozen(value: Any) -> Any:
    if isinstance(value, list):
        return tuple(_frozen(v) for v in value)
    if isinstance(value, dict):
        return MappingProxyType({k: _frozen(v) for k, v in value.items()})
    return value


def _words(code: str, data: Mapping[str, Any]) -> Words:
    """A checked file's data as :class:`Words`; sections of SHAPE keep SHAPE's order."""

    def section(name: str) -> Mapping[str, Any]:
        return MappingProxyType({key: _frozen(data[name][key]) for key in SHAPE[name]})

    speech = dict(section("speech"))
    speech["commands"] = MappingProxyType({key: _frozen(data["speech"]["commands"][key]) for key in COMMANDS})
    language = data["language"]
    return Words(
        code,
        language["name"],
        language["voice"],
        MappingProxyType(dict(data["screen"])),
        section("prompts"),
        MappingProxyType(speech),
        section("export"),
        section("answers"),
    )


def _placeholders(text: Any) -> set[str] | None:
    """The ``{names}`` in ``text``, or None when it is no text or holds a brace that is not a
    ``{name}`` mark or a doubled brace (a format spec, an index, a lone brace)."""
    if not isinstance(text, str):
        return None
    names, wrong = placeholders(text)
    return None if wrong else names


class _Check:
    """The problems of one file's data against SHAPE and the template's (en.yaml's) screen texts."""

    def __init__(self, name: str, positions: Positions, template: Any, codes: set[str]) -> None:
        self.name, self.positions, self.codes = name, positions, codes
        self.template = template if isinstance(template, dict) else {}
        self.found: list[Problem] = []

    def add(self, path: tuple[Any, ...], message: str, key: bool = False) -> None:
        line, column = self.positions.of(path, key=key)
        self.found.append(Problem(self.name, line, column, message))

    def problems(self, data: Any, code: str) -> list[Problem]:
        self.mapping((), data, SHAPE)
        if isinstance(data, dict):
            self.overlaps(data)
        declared = data.get("language", {}).get("code") if isinstance(data, dict) else None
        if isinstance(declared, str) and declared != code:
            self.add(("language", "code"), f"language.code is {declared!r} but the file is {code}.yaml")
        return self.found

    def overlaps(self, data: dict[str, Any]) -> None:
        """Words that would mean two things: a yes word that is also a no word, or a command
        ("pause") that is also a yes or no word (the patient saying it would do the other)."""

        def said(path: tuple[str, ...]) -> dict[str, int]:
            value: Any = data
            for key in path:
                value = value.get(key) if isinstance(value, dict) else None
            words = value if isinstance(value, list) else []
            return {w.strip().casefold(): n for n, w in enumerate(words) if isinstance(w, str)}

        answers: dict[str, str] = {}
        for section in ("prompts", "speech", "answers"):
            yes, no = said((section, "yes_words")), said((section, "no_words"))
            for word in sorted(yes.keys() & no.keys()):
                self.add((section, "no_words", no[word]), f"{section}.no_words: {word!r} is also one of the yes_words")
            if section != "prompts":
                answers |= dict.fromkeys(yes.keys() | no.keys(), section)
        commands = data.get("speech", {}).get("commands") if isinstance(data.get("speech"), dict) else None
        for command in commands if isinstance(commands, dict) else ():
            for word, n in said(("speech", "commands", command)).items():
                if word in answers:
                    self.add(
                        ("speech", "commands", command, n),
                        f"speech.commands.{command}: {word!r} is also one of {answers[word]}'s yes or no words",
                    )

    def mapping(self, path: tuple[Any, ...], value: Any, shape: Mapping[str, Any]) -> None:
        where = describe(path) or "the file"
        if not isinstance(value, dict):
            keys = f" of {', '.join(map(repr, shape))}" if path and shape else ""
            self.add(path, f"{where} must be a mapping{keys}")
            return
        for key in shape:
            if key not in value:
                self.add(path, f"missing {describe(path + (key,))!r} (en.yaml has it)", key=True)
        for key in value:
            if not isinstance(key, str):
                self.add(path + (key,), f"the key {key!r} in {where} must be text (write it in quotes)", key=True)
            elif key not in shape:
                self.add(path + (key,), f"unknown key {describe(path + (key,))!r} (en.yaml has no such key)", key=True)
            else:
                self.value(path + (key,), value[key], shape[key])

    def value(self, path: tuple[Any, ...], value: Any, kind: Any) -> None:
        if isinstance(kind, dict):
            self.mapping(path, value, kind)
        elif kind == SCREEN:  # en.yaml's screen keys (a template without them is reported in its own check)
            texts = self.template.get("screen")
            keys = dict.fromkeys(texts, SCREEN_TEXT) if isinstance(texts, dict) else None
            if keys is not None or not isinstance(value, dict):
                self.mapping(path, value, keys or {})
        elif not self.fits(value, kind):
            self.add(path, f"{describe(path)} must be {_KIND_WORDS[kind]}")
        else:
            self.details(path, value, kind)

    def fits(self, value: Any, kind: str) -> bool:
        def words(v: Any, empty: bool = False) -> bool:
            return isinstance(v, list) and (empty or bool(v)) and all(isinstance(w, str) and w.strip() for w in v)

        if kind in (TEXT, SCREEN_TEXT):
            return isinstance(value, str) and bool(value.strip())
        if kind in (WORDS, NUMBER_FORMS):
            return words(value)
        if kind == WORDS_OR_NONE:
            return words(value, empty=True)
        if kind == NUMBERS:
            return isinstance(value, list) and bool(value) and all(words(v) for v in value)
        return isinstance(value, dict) and all(isinstance(k, str) and words(v) for k, v in value.items())

    def in_template(self, path: tuple[Any, ...]) -> Any:
        """The template's value at ``path``, or None."""
        value: Any = self.template
        for key in path:
            value = value.get(key) if isinstance(value, dict) else None
        return value

    def details(self, path: tuple[Any, ...], value: Any, kind: str) -> None:
        """What a value of the right kind may still get wrong: placeholders, counts, codes."""
        if kind == SCREEN_TEXT:
            mine, theirs = _placeholders(value), _placeholders(self.in_template(path))
            if mine is None:
                wrong = placeholders(value)[1]
                unpaired = [w for w in wrong if not (w.startswith("{") and w.endswith("}"))]
                what = "a brace without its pair" if unpaired else f"{', '.join(wrong)} is not a placeholder"
                self.add(
                    path,
                    f"{describe(path)}: {what}: a placeholder is a name in braces, like {{ways}}, with no "
                    "format, index or attribute (write {{ or }} for a brace)",
                )
            elif theirs is not None and mine != theirs:
                want = ", ".join(f"{{{p}}}" for p in sorted(theirs)) or "none"
                self.add(path, f"{describe(path)} must have the placeholders of en.yaml ({want})")
        elif kind == NUMBERS:
            template = self.in_template(path)
            if isinstance(template, list) and len(value) != len(template):
                self.add(path, f"{describe(path)} must have the words for {len(template)} numbers, as en.yaml")
        elif kind == NUMBER_FORMS:
            for index, form in enumerate(value):
                if _placeholders(form) not in ({"n"}, {"o"}):
                    self.add(path + (index,), f"{describe(path + (index,))} must hold {{n}} or {{o}}")
        elif kind == BY_LANGUAGE:
            for code in value:
                if code not in self.codes:
                    self.add(path + (code,), f"{describe(path + (code,))}: no words file for {code!r}", key=True)

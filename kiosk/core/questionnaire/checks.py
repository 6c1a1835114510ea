"""The rules a questionnaire file must follow that its JSON Schema cannot say.

Translations for the declared languages, unique ids, one display per code, what each kind of
item needs (options, ``answers: yes_no`` or a staff ``input``), the scoring formula and subscales
(:mod:`.rules`), and band sets covering every reachable total. Every problem is collected with
its ``file:line:col`` position, so a clinician editing the file by hand fixes them all in one pass.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

from fileio.positions import Positions, Problem, describe, schema_problems
from kiosk.core.questionnaire.rules import check_items, check_scoring, check_stand_ins, reachable_totals
from kiosk.core.words import LANGUAGES, load_words

#: the languages the kiosk's own screens are written in (a words file each, kiosk/core/words): a
#: questionnaire in another language would start a session its screens cannot show
SCREEN_LANGUAGES = LANGUAGES


def check(
    parsed: tuple[Any, Positions | None, list[Problem]], filename: str, schema: dict[str, Any]
) -> tuple[Any, list[Problem]]:
    """(data, every problem sorted by position) of a parsed file; data is None on a syntax error.

    ``schema`` is the questionnaire JSON Schema; the rules it cannot say are checked here too."""
    data, positions, problems = parsed
    if positions is None:
        return None, problems

    def add(path: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(path, key=key)
        problems.append(Problem(filename, line, col, message))

    _yes_no_keys(data)
    schema_problems(data, schema, positions, add)
    if isinstance(data, dict):
        _check_semantics(data, add)
    problems.sort(key=lambda p: (p.line, p.column, p.message))
    return data, problems


def _yes_no_keys(data: Any) -> None:
    """Unquoted, YAML reads ``points: {yes: 1, no: 0}`` as true and false: read them as meant."""
    items = data.get("items") if isinstance(data, dict) else None
    for item in items if isinstance(items, list) else ():
        points = item.get("points") if isinstance(item, dict) else None
        if isinstance(points, dict) and any(isinstance(k, bool) for k in points):
            item["points"] = {
                ({True: "yes", False: "no"}.get(k, k) if isinstance(k, bool) else k): v for k, v in points.items()
            }


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
    if "patient_title" in data:
        texts(("patient_title",), data.get("patient_title"))
    messages = data.get("messages")
    for name, value in messages.items() if isinstance(messages, dict) else ():
        texts(("messages", name), value)

    def options(path: tuple[Any, ...], value: Any) -> None:
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
                    elif isinstance(word, str) and (command := _commands(lang).get(word.strip().casefold())):
                        add(
                            path + (i, "synonyms", lang, n),
                            f"the synonym {word!r} is the kiosk's {command!r} command in {lang!r}: "
                            f"a patient saying it would {command} instead of answering",
                        )
            answer_code = option.get("code")
            if isinstance(answer_code, dict):
                key = (answer_code.get("system"), answer_code.get("code"))
                if key in codes:
                    add(path + (i, "code"), f"two options of {describe(path[:-1])} have the answer code {key[1]!r}")
                codes.add(key)

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
            options(path + ("options",), entry.get("options"))
            expected, opts = entry.get("expected"), entry.get("options")
            if (
                section == "familiarisation"
                and isinstance(expected, int)
                and isinstance(opts, list)
                and expected > len(opts)
            ):
                add(path + ("expected",), f"expected option {expected} but there are only {len(opts)} options")

    items = dicts(data.get("items"))
    check_items(items, add)
    check_stand_ins(data, items, add)
    translations = data.get("translations")
    for lang in translations if isinstance(translations, dict) else ():
        if languages and lang not in languages:
            add(("translations", lang), f"a translation for {lang!r}, which is not in 'languages'", key=True)
    check_scoring(data, items, texts, add)
    _check_bands(data, dicts, texts, add)


def _commands(language: str) -> dict[str, str]:
    """The voice commands' phrases in ``language`` (casefolded) -> the command ({} for a language
    without a words file)."""
    words = load_words().get(language)
    if words is None:
        return {}
    return {p.strip().casefold(): c for c, phrases in words.speech["commands"].items() for p in phrases}


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


def _check_bands(
    data: dict[str, Any],
    dicts: Callable[[Any], list[tuple[int, dict[str, Any]]]],
    texts: Callable[[tuple[Any, ...], Any], None],
    add: Callable[..., None],
) -> None:
    """Each band set: labels translated, unique band ids, no two bands sharing a total, every total
    a patient can reach in a band, and the last band ending at the highest possible total; the
    default names one of the sets.

    Gaps are judged on reachable totals, computed from the points (a formula total: every whole
    number of its declared range): with Barthel points in steps of 5, "20-35, 40-55" (as
    published) leaves no total out, so it is not a gap."""
    block = data.get("bands")
    if not isinstance(block, dict):
        return
    found = block.get("sets")
    sets: dict[str, Any] = found if isinstance(found, dict) else {}
    default = block.get("default")
    if isinstance(default, str) and sets and default not in sets:
        add(("bands", "default"), f"the default band set {default!r} is not one of the sets ({', '.join(sets)})")
    items = dicts(data.get("items"))
    # no items: the schema says so, and every band would only repeat it as "ends above 0"
    reachable = reachable_totals(data, items) if items else None
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
        below = min(min(reachable), ordered[0][1]["min"]) - 1  # the highest total covered so far
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

"""What the station accepts from a kiosk: every synced row checked against the session's definition.

A row is stored only if the station can show it: its fields have the types, values and lengths
the pages, the exports and both database engines take (times ISO 8601 and within reason, texts
no longer than their columns), and what it says about the questionnaire fits the definition the
session runs (item ids, option numbers and their points, practice questions, languages). A row
that does not is refused with :class:`RowRefused`, whose message names the row (``seq``) and the
field (``seq 17: record_answer.option: ...``), so the kiosk parks that row and delivers the rest.

A definition is accepted only if it rebuilds a questionnaire whose every text exists in every
language it declares and whose FHIR Questionnaire can be written (:func:`check_definition`).
Pure functions: no database, no web.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from datetime import datetime
from typing import Any

from kiosk.core.channels import Channel
from kiosk.core.questionnaire import Questionnaire, Timing
from kiosk.core.questionnaire.definition import DefinitionError, questionnaire_from
from kiosk.core.session import AnsweredBy
from kiosk.core.words import LANGUAGE_CODE
from kiosk.export import ExportError, ExportSite, fhir_questionnaire
from kiosk.store.database import PATIENT_ID

#: the longest id (item, session, kind, name) and time the station's columns hold
ID_MAX, TIME_MAX = 64, 40
#: the longest free text (detail, reason) and the longest identity value
TEXT_MAX, IDENTITY_MAX = 10000, 200
#: times a kiosk writes: date, time, optional fraction and zone (what datetime.isoformat gives)
ISO_TIME = re.compile(r"^\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}(\.\d{1,6})?(Z|[+-]\d{2}:\d{2})?\Z")
#: session times (seconds from its start) within reason: no session lasts a year
T_MAX = 365 * 86400.0
YEARS = (2000, 2200)
_URI = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:[^\s|]+\Z")
_SHA256 = re.compile(r"^[0-9a-f]{64}\Z")
IDENTITY_FIELDS = ("site", "kiosk_id", "patient_system", "questionnaire_url", "identifier_system", "device_system")
#: kinds whose rows say something about the questionnaire (they need the session's definition)
NEEDS_DEFINITION = ("record_answer", "withdraw_answer", "record_not_answered", "record_practice")


class RowRefused(ValueError):
    """A row the station cannot store as it is (the message names the row and the field)."""


def _fail(where: str, message: str) -> RowRefused:
    return RowRefused(f"{where}: {message}")


def text(value: Any, where: str, most: int = TEXT_MAX, *, empty: bool = True) -> str:
    if not isinstance(value, str):
        raise _fail(where, f"must be text, got {type(value).__name__}")
    if len(value) > most:
        raise _fail(where, f"must be at most {most} characters, got {len(value)}")
    if not empty and not value:
        raise _fail(where, "must not be empty")
    if "\x00" in value:
        raise _fail(where, "must not hold a NUL character")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        raise _fail(where, "must be Unicode text (it holds a lone surrogate)") from None
    return value


def integer(value: Any, where: str, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise _fail(where, f"must be a whole number from {low} to {high}, got {value!r:.40}")
    return value


def number(value: Any, where: str, low: float = 0.0, high: float = T_MAX) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not math.isfinite(value)
        or not low <= value <= high
    ):
        raise _fail(where, f"must be a number from {low:g} to {high:g}, got {value!r:.40}")
    return float(value)


def flag(value: Any, where: str) -> bool:
    if not isinstance(value, bool):
        raise _fail(where, f"must be true or false, got {value!r:.40}")
    return value


def one_of(value: Any, where: str, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise _fail(where, f"must be one of {', '.join(allowed)}, got {value!r:.40}")
    return value


def iso_time(value: Any, where: str) -> str:
    """An ISO 8601 date and time, as a kiosk writes it, in a sane year (2000-2200)."""
    text(value, where, TIME_MAX, empty=False)
    if not ISO_TIME.match(value):
        raise _fail(where, f"must be an ISO 8601 date and time such as 2026-11-23T15:02:11Z, got {value!r:.40}")
    try:
        moment = datetime.fromisoformat(value.replace("Z", "+00:00"))
    except ValueError:
        raise _fail(where, f"is not a real date and time: {value!r}") from None
    if not YEARS[0] <= moment.year <= YEARS[1]:
        raise _fail(where, f"the year {moment.year} is not plausible ({YEARS[0]}-{YEARS[1]})")
    return value


def _words(value: Any, where: str) -> None:
    if not isinstance(value, list):
        raise _fail(where, "must be a list of names")
    for i, name in enumerate(value):
        text(name, f"{where}[{i}]", ID_MAX)


def check_definition(definition: Any, where: str) -> Questionnaire:
    """The questionnaire a kiosk's captured definition describes, checked to be one the station
    can show and export in each of its languages (RowRefused naming what does not fit)."""
    if not isinstance(definition, dict):
        raise _fail(where, "must be an object (the kiosk's captured questionnaire definition)")
    try:
        q = questionnaire_from(definition)
    except DefinitionError as exc:
        raise _fail(where, str(exc)) from None
    text(q.id, f"{where}.id", ID_MAX, empty=False)
    text(q.version, f"{where}.version", ID_MAX)
    for language in q.languages:  # a site's own language too (its words file is the kiosk's)
        if not isinstance(language, str) or not LANGUAGE_CODE.fullmatch(language):
            raise _fail(f"{where}.languages", f"must be language codes such as en or pt-BR, got {language!r:.40}")
    ids = [i.id for i in q.items] + [p.id for p in q.familiarisation]
    if len(set(ids)) != len(ids):
        raise _fail(f"{where}.items", "two items or practice questions share an id")
    for item in q.items:
        text(item.id, f"{where}.items.id", ID_MAX, empty=False)
        for option in item.options:
            # any integer an instrument scores, negative ones too (errors counted against a total)
            integer(option.points, f"{where}.items.{item.id}.points", -1000, 1000)
    maps: list[tuple[str, Mapping[str, str]]] = [("title", q.title)]
    # staff items (answered_by: staff) are never spoken: they need no spoken text
    spoken = {i.id: ("text",) if i.staff else ("text", "spoken") for i in q.items}
    maps += [(f"items.{i.id}.{part}", getattr(i, part)) for i in q.items for part in spoken[i.id]]
    maps += [(f"items.{i.id}.options.{o.number}.label", o.label) for i in q.items for o in i.options]
    maps += [
        (f"familiarisation.{p.id}.{part}", getattr(p, part)) for p in q.familiarisation for part in ("text", "spoken")
    ]
    maps += [
        (f"familiarisation.{p.id}.options.{o.number}.label", o.label) for p in q.familiarisation for o in p.options
    ]
    maps += [(f"band_sets.{s.id}.{b.id}.label", b.label) for s in q.band_sets.values() for b in s.bands]
    for name, texts in maps:
        missing = [lang for lang in q.languages if lang not in texts]
        if missing:
            raise _fail(f"{where}.{name}", f"has no {missing[0]!r} text, a language the definition declares")
    for practice in q.familiarisation:
        one_of(practice.checks, f"{where}.familiarisation.{practice.id}.checks", ("hear", "read", "select"))
        integer(practice.expected, f"{where}.familiarisation.{practice.id}.expected", 1, len(practice.options))
    try:
        for language in q.languages:
            fhir_questionnaire(q, language, ExportSite(kiosk_id="station-check"))
    except (ExportError, KeyError, ValueError, TypeError) as exc:
        raise _fail(where, f"cannot be written as a FHIR Questionnaire ({exc})") from None
    return q


def check_identity(value: Any, where: str) -> None:
    """The kiosk's identity (site, kiosk id, FHIR systems) as exports will name the session."""
    if not isinstance(value, dict):
        raise _fail(where, "must be an object")
    for name in IDENTITY_FIELDS:
        if name in value:
            text(value[name], f"{where}.{name}", IDENTITY_MAX)
            if name.endswith(("_system", "_url")) and value[name] and not _URI.match(value[name]):
                raise _fail(f"{where}.{name}", "must be an absolute URI without spaces or '|'")
            if name in ("site", "kiosk_id") and re.search(r"[\s/|]", value[name]):
                raise _fail(f"{where}.{name}", "must hold no spaces, '/' or '|' (it is part of identifiers)")


def check_create(payload: Mapping[str, Any], where: str, session_id: str, q: Questionnaire) -> None:
    """A new session's row: who, in which language, when, and under which identity."""
    if payload["session_id"] != session_id:
        raise _fail(f"{where}.session_id", f"{payload['session_id']!r:.70} in a row of session {session_id!r}")
    if not isinstance(payload["patient_id"], str) or not PATIENT_ID.match(payload["patient_id"]):
        raise _fail(f"{where}.patient_id", "is not pseudonymous (2-64 letters, digits, '-' or '_')")
    if payload["questionnaire_id"] != q.id:
        raise _fail(
            f"{where}.questionnaire_id",
            f"{payload['questionnaire_id']!r:.70} is not the id of the session's definition ({q.id!r})",
        )
    one_of(payload["language"], f"{where}.language", q.languages)
    one_of(payload["answered_by"], f"{where}.answered_by", tuple(a.value for a in AnsweredBy))
    iso_time(payload["started_at"], f"{where}.started_at")
    timing = payload.get("timing", {})
    if not isinstance(timing, dict):
        raise _fail(f"{where}.timing", "must be an object of seconds")
    try:
        Timing().with_overrides(timing)
    except ValueError as exc:
        raise _fail(f"{where}.timing", str(exc)) from None
    if "simulated" in payload:
        flag(payload["simulated"], f"{where}.simulated")
    if "export" in payload:
        check_identity(payload["export"], f"{where}.export")


def check_row(kind: str, payload: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    """Every field of a known kind's payload (``where``: ``seq N: kind``); ``q`` is the session's
    definition (needed by :data:`NEEDS_DEFINITION` kinds, checked by the caller)."""
    p = payload
    if "t" in p or (kind in _CHECKS and kind != "finish_session"):
        number(p.get("t"), f"{where}.t")
    if "at" in p:
        iso_time(p["at"], f"{where}.at")
    for name in ("detail", "reason"):
        if name in p:
            text(p[name], f"{where}.{name}")
    check = _CHECKS.get(kind)
    if check is not None:
        check(p, where, q)


def _answer(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    assert q is not None
    item = _item(p, where, q)
    option = integer(p["option"], f"{where}.option", 1, len(item.options))
    if p["points"] != item.option(option).points or isinstance(p["points"], bool):
        raise _fail(
            f"{where}.points",
            f"{p['points']!r:.20} is not what option {option} of {item.id} scores ({item.option(option).points})",
        )
    integer(p["attempt"], f"{where}.attempt", 1, 10)
    one_of(p["channel"], f"{where}.channel", tuple(c.value for c in Channel))
    one_of(p["answered_by"], f"{where}.answered_by", tuple(a.value for a in AnsweredBy))


def _item(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> Any:
    assert q is not None
    item_id = text(p["item_id"], f"{where}.item_id", ID_MAX, empty=False)
    try:
        return q.item(item_id)
    except KeyError:
        raise _fail(
            f"{where}.item_id", f"{item_id!r} is not an item of {q.id} ({', '.join(i.id for i in q.items)})"
        ) from None


def _practice(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    assert q is not None
    question = next((f for f in q.familiarisation if f.id == p["question_id"]), None)
    if question is None:
        raise _fail(f"{where}.question_id", f"{p['question_id']!r:.70} is not a practice question of {q.id}")
    one_of(p["checks"], f"{where}.checks", ("hear", "read", "select"))
    one_of(p["outcome"], f"{where}.outcome", ("right", "wrong", "not_answered", "skipped"))
    if p.get("option") is not None:
        integer(p["option"], f"{where}.option", 1, len(question.options))
    if p.get("channel") is not None:
        one_of(p["channel"], f"{where}.channel", tuple(c.value for c in Channel))


def _context(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    values = p.get("set", {})
    if not isinstance(values, dict):
        raise _fail(f"{where}.set", "must be an object")
    for name, value in values.items():
        text(name, f"{where}.set", ID_MAX, empty=False)
        if isinstance(value, str):
            text(value, f"{where}.set.{name}", IDENTITY_MAX)
        elif isinstance(value, float) and not math.isfinite(value):
            raise _fail(f"{where}.set.{name}", "must be a finite number")
        elif value is not None and not isinstance(value, (bool, int, float)):
            raise _fail(f"{where}.set.{name}", "must be true/false, a number, text or null")
    _words(p.get("emit", []), f"{where}.emit")


def _metrics(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    if not isinstance(p["metrics"], dict):
        raise _fail(f"{where}.metrics", "must be an object of numbers")
    for name, value in p["metrics"].items():
        text(name, f"{where}.metrics", ID_MAX, empty=False)
        number(value, f"{where}.metrics.{name}", -1e9, 1e9)
    _words(p.get("fired", []), f"{where}.fired")


def _adaptation(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    text(p["name"], f"{where}.name", ID_MAX, empty=False)
    flag(p["active"], f"{where}.active")


def _event(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    text(p["kind"], f"{where}.kind", ID_MAX, empty=False)


def _finish(p: Mapping[str, Any], where: str, q: Questionnaire | None) -> None:
    iso_time(p["finished_at"], f"{where}.finished_at")
    if "total" in p:
        integer(p["total"], f"{where}.total", -100000, 100000)
    if "complete" in p:
        flag(p["complete"], f"{where}.complete")
    if p.get("band") is not None:
        text(p["band"], f"{where}.band", ID_MAX)


_CHECKS = {
    "record_answer": _answer,
    "withdraw_answer": lambda p, where, q: _item(p, where, q),
    "record_not_answered": lambda p, where, q: _item(p, where, q),
    "record_practice": _practice,
    "record_context": _context,
    "record_metrics": _metrics,
    "record_adaptation": _adaptation,
    "record_event": _event,
    "finish_session": _finish,
}


def sha_of(value: Any, where: str) -> str:
    """A definition's content address as a kiosk sends it."""
    if not isinstance(value, str) or not _SHA256.match(value):
        raise _fail(where, "must be a SHA-256 in hex (64 characters)")
    return value

"""Items staff answer (``answered_by: staff``): reading what staff type, and where it is kept.

A staff item is never shown or spoken to the patient; staff answer it after the visit, on the
kiosk's clinician screen (behind the PIN) or at the station. Every staff answer is one line of the
session's log (:data:`STAFF_ANSWER`, detail JSON: item, option or value, who), which is the audit
and, for a number (``input:``), the value itself; a chosen option is also an ordinary answer row
(answered by ``staff``) so every page and export that reads answers reads it. Pure: no store.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable, Mapping
from typing import Any, Protocol

from kiosk.core.questionnaire import Item, Questionnaire

#: the session log's kind for a staff answer
STAFF_ANSWER = "staff_answer"


class LogLine(Protocol):
    """A line of a session's log as :func:`entered_values` reads it (the store's LogEntry)."""

    @property
    def kind(self) -> str: ...
    @property
    def detail(self) -> str: ...


def _bound(value: float) -> str:
    """A range's end as staff read it: 9999999, not %g's 1e+07; 0.5 as it is."""
    return str(int(value)) if float(value).is_integer() else str(value)


def _number_words(item: Item) -> str:
    entry = item.entry
    assert entry is not None
    unit = f" {entry.unit}" if entry.unit else ""
    kind = "a whole number" if entry.type == "integer" else "a number"
    return f"{kind} from {_bound(entry.min)} to {_bound(entry.max)}{unit}"


def entry_hint(item: Item) -> str:
    """What staff may type for an ``input:`` item ("a number from 20 to 250 kg")."""
    return _number_words(item)


#: what staff may type: digits, at most one decimal point (or comma), a sign; no exponent
_DECIMAL = re.compile(r"[+-]?[0-9]+(?:\.[0-9]+)?")
_INTEGER = re.compile(r"[+-]?[0-9]+")


def entry_text(item: Item, typed: str) -> str:
    """The number staff typed for ``item`` as the text to keep (stripped, a decimal comma made a
    point, nothing rounded: ``72.123456`` stays so, ``1234567`` never becomes ``1.23457e+06``);
    ValueError with one sentence naming the item and what it takes when it is no such number
    (an integer item takes no decimals, no item takes an exponent) or out of range."""
    entry = item.entry
    if entry is None:
        raise ValueError(f"{item.id}: staff choose one of its options, not a number")
    text = typed.strip().replace(",", ".")
    pattern = _INTEGER if entry.type == "integer" else _DECIMAL
    if not pattern.fullmatch(text) or len(text) > 40:
        raise ValueError(f"{item.id}: {typed.strip()!r:.30} is not {_number_words(item)}")
    value: int | float = int(text) if entry.type == "integer" else float(text)
    if isinstance(value, float) and not math.isfinite(value) or not entry.fits(value):
        raise ValueError(f"{item.id}: {typed.strip()!r:.30} is not {_number_words(item)}")
    return text


def parse_entry(item: Item, typed: str) -> int | float:
    """The number staff typed for ``item`` (:func:`entry_text`'s rules; ValueError likewise)."""
    text = entry_text(item, typed)
    assert item.entry is not None
    return int(text) if item.entry.type == "integer" else float(text)


def answer_detail(item_id: str, *, option: int | None, value: float | None, by: str) -> str:
    """The log line's detail of one staff answer (JSON: what was entered and who entered it)."""
    return json.dumps({"item_id": item_id, "option": option, "value": value, "by": by}, sort_keys=True)


def read_detail(detail: str) -> dict[str, Any] | None:
    """A staff answer's detail as written by :func:`answer_detail` (None if it is not one)."""
    try:
        data = json.loads(detail)
    except ValueError:
        return None
    return data if isinstance(data, dict) and isinstance(data.get("item_id"), str) else None


def entered_values(q: Questionnaire, log: Iterable[LogLine]) -> dict[str, float]:
    """The numbers staff entered for ``q``'s ``input`` items, the latest per item, from a
    session's log (lines for items ``q`` lacks, or values that do not fit, are left out: the
    result then says the item is still waiting)."""
    values: dict[str, float] = {}
    entries = {item.id: item for item in q.items if item.entry is not None}
    for line in log:
        data = read_detail(line.detail) if line.kind == STAFF_ANSWER else None
        if data is None or (item := entries.get(data["item_id"])) is None or item.entry is None:
            continue
        value = data.get("value")
        if value is not None and item.entry.fits(value):
            values[item.id] = float(value) if item.entry.type == "decimal" else int(value)
    return values


def number_text(value: float) -> str:
    """A number staff entered as every page and export shows it: whole without a point (``64``,
    ``1234567``), else the shortest exact form (``72.123456``): never rounded, never ``%g``."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def waiting_for_staff(q: Questionnaire, options: Mapping[str, int], values: Mapping[str, float]) -> tuple[str, ...]:
    """The staff items with neither a chosen option nor an entered value, in order."""
    return tuple(i.id for i in q.items if i.staff and i.id not in options and i.id not in values)


class EnteredStep(Protocol):
    """A row of the station's audit trail as :func:`entered_at_station` reads it."""

    @property
    def action(self) -> str: ...
    @property
    def item_id(self) -> str | None: ...
    @property
    def reason(self) -> str: ...


#: the station's audit action for a number staff entered there (its ``reason`` holds the number)
ENTER = "enter"


def entered_at_station(q: Questionnaire, steps: Iterable[EnteredStep]) -> dict[str, float]:
    """The numbers staff entered at the station (audit rows :data:`ENTER`, oldest first, their
    ``reason`` the text as entered, :func:`entry_text`; the latest per item counts), for ``q``'s
    ``input`` items. (Rows written before the text was kept hold ``%g``: read as they parse.)"""
    values: dict[str, float] = {}
    entries = {item.id: item for item in q.items if item.entry is not None}
    for step in steps:
        item = entries.get(step.item_id or "") if step.action == ENTER else None
        if item is None:
            continue
        try:
            values[item.id] = parse_entry(item, step.reason)
        except ValueError:
            continue
    return values


def every_entered(q: Questionnaire, log: Iterable[LogLine], steps: Iterable[EnteredStep]) -> dict[str, float]:
    """Every number staff entered for a session: at the kiosk (its log), then at the station
    (its audit trail; later wins). The one reading every station page and export uses."""
    return {**entered_values(q, log), **entered_at_station(q, steps)}

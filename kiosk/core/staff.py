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


def _number_words(item: Item) -> str:
    entry = item.entry
    assert entry is not None
    unit = f" {entry.unit}" if entry.unit else ""
    kind = "a whole number" if entry.type == "integer" else "a number"
    return f"{kind} from {entry.min:g} to {entry.max:g}{unit}"


def entry_hint(item: Item) -> str:
    """What staff may type for an ``input:`` item ("a number from 20 to 250 kg")."""
    return _number_words(item)


def parse_entry(item: Item, typed: str) -> int | float:
    """The number staff typed for ``item`` (decimal comma accepted); ValueError with one sentence
    naming the item and what it takes when it is no such number or out of range."""
    entry = item.entry
    if entry is None:
        raise ValueError(f"{item.id}: staff choose one of its options, not a number")
    text = typed.strip().replace(",", ".")
    try:
        value: int | float = int(text) if entry.type == "integer" else float(text)
    except ValueError:
        raise ValueError(f"{item.id}: {typed.strip()!r:.30} is not {_number_words(item)}") from None
    if isinstance(value, float) and not math.isfinite(value) or not entry.fits(value):
        raise ValueError(f"{item.id}: {typed.strip()!r:.30} is not {_number_words(item)}")
    return value


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
    """The numbers staff entered at the station (audit rows :data:`ENTER`, oldest first; the
    latest per item counts), for ``q``'s ``input`` items."""
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

"""A result in a clinician's words: its total and band, or why it has none yet.

"No total yet: waiting for staff: Weight (kg), Height (cm)", never "total 7/5 incomplete (0 not
answered)": an incomplete result names what it waits for, by the items' own words, so whoever
reads it (the kiosk's staff screens, ``kiosk results``, the exports' text) knows what to do.
Pure: no I/O.
"""

from __future__ import annotations

from kiosk.core.questionnaire.model import Item, Questionnaire
from kiosk.core.questionnaire.scoring import Score

__all__ = ["item_name", "pending_words", "result_words"]

#: the longest an item's words get in a list of them
NAME_CHARS = 48


def item_name(item: Item, language: str = "en") -> str:
    """An item as a list names it: its clinical text's first line (shortened), and its unit for a
    number staff enter ("Weight (kg)")."""
    text = (item.text.get(language) or item.text.get("en") or item.id).strip().splitlines()[0]
    if len(text) > NAME_CHARS:
        text = text[: NAME_CHARS - 1].rstrip() + "…"
    unit = item.entry.unit if item.entry is not None else ""
    return f"{text} ({unit})" if unit else text


def pending_words(q: Questionnaire, score: Score, language: str = "en") -> str:
    """What an incomplete result waits for ("not answered: Feeding; waiting for staff: Weight
    (kg)"), or why its formula gave no total; '' when it is complete."""
    if score.problem:
        return score.problem
    if score.complete:
        return ""
    staff = set(score.awaiting_staff)
    names = {item.id: item_name(item, language) for item in q.items}
    patient = [names.get(i, i) for i in score.missing if i not in staff]
    parts = [f"not answered: {', '.join(patient)}"] if patient else []
    if staff:
        parts.append(f"waiting for staff: {', '.join(_either(q, score.awaiting_staff, names))}")
    return "; ".join(parts)


def _either(q: Questionnaire, waiting: tuple[str, ...], names: dict[str, str]) -> list[str]:
    """The names of ``waiting``, an item answered instead of others joined to their last with
    "or" ("Weight (kg), Height (cm) or Calf circumference (cm)")."""
    stand_ins = {i.id: i.instead_of for i in q.items if i.instead_of and i.id in waiting}
    listed = [i for i in waiting if i not in stand_ins]
    shown = [names.get(i, i) for i in listed]
    for stand_in, others in stand_ins.items():
        last = max((listed.index(o) for o in others if o in listed), default=None)
        if last is None:
            listed.append(stand_in)
            shown.append(names.get(stand_in, stand_in))
        else:
            shown[last] += f" or {names.get(stand_in, stand_in)}"
    return shown


def result_words(q: Questionnaire, score: Score, language: str = "en") -> str:
    """The result in one line: "Total 7 of 10; Mild dependence", "No total yet: waiting for
    staff: Weight (kg), Height (cm)" (only staff items missing), or "No total: not answered:
    Feeding" (a formula that failed: "No total: " and why)."""
    if score.complete:
        band = score.band.label.get(language) or score.band.label.get("en", "") if score.band else ""
        return f"Total {score.total} of {score.max_total}" + (f"; {band}" if band else "")
    waiting = "No total yet" if not score.problem and set(score.missing) <= set(score.awaiting_staff) else "No total"
    return f"{waiting}: {pending_words(q, score, language)}"

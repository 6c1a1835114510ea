"""The rules of format v2 a JSON Schema cannot say: what each kind of item needs, the scoring
formula and subscales, and the totals an instrument can reach.

Kept apart from :mod:`.checks` (texts, ids, codes, bands) so each reads in one sitting; both
report through the same ``add(path, message, key=)`` so every problem is one ``file:line:col``.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Callable
from typing import Any, TypeGuard

from fileio.positions import describe
from kiosk.core.questionnaire.formula import ItemAnswers, prove
from kiosk.core.questionnaire.scoring import local_code
from kiosk.core.questionnaire.ucum import unit_problem

Items = list[tuple[int, dict[str, Any]]]

#: the codes of a yes/no item's options (as :mod:`.loading` expands them)
YES_NO_CODES = {"yes": ("http://loinc.org", "LA33-6"), "no": ("http://loinc.org", "LA32-8")}
#: the kinds of answer an item may have, one each
KINDS = ("options", "answers", "input")
#: the most items that may stand in for others (each multiplies the answers a formula is proved on by 3)
MAX_STAND_INS = 3
#: the largest total (either sign) a formula may declare: clinical scores are far smaller, and
#: bands are checked against every whole number of the range
MAX_TOTAL = 10_000


def _integer(value: Any) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)


def _number(value: Any) -> TypeGuard[float]:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def check_items(items: Items, add: Callable[..., None]) -> None:
    """Each item has one kind of answer; yes/no points, staff inputs and spoken texts where due."""
    for i, item in items:
        path = ("items", i)
        kinds = [k for k in KINDS if k in item]
        if not kinds:
            add(path, f"{describe(path)} needs 'options', 'answers: yes_no' or 'input' (a number staff enter)")
        for extra in kinds[1:]:
            add(path + (extra,), f"{describe(path)} has both {kinds[0]!r} and {extra!r}: give one", key=True)
        if "points" in item and item.get("answers") != "yes_no":
            add(
                path + ("points",),
                f"'points' on {describe(path)} is for 'answers: yes_no' items; give each option its own points",
                key=True,
            )
        if item.get("answers") == "yes_no" and "points" not in item:
            add(path, f'{describe(path)} has answers: yes_no but no points ({{"yes": N, "no": N}})')
        # an unknown answered_by is the schema's to report: judged as neither, it adds no more lines
        patient = item.get("answered_by", "patient") == "patient"
        if "input" in item and patient:
            add(path + ("input",), f"{describe(path)}: only staff enter numbers: add answered_by: staff", key=True)
        if patient and "spoken" not in item:
            add(path, f"{describe(path)} is missing 'spoken' (what the kiosk says to the patient)")
        entry = item.get("input")
        if isinstance(entry, dict):
            low, high = entry.get("min"), entry.get("max")
            if _number(low) and _number(high) and low > high:
                add(path + ("input", "min"), f"{describe(path + ('input',))}: min {low} is above max {high}")
            unit = entry.get("unit")
            why = unit_problem(unit) if isinstance(unit, str) and unit else None
            if why is not None:
                add(path + ("input", "unit"), f"{describe(path + ('input', 'unit'))}: {why}")
            if entry.get("type") == "integer":
                for name in ("min", "max"):
                    value = entry.get(name)
                    if isinstance(value, float) and not value.is_integer():
                        add(path + ("input", name), f"an integer input cannot have {name} {value}")


def _choices(data: dict[str, Any], item: dict[str, Any]) -> list[tuple[tuple[str, str], int]] | None:
    """((system, code), points) of an item's options in order; [] for an input; None if malformed."""
    if item.get("answers") == "yes_no":
        points = item.get("points")
        if not isinstance(points, dict) or not all(_integer(points.get(k)) for k in YES_NO_CODES):
            return None
        return [(YES_NO_CODES[k], points[k]) for k in YES_NO_CODES]
    if "input" in item:
        return []
    options = item.get("options")
    if not isinstance(options, list) or not options:
        return None
    found: list[tuple[tuple[str, str], int]] = []
    for n, option in enumerate(options, start=1):
        if not isinstance(option, dict) or not _integer(option.get("points")):
            return None
        code = option.get("code")
        if isinstance(code, dict) and isinstance(code.get("system"), str) and isinstance(code.get("code"), str):
            key = (code["system"], code["code"])
        else:
            key = local_code(str(data.get("id")), str(item.get("id")), n)
        found.append((key, option["points"]))
    return found


def _formula(data: dict[str, Any]) -> dict[str, Any] | None:
    scoring = data.get("scoring")
    total = scoring.get("total") if isinstance(scoring, dict) else None
    return total if isinstance(total, dict) else None


def reachable_totals(data: dict[str, Any], items: Items) -> set[int] | None:
    """Every total the instrument can give: the sums of one option's points per item (no step
    assumed), or every whole number of a formula's declared range; None when the points or the
    range are malformed (the schema says so, and bands judged on them would bury that mistake)."""
    formula = _formula(data)
    if formula is not None:
        low, high = formula.get("min"), formula.get("max")
        if _integer(low) and _integer(high) and -MAX_TOTAL <= low <= high <= MAX_TOTAL:
            return set(range(low, high + 1))
        return None
    totals = {0}
    for _, item in items:
        choices = _choices(data, item)
        if choices is None:
            return None
        if choices:
            totals = {t + p for t in totals for _, p in choices}
    return totals


def _answers(data: dict[str, Any], items: Items) -> list[ItemAnswers] | None:
    """What each item may be answered with, for the formula's proof; None if malformed."""
    found = []
    for _, item in items:
        choices, entry = _choices(data, item), item.get("input")
        if choices is None or not isinstance(item.get("id"), str):
            return None
        if isinstance(entry, dict):
            low, high = entry.get("min"), entry.get("max")
            if not (_number(low) and _number(high)) or low > high:
                return None
            found.append(ItemAnswers(item["id"], entry=(str(entry.get("type")), low, high)))
        else:
            found.append(ItemAnswers(item["id"], options=tuple((s, c, p) for (s, c), p in choices)))
    return found


def stand_ins(items: Items) -> dict[str, list[str]]:
    """Each well-formed ``instead_of``: the standing-in item's id -> the ids it stands in for."""
    return {
        item["id"]: [i for i in item["instead_of"] if isinstance(i, str)]
        for _, item in items
        if isinstance(item.get("id"), str) and isinstance(item.get("instead_of"), list)
    }


def check_stand_ins(data: dict[str, Any], items: Items, add: Callable[..., None]) -> None:
    """``instead_of`` names other existing items, each in one list only, none itself standing in
    for others; the instrument's total is a formula (which says how either side scores); at most
    :data:`MAX_STAND_INS` items stand in for others (every combination is proved)."""
    ids = {item.get("id") for _, item in items}
    groups = stand_ins(items)
    taken: dict[str, str] = {}
    for i, item in items:
        listed = item.get("instead_of")
        if not isinstance(listed, list):
            continue
        path = ("items", i, "instead_of")
        if _formula(data) is None:
            add(
                path,
                f"{describe(path)}: an item answered instead of others needs a formula total, "
                "which says how either is scored",
                key=True,
            )
        for k, other in enumerate(listed):
            if other == item.get("id") or other not in ids:
                what = "itself" if other == item.get("id") else f"{other!r}, which is not an item"
                add(path + (k,), f"{describe(path)} names {what}")
            elif other in groups:
                add(path + (k,), f"{describe(path)} names {other!r}, which stands in for others itself")
            elif other in taken and taken[other] != item.get("id"):
                add(path + (k,), f"{describe(path)}: {other!r} is already stood in for by {taken[other]!r}")
            else:
                taken[other] = str(item.get("id"))
    if len(groups) > MAX_STAND_INS:
        add(("items",), f"at most {MAX_STAND_INS} items may stand in for others ({len(groups)} do)")


def _scenarios(groups: dict[str, list[str]], answers: list[ItemAnswers]) -> list[tuple[str, list[ItemAnswers]]]:
    """The sets of items a complete result may have answered, described: every item; and for
    each stand-in, either it or the items it stands in for left out."""
    choices = [[("", set[str]())]]
    for stand_in, others in list(groups.items())[:MAX_STAND_INS]:
        choices.append(
            [
                ("", set()),
                (f" (with {stand_in} answered instead of {', '.join(others)})", set(others)),
                (f" (with {', '.join(others)} answered, not {stand_in})", {stand_in}),
            ]
        )
    found = []
    for combination in itertools.product(*choices):
        left_out = set().union(*(c[1] for c in combination))
        found.append(("".join(c[0] for c in combination), [a for a in answers if a.id not in left_out]))
    return found


def check_scoring(
    data: dict[str, Any], items: Items, texts: Callable[[tuple[Any, ...], Any], None], add: Callable[..., None]
) -> None:
    """The formula is in the kiosk's formula language, names existing items, and gives one whole
    number in its range for every complete set of answers (:func:`prove`); subscales name
    existing scored items once each, with ids of their own."""
    formula = _formula(data)
    scoring = data.get("scoring")
    total = scoring.get("total") if isinstance(scoring, dict) else None
    if isinstance(total, str) and total != "sum":
        add(("scoring", "total"), f"scoring.total is 'sum' or a formula ({{fhirpath, min, max}}), not {total!r}")
    path: tuple[Any, ...]
    if formula is not None:
        path = ("scoring", "total")
        low, high = formula.get("min"), formula.get("max")
        if _integer(low) and _integer(high) and low > high:
            add(path + ("min",), f"scoring.total: min {low} is above max {high}")
        for name, value in (("min", low), ("max", high)):
            if _integer(value) and abs(value) > MAX_TOTAL:
                add(path + (name,), f"scoring.total: {name} {value} is beyond ±{MAX_TOTAL:,}, no score's range")
        expression = formula.get("fhirpath")
        answers = _answers(data, items)
        if isinstance(expression, str) and answers is not None and _integer(low) and _integer(high):
            bounded = low <= high and abs(low) <= MAX_TOTAL and abs(high) <= MAX_TOTAL
            found: list[tuple[int, str]] = []
            for described, scenario in _scenarios(stand_ins(items), answers) if bounded else ():
                proved = prove(expression, low, high, scenario, [a.id for a in answers])
                found = [(at, why + (described if not at else "")) for at, why in proved]
                if found:
                    break
            for at, why in found:
                if at:
                    add(path + ("fhirpath",), f"scoring.total.fhirpath, at character {at}: {why}")
                else:
                    whole = "not whole" in why or re.search(r"gives -?\d+\.\d", why)
                    hint = " (round(), floor() or div make one)" if whole else ""
                    add(
                        path + ("fhirpath",),
                        f"scoring.total.fhirpath: {why}; it must give one whole number from {low} to {high}{hint}",
                    )
    subscales = scoring.get("subscales") if isinstance(scoring, dict) else None
    by_id = {item.get("id"): item for _, item in items}
    seen: set[Any] = set()
    for n, sub in enumerate(subscales if isinstance(subscales, list) else ()):
        if not isinstance(sub, dict):
            continue
        path = ("scoring", "subscales", n)
        texts(path + ("label",), sub.get("label"))
        sub_id = sub.get("id")
        if sub_id in seen or sub_id in by_id or sub_id == "total":
            what = "another subscale" if sub_id in seen else "an item" if sub_id in by_id else "the total"
            add(path + ("id",), f"subscale id {sub_id!r} is already {what}'s: give it its own")
        seen.add(sub_id)
        members = sub.get("items")
        for k, item_id in enumerate(members if isinstance(members, list) else ()):
            item = by_id.get(item_id)
            if item is None:
                add(path + ("items", k), f"subscale {sub_id!r}: there is no item {item_id!r}")
            elif "input" in item:
                add(path + ("items", k), f"subscale {sub_id!r}: item {item_id!r} is an input, with no points")
            elif isinstance(members, list) and members.index(item_id) != k:
                add(path + ("items", k), f"subscale {sub_id!r} lists item {item_id!r} twice")

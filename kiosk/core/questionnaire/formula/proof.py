"""Proving a total formula for every possible set of answers, before any patient answers.

Two ways, the cheap one first: the formula evaluated once on unknown answers (each choice item
any of its options, each number anywhere in its range: :mod:`.values`), which bounds the total
and says whether it is always whole; and, when that cannot decide and the answers are few enough
(:data:`MAX_COMBINATIONS`, and :data:`MAX_PROOF_STEPS` steps in all), every combination of
answers evaluated for real, which finds the answers that break it. Each problem is (character
of the formula, message); a formula that passes gives one whole number in its range on every
complete set of answers, which is what lets the kiosk interpret every complete result.
"""

from __future__ import annotations

import difflib
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from decimal import Decimal
from typing import Any

from kiosk.core.questionnaire.formula.evaluation import ITEM_WEIGHT, Budget, evaluate_tree
from kiosk.core.questionnaire.formula.syntax import FormulaError, Node, named_items, parse
from kiosk.core.questionnaire.formula.values import (
    Choice,
    EvaluationError,
    Interval,
    Unprovable,
    describe_kind,
    is_number,
)

#: the most combinations of answers tried one by one
MAX_COMBINATIONS = 100_000
#: the steps all of them may take together (a few seconds at most)
MAX_PROOF_STEPS = 400_000


@dataclass(frozen=True)
class ItemAnswers:
    """What one item may be answered with: its options' (system, code, points), or a number
    staff enter (``entry`` = (type, min, max))."""

    id: str
    options: tuple[tuple[str, str, int], ...] = ()
    entry: tuple[str, float, float] | None = None

    def values(self) -> list[dict[str, Any]] | None:
        """Every answer it may have, when they are few (None: a decimal or a wide range)."""
        if self.entry is None:
            return [
                {"valueCoding": {"system": s, "code": c, "extension": [{"url": ITEM_WEIGHT, "valueDecimal": p}]}}
                for s, c, p in self.options
            ]
        kind, low, high = self.entry
        if kind != "integer" or high - low > 200:
            return None
        return [{"valueInteger": n} for n in range(math.ceil(low), math.floor(high) + 1)]

    def unknown(self) -> dict[str, Any]:
        """Its answer, not known which."""
        if self.entry is None:
            return {"valueCoding": Choice(self.id, self.options)}
        kind, low, high = self.entry
        key = "valueInteger" if kind == "integer" else "valueDecimal"
        return {key: Interval(Decimal(str(low)), Decimal(str(high)), kind == "integer")}


def prove(
    expression: str, low: int, high: int, items: Sequence[ItemAnswers], known: Sequence[str] = ()
) -> list[tuple[int, str]]:
    """Every problem of a total formula ranging ``low``..``high`` over ``items``, as
    (character, message), character 0 for the formula as a whole; empty when every complete set
    of answers gives one whole number in range. ``known``: the instrument's item ids, when
    ``items`` are those a complete result may have answered (some left out)."""
    try:
        tree = parse(expression)
    except FormulaError as exc:
        return [(exc.at, exc.message)]
    ids = list(known) or [i.id for i in items]
    wrong = [(at, _no_item(name, ids)) for name, at in named_items(tree) if name not in ids]
    if wrong:
        return wrong
    response = {
        "resourceType": "QuestionnaireResponse",
        "item": [{"linkId": i.id, "answer": [i.unknown()]} for i in items],
    }
    try:
        result = evaluate_tree(tree, response, Budget())
    except Unprovable as exc:
        return _every_answer(tree, low, high, items, f"its result cannot be bounded for every answer ({exc})")
    except EvaluationError as exc:
        return [(0, f"it cannot be evaluated on every answer: {exc}")]
    why = _judge(result, low, high)
    if why is None:
        return []
    return _every_answer(tree, low, high, items, why)


def _judge(result: list[Any], low: int, high: int) -> str | None:
    """Why ``result`` is not one whole number from ``low`` to ``high`` (None: it is)."""
    if len(result) != 1:
        return f"it gives {len(result)} values, not one number"
    value = result[0]
    if isinstance(value, Interval):
        if value.low < low or value.high > high:
            return f"it can give from {value.low.normalize():f} to {value.high.normalize():f}"
        if not value.whole:
            return "it can give a number that is not whole"
        return None
    if not is_number(value):
        return f"it gives {describe_kind(value)}, not a number"
    if value != int(value) or not low <= value <= high:
        return f"it gives {value}"
    return None


def _every_answer(tree: Node, low: int, high: int, items: Sequence[ItemAnswers], why: str) -> list[tuple[int, str]]:
    """Every combination of answers tried, when few enough (numbers of a wide or decimal range
    stay unknown); else ``why`` stands."""
    choices = [i.values() or [i.unknown()] for i in items]
    count = math.prod(len(c) for c in choices)
    if all(len(c) == 1 for c in choices):
        return [(0, why)]
    too_many = f"{why} (too many combinations of answers, {count:,}, to try each)"
    if count > MAX_COMBINATIONS:
        return [(0, too_many)]
    budget = Budget(MAX_PROOF_STEPS)
    for n, combination in enumerate(itertools.product(*choices)):
        response = {
            "resourceType": "QuestionnaireResponse",
            "item": [{"linkId": i.id, "answer": [a]} for i, a in zip(items, combination, strict=True)],
        }
        try:
            problem = _judge(evaluate_tree(tree, response, budget), low, high)
        except Unprovable:
            return [(0, why)]
        except EvaluationError as exc:
            if budget.steps > budget.limit:
                return [(0, too_many)]
            problem = str(exc)
        if problem is not None:
            return [(0, f"{problem} when {_described(items, combination)}")]
        if n == 0 and budget.steps * count > budget.limit:
            return [(0, too_many)]
    return []


def _described(items: Sequence[ItemAnswers], combination: Sequence[dict[str, Any]]) -> str:
    parts = []
    for item, answer in zip(items, combination, strict=True):
        if item.values() is None:
            continue
        if "valueInteger" in answer:
            parts.append(f"{item.id} is {answer['valueInteger']}")
        else:
            code = answer["valueCoding"]["code"]
            number = next(n for n, o in enumerate(item.options, start=1) if o[1] == code)
            parts.append(f"{item.id} is option {number}")
    return ", ".join(parts)


def _no_item(name: str, ids: list[str]) -> str:
    close = difflib.get_close_matches(name, ids, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else f" (the items are {', '.join(ids)})"
    return f"there is no item {name!r}{hint}"

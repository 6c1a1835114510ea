"""Evaluating a formula's tree on a QuestionnaireResponse, within a budget of steps.

FHIRPath's meaning for the subset :mod:`.syntax` accepts: collections, empty propagating through
operators, three-valued ``and``/``or``, ``/`` giving a decimal and nothing for ÷ 0, ``weight()``
reading a chosen Coding's itemWeight (SDC). Every node visited and every element handled is a
step of a :class:`Budget`, and no collection grows past :data:`MAX_ELEMENTS`, so no formula runs
long whatever its answers: the deterministic counter, not a clock, stops it. The same evaluator
computes with unknown answers (:mod:`.values`) when :mod:`.proof` bounds a formula.
"""

from __future__ import annotations

from collections.abc import Mapping
from decimal import Decimal
from typing import Any

from kiosk.core.questionnaire.formula.syntax import Node
from kiosk.core.questionnaire.formula.values import (
    UNKNOWN,
    Choice,
    EvaluationError,
    Interval,
    Texts,
    Unprovable,
    arithmetic,
    compare,
    describe_kind,
    equal,
    is_number,
    join,
    numeric,
    rounded,
    span,
)

#: steps one evaluation may take: a published score over 60 items takes a few thousand
MAX_STEPS = 200_000
#: the most elements any collection of one evaluation may hold
MAX_ELEMENTS = 10_000

#: SDC/R5 extension giving an answer option its score, and R4's older one (``weight()`` reads both)
ITEM_WEIGHT = "http://hl7.org/fhir/StructureDefinition/itemWeight"
ORDINAL_VALUE = "http://hl7.org/fhir/StructureDefinition/ordinalValue"


class Budget:
    """A count of steps that stops an evaluation past ``limit`` (deterministic: no clock)."""

    def __init__(self, limit: int = MAX_STEPS) -> None:
        self.limit, self.steps = limit, 0

    def spend(self, steps: int = 1) -> None:
        self.steps += steps
        if self.steps > self.limit:
            raise EvaluationError(f"it takes more than {self.limit:,} steps: simplify it")


def evaluate_tree(tree: Node, resource: Mapping[str, Any], budget: Budget | None = None) -> list[Any]:
    """The collection ``tree`` gives on ``resource`` (%resource, and the starting context)."""
    return _Run(resource, budget or Budget()).eval(tree, [resource])


class _Run:
    def __init__(self, resource: Mapping[str, Any], budget: Budget) -> None:
        self.resource, self.budget = resource, budget

    def grown(self, found: list[Any]) -> list[Any]:
        self.budget.spend(len(found))
        if len(found) > MAX_ELEMENTS:
            raise EvaluationError(f"a collection grew past {MAX_ELEMENTS:,} elements")
        return found

    def eval(self, tree: Node, focus: list[Any]) -> list[Any]:
        self.budget.spend()
        kind = tree.kind
        if kind in ("number", "string", "boolean"):
            return [tree.value]
        if kind == "empty":
            return []
        if kind == "env":
            return [self.resource]
        if kind == "this":
            return focus
        if kind == "name":
            return self.step(tree, focus)
        if kind == "call":
            return self.call(tree, focus)
        if kind == "path":
            return self.eval(tree.args[1], self.eval(tree.args[0], focus))
        if kind == "negate":
            return self.binary("-", [0], self.eval(tree.args[0], focus), tree)
        if tree.value in ("and", "or", "xor", "implies"):
            return self.logic(tree, focus)
        return self.binary(tree.value, self.eval(tree.args[0], focus), self.eval(tree.args[1], focus), tree)

    def step(self, tree: Node, focus: list[Any]) -> list[Any]:
        name, found = tree.value, list[Any]()
        for element in focus:
            if isinstance(element, Mapping):
                if element.get("resourceType") == name and element is self.resource:
                    found.append(element)
                    continue
                keys = [k for k in element if k.startswith("value") and k[5:6].isupper()] if name == "value" else [name]
                for key in keys:
                    value = element.get(key)
                    found.extend(_plain(v) for v in (value if isinstance(value, list) else [value]) if v is not None)
            elif isinstance(element, Choice) and name in ("code", "system"):
                texts = frozenset(o[1] if name == "code" else o[0] for o in element.options)
                found.append(next(iter(texts)) if len(texts) == 1 else Texts(texts))
        return self.grown(found)

    def single(self, values: list[Any], tree: Node, what: str) -> Any:
        if len(values) > 1:
            raise EvaluationError(f"at character {tree.at}: {what} got {len(values)} values where it needs one")
        return values[0] if values else None

    def truth(self, values: list[Any], tree: Node, what: str) -> Any:
        """True, False, UNKNOWN, or None for empty."""
        value = self.single(values, tree, what)
        if value is not None and not isinstance(value, bool) and value is not UNKNOWN:
            raise EvaluationError(f"at character {tree.at}: {what} needs true or false, not {describe_kind(value)}")
        return value

    def logic(self, tree: Node, focus: list[Any]) -> list[Any]:
        op = tree.value
        a = self.truth(self.eval(tree.args[0], focus), tree.args[0], f"'{op}'")
        b = self.truth(self.eval(tree.args[1], focus), tree.args[1], f"'{op}'")
        if op == "implies":
            a, op = (None if a is None else UNKNOWN if a is UNKNOWN else not a), "or"
        if op == "and":
            if a is False or b is False:
                return [False]
            result = True if a is True and b is True else None if None in (a, b) else UNKNOWN
        elif op == "or":
            if a is True or b is True:
                return [True]
            result = False if a is False and b is False else None if None in (a, b) else UNKNOWN
        else:
            result = None if None in (a, b) else UNKNOWN if UNKNOWN in (a, b) else a != b
        return [] if result is None else [result]

    def binary(self, op: str, left: list[Any], right: list[Any], tree: Node) -> list[Any]:
        if op == "|":
            found = list(left)
            for value in right:
                if not any(equal(value, seen) is True for seen in found):
                    found.append(value)
            return self.grown(found)
        if op in ("=", "!="):
            if not left or not right:
                return []
            if len(left) != len(right):
                return [op == "!="]
            results = [equal(a, b) for a, b in zip(left, right, strict=True)]
            same = False if False in results else UNKNOWN if UNKNOWN in results else True
            return [same if op == "=" or same is UNKNOWN else not same]
        a = self.single(left, tree, f"'{op}'")
        b = self.single(right, tree, f"'{op}'")
        if a is None or b is None:
            return []
        try:
            if op in ("<", ">", "<=", ">="):
                return [compare(op, a, b)]
            if op == "+" and isinstance(a, str) and isinstance(b, str):
                if len(a) + len(b) > MAX_ELEMENTS:
                    raise EvaluationError(f"a text grew past {MAX_ELEMENTS:,} characters")
                return [a + b]
            if not (numeric(a) and numeric(b)):
                raise EvaluationError(f"'{op}' needs two numbers, not {describe_kind(a)} and {describe_kind(b)}")
            result = arithmetic(op, a, b)
        except Unprovable as exc:
            raise Unprovable(f"at character {tree.at}: {exc}") from None
        except EvaluationError as exc:
            raise EvaluationError(f"at character {tree.at}: {exc}") from None
        return [] if result is None else [result]

    def call(self, tree: Node, focus: list[Any]) -> list[Any]:
        name, args = tree.value, tree.args
        if name == "iif":
            condition = self.truth(self.eval(args[0], focus), args[0], "iif()'s condition")
            otherwise: list[Any] = self.eval(args[2], focus) if len(args) == 3 and condition is not True else []
            if condition is True:
                return self.eval(args[1], focus)
            if condition is not UNKNOWN:
                return otherwise
            chosen = self.eval(args[1], focus)
            if len(chosen) != len(otherwise):
                raise Unprovable(f"at character {tree.at}: iif() gives {len(chosen)} or {len(otherwise)} values")
            try:
                return [join(a, b) for a, b in zip(chosen, otherwise, strict=True)]
            except Unprovable as exc:
                raise Unprovable(f"at character {tree.at}: {exc}") from None
        if name in ("where", "exists") and args:
            kept = []
            for element in focus:
                keep = self.truth(self.eval(args[0], [element]), args[0], f"{name}()'s criterion")
                if keep is UNKNOWN:
                    raise Unprovable(f"at character {tree.at}: which elements {name}() keeps depends on the answers")
                if keep:
                    kept.append(element)
            return kept if name == "where" else [bool(kept)]
        self.budget.spend(len(focus))
        if name in ("exists", "empty"):
            return [bool(focus) == (name == "exists")]
        if name == "count":
            return [len(focus)]
        if name in ("first", "last"):
            return focus[:1] if name == "first" else focus[-1:]
        if name in ("weight", "ordinal"):
            return [w for w in (_weight(v) for v in focus) if w is not None]
        if name == "not":
            value = self.truth(focus, tree, "not()")
            return [] if value is None else [UNKNOWN if value is UNKNOWN else not value]
        return self.numbers(tree, focus)

    def numbers(self, tree: Node, focus: list[Any]) -> list[Any]:
        name = tree.value
        for value in focus:
            if not numeric(value):
                raise EvaluationError(f"at character {tree.at}: {name}() takes numbers, not {describe_kind(value)}")
        try:
            if name == "sum":
                total: Any = 0
                for value in focus:
                    total = arithmetic("+", total, value)
                return [total]
            if name in ("min", "max"):
                return [_extreme(name, focus)] if focus else []
            value = self.single(focus, tree, f"{name}()")
            if value is None:
                return []
            places = 0
            if tree.args:
                digits = self.single(self.eval(tree.args[0], focus), tree.args[0], "round()'s precision")
                if not (isinstance(digits, int) and not isinstance(digits, bool) and 0 <= digits <= 8):
                    raise EvaluationError("round()'s precision is a whole number from 0 to 8")
                places = digits
            return [rounded(name, value, places)]
        except EvaluationError as exc:
            raise type(exc)(f"at character {tree.at}: {exc}") from None


def _extreme(name: str, values: list[Any]) -> Any:
    if all(is_number(v) for v in values):
        return min(values) if name == "min" else max(values)
    lows = [v.low if isinstance(v, Interval) else Decimal(v) for v in values]
    highs = [v.high if isinstance(v, Interval) else Decimal(v) for v in values]
    pick = min if name == "min" else max
    whole = all(v.whole if isinstance(v, Interval) else isinstance(v, int) for v in values)
    return span(pick(lows), pick(highs), whole)


def _weight(value: Any) -> Any:
    """A chosen Coding's score (itemWeight or ordinalValue), or its possible scores; None: none."""
    if isinstance(value, Choice):
        points = [o[2] for o in value.options]
        return span(Decimal(min(points)), Decimal(max(points)), True)
    if not isinstance(value, Mapping):
        return None
    for ext in value.get("extension", ()):
        if isinstance(ext, Mapping) and ext.get("url") in (ITEM_WEIGHT, ORDINAL_VALUE):
            weight = ext.get("valueDecimal", ext.get("valueInteger"))
            if weight is not None and not isinstance(weight, bool):
                return _plain(weight)
    return None


def _plain(value: Any) -> Any:
    """A JSON value as FHIRPath sees it: floats as Decimal, whole Decimals as int."""
    if isinstance(value, float):
        value = Decimal(str(value))
    if isinstance(value, Decimal) and not value.is_finite():
        raise EvaluationError(f"the response holds {value}, not a number")
    if isinstance(value, Decimal) and value.is_finite() and value == value.to_integral_value():
        return int(value)
    return value

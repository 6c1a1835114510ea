"""What a formula computes with: FHIRPath's values, and the unknown answers a proof stands in.

A collection is a list of elements: a resource part (dict), a string, a boolean, an ``int`` or a
``Decimal``. To prove a formula for every answer at once (:mod:`.proof`), an answer may also be
an :class:`Interval` (any number in it), a :class:`Choice` (any option of an item), a
:class:`Texts` (any of some strings) or :data:`UNKNOWN` (true or false): the one evaluator then
computes what every answer could give. Pure arithmetic here; the evaluator is :mod:`.evaluation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal, DivisionByZero, InvalidOperation, localcontext
from typing import Any

from basis.errors import KioskError

#: the largest number a formula may compute with (a clinical score is far smaller)
LIMIT = Decimal(10) ** 12


class EvaluationError(KioskError, ValueError):
    """A formula that cannot give a value on these answers (message says what and where)."""


class Unprovable(EvaluationError):
    """A formula whose result for every answer the range reasoning of :mod:`.proof` cannot bound."""


@dataclass(frozen=True, slots=True)
class Interval:
    """Any number from ``low`` to ``high``; ``whole``: only whole numbers."""

    low: Decimal
    high: Decimal
    whole: bool


@dataclass(frozen=True, slots=True)
class Choice:
    """Any one option of an item, as its Coding: (system, code, points) each."""

    item: str
    options: tuple[tuple[str, str, int], ...]


@dataclass(frozen=True, slots=True)
class Texts:
    """Any one of some strings."""

    values: frozenset[str]


class _Unknown:
    def __repr__(self) -> str:
        return "UNKNOWN"


#: true or false, not known which
UNKNOWN: Any = _Unknown()

Number = int | Decimal


def is_number(value: Any) -> bool:
    return isinstance(value, (int, Decimal)) and not isinstance(value, bool)


def numeric(value: Any) -> bool:
    """A number, known or not."""
    return is_number(value) or isinstance(value, Interval)


def checked(value: Number) -> Number:
    """``value``, with whole Decimals as int; EvaluationError beyond :data:`LIMIT`."""
    if not -LIMIT <= value <= LIMIT:
        raise EvaluationError(f"a value went beyond {LIMIT:,.0f}")
    if isinstance(value, Decimal) and value == value.to_integral_value():
        return int(value)
    return value


def interval(value: Any) -> Interval:
    """A number, known or not, as an interval."""
    if isinstance(value, Interval):
        return value
    return Interval(Decimal(value), Decimal(value), isinstance(value, int))


def span(low: Decimal, high: Decimal, whole: bool) -> Number | Interval:
    """A number when ``low == high``, else the interval; EvaluationError past :data:`LIMIT`."""
    if max(abs(low), abs(high)) > LIMIT:
        raise EvaluationError(f"a value could go beyond {LIMIT:,.0f}")
    if low == high:
        return checked(int(low) if whole else low)
    return Interval(low, high, whole)


def arithmetic(op: str, a: Any, b: Any) -> Any:
    """``a op b`` for two numbers (known or not); None where FHIRPath gives empty (÷ 0)."""
    if is_number(a) and is_number(b):
        return _exact(op, a, b)
    x, y = interval(a), interval(b)
    if op in ("+", "-", "*"):
        corners = [_exact(op, p, q) for p in (x.low, x.high) for q in (y.low, y.high)]
        return span(Decimal(min(corners)), Decimal(max(corners)), x.whole and y.whole)
    if y.low <= 0 <= y.high:
        raise Unprovable(f"it may divide by zero ({op} by something from {y.low} to {y.high})")
    quotients = [_exact("/", p, q) for p in (x.low, x.high) for q in (y.low, y.high)]
    low, high = Decimal(min(quotients)), Decimal(max(quotients))
    if op == "/":
        return span(low, high, False)
    if op == "div":
        return span(Decimal(math.floor(low)), Decimal(math.ceil(high)), True)
    if x.low >= 0 and y.low > 0 and x.whole and y.whole:  # mod
        return span(Decimal(0), min(x.high, y.high - 1), True)
    raise Unprovable("'mod' of numbers not known to be whole and positive cannot be bounded")


def _exact(op: str, a: Number, b: Number) -> Any:
    with localcontext() as context:
        context.prec = 28
        try:
            if op == "+":
                result = a + b
            elif op == "-":
                result = a - b
            elif op == "*":
                result = a * b
            elif b == 0:
                return None
            elif op == "/":
                result = Decimal(a) / Decimal(b)
            elif op == "div":
                result = int(Decimal(a) / Decimal(b))
            else:
                result = Decimal(a) % Decimal(b) if isinstance(a, Decimal) or isinstance(b, Decimal) else _imod(a, b)
        except (InvalidOperation, DivisionByZero, OverflowError):
            raise EvaluationError(f"{a} {op} {b} cannot be computed") from None
    return checked(result)


def _imod(a: int, b: int) -> int:
    return int(math.fmod(a, b)) if abs(a) < 2**52 else a - b * int(Decimal(a) / Decimal(b))


def compare(op: str, a: Any, b: Any) -> Any:
    """``a op b`` (< > <= >=) for two numbers (known or not) or two strings: True, False or UNKNOWN."""
    if isinstance(a, str) and isinstance(b, str):
        return {"<": a < b, ">": a > b, "<=": a <= b, ">=": a >= b}[op]
    if not (numeric(a) and numeric(b)):
        raise EvaluationError(f"{op!r} compares two numbers or two strings, not {_kind(a)} and {_kind(b)}")
    x, y = interval(a), interval(b)
    if op in (">", ">="):
        x, y, op = y, x, "<" if op == ">" else "<="
    if (op == "<" and x.high < y.low) or (op == "<=" and x.high <= y.low):
        return True
    if (op == "<" and x.low >= y.high) or (op == "<=" and x.low > y.high):
        return False
    return UNKNOWN


def equal(a: Any, b: Any) -> Any:
    """FHIRPath ``=`` of two elements: True, False or UNKNOWN."""
    if numeric(a) and numeric(b):
        if is_number(a) and is_number(b):
            return a == b
        x, y = interval(a), interval(b)
        return False if x.high < y.low or y.high < x.low else UNKNOWN
    if isinstance(a, Texts) or isinstance(b, Texts):
        left = a.values if isinstance(a, Texts) else {a}
        right = b.values if isinstance(b, Texts) else {b}
        if not left & right:
            return False
        return True if len(left) == len(right) == 1 else UNKNOWN
    if isinstance(a, Choice) or isinstance(b, Choice) or a is UNKNOWN or b is UNKNOWN:
        return a == b if isinstance(a, Choice) and isinstance(b, Choice) and len(a.options) == 1 else UNKNOWN
    if isinstance(a, bool) != isinstance(b, bool):
        return False
    return bool(a == b)


def rounded(name: str, value: Any, places: int = 0) -> Any:
    """round/floor/ceiling/truncate/abs of a number (known or not)."""
    if isinstance(value, Interval):
        if name == "abs":
            low = Decimal(0) if value.low <= 0 <= value.high else min(abs(value.low), abs(value.high))
            return span(low, max(abs(value.low), abs(value.high)), value.whole)
        low, high = rounded(name, value.low, places), rounded(name, value.high, places)
        return span(Decimal(low), Decimal(high), name != "round" or places == 0)
    if not is_number(value):
        raise EvaluationError(f"{name}() takes a number, not {_kind(value)}")
    number = Decimal(value)
    if name == "abs":
        return checked(abs(value))
    if name == "round":
        return checked(number.quantize(Decimal(1).scaleb(-places), rounding=ROUND_HALF_UP))
    if name == "floor":
        return checked(math.floor(number))
    return checked(math.ceil(number) if name == "ceiling" else math.trunc(number))


def join(a: Any, b: Any) -> Any:
    """What is either ``a`` or ``b`` (the branches of an ``iif`` whose condition is not known)."""
    if a == b and type(a) is type(b):
        return a
    if numeric(a) and numeric(b):
        x, y = interval(a), interval(b)
        return span(min(x.low, y.low), max(x.high, y.high), x.whole and y.whole)
    if isinstance(a, (bool, _Unknown)) and isinstance(b, (bool, _Unknown)):
        return UNKNOWN
    if isinstance(a, (str, Texts)) and isinstance(b, (str, Texts)):
        left = a.values if isinstance(a, Texts) else {a}
        right = b.values if isinstance(b, Texts) else {b}
        return Texts(frozenset(left | right))
    raise Unprovable(f"its branches give {_kind(a)} or {_kind(b)} depending on the answers")


def _kind(value: Any) -> str:
    if isinstance(value, bool) or value is UNKNOWN:
        return "true or false"
    if numeric(value):
        return "a number"
    if isinstance(value, (str, Texts)):
        return "a text"
    if isinstance(value, Choice):
        return "an answer's coding"
    return "a part of the response"


describe_kind = _kind

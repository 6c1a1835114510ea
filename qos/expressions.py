"""Evaluating checked value expressions against the current values.

A value is undefined (None) until its context is first set; an expression reading an undefined value
is undefined, except ``true | undefined`` (true) and ``false & undefined`` (false). Arithmetic that has
no real result (division by zero, ``sqrt`` of a negative, overflow) is undefined too, and so is
``at(i)`` outside the array (``at`` counts from 1, as OCL does).
"""

from __future__ import annotations

import dataclasses
import math
import operator
from collections.abc import Callable, Iterator, Mapping
from typing import Any, cast

from qos.model import Binary, Call, Conditional, Expr, Literal, Unary, Var

#: a compiled expression: values -> value, or None when undefined
Evaluator = Callable[[Mapping[str, object]], object]


def _divide(left: float, right: float) -> float | None:
    return None if right == 0 else left / right


#: the operands are numbers or booleans as the checker typed them
_BINARY: dict[str, Callable[[Any, Any], Any]] = {
    "=": operator.eq,
    "!=": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "/": _divide,
}


def _at(array: tuple, index: float) -> object:
    return array[int(index) - 1] if float(index).is_integer() and 1 <= index <= len(array) else None


_FUNCTIONS: dict[str, Callable[..., object]] = {
    "pow": lambda x, y: x**y,
    "sqrt": lambda x: math.sqrt(x) if x >= 0 else None,
    "exp": math.exp,
    "abs": abs,
    "size": lambda a: float(len(a)),
    "isEmpty": lambda a: len(a) == 0,
    "first": lambda a: a[0] if a else None,
    "last": lambda a: a[-1] if a else None,
    "at": _at,
    "includes": lambda a, v: v in a,
}


def _real(value: object) -> object:
    """None for results that are not real numbers (complex powers, infinities, NaN)."""
    if isinstance(value, complex) or (isinstance(value, float) and not math.isfinite(value)):
        return None
    return float(value) if isinstance(value, int) and not isinstance(value, bool) else value


def compile_expr(expr: Expr) -> Evaluator:
    """Turn a checked expression into a function of the values."""
    if isinstance(expr, Var):
        name = expr.name
        return lambda values: values.get(name)
    if isinstance(expr, Literal):
        value = expr.value
        return lambda values: value
    if isinstance(expr, Unary):
        inner = compile_expr(expr.operand)
        if expr.op == "!":
            return lambda values: None if (x := inner(values)) is None else not x
        return lambda values: None if (x := inner(values)) is None else -cast(float, x)  # typed a number
    if isinstance(expr, Conditional):
        condition, then, otherwise = (compile_expr(part) for part in (expr.condition, expr.then, expr.otherwise))

        def choose(values):
            decided = condition(values)
            return None if decided is None else (then(values) if decided else otherwise(values))

        return choose
    if isinstance(expr, Call):
        function, args = _FUNCTIONS[expr.function], [compile_expr(arg) for arg in expr.args]

        def call(values):
            given = [arg(values) for arg in args]
            if any(value is None for value in given):
                return None
            try:
                return _real(function(*given))
            except (OverflowError, ZeroDivisionError, ValueError):
                return None

        return call
    assert isinstance(expr, Binary)
    left, right = compile_expr(expr.left), compile_expr(expr.right)
    if expr.op in ("&", "|"):
        want = expr.op == "|"  # the value that decides the result on its own

        def logic(values):
            a, b = left(values), right(values)
            if a is want or b is want:
                return want
            return None if a is None or b is None else not want

        return logic
    function = _BINARY[expr.op]

    def binary(values):
        a, b = left(values), right(values)
        if a is None or b is None:
            return None
        return _real(function(a, b))

    return binary


def names_in(node: object) -> Iterator[str]:
    """Every name a checked node (expression, pattern, action…) reads, nested nodes included."""
    if isinstance(node, Var):
        yield node.name
    elif dataclasses.is_dataclass(node) and not isinstance(node, type):
        for item in dataclasses.fields(node):
            yield from names_in(getattr(node, item.name))
    elif isinstance(node, (tuple, list, dict)):
        for item in node.values() if isinstance(node, dict) else node:
            yield from names_in(item)


def variables_of(expr: Expr) -> frozenset[str]:
    """The names an expression reads."""
    return frozenset(names_in(expr))

"""The pattern matcher: decides, batch by batch, which observations fire.

Semantics (what a model author can rely on)
===========================================

The engine receives context updates in *batches*: every call of ``Engine.update(t, set=…, emit=…)``
is one batch (a trace groups its events with the same ``t`` into one batch). A batch is applied as a
whole, then every observation's pattern is evaluated once against the state after the batch. An
observation fires at most once per batch.

Values. A context has no value until it is first set; an expression mentioning a context without a
value is *undefined*, and an undefined expression is never true and never "changes to" anything
(division by zero is undefined too). Eventtype contexts have no value at all: they only *occur*.

Occurrences (the atoms of a pattern):

``update(X)`` (X a context)
    occurs in every batch that sets X, even to the value it already had, or emits X (eventtype).
``update(expr)`` (any other expression)
    occurs in a batch when the expression's value differs from its value after the previous batch
    (becoming defined counts as a change; becoming undefined does not occur).
``eventWhen(X)`` (X a boolean context)
    ``update(X)`` and X is true after the batch: occurs on every update of X to true.
``eventWhen(expr)``
    ``update(expr)`` and the new value is true: occurs when the expression *becomes* true.
a bare context ``X``
    ``eventWhen(X)`` for a boolean context, ``update(X)`` for any other type (eventtype: X is emitted).
a bare boolean expression ``e`` (``TestState = TestState::PAUSED``, ``!PersonDetected``)
    ``eventWhen(e)``.

Pattern operators. Every observation's pattern re-arms after it fires (it is implicitly "every"):
all partial progress (``and``, ``->``, ``repeat``) is cleared and matching starts again from the
next batch. Precedence, loosest first: ``->``, ``or``, ``and``, ``once``, postfix ``while``/``repeat``.

``a or b``
    occurs in a batch in which ``a`` or ``b`` occurs (both keep being evaluated).
``a and b``
    occurs once both ``a`` and ``b`` have occurred since the pattern was (re-)armed, in any order,
    possibly in the same batch.
``a -> b`` (followed-by)
    occurs when ``b`` occurs in a batch *after* the batch in which ``a`` occurred; ``b`` is only
    evaluated from the batch after ``a`` (so ``a -> b`` never occurs on a single batch).
``p while(cond)``
    occurs when ``p`` occurs in a batch after which ``cond`` is true; in a batch after which ``cond``
    is false (or undefined) the partial progress of ``p`` is cleared, as the guard ends it.
    ``update(X) while(!X)`` is the idiom for "X updated to false" (every update, even if unchanged).
``p repeat(n)``
    occurs when ``p`` has occurred in ``n`` batches since (re-)arming; the count then restarts.
``once p``
    occurs the first time ``p`` occurs and never again for the life of the engine (re-arming of an
    enclosing pattern does not revive it).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from qos.model import (
    AllOf, AnyOf, Binary, Changed, Expr, FollowedBy, Literal, Observation, Once, Pattern, Repeat, Unary,
    Updated, Var, While,
)

#: a compiled expression: context values -> value, or None when undefined
Evaluator = Callable[[Mapping[str, object]], object]


@dataclass(frozen=True)
class Batch:
    """What the matcher sees of one batch: values after it, and which contexts it set or emitted."""

    values: Mapping[str, object]
    updated: frozenset[str]


def _divide(left: float, right: float) -> float | None:
    return None if right == 0 else left / right


_BINARY: dict[str, Callable[[object, object], object]] = {
    "=": operator.eq, "!=": operator.ne, "<": operator.lt, "<=": operator.le, ">": operator.gt,
    ">=": operator.ge, "+": operator.add, "-": operator.sub, "*": operator.mul, "/": _divide,
}


def compile_expr(expr: Expr) -> Evaluator:
    """Turn a checked expression into a function of the context values."""
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
        return lambda values: None if (x := inner(values)) is None else -x
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
        result = function(a, b)
        return None if isinstance(result, float) and not math.isfinite(result) else result
    return binary


def variables_of(expr: Expr) -> frozenset[str]:
    """The contexts an expression reads."""
    if isinstance(expr, Var):
        return frozenset({expr.name})
    if isinstance(expr, Literal):
        return frozenset()
    if isinstance(expr, Unary):
        return variables_of(expr.operand)
    return variables_of(expr.left) | variables_of(expr.right)


class _Matcher:
    """One node of a pattern at run time."""

    def step(self, batch: Batch) -> bool:
        """Advance by one batch; True when the node occurs in it."""
        raise NotImplementedError

    def reset(self) -> None:
        """Clear partial progress (the enclosing pattern fired or a guard ended it)."""


class _UpdatedMatcher(_Matcher):
    def __init__(self, node: Updated):
        self.name, self.when_true = node.name, node.when_true

    def step(self, batch: Batch) -> bool:
        return self.name in batch.updated and (not self.when_true or batch.values.get(self.name) is True)


class _ChangedMatcher(_Matcher):
    """Tracks an expression's value; observed on every batch, even when its node is not stepped."""

    def __init__(self, node: Changed):
        self.evaluate = compile_expr(node.expr)
        self.reads = variables_of(node.expr)
        self.when_true = node.when_true
        self.last: object = None
        self.occurred = False

    def observe(self, batch: Batch) -> None:
        if self.reads.isdisjoint(batch.updated):
            self.occurred = False
            return
        value = self.evaluate(batch.values)
        self.occurred = value is not None and value != self.last and (not self.when_true or value is True)
        self.last = value

    def step(self, batch: Batch) -> bool:
        return self.occurred


class _AnyOfMatcher(_Matcher):
    def __init__(self, left: _Matcher, right: _Matcher):
        self.left, self.right = left, right

    def step(self, batch: Batch) -> bool:
        left, right = self.left.step(batch), self.right.step(batch)
        if left or right:
            self.reset()
            return True
        return False

    def reset(self) -> None:
        self.left.reset()
        self.right.reset()


class _AllOfMatcher(_Matcher):
    def __init__(self, left: _Matcher, right: _Matcher):
        self.left, self.right = left, right
        self.seen_left = self.seen_right = False

    def step(self, batch: Batch) -> bool:
        self.seen_left = self.seen_left or self.left.step(batch)
        self.seen_right = self.seen_right or self.right.step(batch)
        if self.seen_left and self.seen_right:
            self.reset()
            return True
        return False

    def reset(self) -> None:
        self.seen_left = self.seen_right = False
        self.left.reset()
        self.right.reset()


class _FollowedByMatcher(_Matcher):
    def __init__(self, first: _Matcher, then: _Matcher):
        self.first, self.then = first, then
        self.armed = False

    def step(self, batch: Batch) -> bool:
        if not self.armed:
            self.armed = self.first.step(batch)
            return False
        if self.then.step(batch):
            self.reset()
            return True
        return False

    def reset(self) -> None:
        self.armed = False
        self.first.reset()
        self.then.reset()


class _OnceMatcher(_Matcher):
    def __init__(self, inner: _Matcher):
        self.inner = inner
        self.done = False

    def step(self, batch: Batch) -> bool:
        if self.done:
            return False
        self.done = self.inner.step(batch)
        return self.done

    def reset(self) -> None:
        self.inner.reset()  # `done` survives: once means once per engine


class _WhileMatcher(_Matcher):
    def __init__(self, inner: _Matcher, condition: Evaluator):
        self.inner, self.condition = inner, condition

    def step(self, batch: Batch) -> bool:
        if self.condition(batch.values) is not True:
            self.inner.reset()
            return False
        return self.inner.step(batch)

    def reset(self) -> None:
        self.inner.reset()


class _RepeatMatcher(_Matcher):
    def __init__(self, inner: _Matcher, times: int):
        self.inner, self.times = inner, times
        self.count = 0

    def step(self, batch: Batch) -> bool:
        if self.inner.step(batch):
            self.count += 1
            if self.count == self.times:
                self.reset()
                return True
        return False

    def reset(self) -> None:
        self.count = 0
        self.inner.reset()


class ObservationMatcher:
    """The run-time state of every observation of a model (one per engine)."""

    def __init__(self, observations: Mapping[str, Observation]):
        self._changed: list[_ChangedMatcher] = []
        self._roots = [(name, self._build(observation.pattern)) for name, observation in observations.items()]

    def _build(self, node: Pattern) -> _Matcher:
        if isinstance(node, Updated):
            return _UpdatedMatcher(node)
        if isinstance(node, Changed):
            matcher = _ChangedMatcher(node)
            self._changed.append(matcher)
            return matcher
        if isinstance(node, AnyOf):
            return _AnyOfMatcher(self._build(node.left), self._build(node.right))
        if isinstance(node, AllOf):
            return _AllOfMatcher(self._build(node.left), self._build(node.right))
        if isinstance(node, FollowedBy):
            return _FollowedByMatcher(self._build(node.first), self._build(node.then))
        if isinstance(node, Once):
            return _OnceMatcher(self._build(node.pattern))
        if isinstance(node, While):
            return _WhileMatcher(self._build(node.pattern), compile_expr(node.condition))
        assert isinstance(node, Repeat)
        return _RepeatMatcher(self._build(node.pattern), node.times)

    def step(self, batch: Batch) -> list[str]:
        """Evaluate every observation on one batch; return the names that fired, in model order."""
        for changed in self._changed:  # value tracking must see every batch
            changed.observe(batch)
        return [name for name, root in self._roots if root.step(batch)]

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
an enum literal ``X::LIT``
    every update of the context X to LIT (RoQME's enum filter), even when X already was LIT.

Pattern operators. Every observation's pattern re-arms after it fires (it is implicitly "every"):
all partial progress (``and``, ``->``, ``repeat``) is cleared and matching starts again from the
next batch. Precedence is RoQME's (see :mod:`qos.grammar`), loosest first: ``once``, postfix
``while``/``repeat``/``range`` (applied to everything before them: ``a -> b while(c)`` is
``(a -> b) while(c)``), ``->``, ``or``, ``and``.

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
``a and not b``
    occurs when ``a`` occurs while ``b`` has not occurred since the pattern was (re-)armed (``b`` in the
    same batch as ``a`` prevents it). An occurrence of ``b`` makes the attempt fail: as Esper's
    ``every`` does, the whole observation's pattern then starts again (so in ``x -> (a and not b)`` a
    ``b`` after ``x`` means waiting for a new ``x``). ``not b`` alone never occurs and is refused.
``p range(a, b)``
    occurs on the a-th, (a+1)-th … b-th occurrence of ``p`` counted over the engine's life (the count
    is not cleared by re-arming, as the generator's unbounded ``count(*)`` is not): a way to say "the
    second and third time".
a timer ``T``
    occurs in the batch in which it fires (see :mod:`qos.timers`).
"""

from __future__ import annotations

from collections.abc import Mapping

from basis import record
from qos.expressions import Evaluator, compile_expr, variables_of
from qos.model import (
    AllOf,
    AndNot,
    AnyOf,
    Changed,
    FollowedBy,
    Observation,
    Once,
    Pattern,
    Range,
    Repeat,
    Updated,
    While,
)


@record
class Batch:
    """What the matcher sees of one batch: values after it, and which names it updated (contexts set
    or emitted, derived contexts and aggregates recomputed, timers fired)."""

    values: Mapping[str, object]
    updated: frozenset[str] | set[str]


class _Matcher:
    """One node of a pattern at run time."""

    #: set by ``step`` when the node can no longer occur until it is reset (an ``and not`` failed)
    failed = False

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
        self.failed = self.left.failed and self.right.failed
        return False

    def reset(self) -> None:
        self.failed = False
        self.left.reset()
        self.right.reset()


class _AllOfMatcher(_Matcher):
    def __init__(self, left: _Matcher, right: _Matcher):
        self.left, self.right = left, right
        self.seen_left = self.seen_right = False

    def step(self, batch: Batch) -> bool:
        self.seen_left = self.seen_left or self.left.step(batch)
        self.seen_right = self.seen_right or self.right.step(batch)
        if self.left.failed or self.right.failed:
            self.reset()
            self.failed = True
            return False
        if self.seen_left and self.seen_right:
            self.reset()
            return True
        return False

    def reset(self) -> None:
        self.failed = False
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
            self.failed = self.first.failed
            return False
        if self.then.step(batch):
            self.reset()
            return True
        if self.then.failed:
            self.reset()
            self.failed = True
        return False

    def reset(self) -> None:
        self.failed = False
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
        if self.inner.failed:
            self.inner.reset()
        return self.done

    def reset(self) -> None:
        self.inner.reset()  # `done` survives: once means once per engine


class _WhileMatcher(_Matcher):
    def __init__(self, inner: _Matcher, condition: Evaluator):
        self.inner, self.condition = inner, condition

    def step(self, batch: Batch) -> bool:
        if self.condition(batch.values) is not True:
            self.inner.reset()
            self.failed = False
            return False
        occurred = self.inner.step(batch)
        self.failed = self.inner.failed
        return occurred

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
        if self.inner.failed:
            self.reset()
            self.failed = True
        return False

    def reset(self) -> None:
        self.failed = False
        self.count = 0
        self.inner.reset()


class _AndNotMatcher(_Matcher):
    def __init__(self, wanted: _Matcher, excluded: _Matcher):
        self.wanted, self.excluded = wanted, excluded

    def step(self, batch: Batch) -> bool:
        wanted, excluded = self.wanted.step(batch), self.excluded.step(batch)
        if excluded:
            self.reset()
            self.failed = True
            return False
        if wanted:
            self.reset()
            return True
        self.failed = self.wanted.failed
        return False

    def reset(self) -> None:
        self.failed = False
        self.wanted.reset()
        self.excluded.reset()


class _RangeMatcher(_Matcher):
    def __init__(self, inner: _Matcher, low: int, high: int):
        self.inner, self.low, self.high = inner, low, high
        #: occurrences over the engine's life: re-arming does not clear it
        self.count = 0

    def step(self, batch: Batch) -> bool:
        if self.inner.step(batch):
            self.count += 1
            return self.low <= self.count <= self.high
        if self.inner.failed:
            self.inner.reset()
        return False

    def reset(self) -> None:
        self.inner.reset()


class PatternRunner:
    """One pattern at run time: steps it batch by batch and re-arms it after it occurs or fails."""

    def __init__(self, pattern: Pattern):
        self._changed: list[_ChangedMatcher] = []
        self._root = self._build(pattern)

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
        if isinstance(node, AndNot):
            return _AndNotMatcher(self._build(node.pattern), self._build(node.excluded))
        if isinstance(node, FollowedBy):
            return _FollowedByMatcher(self._build(node.first), self._build(node.then))
        if isinstance(node, Once):
            return _OnceMatcher(self._build(node.pattern))
        if isinstance(node, While):
            return _WhileMatcher(self._build(node.pattern), compile_expr(node.condition))
        if isinstance(node, Range):
            return _RangeMatcher(self._build(node.pattern), node.low, node.high)
        assert isinstance(node, Repeat)
        return _RepeatMatcher(self._build(node.pattern), node.times)

    def step(self, batch: Batch) -> bool:
        """True when the pattern occurs in this batch."""
        for changed in self._changed:  # value tracking must see every batch
            changed.observe(batch)
        occurred = self._root.step(batch)
        if self._root.failed:
            self._root.reset()  # Esper's `every` starts a failed attempt again
        return occurred


class ObservationMatcher:
    """The run-time state of every observation of a model (one per engine)."""

    def __init__(self, observations: Mapping[str, Observation]):
        self._runners = [(name, PatternRunner(observation.pattern)) for name, observation in observations.items()]

    def step(self, batch: Batch) -> list[str]:
        """Evaluate every observation on one batch; return the names that fired, in model order."""
        return [name for name, runner in self._runners if runner.step(batch)]

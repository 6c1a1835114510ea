"""Computed values the engine keeps up to date batch by batch, with the RoQME generator's meaning.

Every stream has a name (a derived context's, a variable's, or ``#n`` for an aggregate or ``period``
lifted out of an expression). In each batch the streams run in model order, after the batch's
contexts are applied and before observations are evaluated; a stream that produces a value writes it
and counts as *updated* in that batch, so ``update(X)``, a bare ``X`` and other streams see it.

Derived context ``X := value`` (Esper: insert into X from the inputs' last events)
    recomputed in every batch that updates something it reads; updated when the result is defined.
Derived eventtype ``X := pattern``
    occurs in the batches in which the pattern occurs.
Variable ``var v := value``
    recomputed like a derived context but never "updated": variables are read, they do not occur.
Aggregate ``X'f(w)`` / ``f(X, w, where)`` over the updates of X (after which ``where`` is true):
    no window: every update so far (running values, constant memory);
    ``f(X, n)`` (Esper ``length(n)``): the last n updates, recomputed at each update of X (with fewer
    than n so far, over those: ``count`` tells how many);
    ``f(X, 5 minutes)`` (Esper ``time_batch``): updates are gathered in consecutive 5-minute batches
    starting at the first one; at the end of each batch the value is produced (at that instant, even
    if nothing else happens); a batch without updates produces nothing and the next batch starts at the
    next update.
    ``avg min max sum`` need numbers, ``count`` counts updates of any context (eventtype
    occurrences too). ``increasing`` / ``decreasing`` / ``stable`` look at *steps*, pairs of
    consecutive updates (the generator's ``every a=X -> b=X`` window): true when every step in the
    window goes up / down / stays; ``increasing(X, 2)`` covers the last 2 steps, i.e. 3 updates; a
    time batch holds the steps that end in it. Undefined before the first step.
``period(X)``
    at an update of X whose value differs from the previous update's (every occurrence of an
    eventtype), the seconds since that previous update.
``period(a -> b)``
    at each ``b`` in a batch after an ``a``, the seconds since the latest ``a``.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import MutableMapping
from typing import cast

from qos.expressions import compile_expr, variables_of
from qos.model import EVENTTYPE, Aggregate, Context, Model, Period, Stream, Variable
from qos.patterns import Batch, PatternRunner

TRENDS = ("increasing", "decreasing", "stable")


class _Accumulator:
    """Running values of one aggregate window, in constant memory."""

    __slots__ = ("count", "total", "low", "high", "last", "steps", "rising", "falling", "flat")

    def __init__(self, last: float | None = None):
        self.count, self.total, self.steps = 0, 0.0, 0
        self.low: float | None = None
        self.high: float | None = None
        #: the update before this window's first (its first step starts there)
        self.last = last
        self.rising = self.falling = self.flat = True

    def add(self, value: object) -> None:
        self.count += 1
        if not isinstance(value, float):
            return  # count only
        self.total += value
        self.low = value if self.low is None else min(self.low, value)
        self.high = value if self.high is None else max(self.high, value)
        if self.last is not None:
            self.steps += 1
            self.rising &= value > self.last
            self.falling &= value < self.last
            self.flat &= value == self.last
        self.last = value

    def value(self, function: str) -> object:
        if function == "count":
            return float(self.count)
        if self.count == 0:
            return None
        if function in TRENDS:
            if self.steps == 0:
                return None
            return {"increasing": self.rising, "decreasing": self.falling, "stable": self.flat}[function]
        result = {"avg": self.total / self.count, "sum": self.total, "min": self.low, "max": self.high}[function]
        return result if result is None or math.isfinite(result) else None


class StreamRunner:
    """One stream at run time."""

    def __init__(self, name: str):
        self.name = name

    def step(self, t: float, values: MutableMapping[str, object], updated: set[str]) -> None:
        """Run in one batch at time t: maybe produce a value (write it, mark the name updated)."""
        raise NotImplementedError

    def due(self) -> float | None:
        """The time at which this stream must run even without input (a time window's end)."""
        return None

    def _produce(self, value: object, values: MutableMapping[str, object], updated: set[str]) -> None:
        if value is not None:
            values[self.name] = value
            updated.add(self.name)


class _DerivedValue(StreamRunner):
    def __init__(self, name: str, definition, counts: bool):
        super().__init__(name)
        self.evaluate, self.reads, self.counts = compile_expr(definition), variables_of(definition), counts

    def initial(self, values: MutableMapping[str, object]) -> None:
        """A first value from whatever is known when the engine starts (parameters, constants)."""
        value = self.evaluate(values)
        if value is not None:
            values[self.name] = value

    def step(self, t, values, updated) -> None:
        if self.reads.isdisjoint(updated):
            return
        value = self.evaluate(values)
        if value is None:
            return
        values[self.name] = value
        if self.counts:
            updated.add(self.name)


class _DerivedEvent(StreamRunner):
    def __init__(self, name: str, pattern):
        super().__init__(name)
        self.runner = PatternRunner(pattern)

    def step(self, t, values, updated) -> None:
        if self.runner.step(Batch(values, updated)):
            updated.add(self.name)


class _Aggregate(StreamRunner):
    def __init__(self, name: str, aggregate: Aggregate, eventtype: bool):
        super().__init__(name)
        self.function, self.source, self.window = aggregate.function, aggregate.source, aggregate.window
        self.where = compile_expr(aggregate.where) if aggregate.where is not None else None
        self.eventtype = eventtype
        self.running = _Accumulator()
        #: length window: the last n samples
        trend = self.function in TRENDS
        self.recent: deque = deque(maxlen=self.window + trend if isinstance(self.window, int) else None)
        #: time window: end of the current batch (None: waiting for an update to start one)
        self.end: float | None = None

    def due(self) -> float | None:
        return self.end

    def step(self, t, values, updated) -> None:
        if self.end is not None and t >= self.end:  # a time batch is over
            if self.running.count:
                self._produce(self.running.value(self.function), values, updated)
                self.end += cast(float, self.window)  # a time window
            else:
                self.end = None
            self.running = _Accumulator(self.running.last)
        if self.source not in updated or (self.where is not None and self.where(values) is not True):
            return
        sample = True if self.eventtype else values.get(self.source)
        if sample is None:
            return
        if isinstance(self.window, float):
            if self.end is None:
                self.end = t + self.window
            self.running.add(sample)
            return
        if isinstance(self.window, int):
            self.recent.append(sample)
            self.running = _Accumulator()
            for kept in self.recent:
                self.running.add(kept)
        else:
            self.running.add(sample)
        self._produce(self.running.value(self.function), values, updated)


class _PeriodOfContext(StreamRunner):
    def __init__(self, name: str, source: str, eventtype: bool):
        super().__init__(name)
        self.source, self.eventtype = source, eventtype
        self.last_t: float | None = None
        self.last_value: object = None

    def step(self, t, values, updated) -> None:
        if self.source not in updated:
            return
        value = values.get(self.source)
        if self.last_t is not None and (self.eventtype or value != self.last_value):
            self._produce(t - self.last_t, values, updated)
        self.last_t, self.last_value = t, value


class _PeriodOfSequence(StreamRunner):
    def __init__(self, name: str, period: Period):
        super().__init__(name)
        assert period.first is not None and period.then is not None  # a period of a sequence has both
        self.first, self.then = PatternRunner(period.first), PatternRunner(period.then)
        self.since: float | None = None

    def step(self, t, values, updated) -> None:
        batch = Batch(values, updated)
        then, first = self.then.step(batch), self.first.step(batch)
        if then and self.since is not None:
            self._produce(t - self.since, values, updated)
            self.since = None
        if first:
            self.since = t


def build_streams(model: Model, values: MutableMapping[str, object]) -> list[StreamRunner]:
    """The run-time streams of a model, in model order; values get what is known at the start."""
    runners: list[StreamRunner] = []
    for name, stream in model.streams:
        runner = _runner(model, name, stream)
        if isinstance(runner, _DerivedValue):
            runner.initial(values)
        runners.append(runner)
    return runners


def _is_event(model: Model, name: str) -> bool:
    context = model.contexts.get(name)
    return context is not None and context.type == EVENTTYPE


def _runner(model: Model, name: str, stream: Stream) -> StreamRunner:
    if isinstance(stream, Variable):
        return _DerivedValue(name, stream.definition, counts=False)
    if isinstance(stream, Context):
        if stream.type == EVENTTYPE:
            return _DerivedEvent(name, stream.definition)
        return _DerivedValue(name, stream.definition, counts=True)
    if isinstance(stream, Aggregate):
        return _Aggregate(name, stream, _is_event(model, stream.source))
    if stream.source is not None:
        return _PeriodOfContext(name, stream.source, _is_event(model, stream.source))
    return _PeriodOfSequence(name, stream)

"""The engine: applies batches of context updates, fires observations, publishes metrics."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from qos.errors import ContextError
from qos.model import BOOLEAN, EVENTTYPE, NUMBER, Model
from qos.patterns import Batch, ObservationMatcher
from qos.reasoner import PropertyBelief


@dataclass(frozen=True)
class UpdateResult:
    """What one batch did: the metrics after it and the observations it fired."""

    t: float
    #: property name -> metric in [0, 1] after this batch
    metrics: dict[str, float]
    #: observations fired in this batch, sorted by number (O2 before O10)
    fired: list[str]
    #: the contexts the batch set (enum values as literal names) and the eventtypes it emitted
    set: dict[str, object] = field(default_factory=dict)
    emit: list[str] = field(default_factory=list)


def observation_sort_key(name: str) -> tuple:
    """Natural order of observation names: O2 before O10, then by text."""
    digits = "".join(ch for ch in name if ch.isdigit())
    return (name.rstrip("0123456789"), int(digits) if digits else -1, name)


def _describe(value: object) -> str:
    return f"{value!r} ({type(value).__name__})"


def check_time(t: object) -> float:
    """A batch time as a float; ContextError unless it is a finite real number."""
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        raise ContextError(f"time must be a finite number of seconds, not {_describe(t)}")
    return float(t)


def check_batch(model: Model, set: Mapping[str, object] | None,
                emit: Iterable[str] | None) -> tuple[dict[str, object], list[str]]:
    """Validate a batch against the model without applying it.

    Returns the values to set (booleans, floats, enum literal names) and the eventtypes to emit;
    raises :class:`ContextError` naming the context and the problem.
    """
    values: dict[str, object] = {}
    if set is None:
        set = {}
    if not isinstance(set, Mapping):
        raise ContextError(f"'set' must map context names to values, not {_describe(set)}")
    for name, value in set.items():
        context = model.contexts.get(name) if isinstance(name, str) else None
        if context is None:
            raise ContextError(f"context {name!r} is not in model {model.name}")
        if context.kind == EVENTTYPE:
            raise ContextError(f"context {name} is an eventtype: emit it, do not set it")
        if context.kind == BOOLEAN:
            if not isinstance(value, bool):
                raise ContextError(f"context {name} is boolean, got {_describe(value)}")
        elif context.kind == NUMBER:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ContextError(f"context {name} is a number, got {_describe(value)}")
            value = float(value)
        else:
            literal = value
            if isinstance(value, str) and "::" in value:
                type_name, _, literal = value.partition("::")
                if type_name not in (context.type.name, name):
                    raise ContextError(f"context {name} is of type {context.type.name}, got {value!r}")
            if not isinstance(literal, str):
                raise ContextError(f"context {name} is an enum of {', '.join(context.literals)}; "
                                   f"got {_describe(value)}")
            if literal not in context.literals:
                raise ContextError(f"context {name} has no literal {literal!r} (expected one of "
                                   f"{', '.join(context.literals)})")
            value = literal
        values[name] = value
    if emit is None:
        emit = []
    if isinstance(emit, (str, bytes)) or not isinstance(emit, Iterable):
        raise ContextError(f"'emit' must be a list of eventtype names, not {_describe(emit)}")
    emitted: list[str] = []
    for name in emit:
        context = model.contexts.get(name) if isinstance(name, str) else None
        if context is None:
            raise ContextError(f"context {name!r} is not in model {model.name}")
        if context.kind != EVENTTYPE:
            raise ContextError(f"context {name} is {context.kind}, not an eventtype: set it, do not emit it")
        if name not in emitted:
            emitted.append(name)
    return values, emitted


Subscriber = Callable[[UpdateResult], object]


class Engine:
    """Runs one model: feed it batches of context updates with ``update``, read ``metrics``.

    Each ``update`` call is one batch (see :mod:`qos.patterns` for what that means for patterns).
    Times are seconds on any clock the caller likes, but must never go backwards.
    """

    def __init__(self, model: Model):
        self.model = model
        self._beliefs = {name: PropertyBelief(prop) for name, prop in model.properties.items()}
        self._matcher = ObservationMatcher(model.observations)
        self._values: dict[str, object] = {}
        self._t: float | None = None
        self._subscribers: list[Subscriber] = []

    @property
    def t(self) -> float | None:
        """Time of the last batch (None before the first)."""
        return self._t

    @property
    def contexts(self) -> dict[str, object]:
        """Current context values (contexts never set are absent)."""
        return dict(self._values)

    @property
    def live_firings(self) -> dict[str, int]:
        """Per property, how many firings the reasoner still keeps on their own (a bounded number)."""
        return {name: belief.live_firings for name, belief in self._beliefs.items()}

    def update(self, t: float, set: Mapping[str, object] | None = None,
               emit: Iterable[str] | None = None) -> UpdateResult:
        """Apply one batch at time t and return the metrics and fired observations.

        The whole batch is validated first: on a :class:`ContextError` nothing has changed.
        Subscribers are called with the result, in subscription order, after the batch is applied.
        """
        t = check_time(t)
        if self._t is not None and t < self._t:
            raise ContextError(f"time {t:g} s is before the previous update at {self._t:g} s")
        values, emitted = check_batch(self.model, set, emit)
        self._t = t
        self._values.update(values)
        batch = Batch(self._values, frozenset(values) | frozenset(emitted))
        fired = sorted(self._matcher.step(batch), key=observation_sort_key)
        for name in fired:
            observation = self.model.observations[name]
            self._beliefs[observation.property].add(t, observation.likelihood_ratio)
        result = UpdateResult(t, self._metrics_at(t), fired, values, emitted)
        for callback in list(self._subscribers):
            callback(result)
        return result

    def metrics(self, t: float | None = None) -> dict[str, float]:
        """Every property's metric at time t (default: the last update), with decay applied."""
        if t is None:
            t = self._t if self._t is not None else 0.0
        t = check_time(t)
        if self._t is not None and t < self._t:
            raise ContextError(f"time {t:g} s is before the last update at {self._t:g} s")
        return self._metrics_at(t)

    def _metrics_at(self, t: float) -> dict[str, float]:
        return {name: belief.metric(t) for name, belief in self._beliefs.items()}

    def subscribe(self, callback: Subscriber) -> Callable[[], None]:
        """Call ``callback(result)`` after every update; returns a function that unsubscribes."""
        self._subscribers.append(callback)

        def unsubscribe() -> None:
            if callback in self._subscribers:
                self._subscribers.remove(callback)
        return unsubscribe

"""The engine: applies batches of context updates, runs streams and timers, fires observations,
applies their actions and publishes metrics.

Time is whatever the caller gives: ``update(t, …)`` and ``advance(t)``. Nothing reads the wall clock,
so replays are deterministic and run as fast as the machine allows. A timer or a time window due
between two updates runs at its due time, as a batch of its own, before the later update; one due at
exactly the update's time joins that update's batch. A caller with nothing to report calls
``advance(now)`` now and then (the kiosk session does on its poll) so that timers fire on time.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import field

from basis import record
from qos.batches import check_batch, check_time, check_value
from qos.errors import ContextError
from qos.expressions import compile_expr, names_in
from qos.model import SELF_BELIEF, ClearEvidence, Evidence, Model, SetVariable, TimerAction
from qos.patterns import Batch, ObservationMatcher
from qos.reasoner import PropertyBelief
from qos.streams import build_streams
from qos.timers import TimerClock

__all__ = ["Engine", "UpdateResult", "check_batch", "check_time", "check_value", "observation_sort_key"]


@record
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
    #: timers that fired in this batch (a batch the engine ran on its own has only these)
    timers: list[str] = field(default_factory=list)
    #: property name -> its output transformation's value (properties declared ``property P : T := …``)
    outputs: dict[str, object] = field(default_factory=dict)
    #: beliefvar name -> its probability after this batch
    beliefs: dict[str, float] = field(default_factory=dict)

    @property
    def timed(self) -> bool:
        """True for a batch the engine ran on its own (timers, time windows): nothing was set or emitted."""
        return not self.set and not self.emit


def observation_sort_key(name: str) -> tuple:
    """Natural order of observation names: O2 before O10, then by text."""
    digits = "".join(ch for ch in name if ch.isdigit())
    return (name.rstrip("0123456789"), int(digits) if digits else -1, name)


Subscriber = Callable[[UpdateResult], object]

#: timer batches one update or advance may run: a jump that needs more (a 1-second timer and a month of
#: silence) is refused rather than left to run for minutes
MAX_TIMED_BATCHES = 1_000_000


class Engine:
    """Runs one model: feed it batches of context updates with ``update``, read ``metrics``.

    Each ``update`` call is one batch (see :mod:`qos.patterns` for what that means for patterns).
    Times are seconds since the session started and must never go backwards. ``start`` is when
    timers start: 0 by default, as in a trace, so that replaying a session's recorded trace fires its
    timers exactly when the live engine did; None starts them at the first time the engine is given
    (for a caller on another clock). ``origin`` is the calendar time of engine time 0 in seconds since
    1970 UTC, for ``schedule`` timers; ``params`` overrides parameters' defaults.
    """

    def __init__(
        self, model: Model, start: float | None = 0.0, origin: float = 0.0, params: Mapping[str, object] | None = None
    ):
        self.model = model
        beliefs = {**model.properties, **model.beliefvars}
        self._beliefs = {name: PropertyBelief(prop) for name, prop in beliefs.items()}
        self._matcher = ObservationMatcher(model.observations)
        self._values: dict[str, object] = {
            name: variable.initial for name, variable in model.variables.items() if variable.initial is not None
        }
        for name, value in (params or {}).items():
            variable = model.variables.get(name)
            if variable is None or not variable.parameter:
                raise ContextError(f"{name!r} is not a parameter of model {model.name}")
            self._values[name] = check_value(variable, name, variable.type, value)
        self._streams = build_streams(model, self._values)
        self._timers = {name: TimerClock(timer, origin) for name, timer in model.timers.items()}
        self._start = None if start is None else check_time(start)
        self._started = False
        #: beliefs that expressions read: their value is refreshed before each batch
        self._beliefs_read = sorted(set(names_in((model.streams, model.observations))) & set(beliefs))
        self._setters = {
            id(action): compile_expr(action.expr)
            for observation in model.observations.values()
            for action in observation.actions
            if isinstance(action, SetVariable)
        }
        self._outputs = {
            name: compile_expr(prop.transformation)
            for name, prop in model.properties.items()
            if prop.transformation is not None
        }
        self._t: float | None = None
        self._subscribers: list[Subscriber] = []

    @property
    def t(self) -> float | None:
        """Time of the last batch or advance (None before the first)."""
        return self._t

    @property
    def contexts(self) -> dict[str, object]:
        """Current context values, derived ones included (contexts never set are absent)."""
        return {name: value for name, value in self._values.items() if name in self.model.contexts}

    @property
    def variables(self) -> dict[str, object]:
        """Current values of ``var`` and ``param`` declarations (undefined ones are absent)."""
        return {name: value for name, value in self._values.items() if name in self.model.variables}

    @property
    def live_firings(self) -> dict[str, int]:
        """Per belief, how many firings the reasoner still keeps on their own (a bounded number)."""
        return {name: belief.live_firings for name, belief in self._beliefs.items()}

    def next_due(self) -> float | None:
        """When a timer or a time window next needs the engine, or None (nothing pending)."""
        dues = [clock.due for clock in self._timers.values() if clock.due is not None]
        dues += [due for stream in self._streams if (due := stream.due()) is not None]
        return min(dues, default=None)

    def update(
        self, t: float, set: Mapping[str, object] | None = None, emit: Iterable[str] | None = None
    ) -> UpdateResult:
        """Apply one batch at time t and return the metrics and fired observations.

        Timers and time windows due before t run first, each as its own batch. The whole batch is
        validated first: on a :class:`ContextError` nothing has changed. Subscribers are called with
        every result (timed batches included), in subscription order, after each batch is applied.
        """
        t = self._check_forward(t)
        values, emitted = check_batch(self.model, set, emit)
        self._start_timers(t)
        self._run_due(t, include_t=False)
        return self._step(t, values, emitted, self._timers_due(t))

    def advance(self, t: float) -> list[UpdateResult]:
        """Let time pass up to t: run every timer and time window due until then (inclusive).

        Returns the results of the batches this ran (also given to subscribers); t becomes the engine's
        time, so later updates must not be earlier.
        """
        t = self._check_forward(t)
        self._start_timers(t)
        results = self._run_due(t, include_t=True)
        self._t = t
        return results

    def _check_forward(self, t: float) -> float:
        t = check_time(t)
        if self._t is not None and t < self._t:
            raise ContextError(f"time {t:g} s is before the previous update at {self._t:g} s")
        return t

    def _start_timers(self, t: float) -> None:
        """Start the timers at the engine's start, and refuse a jump that would fire them too often."""
        if not self._started:
            start = self._start if self._start is not None else t
            for clock in self._timers.values():
                if not clock.timer.paused:
                    clock.start(start)
            self._started = True
        firings = sum(clock.firings_until(t) for clock in self._timers.values())
        if firings > MAX_TIMED_BATCHES:
            raise ContextError(
                f"time {t:g} s is too far ahead: the timers would fire about {firings:,.0f} times "
                f"before it (at most {MAX_TIMED_BATCHES:,}); advance the engine in smaller steps"
            )

    def _timers_due(self, t: float) -> list[str]:
        fired = [name for name, clock in self._timers.items() if clock.due is not None and clock.due <= t]
        for name in fired:
            self._timers[name].fired()
        return fired

    def _run_due(self, t: float, include_t: bool) -> list[UpdateResult]:
        results = []
        while (due := self.next_due()) is not None and (due < t or (include_t and due == t)):
            results.append(self._step(due, {}, [], self._timers_due(due)))
        return results

    def _step(self, t: float, values: dict[str, object], emitted: list[str], timers: list[str]) -> UpdateResult:
        self._t = t
        for name in self._beliefs_read:  # as it stands before this batch's evidence
            self._values[name] = self._beliefs[name].metric(t)
        self._values.update(values)
        updated = {*values, *emitted, *timers}
        for stream in self._streams:
            stream.step(t, self._values, updated)
        fired = self._matcher.step(Batch(self._values, updated))
        self._act(t, fired)
        metrics = self._metrics_at(t)
        outputs = {name: self._output(name, metrics[name]) for name in self._outputs}
        result = UpdateResult(
            t, metrics, sorted(fired, key=observation_sort_key), values, emitted, timers, outputs, self.beliefs(t)
        )
        for callback in list(self._subscribers):
            callback(result)
        return result

    def _act(self, t: float, fired: list[str]) -> None:
        """Run the actions of the fired observations, in model order; variables change after all ran."""
        assignments: dict[str, object] = {}
        for name in fired:
            for action in self.model.observations[name].actions:
                if isinstance(action, Evidence):
                    self._beliefs[action.target].add(t, action.likelihood_ratio, action.survival)
                elif isinstance(action, ClearEvidence):
                    self._beliefs[action.target].clear()
                elif isinstance(action, SetVariable):
                    value = self._setters[id(action)](self._values)
                    if value is not None:
                        assignments[action.variable] = value
                elif isinstance(action, TimerAction):
                    clock = self._timers[action.timer]
                    {"starts": clock.start, "stops": clock.stop, "resumes": clock.resume}[action.verb](t)
        self._values.update(assignments)

    def _output(self, name: str, metric: float) -> object:
        return self._outputs[name]({**self._values, SELF_BELIEF: metric})

    def metrics(self, t: float | None = None) -> dict[str, float]:
        """Every property's metric at time t (default: the last update), with decay applied."""
        if t is None:
            t = self._t if self._t is not None else 0.0
        t = check_time(t)
        if self._t is not None and t < self._t:
            raise ContextError(f"time {t:g} s is before the last update at {self._t:g} s")
        return self._metrics_at(t)

    def beliefs(self, t: float | None = None) -> dict[str, float]:
        """Every ``beliefvar``'s probability at time t (default: the last update), with decay applied."""
        t = self._t if t is None and self._t is not None else (0.0 if t is None else check_time(t))
        if self._t is not None and t < self._t:
            raise ContextError(f"time {t:g} s is before the last update at {self._t:g} s")
        return {name: self._beliefs[name].metric(t) for name in self.model.beliefvars}

    def _metrics_at(self, t: float) -> dict[str, float]:
        return {name: self._beliefs[name].metric(t) for name in self.model.properties}

    def subscribe(self, callback: Subscriber) -> Callable[[], None]:
        """Call ``callback(result)`` after every batch; returns a function that unsubscribes."""
        self._subscribers.append(callback)

        def unsubscribe() -> None:
            if callback in self._subscribers:
                self._subscribers.remove(callback)

        return unsubscribe

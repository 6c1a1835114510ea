"""How a session tells the world: QoS context batches (one engine update per instant), the stored
log, and events queued for listeners until the operation that caused them is over.

:class:`Operation` brackets every public call: it catches up on time-outs, makes the call one
store transaction, flushes the QoS batch and then dispatches the queued events.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import field
from datetime import timedelta
from typing import Any

from basis import record
from kiosk.core.channels import Channel, ChannelInput
from kiosk.core.session.events import IgnoreReason, InputIgnored, MetricsUpdated, SessionEvent
from kiosk.core.session.ports import QosEngine, SessionStore
from kiosk.core.session.state import SessionState
from kiosk.core.session.timers import AttemptClock

#: how much later a second context batch at the same instant is recorded (see ``Outputs._flush``)
SAME_INSTANT_STEP_S = 0.001

#: the CLARC model's UserInteraction literal for each channel. The keyboard maps to TOUCH_SCREEN:
#: the on-screen number keys are on the same kiosk panel as the touchscreen, and the CLARC model
#: has no keyboard literal.
USER_INTERACTION: Mapping[Channel, str] = {
    Channel.VOICE: "VOICE_RECOGNITION",
    Channel.TOUCH: "TOUCH_SCREEN",
    Channel.REMOTE: "REMOTE_CONTROL",
    Channel.KEYBOARD: "TOUCH_SCREEN",
}

#: an eventtype the session emits when it asks a question (attempt 1 opens), for models that
#: declare it (``qos/models/kiosk_pace.roqme`` times answers from it); CLARC does not, and its
#: traces stay as the paper's context table says
QUESTION_ASKED = "QuestionAsked"

Listener = Callable[[SessionEvent], None]


@record(frozen=False)
class Batch:
    """The context changes of one instant, sent to the QoS engine as one update."""

    t: float
    set: dict[str, Any] = field(default_factory=dict)
    emit: list[str] = field(default_factory=list)


#: told of each QoS result as (session time, metrics, whether it published an answer)
MetricsObserver = Callable[[float, Mapping[str, float], bool], None]
#: acts on one time-out of a kind, due at a session time (see ``Router.fire`` in :mod:`kiosk.core.session.routing`)
Fire = Callable[[str, float], None]


class Outputs:
    """The session's outputs: listeners, QoS batches, the context trace and the stored log.

    ``on_metrics`` hears every QoS result after it is published (the live adaptation policy).
    """

    def __init__(
        self,
        state: SessionState,
        timers: AttemptClock,
        *,
        engine: QosEngine | None,
        store: SessionStore | None,
        on_metrics: MetricsObserver,
    ) -> None:
        self.state = state
        self.timers = timers
        self.engine = engine
        self.store = store
        self._on_metrics = on_metrics
        #: every context batch published, as trace events ({"t":..., "set":..., "emit":...})
        self.trace: list[dict[str, Any]] = []
        #: the latest metrics from the QoS engine
        self.metrics: dict[str, float] = {}
        self._batch: Batch | None = None
        #: batches the engine ran since the session last looked (see _take_qos_results)
        self._qos_results: list[Any] = []
        #: time of the latest batch the engine ran on its own (timers, time windows)
        self._timed_t = -1.0
        self._unsubscribe_engine: Callable[[], object] = (
            engine.subscribe(self._qos_results.append) if engine is not None else lambda: None
        )
        self._listeners: list[Listener] = []
        self._queue: list[SessionEvent] = []
        self._depth = 0
        self._dispatching = False

    def let_go_of_engine(self) -> None:
        """Stop hearing the QoS engine: the next instrument of a battery's session uses it now."""
        self._unsubscribe_engine()

    def operation(self, fire: Fire, inclusive: bool = False) -> Operation:
        """Bracket one public call (see :class:`Operation`); ``fire`` acts on each due time-out."""
        return Operation(self, fire, inclusive)

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(event)`` for every event from now on; returns a function to unsubscribe.

        Listeners run on the thread that called the session, after the operation that caused
        the event has completed; they may call the session again.
        """
        self._listeners.append(listener)
        return lambda: self._listeners.remove(listener) if listener in self._listeners else None

    def emit(self, event: SessionEvent) -> None:
        """Queue ``event`` for the listeners (they hear it once the operation is over)."""
        self._queue.append(event)

    def ignore(self, t: float, event: ChannelInput | None, reason: IgnoreReason, action: str = "") -> None:
        """An input or action that does nothing now: logged and published as InputIgnored."""
        what = action
        if event is not None:
            did = event.option or event.command.value  # type: ignore[union-attr]  # no option: a command
            what = f"{event.channel.value} {did}"
        self.log(t, "input_ignored", f"{what}: {reason.value}")
        self.emit(InputIgnored(t, event, reason, action))

    def log(self, t: float, kind: str, detail: str = "") -> None:
        """Add a line to the stored session log (only once the session exists in the store)."""
        if self.store is not None and self.state.stored:
            self.store.record_event(self.state.id, t=t, kind=kind, detail=detail)

    def wall(self, t: float) -> str:
        """The wall-clock time (ISO 8601, UTC) of session time ``t``."""
        return (self.timers.clock.wall() - timedelta(seconds=self.timers.now() - t)).isoformat()

    def context(self, t: float, set: Mapping[str, Any] | None = None, emit: list[str] | None = None) -> None:
        """Add context changes to the batch of instant ``t`` (one engine update per instant)."""
        if self._batch is not None and self._batch.t != t:
            self._flush()
        if self._batch is None:
            self._batch = Batch(t)
        state = self.state
        if state.repeating and "TestState" not in (set or {}):
            # the repeated prompt is over once anything else happens
            self._batch.set["TestState"] = "STARTED"
            state.repeating = False
        elif set and "TestState" in set:
            state.repeating = set["TestState"] == "REPEATING"
        self._batch.set.update(set or {})
        self._batch.emit.extend(e for e in emit or [] if e not in self._batch.emit)

    def emit_if_modelled(self, t: float, eventtype: str) -> None:
        """Emit an eventtype beyond CLARC's contexts only when the engine's model declares it."""
        if self.engine is not None and eventtype in self.engine.model.contexts:
            self.context(t, emit=[eventtype])

    def qos_deadline(self) -> float | None:
        """Clock time at which the engine next needs time to pass (a timer, a time window), or None."""
        engine = self.engine
        due = engine.next_due() if engine is not None and self._qos_running() else None
        return None if due is None else self.timers.origin + due

    def _flush(self) -> None:
        batch, self._batch = self._batch, None
        if batch is None:
            return
        last = max(self.trace[-1]["t"] if self.trace else -1.0, self._timed_t)
        if batch.t <= last:
            # Two operations at one instant (say pause and resume in the same tick) cannot share a
            # batch once the first went to the engine, nor can a batch join a timer that already
            # fired on its own at that instant; a replay would merge them and fire observations
            # differently. Recording the second a millisecond later keeps the trace exactly what
            # the engine saw.
            batch.t = round(last + SAME_INSTANT_STEP_S, 6)
        event: dict[str, Any] = {"t": batch.t}
        if batch.set:
            event["set"] = dict(batch.set)
        if batch.emit:
            event["emit"] = list(batch.emit)
        self.trace.append(event)
        if self.store is not None:
            self.store.record_context(self.state.id, t=batch.t, set=batch.set, emit=batch.emit)
        if self.engine is None:
            return
        own = self.engine.update(batch.t, set=dict(batch.set), emit=list(batch.emit))
        self._take_qos_results(own, batch)

    def _let_qos_time_pass(self, t: float) -> None:
        """Advance the engine to session time ``t``: its timers and time windows due by then run.

        Only once the engine has had the session's first batch (its timers start then, at time 0,
        as in a replay of the trace), so nothing happens before the patient starts, and only until
        the test is over: what a model says about the time after it is about no one.
        """
        engine = self.engine
        if engine is not None and engine.t is not None and self._qos_running() and t >= engine.t:
            engine.advance(t)
            self._take_qos_results(None, None)

    def _qos_running(self) -> bool:
        return self.engine is not None and self.engine.t is not None and not self.state.finished

    def _take_qos_results(self, own: Any, batch: Batch | None) -> None:
        """Publish every batch the engine ran since the last call, in order: the ones it ran on its
        own (timers, time windows, due before ``batch``) like the session's own ``batch`` (``own``
        is its result): metrics stored, MetricsUpdated published, the adaptation policy told."""
        results, self._qos_results[:] = list(self._qos_results), []
        for result in results:
            mine = batch if result is own else None
            contexts = dict(mine.set) if mine is not None else {}
            self.metrics = dict(result.metrics)
            fired = tuple(result.fired)
            if mine is None:
                self._timed_t = result.t
                if result.timers:
                    self.log(result.t, "qos_timers", ", ".join(result.timers))
            if self.store is not None:
                self.store.record_metrics(self.state.id, t=result.t, metrics=self.metrics, fired=list(fired))
            self.emit(
                MetricsUpdated(
                    result.t,
                    dict(self.metrics),
                    fired,
                    contexts,
                    tuple(mine.emit) if mine is not None else (),
                    tuple(result.timers),
                )
            )
            self._on_metrics(result.t, self.metrics, _is_answer(contexts))


def _is_answer(contexts: Mapping[str, Any]) -> bool:
    return contexts.get("FirstAttemptAnswered") is True or contexts.get("SecondAttemptAnswered") is True


class Operation:
    """One public operation: catch up on time-outs, act, then flush QoS and publish events.

    The outermost operation is one store transaction, committed before listeners hear of it: a
    crash keeps an answer together with its QoS context batch and metrics, or neither. An
    operation that raises (an error, Ctrl-C, the store refusing a session another kiosk holds)
    rolls the transaction back, and its events are dropped: nobody hears of what was not stored.
    """

    def __init__(self, outputs: Outputs, fire: Fire, inclusive: bool = False) -> None:
        self.s = outputs
        self.fire = fire
        self.inclusive = inclusive
        self._transaction: AbstractContextManager[None] | None = None
        #: session time of the operation
        self.t = 0.0

    def __enter__(self) -> float:
        s = self.s
        s._depth += 1
        if s._depth == 1 and s.store is not None:
            self._transaction = s.store.transaction()
            self._transaction.__enter__()
        try:
            now = s.timers.clock.now()
            for kind, due in s.timers.due(now, self.inclusive):
                self.fire(kind, due)
            self.t = s.timers.t(now)
            return self.t
        except BaseException as error:  # `with` does not call __exit__ when __enter__ raises
            self.__exit__(type(error), error, error.__traceback__)
            raise

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        s = self.s
        s._depth -= 1
        if s._depth:
            return
        failure = exc if exc_type is not None else None
        try:
            if failure is None:
                s._flush()
                s._let_qos_time_pass(self.t)  # the model's timers, after what happened now
        except BaseException as error:
            failure = error
            raise
        finally:
            if failure is not None:
                s._queue.clear()
                s._qos_results.clear()
                s._batch = None
            if self._transaction is not None:
                if failure is None:
                    self._transaction.__exit__(None, None, None)
                else:  # the store rolls back, then lets the failure go on
                    self._transaction.__exit__(type(failure), failure, failure.__traceback__)
        if failure is not None:
            return
        if s._dispatching:
            return
        s._dispatching = True
        try:
            while s._queue:
                event = s._queue.pop(0)
                for listener in list(s._listeners):
                    listener(event)
        finally:
            s._dispatching = False

"""Context traces: what a session told the QoS engine, with times (see the trace format doc).

A trace is YAML or JSON::

    model: clarc
    events:
      - {t: 10, set: {PersonDetected: true}}
      - {t: 260, emit: [CallingDoctor]}

Events with the same ``t`` form one batch. :func:`load_trace` checks everything (structure, times,
context names, types, enum literals) against the model before anything is replayed, and names the
file and the event index of the first problem.
"""

from __future__ import annotations

import json
import math
import statistics
from collections.abc import Iterable, Mapping
from dataclasses import field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import yaml

from basis import record
from fileio.bounded import BadFile, write_private
from fileio.yamlfile import load_data
from qos.engine import MAX_TIMED_BATCHES, Engine, UpdateResult, check_batch
from qos.errors import ContextError, ModelError, TraceError
from qos.model import Model

_EVENT_KEYS = ("t", "set", "emit")
_TRACE_KEYS = ("model", "events", "description", "origin")


def seconds(t: float) -> float | int:
    """A time as written in traces and reports: an int when whole (``10``, not ``10.0``)."""
    return int(t) if float(t).is_integer() else t


@record(frozen=False)
class TraceEvent:
    """One entry of a trace: at time ``t`` (seconds), set these contexts and emit these eventtypes."""

    t: float
    set: dict[str, object] = field(default_factory=dict)
    emit: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """The event as it is written in a trace file (empty ``set``/``emit`` left out)."""
        data: dict[str, object] = {"t": self.t}
        if self.set:
            data["set"] = dict(self.set)
        if self.emit:
            data["emit"] = list(self.emit)
        return data


@record(frozen=False)
class Trace:
    """A context trace: the model it was recorded with and its events (in file order)."""

    #: a bundled model name or a path to a .roqme file (relative to the trace's folder)
    model: str
    events: list[TraceEvent] = field(default_factory=list)
    description: str | None = None
    #: the file it was loaded from, for messages and relative model paths
    source: Path | None = None
    #: the calendar time of t = 0 (ISO 8601, UTC unless it says otherwise), for ``schedule`` timers
    origin: str | None = None

    @property
    def origin_seconds(self) -> float:
        """The origin in seconds since 1970 UTC (0 when the trace has none)."""
        return _calendar(self.origin, self.name) if self.origin is not None else 0.0

    @property
    def name(self) -> str:
        """How messages name this trace."""
        return str(self.source) if self.source is not None else "<trace>"

    @classmethod
    def from_events(cls, model: str, events: Iterable[Mapping[str, Any]], description: str | None = None) -> Trace:
        """A trace from recorded events (mappings with ``t`` and optional ``set``/``emit``, as a
        session records them), times whole where they are whole."""
        return cls(
            model,
            [TraceEvent(seconds(e["t"]), dict(e.get("set", {})), list(e.get("emit", []))) for e in events],
            description=description,
        )

    def load_model(self) -> Model:
        """Load the trace's model (a bundled name, or a path relative to the trace's folder)."""
        from qos.bundled import load_model  # knows the bundled models

        model = self.model
        is_path = model.endswith(".roqme") or "/" in model
        if self.source is not None and is_path:
            model = str(self.source.parent / model)
        try:
            return load_model(model)
        except ModelError as exc:
            if is_path:
                raise  # it names the model file, and where in it
            raise ModelError(f"{self.name}: {exc}") from None  # an unknown name: say which trace uses it

    def check(self, model: Model | None = None) -> Model:
        """Validate every event against the model; raise :class:`TraceError` on the first problem."""
        model = model or self.load_model()
        setters: dict[tuple[float, str], int] = {}
        for index, event in enumerate(self.events):
            where = f"{self.name}: events[{index}]"
            try:
                check_batch(model, event.set, event.emit)
            except ContextError as exc:
                raise TraceError(f"{where}: {exc}") from None
            for context in event.set:
                first = setters.setdefault((float(event.t), context), index)
                if first != index:
                    raise TraceError(
                        f"{where}: events[{first}] already sets {context} at t={event.t}; "
                        "one batch can set a context only once"
                    )
        return model

    def batches(self) -> list[tuple[float, dict[str, object], list[str]]]:
        """The events merged into batches of equal time, in time order (a stable sort)."""
        merged: dict[float, tuple[float, dict[str, object], list[str]]] = {}
        for event in sorted(self.events, key=lambda e: float(e.t)):
            t, values, emitted = merged.setdefault(float(event.t), (event.t, {}, []))
            values.update(event.set)
            emitted.extend(name for name in event.emit if name not in emitted)
        return list(merged.values())

    def to_dict(self) -> dict[str, object]:
        """The trace as plain data (what :func:`load_trace` reads)."""
        data: dict[str, object] = {"model": self.model}
        if self.description:
            data["description"] = self.description
        if self.origin:
            data["origin"] = self.origin
        data["events"] = [event.to_dict() for event in self.events]
        return data

    def to_yaml(self, header: str | None = None) -> str:
        """The trace as YAML, one event per line; ``header`` becomes leading ``#`` comment lines."""
        lines = [f"# {line}".rstrip() for line in header.splitlines()] if header else []
        lines.append(f"model: {_flow(self.model)}")
        if self.description:
            lines.append(f"description: {_flow(self.description)}")
        if self.origin:
            lines.append(f"origin: {_flow(self.origin)}")
        lines.append("events:" if self.events else "events: []")
        lines += [f"  - {_flow(event.to_dict())}" for event in self.events]
        return "\n".join(lines) + "\n"

    def to_json(self) -> str:
        """The trace as JSON."""
        return json.dumps(self.to_dict(), indent=1)


def _flow(value: object) -> str:
    return (
        yaml.safe_dump(value, default_flow_style=True, sort_keys=False, width=math.inf, allow_unicode=True)
        .strip()
        .removesuffix("...")
        .strip()
    )


def dump_trace(trace: Trace, path: str | Path, header: str | None = None) -> None:
    """Write a trace to a file (JSON when the name ends in .json, else YAML), readable by its owner only."""
    path = Path(path)
    text = trace.to_json() + "\n" if path.suffix == ".json" else trace.to_yaml(header)
    write_private(path, text)


def _parse_event(raw: object, where: str) -> TraceEvent:
    if not isinstance(raw, Mapping):
        raise TraceError(f"{where}: an event must be a mapping with t and set and/or emit, not {raw!r}")
    unknown = [key for key in raw if key not in _EVENT_KEYS]
    if unknown:
        raise TraceError(f"{where}: unknown key {unknown[0]!r} (an event has t, set and emit)")
    if "t" not in raw:
        raise TraceError(f"{where}: missing time 't'")
    t = raw["t"]
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        raise TraceError(f"{where}: time t must be a number of seconds, not {t!r}")
    if t < 0:
        raise TraceError(f"{where}: time t must not be negative, got {t!r}")
    if "set" not in raw and "emit" not in raw:
        raise TraceError(f"{where}: an event needs 'set' or 'emit'")
    values = raw.get("set") or {}
    if not isinstance(values, Mapping):
        raise TraceError(f"{where}: 'set' must map context names to values, not {values!r}")
    emitted = raw.get("emit") or []
    if not isinstance(emitted, list) or not all(isinstance(name, str) for name in emitted):
        raise TraceError(f"{where}: 'emit' must be a list of eventtype names, not {emitted!r}")
    return TraceEvent(t, dict(values), list(emitted))


def trace_from_data(data: object, source: Path | None = None) -> Trace:
    """Build a trace from parsed YAML/JSON, checking its structure (not yet its contexts)."""
    name = str(source) if source is not None else "<trace>"
    if not isinstance(data, Mapping):
        raise TraceError(f"{name}: a trace must be a mapping with 'model' and 'events'")
    unknown = [key for key in data if key not in _TRACE_KEYS]
    if unknown:
        raise TraceError(f"{name}: unknown key {unknown[0]!r} (a trace has model, events, description and origin)")
    model = data.get("model")
    if not isinstance(model, str) or not model:
        raise TraceError(f"{name}: 'model' must name a bundled model or a .roqme file, not {model!r}")
    events = data.get("events")
    if not isinstance(events, list):
        raise TraceError(f"{name}: 'events' must be a list, not {events!r}")
    description = data.get("description")
    if description is not None and not isinstance(description, str):
        raise TraceError(f"{name}: 'description' must be text")
    origin = data.get("origin")
    if isinstance(origin, datetime):  # YAML reads an unquoted timestamp as one
        origin = origin.isoformat()
    if origin is not None:
        if not isinstance(origin, str):
            raise TraceError(f"{name}: 'origin' must be a date and time such as 2026-11-23T09:00:00Z, not {origin!r}")
        _calendar(origin, name)
    parsed = [_parse_event(raw, f"{name}: events[{index}]") for index, raw in enumerate(events)]
    return Trace(model, parsed, description, source, origin)


def _calendar(text: str, name: str) -> float:
    """An ISO 8601 date and time in seconds since 1970 UTC (UTC when it names no zone)."""
    try:
        moment = datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise TraceError(
            f"{name}: 'origin' must be a date and time such as 2026-11-23T09:00:00Z, not {text!r}"
        ) from None
    return (moment if moment.tzinfo else moment.replace(tzinfo=UTC)).timestamp()


def load_trace(path: str | Path) -> Trace:
    """Read a YAML or JSON trace and check it against its model.

    Raises :class:`TraceError` naming the file and the event index of the first problem
    (or :class:`~qos.errors.ModelError` when the model itself is malformed).
    """
    path = Path(path)
    try:
        data = load_data(path)
    except BadFile as exc:
        raise TraceError(str(exc)) from None
    trace = trace_from_data(data, path)
    trace.check()
    return trace


class TraceRecorder:
    """Records every batch an engine applies, as a trace that :func:`replay` reproduces.

    Replay merges events of equal time into one batch, so a caller that wants a faithful recording
    publishes one batch per instant.
    """

    def __init__(self, engine: Engine, model: str):
        self.model = model
        self.events: list[TraceEvent] = []
        self._unsubscribe = engine.subscribe(self._record)

    def _record(self, result: UpdateResult) -> None:
        if result.timed:
            return  # timers and time windows: a replay runs them again from the model
        values = {name: list(value) if isinstance(value, tuple) else value for name, value in result.set.items()}
        self.events.append(TraceEvent(seconds(result.t), values, list(result.emit)))

    @property
    def trace(self) -> Trace:
        """The trace recorded so far."""
        return Trace(self.model, list(self.events))

    def stop(self) -> None:
        """Stop recording (the recorded events stay available)."""
        self._unsubscribe()


def _statistics(samples: list[float]) -> dict[str, float]:
    return {
        "min": min(samples),
        "max": max(samples),
        "avg": statistics.fmean(samples),
        "sd": statistics.pstdev(samples),
        "last": samples[-1],
    }


@record(frozen=False)
class ReplaySamples:
    """A replayed trace: every property sampled over time, and what fired in which batch."""

    times: list[float]
    #: property name -> metric at each of ``times``
    series: dict[str, list[float]]
    #: one entry per batch that fired something: {"t": time as in the trace, "observations": [...]}
    fired: list[dict[str, object]]
    #: beliefvar name -> its probability at each of ``times`` (models with ``beliefvar`` only)
    beliefs: dict[str, list[float]] = field(default_factory=dict)


#: samples one replay may take (each holds every property): bounds time and memory, so that a tiny
#: trace whose last event is at t = 10⁷ s is refused at once instead of replayed for minutes; a
#: day of events at the default 1 s period fits
MAX_SAMPLES = 100_000


def sample_trace(trace: Trace | str | Path, sample_period: float = 1.0, model: Model | None = None) -> ReplaySamples:
    """Replay a trace through a fresh engine, sampling every property.

    Samples are taken at t = 0, period, 2·period, … up to and including the last event's time, each
    after the events at times ≤ t; when the last event falls between two of those, one more sample
    is taken at its time. Raises :class:`TraceError` (or ModelError) before replaying
    anything when the trace or its model is bad, or when the period would take more than
    :data:`MAX_SAMPLES` samples.
    """
    if (
        isinstance(sample_period, bool)
        or not isinstance(sample_period, (int, float))
        or not math.isfinite(sample_period)
        or sample_period <= 0
    ):
        raise ValueError(f"the sample period must be a positive number of seconds, not {sample_period!r}")
    if not isinstance(trace, Trace):
        trace = load_trace(trace)
    model = trace.check(model)
    engine = Engine(model, origin=trace.origin_seconds)
    batches = trace.batches()
    last_t = float(batches[-1][0]) if batches else 0.0
    count = math.floor(last_t / sample_period + 1e-9) + 1
    if count > MAX_SAMPLES:
        raise TraceError(
            f"{trace.name}: a sample period of {sample_period:g} s over the trace's {last_t:g} s "
            f"would take {count:,} samples (at most {MAX_SAMPLES:,}); use a longer sample period"
        )
    firings = sum(last_t / (timer.interval or 1.0) for timer in model.timers.values())
    if firings > MAX_TIMED_BATCHES:
        raise TraceError(
            f"{trace.name}: the model's timers would fire about {firings:,.0f} times over the trace's "
            f"{last_t:g} s (at most {MAX_TIMED_BATCHES:,}); is a timer's interval too short?"
        )
    samples = ReplaySamples([], {name: [] for name in model.properties}, [], {name: [] for name in model.beliefvars})
    # every batch that fires, timer batches included, in the order the engine runs them
    engine.subscribe(
        lambda result: (
            samples.fired.append({"t": seconds(result.t), "observations": result.fired}) if result.fired else None
        )
    )

    def sample(now: float) -> None:
        engine.advance(max(now, engine.t or 0.0))
        samples.times.append(now)
        at = max(now, engine.t or 0.0)
        for name, value in engine.metrics(at).items():
            samples.series[name].append(value)
        for name, value in engine.beliefs(at).items():
            samples.beliefs[name].append(value)

    try:
        _run(engine, batches, count, sample_period, last_t, sample)
    except ContextError as exc:  # the model's timers cannot follow the trace (a jump too far ahead)
        raise TraceError(f"{trace.name}: {exc}") from None
    return samples


def _run(engine: Engine, batches: list, count: int, sample_period: float, last_t: float, sample) -> None:
    """Apply the batches in time order, sampling at every period (see :func:`sample_trace`)."""
    upcoming = 0
    for k in range(count):
        now = k * sample_period
        # a small tolerance so that samples at k·0.1 s still see the events written at that time
        while upcoming < len(batches) and float(batches[upcoming][0]) <= now + 1e-9:
            t, values, emitted = batches[upcoming]
            engine.update(float(t), set=values, emit=emitted)
            upcoming += 1
        sample(now)
    if upcoming < len(batches):
        # the last event falls between two samples: apply the rest and sample at that time too,
        # so that every batch is counted and `last` is the value after the last event
        for t, values, emitted in batches[upcoming:]:
            engine.update(float(t), set=values, emit=emitted)
        sample(last_t)


def replay(trace: Trace | str | Path, sample_period: float = 1.0, model: Model | None = None) -> dict:
    """Replay a trace and summarise it as trace-format.md specifies.

    Returns ``{"metrics": {property: {min, max, avg, sd, last}}, "fired": [{t, observations}]}``
    (``sd`` is the population standard deviation); see :func:`sample_trace` for the sampling.
    """
    return summarise(sample_trace(trace, sample_period, model))


def summarise(samples: ReplaySamples) -> dict:
    """The replay result of trace-format.md from a replay's samples (and, for a model with belief
    variables, their statistics under ``beliefs``)."""
    result: dict = {
        "metrics": {name: _statistics(values) for name, values in samples.series.items()},
        "fired": samples.fired,
    }
    if samples.beliefs:
        result["beliefs"] = {name: _statistics(values) for name, values in samples.beliefs.items()}
    return result

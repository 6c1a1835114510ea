"""In-process RoQME QoS engine.

Load a model, feed an :class:`Engine` batches of context updates, read the property metrics::

    from qos import load_model, Engine
    engine = Engine(load_model("clarc"))
    result = engine.update(10, set={"PersonDetected": True})
    result.metrics, result.fired
    engine.advance(75)  # nothing happened since: let the model's timers and time windows run

Times are seconds since the session started; the engine never reads the wall clock.

Context traces (recorded sessions, hand-written scenarios) are loaded with :func:`load_trace` and
replayed with :func:`replay`, or from the shell with ``python -m qos replay TRACE``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from basis.lazy import lazy_names
from qos.bundled import bundled_models, load_model
from qos.errors import ContextError, ModelError, QosError, TraceError

if TYPE_CHECKING:
    from qos.engine import Engine, UpdateResult
    from qos.model import Context, EnumType, Model, Observation, Property, Timer, Variable
    from qos.parser import parse_model
    from qos.trace import (
        ReplaySamples,
        Trace,
        TraceEvent,
        TraceRecorder,
        dump_trace,
        load_trace,
        replay,
        sample_trace,
    )

#: each public name -> its module, imported on first use: a program that only names a model, or
#: only reads a trace, does not wait for the grammar, the engine or YAML
_MODULES: dict[str, str] = {
    **dict.fromkeys(("Engine", "UpdateResult"), "qos.engine"),
    **dict.fromkeys(("Context", "EnumType", "Model", "Observation", "Property", "Timer", "Variable"), "qos.model"),
    "parse_model": "qos.parser",
    **dict.fromkeys(
        ("ReplaySamples", "Trace", "TraceEvent", "TraceRecorder", "dump_trace", "load_trace", "replay", "sample_trace"),
        "qos.trace",
    ),
}

__all__ = [
    "Context",
    "ContextError",
    "Engine",
    "EnumType",
    "Model",
    "ModelError",
    "Observation",
    "Property",
    "QosError",
    "ReplaySamples",
    "Timer",
    "Trace",
    "TraceError",
    "TraceEvent",
    "TraceRecorder",
    "UpdateResult",
    "Variable",
    "bundled_models",
    "dump_trace",
    "load_model",
    "load_trace",
    "parse_model",
    "replay",
    "sample_trace",
]


__getattr__, __dir__ = lazy_names(globals(), _MODULES, __all__)

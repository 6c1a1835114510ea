"""Checking what callers give the engine: times and batches of context updates.

Everything is checked before anything is applied, so a bad batch leaves the engine unchanged.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence

from qos.errors import ContextError
from qos.model import BOOLEAN, EVENTTYPE, NUMBER, ArrayType, Context, EnumType, Model, ValueType, Variable


def _describe(value: object) -> str:
    return f"{value!r} ({type(value).__name__})"


def check_time(t: object) -> float:
    """A batch time as a float; ContextError unless it is a finite real number."""
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        raise ContextError(f"time must be a finite number of seconds, not {_describe(t)}")
    return float(t)


def check_batch(
    model: Model, set: Mapping[str, object] | None, emit: Iterable[str] | None
) -> tuple[dict[str, object], list[str]]:
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
        if context.derived:
            raise ContextError(f"context {name} is derived: the engine computes it from its definition")
        if context.kind == EVENTTYPE:
            raise ContextError(f"context {name} is an eventtype: emit it, do not set it")
        values[name] = check_value(context, name, context.type, value)
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


def check_value(context: Context | Variable, name: str, value_type: ValueType, value: object) -> object:
    """One value for a context or a parameter (``context`` gives its name and bounds), as the engine
    keeps it: booleans, floats, enum literal names, tuples for arrays."""
    what = "parameter" if isinstance(context, Variable) else "context"
    if isinstance(value_type, ArrayType):
        size = value_type.size
        if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Sequence) or len(value) > size:
            raise ContextError(f"{what} {name} is an array of at most {size} values, got {_describe(value)}")
        return tuple(
            check_value(context, f"{name}[{index + 1}]", value_type.element, item) for index, item in enumerate(value)
        )
    if value_type == BOOLEAN:
        if not isinstance(value, bool):
            raise ContextError(f"{what} {name} is boolean, got {_describe(value)}")
        return value
    if value_type == NUMBER:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ContextError(f"{what} {name} is a number, got {_describe(value)}")
        problem = context.spec.out_of_bounds(value) if context.spec is not None else None
        if problem:
            raise ContextError(f"{what} {name}: {problem}")
        return float(value)
    assert isinstance(value_type, EnumType)  # the one type left
    literal = value
    if isinstance(value, str) and "::" in value:
        type_name, _, literal = value.partition("::")
        if type_name not in (value_type.name, context.name):
            raise ContextError(f"{what} {name} is of type {value_type.name}, got {value!r}")
    if not isinstance(literal, str):
        raise ContextError(f"{what} {name} is an enum of {', '.join(value_type.literals)}; got {_describe(value)}")
    if literal not in value_type.literals:
        raise ContextError(
            f"{what} {name} has no literal {literal!r} (expected one of {', '.join(value_type.literals)})"
        )
    return literal

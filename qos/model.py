"""The in-memory form of a RoQME model: types, properties and belief variables, contexts (primitive and
derived), variables, parameters, timers, observations with their actions, and the terms in them.

A :class:`Model` is immutable once loaded; every :class:`~qos.engine.Engine` built from it keeps its
own run-time state, so one model can serve many engines. The value types live in :mod:`qos.values`
and the terms (expressions and patterns) in :mod:`qos.nodes`; this module re-exports them, so
``from qos.model import X`` names every part of a model.
"""

from __future__ import annotations

from dataclasses import field

from basis import record
from qos.nodes import (
    Aggregate,
    AllOf,
    AndNot,
    AnyOf,
    Binary,
    Call,
    Changed,
    Conditional,
    Expr,
    FollowedBy,
    Literal,
    Once,
    Pattern,
    Period,
    Range,
    Repeat,
    Unary,
    Updated,
    Var,
    While,
)
from qos.values import BOOLEAN, EVENTTYPE, NUMBER, ArrayType, EnumType, TypeSpec, ValueType, type_name

#: the model's own names and the value types and terms it is built of (one import for callers)
__all__ = [
    "Action",
    "Aggregate",
    "AllOf",
    "AndNot",
    "AnyOf",
    "ArrayType",
    "BOOLEAN",
    "Binary",
    "Call",
    "Changed",
    "ClearEvidence",
    "Conditional",
    "Context",
    "EVENTTYPE",
    "EnumType",
    "Evidence",
    "Expr",
    "FollowedBy",
    "INTENSITY_LR",
    "Literal",
    "Model",
    "NUMBER",
    "Observation",
    "Once",
    "Pattern",
    "Period",
    "Property",
    "REFERENCE_CLAMP",
    "Range",
    "Repeat",
    "Schedule",
    "SetVariable",
    "Stream",
    "Timer",
    "TimerAction",
    "TypeSpec",
    "Unary",
    "Updated",
    "ValueType",
    "Var",
    "Variable",
    "While",
    "type_name",
]

#: likelihood ratio of each intensity (paper, Table 1); an undermining observation uses 1/LR
INTENSITY_LR: dict[str, float] = {
    "veryhigh": 0.1,
    "high": 0.3,
    "default": 0.5,
    "medium": 0.5,
    "low": 0.7,
    "verylow": 0.9,
}

#: the name the engine gives the belief a property's output transformation reads
SELF_BELIEF = "#belief"

#: a reference of exactly 0 or 1 would make a property deaf to evidence (as RoQME's generator does)
REFERENCE_CLAMP = (0.01, 0.99)


@record
class Context:
    """A context variable: what the kiosk tells the engine (``context NAME : TYPE``)."""

    name: str
    type: ValueType
    #: bounds and unit (numbers); None for an unconstrained context
    spec: TypeSpec | None = None
    #: a derived context's definition (``context X : T := …``): an expression or, for an eventtype,
    #: a pattern; None for a primitive context, which the kiosk sets
    definition: Expr | Pattern | None = None
    description: str | None = None

    @property
    def kind(self) -> str:
        """``boolean``, ``number``, ``eventtype``, ``enum`` or ``array``."""
        if isinstance(self.type, ArrayType):
            return "array"
        return "enum" if isinstance(self.type, EnumType) else self.type

    @property
    def derived(self) -> bool:
        """True for a derived context: the engine computes it, nobody may set it."""
        return self.definition is not None

    @property
    def literals(self) -> tuple[str, ...]:
        """The enum literals of an enum context, in declaration order (empty otherwise)."""
        return self.type.literals if isinstance(self.type, EnumType) else ()


@record
class Property:
    """A QoS property: a hidden Boolean whose probability is the metric (``property NAME …``)."""

    name: str
    reference: float = 0.5
    #: seconds; ``None`` means the evidence never fades
    survival: float | None = None
    #: ``property P : T := …``: the value published beside the metric, computed from ``belief``
    transformation: Expr | None = None
    description: str | None = None

    @property
    def prior(self) -> float:
        """The reference clamped to [0.01, 0.99], used as the prior probability."""
        low, high = REFERENCE_CLAMP
        return min(max(self.reference, low), high)

    @property
    def decay_rate(self) -> float:
        """λ = 1/survival (per second); 0 when the evidence never fades."""
        return 0.0 if self.survival is None else 1.0 / self.survival


# ---- actions, variables, timers ------------------------------------------------------------------


@record
class Evidence:
    """``reinforces | undermines BELIEF [strength] [survival T]``."""

    target: str
    reinforces: bool
    intensity: str = "default"
    #: seconds this evidence takes to fade; None: the target's own survival
    survival: float | None = None

    @property
    def likelihood_ratio(self) -> float:
        """The evidence's likelihood ratio: the intensity's LR, or 1/LR when undermining."""
        lr = INTENSITY_LR[self.intensity]
        return lr if self.reinforces else 1.0 / lr


@record
class SetVariable:
    """``sets v := expr``: the variable takes the expression's value after the batch."""

    variable: str
    expr: Expr


@record
class ClearEvidence:
    """``clears BELIEF``: forget every piece of evidence; the belief is its reference again."""

    target: str


@record
class TimerAction:
    """``starts | stops | resumes TIMER``."""

    verb: str
    timer: str


Action = Evidence | SetVariable | ClearEvidence | TimerAction


@record
class Variable:
    """``var v : T := expr`` (recomputed every batch unless constant, set by ``sets``) or
    ``param p : T default value`` (a constant a caller may override)."""

    name: str
    type: ValueType
    spec: TypeSpec | None = None
    #: the value before any batch (None: undefined)
    initial: object = None
    #: recomputed after every batch's contexts when not constant
    definition: Expr | None = None
    parameter: bool = False
    description: str | None = None


@record
class Schedule:
    """``schedule("minutes, hours, days, months, weekdays[, seconds]")`` (Esper ``timer:at``), read by
    :func:`qos.timers.parse_schedule`: each field holds the values at which the timer fires."""

    text: str
    minutes: frozenset[int]
    hours: frozenset[int]
    days: frozenset[int]
    months: frozenset[int]
    weekdays: frozenset[int]
    seconds: frozenset[int]


@record
class Timer:
    """``timer T := interval | schedule(…) [offset d] [onetime] [paused]``; it occurs as a pattern."""

    name: str
    #: seconds between firings (``timer:interval``); None for a schedule
    interval: float | None = None
    schedule: Schedule | None = None
    offset: float = 0.0
    onetime: bool = False
    paused: bool = False
    description: str | None = None


@record
class Observation:
    """``observation NAME : PATTERN ACTION`` or ``… { ACTION… }``."""

    name: str
    pattern: Pattern
    actions: tuple[Action, ...]
    #: line of the declaration in the model file (for messages)
    line: int = 0
    description: str | None = None

    @property
    def evidence(self) -> list[Evidence]:
        """The ``reinforces``/``undermines`` actions, in order."""
        return [action for action in self.actions if isinstance(action, Evidence)]

    @property
    def likelihood_ratio(self) -> float:
        """The likelihood ratio of the first piece of evidence (CLARC's observations have one)."""
        return self.evidence[0].likelihood_ratio


#: a computed value the engine keeps up to date each batch, in ``Model.streams`` order: a derived
#: context (by name), a variable with a definition (by name), or an Aggregate/Period (hidden name ``#n``)
Stream = Context | Variable | Aggregate | Period


@record
class Model:
    """A loaded, checked RoQME model."""

    name: str
    #: where it was loaded from (a path, or ``<string>``)
    source: str
    #: published properties (the metrics), in declaration order
    properties: dict[str, Property] = field(default_factory=dict)
    types: dict[str, TypeSpec] = field(default_factory=dict)
    contexts: dict[str, Context] = field(default_factory=dict)
    #: in declaration order
    observations: dict[str, Observation] = field(default_factory=dict)
    #: ``beliefvar`` declarations: beliefs like properties, not published
    beliefvars: dict[str, Property] = field(default_factory=dict)
    variables: dict[str, Variable] = field(default_factory=dict)
    timers: dict[str, Timer] = field(default_factory=dict)
    #: (name, definition) of every computed value, dependencies first
    streams: tuple[tuple[str, Stream], ...] = ()
    #: models brought in with ``import`` (their declarations are merged into this one)
    imports: tuple[str, ...] = ()
    description: str | None = None

"""The in-memory form of a RoQME model: types, properties, contexts and observations.

A :class:`Model` is immutable once loaded; every :class:`~qos.engine.Engine` built from it keeps its
own run-time state, so one model can serve many engines.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union

#: likelihood ratio of each intensity (paper, Table 1); an undermining observation uses 1/LR
INTENSITY_LR: dict[str, float] = {
    "veryhigh": 0.1,
    "high": 0.3,
    "default": 0.5,
    "low": 0.7,
    "verylow": 0.9,
}

#: a reference of exactly 0 or 1 would make a property deaf to evidence (as RoQME's generator does)
REFERENCE_CLAMP = (0.01, 0.99)


@dataclass(frozen=True)
class EnumType:
    """An enumeration: a named type (``type T : enum {…}``) or the inline type of one context."""

    name: str
    literals: tuple[str, ...]

    def __str__(self) -> str:
        return f"enum {self.name} {{{', '.join(self.literals)}}}"


#: the type of a context or expression: "boolean", "number", "eventtype" or an enumeration
ValueType = Union[str, EnumType]

BOOLEAN = "boolean"
NUMBER = "number"
EVENTTYPE = "eventtype"


def type_name(value_type: ValueType) -> str:
    """How a type is named in messages: ``boolean``, ``number``, ``eventtype`` or ``enum T``."""
    return f"enum {value_type.name}" if isinstance(value_type, EnumType) else value_type


@dataclass(frozen=True)
class Context:
    """A context variable: what the kiosk tells the engine (``context NAME : TYPE``)."""

    name: str
    type: ValueType

    @property
    def kind(self) -> str:
        """``boolean``, ``number``, ``eventtype`` or ``enum``."""
        return "enum" if isinstance(self.type, EnumType) else self.type

    @property
    def literals(self) -> tuple[str, ...]:
        """The enum literals of an enum context, in declaration order (empty otherwise)."""
        return self.type.literals if isinstance(self.type, EnumType) else ()


@dataclass(frozen=True)
class Property:
    """A QoS property: a hidden Boolean whose probability is the metric (``property NAME …``)."""

    name: str
    reference: float = 0.5
    #: seconds; ``None`` means the evidence never fades
    survival: float | None = None

    @property
    def prior(self) -> float:
        """The reference clamped to [0.01, 0.99], used as the prior probability."""
        low, high = REFERENCE_CLAMP
        return min(max(self.reference, low), high)

    @property
    def decay_rate(self) -> float:
        """λ = 1/survival (per second); 0 when the evidence never fades."""
        return 0.0 if self.survival is None else 1.0 / self.survival


# ---- expressions (values) and patterns (occurrences), as parsed and type-checked ----------------

@dataclass(frozen=True)
class Var:
    """A context's current value in an expression."""

    name: str
    type: ValueType


@dataclass(frozen=True)
class Literal:
    """A constant: boolean, number or enum literal."""

    value: object
    type: ValueType


@dataclass(frozen=True)
class Unary:
    """``!e`` (boolean not) or ``-e`` (numeric negation)."""

    op: str
    operand: "Expr"
    type: ValueType


@dataclass(frozen=True)
class Binary:
    """``& | = != < <= > >= + - * /``."""

    op: str
    left: "Expr"
    right: "Expr"
    type: ValueType


Expr = Union[Var, Literal, Unary, Binary]


@dataclass(frozen=True)
class Updated:
    """Occurs on every update of a context in a batch (``update(var)``, a bare non-boolean
    variable, or an eventtype occurring); with ``when_true``, only when the new value is true
    (``eventWhen(var)`` or a bare boolean variable)."""

    name: str
    when_true: bool = False


@dataclass(frozen=True)
class Changed:
    """Occurs when an expression's value changes (``update(expr)``); with ``when_true``, only when
    it changes to true (``eventWhen(expr)``, or a bare boolean expression)."""

    expr: Expr
    when_true: bool = False


@dataclass(frozen=True)
class AnyOf:
    """``a or b``."""

    left: "Pattern"
    right: "Pattern"


@dataclass(frozen=True)
class AllOf:
    """``a and b``."""

    left: "Pattern"
    right: "Pattern"


@dataclass(frozen=True)
class FollowedBy:
    """``a -> b``."""

    first: "Pattern"
    then: "Pattern"


@dataclass(frozen=True)
class Once:
    """``once p``."""

    pattern: "Pattern"


@dataclass(frozen=True)
class While:
    """``p while(cond)``."""

    pattern: "Pattern"
    condition: Expr


@dataclass(frozen=True)
class Repeat:
    """``p repeat(n)``."""

    pattern: "Pattern"
    times: int


Pattern = Union[Updated, Changed, AnyOf, AllOf, FollowedBy, Once, While, Repeat]


@dataclass(frozen=True)
class Observation:
    """``observation NAME : PATTERN (reinforces | undermines) PROPERTY [INTENSITY]``."""

    name: str
    pattern: Pattern
    property: str
    reinforces: bool
    intensity: str = "default"
    #: line of the declaration in the model file (for messages)
    line: int = 0

    @property
    def likelihood_ratio(self) -> float:
        """The evidence's likelihood ratio: the intensity's LR, or 1/LR when undermining."""
        lr = INTENSITY_LR[self.intensity]
        return lr if self.reinforces else 1.0 / lr


@dataclass(frozen=True)
class Model:
    """A loaded, checked RoQME model."""

    name: str
    #: where it was loaded from (a path, or ``<string>``)
    source: str
    properties: dict[str, Property] = field(default_factory=dict)
    types: dict[str, EnumType] = field(default_factory=dict)
    contexts: dict[str, Context] = field(default_factory=dict)
    #: in declaration order
    observations: dict[str, Observation] = field(default_factory=dict)

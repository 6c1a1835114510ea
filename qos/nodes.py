"""The terms of a RoQME model as parsed and type-checked: expressions (values) and patterns
(occurrences). Evaluated by :mod:`qos.expressions` and matched by :mod:`qos.patterns`."""

from __future__ import annotations

from basis import record
from qos.values import NUMBER, ValueType


@record
class Var:
    """A context's current value in an expression."""

    name: str
    type: ValueType


@record
class Literal:
    """A constant: boolean, number or enum literal."""

    value: object
    type: ValueType


@record
class Unary:
    """``!e`` (boolean not) or ``-e`` (numeric negation)."""

    op: str
    operand: Expr
    type: ValueType


@record
class Binary:
    """``& | = != < <= > >= + - * /``."""

    op: str
    left: Expr
    right: Expr
    type: ValueType


@record
class Conditional:
    """``condition ? then : otherwise``; undefined when the condition is."""

    condition: Expr
    then: Expr
    otherwise: Expr
    type: ValueType


@record
class Call:
    """A function of values: ``pow sqrt exp abs`` (numbers) or ``size isEmpty first last at includes``
    (arrays); ``X'f(a)`` is ``f(X, a)``."""

    function: str
    args: tuple[Expr, ...]
    type: ValueType


@record
class Aggregate:
    """``avg min max count sum increasing decreasing stable`` over the updates of one context.

    ``window`` is None (every update so far), an int (the last n updates, Esper ``length(n)``) or a
    float number of seconds (consecutive batches of that length, Esper ``time_batch``); ``where`` keeps
    only the updates after which it is true. Checked models hold it as a stream (see ``Model.streams``).
    """

    function: str
    source: str
    window: int | float | None
    where: Expr | None
    type: ValueType


@record
class Period:
    """``period(X)``: at an update that changes X, the seconds since X's previous update;
    ``period(a -> b)``: at each ``b`` after an ``a``, the seconds since the latest ``a``."""

    source: str | None
    first: Pattern | None = None
    then: Pattern | None = None
    type: ValueType = NUMBER


Expr = Var | Literal | Unary | Binary | Conditional | Call


@record
class Updated:
    """Occurs on every update of a context in a batch (``update(var)``, a bare non-boolean
    variable, or an eventtype occurring); with ``when_true``, only when the new value is true
    (``eventWhen(var)`` or a bare boolean variable)."""

    name: str
    when_true: bool = False


@record
class Changed:
    """Occurs when an expression's value changes (``update(expr)``); with ``when_true``, only when
    it changes to true (``eventWhen(expr)``, or a bare boolean expression)."""

    expr: Expr
    when_true: bool = False


@record
class AnyOf:
    """``a or b``."""

    left: Pattern
    right: Pattern


@record
class AllOf:
    """``a and b``."""

    left: Pattern
    right: Pattern


@record
class FollowedBy:
    """``a -> b``."""

    first: Pattern
    then: Pattern


@record
class Once:
    """``once p``."""

    pattern: Pattern


@record
class While:
    """``p while(cond)``."""

    pattern: Pattern
    condition: Expr


@record
class Repeat:
    """``p repeat(n)``."""

    pattern: Pattern
    times: int


@record
class AndNot:
    """``a and not b``: ``a`` occurs before ``b`` has occurred since the pattern was (re-)armed; an
    occurrence of ``b`` ends the attempt and the pattern starts again (Esper ``every (a and not b)``)."""

    pattern: Pattern
    excluded: Pattern


@record
class Range:
    """``p range(a, b)``: occurs on the a-th to the b-th occurrence of ``p`` in the engine's life."""

    pattern: Pattern
    low: int
    high: int


Pattern = Updated | Changed | AnyOf | AllOf | AndNot | FollowedBy | Once | While | Repeat | Range

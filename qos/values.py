"""The value types of a RoQME model: booleans, numbers, event types, enumerations, arrays, and a
declared type's bounds and unit. Shared by the model, its terms and the engine's values."""

from __future__ import annotations

from basis import record


@record
class EnumType:
    """An enumeration: a named type (``type T : enum {…}``) or the inline type of one context."""

    name: str
    literals: tuple[str, ...]

    def __str__(self) -> str:
        return f"enum {self.name} {{{', '.join(self.literals)}}}"


@record
class ArrayType:
    """An array of at most ``size`` values of one scalar type (``number[3]``, ``enum[2] {…}``)."""

    element: ValueType
    size: int

    def __str__(self) -> str:
        return f"{type_name(self.element)}[{self.size}]"


#: the type of a context or expression: "boolean", "number", "eventtype", an enumeration or an array
ValueType = str | EnumType | ArrayType

BOOLEAN = "boolean"
NUMBER = "number"
EVENTTYPE = "eventtype"


def type_name(value_type: ValueType) -> str:
    """How a type is named in messages: ``boolean``, ``number``, ``eventtype``, ``enum T`` or ``number[3]``."""
    if isinstance(value_type, ArrayType):
        return str(value_type)
    return f"enum {value_type.name}" if isinstance(value_type, EnumType) else value_type


@record
class TypeSpec:
    """A declared data type with its constraints: what ``type T : …`` names and a context or
    variable declares. Bounds and units apply to numbers (and to the elements of number arrays)."""

    type: ValueType
    lower: float | None = None
    upper: float | None = None
    #: the unit a number is measured in (documentation; ``time`` is a number of seconds)
    unit: str | None = None

    def out_of_bounds(self, value: float) -> str | None:
        """Why a number breaks the bounds, or None when it keeps them."""
        if self.lower is not None and value < self.lower:
            return f"{value:g} is below the lower bound {self.lower:g}"
        if self.upper is not None and value > self.upper:
            return f"{value:g} is above the upper bound {self.upper:g}"
        return None
